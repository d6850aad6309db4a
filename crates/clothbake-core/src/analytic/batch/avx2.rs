//! The lanes of [`super`]: every function the lane form of the scalar one it names, inlined
//! into [`run_avx2`], [`run_classes_avx2`] and [`one_avx2`], the functions compiled for AVX2.
//!
//! A unit's constants are read from a [`UnitLanes`], lane by lane: one unit in every lane when
//! the lanes hold four pairs, up to four units when they hold one pair's units. Either way each
//! lane does the scalar arithmetic of its own pair and unit.
//!
//! One file of 1,270 lines on purpose: it is the crate's one file of AVX2 intrinsics, each
//! function the lane form of a scalar one in `evaluate.rs`, and it is read and reviewed as a
//! whole against them (the lanes' tests hold every lane to the scalar bits).

use crate::analytic::{AnalyticModel, ClassTerms, SliceSums, Sums, Unit, Variant, EPS};
use crate::lanes::{F64x4 as F, Mask4 as M};
use crate::reflect::Reflection;
use crate::shadowing::ActiveTable;
use crate::trig::{atan2_x4, sin_cos_x4};
use crate::vec3::{UnitVec3, Vec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// Lanes of an elevation (`shadowing::Elevation`).
#[derive(Clone, Copy)]
struct Elevation {
    psi: F,
    sin: F,
    cos: F,
}

impl Elevation {
    /// `Elevation::of`.
    #[inline(always)]
    fn of(rise: F, run: F) -> Elevation {
        let inv = 1.0 / (rise * rise + run * run).sqrt();
        Elevation {
            psi: atan2_x4(rise, run),
            sin: rise * inv,
            cos: run * inv,
        }
    }

    /// Every lane the elevation in lane `k` of `el` (psi, sine and cosine lane by lane).
    #[inline(always)]
    fn lane(el: &[[f64; 4]; 3], k: usize) -> Elevation {
        Elevation {
            psi: F::splat(el[0][k]),
            sin: F::splat(el[1][k]),
            cos: F::splat(el[2][k]),
        }
    }

    /// Per lane, `a` where `w` holds, else `b`.
    #[inline(always)]
    fn pick(w: M, a: &Elevation, b: &Elevation) -> Elevation {
        Elevation {
            psi: w.select(a.psi, b.psi),
            sin: w.select(a.sin, b.sin),
            cos: w.select(a.cos, b.cos),
        }
    }
}

/// Lanes of an occluder (`shadowing::Occluder`).
#[derive(Clone, Copy)]
struct Occluder {
    u: F,
    z: F,
    rho: F,
}

impl Occluder {
    /// `Occluder::support`.
    #[inline(always)]
    fn support(&self, sin_psi: F, cos_psi: F) -> F {
        self.rho - self.u * sin_psi + self.z * cos_psi
    }
}

/// An active table (`shadowing::ActiveTable`) of each lane's unit, entry by entry, each field
/// lane by lane. A lane whose table is shorter is padded at the front with entries whose bound
/// is +inf, which are never active; a lane whose table is empty has only such entries, with
/// an occluder of zeros, and is not `some`.
#[derive(Clone, Debug, Default)]
pub(super) struct TableLanes {
    /// 1 where the lane's table has an entry, else 0.
    some: [f64; 4],
    /// The entries' lower elevation bounds, decreasing, and their occluders.
    lo: Vec<[f64; 4]>,
    u: Vec<[f64; 4]>,
    z: Vec<[f64; 4]>,
    rho: Vec<[f64; 4]>,
}

impl TableLanes {
    /// The tables of the lanes, one per lane.
    fn new(tables: [&ActiveTable; 4]) -> TableLanes {
        let n = tables.iter().map(|t| t.entries.len()).max().unwrap_or(0);
        let mut t = TableLanes {
            some: tables.map(|t| f64::from(u8::from(!t.entries.is_empty()))),
            lo: vec![[f64::INFINITY; 4]; n],
            u: vec![[0.0; 4]; n],
            z: vec![[0.0; 4]; n],
            rho: vec![[0.0; 4]; n],
        };
        for (lane, table) in tables.iter().enumerate() {
            let pad = n - table.entries.len();
            for (k, (lo, o)) in table.entries.iter().enumerate() {
                t.lo[pad + k][lane] = *lo;
                t.u[pad + k][lane] = o.u;
                t.z[pad + k][lane] = o.z;
                t.rho[pad + k][lane] = o.rho;
            }
        }
        t
    }
}

/// `ActiveTable::active` per lane: which lanes have an occluder, and each lane's. The entries'
/// bounds decrease, so the active entry is the first whose bound is at most psi (the last
/// where none is).
#[inline(always)]
fn active(t: &TableLanes, psi: F) -> (M, Occluder) {
    let Some(last) = t.lo.len().checked_sub(1) else {
        let z = F::splat(0.0);
        return (M::splat(false), Occluder { u: z, z, rho: z });
    };
    let mut o = Occluder {
        u: F::from_array(t.u[last]),
        z: F::from_array(t.z[last]),
        rho: F::from_array(t.rho[last]),
    };
    for k in (0..last).rev() {
        let here = F::from_array(t.lo[k]).le(psi);
        o = Occluder {
            u: here.select(F::from_array(t.u[k]), o.u),
            z: here.select(F::from_array(t.z[k]), o.z),
            rho: here.select(F::from_array(t.rho[k]), o.rho),
        };
    }
    (F::from_array(t.some).gt(F::splat(0.0)), o)
}

/// A piece of a unit in each lane: a unit's whole range with its side tables, or a slice of it
/// with the slice's ([`crate::analytic::Variant::Sliced`]).
#[derive(Clone, Copy)]
pub(super) struct Piece<'a> {
    unit: &'a Unit,
    /// The side tables on the +c and the -c side.
    side: (&'a ActiveTable, &'a ActiveTable),
    /// The parts of the unit's range along the axis.
    ranges: &'a [(f64, f64)],
}

impl<'a> Piece<'a> {
    /// The unit's whole range.
    fn whole(unit: &'a Unit) -> Piece<'a> {
        Piece {
            unit,
            side: (&unit.side_plus, &unit.side_minus),
            ranges: std::slice::from_ref(&unit.range),
        }
    }

    /// Each of the unit's slices.
    fn slices(unit: &'a Unit) -> impl Iterator<Item = Piece<'a>> {
        unit.slices.iter().map(move |sl| Piece {
            unit,
            side: sl.tables(),
            ranges: &sl.ranges,
        })
    }
}

/// The constants of a piece of a unit in each lane ([`Piece`]): one piece in all four lanes, or
/// up to four (the lanes past the last repeat it; their results are dropped). Lanes of one
/// `UnitLanes` agree in what changes the code path: whether the units are endless, whether they
/// have a specular lobe, and its whole exponent.
#[derive(Clone, Debug)]
pub(super) struct UnitLanes {
    radius: [f64; 4],
    height: [f64; 4],
    top: [f64; 4],
    /// The arc above the floor: lo, hi, and the sines and cosines of its ends.
    floor: [[f64; 4]; 6],
    /// The parts of the piece's range along the axis, lo and hi, in their order; a lane with
    /// fewer parts is padded with empty ones (0, 0), whose overlap with anything is +0.
    ranges: Vec<[[f64; 4]; 2]>,
    /// The segment's extent along the axis; `None` for endless segments.
    extent: Option<[[f64; 4]; 2]>,
    /// rho_s; `None` where every lane's is 0.
    specular: Option<[f64; 4]>,
    /// The whole exponent of the Huo facets' closed form.
    exponent: u32,
    /// 1 where the lane's unit is a weft's, 0 for a warp's.
    weft: [f64; 4],
    side_plus: TableLanes,
    side_minus: TableLanes,
    end_plus: TableLanes,
    end_minus: TableLanes,
}

impl UnitLanes {
    /// The lanes of `pieces` (one to four), the lanes past the last repeating it; `exponent`
    /// their common whole exponent. `None` where they differ in what changes the code path.
    pub(super) fn new(pieces: &[Piece<'_>], exponent: u32) -> Option<UnitLanes> {
        let first = pieces.first()?.unit;
        if pieces.len() > 4
            || pieces.iter().any(|p| {
                let u = p.unit;
                u.seg.extent.is_some() != first.seg.extent.is_some()
                    || (u.seg.material.specular == 0.0) != (first.seg.material.specular == 0.0)
            })
        {
            return None;
        }
        let p: [Piece<'_>; 4] = std::array::from_fn(|k| pieces[k.min(pieces.len() - 1)]);
        let u = p.map(|p| p.unit);
        let parts = p.iter().map(|p| p.ranges.len()).max().unwrap_or(0);
        let ranges = (0..parts)
            .map(|k| {
                let part = |end: usize| p.map(|p| p.ranges.get(k).map_or(0.0, |r| [r.0, r.1][end]));
                [part(0), part(1)]
            })
            .collect();
        let lanes = |f: &dyn Fn(&Unit) -> f64| u.map(f);
        let extent = |end: usize| {
            lanes(&|u| {
                let (y0, y1) = u.seg.extent.unwrap_or((0.0, 0.0));
                [y0, y1][end]
            })
        };
        Some(UnitLanes {
            radius: lanes(&|u| u.seg.radius),
            height: lanes(&|u| u.seg.height),
            top: lanes(&|u| u.seg.top),
            floor: [
                lanes(&|u| u.seg.floor.arc.lo),
                lanes(&|u| u.seg.floor.arc.hi),
                lanes(&|u| u.seg.floor.lo.0),
                lanes(&|u| u.seg.floor.lo.1),
                lanes(&|u| u.seg.floor.hi.0),
                lanes(&|u| u.seg.floor.hi.1),
            ],
            ranges,
            extent: first.seg.extent.map(|_| [extent(0), extent(1)]),
            specular: (first.seg.material.specular != 0.0)
                .then(|| lanes(&|u| u.seg.material.specular)),
            exponent,
            weft: lanes(&|u| f64::from(u8::from(u.seg.group == crate::weave::Group::Weft))),
            side_plus: TableLanes::new(p.map(|p| p.side.0)),
            side_minus: TableLanes::new(p.map(|p| p.side.1)),
            end_plus: TableLanes::new(u.map(|u| &u.seg.end_plus)),
            end_minus: TableLanes::new(u.map(|u| &u.seg.end_minus)),
        })
    }
}

/// Per lane, `a`'s occluder where `which` holds, else `b`'s.
#[inline(always)]
fn either(which: M, a: (M, Occluder), b: (M, Occluder)) -> (M, Occluder) {
    let m = (which & a.0) | (!which & b.0);
    let (a, b) = (a.1, b.1);
    (
        m,
        Occluder {
            u: which.select(a.u, b.u),
            z: which.select(a.z, b.z),
            rho: which.select(a.rho, b.rho),
        },
    )
}

/// Lanes of a direction as one group's units see it (`analytic::View`).
#[derive(Clone, Copy)]
struct View {
    /// The projection on the cross-section plane.
    c: F,
    z: F,
    /// Its polar form.
    angle: F,
    norm: F,
    cos: F,
    sin: F,
    /// The side elevation; valid where `side`.
    side: M,
    psi: Elevation,
    mirrored: M,
    /// The axial component, and the end elevation valid where `end`.
    va: F,
    end: M,
    end_psi: Elevation,
}

impl View {
    /// `View::both`.
    #[inline(always)]
    fn both(v: [F; 3]) -> [View; 2] {
        let [x, y, z] = v;
        let (ex, ey) = (Elevation::of(z, x.abs()), Elevation::of(z, y.abs()));
        [View::new(x, y, z, ex, ey), View::new(y, x, z, ey, ex)]
    }

    /// `View::new`.
    #[inline(always)]
    fn new(vc: F, va: F, vz: F, ec: Elevation, ea: Elevation) -> View {
        let mirrored = vc.lt(F::splat(0.0));
        let eps = F::splat(EPS);
        View {
            c: vc,
            z: vz,
            angle: mirrored.select(PI - ec.psi, ec.psi),
            norm: (vc * vc + vz * vz).sqrt(),
            cos: mirrored.select(-ec.cos, ec.cos),
            sin: ec.sin,
            side: vc.abs().gt(eps),
            psi: ec,
            mirrored,
            va,
            end: va.abs().gt(eps),
            end_psi: ea,
        }
    }

    /// The view of `v` from a weft's unit where `weft` holds, else from a warp's, given its
    /// elevations over |x| and over |y| (`View::both`, per lane the lane's group's).
    #[inline(always)]
    fn of_units(weft: M, v: Vec3, over_x: Elevation, over_y: Elevation) -> View {
        let (x, y) = (F::splat(v.x), F::splat(v.y));
        View::new(
            weft.select(y, x),
            weft.select(x, y),
            F::splat(v.z),
            Elevation::pick(weft, &over_y, &over_x),
            Elevation::pick(weft, &over_x, &over_y),
        )
    }
}

/// The unit half vector (L + E) / |L + E| of each lane's light `l` and eye `e`.
#[inline(always)]
fn unit_half(l: [F; 3], e: [F; 3]) -> [F; 3] {
    let h = [l[0] + e[0], l[1] + e[1], l[2] + e[2]];
    let inv = 1.0 / (h[0] * h[0] + h[1] * h[1] + h[2] * h[2]).sqrt();
    [h[0] * inv, h[1] * inv, h[2] * inv]
}

/// What one pair's views share whatever the units' groups: the light and the eye, their four
/// elevations (over |x| and over |y|, the light's then the eye's: one `atan2` of four lanes),
/// and the unit half vector (`Views::both`'s), computed once a pair for all its packs.
struct PairLanes {
    l: Vec3,
    e: Vec3,
    /// psi, sine and cosine, lane by lane.
    elevations: [[f64; 4]; 3],
    h: [F; 3],
}

impl PairLanes {
    #[inline(always)]
    fn new(l: Vec3, e: Vec3) -> PairLanes {
        let el = Elevation::of(
            F::from_array([l.z, l.z, e.z, e.z]),
            F::from_array([l.x.abs(), l.y.abs(), e.x.abs(), e.y.abs()]),
        );
        PairLanes {
            l,
            e,
            elevations: [el.psi.to_array(), el.sin.to_array(), el.cos.to_array()],
            h: unit_half(
                [F::splat(l.x), F::splat(l.y), F::splat(l.z)],
                [F::splat(e.x), F::splat(e.y), F::splat(e.z)],
            ),
        }
    }
}

/// Lanes of a unit half vector's projection (`arc::Heading`).
#[derive(Clone, Copy)]
struct Heading {
    norm: F,
    cos: F,
    sin: F,
}

impl Heading {
    /// `Heading::new`.
    #[inline(always)]
    fn new(c: F, z: F) -> Heading {
        let norm = (c * c + z * z).sqrt();
        let inv = 1.0 / norm;
        Heading {
            norm,
            cos: c * inv,
            sin: z * inv,
        }
    }
}

/// Lanes of light, eye and half vector for one group (`analytic::Views`).
#[derive(Clone, Copy)]
struct Views {
    l: View,
    e: View,
    h: Heading,
}

impl Views {
    /// The views of pair `p` for units of either group, lane by lane: a weft's where `weft`
    /// holds, else a warp's (per lane `Views::both`'s of the lane's group).
    #[inline(always)]
    fn of_units(weft: M, p: &PairLanes) -> Views {
        let el = &p.elevations;
        Views {
            l: View::of_units(weft, p.l, Elevation::lane(el, 0), Elevation::lane(el, 1)),
            e: View::of_units(weft, p.e, Elevation::lane(el, 2), Elevation::lane(el, 3)),
            h: Heading::new(weft.select(p.h[1], p.h[0]), p.h[2]),
        }
    }

    /// `Views::both`.
    #[inline(always)]
    fn both(l: [F; 3], e: [F; 3]) -> [Views; 2] {
        let [lw, lf] = View::both(l);
        let [ew, ef] = View::both(e);
        let h = unit_half(l, e);
        [
            Views {
                l: lw,
                e: ew,
                h: Heading::new(h[0], h[2]),
            },
            Views {
                l: lf,
                e: ef,
                h: Heading::new(h[1], h[2]),
            },
        ]
    }
}

/// Lanes of an arc with its ends' sines and cosines (`arc::ArcTrig`).
#[derive(Clone, Copy)]
struct Arc {
    lo: F,
    hi: F,
    lo_sc: (F, F),
    hi_sc: (F, F),
}

impl Arc {
    /// `ArcTrig::facing`.
    #[inline(always)]
    fn facing(v: &View) -> Arc {
        Arc {
            lo: v.angle - FRAC_PI_2,
            hi: v.angle + FRAC_PI_2,
            lo_sc: (-v.cos, v.sin),
            hi_sc: (v.cos, -v.sin),
        }
    }

    /// `ArcTrig::meet`.
    #[inline(always)]
    fn meet(self, o: &Arc) -> Arc {
        let lo = o.lo.gt(self.lo);
        let hi = o.hi.lt(self.hi);
        Arc {
            lo: lo.select(o.lo, self.lo),
            hi: hi.select(o.hi, self.hi),
            lo_sc: (
                lo.select(o.lo_sc.0, self.lo_sc.0),
                lo.select(o.lo_sc.1, self.lo_sc.1),
            ),
            hi_sc: (
                hi.select(o.hi_sc.0, self.hi_sc.0),
                hi.select(o.hi_sc.1, self.hi_sc.1),
            ),
        }
    }

    /// `Arc::is_empty`.
    #[inline(always)]
    fn empty(&self) -> M {
        self.lo.ge(self.hi)
    }

    /// The arcs of `UnitLanes::floor`.
    #[inline(always)]
    fn load(a: &[[f64; 4]; 6]) -> Arc {
        Arc {
            lo: F::from_array(a[0]),
            hi: F::from_array(a[1]),
            lo_sc: (F::from_array(a[2]), F::from_array(a[3])),
            hi_sc: (F::from_array(a[4]), F::from_array(a[5])),
        }
    }
}

/// `meet` of two intervals.
#[inline(always)]
fn meet(a: (F, F), b: (F, F)) -> (F, F) {
    (a.0.max(b.0), a.1.min(b.1))
}

/// `overlap` of two intervals.
#[inline(always)]
fn overlap(a: (F, F), b: (F, F)) -> F {
    let (lo, hi) = meet(a, b);
    (hi - lo).max(F::splat(0.0))
}

/// The sum of the overlaps of `iv` with the parts `ranges`, in their order (`visible_of`'s
/// `l_v`; every term is +0 or more, so starting from the first term is the iterator's sum).
#[inline(always)]
fn overlap_sum(ranges: &[[[f64; 4]; 2]], iv: (F, F)) -> F {
    let Some((first, rest)) = ranges.split_first() else {
        return F::splat(0.0);
    };
    let mut sum = overlap((F::from_array(first[0]), F::from_array(first[1])), iv);
    for r in rest {
        sum = sum + overlap((F::from_array(r[0]), F::from_array(r[1])), iv);
    }
    sum
}

/// `shadowing::occluded_length` (eq. 3.6).
#[inline(always)]
fn occluded_length(top: F, o: &Occluder, psi: &Elevation) -> F {
    let num = o.support(psi.sin, psi.cos) - top * psi.cos;
    let zero = F::splat(0.0);
    num.le(zero).select(
        zero,
        psi.sin
            .le(zero)
            .select(F::splat(f64::INFINITY), num / psi.sin),
    )
}

/// A break point of an arc in `mean_occluded_length`: its sort key (-cos of its angle from the
/// arc's start; infinite where the point is not one), sine and cosine.
#[derive(Clone, Copy)]
struct Cut {
    key: F,
    s: F,
    c: F,
}

// The helpers below are functions, not closures: a closure written in an `#[inline(always)]`
// helper has the helper's target features (none), not the AVX2 of the function it is inlined
// into, and left out of line its lane operations would be calls.

/// The point `(s, c)` (sine and cosine) turned back by the angle whose sine and cosine are
/// `(s0, c0)`.
#[inline(always)]
fn from_lo((s, c): (F, F), s0: F, c0: F) -> (F, F) {
    (s * c0 - c * s0, c * c0 + s * s0)
}

/// The primitive of w = e.c cos + e.z sin at the point (`mean_occluded_length`).
#[inline(always)]
fn weight((s, c): (F, F), e: (F, F)) -> F {
    e.0 * s - e.1 * c
}

/// The primitive of sin w at the point, of angle `t` (`mean_occluded_length`).
#[inline(always)]
fn sin_weight((s, c): (F, F), t: F, e: (F, F)) -> F {
    e.0 * 0.5 * s * s + e.1 * 0.5 * (t - s * c)
}

/// Lanes where a length `l` is clear of 0 and of `max_len` by more than `tol`.
#[inline(always)]
fn clear(l: F, tol: F, max_len: F) -> M {
    (l.abs().gt(tol)) & ((l - max_len).abs().gt(tol))
}

/// `shadowing::mean_occluded_length` (eq. 3.6 averaged over the arc, the refined variant) for
/// the segments of `u`, of lengths `max_len`. Its fallback's height is `u.top`, the
/// `equal_area_height(r, h)` the scalar function computes.
#[inline(always)]
fn mean_occluded_length(
    u: &UnitLanes,
    o: &Occluder,
    psi: &Elevation,
    arc: &Arc,
    e: (F, F),
    max_len: F,
) -> F {
    let (r, h) = (F::from_array(u.radius), F::from_array(u.height));
    let zero = F::splat(0.0);
    let inf = F::splat(f64::INFINITY);
    let (sp, cp) = (psi.sin, psi.cos);
    let fallback = arc.empty() | sp.le(zero);
    let short = occluded_length(F::from_array(u.top), o, psi).min(max_len);
    let num0 = o.support(sp, cp) - h * cp;
    let rc = r * cp;
    let inv_sp = 1.0 / sp;
    let inv_rc = 1.0 / rc;
    let (a, b) = (num0 * inv_sp, rc * inv_sp);
    let (s0, c0) = arc.lo_sc;
    let cos_len = from_lo(arc.hi_sc, s0, c0).1;
    // The four break points in the scalar's order, each with its validity.
    let b_pos = b.gt(zero);
    let one = F::splat(1.0);
    let mut cand = [Cut {
        key: zero,
        s: zero,
        c: zero,
    }; 4];
    for (j, x) in [num0 * inv_rc, (num0 - max_len * sp) * inv_rc]
        .into_iter()
        .enumerate()
    {
        let ok = b_pos & x.abs().lt(one);
        let x = ok.select(x, zero);
        let c = ((1.0 - x) * (1.0 + x)).sqrt();
        for (i, point) in [(x, c), (x, -c)].into_iter().enumerate() {
            let (sf, cf) = from_lo(point, s0, c0);
            let v = ok & sf.gt(zero) & cf.gt(cos_len);
            cand[2 * j + i] = Cut {
                key: v.select(-cf, inf),
                s: point.0,
                c: point.1,
            };
        }
    }
    let any_cut =
        (cand[0].key.lt(inf) | cand[1].key.lt(inf)) | (cand[2].key.lt(inf) | cand[3].key.lt(inf));
    let mut sorted = [Cut {
        key: inf,
        s: zero,
        c: one,
    }; 4];
    if any_cut.any() {
        // The stable order of the insertion sort: rank = keys below, plus equal keys before.
        let mut rank = [zero; 4];
        for i in 0..4 {
            for j in 0..4 {
                if j == i {
                    continue;
                }
                let before = if j < i {
                    cand[j].key.le(cand[i].key)
                } else {
                    cand[j].key.lt(cand[i].key)
                };
                rank[i] = rank[i] + before.select(one, zero);
            }
        }
        for (pos, slot) in sorted.iter_mut().enumerate() {
            let pos = F::splat(pos as f64);
            for i in 0..4 {
                let here = rank[i].ge(pos) & rank[i].le(pos);
                *slot = Cut {
                    key: here.select(cand[i].key, slot.key),
                    s: here.select(cand[i].s, slot.s),
                    c: here.select(cand[i].c, slot.c),
                };
            }
        }
    }
    let valid = [
        sorted[0].key.lt(inf),
        sorted[1].key.lt(inf),
        sorted[2].key.lt(inf),
        sorted[3].key.lt(inf),
    ];
    // Points 0..=5: the arc's start, the sorted break points, the arc's end; a break point's
    // angle from its offset, computed where a window needs it.
    let mut theta = [arc.lo, zero, zero, zero, zero, arc.hi];
    let mut have = [true, false, false, false, false, true];
    let sc = [
        (s0, c0),
        (sorted[0].s, sorted[0].c),
        (sorted[1].s, sorted[1].c),
        (sorted[2].s, sorted[2].c),
        (sorted[3].s, sorted[3].c),
        arc.hi_sc,
    ];
    let tol = 1e-9 * (a.abs() + b.abs() + max_len);
    let max = max_len;
    let (mut num, mut den) = (zero, zero);
    for k in 0..5 {
        // Window k runs from point k to point k + 1, or to the arc's end after the last valid
        // break point; it exists where point k does.
        let live = if k == 0 { M::splat(true) } else { valid[k - 1] };
        if !live.any() {
            break;
        }
        let next = if k < 4 { valid[k] } else { M::splat(false) };
        let (p0, p1, pe) = (sc[k], sc[k + 1], arc.hi_sc);
        let q1 = (next.select(p1.0, pe.0), next.select(p1.1, pe.1));
        let l_end_at = a - b * q1.0;
        let end_clear = !next & clear(l_end_at, tol, max_len);
        let (known, l_known) = if k == 0 {
            let l0 = a - b * p0.0;
            let c0 = clear(l0, tol, max_len);
            (c0 | end_clear, c0.select(l0, l_end_at))
        } else {
            (end_clear, l_end_at)
        };
        let wsum = weight(q1, e) - weight(p0, e);
        den = den + live.select(wsum, zero);
        // Where l is known to be 0 or the whole length, the window needs no angle.
        let flat = known & (l_known.le(zero) | l_known.ge(max));
        let mut l_mid = l_known;
        let mut inner = zero;
        if (live & !flat).any() {
            for j in [k, k + 1] {
                if !have[j] {
                    let (sf, cf) = from_lo(sc[j], s0, c0);
                    theta[j] = arc.lo + atan2_x4(sf, cf);
                    have[j] = true;
                }
            }
            let t0 = theta[k];
            let t1 = next.select(theta[k + 1], arc.hi);
            l_mid = known.select(l_known, a - b * sin_cos_x4(0.5 * (t0 + t1)).0);
            inner = a * wsum - b * (sin_weight(q1, t1, e) - sin_weight(p0, t0, e));
        }
        let term = l_mid
            .le(zero)
            .select(zero, l_mid.ge(max).select(max_len * wsum, inner));
        num = num + live.select(term, zero);
    }
    let mean = den
        .le(zero)
        .select(zero, (num / den).clamp_to(zero, max_len));
    fallback.select(short, mean)
}

/// The lanes' arc of a unit's cross-section that faces `v`, less what the side neighbour
/// hides (`AnalyticModel::side_arc`).
#[inline(always)]
fn side_arc(u: &UnitLanes, v: &View) -> Arc {
    let mut arc = Arc::facing(v);
    let (some, o) = either(
        v.mirrored,
        active(&u.side_minus, v.psi.psi),
        active(&u.side_plus, v.psi.psi),
    );
    let some = some & v.side;
    if !some.any() {
        return arc;
    }
    // `occluded_arc_at`: theta = psi + alpha, sin(alpha) = s / r1.
    let (r1, h1) = (F::from_array(u.radius), F::from_array(u.height));
    let psi = &v.psi;
    let s = o.support(psi.sin, psi.cos) - h1 * psi.cos;
    let all = s.ge(r1);
    let up_to = s.gt(-r1) & !all;
    let sa = up_to.select(s / r1, F::splat(0.0));
    let ca = ((1.0 - sa) * (1.0 + sa)).sqrt();
    let t = psi.psi + atan2_x4(sa, ca);
    let (ts, tc) = (psi.sin * ca + psi.cos * sa, psi.cos * ca - psi.sin * sa);
    let all = some & all;
    let up_to = some & up_to;
    // Mirrored: the arc ends at pi - t; else it starts at t.
    let pt = PI - t;
    let cut_hi = up_to & v.mirrored & pt.lt(arc.hi);
    let cut_lo = up_to & !v.mirrored & t.gt(arc.lo);
    arc.hi = cut_hi.select(pt, arc.hi);
    arc.hi_sc = (
        cut_hi.select(ts, arc.hi_sc.0),
        cut_hi.select(-tc, arc.hi_sc.1),
    );
    arc.lo = cut_lo.select(t, arc.lo);
    arc.lo_sc = (
        cut_lo.select(ts, arc.lo_sc.0),
        cut_lo.select(tc, arc.lo_sc.1),
    );
    arc.hi = all.select(arc.lo, arc.hi);
    arc.hi_sc = (
        all.select(arc.lo_sc.0, arc.hi_sc.0),
        all.select(arc.lo_sc.1, arc.hi_sc.1),
    );
    arc
}

/// The lanes' interval along the axis the ends' occluders leave (`AnalyticModel::end_interval`).
#[inline(always)]
fn end_interval(m: &AnalyticModel, u: &UnitLanes, v: &View, arc: &Arc, e: (F, F)) -> (F, F) {
    let Some([y0, y1]) = u.extent else {
        return (F::splat(f64::NEG_INFINITY), F::splat(f64::INFINITY));
    };
    let (y0, y1) = (F::from_array(y0), F::from_array(y1));
    let max_len = y1 - y0;
    let plus = v.va.gt(F::splat(0.0));
    let psi = &v.end_psi;
    let (some, o) = either(
        plus,
        active(&u.end_plus, psi.psi),
        active(&u.end_minus, psi.psi),
    );
    let some = some & v.end;
    if !some.any() {
        return (y0, y1);
    }
    let hidden = match m.variant {
        Variant::Thesis => occluded_length(F::from_array(u.top), &o, psi),
        Variant::Refined | Variant::Sliced | Variant::Sliced3d => {
            mean_occluded_length(u, &o, psi, arc, e, max_len)
        }
    };
    let hidden = some.select(hidden, F::splat(0.0));
    (plus.select(y0, y0 + hidden), plus.select(y1 - hidden, y1))
}

/// `arc::projected_width` on a nonempty arc.
#[inline(always)]
fn projected_width(r: F, arc: &Arc, e: (F, F)) -> F {
    r * (weight(arc.hi_sc, e) - weight(arc.lo_sc, e))
}

/// `arc::diffuse_integral` on a nonempty arc.
#[inline(always)]
fn diffuse_integral(arc: &Arc, l: (F, F), e: (F, F)) -> F {
    let half_t = 0.5 * (arc.hi - arc.lo);
    let sc2 = 0.5 * (arc.hi_sc.0 * arc.hi_sc.1 - arc.lo_sc.0 * arc.lo_sc.1);
    let s2 = 0.5 * (arc.hi_sc.0 * arc.hi_sc.0 - arc.lo_sc.0 * arc.lo_sc.0);
    l.0 * e.0 * (half_t + sc2) + (l.0 * e.1 + l.1 * e.0) * s2 + l.1 * e.1 * (half_t - sc2)
}

/// `f64::powi` as compiler-rt's `__powidf2` computes it (square and multiply from the low bit).
#[inline(always)]
fn powi(mut a: F, mut n: u32) -> F {
    let mut r = F::splat(1.0);
    loop {
        if n & 1 != 0 {
            r = r * a;
        }
        n /= 2;
        if n == 0 {
            return r;
        }
        a = a * a;
    }
}

/// The sine and cosine of u = theta - theta_H for a point `(sin theta, cos theta)`.
#[inline(always)]
fn from_heading((st, ct): (F, F), h: &Heading) -> [F; 2] {
    [st * h.cos - ct * h.sin, ct * h.cos + st * h.sin]
}

/// `arc::huo_specular_integral` (eq. 4.10) on a nonempty arc, for a whole exponent `n`.
#[inline(always)]
fn huo_specular_integral(arc: &Arc, h: &Heading, e: &Heading, n: u32) -> F {
    let sd = h.sin * e.cos - h.cos * e.sin;
    let cd = h.cos * e.cos + h.sin * e.sin;
    let ([s0, c0], [s1, c1]) = (from_heading(arc.lo_sc, h), from_heading(arc.hi_sc, h));
    let m = n + 1;
    // `cos_power_integral(m, ...)`.
    let even = m.is_multiple_of(2);
    let (su, cu) = ([s0, s1], [c0, c1]);
    let mut acc = if even {
        let th = atan2_x4(h.sin, h.cos);
        [arc.lo - th, arc.hi - th]
    } else {
        su
    };
    let mut k = if even { 2 } else { 3 };
    let c2 = [cu[0] * cu[0], cu[1] * cu[1]];
    let mut cp = if even { cu } else { c2 };
    let mut power = if even { [F::splat(1.0); 2] } else { cu };
    while k <= m {
        let inv = 1.0 / k as f64;
        let w = (k as f64 - 1.0) * inv;
        for j in 0..2 {
            acc[j] = cp[j] * su[j] * inv + w * acc[j];
            power[j] = cp[j] * cu[j];
            cp[j] = cp[j] * c2[j];
        }
        k += 2;
    }
    let ([p0, p1], [q0, q1]) = (acc, power);
    let n1 = n as f64 + 1.0;
    let v = (cd * p1 + sd * q1 / n1) - (cd * p0 + sd * q0 / n1);
    powi(h.norm, n) * e.norm * v
}

/// A unit's terms in each lane (`AnalyticModel::unit_terms` without I_2).
struct Terms {
    /// Visible length l_v and projected width of the visible arc (eq. 4.3).
    l_v: F,
    width: F,
    /// Lit and visible length l_vi and the arc integrals of the diffuse factor and of the
    /// specular intensity (times rho_s), valid where `lit`.
    l_vi: F,
    kd: F,
    ks: F,
    /// Lanes where the unit is visible, and where it is also lit.
    visible: M,
    lit: M,
}

/// The terms of the lanes' units `u` for the views of their groups: `None` where no lane sees
/// its unit.
#[inline(always)]
fn unit_terms(m: &AnalyticModel, u: &UnitLanes, v: &Views) -> Option<Terms> {
    let zero = F::splat(0.0);
    let floor = Arc::load(&u.floor);
    let seen = side_arc(u, &v.e).meet(&floor);
    let lit = side_arc(u, &v.l).meet(&floor);
    // `visible_of`.
    let ep = (v.e.c, v.e.z);
    let mut visible = !seen.empty();
    if !visible.any() {
        return None;
    }
    let along = end_interval(m, u, &v.e, &seen, ep);
    let l_v = overlap_sum(&u.ranges, along);
    visible = visible & l_v.gt(zero);
    if !visible.any() {
        return None;
    }
    let width = projected_width(F::from_array(u.radius), &seen, ep);
    let vi = seen.meet(&lit);
    let lit_len = end_interval(m, u, &v.l, &vi, ep);
    let l_vi = overlap_sum(&u.ranges, meet(along, lit_len));
    let lit = visible & !vi.empty() & l_vi.gt(zero);
    let mut t = Terms {
        l_v,
        width,
        l_vi,
        kd: zero,
        ks: zero,
        visible,
        lit,
    };
    if lit.any() {
        // `arc_integral`.
        t.kd = diffuse_integral(&vi, (v.l.c, v.l.z), ep);
        if let Some(specular) = u.specular {
            let e = Heading {
                norm: v.e.norm,
                cos: v.e.cos,
                sin: v.e.sin,
            };
            t.ks = F::from_array(specular) * huo_specular_integral(&vi, &v.h, &e, u.exponent);
        }
    }
    Some(t)
}

/// The model's units in lanes: each alone in all four lanes (four pairs at a time), and the
/// pieces of one pair (each unit whole, or each slice of each unit with the sliced variant) in
/// packs of up to four.
#[derive(Clone, Debug)]
pub(crate) struct Lanes {
    /// Unit `k` whole in every lane; empty with the sliced variant (whose batches go pair by
    /// pair, each pair in `packs`).
    single: Vec<UnitLanes>,
    /// Consecutive pieces in the lanes of one `UnitLanes`, with the index of each lane's unit;
    /// in the units' order (and each unit's slices in theirs), so that summing the packs lane
    /// by lane sums as the scalar evaluation does.
    packs: Vec<(UnitLanes, Vec<usize>)>,
    /// Whether the pieces are slices, summed per unit first (`sliced_terms`).
    sliced: bool,
}

impl Lanes {
    /// The lanes of `units`, `exps` their whole exponents; the units' slices where they have
    /// them (all or none do).
    pub(super) fn new(units: &[Unit], exps: &[u32]) -> Option<Lanes> {
        let sliced = units.iter().any(|u| !u.slices.is_empty());
        if sliced && units.iter().any(|u| u.slices.is_empty()) {
            // Units whole beside units in slices: left to the unit-by-unit evaluation.
            return None;
        }
        let pieces: Vec<(usize, Piece<'_>)> = units
            .iter()
            .enumerate()
            .flat_map(|(k, u)| {
                let whole = (!sliced).then(|| Piece::whole(u));
                let slices = Piece::slices(u).filter(move |_| sliced);
                whole.into_iter().chain(slices).map(move |p| (k, p))
            })
            .collect();
        let single = if sliced {
            Vec::new()
        } else {
            units
                .iter()
                .zip(exps)
                .map(|(u, &n)| UnitLanes::new(&[Piece::whole(u)], n))
                .collect::<Option<Vec<_>>>()?
        };
        let mut packs = Vec::new();
        let mut start = 0;
        while start < pieces.len() {
            // The longest run from `start` that one pack holds.
            let n = exps[pieces[start].0];
            let run = |end: usize| pieces[start..end].iter().map(|p| p.1).collect::<Vec<_>>();
            let mut end = start + 1;
            let mut pack = UnitLanes::new(&run(end), n)?;
            while end < pieces.len() && end - start < 4 && exps[pieces[end].0] == n {
                let Some(p) = UnitLanes::new(&run(end + 1), n) else {
                    break;
                };
                pack = p;
                end += 1;
            }
            packs.push((pack, pieces[start..end].iter().map(|p| p.0).collect()));
            start = end;
        }
        Some(Lanes {
            single,
            packs,
            sliced,
        })
    }

    /// Whether four pairs at a time take these lanes (not with the sliced variant).
    pub(crate) fn take_batches(&self) -> bool {
        !self.sliced
    }
}

/// A `Terms` lane by lane, for the sums taken lane after lane.
struct TermsByLane {
    visible: [bool; 4],
    lit: [bool; 4],
    l_v: [f64; 4],
    width: [f64; 4],
    l_vi: [f64; 4],
    kd: [f64; 4],
    ks: [f64; 4],
}

impl TermsByLane {
    #[inline(always)]
    fn of(t: &Terms) -> TermsByLane {
        TermsByLane {
            visible: t.visible.to_array(),
            lit: t.lit.to_array(),
            l_v: t.l_v.to_array(),
            width: t.width.to_array(),
            l_vi: t.l_vi.to_array(),
            kd: t.kd.to_array(),
            ks: t.ks.to_array(),
        }
    }

    /// Lane `k`'s lit terms, where it is lit.
    #[inline(always)]
    fn lit(&self, k: usize) -> Option<(f64, f64, f64)> {
        self.lit[k].then(|| (self.l_vi[k], self.kd[k], self.ks[k]))
    }

    /// Lane `k`'s terms, those of unit `u`, into `sums` where it is visible.
    #[inline(always)]
    fn add_unit(&self, k: usize, u: &Unit, sums: &mut Sums) {
        if self.visible[k] {
            sums.add(u, self.l_v[k], self.width[k], self.lit(k));
        }
    }

    /// Lane `k`'s terms, a slice's, into its unit's `sums` where it is visible.
    #[inline(always)]
    fn add_slice(&self, k: usize, sums: &mut SliceSums) {
        if self.visible[k] {
            sums.seen(self.l_v[k], self.width[k]);
            if let Some((l_vi, kd, ks)) = self.lit(k) {
                sums.lit(l_vi, kd, ks);
            }
        }
    }
}

/// A sliced unit's slice sums into `sums`, as `sliced_terms` hands them to the unit-by-unit
/// evaluation.
#[inline(always)]
fn add_sliced(u: &Unit, slices: &SliceSums, sums: &mut Sums) {
    if let Some((l_v, width, lit)) = slices.unit() {
        sums.add(u, l_v, width, lit);
    }
}

/// Eq. 4.11 for one pair (`AnalyticModel::intensity_with` without I_2), both above the horizon:
/// the pieces in the lanes of their packs, their terms summed in the units' order (and a sliced
/// unit's slices in theirs) as the scalar evaluation sums them.
#[inline(always)]
fn intensity1(m: &AnalyticModel, lanes: &Lanes, wi: UnitVec3, wo: UnitVec3) -> Reflection {
    let zero = F::splat(0.0);
    let pair = PairLanes::new(wi.get(), wo.get());
    let mut sums = Sums::default();
    // The sliced unit being summed, and its sums so far.
    let mut open: Option<(usize, SliceSums)> = None;
    for (pack, units) in &lanes.packs {
        let weft = F::from_array(pack.weft).gt(zero);
        let t = unit_terms(m, pack, &Views::of_units(weft, &pair)).map(|t| TermsByLane::of(&t));
        for (k, &u) in units.iter().enumerate() {
            if !lanes.sliced {
                if let Some(t) = &t {
                    t.add_unit(k, &m.units[u], &mut sums);
                }
                continue;
            }
            if open.as_ref().is_none_or(|(v, _)| *v != u) {
                if let Some((v, s)) = open.take() {
                    add_sliced(&m.units[v], &s, &mut sums);
                }
                open = Some((u, SliceSums::default()));
            }
            if let (Some((_, s)), Some(t)) = (open.as_mut(), &t) {
                t.add_slice(k, s);
            }
        }
    }
    if let Some((v, s)) = open {
        add_sliced(&m.units[v], &s, &mut sums);
    }
    sums.reflection()
}

/// Eq. 4.11 for four pairs (`AnalyticModel::intensity_with` without I_2).
#[inline(always)]
fn intensity4(m: &AnalyticModel, lanes: &Lanes, wi: [F; 3], wo: [F; 3]) -> [Reflection; 4] {
    let views = Views::both(wi, wo);
    let mut sums: [Sums; 4] = Default::default();
    for (u, ul) in m.units.iter().zip(&lanes.single) {
        let Some(t) = unit_terms(m, ul, &views[u.seg.group as usize]) else {
            continue;
        };
        let t = TermsByLane::of(&t);
        for (k, s) in sums.iter_mut().enumerate() {
            t.add_unit(k, u, s);
        }
    }
    [0, 1, 2, 3].map(|k| sums[k].reflection())
}

/// Each class's terms for four pairs (`AnalyticModel::class_terms`), pair `k`'s into
/// `out[k * classes..]` (zero where the class is not seen).
#[inline(always)]
fn class_terms4(m: &AnalyticModel, lanes: &Lanes, wi: [F; 3], wo: [F; 3], out: &mut [ClassTerms]) {
    let zero = F::splat(0.0);
    let classes = m.class_unit.len();
    let views = Views::both(wi, wo);
    let (px, py) = m.grid.period();
    // `direct_terms`: the visible share, and f_r = I / (pi cos theta_i) (`intensity_to_brdf`).
    let (area, cos_i) = (px * py * wo[2], PI * wi[2]);
    for (c, &u) in m.class_unit.iter().enumerate() {
        let (u, ul) = (&m.units[u as usize], &lanes.single[u as usize]);
        let Some(t) = unit_terms(m, ul, &views[u.seg.group as usize]) else {
            continue;
        };
        let s_v = t.l_v * t.width;
        let w = t.l_vi * u.seg.radius / s_v;
        let d = t.lit.select((w * t.kd / cos_i).max(zero), zero);
        let s = t.lit.select((w * t.ks / cos_i).max(zero), zero);
        let (visible, share) = (t.visible.to_array(), (s_v / area).to_array());
        let (d, s) = (d.to_array(), s.to_array());
        for k in 0..4 {
            if visible[k] {
                out[k * classes + c] = ClassTerms {
                    visible: share[k],
                    diffuse: d[k],
                    specular: s[k],
                    ..ClassTerms::default()
                };
            }
        }
    }
}

/// The lanes of four pairs (the missing ones and those below the horizon replaced by a pair
/// above it, whose results the caller drops).
#[inline(always)]
fn lanes_of(q: &[(UnitVec3, UnitVec3)]) -> ([F; 3], [F; 3]) {
    let up = UnitVec3::Z;
    let pair = |k: usize| {
        q.get(k)
            .filter(|(wi, wo)| wi.above_horizon() && wo.above_horizon())
            .map_or((up, up), |&q| q)
    };
    let v = [pair(0), pair(1), pair(2), pair(3)].map(|(wi, wo)| (wi.get(), wo.get()));
    (
        [
            F::from_array(v.map(|p| p.0.x)),
            F::from_array(v.map(|p| p.0.y)),
            F::from_array(v.map(|p| p.0.z)),
        ],
        [
            F::from_array(v.map(|p| p.1.x)),
            F::from_array(v.map(|p| p.1.y)),
            F::from_array(v.map(|p| p.1.z)),
        ],
    )
}

/// Runs [`class_terms4`] over the pairs, four at a time; pairs below the horizon give 0.
#[inline(always)]
fn run_classes(
    m: &AnalyticModel,
    lanes: &Lanes,
    pairs: &[(UnitVec3, UnitVec3)],
    out: &mut [ClassTerms],
) {
    let classes = m.class_unit.len();
    out.fill(ClassTerms::default());
    let mut four = vec![ClassTerms::default(); 4 * classes];
    for (q, o) in pairs.chunks(4).zip(out.chunks_mut(4 * classes)) {
        let (wi, wo) = lanes_of(q);
        four.fill(ClassTerms::default());
        class_terms4(m, lanes, wi, wo, &mut four);
        for (k, &(wi, wo)) in q.iter().enumerate() {
            if wi.above_horizon() && wo.above_horizon() {
                o[k * classes..(k + 1) * classes]
                    .copy_from_slice(&four[k * classes..(k + 1) * classes]);
            }
        }
    }
}

/// Runs [`intensity4`] over the pairs, four at a time (the last group padded with a pair
/// above the horizon whose result is dropped); pairs below the horizon give 0.
#[inline(always)]
fn run(m: &AnalyticModel, lanes: &Lanes, pairs: &[(UnitVec3, UnitVec3)], out: &mut [Reflection]) {
    for (q, o) in pairs.chunks(4).zip(out.chunks_mut(4)) {
        let (wi, wo) = lanes_of(q);
        let r = intensity4(m, lanes, wi, wo);
        for (k, slot) in o.iter_mut().enumerate() {
            let (wi, wo) = q[k];
            *slot = if wi.above_horizon() && wo.above_horizon() {
                r[k]
            } else {
                Reflection::default()
            };
        }
    }
}

/// [`run`] compiled for AVX2.
///
/// # Safety
/// The processor must have AVX2.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn run_avx2(
    m: &AnalyticModel,
    lanes: &Lanes,
    pairs: &[(UnitVec3, UnitVec3)],
    out: &mut [Reflection],
) {
    run(m, lanes, pairs, out)
}

/// [`intensity1`] compiled for AVX2.
///
/// # Safety
/// The processor must have AVX2.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn one_avx2(
    m: &AnalyticModel,
    lanes: &Lanes,
    wi: UnitVec3,
    wo: UnitVec3,
) -> Reflection {
    intensity1(m, lanes, wi, wo)
}

/// [`run_classes`] compiled for AVX2.
///
/// # Safety
/// The processor must have AVX2.
#[target_feature(enable = "avx2")]
pub(super) unsafe fn run_classes_avx2(
    m: &AnalyticModel,
    lanes: &Lanes,
    pairs: &[(UnitVec3, UnitVec3)],
    out: &mut [ClassTerms],
) {
    run_classes(m, lanes, pairs, out)
}
