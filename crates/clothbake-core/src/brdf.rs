//! The analytic model as a [`Bsdf`]: f_r = I / (pi cos theta_i) (thesis eq. 4.1 summed over
//! the units, eq. 4.11), with the secondary reflection of ch. 5 when asked for. This is the one
//! adapter from the thesis's intensity ([`AnalyticModel::intensity_with`]) to f_r: baking,
//! export, pictures and Python all evaluate the model through it.

use crate::analytic::{AnalyticModel, SecondaryOptions};
use crate::reflect::{intensity_to_brdf, Reflection};
use clothbake_bsdf::{Bsdf, Rgb, UnitVec3};

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

impl Bsdf for AnalyticBsdf {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return [0.0; 3];
        }
        intensity_to_brdf(self.component.of(&self.intensity(wi, wo)), wi)
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
