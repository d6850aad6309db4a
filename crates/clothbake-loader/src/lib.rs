//! clothbake-loader: the baked BRDF table formats and render-time lookup of baked tables.
//!
//! This crate is the one renderers link (from C through `clothbake-capi`). [`mod@format`]
//! reads and writes tables in both formats (OpenEXR and the checksummed binary file); see
//! `docs/table-format.md`. [`mod@stored`] keeps half-float tables half in memory.
//! [`mod@lookup`] interpolates them ([`Brdf::eval`]) and [`mod@sampling`] importance-samples
//! them ([`Brdf::sample`]); see `docs/loader.md`.

pub mod angles;
#[cfg(target_arch = "x86_64")]
mod avx2;
mod bsdf;
pub mod format;
pub mod lookup;
mod nodes;
pub mod sampling;
pub mod stored;

pub use clothbake_bsdf::{Bsdf, BsdfSample, UnitVec3};
pub use format::{
    read_binary, read_exr, read_exr_stored, read_table, read_table_stored, write_atomic,
    write_binary, write_exr, Grid, Metadata, Precision, Table, TableError, FORMAT_VERSION,
};
pub use half::f16;
pub use lookup::{Brdf, Kernel, LengthMismatch, Memory, Options, Sample, HORIZON_COS};
pub use stored::{Samples, StoredTable};
