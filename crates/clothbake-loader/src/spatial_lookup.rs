//! The render-time lookup of a spatially varying table ([`SpatialLookup`]) at a point of the
//! period through a footprint: its classes' values held in node tables of the averaged
//! lookup's kind, the cell of a point found from uniform bins, classes that are mirror images
//! of others held once, and each class's coverage interpolated over the outgoing directions.
//! The layout it reads is [`crate::spatial`]'s (docs/science/spatial.md).

use crate::angles::{above_horizon, has_value, theta_phi};
#[cfg(target_arch = "x86_64")]
use crate::avx2;
use crate::axis::Span;
use crate::grid::Grid;
use crate::nodes::{Lane, MirrorLanes, Nodes, Values};
use crate::padding::pad4;
use crate::simd::SimdPath;
use crate::spatial::Spatial;
use crate::stored::Samples;
use clothbake_bsdf::Footprint;

/// A unit direction as (theta, phi) in degrees, by the averaged lookup's rules: `None` at or
/// below the horizon (z <= [`crate::HORIZON_COS`]) or not a number.
fn angles(w: [f32; 3]) -> Option<(f32, f32)> {
    if w.iter().any(|x| x.is_nan()) || !above_horizon(w) {
        return None;
    }
    let (theta, phi) = theta_phi(w);
    let phi = phi.to_degrees();
    // atan2's (-180, 180] onto the azimuth axes' span, [0, 360).
    let turn = Span::Turn.degrees_f32();
    Some((theta.to_degrees(), if phi < 0.0 { phi + turn } else { phi }))
}

/// The classes' values of a spatial table and its layout, for lookups at a point of the period.
///
/// The classes are held two to a node table of the averaged lookup's kind (`crate::nodes`, its
/// padding, pole rows and kernels), two lanes to a slot and two slots to a table: each stored
/// class's (D, S) and, with the second bounce, each of its sides that has a neighbour (N, B),
/// slot after slot; without the second bounce lanes (D, S) of class 2 m and of class 2 m + 1,
/// so that a point lookup costs one averaged lookup and the cell's location.
#[derive(Clone, Debug)]
pub struct SpatialLookup {
    layout: Spatial,
    grid: Grid,
    /// Where each class is held: its stored class, its slots and the mirror onto it.
    classes: Vec<Held>,
    /// The node tables of the slots, two slots each.
    tables: Vec<Nodes>,
    /// A point's cell along u and along v, found without a search.
    u_bins: Bins,
    v_bins: Bins,
    /// Cells along u.
    columns: usize,
    /// Whether both axes' bins split their cells ([`Bins::split`]).
    split: bool,
    /// What a point lookup reads of each cell (row-major), in one place.
    points: Vec<PointCell>,
    /// Whether the node tables hold half floats.
    f16: bool,
}

/// Two lanes of the node tables: lanes `lane` (0 or 2) and `lane + 1` of table `table`
/// ([`NO_TABLE`]: none).
#[derive(Clone, Copy, Debug)]
struct Slot {
    table: u32,
    lane: u32,
}

/// [`Slot::table`] of a slot that is not held (a side without a neighbour).
const NO_TABLE: u32 = u32::MAX;

impl Slot {
    /// Slot `q` of the tables: table `q / 2`, lanes `2 (q % 2)` and the next.
    fn at(q: usize) -> Slot {
        Slot {
            table: (q / 2) as u32,
            lane: 2 * (q % 2) as u32,
        }
    }

    const NONE: Slot = Slot {
        table: NO_TABLE,
        lane: 0,
    };
}

/// Where a class is held: stored class `stored`, its D and S in slot `direct` and, with the
/// second bounce, its +c and -c side terms (N, B) in `sides` (in the stored class's order of
/// sides: a mirror that exchanges the neighbours is taken care of by the cells' records),
/// read at the directions mirrored by `sign`.
#[derive(Clone, Copy, Debug)]
struct Held {
    stored: u32,
    direct: Slot,
    sides: [Slot; 2],
    /// The mirror's factors (+-1) of x and y ([`mirror_signs`]), as the kernels apply them.
    mirror: MirrorLanes,
}

impl Held {
    /// Whether either side has terms.
    #[inline(always)]
    fn has_sides(&self) -> bool {
        (self.sides[0].table & self.sides[1].table) != NO_TABLE
    }
}

/// A point lookup's view of one cell: where its class is held, its thread's albedo and, with
/// the second bounce, its neighbours' in the order of the stored class's sides (exchanged
/// when the class is held as a mirror image that exchanges them).
#[derive(Clone, Copy, Debug)]
struct PointCell {
    held: Held,
    albedo: [f32; 3],
    sides: [[f32; 3]; 2],
}

/// The cell of an axis's `edges` holding a fraction of the period, found from uniform bins
/// instead of a search: the same cell as [`Spatial::locate`] (tested), in few instructions and
/// no unpredictable branches.
///
/// Bin `b` of `n` (a power of two, so that `f n` is exact) holds fractions in [b / n,
/// (b + 1) / n). The bins are made fine enough that none holds more than one edge, so a
/// point's cell is its bin's first cell, or the next one from the bin's split edge on: one
/// comparison. An axis whose cells differ too much in width for that within 2^20 bins walks
/// from the bin's first cell instead.
#[derive(Clone, Debug)]
struct Bins {
    /// The first edge (kept beside the bins for locality).
    e0: f64,
    edges: Vec<f64>,
    /// Bins per period.
    n: f64,
    /// Per bin: the edge from which the point lies in the next cell (infinite when the bin
    /// has none), and the cell holding the bin's start; one more for f = 1 (by rounding), and
    /// copies of that one up to 2 n, so that a bin index masked by `mask` is in bounds.
    bins: Vec<(f64, u32)>,
    /// 2 n - 1.
    mask: usize,
    /// Whether every bin holds at most one edge (else the walk corrects the cell).
    split: bool,
}

/// `x` (finite, in [0, 2^31)) truncated toward zero: one instruction where the saturating
/// `as` takes seven.
#[inline(always)]
fn truncate(x: f64) -> u32 {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_cvttsd_si32, _mm_set_sd};
        // SAFETY: SSE2 is part of every x86_64 processor. Out of range or NaN gives
        // i32::MIN, which the caller's clamp bounds.
        unsafe { _mm_cvttsd_si32(_mm_set_sd(x)) as u32 }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        x as u32
    }
}

/// Most bins an axis may use (the split needs a bin narrower than the narrowest cell).
const MAX_BINS: usize = 1 << 20;

impl Bins {
    fn new(edges: &[f64]) -> Bins {
        let cells = edges.len() - 1;
        let e0 = edges[0];
        // The cell of x = e0 + f, by the search's own rule on the same x the lookup forms.
        let cell = |x: f64| {
            edges
                .partition_point(|&e| e <= x)
                .saturating_sub(1)
                .min(cells - 1)
        };
        let mut n = (4 * cells).max(16).next_power_of_two();
        loop {
            let first: Vec<usize> = (0..=n).map(|b| cell(e0 + b as f64 / n as f64)).collect();
            // A point of bin b lies between its start and the next bin's start (rounding is
            // monotonic), so its cell is first[b] or first[b] + 1 when first[b + 1] is at
            // most that.
            let split = first.windows(2).all(|w| w[1] <= w[0] + 1);
            if split || n >= MAX_BINS {
                let last = first[n];
                let bins = first
                    .iter()
                    .chain(std::iter::repeat_n(&last, n - 1))
                    .map(|&i| {
                        let next = if i + 1 < cells {
                            edges[i + 1]
                        } else {
                            f64::INFINITY
                        };
                        (next, i as u32)
                    })
                    .collect();
                return Bins {
                    e0,
                    edges: edges.to_vec(),
                    n: n as f64,
                    bins,
                    mask: 2 * n - 1,
                    split,
                };
            }
            n *= 2;
        }
    }

    /// The cell holding fraction `t` (wrapped; not finite: 0), as [`Spatial::locate`].
    #[cfg(test)]
    fn locate(&self, t: f64) -> usize {
        self.locate_finite(if t.is_finite() { t } else { 0.0 })
    }

    /// [`Bins::locate`] of a finite `t`.
    #[inline(always)]
    fn locate_finite(&self, t: f64) -> usize {
        let (i, x) = self.bin_cell(t);
        if self.split {
            i
        } else {
            self.walk(i, x)
        }
    }

    /// The cell of finite `t` from its bin alone (right when [`Bins::split`]), and the wrapped
    /// fraction x it was found for.
    #[inline(always)]
    fn bin_cell(&self, t: f64) -> (usize, f64) {
        let e0 = self.e0;
        let d = t - e0;
        let f = d - d.floor();
        let x = e0 + f;
        // f in [0, 1] (1 by rounding): bin n holds f = 1 alone; the mask only keeps any index
        // (a NaN's) in bounds.
        let b = truncate(f * self.n) as usize & self.mask;
        // SAFETY: b <= mask = 2 n - 1 < bins.len() = 2 n (`new`).
        let (next, first) = unsafe { *self.bins.get_unchecked(b) };
        (first as usize + usize::from(x >= next), x)
    }

    /// The cell holding `x` from cell `i` on, by the edges (bins that hold more than one edge),
    /// out of line.
    #[cold]
    #[inline(never)]
    fn walk(&self, mut i: usize, x: f64) -> usize {
        let e = &self.edges;
        let last = e.len() - 2;
        while i > 0 && e[i] > x {
            i -= 1;
        }
        while i < last && e[i + 1] <= x {
            i += 1;
        }
        i
    }
}

/// A mirror of the cloth's frame, as bits: 1 negates x (the weft direction), 2 negates y (the
/// warp direction), 3 both (a half turn about the normal); 0 is none.
type Mirror = u8;

/// The factors (+-1) of x and y of mirror `m`.
fn mirror_signs(m: Mirror) -> [f32; 2] {
    let sign = |bit: Mirror| if m & bit != 0 { -1.0 } else { 1.0 };
    [sign(1), sign(2)]
}

/// `w` with x and y multiplied by `sign` (a mirror's [`mirror_signs`]; exact).
#[inline(always)]
fn flipped(w: [f32; 3], [sx, sy]: [f32; 2]) -> [f32; 3] {
    [w[0] * sx, w[1] * sy, w[2]]
}

/// Lanes `slot.lane` and the next of a table's 4.
#[inline(always)]
fn lanes_of(f: [f32; 4], slot: Slot) -> [f32; 2] {
    // The lane is 0 or 2 (`& 2` lets the compiler drop the bound checks).
    let l = slot.lane as usize & 2;
    [f[l], f[l + 1]]
}

/// The side terms (N+, B+, N-, B-) of the class held at `h`, from `main` (the blend of its
/// direct slot's table) where a side shares that table, else from `blend` of the side's
/// table (once for both sides in one other table); 0 for a side without terms.
#[inline(always)]
fn side_terms(h: &Held, main: [f32; 4], blend: impl Fn(u32) -> [f32; 4]) -> [f32; 4] {
    let mut other: Option<(u32, [f32; 4])> = None;
    let mut out = [0.0; 4];
    for (k, slot) in h.sides.iter().enumerate() {
        let f = match slot.table {
            NO_TABLE => continue,
            t if t == h.direct.table => main,
            t => match other {
                Some((o, f)) if o == t => f,
                _ => {
                    let f = blend(t);
                    other = Some((t, f));
                    f
                }
            },
        };
        let [n, b] = lanes_of(f, *slot);
        out[2 * k] = n;
        out[2 * k + 1] = b;
    }
    out
}

/// A cell's f_r with the second bounce from its class's `d`, `s` and side terms `g` (N+, B+,
/// N-, B-, in the order of `p.sides`): rho D + S + sum_k rho_k (N_k + rho B_k).
#[inline(always)]
fn with_sides(p: &PointCell, d: f32, s: f32, g: [f32; 4]) -> [f32; 3] {
    std::array::from_fn(|c| {
        let a = p.albedo[c];
        let [plus, minus] = p.sides;
        non_negative(a * d + s + plus[c] * (g[0] + a * g[1]) + minus[c] * (g[2] + a * g[3]))
    })
}

/// `x`, or 0 where it is below 0 or NaN (as `x.max(0.0)`, in one instruction on x86-64).
#[inline(always)]
fn non_negative(x: f32) -> f32 {
    if x > 0.0 {
        x
    } else {
        0.0
    }
}

/// `w` mirrored by `m`.
#[cfg(test)]
fn mirrored(w: [f32; 3], m: Mirror) -> [f32; 3] {
    flipped(w, mirror_signs(m))
}

/// The azimuth cell (of `n`) whose centre `m` moves cell `p`'s centre to; `None` for a mirror
/// in x on an odd number of cells, which maps centres between cells.
fn mirrored_cell(p: u32, n: u32, m: Mirror) -> Option<u32> {
    match m {
        0 => Some(p),
        2 => Some(n - 1 - p),
        _ if n % 2 == 1 => None,
        1 => Some((n / 2 + n - 1 - p) % n),
        _ => Some((p + n / 2) % n),
    }
}

/// True when class `c`'s values and visible areas equal class `j`'s mirrored by `m` at every
/// grid cell, to `tol` of the larger (the stored precision: a mirror image evaluates in
/// another order and rounds apart); with `swap`, `c`'s +c side's terms equal `j`'s -c side's
/// and the other way round. Each value compared takes one from `budget`; false once it is
/// spent.
fn mirror_of(
    layout: &Spatial,
    grid: &Grid,
    values: &Samples,
    (c, j, m, swap): (usize, usize, Mirror, bool),
    tol: f32,
    budget: &mut u64,
) -> bool {
    let lanes = layout.lanes();
    // Lane of `j` that `c`'s lane `d` is compared with: sides exchanged by `swap`.
    let other = |d: usize| {
        if swap && d >= 2 {
            2 + (d - 2 + 2) % 4
        } else {
            d
        }
    };
    let n = grid.len();
    let mut close = |a: f32, b: f32| {
        *budget = budget.saturating_sub(1);
        *budget > 0 && (a - b).abs() <= tol * a.abs().max(b.abs()) + 1e-12
    };
    let (npi, npo) = (grid.n_phi_i, grid.n_phi_o);
    let (Some(pi_map), Some(po_map)) = (
        (0..npi)
            .map(|p| mirrored_cell(p, npi, m))
            .collect::<Option<Vec<_>>>(),
        (0..npo)
            .map(|p| mirrored_cell(p, npo, m))
            .collect::<Option<Vec<_>>>(),
    ) else {
        return false;
    };
    let nto = grid.n_theta_o as usize;
    let vis = |k: usize, to: usize, po: usize| layout.visible[(k * nto + to) * npo as usize + po];
    for to in 0..nto {
        for (po, &q) in po_map.iter().enumerate() {
            if !close(vis(c, to, po), vis(j, to, q as usize)) {
                return false;
            }
        }
    }
    for ti in 0..grid.n_theta_i {
        for pi in 0..npi {
            for to in 0..grid.n_theta_o {
                for po in 0..npo {
                    let a = grid.index(ti, pi, to, po);
                    let b = grid.index(ti, pi_map[pi as usize], to, po_map[po as usize]);
                    for d in 0..lanes {
                        if !close(
                            values.get(lanes * (c * n + a) + d),
                            values.get(lanes * (j * n + b) + other(d)),
                        ) {
                            return false;
                        }
                    }
                }
            }
        }
    }
    true
}

/// The classes held, and how every class is held: the stored classes (their index in the
/// table) and, per class, its stored class, mirror and whether the mirror exchanges the +c
/// and -c neighbours (see [`SpatialLookup::new`]); and how many values the search compared.
///
/// A comparison stops at the first difference, but classes that differ only in their last
/// values (a crafted file) would each be compared in full with every stored class: classes^2
/// scans, hours for a large table. So the search compares at most 8 times the classes'
/// values; from there on, classes are held as they are (more memory, the same lookups).
#[allow(clippy::type_complexity)]
fn mirror_images(
    layout: &Spatial,
    grid: &Grid,
    values: &Samples,
) -> ((Vec<usize>, Vec<(usize, Mirror, bool)>), u64) {
    let tol = if matches!(values, Samples::F16(_)) {
        1.5e-3
    } else {
        1e-5
    };
    let start = 8 * (layout.values_len(grid) as u64 + layout.visible.len() as u64);
    let mut budget = start;
    let mut stored: Vec<usize> = Vec::new();
    let mut held: Vec<(usize, Mirror, bool)> = Vec::with_capacity(layout.classes as usize);
    let swaps: &[bool] = if layout.secondary {
        &[false, true]
    } else {
        &[false]
    };
    for c in 0..layout.classes as usize {
        let mut found = None;
        'search: for (s, &j) in stored.iter().enumerate() {
            for m in [1, 2, 3] {
                for &w in swaps {
                    if budget == 0 {
                        break 'search;
                    }
                    if mirror_of(layout, grid, values, (c, j, m, w), tol, &mut budget) {
                        found = Some((s, m, w));
                        break 'search;
                    }
                }
            }
        }
        held.push(found.unwrap_or_else(|| {
            stored.push(c);
            (stored.len() - 1, 0, false)
        }));
    }
    ((stored, held), start - budget)
}

/// What a footprint of the period sees of each class.
struct Seen {
    /// Per class: the summed share of its cells the footprint covers.
    share: Vec<f32>,
    /// Per class: that share times each cell's albedo, summed (RGB).
    albedo: Vec<[f32; 3]>,
    /// With the second bounce, per class and stored side: the share times the neighbour's
    /// albedo, and times both albedos, summed (RGB).
    sides: Vec<[[[f32; 3]; 2]; 2]>,
}

impl SpatialLookup {
    /// The lookup of a table's class values (`values`, as [`Spatial::values_len`] counts them),
    /// held in half floats when `f16`.
    ///
    /// A class that is another's mirror image (a mirror of the frame in x, y or both; e.g. the
    /// basket's two halves of a float), to the stored precision (1.5e-3 of the larger value
    /// for half floats, 1e-5 for floats) at every grid cell, is held once: its lookups read the
    /// other's nodes at the mirrored directions.
    pub(crate) fn new(layout: Spatial, grid: Grid, values: &Samples, f16: bool) -> SpatialLookup {
        debug_assert_eq!(values.len(), layout.values_len(&grid));
        let n = grid.len();
        let (stored, held) = mirror_images(&layout, &grid, values).0;
        // Slots, stored class by stored class: (D, S), then each side with terms (N, B) as
        // (class, its first lane in the values).
        let lanes = layout.lanes();
        let lane = |s: usize, c: usize, j: usize| values.get(lanes * (stored[s] * n + c) + j);
        let mut slots: Vec<(usize, usize)> = Vec::new();
        let mut where_held: Vec<(Slot, [Slot; 2])> = Vec::with_capacity(stored.len());
        for s in 0..stored.len() {
            let direct = Slot::at(slots.len());
            slots.push((s, 0));
            let mut sides = [Slot::NONE; 2];
            if layout.secondary {
                for (k, side) in sides.iter_mut().enumerate() {
                    let j = 2 + 2 * k;
                    if (0..n).any(|c| lane(s, c, j) != 0.0 || lane(s, c, j + 1) != 0.0) {
                        *side = Slot::at(slots.len());
                        slots.push((s, j));
                    }
                }
            }
            where_held.push((direct, sides));
        }
        let tables = slots
            .chunks(2)
            .map(|pair| {
                let at = |q: usize, c: usize, d: usize| {
                    pair.get(q).map_or(0.0, |&(s, j)| lane(s, c, j + d))
                };
                pad4(
                    &grid,
                    &|ti, pi, to, po| {
                        let c = grid.index(ti, pi, to, po);
                        [at(0, c, 0), at(0, c, 1), at(1, c, 0), at(1, c, 1)]
                    },
                    f16,
                )
            })
            .collect();
        let classes: Vec<Held> = held
            .iter()
            .map(|&(s, m, _)| Held {
                stored: s as u32,
                direct: where_held[s].0,
                sides: where_held[s].1,
                mirror: MirrorLanes::new(mirror_signs(m)),
            })
            .collect();
        let (u_bins, v_bins) = (Bins::new(&layout.u_edges), Bins::new(&layout.v_edges));
        let points = (0..layout.cell_class.len())
            .map(|c| {
                let k = layout.cell_class[c] as usize;
                let nb = layout.cell_neighbours.get(c).copied().unwrap_or_default();
                PointCell {
                    held: classes[k],
                    albedo: layout.cell_albedo[c],
                    sides: if held[k].2 { [nb[1], nb[0]] } else { nb },
                }
            })
            .collect();
        SpatialLookup {
            columns: u_bins.edges.len() - 1,
            split: u_bins.split && v_bins.split,
            u_bins,
            v_bins,
            points,
            layout,
            grid,
            classes,
            tables,
            f16,
        }
    }

    /// Number of classes held (after mirror images are shared).
    pub fn stored_classes(&self) -> usize {
        self.classes
            .iter()
            .map(|h| h.stored as usize + 1)
            .max()
            .unwrap_or(0)
    }

    /// The layout.
    pub fn layout(&self) -> &Spatial {
        &self.layout
    }

    /// Bytes held by the class values.
    pub fn memory_bytes(&self) -> usize {
        self.tables
            .iter()
            .map(|p| {
                let lane = match p.values {
                    Values::F16(_) => 2,
                    Values::F32(_) => 4,
                };
                lane * p.len()
            })
            .sum()
    }

    /// The (D, S) of the class held at `h`: its slot's lanes at the mirrored directions,
    /// interpolated as the averaged table is (16 nodes, pole rows), by `simd`'s kernel.
    #[inline(always)]
    fn held_f(&self, simd: SimdPath, h: Held, wi: [f32; 3], wo: [f32; 3]) -> [f32; 2] {
        let sign = h.mirror.signs();
        let (wi, wo) = (flipped(wi, sign), flipped(wo, sign));
        let f = Self::pair_f(&self.tables[h.direct.table as usize], simd, wi, wo);
        lanes_of(f, h.direct)
    }

    /// The (D, S) and the side terms (N+, B+, N-, B-, in the stored class's order of sides)
    /// of the class held at `h`, at the mirrored directions.
    #[inline(always)]
    fn held_all(
        &self,
        simd: SimdPath,
        h: Held,
        wi: [f32; 3],
        wo: [f32; 3],
    ) -> ([f32; 2], [f32; 4]) {
        let sign = h.mirror.signs();
        let (wi, wo) = (flipped(wi, sign), flipped(wo, sign));
        let blend = |t: u32| Self::pair_f(&self.tables[t as usize], simd, wi, wo);
        let main = blend(h.direct.table);
        (lanes_of(main, h.direct), side_terms(&h, main, blend))
    }

    /// A class pair's 4 lanes (D, S of each) at the directions, by `simd`'s kernel.
    #[inline(always)]
    fn pair_f(nodes: &Nodes, simd: SimdPath, wi: [f32; 3], wo: [f32; 3]) -> [f32; 4] {
        match (&nodes.values, simd) {
            // SAFETY: the kernel is AVX2 only when the processor has AVX2, FMA and F16C (the
            // table's `SimdPath`, checked by `Brdf::with_simd_path` and `SimdPath::best`).
            #[cfg(target_arch = "x86_64")]
            (Values::F16(v), SimdPath::Avx2) => unsafe { avx2::eval4(nodes, v, wi, wo) },
            #[cfg(target_arch = "x86_64")]
            (Values::F32(v), SimdPath::Avx2) => unsafe { avx2::eval4(nodes, v, wi, wo) },
            (Values::F16(v), _) => nodes.blend4(v, crate::nodes::angles(wi, wo)),
            (Values::F32(v), _) => nodes.blend4(v, crate::nodes::angles(wi, wo)),
        }
    }

    /// Class `k`'s visible share of the period at outgoing angles `o` (degrees), interpolated
    /// ([`crate::Axis::clamped_taps_deg`]: the visible areas have no pole node).
    fn visible(&self, k: usize, o: (f32, f32)) -> f32 {
        let g = self.grid;
        let (c, d) = (
            g.theta_o().clamped_taps_deg(o.0),
            g.phi_o().clamped_taps_deg(o.1),
        );
        let mut v = 0.0;
        for (to, wc) in c {
            for (po, wd) in d {
                let n = (k * g.n_theta_o as usize + to) * g.n_phi_o as usize + po;
                v += wc * wd * self.layout.visible[n];
            }
        }
        v
    }

    /// What a footprint of side `width` (0 for a point, else in (0, 1)) centred on (u, v)
    /// covers of each class.
    fn seen(&self, u: f64, v: f64, width: f64) -> Seen {
        let l = &self.layout;
        let k = l.classes as usize;
        let mut seen = Seen {
            share: vec![0.0; k],
            albedo: vec![[0.0; 3]; k],
            sides: vec![[[[0.0; 3]; 2]; 2]; if l.secondary { k } else { 0 }],
        };
        for (c, share, _) in self.covered(u, v, width) {
            let class = l.cell_class[c] as usize;
            let w = share as f32;
            seen.share[class] += w;
            for (acc, a) in seen.albedo[class].iter_mut().zip(l.cell_albedo[c]) {
                *acc += w * a;
            }
            if let Some(acc) = seen.sides.get_mut(class) {
                let p = &self.points[c];
                for (acc, nb) in acc.iter_mut().zip(&p.sides) {
                    for ch in 0..3 {
                        acc[0][ch] += w * nb[ch];
                        acc[1][ch] += w * nb[ch] * p.albedo[ch];
                    }
                }
            }
        }
        seen
    }

    /// The side of a crossing cell that the level rule measures footprints in: one over the
    /// larger count of cells along u and along v (as the model's `AnalyticBsdf::cell_width`).
    pub(crate) fn cell_width(&self) -> f64 {
        let (nx, ny) = self.layout.dims();
        1.0 / nx.max(ny).max(1) as f64
    }

    /// Whether this table answers f_r and coverage at (u, v) through a footprint of side
    /// `width` ([`crate::Brdf::eval_at`]): where the level rule asks for less than the period
    /// ([`Footprint::within_period`], the first test of [`Footprint::level`]: below a period,
    /// NaN a point, at a finite point); elsewhere the averaged table answers. Inside the
    /// period the cells answer, or the point level where the table has it (`Brdf`).
    #[inline(always)]
    pub(crate) fn answers(u: f64, v: f64, width: f64) -> bool {
        Footprint { u, v, width }.within_period()
    }

    /// f_r through the footprint, where the table [`answers`](SpatialLookup::answers): the
    /// mean of the covered cells' f_r, each weighted by its covered share times its coverage;
    /// 0 below the horizon. Inline: a point's lookup (one call); footprints out of line. The
    /// directions are used once on each path, so that a caller's are passed on without copies.
    #[inline]
    pub(crate) fn eval_within(
        &self,
        simd: SimdPath,
        wi: [f32; 3],
        wo: [f32; 3],
        u: f64,
        v: f64,
        width: f64,
    ) -> [f32; 3] {
        if width.is_nan() || width <= 0.0 {
            // A point. The AVX2 kernel tells the horizon and NaN itself (D = S = 0 then, and
            // albedos are finite); the portable blend does not.
            return match simd {
                // SAFETY: the kernel is AVX2 only when the processor has AVX2, FMA and F16C
                // (the table's `SimdPath`, as in `pair_f`).
                #[cfg(target_arch = "x86_64")]
                SimdPath::Avx2 if self.f16 => unsafe { self.point_avx2::<half::f16>(wi, wo, u, v) },
                #[cfg(target_arch = "x86_64")]
                SimdPath::Avx2 => unsafe { self.point_avx2::<f32>(wi, wo, u, v) },
                _ => self.point(simd, wi, wo, u, v),
            };
        }
        self.eval_footprint(simd, wi, wo, Footprint { u, v, width })
    }

    /// A point's f_r (u, v finite) by the portable kernel: its cell's `rho_d D + S` and, with
    /// the second bounce, its neighbours' terms (its coverage cancels; where the class is not
    /// seen, all are 0; 0 below the horizon). Out of line: inlined, its registers would be
    /// saved on every AVX2 point lookup too.
    #[inline(never)]
    fn point(&self, simd: SimdPath, wi: [f32; 3], wo: [f32; 3], u: f64, v: f64) -> [f32; 3] {
        if !has_value(wi, wo) {
            return [0.0; 3];
        }
        // `eval_at` passes finite u, v only.
        let p = self.point_cell(u, v);
        if !p.held.has_sides() {
            let [d, s] = self.held_f(simd, p.held, wi, wo);
            return p.albedo.map(|a| non_negative(a * d + s));
        }
        let ([d, s], g) = self.held_all(simd, p.held, wi, wo);
        with_sides(p, d, s, g)
    }

    /// [`SpatialLookup::point`] compiled for AVX2 on lanes `V` (the cell's `floor` one
    /// instruction, the kernel inline: one call site per lane type).
    ///
    /// # Safety
    /// The processor must have AVX2, FMA and F16C.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma,f16c")]
    unsafe fn point_avx2<V: Lane>(&self, wi: [f32; 3], wo: [f32; 3], u: f64, v: f64) -> [f32; 3] {
        let p = self.point_cell(u, v);
        let h = &p.held;
        // SAFETY: every held class's slots name tables that `new` made.
        let nodes = unsafe { self.tables.get_unchecked(h.direct.table as usize) };
        let Some(values) = V::tiles(&nodes.values) else {
            return [0.0; 3];
        };
        let f = avx2::eval4_mirrored(nodes, values, &wi, &wo, &h.mirror);
        let [d, s] = lanes_of(f, h.direct);
        if !h.has_sides() {
            return p.albedo.map(|a| non_negative(a * d + s));
        }
        self.point_sides_avx2::<V>(p, f, &wi, &wo)
    }

    /// The rest of [`SpatialLookup::point_avx2`] for a class with side terms, out of line (so
    /// that the one-bounce lookup keeps its kernel inline): `main` is the blend of the class's
    /// direct slot's table at the class's mirror of `wi`, `wo`.
    ///
    /// # Safety
    /// The processor must have AVX2, FMA and F16C.
    #[cfg(target_arch = "x86_64")]
    #[inline(never)]
    #[target_feature(enable = "avx2,fma,f16c")]
    unsafe fn point_sides_avx2<V: Lane>(
        &self,
        p: &PointCell,
        main: [f32; 4],
        wi: &[f32; 3],
        wo: &[f32; 3],
    ) -> [f32; 3] {
        let blend = |t: u32| {
            let nodes = &self.tables[t as usize];
            match V::tiles(&nodes.values) {
                // SAFETY: as this function's caller guarantees.
                Some(values) => unsafe {
                    avx2::eval4_mirrored(nodes, values, wi, wo, &p.held.mirror)
                },
                None => [0.0; 4],
            }
        };
        let [d, s] = lanes_of(main, p.held.direct);
        with_sides(p, d, s, side_terms(&p.held, main, blend))
    }

    /// The record of the cell holding (u, v) (finite).
    #[inline(always)]
    fn point_cell(&self, u: f64, v: f64) -> &PointCell {
        let (i, j) = if self.split {
            (self.u_bins.bin_cell(u).0, self.v_bins.bin_cell(v).0)
        } else {
            self.walked_cell(u, v)
        };
        let k = j * self.columns + i;
        debug_assert!(k < self.points.len());
        // SAFETY: the bins give i < the cells along u and j < those along v, and `new` makes
        // one record per cell (the layout's cells, checked by `Spatial::validate`).
        unsafe { self.points.get_unchecked(k) }
    }

    /// The cell (along u, along v) holding (u, v) (finite) where an axis's bins do not split
    /// its cells, out of line.
    #[cold]
    #[inline(never)]
    fn walked_cell(&self, u: f64, v: f64) -> (usize, usize) {
        (self.u_bins.locate_finite(u), self.v_bins.locate_finite(v))
    }

    /// [`SpatialLookup::eval_within`] of a footprint whose side is in (0, 1) (0 below the horizon),
    /// out of line.
    #[inline(never)]
    fn eval_footprint(
        &self,
        simd: SimdPath,
        wi: [f32; 3],
        wo: [f32; 3],
        at: Footprint,
    ) -> [f32; 3] {
        let (true, Some(o)) = (has_value(wi, wo), angles(wo)) else {
            return [0.0; 3];
        };
        let seen = self.seen(at.u, at.v, at.width);
        let (mut num, mut den) = ([0.0f32; 3], 0.0f32);
        for (k, (&share, a)) in seen.share.iter().zip(&seen.albedo).enumerate() {
            if share <= 0.0 {
                continue;
            }
            let vis = self.visible(k, o);
            if vis <= 0.0 {
                continue;
            }
            let h = self.classes[k];
            let sides = seen.sides.get(k).filter(|_| h.has_sides());
            // With sides, one call blends the direct slot's table once for both.
            let ([d, s], g) = match sides {
                Some(_) => self.held_all(simd, h, wi, wo),
                None => (self.held_f(simd, h, wi, wo), [0.0; 4]),
            };
            for (n, a) in num.iter_mut().zip(a) {
                *n += vis * (a * d + share * s);
            }
            if let Some(sides) = sides {
                for (ch, n) in num.iter_mut().enumerate() {
                    let [p, m] = sides;
                    *n += vis
                        * (p[0][ch] * g[0] + p[1][ch] * g[1] + m[0][ch] * g[2] + m[1][ch] * g[3]);
                }
            }
            den += vis * share;
        }
        if den > 0.0 {
            num.map(|n| (n / den).max(0.0))
        } else {
            [0.0; 3]
        }
    }

    /// The footprint's coverage: the share of its projected area in which the eye meets yarn
    /// seen from `wo`. `None` where the averaged table answers (as for `Brdf::eval_at`): a
    /// footprint of a whole period or more, a point not finite.
    pub fn coverage_at(&self, wo: [f32; 3], u: f64, v: f64, width: f64) -> Option<f32> {
        if !Self::answers(u, v, width) {
            return None;
        }
        let Some(o) = angles(wo) else {
            return Some(0.0);
        };
        // Each covered cell's area times its coverage (visible share / cell's area share),
        // over the covered area.
        let (mut covered, mut area) = (0.0f64, 0.0f64);
        for (c, share, cell_area) in self.covered(u, v, width.max(0.0)) {
            let k = self.layout.cell_class[c] as usize;
            covered += share * f64::from(self.visible(k, o));
            area += share * cell_area;
        }
        Some(if area > 0.0 {
            (covered / area) as f32
        } else {
            0.0
        })
    }

    /// The cells a footprint of side `width` (0 for a point, else in (0, 1)) centred on (u, v)
    /// covers: row-major index, the share of the cell covered, the cell's share of the period.
    fn covered(&self, u: f64, v: f64, width: f64) -> Vec<(usize, f64, f64)> {
        let l = &self.layout;
        let (nx, _) = l.dims();
        let cell_area = |i: usize, j: usize| {
            (l.u_edges[i + 1] - l.u_edges[i]) * (l.v_edges[j + 1] - l.v_edges[j])
        };
        if width > 0.0 {
            let h = 0.5 * width;
            let (mut xs, mut ys) = (Vec::new(), Vec::new());
            Spatial::overlaps(&l.u_edges, u - h, u + h, &mut xs);
            Spatial::overlaps(&l.v_edges, v - h, v + h, &mut ys);
            let mut out = Vec::with_capacity(xs.len() * ys.len());
            for &(j, wy) in &ys {
                for &(i, wx) in &xs {
                    out.push((j * nx + i, wx * wy, cell_area(i, j)));
                }
            }
            out
        } else {
            let (i, j) = l.cell_at(u, v);
            vec![(j * nx + i, 1.0, cell_area(i, j))]
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::axis::Axis;

    #[test]
    fn bins_find_the_cell_that_the_search_finds() {
        // Uneven cells, points on and beside every edge, outside the period, not finite.
        for inner in [
            vec![0.0],
            vec![-0.2, 0.1, 0.15, 0.5],
            vec![0.05, 0.06, 0.07, 0.5, 1.0],
            (0..37)
                .map(|k| (f64::from(k) / 37.0).powf(1.7) + 0.3)
                .collect(),
            // Cells too narrow for the split within the most bins: the walk.
            vec![0.1, 0.1 + 1e-9, 0.1 + 2e-9, 0.5],
        ] {
            // The last edge one period after the first, as every layout has it.
            let edges: Vec<f64> = inner.iter().copied().chain([inner[0] + 1.0]).collect();
            let bins = Bins::new(&edges);
            assert_eq!(bins.split, inner.len() < 4 || inner[1] - inner[0] > 1e-6);
            let mut ts: Vec<f64> = vec![f64::NAN, f64::INFINITY, -1e300, 1e300, -0.0];
            for &x in &edges {
                for d in [-1e-12, 0.0, 1e-12, -1.0, 1.0, 3.0, -7.0] {
                    ts.push(x + d);
                    ts.push(f64::from_bits((x + d).to_bits().wrapping_add(1)));
                    ts.push(f64::from_bits((x + d).to_bits().wrapping_sub(1)));
                }
            }
            let mut r = 0x9e37_79b9_7f4a_7c15u64;
            for _ in 0..20_000 {
                r ^= r << 13;
                r ^= r >> 7;
                r ^= r << 17;
                ts.push((r >> 11) as f64 / (1u64 << 53) as f64 * 6.0 - 3.0);
            }
            for t in ts {
                assert_eq!(bins.locate(t), Spatial::locate(&edges, t), "{edges:?} {t}");
            }
        }
    }

    /// A one-bounce layout of `classes` classes over 2 x 1 cells, every class seen alike.
    fn layout(classes: u32, grid: &Grid) -> Spatial {
        Spatial {
            classes,
            u_edges: vec![0.0, 0.5, 1.0],
            v_edges: vec![0.0, 1.0],
            cell_class: vec![0, classes - 1],
            cell_albedo: vec![[0.5; 3]; 2],
            visible: vec![0.3; classes as usize * (grid.n_theta_o * grid.n_phi_o) as usize],
            secondary: false,
            cell_neighbours: Vec::new(),
        }
    }

    #[test]
    fn mirror_images_are_found_and_the_search_is_bounded() {
        let grid = Grid::new(2, 4, 2, 4);
        let n = grid.len();
        // Class 1 is class 0 mirrored in y (phi -> -phi), class 2 is neither.
        let l = layout(3, &grid);
        let mut r = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            r ^= r << 13;
            r ^= r >> 7;
            r ^= r << 17;
            (r >> 40) as f32 / (1u64 << 24) as f32 + 0.1
        };
        let c0: Vec<f32> = (0..2 * n).map(|_| next()).collect();
        let mut values = c0.clone();
        for ti in 0..2 {
            for pi in 0..4 {
                for to in 0..2 {
                    for po in 0..4 {
                        let b = grid.index(ti, mirrored_cell(pi, 4, 2).unwrap(), to, {
                            mirrored_cell(po, 4, 2).unwrap()
                        });
                        values.extend_from_slice(&c0[2 * b..2 * b + 2]);
                    }
                }
            }
        }
        values.extend((0..2 * n).map(|_| next()));
        let ((stored, held), _) = mirror_images(&l, &grid, &Samples::F32(values));
        assert_eq!(stored, [0, 2]);
        assert_eq!(held, [(0, 0, false), (0, 2, false), (1, 0, false)]);

        // Classes alike but for their last value (a crafted file): each would be compared
        // nearly in full with every class before it, 256^2 / 2 x 3 mirrors x about 64 values;
        // the search stops at 8 times the values.
        let k = 256u32;
        let l = layout(k, &grid);
        let values: Vec<f32> = (0..k as usize)
            .flat_map(|c| (0..2 * n).map(move |i| if i + 1 == 2 * n { c as f32 } else { 0.5 }))
            .collect();
        let budget = 8 * (values.len() + l.visible.len()) as u64;
        let ((stored, held), compared) = mirror_images(&l, &grid, &Samples::F32(values));
        assert!(compared <= budget, "{compared} values compared");
        assert_eq!(stored.len(), k as usize);
        assert!(held.iter().enumerate().all(|(c, h)| *h == (c, 0, false)));
    }

    #[test]
    fn mirrors_move_cell_centres_onto_cell_centres() {
        // The centre of cell p at (p + 0.5) 360 / n degrees, mirrored as the direction is.
        for n in [1u32, 2, 3, 8, 12, 64] {
            for p in 0..n {
                let phi = Axis::azimuth(n).centre_deg(p);
                let w = [
                    phi.to_radians().cos() as f32,
                    phi.to_radians().sin() as f32,
                    0.5,
                ];
                for m in [1, 2, 3] {
                    let Some(q) = mirrored_cell(p, n, m) else {
                        assert!(m & 1 == 1 && n % 2 == 1, "n {n} mirror {m}");
                        continue;
                    };
                    let v = mirrored(w, m);
                    let want = Axis::azimuth(n).centre_deg(q);
                    let got = f64::from(v[1])
                        .atan2(f64::from(v[0]))
                        .to_degrees()
                        .rem_euclid(360.0);
                    let d = (got - want).abs();
                    assert!(
                        d.min(360.0 - d) < 1e-4,
                        "n {n} p {p} mirror {m}: {got} vs {want}"
                    );
                }
            }
        }
    }
}
