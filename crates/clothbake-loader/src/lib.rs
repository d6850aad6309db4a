//! clothbake-loader: render-time lookup of baked BRDF tables (issue 5; not yet built).
//!
//! This crate is the one renderers link. It is empty until the baker writes tables.
