//! Preprocessing (thesis sec. 3.2, 4.1): every segment of the period cut into pieces, one per
//! crossing it floats over, each piece's cross-section profile and end profiles turned into
//! active-occluder tables, and identical pieces merged into units with multiplicities D_i
//! (eq. 4.11). [`AnalyticModel::with_variant`] is the one constructor.

use super::*;

pub(super) fn frame(g: Group) -> (Vec3, Vec3) {
    // (c: across the segment, a: along its axis)
    match g {
        Group::Warp => (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)),
        Group::Weft => (Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0)),
    }
}

pub(super) fn rem(k: isize, n: usize) -> usize {
    k.rem_euclid(n as isize) as usize
}

/// The copy (period shift) of segment `s`'s extent that covers axis coordinate `p`.
pub(super) fn extent_near(s: &Segment, p: f64, period: f64) -> (f64, f64) {
    let (e0, e1) = s.extent.expect("finite float");
    let q = ((p - 0.5 * (e0 + e1)) / period).round();
    (e0 + q * period, e1 + q * period)
}

/// The occluder thread `seg.thread + dir * m` (same group) presents at crossing `cross` in the
/// cross-section of `seg`: that thread seen end-on where it is on top, else the crossing thread's
/// float over it seen side-on (its equal-area rectangle, eq. 3.1). Also returns the rectangle's
/// identity (segment, copy) so runs of the same float can be merged.
pub(super) fn occluder_at(
    geo: &Geometry,
    seg: &Segment,
    m: isize,
    cross: isize,
    dir: isize,
) -> (Occluder, Option<(usize, i64)>) {
    let g = seg.group;
    let c = g.other();
    let weave = &geo.fabric.weave();
    let (ng, nc) = (weave.n(g), weave.n(c));
    let tt = seg.thread as isize + dir * m;
    let p = geo.position(g, tt);
    if weave.on_top(g, rem(tt, ng), rem(cross, nc)) {
        let yarn = geo.fabric.group(g).threads[rem(tt, ng)];
        (
            Occluder {
                u: dir as f64 * (p - seg.axis),
                z: yarn.height,
                rho: yarn.radius,
            },
            None,
        )
    } else {
        let cross_yarn = geo.fabric.group(c).threads[rem(cross, nc)];
        let si = geo
            .segment_at(c, rem(cross, nc), tt)
            .expect("crossing thread is on top");
        let (e0, e1) = extent_near(&geo.segments[si], p, geo.period_across(g));
        let u = if dir > 0 {
            e0 - seg.axis
        } else {
            seg.axis - e1
        };
        let z = equal_area_height(cross_yarn.radius, cross_yarn.height);
        (
            Occluder { u, z, rho: 0.0 },
            Some((si, (e0 * 1e6).round() as i64)),
        )
    }
}

/// Occluders on one side (`dir` = +1 or -1 along c) of the cross-section of `seg` at crossing
/// `cross` (the thesis's profile, sec. 3.2): one period of neighbours plus the segment's own
/// repetition, a float spanning several neighbours counted once; produced on demand, outward
/// (non-decreasing u: each neighbour, disc or rectangle, lies beyond the previous one).
pub(super) fn side_profile<'a>(
    geo: &'a Geometry,
    seg: &'a Segment,
    cross: isize,
    dir: isize,
) -> impl Iterator<Item = Occluder> + 'a {
    let mut last_box = None;
    (1..=geo.fabric.weave().n(seg.group) as isize).filter_map(move |m| {
        let (o, id) = occluder_at(geo, seg, m, cross, dir);
        if id.is_some() && id == last_box {
            return None;
        }
        last_box = id;
        Some(o)
    })
}

/// Occluders beyond one end (`dir` = +1: the +axis end) of a finite segment, along its axis:
/// crossing threads seen end-on (discs) and the thread's own next floats (rectangles);
/// produced on demand, outward.
pub(super) fn end_profile<'a>(
    geo: &'a Geometry,
    seg: &'a Segment,
    top: f64,
    dir: isize,
) -> impl Iterator<Item = Occluder> + 'a {
    let g = seg.group;
    let c = g.other();
    let weave = geo.fabric.weave();
    let nc = weave.n(c);
    let (y0, y1) = seg.extent.expect("finite float");
    let (a, f) = (seg.float.start as isize, seg.float.len as isize);
    let mut last_box = None;
    (0..nc as isize).filter_map(move |j| {
        let k = if dir > 0 { a + f + j } else { a - 1 - j };
        let p = geo.position(c, k);
        if weave.on_top(g, seg.thread, rem(k, nc)) {
            let si = geo.segment_at(g, seg.thread, k).expect("own float");
            let (e0, e1) = extent_near(&geo.segments[si], p, geo.period_along(g));
            let key = (si, (e0 * 1e6).round() as i64);
            if last_box == Some(key) {
                return None;
            }
            last_box = Some(key);
            let u = if dir > 0 { e0 - y1 } else { y0 - e1 };
            Some(Occluder {
                u,
                z: top,
                rho: 0.0,
            })
        } else {
            let yarn = geo.fabric.group(c).threads[rem(k, nc)];
            let u = if dir > 0 { p - y1 } else { y0 - p };
            last_box = None;
            Some(Occluder {
                u,
                z: yarn.height,
                rho: yarn.radius,
            })
        }
    })
}

/// The occluders on one side (`dir` = +1 or -1 along c) of the cross-section of `seg` over the
/// slice `(y0, y1)` of its piece over crossing `k`, as the micro-geometry has them there
/// ([`Variant::Sliced`]): each neighbour whose float covers the slice's middle, seen end-on;
/// else the crossing thread floating over that neighbour where its cylinder covers the middle,
/// as the near top corner of its float at the cylinder's mean height over the slice (the
/// slice's equal-area rectangle, eq. 3.1's rule along the axis); else nothing (the floor
/// shows). Outward, a float over several neighbours counted once.
pub(super) fn slice_profile<'a>(
    geo: &'a Geometry,
    seg: &'a Segment,
    k: isize,
    (y0, y1): (f64, f64),
    dir: isize,
) -> impl Iterator<Item = Occluder> + 'a {
    let y = 0.5 * (y0 + y1);
    let g = seg.group;
    let c = g.other();
    let weave = geo.fabric.weave();
    let (ng, nc) = (weave.n(g), weave.n(c));
    let mut last_box = None;
    (1..=ng as isize).filter_map(move |m| {
        let tt = seg.thread as isize + dir * m;
        let t = rem(tt, ng);
        let found = (k - 2..=k + 2).find_map(|kk| {
            if weave.on_top(g, t, rem(kk, nc)) {
                let si = geo.segment_at(g, t, kk).expect("own float");
                let s = &geo.segments[si];
                let covers = s.extent.is_none_or(|_| {
                    let (e0, e1) = extent_near(s, geo.position(c, kk), geo.period_along(g));
                    e0 <= y && y <= e1
                });
                covers.then(|| {
                    let yarn = geo.fabric.group(g).threads[t];
                    let p = geo.position(g, tt);
                    let disc = Occluder {
                        u: dir as f64 * (p - seg.axis),
                        z: yarn.height,
                        rho: yarn.radius,
                    };
                    (disc, None)
                })
            } else {
                let cy = geo.fabric.group(c).threads[rem(kk, nc)];
                let d = y - geo.position(c, kk);
                (d.abs() < cy.radius).then(|| {
                    let (o, id) = occluder_at(geo, seg, m, kk, dir);
                    let p = geo.position(c, kk);
                    let z = cy.height + mean_chord_height(cy.radius, y0 - p, y1 - p);
                    (Occluder { z, ..o }, id)
                })
            }
        });
        let Some((o, id)) = found else {
            last_box = None;
            return None;
        };
        if id.is_some() && id == last_box {
            return None;
        }
        last_box = id;
        Some(o)
    })
}

/// Whether two active tables have the same entries to within `tol` (lengths) and `tol` radians,
/// as the unit keys compare them: slices mirror images of one another across a crossing
/// cylinder's axis agree only to rounding.
pub(super) fn tables_alike(a: &ActiveTable, b: &ActiveTable, tol: f64) -> bool {
    a.entries.len() == b.entries.len()
        && a.entries
            .iter()
            .zip(&b.entries)
            .all(|((pa, oa), (pb, ob))| {
                (pa - pb).abs() <= KEY_TOLERANCE
                    && (oa.u - ob.u).abs() <= tol
                    && (oa.z - ob.z).abs() <= tol
                    && (oa.rho - ob.rho).abs() <= tol
            })
}

/// The mean over `d` in (a, b) of sqrt(r^2 - d^2), taken as 0 outside (-r, r): the mean height
/// above its axis of a cylinder of radius `r` seen side-on, over part of its width.
pub(super) fn mean_chord_height(r: f64, a: f64, b: f64) -> f64 {
    // Integral of sqrt(r^2 - d^2): (d sqrt(r^2 - d^2) + r^2 asin(d / r)) / 2.
    // A cut at the cylinder's edge lands within rounding of +-r, where the square root is
    // ill-conditioned (an error e in d moves it by sqrt(2 r e)): such a d is the edge.
    let f = |d: f64| {
        let d = if r - d.abs() <= 1e-9 * r {
            r.copysign(d)
        } else {
            d
        };
        0.5 * (d * ((r - d) * (r + d)).sqrt() + r * r * (d / r).asin())
    };
    (f(b) - f(a)) / (b - a)
}

/// The slices of the piece of `seg` over crossing `k` with range `range` ([`Variant::Sliced`]):
/// cut where a crossing cylinder begins or ends and where a float of the nearest two neighbours
/// on either side does; the parts under a crossing cylinder split in `parts.0`, the others in
/// `parts.1`. Each is its range and the coordinate its profile is taken at (its middle).
pub(super) fn slices_of(
    geo: &Geometry,
    seg: &Segment,
    k: isize,
    range: (f64, f64),
    parts: (usize, usize),
) -> Vec<((f64, f64), f64)> {
    let g = seg.group;
    let c = g.other();
    let weave = geo.fabric.weave();
    let (ng, nc) = (weave.n(g), weave.n(c));
    let (lo, hi) = range;
    let mut cuts = vec![lo, hi];
    let mut under: Vec<(f64, f64)> = Vec::new();
    for kk in k - 2..=k + 2 {
        let r = geo.fabric.group(c).threads[rem(kk, nc)].radius;
        let p = geo.position(c, kk);
        cuts.extend([p - r, p + r]);
        under.push((p - r, p + r));
        for tt in [-2, -1, 1, 2].map(|m| rem(seg.thread as isize + m, ng)) {
            if let Some(si) = geo.segment_at(g, tt, kk) {
                if geo.segments[si].extent.is_some() {
                    let (e0, e1) = extent_near(&geo.segments[si], p, geo.period_along(g));
                    cuts.extend([e0, e1]);
                }
            }
        }
    }
    // Cuts closer than this to one another are one (rounding of the same position).
    let tiny = 1e-9 * (hi - lo);
    cuts.retain(|&x| x >= lo && x <= hi);
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| *a - *b <= tiny);
    *cuts.last_mut().expect("two cuts") = hi;
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b - a <= tiny {
            continue;
        }
        let mid = 0.5 * (a + b);
        let n = if under.iter().any(|&(x0, x1)| x0 < mid && mid < x1) {
            parts.0
        } else {
            parts.1
        };
        for j in 0..n {
            let y0 = a + (b - a) * j as f64 / n as f64;
            let y1 = if j + 1 == n {
                b
            } else {
                a + (b - a) * (j + 1) as f64 / n as f64
            };
            out.push(((y0, y1), 0.5 * (y0 + y1)));
        }
    }
    out
}

/// The distinct (radius, height) of a group's threads: the shapes its threads take as discs in
/// a profile.
pub(super) fn disc_shapes(fabric: &Fabric, g: Group) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    for y in &fabric.group(g).threads {
        if !out.iter().any(|&(r, h)| r == y.radius && h == y.height) {
            out.push((y.radius, y.height));
        }
    }
    out
}

/// Two pieces are one unit when every component of their keys agrees to within this.
pub(super) const KEY_TOLERANCE: f64 = 1e-9;

/// The unit of length of unit keys: the fabric's smallest radius. Only ratios of lengths
/// matter, so keys compare lengths relative to the yarns: a fabric scaled down must not merge
/// pieces that differ, nor one scaled up keep apart pieces that differ by rounding.
pub(super) fn key_length_unit(fabric: &Fabric) -> f64 {
    [Group::Warp, Group::Weft]
        .iter()
        .flat_map(|&g| fabric.group(g).threads.iter().map(|y| y.radius))
        .fold(f64::INFINITY, f64::min)
}

/// The key of a unit's neighbour pair, written into `key`: the unit, then each neighbour's
/// distance, radius, height and float extent along the axis relative to the piece (lengths
/// divided by `unit`; an endless float as +-1e300).
pub(super) fn neighbour_key(
    unit_id: usize,
    nbs: &[Option<Neighbour>; 2],
    unit: f64,
    key: &mut Vec<f64>,
) {
    let along = |x: f64| {
        if x.is_finite() {
            x / unit
        } else {
            x.signum() * 1e300
        }
    };
    key.clear();
    key.push(unit_id as f64);
    for nb in nbs {
        key.extend(nb.map_or([0.0; 5], |n| {
            [
                n.d / unit,
                n.radius / unit,
                n.height / unit,
                along(n.axial.0),
                along(n.axial.1),
            ]
        }));
    }
}

/// Appends an active table to a unit key, lengths divided by `unit`.
pub(super) fn table_key(t: &ActiveTable, unit: f64, out: &mut Vec<f64>) {
    out.push(t.entries.len() as f64);
    for (psi, o) in &t.entries {
        out.extend([*psi, o.u / unit, o.z / unit, o.rho / unit]);
    }
}

impl AnalyticModel {
    /// Preprocesses the weave period with the default variant, which takes every period (a
    /// test holds it: a default with limits would make this constructor fallible).
    pub fn new(fabric: &Fabric, facet: FacetModel) -> Self {
        Self::build(fabric, facet, Variant::default(), true)
    }

    /// Preprocesses the weave period: pieces, active-occluder tables (the cylinder scan),
    /// and independent units with their multiplicities. Refused, before any work, where the
    /// variant does not take the period ([`Variant::check`]).
    pub fn with_variant(
        fabric: &Fabric,
        facet: FacetModel,
        variant: Variant,
    ) -> Result<Self, VariantError> {
        variant.check(fabric)?;
        Ok(Self::build(fabric, facet, variant, true))
    }

    /// The preprocessing; `merge` false keeps every piece its own unit (tests: merging must
    /// not change the intensity).
    pub(super) fn build(fabric: &Fabric, facet: FacetModel, variant: Variant, merge: bool) -> Self {
        let geo = Geometry::new(fabric);
        let grid = CellGrid::new(&geo.warp_pos, geo.period.0, &geo.weft_pos, geo.period.1);
        let (nx, ny) = grid.dims();
        let mut cell_units = vec![(u32::MAX, 0); nx * ny];
        let mut units: Vec<Unit> = Vec::new();
        let mut index = UnitIndex::new(KEY_TOLERANCE);
        // Classes: the unit keys without the diffuse albedos.
        let mut classes = UnitIndex::new(KEY_TOLERANCE);
        let mut unit_class: Vec<u32> = Vec::new();
        let mut class_unit: Vec<u32> = Vec::new();
        // Neighbour pairs of each unit: keys [unit, neighbours...] -> (unit, its variant).
        let mut pairs = UnitIndex::new(KEY_TOLERANCE);
        let mut pair_at: Vec<(usize, usize)> = Vec::new();
        let unit_len = key_length_unit(fabric);
        let discs = [
            disc_shapes(fabric, Group::Warp),
            disc_shapes(fabric, Group::Weft),
        ];
        // Buffers reused from piece to piece: the shapes a profile can hold and the keys.
        let mut end_shapes: Vec<(f64, f64)> = Vec::new();
        let mut side_shapes: Vec<(f64, f64)> = Vec::new();
        let mut key: Vec<f64> = Vec::new();
        let mut pair_key: Vec<f64> = Vec::new();
        for seg in &geo.segments {
            let g = seg.group;
            let c = g.other();
            let top = equal_area_height(seg.radius, seg.height);
            // What the profiles can hold (scan_ordered): along the axis, the crossing threads
            // end-on and this thread's own floats side-on, within a period and a half.
            end_shapes.clear();
            end_shapes.extend_from_slice(&discs[c as usize]);
            end_shapes.push((0.0, top));
            let end_u = 3.0 * geo.period_along(g);
            let (end_plus, end_minus) = match seg.extent {
                Some(_) => (
                    ActiveTable::scan_ordered(end_profile(&geo, seg, top, 1), &end_shapes, end_u),
                    ActiveTable::scan_ordered(end_profile(&geo, seg, top, -1), &end_shapes, end_u),
                ),
                None => Default::default(),
            };
            let data = SegmentData {
                group: g,
                radius: seg.radius,
                height: seg.height,
                top,
                floor: ArcTrig::new(Arc::above_floor(seg.radius, seg.height)),
                extent: seg.extent,
                end_plus,
                end_minus,
                material: fabric.thread_material(g, seg.thread),
            };
            let mid = |k: isize| 0.5 * (geo.position(c, k - 1) + geo.position(c, k));
            let a = seg.float.start as isize;
            let f = seg.float.len as isize;
            for m in 0..f {
                let k = a + m;
                let lo = match seg.extent {
                    Some((y0, _)) if m == 0 => y0,
                    _ => mid(k),
                };
                let hi = match seg.extent {
                    Some((_, y1)) if m == f - 1 => y1,
                    _ => mid(k + 1),
                };
                // Across it: the parallel threads end-on and crossing thread k side-on, within
                // a period.
                let cross_yarn = fabric.group(c).threads[rem(k, geo.fabric.weave().n(c))];
                side_shapes.clear();
                side_shapes.extend_from_slice(&discs[g as usize]);
                side_shapes.push((0.0, equal_area_height(cross_yarn.radius, cross_yarn.height)));
                let side_u = 2.0 * geo.period_across(g);
                let neighbour = |dir: isize| {
                    let (o, id) = occluder_at(&geo, seg, 1, k, dir);
                    if id.is_some() {
                        return None;
                    }
                    let t = seg.thread as isize + dir;
                    let nt = rem(t, geo.fabric.weave().n(g));
                    let yarn = geo.fabric.group(g).threads[nt];
                    let mid = 0.5 * (lo + hi);
                    let axial = match geo.segment_at(g, nt, k).map(|i| &geo.segments[i]) {
                        Some(s) if s.extent.is_some() => {
                            let (e0, e1) = extent_near(s, geo.position(c, k), geo.period_along(g));
                            (e0 - mid, e1 - mid)
                        }
                        _ => (f64::NEG_INFINITY, f64::INFINITY),
                    };
                    Some(Neighbour {
                        d: o.u,
                        radius: yarn.radius,
                        height: yarn.height,
                        axial,
                        material: geo.fabric.thread_material(g, nt),
                    })
                };
                let nbs = [neighbour(1), neighbour(-1)];
                let side_plus =
                    ActiveTable::scan_ordered(side_profile(&geo, seg, k, 1), &side_shapes, side_u);
                let side_minus =
                    ActiveTable::scan_ordered(side_profile(&geo, seg, k, -1), &side_shapes, side_u);
                let mut slices: Vec<Slice> = Vec::new();
                let around =
                    (variant == Variant::Sliced3d).then(|| around::Around::of(&geo, seg, (lo, hi)));
                if variant == Variant::Sliced3d {
                    // Each slice sees its own surroundings (`around`): one range a slice, and no
                    // side tables (what hides its arc is found in 3-D).
                    for (range, _) in slices_of(&geo, seg, k, (lo, hi), SLICE3D_PARTS) {
                        slices.push(Slice {
                            ranges: vec![range],
                            side_plus: ActiveTable::default(),
                            side_minus: ActiveTable::default(),
                        });
                    }
                } else if variant == Variant::Sliced {
                    for (range, _) in slices_of(&geo, seg, k, (lo, hi), (SLICE_PARTS, 1)) {
                        let table = |dir| {
                            let profile: Vec<Occluder> =
                                slice_profile(&geo, seg, k, range, dir).collect();
                            ActiveTable::scan(&profile)
                        };
                        let (plus, minus) = (table(1), table(-1));
                        let alike = |a: &ActiveTable, b: &ActiveTable| {
                            tables_alike(a, b, KEY_TOLERANCE * unit_len)
                        };
                        match slices
                            .iter_mut()
                            .find(|s| alike(&s.side_plus, &plus) && alike(&s.side_minus, &minus))
                        {
                            Some(s) => s.ranges.push(range),
                            None => slices.push(Slice {
                                ranges: vec![range],
                                side_plus: plus,
                                side_minus: minus,
                            }),
                        }
                    }
                }
                // Key: everything the unit's reflection depends on, relative to its segment,
                // lengths in units of `unit_len`.
                let origin = seg.extent.map_or(lo, |e| e.0);
                key.clear();
                key.extend([
                    g as u8 as f64,
                    seg.radius / unit_len,
                    seg.height / unit_len,
                    seg.extent.map_or(-1.0, |e| (e.1 - e.0) / unit_len),
                    (lo - origin) / unit_len,
                    (hi - origin) / unit_len,
                ]);
                let mat = data.material;
                key.extend([mat.specular, mat.exponent]);
                for t in [&side_plus, &side_minus, &data.end_plus, &data.end_minus] {
                    table_key(t, unit_len, &mut key);
                }
                for sl in &slices {
                    key.push(sl.ranges.len() as f64);
                    for r in &sl.ranges {
                        key.extend([(r.0 - origin) / unit_len, (r.1 - origin) / unit_len]);
                    }
                    table_key(&sl.side_plus, unit_len, &mut key);
                    table_key(&sl.side_minus, unit_len, &mut key);
                }
                if let Some(a) = &around {
                    a.key(origin, unit_len, &mut key);
                }
                // The class key: the unit key without the albedos that follow.
                let class_len = key.len();
                key.extend(mat.albedo);
                // Per-thread colours: the neighbours' albedos enter the secondary reflection.
                for nb in &nbs {
                    key.extend(nb.map_or([-1.0; 3], |n| n.material.albedo));
                }
                let cell = grid.index(grid.crossing(g, seg.thread, k));
                let Some(i) = merge.then(|| index.find_or_insert(&key)).flatten() else {
                    if merge {
                        neighbour_key(units.len(), &nbs, unit_len, &mut pair_key);
                        pairs.find_or_insert(&pair_key);
                        pair_at.push((units.len(), 0));
                    }
                    let found = merge.then(|| classes.find_or_insert(&key[..class_len]));
                    let class = match found.flatten() {
                        Some(c) => c as u32,
                        None => {
                            class_unit.push(units.len() as u32);
                            class_unit.len() as u32 - 1
                        }
                    };
                    unit_class.push(class);
                    cell_units[cell] = (units.len() as u32, 0);
                    units.push(Unit {
                        seg: data.clone(),
                        range: (lo, hi),
                        neighbours: vec![(nbs, 1)],
                        side_plus,
                        side_minus,
                        count: 1,
                        slices,
                        around,
                        first_slice: 0,
                    });
                    continue;
                };
                units[i].count += 1;
                // The neighbours' sizes, distance and float extent along the axis.
                neighbour_key(i, &nbs, unit_len, &mut pair_key);
                let variant = match pairs.find_or_insert(&pair_key) {
                    Some(v) => {
                        units[i].neighbours[pair_at[v].1].1 += 1;
                        pair_at[v].1
                    }
                    None => {
                        pair_at.push((i, units[i].neighbours.len()));
                        units[i].neighbours.push((nbs, 1));
                        units[i].neighbours.len() - 1
                    }
                };
                cell_units[cell] = (i as u32, variant as u32);
            }
        }
        // Classes with the second bounce: a cell's class and its neighbours' geometry.
        let mut bounce_index = UnitIndex::new(KEY_TOLERANCE);
        let mut bounce_unit: Vec<(u32, u32)> = Vec::new();
        let bounce_class = cell_units
            .iter()
            .map(|&(u, var)| {
                let nbs = &units[u as usize].neighbours[var as usize].0;
                neighbour_key(
                    unit_class[u as usize] as usize,
                    nbs,
                    unit_len,
                    &mut pair_key,
                );
                match bounce_index.find_or_insert(&pair_key) {
                    Some(b) => b as u32,
                    None => {
                        bounce_unit.push((u, var));
                        bounce_unit.len() as u32 - 1
                    }
                }
            })
            .collect();
        let mut first_slice = 0;
        for u in units.iter_mut().filter(|u| u.around.is_some()) {
            u.first_slice = first_slice;
            first_slice += u.slices.len();
        }
        AnalyticModel {
            arc_store: open_arcs::ArcStore::default(),
            arcs_key: open_arcs::model_key(&units),
            facet,
            variant,
            lanes: if variant == Variant::Sliced3d {
                None
            } else {
                batch::lanes(facet, &units)
            },
            units,
            grid,
            cell_units,
            unit_class,
            class_unit,
            bounce_class,
            bounce_unit,
        }
    }
}
