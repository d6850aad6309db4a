//! The names of the facet (microscopic) reflection models a fabric is shaded with (thesis
//! sec. 4.2). The formulas live with the analytic model (`clothbake_core::facet`) and, written
//! again on purpose, with the ground truth (`clothbake_truth::facets`); this is the selector
//! both read.

use serde::{Deserialize, Serialize};

/// The selectable facet models.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum FacetModel {
    /// The thesis's Phong-like terms: I_d = rho_d N.L (eq. 4.6), I_s = rho_s (N.H)^n (eq. 4.8).
    /// Neither reciprocal nor energy conserving (Lewis 1993).
    #[default]
    Huo,
    /// Lewis's modified Phong (the thesis's future-work item): f = rho_d / pi +
    /// rho_s (n + 2) / (2 pi) (R.E)^n, reciprocal, and energy conserving when rho_d + rho_s <= 1.
    Lewis,
}

impl FacetModel {
    /// Name as used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            FacetModel::Huo => "huo",
            FacetModel::Lewis => "lewis",
        }
    }
}
