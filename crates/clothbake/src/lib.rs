//! clothbake: bake the BRDF of woven cloth into tables renderers load.
//!
//! The library half of the `clothbake` binary: [`bake::bake`] sweeps the (theta_i, phi_i,
//! theta_o, phi_o) grid of a fabric in parallel and returns the table; [`compare`] holds two
//! tables against each other (`clothbake diff`, the golden tables of [`golden`]); [`albedo`]
//! integrates a table's directional albedo (`clothbake info`); [`output`] writes tables with
//! reproducible bytes; [`export`] writes the BRDF for other renderers (RGL `.bsdf`,
//! MERL binary). The file formats live in `clothbake-loader`, except the baker's own
//! shard and checkpoint files ([`shard`], [`merge`], [`checkpoint`]; docs/cluster.md).
//! [`render`] draws pictures of cloth (`clothbake render`) and [`plot`] plots BRDF slices and
//! hemisphere maps (`clothbake plot`).

pub mod albedo;
pub mod bake;
pub mod checkpoint;
pub mod compare;
pub mod export;
pub mod golden;
pub mod merge;
pub mod output;
pub mod plot;
pub mod render;
pub mod shard;
