//! What share of the period the eye sees a yarn at, and a lit one (the coverage a spatial
//! table's point level and the level-of-detail hand-over use).

use super::*;

impl AnalyticModel {
    /// c(x; wo) of a cell whose unit shows visible projected area `s_v`.
    pub(super) fn cell_coverage(&self, cell: Cell, s_v: f64, wo: UnitVec3) -> f64 {
        let (px, py) = self.grid.period();
        s_v / (self.grid.area_fraction(cell) * px * py * wo.cos_theta())
    }

    /// The coverage c(x; wo) of a cell alone, as [`AnalyticModel::intensity_in`] reports it,
    /// without the facet terms (0 below the horizon).
    pub fn coverage_in(&self, cell: Cell, wo: UnitVec3) -> f64 {
        if !wo.above_horizon() {
            return 0.0;
        }
        let (unit, _) = self.cell_units[self.grid.index(cell)];
        let u = &self.units[unit as usize];
        self.seen_area(u, &View::both(wo.get())[u.seg.group as usize])
            .map_or(0.0, |(l_v, width)| {
                self.cell_coverage(cell, l_v * width, wo)
            })
    }

    /// The directional coverage C(wo): the period mean of the coverage, the visible yarn's
    /// projected area per unit projected area of the period (0 below the horizon).
    pub fn coverage(&self, wo: UnitVec3) -> f64 {
        if !wo.above_horizon() {
            return 0.0;
        }
        let views = View::both(wo.get());
        let s: f64 = self
            .units
            .iter()
            .filter_map(|u| {
                let (l_v, width) = self.seen_area(u, &views[u.seg.group as usize])?;
                Some(u.count as f64 * l_v * width)
            })
            .sum();
        let (px, py) = self.grid.period();
        s / (px * py * wo.cos_theta())
    }

    /// The model's share of the period's projected area, seen from `wo`, that is visible, faces
    /// the light `wi` and is lit: the sum of D_i l_vi times the projected width of the lit and
    /// visible arc (eqs 4.2-4.3), per unit projected area. With [`AnalyticModel::coverage`] it
    /// splits the model's error into masking and shadowing (docs/science/model.md, "Where the error
    /// comes from"); 0 below the horizon.
    pub fn lit_coverage(&self, wi: UnitVec3, wo: UnitVec3) -> f64 {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return 0.0;
        }
        let views = Views::both(wi, wo);
        let s: f64 = self
            .units
            .iter()
            .map(|u| {
                let v = &views[u.seg.group as usize];
                let lit_area = |ranges: &[(f64, f64)], seen: ArcTrig, lit: ArcTrig| {
                    let seen = self.visible_of(u, ranges, &v.e, seen)?;
                    let vi = seen.arc.meet(&lit);
                    let lit_len = self.end_interval(u, &v.l, &vi, v.e.p.p);
                    let lit_along = meet(seen.along, lit_len);
                    let l_vi: f64 = ranges.iter().map(|&r| overlap(r, lit_along)).sum();
                    Some(l_vi * projected_width(u.seg.radius, &vi, v.e.p.p))
                };
                // The unit's parts: its whole range with its own tables, or its slices.
                let lit_area: f64 = if u.slices.is_empty() {
                    let arc = |w: &View| self.side_arc(u, w).meet(&u.seg.floor);
                    lit_area(std::slice::from_ref(&u.range), arc(&v.e), arc(&v.l)).unwrap_or(0.0)
                } else {
                    u.slices
                        .iter()
                        .enumerate()
                        .filter_map(|(k, sl)| {
                            let arc = |w: &View| self.slice_arc(u, k, sl, w);
                            lit_area(&sl.ranges, arc(&v.e), arc(&v.l))
                        })
                        .sum()
                };
                u.count as f64 * lit_area
            })
            .sum();
        let (px, py) = self.grid.period();
        s / (px * py * wo.cos_theta())
    }
}
