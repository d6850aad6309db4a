//! The quantities the model and the ground truth both answer in: the reflected intensity split
//! into diffuse and specular parts (thesis eq. 4.11), the secondary reflection's four components
//! (eq. 5.15), the second bounce's kernel, and the BRDF f_r = I / (pi cos theta_i).

use clothbake_bsdf::UnitVec3;
use std::f64::consts::PI;

/// Reflected intensity for unit incident intensity (thesis units: pi times radiance), RGB.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Reflection {
    /// Diffuse part I_d of the direct reflection.
    pub i_d: [f64; 3],
    /// Specular part I_s of the direct reflection.
    pub i_s: [f64; 3],
    /// Secondary reflection I_2 and its components (thesis ch. 5), when computed.
    pub secondary: Option<Secondary>,
}

impl Reflection {
    /// Direct reflection I_1 = I_d + I_s.
    pub fn direct(&self) -> [f64; 3] {
        std::array::from_fn(|k| self.i_d[k] + self.i_s[k])
    }

    /// Total intensity I = I_1 (+ I_2 when the secondary reflection was computed).
    pub fn total(&self) -> [f64; 3] {
        let i2 = self.secondary.map_or([0.0; 3], |s| s.total());
        std::array::from_fn(|k| self.i_d[k] + self.i_s[k] + i2[k])
    }

    /// The BRDF f_r = I / (pi cos theta_i) in 1/sr (zero for light at or below the horizon).
    pub fn brdf(&self, wi: UnitVec3) -> [f64; 3] {
        intensity_to_brdf(self.total(), wi)
    }
}

/// f_r = I / (pi cos theta_i): a flat Lambertian facet of albedo rho gives rho / pi.
pub fn intensity_to_brdf(i: [f64; 3], wi: UnitVec3) -> [f64; 3] {
    if !wi.above_horizon() {
        return [0.0; 3];
    }
    let c = wi.cos_theta();
    std::array::from_fn(|k| i[k] / (PI * c))
}

/// Weight of the second bounce (docs/science/interreflection.md): the thesis's kernel is the
/// radiometric one times pi (N_i . P_iP_j).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Kernel {
    /// As printed: facet intensities times the projected solid angle (N_i . w) dw.
    Thesis,
    /// The rendering equation: facet intensities times dw / pi.
    #[default]
    Radiometric,
}

impl Kernel {
    /// The kernel's name, as the command line and the tables' options spell it.
    pub fn name(self) -> &'static str {
        match self {
            Kernel::Thesis => "thesis",
            Kernel::Radiometric => "radiometric",
        }
    }
}

/// The four components of the secondary reflection (thesis intensity units), RGB.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Secondary {
    /// Specular at P_j, then specular at P_i.
    pub ss: [f64; 3],
    /// Specular at P_j, then diffuse at P_i.
    pub sd: [f64; 3],
    /// Diffuse at P_j, then specular at P_i.
    pub ds: [f64; 3],
    /// Diffuse at both.
    pub dd: [f64; 3],
}

impl Secondary {
    /// I_2 = I_ss + I_sd + I_ds + I_dd (eq. 5.15).
    pub fn total(&self) -> [f64; 3] {
        std::array::from_fn(|k| self.ss[k] + self.sd[k] + self.ds[k] + self.dd[k])
    }
    /// `self += w * o`.
    pub fn add_scaled(&mut self, o: &Secondary, w: f64) {
        for k in 0..3 {
            self.ss[k] += w * o.ss[k];
            self.sd[k] += w * o.sd[k];
            self.ds[k] += w * o.ds[k];
            self.dd[k] += w * o.dd[k];
        }
    }
    /// Every component times `w`.
    pub fn scaled(mut self, w: f64) -> Secondary {
        for c in [&mut self.ss, &mut self.sd, &mut self.ds, &mut self.dd] {
            for x in c.iter_mut() {
                *x *= w;
            }
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_lambertian_facet_gives_rho_over_pi() {
        // A flat facet reflects I = rho N.L for unit light (thesis units).
        for theta in [0.0, 30.0, 75.0] {
            let wi = UnitVec3::from_degrees(theta, 40.0);
            let i = 0.4 * wi.cos_theta();
            let f = intensity_to_brdf([i; 3], wi);
            assert!((f[0] - 0.4 / PI).abs() < 1e-15);
        }
        assert_eq!(
            intensity_to_brdf([1.0; 3], UnitVec3::from_degrees(90.0, 0.0)),
            [0.0; 3]
        );
    }
}
