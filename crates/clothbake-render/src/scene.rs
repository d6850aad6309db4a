//! The scenes `clothbake render` draws, and where a ray meets them.
//!
//! World frame: right-handed, +Z up. Every scene carries a tangent frame at each surface point
//! (the cloth's weft direction, its warp direction and the outward normal), so that light and
//! eye directions can be expressed in the fabric's local frame (+X weft, +Y warp, +Z normal):
//!
//! * `swatch`: the square `|x|, |y| <= half` on z = 0; weft +X, warp +Y, normal +Z.
//! * `disk`: the disk `x^2 + y^2 <= radius^2` on z = 0, the same frame (the disk of thesis
//!   sec. 5.4, whose cylinders run along +Y).
//! * `sphere`: radius r at the origin; weft = the eastward tangent (increasing longitude,
//!   `Z x N` normalised), warp = `N x weft` (toward the north pole +Z, the cylinders following the
//!   meridians as in `cargo xtask ch5`); at the poles, where east is undefined, weft = +X projected.
//! * `drape`: a smooth height field z = h(x, y) over the square `|x|, |y| <= half`, a uniform
//!   bicubic B-spline (C2) through fixed fold-shaped control heights, shifted so that its exact
//!   mean over the square is 0 ("resting on average on the z = 0 plane", thesis sec. 4.3).
//!   weft = dP/dx projected into the tangent plane, warp = N x weft.

use clothbake_core::Vec3;

/// A ray: origin and unit direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Origin.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

impl Ray {
    /// The point at parameter `t`.
    pub fn at(&self, t: f64) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// A surface point with its tangent frame (orthonormal, right-handed: weft x warp = normal).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// The point.
    pub point: Vec3,
    /// Outward (upper-side) unit normal: the fabric's local +Z.
    pub normal: Vec3,
    /// Unit weft direction in the tangent plane: the fabric's local +X.
    pub weft: Vec3,
    /// Unit warp direction, `normal x weft`: the fabric's local +Y.
    pub warp: Vec3,
    /// Surface coordinates along the weft and the warp, in scene lengths: (x, y) on the flat
    /// scenes and the drape (its slopes ignored), (r longitude, r latitude) on the sphere.
    pub surface: (f64, f64),
}

impl Hit {
    /// `v` in the local frame (weft, warp, normal) components.
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.weft), v.dot(self.warp), v.dot(self.normal))
    }
}

/// A scene: one surface.
#[derive(Clone, Debug, PartialEq)]
pub enum Scene {
    /// Flat square on z = 0.
    Swatch {
        /// Half the side.
        half: f64,
    },
    /// Flat disk on z = 0.
    Disk {
        /// Radius.
        radius: f64,
    },
    /// Sphere at the origin.
    Sphere {
        /// Radius.
        radius: f64,
    },
    /// Bicubic-spline height field.
    Drape(Drape),
}

/// The default sizes: a swatch and drape of side 60 (the thesis's eye at (0, -55, 45) sees the
/// whole cloth), the disk of radius 5 and the unit sphere of `cargo xtask ch5`.
impl Scene {
    /// The flat square of half side `half`.
    pub fn swatch(half: f64) -> Scene {
        Scene::Swatch { half }
    }

    /// The scene `name` (swatch, disk, sphere, drape) at its default size.
    pub fn by_name(name: &str) -> Option<Scene> {
        Some(match name {
            "swatch" => Scene::Swatch { half: 30.0 },
            "disk" => Scene::Disk { radius: 5.0 },
            "sphere" => Scene::Sphere { radius: 1.0 },
            "drape" => Scene::Drape(Drape::default()),
            _ => return None,
        })
    }

    /// The scene's width along x, in scene lengths: what `render --periods N` divides into N
    /// weave periods.
    pub fn width(&self) -> f64 {
        let (lo, hi) = self.bounds();
        hi.x - lo.x
    }

    /// The corners (low, high) of a box enclosing the scene, for framing the camera.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        let sq = |h: f64, zlo: f64, zhi: f64| (Vec3::new(-h, -h, zlo), Vec3::new(h, h, zhi));
        match self {
            Scene::Swatch { half } => sq(*half, 0.0, 0.0),
            Scene::Disk { radius } => sq(*radius, 0.0, 0.0),
            Scene::Sphere { radius } => sq(*radius, -radius, *radius),
            Scene::Drape(d) => {
                let (lo, hi) = d.z_range();
                sq(d.half, lo, hi)
            }
        }
    }

    /// The first intersection of `ray` with the surface (t > 0), with its tangent frame.
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let up = Vec3::new(0.0, 0.0, 1.0);
        let flat = |p: Vec3| Hit {
            point: p,
            normal: up,
            weft: Vec3::new(1.0, 0.0, 0.0),
            warp: Vec3::new(0.0, 1.0, 0.0),
            surface: (p.x, p.y),
        };
        match self {
            Scene::Swatch { half } => {
                let p = plane_hit(ray)?;
                (p.x.abs() <= *half && p.y.abs() <= *half).then(|| flat(p))
            }
            Scene::Disk { radius } => {
                let p = plane_hit(ray)?;
                (p.x * p.x + p.y * p.y <= radius * radius).then(|| flat(p))
            }
            Scene::Sphere { radius } => {
                let b = ray.origin.dot(ray.dir);
                let c = ray.origin.dot(ray.origin) - radius * radius;
                let disc = b * b - c;
                if disc < 0.0 {
                    return None;
                }
                let s = disc.sqrt();
                let t = if -b - s > 1e-9 { -b - s } else { -b + s };
                if t <= 1e-9 {
                    return None;
                }
                let p = ray.at(t);
                let n = unit(p);
                let surface = (
                    radius * p.y.atan2(p.x),
                    radius * n.z.clamp(-1.0, 1.0).asin(),
                );
                Some(frame(p, n, up.cross(n), Vec3::new(1.0, 0.0, 0.0), surface))
            }
            Scene::Drape(d) => d.intersect(ray),
        }
    }
}

fn unit(v: Vec3) -> Vec3 {
    v * (1.0 / v.length())
}

/// The frame at `p` with normal `n` and weft along `t` projected into the tangent plane
/// (`fallback` where `t` has no tangential part), at surface coordinates `surface`.
fn frame(p: Vec3, n: Vec3, t: Vec3, fallback: Vec3, surface: (f64, f64)) -> Hit {
    let proj = |v: Vec3| v - n * v.dot(n);
    let mut w = proj(t);
    if w.length() < 1e-9 {
        w = proj(fallback);
    }
    let weft = unit(w);
    Hit {
        point: p,
        normal: n,
        weft,
        warp: n.cross(weft),
        surface,
    }
}

/// Where `ray` crosses z = 0 going forward.
fn plane_hit(ray: &Ray) -> Option<Vec3> {
    if ray.dir.z.abs() < 1e-12 {
        return None;
    }
    let t = -ray.origin.z / ray.dir.z;
    (t > 1e-9).then(|| ray.at(t))
}

/// A bicubic uniform B-spline height field over a square (see the module documentation).
#[derive(Clone, Debug, PartialEq)]
pub struct Drape {
    /// Half the side of the square.
    pub half: f64,
    /// Control points per side (at least 4).
    pub n: usize,
    /// Control heights, row-major (`c[j * n + i]`, i along x), with zero exact mean surface height.
    pub c: Vec<f64>,
}

/// Weights of the four cubic B-spline basis segments at local parameter `f` in [0, 1].
fn basis(f: f64) -> [f64; 4] {
    let g = 1.0 - f;
    [
        g * g * g / 6.0,
        (3.0 * f * f * f - 6.0 * f * f + 4.0) / 6.0,
        (-3.0 * f * f * f + 3.0 * f * f + 3.0 * f + 1.0) / 6.0,
        f * f * f / 6.0,
    ]
}

/// Derivatives of [`basis`] with respect to `f`.
fn basis_d(f: f64) -> [f64; 4] {
    let g = 1.0 - f;
    [
        -g * g / 2.0,
        (9.0 * f * f - 12.0 * f) / 6.0,
        (-9.0 * f * f + 6.0 * f + 3.0) / 6.0,
        f * f / 2.0,
    ]
}

/// Integrals over [0, 1] of the four basis segments (they add up to 1).
const BASIS_INTEGRAL: [f64; 4] = [1.0 / 24.0, 11.0 / 24.0, 11.0 / 24.0, 1.0 / 24.0];

impl Default for Drape {
    /// The drape of the thesis's scenes: side 60, 9 x 9 control heights of a few folds
    /// (heights within about +-6).
    fn default() -> Self {
        let n = 9;
        let c = (0..n * n)
            .map(|k| {
                let (i, j) = ((k % n) as f64, (k / n) as f64);
                6.0 * (0.65 * (1.3 * i + 0.4 * j).sin() + 0.35 * (0.9 * j - 0.5 * i + 1.0).cos())
            })
            .collect();
        Drape::new(30.0, n, c)
    }
}

impl Drape {
    /// A drape over `|x|, |y| <= half` with `n` x `n` control heights (row-major), shifted by
    /// their exact mean surface height so that the surface rests on average on z = 0.
    pub fn new(half: f64, n: usize, mut c: Vec<f64>) -> Drape {
        assert!(
            n >= 4 && c.len() == n * n,
            "a drape needs n >= 4 and n*n heights"
        );
        // Integral weight of control point i over the parameter domain [0, n - 3].
        let mut w = vec![0.0; n];
        for span in 0..n - 3 {
            for (k, b) in BASIS_INTEGRAL.iter().enumerate() {
                w[span + k] += b;
            }
        }
        let area = ((n - 3) * (n - 3)) as f64;
        let mean: f64 = (0..n * n).map(|k| w[k % n] * w[k / n] * c[k]).sum::<f64>() / area;
        for x in &mut c {
            *x -= mean;
        }
        Drape { half, n, c }
    }

    /// Span spacing in world units.
    fn spacing(&self) -> f64 {
        2.0 * self.half / (self.n - 3) as f64
    }

    /// (span, local parameter) of a world coordinate.
    fn locate(&self, x: f64) -> (usize, f64) {
        let t = ((x + self.half) / self.spacing()).clamp(0.0, (self.n - 3) as f64);
        let k = (t.floor() as usize).min(self.n - 4);
        (k, t - k as f64)
    }

    /// Height and its x and y derivatives at (x, y).
    pub fn height(&self, x: f64, y: f64) -> (f64, f64, f64) {
        let ((ki, fi), (kj, fj)) = (self.locate(x), self.locate(y));
        let (bi, bj, di, dj) = (basis(fi), basis(fj), basis_d(fi), basis_d(fj));
        let (mut h, mut hx, mut hy) = (0.0, 0.0, 0.0);
        for (b, (&wj, &dwj)) in bj.iter().zip(&dj).enumerate() {
            let row = &self.c[(kj + b) * self.n + ki..][..4];
            for (a, &c) in row.iter().enumerate() {
                h += bi[a] * wj * c;
                hx += di[a] * wj * c;
                hy += bi[a] * dwj * c;
            }
        }
        let s = self.spacing();
        (h, hx / s, hy / s)
    }

    /// Bounds of the height (the control heights' range: the convex hull property).
    pub fn z_range(&self) -> (f64, f64) {
        self.c
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &z| {
                (lo.min(z), hi.max(z))
            })
    }

    /// The surface point and frame at (x, y).
    pub fn hit_at(&self, x: f64, y: f64) -> Hit {
        let (h, hx, hy) = self.height(x, y);
        let n = unit(Vec3::new(-hx, -hy, 1.0));
        frame(
            Vec3::new(x, y, h),
            n,
            Vec3::new(1.0, 0.0, hx),
            Vec3::new(0.0, 1.0, 0.0),
            (x, y),
        )
    }

    /// First crossing of the ray with the surface inside the square: marching in steps of an
    /// eighth of a span, then bisection.
    fn intersect(&self, ray: &Ray) -> Option<Hit> {
        let (zlo, zhi) = self.z_range();
        let lo = Vec3::new(-self.half, -self.half, zlo - 1e-6);
        let hi = Vec3::new(self.half, self.half, zhi + 1e-6);
        let (mut t0, mut t1) = (1e-9f64, f64::INFINITY);
        for (o, d, l, h) in [
            (ray.origin.x, ray.dir.x, lo.x, hi.x),
            (ray.origin.y, ray.dir.y, lo.y, hi.y),
            (ray.origin.z, ray.dir.z, lo.z, hi.z),
        ] {
            if d.abs() < 1e-15 {
                if o < l || o > h {
                    return None;
                }
            } else {
                let (a, b) = ((l - o) / d, (h - o) / d);
                t0 = t0.max(a.min(b));
                t1 = t1.min(a.max(b));
            }
        }
        if t0 >= t1 {
            return None;
        }
        let gap = |t: f64| {
            let p = ray.at(t);
            p.z - self.height(p.x, p.y).0
        };
        let step = self.spacing() / 8.0;
        let (mut a, mut ga) = (t0, gap(t0));
        loop {
            let b = (a + step).min(t1);
            let gb = gap(b);
            if (ga > 0.0) != (gb > 0.0) {
                let (mut l, mut h) = (a, b);
                for _ in 0..40 {
                    let m = 0.5 * (l + h);
                    if (gap(m) > 0.0) == (ga > 0.0) {
                        l = m;
                    } else {
                        h = m;
                    }
                }
                let p = ray.at(0.5 * (l + h));
                return Some(self.hit_at(p.x, p.y));
            }
            if b >= t1 {
                return None;
            }
            (a, ga) = (b, gb);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn drape_rests_on_average_on_z0() {
        // Midpoint rule on a fine grid, independent of the exact B-spline integral weights.
        let d = Drape::default();
        let m = 400;
        let mut s = 0.0;
        for j in 0..m {
            for i in 0..m {
                let x = -d.half + (i as f64 + 0.5) * 2.0 * d.half / m as f64;
                let y = -d.half + (j as f64 + 0.5) * 2.0 * d.half / m as f64;
                s += d.height(x, y).0;
            }
        }
        let mean = s / (m * m) as f64;
        let (lo, hi) = d.z_range();
        assert!(hi - lo > 4.0, "the drape has folds");
        assert!(mean.abs() < 1e-3, "mean height {mean}");
    }

    #[test]
    fn drape_derivatives_match_finite_differences_and_frame_is_orthonormal() {
        let d = Drape::default();
        for &(x, y) in &[(0.3, -7.1), (12.0, 4.4), (-25.0, 25.0), (-3.3, 0.1)] {
            let (_, hx, hy) = d.height(x, y);
            let e = 1e-5;
            let fx = (d.height(x + e, y).0 - d.height(x - e, y).0) / (2.0 * e);
            let fy = (d.height(x, y + e).0 - d.height(x, y - e).0) / (2.0 * e);
            assert!((hx - fx).abs() < 1e-6 && (hy - fy).abs() < 1e-6);
            let h = d.hit_at(x, y);
            for (a, b) in [(h.weft, h.warp), (h.warp, h.normal), (h.normal, h.weft)] {
                assert!(a.dot(b).abs() < 1e-12);
            }
            for v in [h.weft, h.warp, h.normal] {
                assert!((v.length() - 1.0).abs() < 1e-12);
            }
            // Right-handed, weft follows dP/dx, normal upward.
            assert!((h.weft.cross(h.warp) - h.normal).length() < 1e-12);
            assert!(h.weft.dot(Vec3::new(1.0, 0.0, hx)) > 0.0 && h.normal.z > 0.0);
        }
    }

    #[test]
    fn drape_hit_lies_on_the_surface() {
        let d = Drape::default();
        let scene = Scene::Drape(d.clone());
        let origin = Vec3::new(3.0, -55.0, 45.0);
        for k in 0..20 {
            let target = Vec3::new(-20.0 + 2.0 * k as f64, 10.0 - k as f64, 0.0);
            let ray = Ray {
                origin,
                dir: unit(target - origin),
            };
            let h = scene.intersect(&ray).expect("hits the cloth");
            assert!((h.point.z - d.height(h.point.x, h.point.y).0).abs() < 1e-6);
            // Nothing of the surface lies between the eye and the hit: the gap stays positive.
            let t_hit = (h.point - origin).length();
            for s in 1..200 {
                let p = ray.at(t_hit * s as f64 / 200.0 * 0.999);
                if p.x.abs() <= d.half && p.y.abs() <= d.half {
                    assert!(p.z > d.height(p.x, p.y).0 - 1e-9);
                }
            }
        }
    }

    #[test]
    fn sphere_frame_follows_the_meridians() {
        let s = Scene::Sphere { radius: 2.0 };
        let ray = Ray {
            origin: Vec3::new(10.0, 0.5, 0.7),
            dir: Vec3::new(-1.0, 0.0, 0.0),
        };
        let h = s.intersect(&ray).unwrap();
        assert!((h.point.length() - 2.0).abs() < 1e-12);
        assert!((h.normal - h.point * 0.5).length() < 1e-12);
        // Warp points north (positive z component), weft east (increasing longitude).
        assert!(h.warp.z > 0.0);
        let east = Vec3::new(-h.point.y, h.point.x, 0.0);
        assert!(h.weft.dot(east) > 0.0 && h.weft.z.abs() < 1e-12);
        assert!((h.weft.cross(h.warp) - h.normal).length() < 1e-12);
    }

    #[test]
    fn flat_scenes() {
        let ray = Ray {
            origin: Vec3::new(0.0, -10.0, 10.0),
            dir: unit(Vec3::new(0.0, 10.0, -10.0)),
        };
        assert!(Scene::Disk { radius: 5.0 }.intersect(&ray).is_some());
        let away = Ray {
            origin: ray.origin,
            dir: unit(Vec3::new(0.0, 1.0, 1.0)),
        };
        assert!(Scene::Disk { radius: 5.0 }.intersect(&away).is_none());
        let far = Ray {
            origin: ray.origin,
            dir: unit(Vec3::new(0.0, 1.0, -0.1)),
        };
        assert!(Scene::Swatch { half: 30.0 }.intersect(&far).is_none());
    }
}
