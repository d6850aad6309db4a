//! Export a fabric's BRDF into the file formats other renderers read.
//!
//! * [`rgl`]: the tensor-file `.bsdf` of the RGL material database (Dupuy & Jakob 2018), read by
//!   Mitsuba 3's `measured` BSDF (RGB file: RGB variants; spectral file: spectral variants) and
//!   pbrt-v4's `measured` material (spectral file). Anisotropic: one slice per (theta, phi) of
//!   the view direction.
//! * [`spectrum`]: the linear RGB-to-spectrum upsampling of the spectral file, and the CIE
//!   projection it inverts.
//! * [`klems`]: the LBNL/Radiance BSDF XML on the Klems basis (front and back reflection and
//!   transmission) for daylighting tools, and the datasheet figures of a fabric shade.
//! * [`merl`]: the 90 x 90 x 180 half/difference-angle binary of the MERL database. Isotropic
//!   only: the cloth's BRDF is averaged over rotations about the normal.
//! * [`fitted`]: analytic materials fitted to the cloth (glTF's, OpenPBR's), per crossing cell;
//!   [`gltf`] and [`openpbr`] write them (glTF 2.0, MaterialX, USD, a Blender module), and
//!   [`fits`] fits both families as their files hold them, with their residuals.
//!
//! Both sample a [`Bsdf`]'s f_r (wi toward the light, wo toward the eye, in 1/sr, RGB): the
//! analytic model as the baker evaluates it (`clothbake_core::AnalyticBsdf`) or a baked table
//! (`clothbake_loader::Brdf`).

pub mod fits;
pub mod fitted;
pub mod gltf;
pub mod klems;
pub mod merl;
pub mod openpbr;
pub mod rgl;
pub mod spectrum;

use clothbake_core::{UnitVec3, Vec3};
use clothbake_loader::{write_atomic_as, TableError};
use std::io::Write;
use std::path::Path;

/// Writes `bytes` to `path` atomically (temporary file, fsync, rename), refusing an existing
/// file unless `overwrite`.
pub fn write_file(path: &Path, bytes: &[u8], overwrite: bool) -> Result<(), TableError> {
    write_atomic_as(path, "exported file", overwrite, |w| w.write_all(bytes))
}

pub use clothbake_core::Bsdf;

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
}
