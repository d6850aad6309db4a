//! The model resolved over the weave period (docs/science/spatial.md): the reflection of one
//! crossing cell, and the cells grouped into classes whose terms differ only by the threads'
//! albedos, for spatial tables.

use super::*;

impl AnalyticModel {
    /// The period's crossing cells.
    pub fn cells(&self) -> &CellGrid {
        &self.grid
    }

    /// The reflection at point `at` of the period (docs/science/spatial.md): eq. 4.11 restricted to the
    /// unit over the cell containing `at`, with the cell's coverage. The coverage-weighted mean
    /// over the period of the local reflection is [`AnalyticModel::intensity_with`].
    pub fn intensity_at(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        at: PeriodPoint,
        secondary: Option<&SecondaryOptions>,
    ) -> LocalReflection {
        self.intensity_in(wi, wo, self.grid.cell_at(at), secondary)
    }

    /// As [`AnalyticModel::intensity_at`], for a cell.
    pub fn intensity_in(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        cell: Cell,
        secondary: Option<&SecondaryOptions>,
    ) -> LocalReflection {
        let empty = LocalReflection {
            reflection: Reflection {
                secondary: secondary.map(|_| Secondary::default()),
                ..Reflection::default()
            },
            coverage: 0.0,
        };
        if !(wi.above_horizon() && wo.above_horizon()) {
            return empty;
        }
        let (unit, variant) = self.cell_units[self.grid.index(cell)];
        let u = &self.units[unit as usize];
        let variants = std::slice::from_ref(&u.neighbours[variant as usize]);
        let views = self.views(wi, wo)[u.seg.group as usize];
        let Some(t) = self.unit_terms(u, variants, &views, wi, wo, secondary, false) else {
            return empty;
        };
        let s_v = t.l_v * t.width;
        let coverage = self.cell_coverage(cell, s_v, wo);
        let (i_d, i_s) = match t.lit {
            Some((l_vi, kd, ks)) => {
                let w = l_vi * u.seg.radius / s_v;
                (u.seg.material.albedo.map(|a| w * kd * a), [w * ks; 3])
            }
            None => ([0.0; 3], [0.0; 3]),
        };
        LocalReflection {
            reflection: Reflection {
                i_d,
                i_s,
                secondary: secondary.map(|_| {
                    t.secondary.first().map_or_else(Secondary::default, |s| {
                        both_sides(&s.0).scaled(1.0 / t.width)
                    })
                }),
            },
            coverage,
        }
    }

    /// Number of classes of the period's units (see [`ClassTerms`]).
    pub fn classes(&self) -> usize {
        self.class_unit.len()
    }

    /// Each class's direct reflection for light from `wi` seen from `wo`, written to `out`
    /// (one entry per class; zero below the horizon). For every cell, rho_d `diffuse` +
    /// `specular` is the f_r of [`AnalyticModel::intensity_in`] without secondary reflection,
    /// and `visible` over the cell's area share its coverage.
    pub fn class_terms(&self, wi: UnitVec3, wo: UnitVec3, out: &mut [ClassTerms]) {
        assert_eq!(out.len(), self.classes(), "one entry per class");
        out.fill(ClassTerms::default());
        if !(wi.above_horizon() && wo.above_horizon()) {
            return;
        }
        let views = self.views(wi, wo);
        for (o, &u) in out.iter_mut().zip(&self.class_unit) {
            let u = &self.units[u as usize];
            let v = &views[u.seg.group as usize];
            let Some(t) = self.unit_terms(u, &[], v, wi, wo, None, false) else {
                continue;
            };
            let (visible, d, s) = self.direct_terms(u, &t, wi, wo);
            o.visible = visible;
            // Each is a non-negative quantity; near the horizon a lit arc of almost no length
            // leaves rounding of either sign (-1.2e-28 seen on the taffeta at 87 degrees),
            // which a table may not hold.
            o.diffuse = d.max(0.0);
            o.specular = s.max(0.0);
        }
    }

    /// A class's visible share of the period and its direct f_r at unit diffuse albedo and
    /// specular, not yet clamped at 0, from its unit `u`'s terms `t` ([`ClassTerms`]).
    pub(super) fn direct_terms(
        &self,
        u: &Unit,
        t: &UnitTerms,
        wi: UnitVec3,
        wo: UnitVec3,
    ) -> (f64, f64, f64) {
        let s_v = t.l_v * t.width;
        let (px, py) = self.grid.period();
        let visible = s_v / (px * py * wo.cos_theta());
        let (d, s) = t.lit.map_or((0.0, 0.0), |(l_vi, kd, ks)| {
            let w = l_vi * u.seg.radius / s_v;
            let [d, s, _] = intensity_to_brdf([w * kd, w * ks, 0.0], wi);
            (d, s)
        });
        (visible, d, s)
    }

    /// Each class's visible share of the period seen from `wo`, as [`ClassTerms::visible`]
    /// (the classes of [`AnalyticModel::classes_with`] `secondary`), without the facet terms or
    /// the second bounce (0 below the horizon).
    pub fn class_visible(&self, wo: UnitVec3, secondary: bool, out: &mut [f64]) {
        let units: Vec<u32> = if secondary {
            self.bounce_unit.iter().map(|&(u, _)| u).collect()
        } else {
            self.class_unit.clone()
        };
        assert_eq!(out.len(), units.len(), "one entry per class");
        out.fill(0.0);
        if !wo.above_horizon() {
            return;
        }
        let views = View::both(wo.get());
        let (px, py) = self.grid.period();
        for (o, &u) in out.iter_mut().zip(&units) {
            let u = &self.units[u as usize];
            if let Some((l_v, width)) = self.seen_area(u, &views[u.seg.group as usize]) {
                *o = l_v * width / (px * py * wo.cos_theta());
            }
        }
    }

    /// The period's averaged f_r (RGB, 1/sr) from [`AnalyticModel::class_terms`]' `terms`:
    /// each unit's rho_d D + S weighted by its multiplicity times its class's visible area
    /// (eq. 4.11). Equal to the f_r of [`AnalyticModel::intensity`] to rounding, without
    /// evaluating any unit again.
    pub fn average_of_classes(&self, terms: &[ClassTerms]) -> [f64; 3] {
        assert_eq!(terms.len(), self.classes(), "one entry per class");
        let (mut num, mut den) = ([0.0; 3], 0.0);
        for (u, &c) in self.units.iter().zip(&self.unit_class) {
            let t = &terms[c as usize];
            let w = f64::from(u.count) * t.visible;
            for (n, a) in num.iter_mut().zip(u.seg.material.albedo) {
                *n += w * (a * t.diffuse + t.specular);
            }
            den += w;
        }
        if den > 0.0 {
            num.map(|n| n / den)
        } else {
            [0.0; 3]
        }
    }

    /// Number of classes with the second bounce (`secondary`) or without: with it, cells of
    /// one class beside neighbours of different geometry are apart.
    pub fn classes_with(&self, secondary: bool) -> usize {
        if secondary {
            self.bounce_unit.len()
        } else {
            self.classes()
        }
    }

    /// Each cell's class (with the second bounce when `secondary`) and the albedos its
    /// [`ClassTerms`] are multiplied by, by [`CellGrid::index`].
    pub fn cell_classes_with(&self, secondary: bool) -> Vec<CellClass> {
        self.cell_units
            .iter()
            .zip(&self.bounce_class)
            .map(|(&(u, var), &b)| {
                let unit = &self.units[u as usize];
                let nbs = &unit.neighbours[var as usize].0;
                CellClass {
                    class: if secondary {
                        b
                    } else {
                        self.unit_class[u as usize]
                    },
                    albedo: unit.seg.material.albedo,
                    neighbours: nbs.map(|n| n.map_or([0.0; 3], |n| n.material.albedo)),
                }
            })
            .collect()
    }

    /// As [`AnalyticModel::class_terms`], with the second bounce when `secondary` is given:
    /// one entry per class of [`AnalyticModel::classes_with`]. For every cell, its
    /// [`CellClass`]'s albedos and its class's terms give the f_r of
    /// [`AnalyticModel::intensity_in`] with the same `secondary`.
    pub fn class_terms_with(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
        out: &mut [ClassTerms],
    ) {
        let Some(opts) = secondary else {
            return self.class_terms(wi, wo, out);
        };
        assert_eq!(out.len(), self.bounce_unit.len(), "one entry per class");
        out.fill(ClassTerms::default());
        if !(wi.above_horizon() && wo.above_horizon()) {
            return;
        }
        let views = self.views(wi, wo);
        // I_2 of a cell is its piece's, per unit visible length, over the visible width.
        let f = |x: f64, width: f64| intensity_to_brdf([x / width, 0.0, 0.0], wi)[0];
        for (o, &(u, var)) in out.iter_mut().zip(&self.bounce_unit) {
            let u = &self.units[u as usize];
            let v = &views[u.seg.group as usize];
            let variants = std::slice::from_ref(&u.neighbours[var as usize]);
            let Some(t) = self.unit_terms(u, variants, v, wi, wo, Some(opts), true) else {
                continue;
            };
            let (visible, d, s) = self.direct_terms(u, &t, wi, wo);
            o.visible = visible;
            // Threads of albedo 1: each component is the same in every channel.
            let sides = &t.secondary[0].0;
            let own = f(sides[0].sd[0] + sides[1].sd[0], t.width);
            let none = f(sides[0].ss[0] + sides[1].ss[0], t.width);
            // Each is non-negative; rounding near the horizon may leave either sign (as in
            // `class_terms`), which a table may not hold.
            o.diffuse = (d + own).max(0.0);
            o.specular = (s + none).max(0.0);
            o.neighbour = sides.map(|p| f(p.ds[0], t.width).max(0.0));
            o.both = sides.map(|p| f(p.dd[0], t.width).max(0.0));
        }
    }

    /// A cell's f_r (RGB, 1/sr) from its [`CellClass`] and its class's [`ClassTerms`].
    pub fn cell_f(cell: &CellClass, t: &ClassTerms) -> [f64; 3] {
        std::array::from_fn(|c| {
            let a = cell.albedo[c];
            let [p, m] = cell.neighbours;
            a * t.diffuse
                + t.specular
                + p[c] * (t.neighbour[0] + a * t.both[0])
                + m[c] * (t.neighbour[1] + a * t.both[1])
        })
    }

    /// The period's averaged f_r (RGB, 1/sr) from the cells' classes (`cells`, of
    /// [`AnalyticModel::cell_classes_with`]) and their `terms`: each cell's f_r weighted by its
    /// class's visible area (eq. 4.11 over the pieces, one piece a cell). Equal to the f_r of
    /// [`AnalyticModel::intensity_with`] to rounding.
    pub fn average_of_cells(&self, cells: &[CellClass], terms: &[ClassTerms]) -> [f64; 3] {
        let (mut num, mut den) = ([0.0; 3], 0.0);
        for c in cells {
            let t = &terms[c.class as usize];
            let f = Self::cell_f(c, t);
            for (n, f) in num.iter_mut().zip(f) {
                *n += t.visible * f;
            }
            den += t.visible;
        }
        if den > 0.0 {
            num.map(|n| n / den)
        } else {
            [0.0; 3]
        }
    }
}
