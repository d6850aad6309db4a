//! clothbake-core: the analytic BRDF of woven cloth derived from its yarn geometry, after
//! Gang Huo, *Local Illumination Models from Surface Geometry* (UBC, 1993), chapters 2-5.
//!
//! The fabric it reads is `clothbake-fabric`'s (re-exported here: [`fabric`], [`weave`],
//! [`yarn`], [`wif`], [`source`], [`reflect`]). The ground truth it is measured against,
//! `clothbake-truth`, is a crate this one cannot see (and that cannot see it): only the tests
//! hold the two side by side.
//!
//! Frame: +X weft direction, +Y warp direction, +Z macro normal. `wi` points toward the light,
//! `wo` toward the eye. Quantities follow the thesis: the reflected *intensity* I for unit incident
//! intensity (pi times radiance; a flat Lambertian facet gives rho_d cos(theta_i)) and the BRDF
//! f_r = I / (pi cos(theta_i)) in 1/sr.

pub mod analytic;
pub mod arc;
pub mod brdf;
pub mod cells;
pub mod directions;
pub mod facet;
pub mod geometry;
pub mod interreflection;
pub mod lanes;
pub mod openness;
pub mod point;
pub mod quad;
pub mod shadowing;
pub mod symmetry;
pub mod trig;
mod unit_index;

pub use clothbake_bsdf::rng;
pub use clothbake_fabric::reflection as reflect;
pub use clothbake_fabric::{fabric, source, weave, wif, yarn};

pub use analytic::{
    AnalyticModel, CellClass, ClassTerms, LocalReflection, SecondaryMethod, SecondaryOptions,
    Variant, VariantError, SLICED3D_MAX_CELLS,
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
pub use vec3::{UnitVec3, Vec3};
pub use weave::{Group, Weave};
pub use wif::{WifError, WifOptions};
pub use yarn::{Material, Yarn, YarnGroup};
