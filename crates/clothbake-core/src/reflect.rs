//! The output quantity: reflected intensity split into diffuse and specular parts, and the BRDF.

use crate::interreflection::Secondary;
use crate::vec3::UnitVec3;
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
