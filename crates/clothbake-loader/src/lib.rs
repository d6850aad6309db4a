//! clothbake-loader: the baked BRDF table formats, and (issue 5, not yet built) render-time
//! lookup of baked tables.
//!
//! This crate is the one renderers link. [`mod@format`] reads and writes tables in both formats
//! (OpenEXR and the checksummed binary file); see `docs/table-format.md`.

pub mod format;

pub use format::{
    read_binary, read_exr, read_table, write_atomic, write_binary, write_exr, Grid, Metadata,
    Precision, Table, TableError, FORMAT_VERSION,
};
