//! The direct model (eq. 4.11) for four direction pairs at once, one pair a lane of an AVX
//! register: [`AnalyticModel::intensity_batch`].
//!
//! Each function in `avx2.rs` is the lane form of the scalar one in `analytic.rs`, `arc.rs` or
//! `shadowing.rs` it names, with the same arithmetic in the same order: branches become
//! selects (both sides computed, each lane keeping its own), a table's active occluder is
//! chosen by a chain of selects over the table's entries, and terms a lane skips add an exact
//! zero. So every lane gives the bits the scalar evaluation gives (tested on every shipped
//! fabric). The lanes are AVX registers: on a processor without AVX2 (or not x86-64) the batch is
//! evaluated pair by pair, with the same results.
//!
//! Covered: Huo facets whose exponents are whole numbers up to 4096 (the closed-form specular
//! integral, eq. 4.10), the `thesis` and `refined` variants, one bounce. Anything else (Lewis
//! facets, an exponent the closed form does not take, the `sliced` variant) is evaluated pair by
//! pair by
//! [`AnalyticModel::intensity`].

use super::AnalyticModel;
use crate::analytic::ClassTerms;
#[cfg(target_arch = "x86_64")]
use crate::facet::FacetModel;
use crate::reflect::Reflection;
use crate::vec3::UnitVec3;

#[cfg(target_arch = "x86_64")]
mod avx2;

/// The Huo exponent of every unit's material as the closed form takes it, `None` where one
/// does not.
#[cfg(target_arch = "x86_64")]
fn whole_exponents(m: &AnalyticModel) -> Option<Vec<u32>> {
    // The sliced variant's units are evaluated slice by slice, pair by pair.
    if m.facet != FacetModel::Huo || m.variant == super::Variant::Sliced {
        return None;
    }
    m.units
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
        if let Some(exps) = whole_exponents(self) {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: AVX2 was detected.
                unsafe { avx2::run_avx2(self, &exps, pairs, out) };
                return;
            }
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
        if let Some(exps) = whole_exponents(self) {
            if std::arch::is_x86_feature_detected!("avx2") {
                // SAFETY: AVX2 was detected.
                unsafe { avx2::run_classes_avx2(self, &exps, pairs, out) };
                return;
            }
        }
        for (o, &(wi, wo)) in out.chunks_mut(classes).zip(pairs) {
            self.class_terms(wi, wo, o);
        }
    }
}
