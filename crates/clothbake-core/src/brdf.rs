//! The analytic model as a [`Bsdf`]: f_r = I / (pi cos theta_i) (thesis eq. 4.1 summed over
//! the units, eq. 4.11), with the secondary reflection of ch. 5 when asked for. This is the one
//! adapter from the thesis's intensity ([`AnalyticModel::intensity_with`]) to f_r: baking,
//! export, pictures and Python all evaluate the model through it.

use crate::analytic::{AnalyticModel, SecondaryOptions};
use crate::cells::{Cell, PeriodPoint};
use crate::reflect::{intensity_to_brdf, Reflection};
use clothbake_bsdf::{Bsdf, Footprint, Rgb, UnitVec3};

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
pub struct AnalyticBsdf {
    model: AnalyticModel,
    secondary: Option<SecondaryOptions>,
    component: Component,
}

impl AnalyticBsdf {
    /// The model with one bounce (`secondary` `None`) or two (I_2 with these options).
    pub fn new(model: AnalyticModel, secondary: Option<SecondaryOptions>) -> AnalyticBsdf {
        AnalyticBsdf {
            model,
            secondary,
            component: Component::Total,
        }
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
    /// The cells a footprint covers with their shares of the period's area; `None` once it
    /// spans the whole period (or is not finite).
    fn cells_under(&self, at: Footprint) -> Option<Vec<(Cell, f64)>> {
        let p = PeriodPoint::new(at.u, at.v)?;
        let grid = self.model.cells();
        if at.width >= 1.0 || at.width.is_nan() {
            return None;
        }
        if at.width <= 0.0 {
            return Some(vec![(grid.cell_at(p), 1.0)]);
        }
        Some(grid.overlaps(p, at.width))
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

    /// The box filter over the footprint of the cells' f_r (thesis units, docs/spatial.md),
    /// weighted by area times coverage; [`Bsdf::f`] at a footprint of a period or more.
    fn f_at(&self, at: Footprint, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return [0.0; 3];
        }
        let Some(cells) = self.cells_under(at) else {
            return self.f(wi, wo);
        };
        let (mut num, mut den) = ([0.0; 3], 0.0);
        for (cell, share) in cells {
            let l = self
                .model
                .intensity_in(wi, wo, cell, self.secondary.as_ref());
            let i = self.component.of(&l.reflection);
            let w = share * l.coverage;
            for k in 0..3 {
                num[k] += w * i[k];
            }
            den += w;
        }
        if den <= 0.0 {
            return [0.0; 3];
        }
        intensity_to_brdf(num.map(|x| x / den), wi)
    }

    fn coverage_at(&self, at: Footprint, wo: UnitVec3) -> f64 {
        let Some(cells) = self.cells_under(at) else {
            return self.model.coverage(wo);
        };
        let total: f64 = cells.iter().map(|c| c.1).sum();
        cells
            .iter()
            .map(|&(cell, share)| share * self.model.coverage_in(cell, wo))
            .sum::<f64>()
            / total
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
