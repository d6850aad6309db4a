//! The truth's own facet terms, written from the thesis and docs/science/model.md independently of the
//! model's `facet` module. Intensities are the thesis's (pi times radiance, for unit light):
//!
//! * Huo (thesis eqs 4.6 and 4.8): `I_d = rho_d N.L`, `I_s = rho_s (N.H)^n` with
//!   `H = (L + E) / |L + E|`;
//! * Lewis's modified Phong: `f = rho_d / pi + rho_s (n + 2) / (2 pi) (R.E)^n` with R the
//!   mirror direction of L about N, i.e. `I_d = rho_d N.L`, `I_s = rho_s (n + 2) / 2 (R.E)^n N.L`.
//!
//! Both are zero unless the facet faces the light and the eye (N.L > 0 and N.E > 0).

use super::description::Finish;
use clothbake_bsdf::vec3::Vec3;

/// Which facet terms the truth shades with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Terms {
    /// The thesis's Phong-like terms (eqs 4.6, 4.8).
    Huo,
    /// Lewis's reciprocal modified Phong.
    Lewis,
}

/// A facet's reflected intensity: `diffuse` is to be multiplied by the RGB albedo.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Shading {
    /// N.L where lit and seen (the albedo not applied).
    pub diffuse: f64,
    /// The specular intensity (white; rho_s included).
    pub specular: f64,
}

/// `x^n` for `x >= 0`: square-and-multiply for whole `n` (inline, where `powi` is a library
/// call for an `n` known only at run time), `powf` otherwise.
#[inline]
fn power(x: f64, n: f64) -> f64 {
    if n.fract() == 0.0 && (0.0..=1024.0).contains(&n) {
        let (mut base, mut k, mut acc) = (x, n as u32, 1.0);
        while k > 0 {
            if k & 1 == 1 {
                acc *= base;
            }
            base *= base;
            k >>= 1;
        }
        acc
    } else {
        x.powf(n)
    }
}

impl Terms {
    /// Intensity reflected toward `e` by a facet of unit normal `n` lit from `l` (unit vectors).
    pub fn shade(self, f: &Finish, n: Vec3, l: Vec3, e: Vec3) -> Shading {
        let (nl, ne) = (n.dot(l), n.dot(e));
        if nl <= 0.0 || ne <= 0.0 {
            return Shading::default();
        }
        let specular = match self {
            Terms::Huo => {
                let h = l + e;
                let len = h.length();
                if len > 0.0 {
                    f.specular * power((n.dot(h) / len).clamp(0.0, 1.0), f.exponent)
                } else {
                    0.0
                }
            }
            Terms::Lewis => {
                let r = n * (2.0 * nl) - l;
                let re = r.dot(e).max(0.0);
                f.specular * 0.5 * (f.exponent + 2.0) * power(re, f.exponent) * nl
            }
        };
        Shading {
            diffuse: nl,
            specular,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn whole_powers_agree_with_powf() {
        for n in 0..=64u32 {
            for x in [0.0, 1e-3, 0.37, 0.999, 1.0, 1.7] {
                let (got, want) = (power(x, f64::from(n)), x.powf(f64::from(n)));
                assert!(
                    (got - want).abs() <= 1e-14 * want,
                    "{x}^{n}: {got} vs {want}"
                );
            }
        }
        assert_eq!(power(0.3, 1.0), 0.3);
        assert_eq!(power(0.0, 0.0), 1.0);
        assert_eq!(power(0.5, 2.5), 0.5f64.powf(2.5));
    }
    use clothbake_bsdf::rng::Rng;
    use clothbake_bsdf::vec3::UnitVec3;
    use std::f64::consts::PI;

    fn finish(specular: f64, exponent: f64) -> Finish {
        Finish {
            albedo: [0.4; 3],
            specular,
            exponent,
            transmittance: [0.0; 3],
        }
    }

    fn dir(t: f64, p: f64) -> Vec3 {
        UnitVec3::from_degrees(t, p).get()
    }

    #[test]
    fn huo_closed_forms() {
        // In the plane: N = Z, L at 40 degrees, E at 20 degrees on the other side: H lies 10
        // degrees from N toward L.
        let f = finish(0.7, 10.0);
        let s = Terms::Huo.shade(
            &f,
            Vec3::new(0.0, 0.0, 1.0),
            dir(40.0, 0.0),
            dir(20.0, 180.0),
        );
        assert!((s.diffuse - 40f64.to_radians().cos()).abs() < 1e-15);
        assert!((s.specular - 0.7 * 10f64.to_radians().cos().powi(10)).abs() < 1e-14);
        // Mirror configuration: N.H = 1 gives rho_s whatever the exponent.
        for n in [0.0, 3.0, 7.5, 200.0] {
            let s = Terms::Huo.shade(
                &finish(0.3, n),
                dir(0.0, 0.0),
                dir(60.0, 30.0),
                dir(60.0, 210.0),
            );
            assert!((s.specular - 0.3).abs() < 1e-14, "{n}: {s:?}");
        }
        // Facing away from light or eye: nothing.
        let z = Vec3::new(0.0, 0.0, 1.0);
        assert_eq!(
            Terms::Huo.shade(&f, z, dir(100.0, 0.0), z),
            Shading::default()
        );
        assert_eq!(
            Terms::Lewis.shade(&f, z, z, dir(91.0, 0.0)),
            Shading::default()
        );
    }

    #[test]
    fn lewis_is_reciprocal_and_its_lobe_holds_rho_s() {
        let f = finish(1.0, 7.0);
        let n = dir(20.0, 50.0);
        let mut rng = Rng::new(3);
        for _ in 0..200 {
            let l = dir(80.0 * rng.next_f64(), 360.0 * rng.next_f64());
            let e = dir(80.0 * rng.next_f64(), 360.0 * rng.next_f64());
            // f = I / (pi N.L) must be symmetric in L and E.
            let a = Terms::Lewis.shade(&f, n, l, e);
            let b = Terms::Lewis.shade(&f, n, e, l);
            if a.diffuse > 0.0 {
                let (fa, fb) = (a.specular / n.dot(l), b.specular / n.dot(e));
                assert!((fa - fb).abs() <= 1e-12 * fa.max(1e-300), "{fa} vs {fb}");
            }
        }
        // Directional albedo of the specular lobe at normal incidence: rho_s.
        let z = Vec3::new(0.0, 0.0, 1.0);
        let (nt, np) = (600, 48);
        let mut sum = 0.0;
        for it in 0..nt {
            let t = (it as f64 + 0.5) / nt as f64 * PI / 2.0;
            for ip in 0..np {
                let p = (ip as f64 + 0.5) / np as f64 * 2.0 * PI;
                let e = UnitVec3::from_spherical(t, p).get();
                sum += Terms::Lewis.shade(&f, z, z, e).specular / PI * t.cos() * t.sin();
            }
        }
        sum *= PI / 2.0 / nt as f64 * 2.0 * PI / np as f64;
        assert!((sum - 1.0).abs() < 1e-3, "{sum}");
    }
}
