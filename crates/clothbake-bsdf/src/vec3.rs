//! Small 3-vector algebra and unit directions in the fabric's local frame.
//!
//! Frame: +X is the weft direction, +Y the warp direction, +Z the macro normal.
//! Angles: `theta` from +Z, `phi` from +X toward +Y, both in radians unless a name says degrees.

use std::ops::{Add, Mul, Neg, Sub};

/// A plain 3-vector.
#[derive(Clone, Copy, Debug, PartialEq, Default)]
pub struct Vec3 {
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

impl Vec3 {
    /// Builds a vector from its components.
    #[inline]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
    /// Dot product.
    #[inline]
    pub fn dot(self, o: Vec3) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }
    /// Euclidean length.
    #[inline]
    pub fn length(self) -> f64 {
        self.dot(self).sqrt()
    }
    /// Cross product.
    #[inline]
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(
            self.y * o.z - self.z * o.y,
            self.z * o.x - self.x * o.z,
            self.x * o.y - self.y * o.x,
        )
    }
    /// True when every component is finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline]
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl Sub for Vec3 {
    type Output = Vec3;
    #[inline]
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl Mul<f64> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, s: f64) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    #[inline]
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}

/// Cosines at or below this count as on or below the horizon (about 90 - 6e-8 degrees).
pub const HORIZON_COS: f64 = 1e-9;

/// A direction of unit length. Constructed only through normalising constructors,
/// so every `UnitVec3` in the program is finite and has length 1 (to rounding).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct UnitVec3(Vec3);

impl UnitVec3 {
    /// +Z, the macro normal of the fabric.
    pub const Z: UnitVec3 = UnitVec3(Vec3::new(0.0, 0.0, 1.0));

    /// Normalises `v`; `None` for a zero-length or non-finite vector.
    #[inline]
    pub fn new(v: Vec3) -> Option<Self> {
        let l = v.length();
        if !(l.is_finite() && l > 1e-300) {
            return None;
        }
        Some(UnitVec3(v * (1.0 / l)))
    }

    /// The direction at polar angle `theta` (from +Z) and azimuth `phi` (from +X toward +Y), radians.
    #[inline]
    pub fn from_spherical(theta: f64, phi: f64) -> Self {
        let (st, ct) = theta.sin_cos();
        let (sp, cp) = phi.sin_cos();
        UnitVec3(Vec3::new(st * cp, st * sp, ct))
    }

    /// As [`UnitVec3::from_spherical`] with angles in degrees.
    #[inline]
    pub fn from_degrees(theta_deg: f64, phi_deg: f64) -> Self {
        Self::from_spherical(theta_deg.to_radians(), phi_deg.to_radians())
    }

    /// The polar angle from +Z and the azimuth from +X (radians, azimuth in (-pi, pi]).
    #[inline]
    pub fn to_spherical(self) -> (f64, f64) {
        (self.0.z.clamp(-1.0, 1.0).acos(), self.0.y.atan2(self.0.x))
    }

    /// The underlying vector.
    #[inline]
    pub fn get(self) -> Vec3 {
        self.0
    }
    /// Cosine of the angle to the macro normal +Z.
    #[inline]
    pub fn cos_theta(self) -> f64 {
        self.0.z
    }
    /// True when the direction is above the horizon: cos(theta) > [`HORIZON_COS`]. Directions at
    /// the horizon (theta = 90 degrees, whose cosine rounds to about 6e-17) count as below it.
    #[inline]
    pub fn above_horizon(self) -> bool {
        self.0.z > HORIZON_COS
    }
    /// True when the direction is below the horizon, on the cloth's back: cos(theta) <
    /// -[`HORIZON_COS`].
    #[inline]
    pub fn below_horizon(self) -> bool {
        self.0.z < -HORIZON_COS
    }
    /// The opposite direction.
    #[inline]
    pub fn reverse(self) -> Self {
        UnitVec3(Vec3::new(-self.0.x, -self.0.y, -self.0.z))
    }
    /// Mirror image under z -> -z: a direction of the back seen in the front's frame.
    #[inline]
    pub fn mirror_z(self) -> Self {
        UnitVec3(Vec3::new(self.0.x, self.0.y, -self.0.z))
    }
    /// Mirror image under x -> -x.
    #[inline]
    pub fn mirror_x(self) -> Self {
        UnitVec3(Vec3::new(-self.0.x, self.0.y, self.0.z))
    }
    /// Mirror image under y -> -y.
    #[inline]
    pub fn mirror_y(self) -> Self {
        UnitVec3(Vec3::new(self.0.x, -self.0.y, self.0.z))
    }
    /// Rotation by +90 degrees about +Z: (x, y) -> (-y, x).
    #[inline]
    pub fn rotate_z90(self) -> Self {
        UnitVec3(Vec3::new(-self.0.y, self.0.x, self.0.z))
    }
}

impl std::ops::Deref for UnitVec3 {
    type Target = Vec3;
    #[inline]
    fn deref(&self) -> &Vec3 {
        &self.0
    }
}

/// The half vector of two unit directions, `None` when they are opposite.
#[inline]
pub fn half_vector(a: UnitVec3, b: UnitVec3) -> Option<UnitVec3> {
    UnitVec3::new(a.get() + b.get())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spherical_round_trip() {
        let d = UnitVec3::from_degrees(35.0, 120.0);
        let (t, p) = d.to_spherical();
        assert!((t.to_degrees() - 35.0).abs() < 1e-12);
        assert!((p.to_degrees() - 120.0).abs() < 1e-12);
        assert!((d.length() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn zero_vector_is_not_a_direction() {
        assert!(UnitVec3::new(Vec3::default()).is_none());
        assert!(UnitVec3::new(Vec3::new(f64::NAN, 0.0, 1.0)).is_none());
    }
}
