//! clothbake-loader: the baked BRDF table formats and render-time lookup of baked tables.
//!
//! This crate is the one renderers link (from C through `clothbake-capi`). A [`Table`] (a
//! [`Grid`], its [`Metadata`] and RGB values) is read with [`read_table`] from either format:
//! OpenEXR ([`mod@exr`]) or the checksummed binary file ([`write_binary`]), which is one kind
//! of the binary [`mod@container`] that also holds the baker's shards and checkpoints; see
//! `docs/reference/table-format.md`. Files are written atomically ([`write_atomic_as`]).
//! [`mod@stored`] keeps half-float tables half in memory. [`mod@lookup`] interpolates them
//! ([`Brdf::eval`]) and [`mod@sampling`] importance-samples them ([`Brdf::sample`]); see
//! `docs/reference/loader.md`. A two-faced table (reflection and transmission over the sphere,
//! [`Faces::Two`]) opens as a [`TwoFacedBrdf`]; [`Lookup::open`] opens either kind.

pub mod angles;
mod atomic;
#[cfg(target_arch = "x86_64")]
mod avx2;
mod axis;
mod binary;
mod bsdf;
mod bytes;
pub mod container;
mod error;
pub mod exr;
mod grid;
pub mod lookup;
mod nodes;
mod padding;
mod read;
pub mod sampling;
mod simd;
pub mod spatial;
mod spatial_lookup;
pub mod stored;
mod table;
mod two_faced;

pub use atomic::{abandon_temporaries, bake_owned, check_target, write_atomic_as, Batch};
pub use axis::{Axis, Span};
pub use binary::{read_binary, write_binary};
pub use clothbake_bsdf::{Bsdf, BsdfSample, UnitVec3};
pub use container::{
    read_container, write_container, write_container_chunks, write_container_counted, Container,
    ContainerKind, BINARY_MAGIC, CONTAINER_VERSION,
};
pub use error::TableError;
pub use exr::{read_exr, read_exr_stored, write_exr, EXR_MAGIC};
pub use grid::{Faces, Grid, MAX_CELLS};
pub use half::f16;
pub use lookup::{Brdf, LengthMismatch, Memory, Options, Sample, SimdPath, HORIZON_COS};
pub use read::{read_table, read_table_stored};
pub use spatial::Spatial;
pub use spatial_lookup::SpatialLookup;
pub use stored::{Samples, StoredTable};
pub use table::{
    version_for, Metadata, Precision, Table, FORMAT_VERSION, MAX_VALUE, TWO_FACED_VERSION,
};
pub use two_faced::TwoFacedBrdf;

/// The lookup of a table of either kind: one-faced ([`Brdf`]) or two-faced ([`TwoFacedBrdf`]).
#[derive(Clone, Debug)]
pub enum Lookup {
    /// Reflection over the thesis's floor (boxed, as the other).
    One(Box<Brdf>),
    /// Reflection and transmission over the sphere, and the openness (boxed: four blocks).
    Two(Box<TwoFacedBrdf>),
}

impl Lookup {
    /// Opens a table file of either kind (either format), reading it once.
    pub fn open(path: &std::path::Path, options: Options) -> Result<Lookup, TableError> {
        Ok(match Brdf::open_either(path, options)? {
            lookup::Opened::One(b) => Lookup::One(b),
            lookup::Opened::Two(stored) => Lookup::Two(Box::new(
                TwoFacedBrdf::from_checked(*stored, options).map_err(|e| e.in_file(path))?,
            )),
        })
    }

    /// The lookup as a [`Bsdf`] (f over the sphere, sampling, the openness).
    pub fn into_bsdf(self) -> Box<dyn Bsdf + Send> {
        match self {
            Lookup::One(b) => b,
            Lookup::Two(t) => t,
        }
    }
}

/// How a one-faced lookup names a two-faced table it refuses ([`TableError::WrongKind`]).
pub(crate) const TWO_FACED: &str = "two-faced table";
