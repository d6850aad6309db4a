//! clothbake-bake: bake a fabric's BRDF into a table.
//!
//! [`sweep`] evaluates the (theta_i, phi_i, theta_o, phi_o) grid of a fabric in parallel rows
//! through the model's BSDF and returns the table (its items are re-exported here: [`bake`],
//! [`BakeOptions`], [`Baker`]), the rows landing in the table's one buffer ([`assembly`]); the
//! leaves [`directions`] (a row's incident cell, a cell's direction) and [`orbit`] (the
//! symmetry orbits of the azimuth cells) serve it, [`spatial`] and [`transport`]; [`shard`],
//! [`merge`] and [`checkpoint`] split a bake into shards, assemble them and resume an
//! interrupted one (docs/guide/cluster.md); [`job`] runs a whole bake (checkpoints, resume, shard or
//! table file, cancellation) for the CLI and Python, under the output's [`lock`] and after the
//! [`memory`] check; [`settings`] checks and resolves the options as users give them;
//! [`output`] checks outputs and writes tables with reproducible bytes; [`compare`] holds two
//! tables against each other (`clothbake diff`, the golden tables of [`golden`]); [`albedo`]
//! integrates a table's directional albedo (`clothbake info`). The file formats live in
//! `clothbake-loader`. Nothing here parses command lines or draws progress bars: the
//! `clothbake` binary and the Python package call the same functions.

pub mod albedo;
pub mod assembly;
pub mod checkpoint;
pub mod compare;
pub mod directions;
pub mod golden;
pub mod job;
pub mod lock;
pub mod memory;
pub mod merge;
pub mod orbit;
pub mod output;
pub mod settings;
pub mod shard;
pub mod spatial;
pub mod sweep;
pub mod transport;
pub mod two_faced;

pub use sweep::*;
