//! Evaluation for one pair of directions (thesis eqs 3.4-3.6, 4.2-4.11): per unit, the visible
//! and lit arc, the length its ends' occluders leave, the projected areas and the arc integrals
//! of the facet terms; then the area-weighted average over the units.

use super::*;

/// A direction as the units of one group see it, computed once per evaluation rather than per
/// unit (issue 22): the projection on their cross-section plane in polar form, the elevation
/// their side tables are read at, and its axial component with the elevation their end tables
/// are read at.
#[derive(Clone, Copy, Debug)]
pub(super) struct View {
    /// Projection on the cross-section plane.
    pub(super) p: Polar,
    /// Elevation from the side it comes from: (psi, mirrored: from the -c side); `None` in the
    /// plane of the axis and the normal (|V.c| <= EPS).
    pub(super) side: Option<(Elevation, bool)>,
    /// Component along the axis.
    pub(super) va: f64,
    /// Elevation along the axis from the end it comes from; `None` across it (|V.a| <= EPS).
    pub(super) end: Option<Elevation>,
    /// [`Variant::Sliced3d`]: the place of the direction's open arcs in the model's store,
    /// where kept ([`AnalyticModel::keep_open_arcs`]).
    pub(super) kept: Option<u32>,
}

impl View {
    /// The views of `v` from the warp's units and from the weft's. A warp's cross-section is
    /// the XZ plane and its axis Y, a weft's the other way round, so the two share the
    /// direction's two elevations atan2(z, |x|) and atan2(z, |y|).
    pub(super) fn both(v: Vec3) -> [View; 2] {
        let (ex, ey) = (Elevation::of(v.z, v.x.abs()), Elevation::of(v.z, v.y.abs()));
        [
            View::new(v.x, v.y, v.z, ex, ey),
            View::new(v.y, v.x, v.z, ey, ex),
        ]
    }

    /// The view of a direction with components `vc` across, `va` along and `vz` up, and
    /// elevations `ec` = atan2(vz, |vc|) and `ea` = atan2(vz, |va|).
    pub(super) fn new(vc: f64, va: f64, vz: f64, ec: Elevation, ea: Elevation) -> View {
        let mirrored = vc < 0.0;
        let norm = (vc * vc + vz * vz).sqrt();
        let p = Polar {
            p: Projected { c: vc, z: vz },
            angle: if mirrored { PI - ec.psi } else { ec.psi },
            norm,
            cos: if mirrored { -ec.cos } else { ec.cos },
            sin: ec.sin,
        };
        View {
            p,
            side: (vc.abs() > EPS).then_some((ec, mirrored)),
            va,
            end: (va.abs() > EPS).then_some(ea),
            kept: None,
        }
    }
}

/// The views of light and eye (and of the Huo half vector) for the units of one group.
#[derive(Clone, Copy, Debug)]
pub(super) struct Views {
    pub(super) l: View,
    pub(super) e: View,
    /// The projected unit half vector (L + E) / |L + E|, for the Huo facets' closed form.
    pub(super) h: Heading,
}

impl Views {
    /// The views of the warp's units and of the weft's.
    pub(super) fn both(wi: UnitVec3, wo: UnitVec3) -> [Views; 2] {
        let (l, e) = (wi.get(), wo.get());
        let [lw, lf] = View::both(l);
        let [ew, ef] = View::both(e);
        let h = l + e;
        let h = h * (1.0 / h.length());
        let hp = |c: f64| Heading::new(Projected { c, z: h.z });
        [
            Views {
                l: lw,
                e: ew,
                h: hp(h.x),
            },
            Views {
                l: lf,
                e: ef,
                h: hp(h.y),
            },
        ]
    }
}

/// What of a unit the eye sees.
pub(super) struct Visible {
    /// The visible arc of the cross-section (above the floor, not self- or neighbour-hidden).
    pub(super) arc: ArcTrig,
    /// The interval along the axis the ends' occluders leave visible.
    pub(super) along: (f64, f64),
    /// Visible length l_v within the piece.
    pub(super) l_v: f64,
    /// Projected width of the visible arc, with |E_p|.
    pub(super) width: f64,
}

/// The sums of eq. 4.11 over the units, in the units' order: the visible projected area
/// sum_i D_i S_v,i and the lit terms sum_i D_i l_vi,i r_i (diffuse factor times albedo, specular
/// intensity). One place for the weighting, whatever computed the units' terms (unit by unit, or
/// a pair's units in AVX2 lanes).
#[derive(Default)]
pub(super) struct Sums {
    pub(super) s_total: f64,
    pub(super) i_d: [f64; 3],
    pub(super) i_s: f64,
}

impl Sums {
    /// Adds unit `u`'s visible projected area, l_v times the visible arc's projected width,
    /// times its multiplicity D_i (eq. 4.3).
    #[inline(always)]
    pub(super) fn seen(&mut self, u: &Unit, l_v: f64, width: f64) {
        self.s_total += u.count as f64 * l_v * width;
    }

    /// Adds unit `u`'s lit terms: lit and visible length `l_vi`, and the arc integrals of the
    /// diffuse factor `kd` and the specular intensity `ks` (eqs 4.4-4.10).
    #[inline(always)]
    pub(super) fn lit(&mut self, u: &Unit, l_vi: f64, kd: f64, ks: f64) {
        let w = u.count as f64 * l_vi * u.seg.radius;
        for (acc, a) in self.i_d.iter_mut().zip(u.seg.material.albedo) {
            *acc += w * kd * a;
        }
        self.i_s += w * ks;
    }

    /// Adds unit `u`'s visible area and, where some of it is lit, its lit terms (`seen`,
    /// `lit`).
    #[inline(always)]
    pub(super) fn add(&mut self, u: &Unit, l_v: f64, width: f64, lit: Option<(f64, f64, f64)>) {
        self.seen(u, l_v, width);
        if let Some((l_vi, kd, ks)) = lit {
            self.lit(u, l_vi, kd, ks);
        }
    }

    /// I_d and I_s, the lit terms over the visible area (eq. 4.11); zero where nothing is
    /// visible.
    #[inline(always)]
    pub(super) fn reflection(&self) -> Reflection {
        let s = self.s_total;
        if s <= 0.0 {
            return Reflection::default();
        }
        Reflection {
            i_d: self.i_d.map(|x| x / s),
            i_s: [self.i_s / s; 3],
            secondary: None,
        }
    }
}

/// A sliced unit's sums over its slices ([`Variant::Sliced`]), in the slices' order: the
/// visible length and area, the lit length and the lit-length-weighted arc integrals. One place
/// for them, whether the slices were evaluated one by one or in AVX2 lanes.
#[derive(Default)]
pub(super) struct SliceSums {
    pub(super) l_v: f64,
    pub(super) s_v: f64,
    pub(super) l_vi: f64,
    pub(super) kd: f64,
    pub(super) ks: f64,
}

impl SliceSums {
    /// Adds a slice's visible length `l_v` and area `l_v` times `width`.
    #[inline(always)]
    pub(super) fn seen(&mut self, l_v: f64, width: f64) {
        self.l_v += l_v;
        self.s_v += l_v * width;
    }

    /// Adds a slice's lit and visible length `l_vi` and its arc integrals `kd`, `ks`.
    #[inline(always)]
    pub(super) fn lit(&mut self, l_vi: f64, kd: f64, ks: f64) {
        self.l_vi += l_vi;
        self.kd += l_vi * kd;
        self.ks += l_vi * ks;
    }

    /// The unit's visible length, its width S_v / l_v, and its lit length with the integrals'
    /// lit-length-weighted means; `None` where no slice is visible.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    pub(super) fn unit(&self) -> Option<(f64, f64, Option<(f64, f64, f64)>)> {
        if self.l_v <= 0.0 {
            return None;
        }
        let lit = (self.l_vi > 0.0).then(|| (self.l_vi, self.kd / self.l_vi, self.ks / self.l_vi));
        Some((self.l_v, self.s_v / self.l_v, lit))
    }
}

/// A unit's share of eq. 4.11 for one pair of directions, before the multiplicity D_i.
pub(super) struct UnitTerms {
    /// Visible length l_v along the axis (within the piece).
    pub(super) l_v: f64,
    /// Projected width of the visible arc (with |E_p|): S_v = l_v * width (eq. 4.3).
    pub(super) width: f64,
    /// Secondary reflection per unit visible length from each neighbour pair asked for, from
    /// the +c and the -c side, with the number of pieces beside that pair (empty with one
    /// bounce).
    pub(super) secondary: Vec<([Secondary; 2], u32)>,
    /// Lit and visible length l_vi and the arc integrals of the facet's diffuse factor and
    /// specular intensity (eqs 4.4-4.10); `None` where no point is both lit and visible.
    pub(super) lit: Option<(f64, f64, f64)>,
}

/// [`AnalyticModel::side_arc`] of a segment with the side tables `(plus, minus)`.
pub(super) fn side_arc_in(
    seg: &SegmentData,
    (plus, minus): (&ActiveTable, &ActiveTable),
    v: &View,
) -> ArcTrig {
    let mut arc = ArcTrig::facing(&v.p);
    let Some((psi, mirrored)) = v.side else {
        return arc;
    };
    let table = if mirrored { minus } else { plus };
    let Some(o) = table.active(psi.psi) else {
        return arc;
    };
    match occluded_arc_at(seg.radius, seg.height, o, &psi) {
        ArcOcclusion::None => {}
        ArcOcclusion::All => {
            arc.arc.hi = arc.arc.lo;
            arc.hi = arc.lo;
        }
        ArcOcclusion::UpTo(t, (s, c)) if mirrored => {
            // pi - t
            if PI - t < arc.arc.hi {
                arc.arc.hi = PI - t;
                arc.hi = (s, -c);
            }
        }
        ArcOcclusion::UpTo(t, sc) => {
            if t > arc.arc.lo {
                arc.arc.lo = t;
                arc.lo = sc;
            }
        }
    }
    arc
}

pub(super) fn meet(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0.max(b.0), a.1.min(b.1))
}

pub(super) fn overlap(a: (f64, f64), b: (f64, f64)) -> f64 {
    let (lo, hi) = meet(a, b);
    (hi - lo).max(0.0)
}

impl AnalyticModel {
    /// Directly reflected intensity toward `wo` for unit light from `wi` (eq. 4.11): the
    /// visible-area-weighted average over the units of the period. Zero when either direction
    /// is at or below the horizon.
    pub fn intensity(&self, wi: UnitVec3, wo: UnitVec3) -> Reflection {
        self.intensity_with(wi, wo, None)
    }

    /// As [`AnalyticModel::intensity`], adding the secondary reflection I_2 between adjacent
    /// parallel cylinders (thesis ch. 5; for cloth, sec. 5.4's approximation) when `secondary`
    /// is given. I_2 is averaged over the same visible projected area as I_1.
    pub fn intensity_with(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
    ) -> Reflection {
        if secondary.is_none() && wi.above_horizon() && wo.above_horizon() {
            if let Some(r) = self.intensity_in_lanes(wi, wo) {
                return r;
            }
        }
        self.intensity_of_units(wi, wo, secondary)
    }

    /// [`AnalyticModel::intensity_with`] unit by unit (what the lanes are checked against).
    pub(super) fn intensity_of_units(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
    ) -> Reflection {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return Reflection {
                secondary: secondary.map(|_| Secondary::default()),
                ..Reflection::default()
            };
        }
        let mut sums = Sums::default();
        let mut i_2 = Secondary::default();
        let views = self.views(wi, wo);
        for u in &self.units {
            let v = &views[u.seg.group as usize];
            let Some(t) = self.unit_terms(u, &u.neighbours, v, wi, wo, secondary, false) else {
                continue;
            };
            sums.add(u, t.l_v, t.width, t.lit);
            for (s, n) in &t.secondary {
                i_2.add_scaled(&both_sides(s), f64::from(*n) * t.l_v);
            }
        }
        let (direct, s_total) = (sums.reflection(), sums.s_total);
        Reflection {
            secondary: secondary.map(|_| {
                if s_total <= 0.0 {
                    Secondary::default()
                } else {
                    i_2.scaled(1.0 / s_total)
                }
            }),
            ..direct
        }
    }

    /// What of unit `u` is visible from the eye's view `e`: `None` where nothing is.
    pub(super) fn visible(&self, u: &Unit, e: &View) -> Option<Visible> {
        let arc = self.side_arc(u, e).meet(&u.seg.floor);
        self.visible_of(u, std::slice::from_ref(&u.range), e, arc)
    }

    /// The visible length l_v and projected width of unit `u` from the eye's view `e`, whose
    /// product is its visible projected area S_v (eq. 4.3); of its slices summed with
    /// [`Variant::Sliced`] (the width then S_v / l_v).
    pub(super) fn seen_area(&self, u: &Unit, e: &View) -> Option<(f64, f64)> {
        if u.slices.is_empty() {
            return self.visible(u, e).map(|v| (v.l_v, v.width));
        }
        let (l_v, s_v) = u
            .slices
            .iter()
            .enumerate()
            .filter_map(|(k, sl)| self.slice_visible(u, k, sl, e))
            .fold((0.0, 0.0), |(l, s), v| (l + v.l_v, s + v.l_v * v.width));
        (l_v > 0.0).then(|| (l_v, s_v / l_v))
    }

    /// What of the slice `sl` (its `k`th) of unit `u` the eye's view `e` sees ([`Visible`]
    /// over the slice's ranges).
    pub(super) fn slice_visible(
        &self,
        u: &Unit,
        k: usize,
        sl: &Slice,
        e: &View,
    ) -> Option<Visible> {
        self.visible_of(u, &sl.ranges, e, self.slice_arc(u, k, sl, e))
    }

    /// As [`AnalyticModel::visible`] over the parts `ranges` of the piece, given the arc of the
    /// cross-section that faces the eye above the floor and not behind the side neighbour.
    pub(super) fn visible_of(
        &self,
        u: &Unit,
        ranges: &[(f64, f64)],
        e: &View,
        arc: ArcTrig,
    ) -> Option<Visible> {
        let seg = &u.seg;
        if arc.arc.is_empty() {
            return None;
        }
        let along = self.end_interval(u, e, &arc, e.p.p);
        let l_v: f64 = ranges.iter().map(|&r| overlap(r, along)).sum();
        if l_v <= 0.0 {
            return None;
        }
        Some(Visible {
            arc,
            along,
            l_v,
            width: projected_width(seg.radius, &arc, e.p.p),
        })
    }

    /// Unit `u`'s terms of eq. 4.11 (and of I_2 with `secondary`, from threads of albedo 1 when
    /// `white`) for light from `wi` seen from `wo` (both above the horizon; `views` of its
    /// group): `None` where nothing of it is visible.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn unit_terms(
        &self,
        u: &Unit,
        variants: &[([Option<Neighbour>; 2], u32)],
        views: &Views,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
        white: bool,
    ) -> Option<UnitTerms> {
        if !u.slices.is_empty() {
            return self.sliced_terms(u, variants, views, wi, wo, secondary, white);
        }
        let seg = &u.seg;
        // The eye's and the light's arcs first: two independent chains of divisions and
        // square roots that the processor can overlap.
        let seen = self.side_arc(u, &views.e).meet(&seg.floor);
        let lit = self.side_arc(u, &views.l).meet(&seg.floor);
        let v = self.visible_of(u, std::slice::from_ref(&u.range), &views.e, seen)?;
        let ep = views.e.p.p;
        let vi = v.arc.meet(&lit);
        let lit_len = self.end_interval(u, &views.l, &vi, ep);
        let secondary = secondary.map_or_else(Vec::new, |opts| {
            let (l, e) = (wi.get(), wo.get());
            variants
                .iter()
                .map(|(nbs, n)| {
                    let sides = self.secondary(u, nbs, opts, l, e, (v.arc.arc, lit.arc), white);
                    (sides, *n)
                })
                .collect()
        });
        let l_vi = overlap(u.range, meet(v.along, lit_len));
        let lit = (!vi.arc.is_empty() && l_vi > 0.0).then(|| {
            let (kd, ks) = self.arc_integral(&seg.material, seg.group, &vi, views, wi, wo);
            (l_vi, kd, ks)
        });
        Some(UnitTerms {
            l_v: v.l_v,
            width: v.width,
            secondary,
            lit,
        })
    }

    /// [`AnalyticModel::unit_terms`] of a unit in slices ([`Variant::Sliced`]): each slice's
    /// visible area, lit length and arc integrals summed, given back as one piece's terms (the
    /// width is S_v / l_v, the integrals the lit-length-weighted means, the secondary
    /// reflection per unit visible length).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn sliced_terms(
        &self,
        u: &Unit,
        variants: &[([Option<Neighbour>; 2], u32)],
        views: &Views,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
        white: bool,
    ) -> Option<UnitTerms> {
        let seg = &u.seg;
        let ep = views.e.p.p;
        let mut sums = SliceSums::default();
        let mut sec: Vec<([Secondary; 2], u32)> = match secondary {
            Some(_) => variants
                .iter()
                .map(|(_, n)| ([Secondary::default(); 2], *n))
                .collect(),
            None => Vec::new(),
        };
        for (k, sl) in u.slices.iter().enumerate() {
            let Some(v) = self.slice_visible(u, k, sl, &views.e) else {
                continue;
            };
            let lit = self.slice_arc(u, k, sl, &views.l);
            sums.seen(v.l_v, v.width);
            if let Some(opts) = secondary {
                let (l, e) = (wi.get(), wo.get());
                for ((acc, _), (nbs, _)) in sec.iter_mut().zip(variants) {
                    let sides = self.secondary(u, nbs, opts, l, e, (v.arc.arc, lit.arc), white);
                    for (a, s) in acc.iter_mut().zip(&sides) {
                        a.add_scaled(s, v.l_v);
                    }
                }
            }
            let vi = v.arc.meet(&lit);
            let lit_len = self.end_interval(u, &views.l, &vi, ep);
            let lit_along = meet(v.along, lit_len);
            let li: f64 = sl.ranges.iter().map(|&r| overlap(r, lit_along)).sum();
            if !vi.arc.is_empty() && li > 0.0 {
                let (d, s) = self.arc_integral(&seg.material, seg.group, &vi, views, wi, wo);
                sums.lit(li, d, s);
            }
        }
        let (l_v, width, lit) = sums.unit()?;
        for (acc, _) in &mut sec {
            *acc = acc.map(|a| a.scaled(1.0 / l_v));
        }
        Some(UnitTerms {
            l_v,
            width,
            secondary: sec,
            lit,
        })
    }

    /// Arc of the unit's cross-section that faces `v` and is not hidden by a neighbour on the
    /// side `v` comes from (self-shadowing/blocking plus eqs 3.4-3.5 via the active table).
    pub(super) fn side_arc(&self, u: &Unit, v: &View) -> ArcTrig {
        side_arc_in(&u.seg, (&u.side_plus, &u.side_minus), v)
    }

    /// The arc of slice `sl` (its `k`th) of unit `u` that faces `v` above the floor and that
    /// nothing beside it hides: by the slice's side tables, or ([`Variant::Sliced3d`]) by the
    /// floats around the piece at the middle of the slice's one range (kept, where `v`'s
    /// direction's arcs are).
    pub(super) fn slice_arc(&self, u: &Unit, k: usize, sl: &Slice, v: &View) -> ArcTrig {
        let seg = &u.seg;
        match &u.around {
            Some(around) => {
                if let Some(place) = v.kept {
                    return self.arc_store.arc(place, u.first_slice + k);
                }
                let (y0, y1) = sl.ranges[0];
                let arc = ArcTrig::facing(&v.p).meet(&seg.floor);
                around.open_arc(seg.radius, seg.height, 0.5 * (y0 + y1), v, arc)
            }
            None => side_arc_in(seg, sl.tables(), v).meet(&seg.floor),
        }
    }

    /// [`Views::both`], with the places of the directions' open arcs where kept.
    pub(super) fn views(&self, wi: UnitVec3, wo: UnitVec3) -> [Views; 2] {
        let mut views = Views::both(wi, wo);
        let (l, e) = (self.arc_store.find(wi), self.arc_store.find(wo));
        if l.is_some() || e.is_some() {
            for v in &mut views {
                v.l.kept = l;
                v.e.kept = e;
            }
        }
        views
    }
    /// Interval along the axis not hidden by the occluders at the end that direction `v` comes
    /// from (eq. 3.6 via the active table). `arc` and `e` give the points and weights the
    /// refined variant averages over.
    pub(super) fn end_interval(
        &self,
        u: &Unit,
        v: &View,
        arc: &ArcTrig,
        e: Projected,
    ) -> (f64, f64) {
        let Some((y0, y1)) = u.seg.extent else {
            return (f64::NEG_INFINITY, f64::INFINITY);
        };
        let Some(psi) = v.end else {
            return (y0, y1);
        };
        if u.around.is_some() {
            // Sliced3d: what lies along the axis hides the arc itself (`slice_arc`).
            return (y0, y1);
        }
        let seg = &u.seg;
        let table = if v.va > 0.0 {
            &seg.end_plus
        } else {
            &seg.end_minus
        };
        let hidden = table.active(psi.psi).map_or(0.0, |o| match self.variant {
            Variant::Thesis => occluded_length(seg.top, o, &psi),
            Variant::Refined | Variant::Sliced | Variant::Sliced3d => {
                mean_occluded_length(seg.radius, seg.height, o, &psi, arc, e, y1 - y0)
            }
        });
        if v.va > 0.0 {
            (y0, y1 - hidden)
        } else {
            (y0 + hidden, y1)
        }
    }

    /// Integrals over the arc of the facet's diffuse factor and specular intensity, each times
    /// N.E (the cos(theta - theta_E) correction of eqs 4.7 and 4.9, times |E_p|).
    pub(super) fn arc_integral(
        &self,
        m: &Material,
        g: Group,
        arc: &ArcTrig,
        views: &Views,
        wi: UnitVec3,
        wo: UnitVec3,
    ) -> (f64, f64) {
        let kd = diffuse_integral(arc, views.l.p.p, views.e.p.p);
        if m.specular == 0.0 {
            return (kd, 0.0);
        }
        if self.facet == FacetModel::Huo {
            let e = Heading::from(&views.e.p);
            if let Some(s) = huo_specular_integral(arc, &views.h, &e, m.exponent) {
                return (kd, m.specular * s);
            }
        }
        let arc = arc.arc;
        // Quadrature of the facet model, split at the specular peak.
        let (c, _) = frame(g);
        let (l, e) = (wi.get(), wo.get());
        let mut f = |t: f64| {
            let n = c * t.cos() + Vec3::new(0.0, 0.0, t.sin());
            self.facet.intensity(m, n, l, e).specular * n.dot(e).max(0.0)
        };
        let h = l + e;
        let peak = Projected {
            c: h.dot(c),
            z: h.z,
        }
        .angle()
        .clamp(arc.lo, arc.hi);
        let tol = 1e-10 * (arc.hi - arc.lo);
        let s = integrate(&mut f, arc.lo, peak, tol) + integrate(&mut f, peak, arc.hi, tol);
        (kd, s)
    }
}
