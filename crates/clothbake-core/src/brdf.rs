//! The analytic model as a [`Bsdf`]: f_r = I / (pi cos theta_i) (thesis eq. 4.1 summed over
//! the units, eq. 4.11), with the secondary reflection of ch. 5 when asked for. This is the one
//! adapter from the thesis's intensity ([`AnalyticModel::intensity_with`]) to f_r: baking,
//! export, pictures and Python all evaluate the model through it.

use crate::analytic::{AnalyticModel, SecondaryOptions};
use crate::cells::{Cell, PeriodPoint};
use crate::reflect::{intensity_to_brdf, Reflection};
use clothbake_bsdf::{Bsdf, Footprint, Level, Local, Rgb, UnitVec3};
use clothbake_point::Yarns;

/// Which part of the model's reflection an [`AnalyticBsdf`] returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Component {
    /// Everything computed: I_1, plus I_2 with two bounces.
    #[default]
    Total,
    /// The direct reflection I_1 = I_d + I_s (thesis eq. 4.11).
    Direct,
    /// The secondary reflection I_2 = I_ss + I_sd + I_ds + I_dd alone (eq. 5.15).
    Secondary,
    /// The specular-specular secondary reflection I_ss alone (eq. 5.11).
    SecondarySpecular,
}

impl Component {
    /// The intensity this component takes from a reflection.
    pub fn of(self, r: &Reflection) -> Rgb {
        let s = r.secondary.unwrap_or_default();
        match self {
            Component::Total => r.total(),
            Component::Direct => r.direct(),
            Component::Secondary => s.total(),
            Component::SecondarySpecular => s.ss,
        }
    }
}

/// The analytic model of a fabric (any facet and variant) with a bounce setting, as a BSDF.
/// Sampling is the trait's cos(theta_i)-weighted default: the model has no closed-form inverse.
/// With the fabric's yarns ([`AnalyticBsdf::with_yarns`]) footprints smaller than a crossing
/// cell are answered by the point level (docs/science/spatial.md, "Levels of detail").
pub struct AnalyticBsdf {
    model: AnalyticModel,
    secondary: Option<SecondaryOptions>,
    component: Component,
    yarns: Option<Yarns>,
}

impl AnalyticBsdf {
    /// The model with one bounce (`secondary` `None`) or two (I_2 with these options).
    pub fn new(model: AnalyticModel, secondary: Option<SecondaryOptions>) -> AnalyticBsdf {
        AnalyticBsdf {
            model,
            secondary,
            component: Component::Total,
            yarns: None,
        }
    }

    /// The same BSDF with the point level: the fabric's yarns (`crate::point::yarns` of the
    /// fabric the model was built from), traced for footprints under a crossing cell. The
    /// point level is one bounce; with two, the cells carry the second bounce's share as the
    /// footprint grows, and [`Component::Secondary`] has no point level.
    pub fn with_yarns(mut self, yarns: Yarns) -> AnalyticBsdf {
        self.yarns = Some(yarns);
        self
    }

    /// The yarns of the point level, when given.
    pub fn yarns(&self) -> Option<&Yarns> {
        self.yarns.as_ref()
    }

    /// The same BSDF returning only `component`; `None` where the component needs the second
    /// bounce and this BSDF has none.
    pub fn with_component(mut self, component: Component) -> Option<AnalyticBsdf> {
        let needs_i2 = matches!(
            component,
            Component::Secondary | Component::SecondarySpecular
        );
        if needs_i2 && self.secondary.is_none() {
            return None;
        }
        self.component = component;
        Some(self)
    }

    /// The model evaluated.
    pub fn model(&self) -> &AnalyticModel {
        &self.model
    }

    /// The secondary-reflection options, with two bounces.
    pub fn secondary(&self) -> Option<&SecondaryOptions> {
        self.secondary.as_ref()
    }

    /// The thesis's intensity I for unit light (pi times radiance), every part of it.
    pub fn intensity(&self, wi: UnitVec3, wo: UnitVec3) -> Reflection {
        self.model.intensity_with(wi, wo, self.secondary.as_ref())
    }
}

impl AnalyticBsdf {
    /// The side of a crossing cell, in periods, that the level rule ([`Footprint::level`])
    /// measures footprints in: one over the larger thread count of the period.
    pub fn cell_width(&self) -> f64 {
        let (nx, ny) = self.model.cells().dims();
        1.0 / nx.max(ny).max(1) as f64
    }

    /// The point level, where this BSDF has it and the component is one it holds.
    fn point_level(&self) -> Option<&Yarns> {
        match self.component {
            Component::Total | Component::Direct => self.yarns.as_ref(),
            _ => None,
        }
    }

    /// The crossing cells the square of side `width` periods at the footprint's point covers,
    /// each with its covered share of the period (`width` 0: the cell at the point). Called
    /// only where the level rule gave a local level, so the point is finite.
    fn cells_under(&self, at: Footprint, width: f64) -> Vec<(Cell, f64)> {
        let p = PeriodPoint::new(at.u, at.v).expect("the level rule gives a finite point");
        let grid = self.model.cells();
        if width <= 0.0 {
            vec![(grid.cell_at(p), 1.0)]
        } else {
            grid.overlaps(p, width)
        }
    }

    /// The box filter of side `width` periods over the crossing cells: the cells' f_r
    /// weighted by their covered share times their coverage, and the mean coverage (thesis
    /// units, docs/science/spatial.md).
    fn cells(&self, at: Footprint, width: f64, wi: UnitVec3, wo: UnitVec3) -> Local {
        let (mut num, mut den, mut area) = ([0.0; 3], 0.0, 0.0);
        for (cell, share) in self.cells_under(at, width) {
            let l = self
                .model
                .intensity_in(wi, wo, cell, self.secondary.as_ref());
            let i = self.component.of(&l.reflection);
            let w = share * l.coverage;
            for k in 0..3 {
                num[k] += w * i[k];
            }
            den += w;
            area += share;
        }
        Local {
            f: if den > 0.0 {
                intensity_to_brdf(num.map(|x| x / den), wi)
            } else {
                [0.0; 3]
            },
            coverage: if area > 0.0 { den / area } else { 0.0 },
        }
    }

    /// The mean coverage of the cells' box filter, from the cells' coverage alone (no facet
    /// terms).
    fn cells_coverage(&self, at: Footprint, width: f64, wo: UnitVec3) -> f64 {
        let cells = self.cells_under(at, width);
        let total: f64 = cells.iter().map(|c| c.1).sum();
        cells
            .iter()
            .map(|&(cell, share)| share * self.model.coverage_in(cell, wo))
            .sum::<f64>()
            / total
    }

    /// The whole period: f_r and the directional coverage C(wo).
    fn period(&self, wi: UnitVec3, wo: UnitVec3) -> Local {
        Local {
            f: self.f(wi, wo),
            coverage: self.model.coverage(wo),
        }
    }
}

impl Bsdf for AnalyticBsdf {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return [0.0; 3];
        }
        intensity_to_brdf(self.component.of(&self.intensity(wi, wo)), wi)
    }

    /// With one bounce the pairs go through [`AnalyticModel::intensity_batch`] (four at a time
    /// in AVX2 lanes, the same bits); with two, one at a time.
    fn f_batch(&self, pairs: &[(UnitVec3, UnitVec3)], out: &mut [Rgb]) {
        assert_eq!(pairs.len(), out.len(), "one output per pair");
        if self.secondary.is_some() {
            for (o, &(wi, wo)) in out.iter_mut().zip(pairs) {
                *o = self.f(wi, wo);
            }
            return;
        }
        const CHUNK: usize = 64;
        let mut r = [Reflection::default(); CHUNK];
        for (p, o) in pairs.chunks(CHUNK).zip(out.chunks_mut(CHUNK)) {
            let r = &mut r[..p.len()];
            self.model.intensity_batch(p, r);
            for ((&(wi, wo), r), o) in p.iter().zip(r.iter()).zip(o) {
                *o = if wi.above_horizon() && wo.above_horizon() {
                    intensity_to_brdf(self.component.of(r), wi)
                } else {
                    [0.0; 3]
                };
            }
        }
    }

    /// The footprint's level of detail ([`Footprint::level`]): the point level's look (with
    /// the yarns), the box filter of the crossing cells' f_r weighted by area times coverage,
    /// a coverage-weighted blend of the two, or [`Bsdf::f`] at a footprint of a period or more.
    fn f_at(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        self.local(at, wi, wo).f
    }

    fn coverage_at(&self, at: Footprint, wo: UnitVec3) -> f64 {
        if !wo.above_horizon() {
            return 0.0;
        }
        let (point, width, points) = match at.level(self.cell_width()) {
            Level::Period => return self.model.coverage(wo),
            Level::Local {
                point,
                width,
                points,
            } => (point, width, points),
        };
        // The coverage does not depend on the light: the eye rays alone.
        let seen = |y: &Yarns| y.coverage_within(at.u, at.v, width, points, wo);
        match self.point_level().filter(|_| point > 0.0) {
            Some(y) if point >= 1.0 => seen(y),
            Some(y) => point * seen(y) + (1.0 - point) * self.cells_coverage(at, width, wo),
            None => self.cells_coverage(at, width, wo),
        }
    }

    fn local(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> Local {
        if !wo.above_horizon() {
            return Local {
                f: [0.0; 3],
                coverage: 0.0,
            };
        }
        if !wi.above_horizon() {
            // Nothing reflected, but the eye still sees what it sees.
            return Local {
                f: [0.0; 3],
                coverage: self.coverage_at(at, wo),
            };
        }
        let (point, width, points) = match at.level(self.cell_width()) {
            Level::Period => return self.period(wi, wo),
            Level::Local {
                point,
                width,
                points,
            } => (point, width, points),
        };
        let yarns = self.point_level().filter(|_| point > 0.0);
        let Some(yarns) = yarns else {
            return self.cells(at, width, wi, wo);
        };
        let look = yarns.look_within(at.u, at.v, width, points, wi, wo);
        let seen = Local {
            f: look.f,
            coverage: look.coverage,
        };
        if point >= 1.0 {
            return seen;
        }
        Local::blend(point, seen, self.cells(at, width, wi, wo))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{Fabric, FacetModel};

    fn shipped(name: &str) -> AnalyticModel {
        let f = Fabric::from_path(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
                .join(format!("../../tables/{name}.json")),
        )
        .unwrap();
        AnalyticModel::new(&f, FacetModel::Huo)
    }

    #[test]
    fn f_is_zero_below_the_horizon_and_the_intensity_over_pi_cos_above() {
        let b = AnalyticBsdf::new(shipped("plain"), None);
        let below = UnitVec3::from_degrees(95.0, 0.0);
        assert_eq!(b.f(below, UnitVec3::Z), [0.0; 3]);
        assert_eq!(b.f(UnitVec3::Z, below), [0.0; 3]);
        let (wi, wo) = (
            UnitVec3::from_degrees(35.0, 20.0),
            UnitVec3::from_degrees(30.0, 10.0),
        );
        let i = b.model().intensity(wi, wo).total();
        let f = b.f(wi, wo);
        for k in 0..3 {
            let want = i[k] / (std::f64::consts::PI * wi.cos_theta());
            assert!(f[k] > 0.0 && (f[k] - want).abs() <= 1e-15 * want, "{f:?}");
        }
    }

    #[test]
    fn footprints_filter_between_a_cell_and_the_period() {
        let b = AnalyticBsdf::new(shipped("twill"), None);
        let (wi, wo) = (
            UnitVec3::from_degrees(60.0, 0.0),
            UnitVec3::from_degrees(20.0, 180.0),
        );
        let at = |u, v, width| Footprint { u, v, width };
        // A footprint of a period or more is the average, wherever it lies.
        assert_eq!(b.f_at(at(0.3, 0.7, 1.0), wi, wo), b.f(wi, wo));
        assert_eq!(b.coverage_at(at(0.3, 0.7, 2.0), wo), b.model().coverage(wo));
        // A point, or a footprint inside one cell, is that cell's unit.
        let cell = b
            .model()
            .intensity_in(wi, wo, Cell { warp: 0, weft: 0 }, None);
        let f = intensity_to_brdf(cell.reflection.total(), wi);
        assert_eq!(b.f_at(at(0.0, 0.0, 0.0), wi, wo), f);
        let small = b.f_at(at(0.01, 0.02, 0.05), wi, wo);
        assert!((0..3).all(|k| (small[k] - f[k]).abs() <= 1e-15 * f[k]));
        // A footprint just under the period approaches the average.
        let near = b.f_at(at(0.37, 0.61, 0.999), wi, wo);
        let avg = b.f(wi, wo);
        assert!((near[0] - avg[0]).abs() < 0.01 * avg[0], "{near:?} {avg:?}");
        // Between them, the value lies between the cells' extremes.
        let cells: Vec<f64> = (0..9)
            .map(|k| {
                let c = Cell {
                    warp: k % 3,
                    weft: k / 3,
                };
                intensity_to_brdf(
                    b.model().intensity_in(wi, wo, c, None).reflection.total(),
                    wi,
                )[0]
            })
            .collect();
        let mid = b.f_at(at(0.2, 0.4, 0.5), wi, wo)[0];
        let lo = cells.iter().cloned().fold(f64::INFINITY, f64::min);
        let hi = cells.iter().cloned().fold(0.0, f64::max);
        assert!(lo <= mid && mid <= hi && lo < hi);
    }

    #[test]
    fn with_yarns_a_point_is_the_point_level_and_the_levels_blend_without_a_step() {
        let f = Fabric::from_path(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/twill.json"),
        )
        .unwrap();
        let y = crate::point::yarns(&f, FacetModel::Huo).unwrap();
        let cells = AnalyticBsdf::new(AnalyticModel::new(&f, FacetModel::Huo), None);
        let b = AnalyticBsdf::new(AnalyticModel::new(&f, FacetModel::Huo), None).with_yarns(y);
        let (wi, wo) = (
            UnitVec3::from_degrees(50.0, 20.0),
            UnitVec3::from_degrees(30.0, 200.0),
        );
        let at = |u, v, width| Footprint { u, v, width };
        let cell = 1.0 / 3.0;
        let (mut gaps, mut apart) = (0, 0.0);
        let mut moved = [0.0; 100];
        for k in 0..200 {
            let (u, v) = (k as f64 * 0.137 % 1.0, k as f64 * 0.291 % 1.0);
            // A point (and anything under an eighth of a cell) is the yarns' look.
            let look = b.yarns().unwrap().look(u, v, wi, wo);
            for w in [0.0, f64::NAN, 0.1 * cell] {
                let l = b.local(at(u, v, w), wi, wo);
                assert_eq!((l.f, l.coverage), (look.f, look.coverage));
                assert_eq!(b.f_at(at(u, v, w), wi, wo), look.f);
                assert_eq!(b.coverage_at(at(u, v, w), wo), look.coverage);
            }
            // Up to a cell, the yarns' looks integrated over the footprint.
            let w = 0.9 * cell;
            let within = b.yarns().unwrap().look_within(u, v, w, 8, wi, wo);
            let l = b.local(at(u, v, w), wi, wo);
            assert_eq!((l.f, l.coverage), (within.f, within.coverage));
            gaps += usize::from(look.coverage == 0.0);
            // From two cells on, the cells' box filter, as without the yarns.
            for w in [2.0 * cell, 0.7, 0.99] {
                assert_eq!(b.f_at(at(u, v, w), wi, wo), cells.f_at(at(u, v, w), wi, wo));
                let (c0, c1) = (
                    b.coverage_at(at(u, v, w), wo),
                    cells.coverage_at(at(u, v, w), wo),
                );
                assert!((c0 - c1).abs() < 1e-12, "{c0} {c1}");
            }
            // Between, a coverage-weighted blend whose weight moves smoothly with the width.
            let w = 1.5 * cell;
            let mid = b.local(at(u, v, w), wi, wo);
            let c = cells.local(at(u, v, w), wi, wo);
            let p = b.yarns().unwrap().look_within(u, v, w, 8, wi, wo);
            let want_cov = 0.5 * p.coverage + 0.5 * c.coverage;
            assert!((mid.coverage - want_cov).abs() < 1e-12);
            let step = |w: f64| b.local(at(u, v, w), wi, wo).f[0] * b.coverage_at(at(u, v, w), wo);
            // The change of f c over each step of a hundredth of a cell from one cell to two,
            // in absolute value, summed over the points: the point level's sampling noise (a
            // point of the 64 crossing an edge) stays small in it, a pop between the levels
            // would add the levels' whole difference at one step.
            let mut last = step(cell);
            for (i, acc) in moved.iter_mut().enumerate() {
                let s = step((1.0 + 0.01 * (i + 1) as f64) * cell);
                *acc += (s - last).abs();
                last = s;
            }
            apart += (p.f[0] * p.coverage - c.f[0] * c.coverage).abs();
        }
        let worst = moved.iter().cloned().fold(0.0, f64::max);
        assert!(
            worst < 0.1 * apart,
            "a step moves {worst}, the levels differ by {apart}"
        );
        assert!(gaps < 100, "{gaps} gaps of 200");
        // The period is the average, with or without the yarns.
        assert_eq!(b.f_at(at(0.3, 0.4, 1.0), wi, wo), b.f(wi, wo));
        assert_eq!(b.coverage_at(at(0.3, 0.4, 1.0), wo), b.model().coverage(wo));
    }

    #[test]
    fn components_of_the_second_bounce_need_it() {
        // The parallel surface (sec. 5.4) has neighbours to reflect between.
        assert!(AnalyticBsdf::new(shipped("parallel"), None)
            .with_component(Component::Secondary)
            .is_none());
        let two = AnalyticBsdf::new(shipped("parallel"), Some(SecondaryOptions::default()));
        let (wi, wo) = (
            UnitVec3::from_degrees(40.0, 0.0),
            UnitVec3::from_degrees(40.0, 180.0),
        );
        let total = two.f(wi, wo);
        let direct = AnalyticBsdf::new(shipped("parallel"), Some(SecondaryOptions::default()))
            .with_component(Component::Direct)
            .unwrap()
            .f(wi, wo);
        let second = two.with_component(Component::Secondary).unwrap().f(wi, wo);
        for k in 0..3 {
            assert!(second[k] > 0.0);
            assert!((direct[k] + second[k] - total[k]).abs() <= 1e-12 * total[k]);
        }
    }
}
