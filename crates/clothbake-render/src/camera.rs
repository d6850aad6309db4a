//! The pinhole camera of `clothbake render`.
//!
//! Conventions: the camera sits at `eye` looking at `look_at`, with +Z up in the image (when
//! the view is vertical, +Y is up instead). `fov` is the full vertical field of view. Pixel
//! (i, j) counts from the top-left corner; a pixel's sample at sub-pixel offset (sx, sy) in
//! [0, 1) maps to the image-plane point `x = (2 (i + sx) / W - 1) tan(fov/2) W/H`,
//! `y = (1 - 2 (j + sy) / H) tan(fov/2)`, and the ray direction is `forward + x right + y up`,
//! normalised.

use super::scene::Ray;
use clothbake_core::Vec3;

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Unit view direction.
    pub forward: Vec3,
    /// Unit image-plane right.
    pub right: Vec3,
    /// Unit image-plane up.
    pub up: Vec3,
    /// tan(fov / 2).
    pub tan_half: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

/// Why a camera cannot be built.
#[derive(Clone, Debug, PartialEq)]
pub enum CameraError {
    /// The eye and the look-at point coincide.
    EyeAtTarget,
    /// The field of view is not in (0, 180) degrees.
    BadFov(f64),
}

impl Camera {
    /// A camera at `eye` looking at `look_at` with vertical field of view `fov_deg`.
    pub fn new(
        eye: Vec3,
        look_at: Vec3,
        fov_deg: f64,
        width: u32,
        height: u32,
    ) -> Result<Camera, CameraError> {
        let d = look_at - eye;
        if d.length() < 1e-9 {
            return Err(CameraError::EyeAtTarget);
        }
        if !(fov_deg > 0.0 && fov_deg < 180.0) {
            return Err(CameraError::BadFov(fov_deg));
        }
        let forward = d * (1.0 / d.length());
        let mut r = forward.cross(Vec3::new(0.0, 0.0, 1.0));
        if r.length() < 1e-9 {
            r = forward.cross(Vec3::new(0.0, 1.0, 0.0));
        }
        let right = r * (1.0 / r.length());
        Ok(Camera {
            eye,
            forward,
            right,
            up: right.cross(forward),
            tan_half: (fov_deg.to_radians() / 2.0).tan(),
            width,
            height,
        })
    }

    /// The vertical field of view (degrees) that frames the box `lo`..`hi` seen from `eye`
    /// looking at `look_at` in a `width` x `height` image, with a 5% margin (at most 120
    /// degrees; 60 when part of the box is behind the eye).
    pub fn fitting_fov(
        eye: Vec3,
        look_at: Vec3,
        width: u32,
        height: u32,
        lo: Vec3,
        hi: Vec3,
    ) -> f64 {
        let Ok(c) = Camera::new(eye, look_at, 60.0, width, height) else {
            return 60.0;
        };
        let aspect = f64::from(width) / f64::from(height);
        let mut t = 0.0f64;
        for k in 0..8 {
            let p = Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            ) - eye;
            let depth = p.dot(c.forward);
            if depth <= 1e-9 {
                return 60.0;
            }
            t = t.max((p.dot(c.up) / depth).abs());
            t = t.max((p.dot(c.right) / depth).abs() / aspect);
        }
        (2.0 * (1.05 * t).atan().to_degrees()).clamp(1.0, 120.0)
    }

    /// The ray through pixel (i, j) at sub-pixel offset (sx, sy).
    pub fn ray(&self, i: u32, j: u32, sx: f64, sy: f64) -> Ray {
        let (w, h) = (f64::from(self.width), f64::from(self.height));
        let x = (2.0 * (f64::from(i) + sx) / w - 1.0) * self.tan_half * w / h;
        let y = (1.0 - 2.0 * (f64::from(j) + sy) / h) * self.tan_half;
        let d = self.forward + self.right * x + self.up * y;
        Ray {
            origin: self.eye,
            dir: d * (1.0 / d.length()),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centre_pixel_looks_at_the_target_and_up_is_up() {
        let c = Camera::new(Vec3::new(0.0, -55.0, 45.0), Vec3::default(), 40.0, 101, 101).unwrap();
        let r = c.ray(50, 50, 0.5, 0.5);
        let want = Vec3::new(0.0, 55.0, -45.0) * (1.0 / 71.06335201775947);
        assert!((r.dir - want).length() < 1e-12);
        // The top row looks higher than the bottom row; the left column toward -x.
        assert!(c.ray(50, 0, 0.5, 0.5).dir.z > c.ray(50, 100, 0.5, 0.5).dir.z);
        assert!(c.ray(0, 50, 0.5, 0.5).dir.x < 0.0);
        // The top edge of the image is fov/2 above the axis.
        let top = c.ray(50, 0, 0.5, 0.0);
        assert!((top.dir.dot(c.forward).acos().to_degrees() - 20.0).abs() < 1e-9);
        assert!(Camera::new(Vec3::default(), Vec3::default(), 40.0, 1, 1).is_err());
        assert!(Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::default(), 40.0, 1, 1).is_ok());
        assert!(Camera::new(Vec3::new(0.0, 0.0, 5.0), Vec3::default(), 180.0, 1, 1).is_err());
    }
}
