//! Export a fabric's BRDF into the file formats other renderers read.
//!
//! * [`rgl`]: the tensor-file `.bsdf` of the RGL material database (Dupuy & Jakob 2018), read by
//!   Mitsuba 3's `measured` BSDF (RGB file: RGB variants; spectral file: spectral variants) and
//!   pbrt-v4's `measured` material (spectral file). Anisotropic: one slice per (theta, phi) of
//!   the view direction.
//! * [`spectrum`]: the linear RGB-to-spectrum upsampling of the spectral file, and the CIE
//!   projection it inverts.
//! * [`merl`]: the 90 x 90 x 180 half/difference-angle binary of the MERL database. Isotropic
//!   only: the cloth's BRDF is averaged over rotations about the normal.
//!
//! Both sample a [`Brdf`]: any function of (wi toward the light, wo toward the eye) returning f_r
//! in 1/sr, RGB; [`model_brdf`] wraps the analytic model as the baker evaluates it,
//! [`table_brdf`] a baked table's lookup.

pub mod merl;
pub mod rgl;
pub mod spectrum;

use clothbake_core::{AnalyticModel, SecondaryOptions, UnitVec3, Vec3};
use clothbake_loader::{write_atomic_as, TableError};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file, fsync, rename), refusing an existing
/// file unless `overwrite`.
pub fn write_file(path: &Path, bytes: &[u8], overwrite: bool) -> Result<(), TableError> {
    write_atomic_as(path, "exported file", overwrite, |w| w.write_all(bytes))
}

/// f_r(wi, wo) in 1/sr, RGB: wi toward the light, wo toward the eye, both in the fabric's frame
/// (+X weft, +Y warp, +Z normal). Must be zero when either direction is at or below the horizon.
pub type Brdf<'a> = dyn Fn(UnitVec3, UnitVec3) -> [f64; 3] + Sync + 'a;

/// The analytic model's f_r = I / (pi cos theta_i) (thesis eq. 4.1 summed over the units), with
/// the secondary reflection of ch. 5 when `secondary` is given: what `clothbake bake` tabulates.
pub fn model_brdf<'a>(
    model: &'a AnalyticModel,
    secondary: Option<SecondaryOptions>,
) -> impl Fn(UnitVec3, UnitVec3) -> [f64; 3] + Sync + 'a {
    move |wi, wo| {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return [0.0; 3];
        }
        model.eval_with(wi, wo, secondary.as_ref()).brdf(wi)
    }
}

/// A baked table's f_r through the loader's interpolated lookup (`Brdf::eval`, zero at and below
/// the horizon): the source of `clothbake export --table`.
pub fn table_brdf(
    lookup: &clothbake_loader::Brdf,
) -> impl Fn(UnitVec3, UnitVec3) -> [f64; 3] + Sync + '_ {
    move |wi: UnitVec3, wo: UnitVec3| {
        let v = |u: UnitVec3| [u.x as f32, u.y as f32, u.z as f32];
        lookup.eval(v(wi), v(wo)).map(f64::from)
    }
}

/// The mirror image of `v` about the unit vector `m`: 2 (v.m) m - v (`None` only for a
/// degenerate input).
pub fn reflect(v: UnitVec3, m: UnitVec3) -> Option<UnitVec3> {
    let d = v.dot(m.get());
    UnitVec3::new(m.get() * (2.0 * d) - v.get())
}

/// Rec. 709 luminance of linear RGB.
pub fn luminance(c: [f64; 3]) -> f64 {
    0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]
}

/// A direction from its Cartesian components, normalised (`None` for zero or non-finite).
pub fn unit(x: f64, y: f64, z: f64) -> Option<UnitVec3> {
    UnitVec3::new(Vec3::new(x, y, z))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn write_file_is_atomic_and_refuses_to_overwrite() {
        let dir = std::env::temp_dir().join(format!("clothbake-export-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("a.bsdf");
        write_file(&p, b"abc", false).unwrap();
        assert!(matches!(
            write_file(&p, b"def", false),
            Err(TableError::AlreadyExists { .. })
        ));
        assert_eq!(std::fs::read(&p).unwrap(), b"abc");
        write_file(&p, b"def", true).unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"def");
        assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn reflection_about_the_normal_mirrors_the_azimuth() {
        let v = UnitVec3::from_degrees(40.0, 30.0);
        let r = reflect(v, UnitVec3::Z).unwrap();
        let (t, p) = r.to_spherical();
        assert!((t.to_degrees() - 40.0).abs() < 1e-12);
        assert!((p.to_degrees() - (30.0 - 180.0)).abs() < 1e-12);
    }

    #[test]
    fn model_brdf_is_zero_below_the_horizon() {
        let f = clothbake_core::Fabric::from_path(
            &std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables/plain.json"),
        )
        .unwrap();
        let m = AnalyticModel::new(&f, clothbake_core::FacetModel::Huo);
        let b = model_brdf(&m, None);
        let below = unit(1.0, 0.0, -0.1).unwrap();
        assert_eq!(b(below, UnitVec3::Z), [0.0; 3]);
        assert_eq!(b(UnitVec3::Z, below), [0.0; 3]);
        assert!(b(UnitVec3::Z, UnitVec3::from_degrees(30.0, 10.0))[0] > 0.0);
    }
}
