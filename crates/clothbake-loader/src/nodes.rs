//! The lookup's node table: the grid padded for branch-free gathers, in tiles of one cache
//! line, and the portable blend.
//!
//! Nodes (in lanes, `V` = [`f16`] or `f32`, see [`Lane`]): polar rows `0..=n_theta_i` (row 0
//! the pole node, row `k + 1` cell `k`) x `n_phi_i` azimuth columns x polar rows
//! `0..=n_theta_o` x `phi_o` columns (column `n_phi_o` a copy of column 0) x 4 lanes (R, G,
//! B, 0). A lookup blends the nodes at `(a + ia, b or b', c + ic, d + id)`, `ia, ic, id` in
//! {0, 1}: for each `(ia, ib)` the 2 x 2 block of `(theta_o, phi_o)` nodes at `(c, d)`.
//!
//! Layout: the `(theta_o, phi_o)` plane of each `(theta_i, phi_i)` node is stored as
//! overlapping *tiles* of 2 polar rows (`c`, `c + 1`) x [`TILE_COLUMNS`] = 4 columns (`3 e` to
//! `3 e + 3`), one for every `c < n_theta_o` and every `e`: row `c`'s 4 nodes, then row
//! `c + 1`'s, 32 lanes (64 bytes of halves: one cache line; f32 tiles are two). The block of a
//! lookup at `(c, d)` lies in tile `(c, d / 3)` at column `d % 3` (tiles advance 3 columns and
//! overlap by one, so columns `d` and `d + 1` are always in one tile), and the storage is
//! aligned to 64 bytes: the 16 nodes of an f16 lookup are 4 cache lines, one per `(ia, ib)`
//! (at most 8 for f32). The price is memory: every node is held about 2 x 4/3 times (2.6 times
//! the plain padded grid on the default grid: 95 MB of halves for a 32 x 64 x 32 x 64 table).
//!
//! A lookup reads 8 *runs* of 8 lanes (2 nodes, `(c + ic, d)` and `(c + ic, d + 1)`): run
//! `r = 4 ia + 2 ib + ic` starts at `base_ib + ia s_ti + ic` [`TILE_ROW`], where
//! `base_ib = lo_a s_ti + b s_pi + lo_c s_to + `[`column_offset`]`(lo_d)` for the low and high
//! `phi_i` columns `b` (the `phi_i` axis has no copied column: its high neighbour is
//! [`next_column`], wrapping to 0).
//!
//! Index safety: every axis gives a low index `lo <= n - 1` (clamped, NaN included). The
//! polar axes use rows `lo` and `lo + 1 <= n` (theta_i rows `0..=n` exist; theta_o row
//! `lo + 1` is in tile `lo`), `phi_o` columns `lo` and `lo + 1` (in tile `lo / 3`), `phi_i`
//! columns `lo` and `next_column(lo) <= n - 1`. For each `phi_i` column the highest run ends
//! at `base + s_ti + TILE_ROW + 8`, at most `len`. [`Nodes::with_runs`] checks that end once
//! per lookup and returns the 8 runs as arrays borrowed from the values.

#[cfg(target_arch = "x86_64")]
use std::arch::x86_64::{__m128i, __m256, _mm256_cvtph_ps, _mm256_loadu_ps, _mm_loadu_si128};

use half::f16;

use crate::angles::{atan2, ATAN_COEFFS};
use crate::axis::Axis;
use crate::grid::Grid;
use crate::stored::f16_to_f32;

/// Lanes per node: R, G, B and a zero pad.
pub(crate) const LANES: usize = 4;

/// `phi_o` columns a tile holds.
pub(crate) const TILE_COLUMNS: usize = 4;

/// `phi_o` columns from one tile to the next (tiles overlap by one column).
pub(crate) const TILE_STEP: usize = TILE_COLUMNS - 1;

/// Lanes from a tile's first polar row to its second.
pub(crate) const TILE_ROW: usize = TILE_COLUMNS * LANES;

/// Lanes of a tile: 2 polar rows of [`TILE_COLUMNS`] nodes.
pub(crate) const TILE: usize = 2 * TILE_ROW;

/// Lanes from a tile row's start to the node of the lookups whose low `phi_o` column is `d`:
/// tile `d / 3`, column `d % 3`.
#[inline(always)]
pub(crate) fn column_offset(d: usize) -> usize {
    TILE * (d / TILE_STEP) + LANES * (d % TILE_STEP)
}

/// Values of the tiled table at their precision.
#[derive(Clone, Debug)]
pub(crate) enum Values {
    F16(Tiles<f16>),
    F32(Tiles<f32>),
}

/// Lanes in whole tiles whose first lane starts a cache line (64 bytes); used as a slice of
/// lanes.
#[derive(Clone, Debug)]
pub(crate) struct Tiles<V> {
    tiles: Vec<Tile<V>>,
}

/// True when a tile of lanes `V` is one cache line (half floats; f32 tiles are two).
#[cfg(target_arch = "x86_64")]
pub(crate) const fn one_line_tiles<V>() -> bool {
    size_of::<V>() * TILE <= 64
}

/// One tile's lanes, aligned to a cache line.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
struct Tile<V>([V; TILE]);

/// Tiles of a theta_o row on an axis of `npo` columns: the last starts at or below column
/// `npo - 1` (a lookup's low column), so that columns up to `npo` (the copy of column 0) are
/// held.
fn tiles_per_row(npo: u32) -> usize {
    (npo as usize - 1) / TILE_STEP + 1
}

/// A source of the padded grid one `phi_o` row at a time: `fill(ri, pi, ro, row)` writes the
/// `n_phi_o` nodes of polar row `ri`, `phi_i` column `pi` and polar row `ro` (rows as in the
/// module documentation: row 0 the pole) into `row`, one `[V; LANES]` a node.
pub(crate) type RowFill<'a, V> = dyn Fn(u32, u32, u32, &mut [[V; LANES]]) + Sync + 'a;

/// Fills the `(theta_o, phi_o)` planes of the padded grid in order (see
/// [`Tiles::from_planes`]): `fill(ri, pi, plane)` writes the `n_theta_o + 1` polar rows of
/// `n_phi_o` nodes of polar row `ri`, `phi_i` column `pi`.
pub(crate) trait PlaneFill<V> {
    /// Why a plane could not be filled (a damaged file).
    type Error;
    /// Fills the plane `(ri, pi)`.
    fn fill(&mut self, ri: u32, pi: u32, plane: &mut [[V; LANES]]) -> Result<(), Self::Error>;
}

impl<V: Copy + Default + Send + Sync> Tiles<V> {
    /// The tiles of `g` (see the module documentation) from `node(polar row i, phi_i, polar
    /// row o, phi_o)`, each lane converted by `lane`.
    fn of(
        g: &Grid,
        node: &(dyn Fn(u32, u32, u32, u32) -> [f32; 4] + Sync),
        lane: impl Fn(f32) -> V + Sync,
    ) -> Tiles<V> {
        Tiles::from_rows(g, &|ri, pi, ro, row: &mut [[V; LANES]]| {
            for (po, x) in row.iter_mut().enumerate() {
                *x = node(ri, pi, ro, po as u32).map(&lane);
            }
        })
    }

    /// The tiles of `g` from whole `phi_o` rows ([`RowFill`]): each `(theta_i, phi_i)` node's
    /// `(theta_o, phi_o)` plane is filled once into a small buffer and cut into its tiles, on
    /// up to two threads (each writes its own `theta_i` rows; the bytes do not depend on the
    /// split).
    pub(crate) fn from_rows(g: &Grid, fill: &RowFill<'_, V>) -> Tiles<V> {
        /// A [`PlaneFill`] of whole rows.
        struct Rows<'f, 'a, V> {
            fill: &'f RowFill<'a, V>,
            npo: usize,
        }
        impl<V> PlaneFill<V> for Rows<'_, '_, V> {
            type Error = std::convert::Infallible;
            fn fill(
                &mut self,
                ri: u32,
                pi: u32,
                plane: &mut [[V; LANES]],
            ) -> Result<(), Self::Error> {
                for (ro, row) in plane.chunks_exact_mut(self.npo).enumerate() {
                    (self.fill)(ri, pi, ro as u32, row);
                }
                Ok(())
            }
        }
        let npo = g.n_phi_o as usize;
        match Tiles::from_planes(g, &|_| Rows { fill, npo }) {
            Ok((tiles, _)) => tiles,
            Err(never) => match never {},
        }
    }

    /// The tiles of `g` from whole `(theta_o, phi_o)` planes: `make(first)` gives the filler
    /// of the polar rows `theta_i` from `first` on, which is called with `(ri, pi, plane)` in
    /// order (`ri` ascending, then `pi`) and writes the `n_theta_o + 1` rows of `n_phi_o`
    /// nodes of that plane. Up to two fillers run on two threads, each on its own rows; they
    /// are returned in the order of their rows, with the first error if any.
    pub(crate) fn from_planes<F>(
        g: &Grid,
        make: &(dyn Fn(u32) -> F + Sync),
    ) -> Result<(Tiles<V>, Vec<F>), F::Error>
    where
        F: PlaneFill<V> + Send,
        F::Error: Send,
    {
        let (nti, npi, nto, npo) = (g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o);
        let per_row = tiles_per_row(npo);
        let per_ti = npi as usize * nto as usize * per_row;
        let rows_i = nti as usize + 1;
        let count = rows_i * per_ti;
        let mut tiles: Vec<Tile<V>> = Vec::with_capacity(count);
        huge_pages(&tiles);
        // Column of the plane each tile column shows (beyond the copied column `npo`, never
        // read: any node; the column modulo `npo`).
        let cols: Vec<usize> = (0..per_row * TILE_COLUMNS)
            .map(|k| (TILE_STEP * (k / TILE_COLUMNS) + k % TILE_COLUMNS) % npo as usize)
            .collect();
        let fill_rows = |first: usize,
                         out: &mut [std::mem::MaybeUninit<Tile<V>>]|
         -> (F, Result<(), F::Error>) {
            let mut fill = make(first as u32);
            let mut plane = vec![[V::default(); LANES]; (nto as usize + 1) * npo as usize];
            let mut at = 0;
            for ri in first..first + out.len() / per_ti.max(1) {
                for pi in 0..npi {
                    if let Err(e) = fill.fill(ri as u32, pi, &mut plane) {
                        return (fill, Err(e));
                    }
                    for c in 0..nto as usize {
                        let rows = &plane[c * npo as usize..(c + 2) * npo as usize];
                        for e in 0..per_row {
                            let mut t = [V::default(); TILE];
                            for (k, half) in t.chunks_exact_mut(TILE_ROW).enumerate() {
                                let row = &rows[k * npo as usize..(k + 1) * npo as usize];
                                for (j, x) in half.chunks_exact_mut(LANES).enumerate() {
                                    x.copy_from_slice(&row[cols[TILE_COLUMNS * e + j]]);
                                }
                            }
                            out[at].write(Tile(t));
                            at += 1;
                        }
                    }
                }
            }
            debug_assert_eq!(at, out.len());
            (fill, Ok(()))
        };
        let spare = &mut tiles.spare_capacity_mut()[..count];
        // Two halves of the theta_i rows where there is enough work to share.
        let split = if count >= 1 << 16 && rows_i >= 4 {
            rows_i / 2
        } else {
            rows_i
        };
        let (low, high) = spare.split_at_mut(split * per_ti);
        let mut fillers = Vec::with_capacity(2);
        if high.is_empty() {
            let (f, r) = fill_rows(0, low);
            r?;
            fillers.push(f);
        } else {
            let (a, b) = std::thread::scope(|s| {
                let b = s.spawn(|| fill_rows(split, high));
                let a = fill_rows(0, low);
                (a, b.join())
            });
            let b = match b {
                Ok(b) => b,
                Err(panic) => std::panic::resume_unwind(panic),
            };
            a.1?;
            b.1?;
            fillers.extend([a.0, b.0]);
        }
        // SAFETY: both fillers succeeded, so `fill_rows` wrote every one of the `count` tiles
        // (each (ri, pi, c, e) once, in order, the halves covering the theta_i rows 0..split
        // and split..rows_i).
        unsafe { tiles.set_len(count) };
        Ok((Tiles { tiles }, fillers))
    }
}

/// Asks the operating system to back the capacity of `v` with huge pages where it can (Linux:
/// `madvise(MADV_HUGEPAGE)` on the whole pages inside it, before they are first touched): a
/// random lookup's 4 pages then cost no page walk from memory. A hint: no effect on any value,
/// and none at all where transparent huge pages are off or the call fails.
pub(crate) fn huge_pages<T>(v: &Vec<T>) {
    #[cfg(target_os = "linux")]
    {
        const PAGE: usize = 4096;
        let start = v.as_ptr() as usize;
        let end = start + v.capacity() * size_of::<T>();
        let first = start.next_multiple_of(PAGE);
        if end > first + PAGE {
            let len = (end - first) / PAGE * PAGE;
            // SAFETY: [first, first + len) lies inside the allocation of `v`, which this process
            // owns; MADV_HUGEPAGE changes how the pages are backed, never their contents.
            unsafe {
                libc::madvise(first as *mut libc::c_void, len, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}

impl<V> std::ops::Deref for Tiles<V> {
    type Target = [V];

    fn deref(&self) -> &[V] {
        // SAFETY: a `Tile<V>` is `repr(C)` around `[V; TILE]`, whose size (64 or 128 bytes) is
        // a multiple of its alignment (64): no padding, so the tiles are `TILE * len`
        // consecutive, initialised `V`s, borrowed with `self`.
        unsafe {
            std::slice::from_raw_parts(self.tiles.as_ptr().cast::<V>(), self.tiles.len() * TILE)
        }
    }
}

mod sealed {
    /// Implemented for the lane types only: [`super::Lane`] cannot be implemented elsewhere.
    pub trait Sealed {}
    impl Sealed for half::f16 {}
    impl Sealed for f32 {}
}

/// The type of the padded table's lanes, [`f16`] or `f32`: the type alone picks how the
/// lookups widen and load them. Sealed: implemented for those two only.
pub(crate) trait Lane: Copy + sealed::Sealed {
    /// The lane as f32 (exact).
    fn widen(self) -> f32;

    /// The 8 lanes of a run widened to f32 in one register: F16C's conversion of 8 halves,
    /// or one load of 8 floats.
    ///
    /// # Safety
    /// The processor must have AVX2, FMA and F16C.
    #[cfg(target_arch = "x86_64")]
    unsafe fn load8(run: &[Self; 8]) -> __m256;

    /// `values`' tiles when they are of this lane type.
    fn tiles(values: &Values) -> Option<&Tiles<Self>>;
}

impl Lane for f16 {
    #[inline(always)]
    fn widen(self) -> f32 {
        f16_to_f32(self.to_bits())
    }

    #[cfg(target_arch = "x86_64")]
    #[inline]
    #[target_feature(enable = "avx2,fma,f16c")]
    unsafe fn load8(run: &[f16; 8]) -> __m256 {
        // 16 bytes, unaligned: the 8 halves of `run`.
        _mm256_cvtph_ps(_mm_loadu_si128(run.as_ptr().cast::<__m128i>()))
    }

    #[inline(always)]
    fn tiles(values: &Values) -> Option<&Tiles<f16>> {
        match values {
            Values::F16(t) => Some(t),
            Values::F32(_) => None,
        }
    }
}

impl Lane for f32 {
    #[inline(always)]
    fn widen(self) -> f32 {
        self
    }

    #[cfg(target_arch = "x86_64")]
    #[inline]
    #[target_feature(enable = "avx2,fma,f16c")]
    unsafe fn load8(run: &[f32; 8]) -> __m256 {
        // 32 bytes, unaligned: the 8 floats of `run`.
        _mm256_loadu_ps(run.as_ptr())
    }

    #[inline(always)]
    fn tiles(values: &Values) -> Option<&Tiles<f32>> {
        match values {
            Values::F32(t) => Some(t),
            Values::F16(_) => None,
        }
    }
}

/// The tiled table and the constants of its lookups.
#[derive(Clone, Debug)]
pub(crate) struct Nodes {
    pub(crate) values: Values,
    /// Strides (in lanes) of theta_i rows, phi_i columns and theta_o tiles (see the module
    /// documentation; phi_o's offsets are [`column_offset`]).
    pub(crate) strides: [usize; 3],
    /// `s_ti + TILE_ROW + 8`: lanes from the start of a lookup's first run at one `phi_i`
    /// column to the end of its last.
    extent: usize,
    /// Cells per radian of the four axes (theta_i, phi_i, theta_o, phi_o):
    /// [`Axis::cells_per_radian`].
    pub(crate) scale: [f32; 4],
    /// Cells on the four axes.
    pub(crate) n: [u32; 4],
    /// Per-axis constants of the vector kernels' spans.
    pub(crate) lanes: SpanLanes,
}

/// Constants of the spans of the four axes, one lane each (theta_i, phi_i, theta_o, phi_o):
/// the AVX2 kernel's form of the axes' [`Axis::lookup_node`] ([`Axis::lookup_lines`]).
#[derive(Clone, Debug)]
#[cfg_attr(not(target_arch = "x86_64"), allow(dead_code))] // read by the AVX2 kernel only
pub(crate) struct SpanLanes {
    /// Position in cells of an angle `a`: `min(a k1 + b1, a k2 + b2)` per lane (see
    /// [`Axis::lookup_lines`]).
    pub(crate) k1: [f32; 4],
    /// See [`SpanLanes::k1`].
    pub(crate) b1: [f32; 4],
    /// See [`SpanLanes::k1`].
    pub(crate) k2: [f32; 4],
    /// See [`SpanLanes::k1`].
    pub(crate) b2: [f32; 4],
    /// The `atan` coefficients ([`crate::angles::ATAN_COEFFS`]) times `k1` (`[j]` for `c_j`),
    /// so that the polynomial gives the angle in cells directly.
    pub(crate) c1: [[f32; 4]; 6],
    /// The `atan` coefficients times `k2`.
    pub(crate) c2: [[f32; 4]; 6],
    /// Largest position: `n` (polar: hold the last ring), `2 n` (azimuth).
    pub(crate) cap: [f32; 4],
    /// Largest low index before the wrap: `cap - 1`.
    pub(crate) top: [i32; 4],
    /// Cells.
    pub(crate) n: [i32; 4],
    /// True when every axis has at most 2^22 cells, so that these constants and every
    /// position in cells are exact in `f32` and `i32` (a larger axis uses the portable kernel).
    pub(crate) exact: bool,
}

impl SpanLanes {
    /// The constants of the four axes (theta_i, phi_i, theta_o, phi_o).
    fn new(axes: [Axis; 4]) -> SpanLanes {
        let lines = axes.map(Axis::lookup_lines);
        let k1 = lines.map(|l| l.k1);
        let k2 = lines.map(|l| l.k2);
        let coef = |m: [f32; 4]| std::array::from_fn(|j| m.map(|m| ATAN_COEFFS[j] * m));
        SpanLanes {
            k1,
            b1: lines.map(|l| l.b1),
            k2,
            b2: lines.map(|l| l.b2),
            c1: coef(k1),
            c2: coef(k2),
            cap: lines.map(|l| l.cap),
            top: lines.map(|l| l.top),
            n: axes.map(|a| a.count() as i32),
            exact: axes.iter().all(|a| a.count() <= 1 << 22),
        }
    }
}

/// Where one lookup falls: the first lane of its first run and the blend weights.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Corner {
    /// First lanes of runs 0 and 2 (the low and high `phi_i` columns).
    pub(crate) base: [usize; 2],
    /// Weight of run `r = 4 ia + 2 ib + ic` (offset `ia s_ti + ib s_pi + ic s_to`): the
    /// product of the theta_i, phi_i and theta_o weights.
    pub(crate) w: [f32; 8],
    /// Weight of the second phi_o node of each run.
    pub(crate) t_po: f32,
}

impl Nodes {
    /// The padded table of `g` from `node(polar row i, phi_i, polar row o, phi_o)` (rows as in
    /// the module documentation), widened or narrowed by `f16`; the fourth lane 0.
    #[cfg(test)]
    pub(crate) fn new(
        g: &Grid,
        node: &(dyn Fn(u32, u32, u32, u32) -> [f32; 3] + Sync),
        f16: bool,
    ) -> Nodes {
        Nodes::new4(
            g,
            &|a, b, c, d| {
                let [r, g, b] = node(a, b, c, d);
                [r, g, b, 0.0]
            },
            f16,
        )
    }

    /// As [`Nodes::new`] with all four lanes given (a spatial table's two classes a node).
    pub(crate) fn new4(
        g: &Grid,
        node: &(dyn Fn(u32, u32, u32, u32) -> [f32; 4] + Sync),
        f16: bool,
    ) -> Nodes {
        Nodes::with_values(
            g,
            if f16 {
                Values::F16(Tiles::of(g, node, f16::from_f32))
            } else {
                Values::F32(Tiles::of(g, node, |x| x))
            },
        )
    }

    /// The constants of `g`'s lookups with `values`, tiles of `g` ([`Tiles::from_rows`]).
    pub(crate) fn with_values(g: &Grid, values: Values) -> Nodes {
        let mut nodes = Nodes::empty(g);
        nodes.values = values;
        debug_assert_eq!(nodes.len(), nodes.strides[0] * (g.n_theta_i as usize + 1));
        nodes
    }

    /// The lanes R, G, B of table cell `(ti, pi, to, po)` widened to f32 (exact): node
    /// `(ti + 1, pi, to + 1, po)` of the tiles, where the lookups read it.
    pub(crate) fn cell(&self, ti: u32, pi: u32, to: u32, po: u32) -> [f32; 3] {
        let [s_ti, s_pi, s_to] = self.strides;
        // Polar row `to + 1` is the second row of tile `to`.
        let at = (ti as usize + 1) * s_ti
            + pi as usize * s_pi
            + to as usize * s_to
            + TILE_ROW
            + column_offset(po as usize);
        fn rgb<V: Lane>(v: &[V], at: usize) -> [f32; 3] {
            std::array::from_fn(|k| v[at + k].widen())
        }
        match &self.values {
            Values::F16(v) => rgb(v, at),
            Values::F32(v) => rgb(v, at),
        }
    }

    /// The constants of `g`'s lookups, with no values (every lookup out of range).
    pub(crate) fn empty(g: &Grid) -> Nodes {
        let (nti, npi, nto, npo) = (g.n_theta_i, g.n_phi_i, g.n_theta_o, g.n_phi_o);
        let s_to = TILE * tiles_per_row(npo);
        let s_pi = s_to * nto as usize;
        let s_ti = s_pi * npi as usize;
        let axes = g.axes();
        let scale = axes.map(Axis::cells_per_radian);
        Nodes {
            values: Values::F32(Tiles { tiles: Vec::new() }),
            strides: [s_ti, s_pi, s_to],
            extent: s_ti + TILE_ROW + 2 * LANES,
            scale,
            n: [nti, npi, nto, npo],
            lanes: SpanLanes::new(axes),
        }
    }

    /// Number of lanes held.
    pub(crate) fn len(&self) -> usize {
        match &self.values {
            Values::F16(v) => v.len(),
            Values::F32(v) => v.len(),
        }
    }

    /// `f` of the 8 runs of a lookup whose runs at the low and high `phi_i` columns start at
    /// lanes `base[0]` and `base[1]`: run `r = 4 ia + 2 ib + ic` is the 8 lanes of `v` from
    /// `base[ib] + ia s_ti + ic TILE_ROW`, borrowed from `v`. `None`, without calling `f`, when
    /// they would not all lie inside `v` (never for a [`Corner`] of this table: see the module
    /// documentation). One bounds check for all 8.
    ///
    /// The runs go to `f` rather than out in an `Option`: that `Option`'s `None` would be a
    /// null first reference, which the compiler cannot rule out and would test on every lookup.
    #[inline(always)]
    pub(crate) fn with_runs<'v, V, R>(
        &self,
        v: &'v [V],
        base: [usize; 2],
        f: impl FnOnce([&'v [V; 8]; 8]) -> R,
    ) -> Option<R> {
        match v.len().checked_sub(self.extent) {
            Some(last) if base[0] <= last && base[1] <= last => {}
            _ => return None,
        }
        let [s_ti, _, _] = self.strides;
        let s_to = TILE_ROW;
        let p = v.as_ptr();
        let [b0, b1] = base;
        // SAFETY: b + s_ti + TILE_ROW + 8 <= v.len() for both bases (checked above, as
        // b <= v.len() - extent, without overflow), and every start below is at most
        // b + s_ti + TILE_ROW, so each run of 8 lies inside `v`; a `[V; 8]` has the alignment
        // of `V`, and the runs borrow `v`.
        let run = |at: usize| unsafe { &*p.add(at).cast::<[V; 8]>() };
        Some(f([
            run(b0),
            run(b0 + s_to),
            run(b1),
            run(b1 + s_to),
            run(b0 + s_ti),
            run(b0 + s_ti + s_to),
            run(b1 + s_ti),
            run(b1 + s_ti + s_to),
        ]))
    }

    /// Asks the processor to bring the runs of a lookup at `base` into the caches (a hint with
    /// no effect on any value): for each `(ia, ib)` the line of its f16 tile, or the first lane
    /// of its first run and the last of its second, an f32 tile's two lines. The addresses are
    /// formed with wrapping arithmetic and a prefetch never faults, so no bound is checked.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    pub(crate) fn prefetch<V>(&self, v: &[V], base: [usize; 2]) {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        let [s_ti, _, _] = self.strides;
        let p = v.as_ptr();
        // An f16 tile is one aligned line (its first lane suffices); an f32 tile is two.
        let two_lines = !one_line_tiles::<V>();
        for b in base {
            for at in [b, b + s_ti] {
                // SAFETY: a prefetch reads nothing the program sees and never faults, whatever
                // the address; the pointer is not dereferenced.
                unsafe { _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(at).cast::<i8>()) };
                if two_lines {
                    // SAFETY: as above.
                    unsafe {
                        _mm_prefetch::<_MM_HINT_T0>(p.wrapping_add(at + TILE_ROW + 7).cast::<i8>())
                    };
                }
            }
        }
    }

    /// The four axes of the lookups, theta_i, phi_i, theta_o, phi_o (their spans known here,
    /// so that each axis's rule is inlined without a branch on it).
    #[inline(always)]
    pub(crate) fn axes(&self) -> [Axis; 4] {
        let n = self.n;
        [
            Axis::polar(n[0]),
            Axis::azimuth(n[1]),
            Axis::polar(n[2]),
            Axis::azimuth(n[3]),
        ]
    }

    /// The corner of a lookup at angles `[theta_i, phi_i, theta_o, phi_o]`, radians (phi in
    /// `[-pi, 2 pi)`), with the rules of the lookup module: each axis's
    /// [`Axis::lookup_node`] (the polar ones padded with the pole node).
    #[inline(always)]
    pub(crate) fn corner(&self, ang: [f32; 4]) -> Corner {
        let [a, b, c, d] = self.axes();
        let (lo_a, ta) = a.lookup_node(ang[0] * self.scale[0]);
        let (lo_b, tb) = b.lookup_node(ang[1] * self.scale[1]);
        let (lo_c, tc) = c.lookup_node(ang[2] * self.scale[2]);
        let (lo_d, td) = d.lookup_node(ang[3] * self.scale[3]);
        let [s_ti, s_pi, s_to] = self.strides;
        let common = lo_a as usize * s_ti + lo_c as usize * s_to + column_offset(lo_d as usize);
        let base = [
            common + lo_b as usize * s_pi,
            common + next_column(lo_b, self.n[1]) as usize * s_pi,
        ];
        let (wa, wb, wc) = ([1.0 - ta, ta], [1.0 - tb, tb], [1.0 - tc, tc]);
        let w = std::array::from_fn(|r| wa[r >> 2] * wb[(r >> 1) & 1] * wc[r & 1]);
        Corner { base, w, t_po: td }
    }

    /// The portable quadrilinear blend at `ang` (see [`Nodes::corner`]) of the values `v`.
    #[inline(always)]
    pub(crate) fn blend<V: Lane>(&self, v: &[V], ang: [f32; 4]) -> [f32; 3] {
        let [r, g, b, _] = self.blend4(v, ang);
        [r, g, b]
    }

    /// [`Nodes::blend`] of all four lanes.
    #[inline(always)]
    pub(crate) fn blend4<V: Lane>(&self, v: &[V], ang: [f32; 4]) -> [f32; 4] {
        let k = self.corner(ang);
        let sum = self.with_runs(
            v,
            k.base,
            #[inline(always)]
            |runs| {
                let mut acc = [0f32; 8];
                for (run, w) in runs.into_iter().zip(k.w) {
                    for (a, x) in acc.iter_mut().zip(run) {
                        *a += x.widen() * w;
                    }
                }
                acc
            },
        );
        let Some(acc) = sum else {
            return [0.0; 4];
        };
        let (u, t) = (1.0 - k.t_po, k.t_po);
        [
            acc[0] * u + acc[4] * t,
            acc[1] * u + acc[5] * t,
            acc[2] * u + acc[6] * t,
            acc[3] * u + acc[7] * t,
        ]
    }
}

/// The `phi_i` column after `lo` of `n`, periodic.
#[inline(always)]
pub(crate) fn next_column(lo: u32, n: u32) -> u32 {
    if lo + 1 >= n {
        0
    } else {
        lo + 1
    }
}

/// Polar angles and azimuths `[theta_i, phi_i, theta_o, phi_o]` (radians) of two directions,
/// portable (the fast [`atan2`] four times).
#[inline(always)]
pub(crate) fn angles(wi: [f32; 3], wo: [f32; 3]) -> [f32; 4] {
    let rho = |w: [f32; 3]| (w[0] * w[0] + w[1] * w[1]).sqrt();
    let y = [rho(wi), wi[1], rho(wo), wo[1]];
    let x = [wi[2], wi[0], wo[2], wo[0]];
    std::array::from_fn(|k| atan2(y[k], x[k]))
}

/// The signs that mirror a pair's lanes in the AVX2 kernel's `octant_mirrored`: `x` for
/// `[z_i, x_i, z_o, x_o]`, `a` for `[x_i, y_i, x_o, y_o]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct MirrorLanes {
    pub(crate) x: [f32; 4],
    pub(crate) a: [f32; 4],
}

impl MirrorLanes {
    /// The lanes of a mirror whose factors of x and y are `[sx, sy]` (each +-1).
    pub(crate) fn new([sx, sy]: [f32; 2]) -> MirrorLanes {
        MirrorLanes {
            x: [1.0, sx, 1.0, sx],
            a: [sx, sy, sx, sy],
        }
    }

    /// The factors of x and y.
    pub(crate) fn signs(&self) -> [f32; 2] {
        [self.a[0], self.a[1]]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn runs_are_the_lanes_at_their_offsets_or_none() {
        let g = Grid::new(2, 3, 4, 5);
        let node = |a: u32, b: u32, c: u32, d: u32| [a as f32, b as f32, (10 * c + d) as f32];
        let nodes = Nodes::new(&g, &node, false);
        let Values::F32(v) = &nodes.values else {
            panic!("f32 lanes")
        };
        let [s_ti, _, _] = nodes.strides;
        let s_to = TILE_ROW;
        let last = v.len() - (s_ti + s_to + 8);
        for [b0, b1] in [[0, 0], [last, 0], [3, last], [last, last]] {
            let runs = nodes.with_runs(v, [b0, b1], |r| r.map(|x| *x)).unwrap();
            let starts = [
                b0,
                b0 + s_to,
                b1,
                b1 + s_to,
                b0 + s_ti,
                b0 + s_ti + s_to,
                b1 + s_ti,
                b1 + s_ti + s_to,
            ];
            for (run, s) in runs.iter().zip(starts) {
                assert_eq!(run[..], v[s..s + 8], "base {b0}, {b1}");
            }
        }
        for base in [[last + 1, 0], [0, last + 1], [usize::MAX, 0]] {
            assert!(nodes.with_runs(v, base, |_| ()).is_none(), "{base:?}");
        }
        assert!(nodes.with_runs(&v[..s_ti], [0, 0], |_| ()).is_none());
    }

    #[test]
    fn lanes_widen_and_load_exactly() {
        let xs = [0.0f32, -0.0, 1.5, -65504.0, 6.1e-5, 3e-8, 0.1, 1e4];
        let halves = xs.map(f16::from_f32);
        for h in halves {
            assert_eq!(h.widen().to_bits(), h.to_f32().to_bits());
        }
        #[cfg(target_arch = "x86_64")]
        if crate::avx2::available() {
            let mut got = [[0f32; 8]; 2];
            // SAFETY: AVX2, FMA and F16C were detected.
            unsafe {
                use std::arch::x86_64::_mm256_storeu_ps;
                _mm256_storeu_ps(got[0].as_mut_ptr(), f16::load8(&halves));
                _mm256_storeu_ps(got[1].as_mut_ptr(), f32::load8(&xs));
            }
            assert_eq!(
                got[0].map(f32::to_bits),
                halves.map(|h| h.to_f32().to_bits())
            );
            assert_eq!(got[1].map(f32::to_bits), xs.map(f32::to_bits));
        }
    }

    /// The distinct 64-byte cache lines the runs of a lookup at `ang` touch.
    fn lines_of<V: Lane>(nodes: &Nodes, v: &[V], ang: [f32; 4]) -> Vec<usize> {
        let k = nodes.corner(ang);
        let mut lines: Vec<usize> = nodes
            .with_runs(v, k.base, |runs| {
                runs.iter()
                    .flat_map(|r| {
                        let start = r.as_ptr() as usize;
                        [start / 64, (start + size_of::<[V; 8]>() - 1) / 64]
                    })
                    .collect()
            })
            .expect("a lookup of the table");
        lines.sort_unstable();
        lines.dedup();
        lines
    }

    /// Uniform numbers in [0, 1) from a 64-bit LCG seeded with `seed`.
    fn uniform(seed: u64) -> impl FnMut() -> f32 {
        let mut state = seed;
        move || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn a_lookup_reads_few_cache_lines() {
        // The default grid; random angles over the whole domain (azimuths over [-pi, 2 pi)).
        let g = Grid::new(32, 64, 32, 64);
        let mut next = uniform(1);
        let pi = std::f32::consts::PI;
        let angles: Vec<[f32; 4]> = (0..100_000)
            .map(|_| {
                [
                    next() * pi / 2.0,
                    next() * 3.0 * pi - pi,
                    next() * pi / 2.0,
                    next() * 3.0 * pi - pi,
                ]
            })
            .collect();
        for f16 in [true, false] {
            let nodes = Nodes::new(
                &g,
                &|a, b, c, d| [a as f32, b as f32, (c * 100 + d) as f32],
                f16,
            );
            let (mut total, mut most) = (0, 0);
            for &a in &angles {
                let n = match &nodes.values {
                    Values::F16(v) => lines_of(&nodes, v, a).len(),
                    Values::F32(v) => lines_of(&nodes, v, a).len(),
                };
                total += n;
                most = most.max(n);
            }
            let mean = total as f64 / angles.len() as f64;
            eprintln!("f16 {f16}: {mean:.3} cache lines a lookup on average, at most {most}");
            // Halves: one line per (theta_i, phi_i) neighbour; floats: two.
            assert!(most <= if f16 { 4 } else { 8 }, "{most} lines");
        }
    }

    #[test]
    fn the_tiles_blend_as_the_plain_grid_bit_for_bit() {
        // The blend written straight from the node function (no layout): the corner's rules,
        // the 16 nodes by their indices, summed in the kernel's order.
        let mut next = uniform(5);
        let node = |a: u32, b: u32, c: u32, d: u32| {
            let x = (a * 7919 + b * 104_729 + c * 31 + d * 1009) as f32;
            [
                (x * 0.37).sin().abs(),
                (x * 0.11).cos().abs(),
                1.0 + (x * 0.7).sin(),
                0.5,
            ]
        };
        let pi = std::f32::consts::PI;
        for n in [
            [32, 64, 32, 64],
            [5, 7, 4, 9],
            [1, 1, 1, 1],
            [3, 2, 2, 3],
            [2, 3, 1, 4],
        ] {
            let g = Grid::new(n[0], n[1], n[2], n[3]);
            for f16 in [true, false] {
                let nodes = Nodes::new4(&g, &node, f16);
                let stored = |a, b, c, d| {
                    let v = node(a, b, c, d);
                    if f16 {
                        v.map(|x| f16::from_f32(x).to_f32())
                    } else {
                        v
                    }
                };
                for _ in 0..20_000 {
                    let ang = [
                        next() * pi / 2.0,
                        next() * 3.0 * pi - pi,
                        next() * pi / 2.0,
                        next() * 3.0 * pi - pi,
                    ];
                    let got = match &nodes.values {
                        Values::F16(v) => nodes.blend4(v, ang),
                        Values::F32(v) => nodes.blend4(v, ang),
                    };
                    let (a, ta) = g.theta_i().lookup_node(ang[0] * nodes.scale[0]);
                    let (b, tb) = g.phi_i().lookup_node(ang[1] * nodes.scale[1]);
                    let (c, tc) = g.theta_o().lookup_node(ang[2] * nodes.scale[2]);
                    let (d, td) = g.phi_o().lookup_node(ang[3] * nodes.scale[3]);
                    let bs = [b, next_column(b, n[1])];
                    let (wa, wb, wc) = ([1.0 - ta, ta], [1.0 - tb, tb], [1.0 - tc, tc]);
                    let mut acc = [0f32; 8];
                    for r in 0..8 {
                        let (ia, ib, ic) = (r >> 2, (r >> 1) & 1, r & 1);
                        let w = wa[ia] * wb[ib] * wc[ic];
                        for id in 0..2usize {
                            let po = (d + id as u32) % n[3];
                            let v = stored(a + ia as u32, bs[ib], c + ic as u32, po);
                            for k in 0..4 {
                                acc[4 * id + k] += v[k] * w;
                            }
                        }
                    }
                    let want: [f32; 4] =
                        std::array::from_fn(|k| acc[k] * (1.0 - td) + acc[4 + k] * td);
                    assert_eq!(
                        got.map(f32::to_bits),
                        want.map(f32::to_bits),
                        "{n:?} {ang:?}"
                    );
                }
            }
        }
    }
}
