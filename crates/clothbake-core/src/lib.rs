//! clothbake-core: the BRDF of woven cloth derived from its yarn geometry, after
//! Gang Huo, *Local Illumination Models from Surface Geometry* (UBC, 1993), chapters 2-4,
//! with an exact ray tracer of the same micro-geometry as ground truth.
//!
//! Frame: +X weft direction, +Y warp direction, +Z macro normal. `wi` points toward the light,
//! `wo` toward the eye. Quantities follow the thesis: the reflected *intensity* I for unit incident
//! intensity (pi times radiance; a flat Lambertian facet gives rho_d cos(theta_i)) and the BRDF
//! f_r = I / (pi cos(theta_i)) in 1/sr.

pub mod analytic;
pub mod arc;
pub mod brdf;
pub mod cells;
pub mod fabric;
pub mod facet;
pub mod geometry;
pub mod interreflection;
pub mod lanes;
pub mod openness;
pub mod point;
pub mod quad;
pub mod reflect;
pub mod rng;
pub mod shadowing;
pub mod source;
pub mod symmetry;
pub mod transport;
pub mod trig;
pub mod truth;
mod unit_index;
pub mod validate;
pub mod weave;
pub mod wif;
pub mod yarn;

pub use analytic::{
    check_variant, AnalyticModel, CellClass, ClassTerms, LocalReflection, SecondaryMethod,
    SecondaryOptions, Variant, SLICED3D_MAX_CELLS,
};
pub use brdf::{AnalyticBsdf, Component};
pub use cells::{Cell, CellGrid, PeriodPoint};
pub use clothbake_bsdf::{
    cosine_sample, two_sided_pdf, two_sided_sample, vec3, Bsdf, BsdfSample, Footprint, FromFn,
    Level, Local, Rgb,
};
pub use fabric::{Fabric, FabricError, Field, Naming, PlainNaming};
pub use facet::{Facet, FacetIntensity, FacetModel};
pub use geometry::Geometry;
pub use interreflection::{Kernel, Secondary};
pub use reflect::{intensity_to_brdf, Reflection};
pub use transport::{Transport, ALL_BOUNCES};
/// The path tracer under its former module name.
pub use truth::pathtracer as pathtrace;
pub use truth::{Caps, Estimate, PathEstimate, PathOptions, RayTracer};
pub use vec3::{UnitVec3, Vec3};
pub use weave::{Group, Weave};
pub use wif::{WifError, WifOptions};
pub use yarn::{Material, Yarn, YarnGroup};
