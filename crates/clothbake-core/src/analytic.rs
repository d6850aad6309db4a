//! The analytic direct-reflection model (thesis ch. 3-4). (Being written.)

use crate::fabric::Fabric;
use crate::facet::FacetModel;
use crate::reflect::Reflection;
use crate::vec3::UnitVec3;

/// The thesis's analytic model of one fabric, with its look-up tables built once.
#[derive(Clone, Debug)]
pub struct AnalyticModel {
    facet: FacetModel,
    _fabric: Fabric,
}

impl AnalyticModel {
    /// Preprocesses the weave period (units, multiplicities, active-cylinder tables).
    pub fn new(fabric: &Fabric, facet: FacetModel) -> Self {
        AnalyticModel { facet, _fabric: fabric.clone() }
    }
    /// The facet model in use.
    pub fn facet(&self) -> FacetModel {
        self.facet
    }
    /// Directly reflected intensity toward `wo` for unit light from `wi` (eq. 4.11).
    pub fn eval(&self, _wi: UnitVec3, _wo: UnitVec3) -> Reflection {
        Reflection::default()
    }
}
