//! The open arcs of a [`Variant::Sliced3d`] model's slices toward directions known in
//! advance: what hides each slice's arc from a direction (`Around::open_arc`, the model's
//! dearest part) depends on that direction alone, so a bake, whose pairs reuse the grid's
//! directions row after row, finds it once a direction instead of once a pair.
//!
//! The arcs kept are those [`AnalyticModel::open_arcs`] computes, each set carrying its
//! direction and its model's key (so that no other model's arcs, and no other direction's, can
//! be kept), looked up by the direction's bits: a model with arcs kept gives the same bits as
//! one without.

use super::{AnalyticModel, Unit, Variant, View};
use crate::arc::ArcTrig;
use crate::vec3::UnitVec3;
use std::collections::HashMap;

/// The open arc of every slice of a [`Variant::Sliced3d`] model toward one direction, in the
/// order of the model's units and their slices ([`AnalyticModel::open_arcs`]), with that
/// direction and the model's key.
#[derive(Clone, Debug, PartialEq)]
pub struct OpenArcs {
    toward: [u64; 3],
    model: u64,
    arcs: Vec<ArcTrig>,
}

/// The key of a model's slices: a hash (FNV-1a) of all that decides their open arcs toward a
/// direction (each sliced unit's group, radius, height, floor, slices and the floats around
/// it), in order.
pub(super) fn model_key(units: &[Unit]) -> u64 {
    let mut hash = 0xcbf2_9ce4_8422_2325_u64;
    let mut key = Vec::new();
    for u in units {
        let Some(around) = &u.around else {
            continue;
        };
        let seg = &u.seg;
        key.clear();
        key.extend([
            f64::from(seg.group as u8),
            seg.radius,
            seg.height,
            seg.floor.arc.lo,
            seg.floor.arc.hi,
        ]);
        for sl in &u.slices {
            key.extend(sl.ranges.iter().flat_map(|&(a, b)| [a, b]));
        }
        around.key(0.0, 1.0, &mut key);
        for x in &key {
            for b in x.to_bits().to_le_bytes() {
                hash = (hash ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3);
            }
        }
    }
    hash
}

/// The open arcs kept for some directions (`AnalyticModel::keep_open_arcs`).
#[derive(Clone, Debug, Default)]
pub(super) struct ArcStore {
    /// Each direction's place, by the bits of its components.
    index: HashMap<[u64; 3], u32>,
    /// The arcs, `slices` a direction, in the directions' places.
    arcs: Vec<ArcTrig>,
    slices: usize,
}

fn bits(w: UnitVec3) -> [u64; 3] {
    let v = w.get();
    [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()]
}

impl ArcStore {
    /// The place of `w`'s arcs, if kept.
    pub(super) fn find(&self, w: UnitVec3) -> Option<u32> {
        if self.index.is_empty() {
            return None;
        }
        self.index.get(&bits(w)).copied()
    }

    /// Slice `slice`'s arc (numbered over the model) toward the direction at `place`.
    pub(super) fn arc(&self, place: u32, slice: usize) -> ArcTrig {
        self.arcs[place as usize * self.slices + slice]
    }
}

impl AnalyticModel {
    /// Slices whose open arcs [`AnalyticModel::open_arcs`] holds: every slice of a
    /// [`Variant::Sliced3d`] model, none of the other variants'. Each takes 48 bytes a
    /// direction kept.
    pub fn open_arc_slices(&self) -> usize {
        self.units
            .iter()
            .filter(|u| u.around.is_some())
            .map(|u| u.slices.len())
            .sum()
    }

    /// The number of directions whose open arcs are kept.
    pub fn open_arcs_kept(&self) -> usize {
        self.arc_store.index.len()
    }

    /// The part of each slice's cross-section that faces `w`, lies above the floor and is
    /// hidden by no float around it (docs/science/model.md, "The sliced3d variant"), for every slice
    /// of a [`Variant::Sliced3d`] model; empty for the other variants and below the horizon.
    pub fn open_arcs(&self, w: UnitVec3) -> OpenArcs {
        let mut out = OpenArcs {
            toward: bits(w),
            model: self.arcs_key,
            arcs: Vec::new(),
        };
        if self.variant != Variant::Sliced3d || !w.above_horizon() {
            return out;
        }
        let views = View::both(w.get());
        out.arcs.reserve(self.open_arc_slices());
        for u in self.units.iter().filter(|u| u.around.is_some()) {
            let v = &views[u.seg.group as usize];
            let arcs = u.slices.iter().enumerate();
            out.arcs
                .extend(arcs.map(|(k, sl)| self.slice_arc(u, k, sl, v)));
        }
        out
    }

    /// Keeps `arcs` ([`AnalyticModel::open_arcs`] of some directions) in place of computing
    /// them again for every pair with one of those directions: the same bits, faster where
    /// pairs share directions (a bake). Arcs of another model (by its key) and of directions
    /// below the horizon (none) are left out.
    pub fn keep_open_arcs(&mut self, arcs: impl IntoIterator<Item = OpenArcs>) {
        let slices = self.open_arc_slices();
        if slices == 0 {
            return;
        }
        let store = &mut self.arc_store;
        store.slices = slices;
        for a in arcs {
            let fits = a.model == self.arcs_key && a.arcs.len() == slices;
            if !fits || store.index.contains_key(&a.toward) {
                continue;
            }
            store.index.insert(a.toward, store.index.len() as u32);
            store.arcs.extend(a.arcs);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analytic::{ClassTerms, SecondaryOptions};
    use crate::cells::PeriodPoint;
    use crate::fabric::Fabric;
    use crate::facet::FacetModel;
    use crate::rng::Rng;

    fn random_direction(rng: &mut Rng) -> UnitVec3 {
        let (ct, phi) = (0.05 + 0.95 * rng.next_f64(), 360.0 * rng.next_f64());
        UnitVec3::from_degrees(ct.acos().to_degrees(), phi)
    }

    /// A model with the open arcs of some directions kept gives the bits of one without, for
    /// pairs of kept directions, of kept and other ones, and below the horizon: the average
    /// (with and without I_2), a cell's reflection and the classes' terms, on the twill and the
    /// gingham. Arcs kept under the wrong direction change the twill's values (the lookup is
    /// used); another model's arcs are not kept, and another variant keeps none.
    #[test]
    fn kept_arcs_give_the_bits_of_arcs_found_again() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
        let mut rng = Rng::new(11);
        for name in ["twill.json", "gingham.wif"] {
            let f = Fabric::from_path(&dir.join(name)).expect(name);
            let plain = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Sliced3d)
                .expect("the variant takes the period");
            let mut dirs: Vec<UnitVec3> = (0..10).map(|_| random_direction(&mut rng)).collect();
            let kept = dirs[..7].to_vec();
            dirs.push(UnitVec3::from_degrees(95.0, 30.0));
            let mut model = plain.clone();
            model.keep_open_arcs(kept.iter().map(|&w| plain.open_arcs(w)));
            assert!(kept.iter().all(|&w| model.arc_store.find(w).is_some()));
            assert!(model.arc_store.find(dirs[8]).is_none());
            let opts = SecondaryOptions::default();
            let classes = plain.classes();
            let bounce = plain.cell_classes_with(true).len();
            let cell = plain
                .cells()
                .cell_at(PeriodPoint::new(0.3, 0.6).expect("in"));
            for &wi in &dirs {
                for &wo in &dirs {
                    assert_eq!(model.intensity(wi, wo), plain.intensity(wi, wo));
                    let both = |m: &AnalyticModel| m.intensity_with(wi, wo, Some(&opts));
                    assert_eq!(both(&model), both(&plain));
                    let local = |m: &AnalyticModel| m.intensity_in(wi, wo, cell, None);
                    assert_eq!(local(&model), local(&plain));
                    let terms = |m: &AnalyticModel| {
                        let mut t = vec![ClassTerms::default(); classes];
                        m.class_terms(wi, wo, &mut t);
                        t
                    };
                    assert_eq!(terms(&model), terms(&plain));
                    let bounced = |m: &AnalyticModel| {
                        let mut t = vec![ClassTerms::default(); m.bounce_unit.len()];
                        m.class_terms_with(wi, wo, Some(&opts), &mut t);
                        t
                    };
                    assert!(bounce > 0);
                    assert_eq!(bounced(&model), bounced(&plain));
                }
            }
        }
        // The wrong arcs kept: the values follow them.
        let f = Fabric::from_path(&dir.join("twill.json")).expect("twill");
        let plain = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Sliced3d)
            .expect("the variant takes the period");
        let (a, b) = (
            UnitVec3::from_degrees(70.0, 20.0),
            UnitVec3::from_degrees(60.0, 200.0),
        );
        let mut wrong = plain.clone();
        let mut b_as_a = plain.open_arcs(b);
        b_as_a.toward = bits(a);
        wrong.keep_open_arcs([b_as_a]);
        assert_ne!(wrong.intensity(a, b), plain.intensity(a, b));
        // Another model's arcs are not kept: the satin's, and those of the twill with another
        // spacing, as many as the twill's.
        let twill = std::fs::read_to_string(dir.join("twill.json")).expect("twill");
        let wider = twill.replace("\"spacing\": 3.1", "\"spacing\": 3.3");
        assert_ne!(wider, twill);
        let wider = Fabric::from_json_str(&wider, "wider.json").expect("wider twill");
        let wider = AnalyticModel::with_variant(&wider, FacetModel::Huo, Variant::Sliced3d)
            .expect("the variant takes the period");
        assert_eq!(wider.open_arc_slices(), plain.open_arc_slices());
        let satin = Fabric::from_path(&dir.join("satin5.json")).expect("satin");
        let satin = AnalyticModel::with_variant(&satin, FacetModel::Huo, Variant::Sliced3d)
            .expect("the variant takes the period");
        let mut model = plain.clone();
        model.keep_open_arcs([wider.open_arcs(a), satin.open_arcs(a)]);
        assert_eq!(model.open_arcs_kept(), 0);
        model.keep_open_arcs([plain.open_arcs(a)]);
        assert_eq!(model.open_arcs_kept(), 1);
        let mut refined = AnalyticModel::new(&f, FacetModel::Huo);
        assert_eq!(refined.open_arc_slices(), 0);
        refined.keep_open_arcs([plain.open_arcs(a)]);
        assert!(refined.arc_store.find(a).is_none());
    }
}
