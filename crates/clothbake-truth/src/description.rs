//! The one door from the model's side: the only file of the truth that reads a
//! [`Fabric`] or names the model's facet selector. It copies the fabric's
//! description (weave pattern, per-thread radius, height, spacing, given segment length and facet
//! material) into the truth's own plain [`Description`], from which [`super::yarns`] builds the
//! micro-geometry by its own rules.

use super::facets::Terms;
use super::raytracer::RayTracer;
use super::yarns::Yarns;
use clothbake_fabric::fabric::Fabric;
use clothbake_fabric::weave::{Group, Weave};
use clothbake_fabric::FacetModel;

/// The facet material of one thread, as the truth shades it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Finish {
    /// Diffuse albedo rho_d, RGB.
    pub albedo: [f64; 3],
    /// Specular coefficient rho_s.
    pub specular: f64,
    /// Specular exponent n.
    pub exponent: f64,
    /// Diffuse transmittance through the yarn, RGB (docs/science/transmission.md; 0 for opaque yarn).
    pub transmittance: [f64; 3],
}

/// One thread of the period, as described (lengths in the fabric's unit).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Thread {
    /// Cylinder radius.
    pub radius: f64,
    /// Height of the axis above the floor z = 0.
    pub height: f64,
    /// Centre-to-centre distance to the next thread of its group (the last one's: to the first
    /// thread of the next period).
    pub spacing: f64,
    /// Length of each of its floats when given, `None` to derive it from the crossing threads.
    pub length: Option<f64>,
    /// Its facet material (the thread's own albedo where it has one, else its group's).
    pub finish: Finish,
}

/// A fabric's description: the weave period and the threads of both groups.
#[derive(Clone, Debug, PartialEq)]
pub struct Description {
    /// The point-paper period (1: warp over weft).
    pub weave: Weave,
    /// Warp threads (pattern columns, along +Y), in order of increasing x.
    pub warp: Vec<Thread>,
    /// Weft threads (pattern rows, along +X), in order of increasing y.
    pub weft: Vec<Thread>,
}

impl Description {
    /// The description of a validated fabric.
    pub fn of(fabric: &Fabric) -> Description {
        let threads = |g: Group| -> Vec<Thread> {
            let group = fabric.group(g);
            group
                .threads
                .iter()
                .map(|y| {
                    let albedo = y.albedo.unwrap_or(group.material.albedo);
                    Thread {
                        radius: y.radius,
                        height: y.height,
                        spacing: y.spacing,
                        length: y.segment_length,
                        finish: Finish {
                            albedo,
                            specular: group.material.specular,
                            exponent: group.material.exponent,
                            transmittance: group.material.transmittance(albedo),
                        },
                    }
                })
                .collect()
        };
        Description {
            weave: fabric.weave().clone(),
            warp: threads(Group::Warp),
            weft: threads(Group::Weft),
        }
    }

    /// The threads of group `g`.
    pub fn threads(&self, g: Group) -> &[Thread] {
        match g {
            Group::Warp => &self.warp,
            Group::Weft => &self.weft,
        }
    }
}

impl Terms {
    /// The truth's facet terms for the model's selector of the same name.
    pub fn of(model: FacetModel) -> Terms {
        match model {
            FacetModel::Huo => Terms::Huo,
            FacetModel::Lewis => Terms::Lewis,
        }
    }
}

impl RayTracer {
    /// Builds the tracer (its own micro-geometry and acceleration cells) of a validated fabric,
    /// shading with the facet terms named by `facet`.
    pub fn new(fabric: &Fabric, facet: FacetModel) -> RayTracer {
        RayTracer::from_description(&Description::of(fabric), Terms::of(facet))
    }

    /// The tracer of the fabric's two-faced cloth (docs/science/transmission.md): its front as
    /// [`RayTracer::new`] builds it, its back the inverted weave mirrored below z = 0, no
    /// floor, every surface shaded (caps and the flat undersides included) and translucent
    /// yarns transmitting.
    pub fn two_faced(fabric: &Fabric, facet: FacetModel) -> RayTracer {
        RayTracer::from_yarns(
            Yarns::build_two_faced(&Description::of(fabric)),
            Terms::of(facet),
        )
        .with_caps(super::raytracer::Caps::Shaded)
    }
}
