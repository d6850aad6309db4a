//! Yarns and their layout in the period (thesis ch. 2): the plain values a fabric is made of,
//! and the rules that place them, in one place for the fabric's validation and the geometry.
//!
//! * Thread i of a group sits at P_0 = 0, P_{i+1} = P_i + spacing_i across its direction; the
//!   period is the sum of the spacings and tiles the plane.
//! * Neighbouring threads may touch but not overlap: spacing_i >= r_i + r_{i+1}
//!   ([`spacing_fits`]); yarns given thicker than their spacing are packed ([`packed_radii`]).
//! * A float over crossing threads a..=b has, along its axis, the room between the surfaces of
//!   the crossing threads before and after it, [P_{a-1} + r_{a-1}, P_{b+1} - r_{b+1}]
//!   ([`float_room`]); a given segment length is centred in that room ([`float_extent`]).

use crate::weave::Float;

/// Facet material defaults of thesis sec. 4.3.
pub const DEFAULT_ALBEDO: f64 = 0.4;
/// Default specular coefficient rho_s (sec. 4.3).
pub const DEFAULT_SPECULAR: f64 = 0.3;
/// Default specular exponent n (sec. 4.3).
pub const DEFAULT_EXPONENT: f64 = 10.0;

/// Facet material of one yarn group.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Material {
    /// Diffuse albedo rho_d per RGB channel, each in [0, 1].
    pub albedo: [f64; 3],
    /// Specular coefficient rho_s in [0, 1].
    pub specular: f64,
    /// Specular exponent n >= 0.
    pub exponent: f64,
    /// Translucency tau in [0, 1]: what a yarn lets through its far side, as a share of what
    /// it gives back diffusely on the near side, in the same colour (the dye absorbs alike on
    /// both ways): t = tau rho_d ([`Material::transmittance`]). 0, the thesis's, lets nothing
    /// through. With tau > 0 the fabric must keep rho_d (1 + tau) + rho_s <= 1 in every
    /// channel. Only the two-faced cloth (docs/science/transmission.md) shows it.
    pub translucency: f64,
}

impl Material {
    /// The diffuse transmittance t of a facet per RGB channel: the share of the light arriving
    /// at a point that leaves the yarn diffusely (Lambertian) from the far end of the chord
    /// through the cross-section's middle, t = tau rho_d with tau the
    /// [`Material::translucency`] and rho_d the facet's diffuse albedo (`albedo`): the
    /// transmitted light has the reflected light's colour. With Lewis facets the reflected
    /// share is at most rho_d + rho_s, so R + t <= rho_d (1 + tau) + rho_s <= 1 (checked on
    /// the fabric) at every incident direction, and the absorbed share goes to 0 as that sum
    /// goes to 1 (docs/science/transmission.md).
    pub fn transmittance(&self, albedo: [f64; 3]) -> [f64; 3] {
        albedo.map(|a| self.translucency * a)
    }
}

impl Default for Material {
    fn default() -> Self {
        Material {
            albedo: [DEFAULT_ALBEDO; 3],
            specular: DEFAULT_SPECULAR,
            exponent: DEFAULT_EXPONENT,
            translucency: 0.0,
        }
    }
}

/// One thread of the period: its cylinder radius and axis height above the floor z = 0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Yarn {
    /// Cylinder radius (> 0).
    pub radius: f64,
    /// Height of the cylinder axis above the floor, in (-radius, radius); 0 is a half cylinder.
    pub height: f64,
    /// Centre-to-centre distance to the next thread of the same group (>= the two radii).
    pub spacing: f64,
    /// Explicit length of every float of this thread, or `None` to derive it ([`float_room`]).
    pub segment_length: Option<f64>,
    /// This thread's own diffuse albedo rho_d (RGB), overriding the group material's albedo;
    /// `None` to use the group's (fabric files: `thread_albedo`).
    pub albedo: Option<[f64; 3]>,
}

/// A yarn group (warp or weft): its threads in the period and their facet material.
#[derive(Clone, Debug, PartialEq)]
pub struct YarnGroup {
    /// One entry per thread of the period.
    pub threads: Vec<Yarn>,
    /// Facet material of the whole group (a thread's own albedo overrides its `albedo`).
    pub material: Material,
}

impl YarnGroup {
    /// Diffuse albedo of thread `t` (index modulo the period): its own, else the group's.
    pub fn albedo(&self, t: usize) -> [f64; 3] {
        self.threads[t % self.threads.len()]
            .albedo
            .unwrap_or(self.material.albedo)
    }

    /// Facet material of thread `t` (index modulo the period).
    pub fn thread_material(&self, t: usize) -> Material {
        Material {
            albedo: self.albedo(t),
            ..self.material
        }
    }

    /// Positions P_i of the threads across their direction, and the period (sum of spacings).
    pub fn positions(&self) -> (Vec<f64>, f64) {
        let mut pos = Vec::with_capacity(self.threads.len());
        let mut acc = 0.0;
        for t in &self.threads {
            pos.push(acc);
            acc += t.spacing;
        }
        (pos, acc)
    }

    /// Radius of thread `k` (any integer, taken modulo the period).
    pub fn radius(&self, k: isize) -> f64 {
        self.threads[k.rem_euclid(self.threads.len() as isize) as usize].radius
    }
}

/// Unwrapped position of thread `k` (any integer) of a group whose threads sit at `pos` in a
/// period of length `period` ([`YarnGroup::positions`]): P_{k mod n} + floor(k / n) period.
pub fn unwrapped_position(pos: &[f64], period: f64, k: isize) -> f64 {
    let n = pos.len() as isize;
    pos[k.rem_euclid(n) as usize] + k.div_euclid(n) as f64 * period
}

/// Whether threads of radii `r` and `r_next` may stand `spacing` apart: they may touch but not
/// overlap (to a relative 1e-12, so that sizes converted between units still touch).
pub fn spacing_fits(spacing: f64, r: f64, r_next: f64) -> bool {
    spacing >= (r + r_next) * (1.0 - 1e-12)
}

/// Radii of round yarns packed in a row: each thread's `radii[i]`, or less where it and a
/// neighbour would overlap at the centre distances `spacing` (`spacing[i]` from thread i to
/// thread i + 1, cyclic). An overlapping pair (i, i + 1) is scaled by f_i = spacing_i /
/// (r_i + r_{i+1}) so that it touches; a thread in two such pairs takes the smaller factor:
/// r'_i = r_i min(1, f_{i-1}, f_i). Threads that fit keep their radius; uniform yarns of
/// thickness T at spacing S < T get radius S / 2 (round yarns that touch). Returns the radii
/// and how many were capped.
pub fn packed_radii(radii: &[f64], spacing: &[f64]) -> (Vec<f64>, usize) {
    let n = radii.len();
    let factor = |i: usize| {
        let pair = radii[i] + radii[(i + 1) % n];
        if spacing_fits(spacing[i], radii[i], radii[(i + 1) % n]) {
            1.0
        } else {
            spacing[i] / pair
        }
    };
    let mut capped = 0;
    let out = (0..n)
        .map(|i| {
            let f = factor(i).min(factor((i + n - 1) % n));
            if f < 1.0 {
                capped += 1;
                radii[i] * f
            } else {
                radii[i]
            }
        })
        .collect();
    (out, capped)
}

/// The room a float `fl` has along its axis between the surfaces of the `crossing` group's
/// threads before and after it (unwrapped coordinates); `pos` and `period` are the crossing
/// group's [`YarnGroup::positions`].
pub fn float_room(crossing: &YarnGroup, pos: &[f64], period: f64, fl: Float) -> (f64, f64) {
    let a = fl.start as isize;
    let b = a + fl.len as isize; // first crossing thread after the float
    let lo = unwrapped_position(pos, period, a - 1) + crossing.radius(a - 1);
    let hi = unwrapped_position(pos, period, b) - crossing.radius(b);
    (lo, hi)
}

/// The extent of a float's segment along its axis: its room, or `segment_length` centred in it.
pub fn float_extent(room: (f64, f64), segment_length: Option<f64>) -> (f64, f64) {
    let (lo, hi) = room;
    match segment_length {
        Some(len) => {
            let mid = 0.5 * (lo + hi);
            (mid - 0.5 * len, mid + 0.5 * len)
        }
        None => (lo, hi),
    }
}
