//! clothbake-fabric: the woven fabric as clothbake reads it, and the vocabulary the analytic
//! model (`clothbake-core`) and the ground truth (`clothbake-truth`) share without seeing each
//! other.
//!
//! * [`weave`]: the interlacing pattern (thesis ch. 2: which yarn floats on top at each crossing);
//! * [`yarn`]: a yarn group's sizes and facet material;
//! * [`fabric`]: the validated [`Fabric`] and its JSON file format
//!   (docs/reference/fabric-format.md), every error naming the file, the field and the fix;
//! * [`wif`]: weaving drafts (WIF 1.1, docs/reference/wif.md);
//! * [`source`]: reading a fabric file safely (bounded, no FIFOs), JSON or WIF;
//! * [`facet_model`]: which facet model shades the yarns ([`FacetModel`]);
//! * [`reflection`]: what both answer: [`Reflection`] (eq. 4.11), [`Secondary`] (eq. 5.15),
//!   the second bounce's [`Kernel`], and [`intensity_to_brdf`].
//!
//! Lengths are in one arbitrary unit; the frame is +X weft, +Y warp, +Z the macro normal.

pub mod fabric;
pub mod facet_model;
pub mod reflection;
pub mod source;
pub mod weave;
pub mod wif;
pub mod yarn;

pub use fabric::{Fabric, FabricError, Field, Naming, PlainNaming};
pub use facet_model::FacetModel;
pub use reflection::{intensity_to_brdf, Kernel, Reflection, Secondary};
pub use weave::{Group, Weave};
pub use wif::{WifError, WifOptions};
pub use yarn::{Material, Yarn, YarnGroup};
