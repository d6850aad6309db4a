//! clothbake: bake the BRDF of woven cloth into tables renderers load.
//!
//! The library half of the `clothbake` binary: [`bake::bake`] sweeps the (theta_i, phi_i,
//! theta_o, phi_o) grid of a fabric in parallel and returns the table; the file formats live in
//! `clothbake-loader`.

pub mod bake;
