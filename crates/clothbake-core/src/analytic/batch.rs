//! The direct model (eq. 4.11) in the lanes of an AVX register: four direction pairs at once,
//! one pair a lane ([`AnalyticModel::intensity_batch`]), or one pair with up to four of its
//! units (or, with the `sliced` variant, of its units' slices) at once, one a lane
//! ([`AnalyticModel::intensity`]; the terms summed afterwards in the units' and slices' order,
//! as the scalar evaluation sums them).
//!
//! Each function in `avx2.rs` is the lane form of the scalar one in `evaluate.rs`, `arc.rs` or
//! `shadowing.rs` it names, with the same arithmetic in the same order: branches become
//! selects (both sides computed, each lane keeping its own), a table's active occluder is
//! chosen by a chain of selects over the table's entries, and terms a lane skips add an exact
//! zero. So every lane gives the bits the scalar evaluation gives (tested on every shipped
//! fabric). The lanes are AVX registers: on a processor without AVX2 (or not x86-64) the batch is
//! evaluated pair by pair, with the same results.
//!
//! Covered: Huo facets whose exponents are whole numbers up to 4096 (the closed-form specular
//! integral, eq. 4.10), one bounce; four pairs at a time the `thesis` and `refined` variants,
//! one pair at a time all three. Anything else (Lewis facets, an exponent the closed form does
//! not take, the second bounce) is evaluated unit by unit.

use super::{AnalyticModel, Unit};
use crate::analytic::ClassTerms;
use crate::facet::FacetModel;
use crate::reflect::Reflection;
use crate::vec3::UnitVec3;

#[cfg(target_arch = "x86_64")]
mod avx2;

#[cfg(target_arch = "x86_64")]
pub(crate) use avx2::Lanes;

/// Where the lanes are not built (not x86-64).
#[cfg(not(target_arch = "x86_64"))]
#[derive(Clone, Debug)]
pub(crate) struct Lanes;

/// The units in lanes, where the processor has AVX2 and the closed forms take every unit;
/// `None` elsewhere (the model is then evaluated unit by unit).
pub(super) fn lanes(facet: FacetModel, units: &[Unit]) -> Option<Lanes> {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        return Lanes::new(units, &whole_exponents(facet, units)?);
    }
    let _ = (facet, units);
    None
}

/// The Huo exponent of every unit's material as the closed form takes it, `None` where one
/// does not.
#[cfg(target_arch = "x86_64")]
fn whole_exponents(facet: FacetModel, units: &[Unit]) -> Option<Vec<u32>> {
    if facet != FacetModel::Huo {
        return None;
    }
    units
        .iter()
        .map(|u| {
            let mat = &u.seg.material;
            if mat.specular == 0.0 {
                Some(0)
            } else if mat.exponent.fract() == 0.0 && (0.0..=4096.0).contains(&mat.exponent) {
                Some(mat.exponent as u32)
            } else {
                None
            }
        })
        .collect()
}

impl AnalyticModel {
    /// Directly reflected intensity (eq. 4.11) for each pair of directions (light `wi`, eye
    /// `wo`): `out[k]` is [`AnalyticModel::intensity`] of `pairs[k]`, bit for bit, computed
    /// four pairs at a time in the f64 lanes of AVX2 registers. Huo facets with whole
    /// exponents up to 4096 take the lanes; other facets, and processors without AVX2, are
    /// evaluated pair by pair.
    ///
    /// # Panics
    /// If `out` and `pairs` differ in length.
    pub fn intensity_batch(&self, pairs: &[(UnitVec3, UnitVec3)], out: &mut [Reflection]) {
        assert_eq!(pairs.len(), out.len(), "one output per pair");
        #[cfg(target_arch = "x86_64")]
        if let Some(lanes) = self.lanes.as_ref().filter(|l| l.take_batches()) {
            // SAFETY: the lanes are built only where AVX2 was detected.
            unsafe { avx2::run_avx2(self, lanes, pairs, out) };
            return;
        }
        for (o, &(wi, wo)) in out.iter_mut().zip(pairs) {
            *o = self.intensity(wi, wo);
        }
    }

    /// [`AnalyticModel::class_terms`] of each pair: pair `k`'s entries (one per class) are
    /// `out[k * classes..(k + 1) * classes]`, bit for bit; four pairs at a time in AVX2 lanes
    /// where [`AnalyticModel::intensity_batch`] takes them, else pair by pair.
    ///
    /// # Panics
    /// If `out` does not hold one entry per class for each pair.
    pub fn class_terms_batch(&self, pairs: &[(UnitVec3, UnitVec3)], out: &mut [ClassTerms]) {
        let classes = self.classes();
        assert_eq!(
            out.len(),
            pairs.len() * classes,
            "one entry per class and pair"
        );
        if classes == 0 {
            return;
        }
        #[cfg(target_arch = "x86_64")]
        if let Some(lanes) = self.lanes.as_ref().filter(|l| l.take_batches()) {
            // SAFETY: the lanes are built only where AVX2 was detected.
            unsafe { avx2::run_classes_avx2(self, lanes, pairs, out) };
            return;
        }
        for (o, &(wi, wo)) in out.chunks_mut(classes).zip(pairs) {
            self.class_terms(wi, wo, o);
        }
    }

    /// Eq. 4.11 without I_2 for one pair above the horizon, its units in the lanes of AVX2
    /// registers (the bits of the unit-by-unit evaluation); `None` where the lanes do not
    /// take this model.
    #[inline]
    pub(super) fn intensity_in_lanes(&self, wi: UnitVec3, wo: UnitVec3) -> Option<Reflection> {
        #[cfg(target_arch = "x86_64")]
        if let Some(lanes) = &self.lanes {
            // SAFETY: the lanes are built only where AVX2 was detected.
            return Some(unsafe { avx2::one_avx2(self, lanes, wi, wo) });
        }
        let _ = (wi, wo);
        None
    }
}
