//! Ray-solid intersection of one yarn segment: the infinite cylinder's interval, the slab
//! between the end-cap planes, the half-space the plane z = 0 cuts (the floor's, or a face's
//! of the two-faced cloth), and the entry point of their intersection (which surface a ray
//! enters through).

use super::yarns::Face;

/// Which surface of a segment a ray enters through.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Surface {
    /// The curved side of the cylinder.
    Side,
    /// The end cap at the low end of the extent (outward normal: minus the axis direction).
    CapLo,
    /// The end cap at the high end of the extent (outward normal: plus the axis direction).
    CapHi,
    /// The flat face in the plane z = 0 of a two-faced cloth's segment (outward normal: -Z on
    /// the front, +Z on the back).
    Cut,
}

/// Parameter interval `(t_in, t_out)` in which the line `o + t d` lies inside the infinite
/// cylinder of radius `radius` whose axis is parallel to the v axis through (u, z) =
/// (`axis`, `height`); arguments are the u and z components of origin and direction. `None`
/// when the line misses it or runs parallel to the axis (`du = dz = 0`).
pub fn cylinder_interval(
    ou: f64,
    oz: f64,
    du: f64,
    dz: f64,
    axis: f64,
    height: f64,
    radius: f64,
) -> Option<(f64, f64)> {
    let a = du * du + dz * dz;
    if a == 0.0 {
        return None;
    }
    let (pu, pz) = (ou - axis, oz - height);
    let b = du * pu + dz * pz; // half the linear coefficient
    let c = pu * pu + pz * pz - radius * radius;
    let disc = b * b - a * c;
    if disc < 0.0 {
        return None;
    }
    // Numerically stable roots of a t^2 + 2 b t + c = 0.
    let q = -(b + disc.sqrt().copysign(b));
    if q == 0.0 {
        return Some((0.0, 0.0));
    }
    let (t0, t1) = (q / a, c / q);
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// Parameter interval in which the line `ov + t dv` (the component along a segment's axis)
/// lies between the planes of its two end caps, `lo <= v <= hi`. `None` when it never does.
/// Entering this slab while inside the cylinder and above the floor is exactly hitting a cap
/// disc (cut at z >= 0): the low cap when `dv > 0`, the high cap when `dv < 0`.
pub fn cap_slab_interval(ov: f64, dv: f64, lo: f64, hi: f64) -> Option<(f64, f64)> {
    if dv == 0.0 {
        return (lo..=hi)
            .contains(&ov)
            .then_some((f64::NEG_INFINITY, f64::INFINITY));
    }
    let (ta, tb) = ((lo - ov) / dv, (hi - ov) / dv);
    Some(if ta <= tb { (ta, tb) } else { (tb, ta) })
}

/// A ray in a segment's own frame: u across the axis (horizontal), v along it, z up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalRay {
    /// Origin (u, v, z).
    pub o: [f64; 3],
    /// Direction (u, v, z), not necessarily normalised.
    pub d: [f64; 3],
}

impl LocalRay {
    /// The ray `o + t d` (period coordinates) in the frame of a warp segment (`warp`: u = x,
    /// v = y) or a weft one (u = y, v = x).
    pub fn in_frame(
        warp: bool,
        o: clothbake_bsdf::vec3::Vec3,
        d: clothbake_bsdf::vec3::Vec3,
    ) -> LocalRay {
        if warp {
            LocalRay {
                o: [o.x, o.y, o.z],
                d: [d.x, d.y, d.z],
            }
        } else {
            LocalRay {
                o: [o.y, o.x, o.z],
                d: [d.y, d.x, d.z],
            }
        }
    }
}

/// The solid of one segment in its own frame: the cylinder about the axis at u = `axis`, z =
/// `height`, within `extent` along v (`None`: endless), cut by the plane z = 0 (kept: z >= 0
/// over the floor and on the front, z <= 0 on the back).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SegmentShape {
    /// Across coordinate of the axis.
    pub axis: f64,
    /// Height of the axis above the floor.
    pub height: f64,
    /// Cylinder radius.
    pub radius: f64,
    /// Extent along the axis, `None` when endless.
    pub extent: Option<(f64, f64)>,
    /// The side of z = 0 it lies on, and whether that plane is the floor.
    pub face: Face,
}

/// The first point where the ray enters the segment's solid with `t_min < t < t_max`, and the
/// surface it enters through. The solid is the intersection of three convex sets (infinite
/// cylinder, cap slab, half-space z >= 0), so the ray enters it at the last of their entries
/// and must do so before the first of their exits. An entry through the floor plane (a ray
/// coming from below the floor) is the floor's hit, not the yarn's, and gives `None`; on a
/// two-faced cloth the plane z = 0 is the segment's flat face, [`Surface::Cut`].
#[inline]
pub fn segment_entry(
    ray: &LocalRay,
    s: &SegmentShape,
    t_min: f64,
    t_max: f64,
) -> Option<(f64, Surface)> {
    let [ou, ov, oz] = ray.o;
    let [du, dv, dz] = ray.d;
    // The cap slab first: it is cheaper than the cylinder and rejects most segments a ray
    // passes beside along their axis. An entry at or after `t_max` or an exit at or before
    // `t_min` leaves no entry inside (t_min, t_max), whatever the cylinder gives.
    let slab = match s.extent {
        Some((lo, hi)) => {
            let (a, b) = cap_slab_interval(ov, dv, lo, hi)?;
            if a >= t_max || b <= t_min {
                return None;
            }
            Some((a, b))
        }
        None => None,
    };
    let (mut t_in, mut t_out) = cylinder_interval(ou, oz, du, dz, s.axis, s.height, s.radius)?;
    let mut surface = Surface::Side;
    if let Some((a, b)) = slab {
        if a > t_in {
            t_in = a;
            surface = if dv > 0.0 {
                Surface::CapLo
            } else {
                Surface::CapHi
            };
        }
        t_out = t_out.min(b);
    }
    match s.face {
        // Half-space z >= 0 over the floor.
        Face::OverFloor => {
            if dz < 0.0 {
                t_out = t_out.min(-oz / dz);
            } else if dz > 0.0 {
                if -oz / dz > t_in {
                    return None;
                }
            } else if oz < 0.0 {
                return None;
            }
        }
        // Half-space z >= 0 (front) or z <= 0 (back), entered through its flat face.
        Face::Front | Face::Back => {
            let (z, dzs) = if s.face == Face::Front {
                (oz, dz)
            } else {
                (-oz, -dz)
            };
            if dzs < 0.0 {
                t_out = t_out.min(-z / dzs);
            } else if dzs > 0.0 {
                let t_cut = -z / dzs;
                if t_cut > t_in {
                    t_in = t_cut;
                    surface = Surface::Cut;
                }
            } else if z < 0.0 {
                return None;
            }
        }
    }
    (t_in < t_out && t_in > t_min && t_in < t_max).then_some((t_in, surface))
}
