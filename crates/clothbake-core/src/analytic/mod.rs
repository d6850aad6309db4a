//! The analytic direct-reflection model (thesis ch. 3-4).
//!
//! Preprocessing ([`AnalyticModel::new`]) cuts every segment of the period into *pieces*, one per
//! crossing it floats over (the piece's cross-section sees that crossing row's neighbours), builds
//! for each piece the active-occluder tables of its two cross-section sides and for each segment
//! those of its two ends (sec. 3.2), and merges identical pieces into independent *units* with
//! multiplicities D_i (eq. 4.11). Evaluation ([`AnalyticModel::intensity`]) then, per unit:
//!
//! 1. arc: above-floor arc, minus self-shadowing/self-blocking (Poulin & Fournier), minus the
//!    arc the active neighbour hides from L and from E (eqs 3.4-3.5);
//! 2. length: the segment's length minus what the active occluders at its ends hide from L and
//!    from E (eq. 3.6), intersected with the piece (sec. 4.1's length code and its "case 2" with
//!    a mixed neighbourhood follow from treating each piece on its own);
//! 3. projected areas S_vi, S_v (eqs 4.2-4.3, with the |E_p| factor that makes the areas of warp
//!    and weft pieces comparable) and the arc integrals of the facet terms with the
//!    cos(theta - theta_E) correction (eqs 4.4-4.10);
//! 4. the area-weighted average I = sum D_i I_i / sum D_i S_v,i (eq. 4.11 and its pseudocode).

use crate::arc::{
    diffuse_integral, huo_specular_integral, projected_width, Arc, ArcTrig, Heading, Polar,
    Projected,
};
use crate::cells::{Cell, CellGrid, PeriodPoint};
use crate::fabric::{Fabric, Material};
use crate::facet::{Facet, FacetModel};
use crate::geometry::{equal_area_height, Geometry, Segment};
use crate::interreflection::{
    analytic as secondary_analytic, two_level_sampling, Kernel, Orders, Pair, Ranges, Sampling,
    Secondary, Setting,
};
use crate::quad::integrate;
use crate::reflect::{intensity_to_brdf, Reflection};
use crate::shadowing::{
    mean_occluded_length, occluded_arc_at, occluded_length, ActiveTable, ArcOcclusion, Elevation,
    Occluder,
};
use crate::unit_index::UnitIndex;
use crate::vec3::{UnitVec3, Vec3};
use crate::weave::Group;
use std::f64::consts::PI;

mod build;
mod classes;
mod coverage;
mod evaluate;
mod secondary;
mod variant;

use build::*;
use evaluate::*;
use secondary::*;
pub use variant::*;

/// Below this, a projected component counts as zero (direction in a symmetry plane).
const EPS: f64 = 1e-12;

/// Per-segment data shared by its pieces.
#[derive(Clone, Debug, PartialEq)]
struct SegmentData {
    group: Group,
    radius: f64,
    height: f64,
    /// Height of the segment's equal-area rectangle (eq. 3.1), its top in axial profiles.
    top: f64,
    /// The arc of its cross-section above the floor.
    floor: ArcTrig,
    /// Extent along the axis; `None` when endless.
    extent: Option<(f64, f64)>,
    /// Occluders beyond the +axis end and beyond the -axis end.
    end_plus: ActiveTable,
    end_minus: ActiveTable,
    material: Material,
}

/// An independent unit: a piece of a segment with its cross-section neighbourhood.
#[derive(Clone, Debug)]
struct Unit {
    seg: SegmentData,
    /// Range of the piece along the axis.
    range: (f64, f64),
    /// Occluders on the +c side and on the -c side of the cross-section.
    side_plus: ActiveTable,
    side_minus: ActiveTable,
    /// The parallel neighbours on the +c and -c sides, for secondary reflection (sec. 5.4):
    /// each distinct pair met by the unit's pieces, with how many pieces meet it (the counts
    /// sum to `count`). Pieces alike in themselves can stand beside different neighbours.
    neighbours: Vec<([Option<Neighbour>; 2], u32)>,
    /// Number of identical pieces in the period (D_i).
    count: u32,
    /// [`Variant::Sliced`]: the piece's range in slices, each with its own side profiles (in
    /// place of `range`'s `side_plus` and `side_minus`); empty for the other variants.
    slices: Vec<Slice>,
    /// [`Variant::Sliced3d`]: the floats around the piece, which decide what hides its slices'
    /// sides (each slice then one range).
    around: Option<around::Around>,
    /// The number of its first slice among the model's slices with `around` (their open arcs'
    /// order, [`AnalyticModel::open_arcs`]).
    first_slice: usize,
}

/// Parts of a piece's range along which its cross-section profile is one and the same
/// ([`Variant::Sliced`]): the parts with equal side tables together, so that their arcs are
/// computed once. With [`Variant::Sliced3d`] one range each and empty tables (`slice_arc`).
#[derive(Clone, Debug)]
struct Slice {
    ranges: Vec<(f64, f64)>,
    side_plus: ActiveTable,
    side_minus: ActiveTable,
}

impl Slice {
    fn tables(&self) -> (&ActiveTable, &ActiveTable) {
        (&self.side_plus, &self.side_minus)
    }
}

/// A parallel cylinder next to a piece, in the piece's crossing row (thesis sec. 5.4: cloth's
/// inter-reflection approximated by that between adjacent parallel segments).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Neighbour {
    /// Axis-to-axis distance.
    d: f64,
    radius: f64,
    height: f64,
    /// Its extent along the axis relative to the piece's middle (infinite when endless).
    axial: (f64, f64),
    material: Material,
}

/// How the secondary reflection (thesis ch. 5) is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SecondaryMethod {
    /// The analytical solution (sec. 5.3).
    Analytic {
        /// Integration ranges.
        ranges: Ranges,
        /// Quadrature orders.
        orders: Orders,
    },
    /// The two-level ray-traced sampling (sec. 5.2).
    Sampling(Sampling),
}

/// Options of the secondary reflection.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SecondaryOptions {
    /// Solution method.
    pub method: SecondaryMethod,
    /// Second-bounce weight.
    pub kernel: Kernel,
}

impl Default for SecondaryOptions {
    fn default() -> Self {
        SecondaryOptions {
            method: SecondaryMethod::Analytic {
                ranges: Ranges::Full,
                orders: Orders::default(),
            },
            kernel: Kernel::default(),
        }
    }
}

/// Inventory of the preprocessing, for reports and tests.
#[derive(Clone, Debug, PartialEq)]
pub struct UnitSummary {
    /// Warp or weft.
    pub group: Group,
    /// Multiplicity D_i.
    pub count: u32,
    /// Piece length along the axis.
    pub length: f64,
    /// Entries in the four active-occluder tables (+c, -c, +axis end, -axis end).
    pub table_sizes: [usize; 4],
}

/// The thesis's analytic model of one fabric, with its look-up tables built once.
#[derive(Clone, Debug)]
pub struct AnalyticModel {
    facet: FacetModel,
    variant: Variant,
    units: Vec<Unit>,
    /// The period's crossing cells.
    grid: CellGrid,
    /// The unit each cell shows and the unit's neighbour pair there, by [`CellGrid::index`].
    cell_units: Vec<(u32, u32)>,
    /// The class of each unit: units that differ in their threads' diffuse albedos only.
    unit_class: Vec<u32>,
    /// A unit of each class.
    class_unit: Vec<u32>,
    /// The class with the second bounce of each cell, by [`CellGrid::index`]: cells whose
    /// class and neighbours' geometry agree (their albedos may differ).
    bounce_class: Vec<u32>,
    /// Each such class's unit and neighbour pair (the variant), as in `cell_units`.
    bounce_unit: Vec<(u32, u32)>,
    /// The units in AVX2 lanes, where the processor and the closed forms take them (`batch`).
    lanes: Option<batch::Lanes>,
    /// [`Variant::Sliced3d`]: the open arcs kept for directions given in advance.
    arc_store: open_arcs::ArcStore,
    /// The key of the units' slices the open arcs belong to (`open_arcs::model_key`).
    arcs_key: u64,
}

/// A class's reflection for one pair of directions, per unit diffuse albedo
/// (docs/science/spatial.md): a cell of the class whose thread has albedo rho_d reflects
/// f_r = rho_d `diffuse` + `specular` (eqs 4.1, 4.11 restricted to the cell's piece). With the
/// second bounce (eq. 5.15, sec. 5.4), its neighbours on the +c and -c sides, of albedos
/// rho_+ and rho_-, add sum_k rho_k (`neighbour[k]` + rho_d `both[k]`), and `diffuse` and
/// `specular` include I_sd and I_ss.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ClassTerms {
    /// f_r of the terms proportional to the thread's own diffuse albedo, at rho_d = 1, in 1/sr.
    pub diffuse: f64,
    /// f_r of the terms of no diffuse albedo (the specular term; with the second bounce also
    /// I_ss), in 1/sr.
    pub specular: f64,
    /// f_r of I_ds from the neighbour on the +c side and on the -c side, per unit albedo of
    /// that neighbour (0 with one bounce).
    pub neighbour: [f64; 2],
    /// f_r of I_dd from each side, per unit albedo of both threads (0 with one bounce).
    pub both: [f64; 2],
    /// The piece's visible projected area seen from `wo` over the period's projected area:
    /// a cell's coverage is this over the cell's share of the period's area.
    pub visible: f64,
}

/// What a spatial table records of one crossing cell: its class and the albedos its
/// [`ClassTerms`] are multiplied by.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellClass {
    /// The class of the unit the cell shows.
    pub class: u32,
    /// The diffuse albedo of its thread.
    pub albedo: [f64; 3],
    /// The diffuse albedos of its parallel neighbours on the +c and -c sides (0 where there
    /// is none); they matter with the second bounce only.
    pub neighbours: [[f64; 3]; 2],
}

/// What the model answers at one point of the weave period (docs/science/spatial.md).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LocalReflection {
    /// The intensity averaged over the visible yarn of the cell (eq. 4.11 restricted to the
    /// cell's unit): f_r(x) = I / (pi cos theta_i). Zero where `coverage` is zero.
    pub reflection: Reflection,
    /// c(x; wo): the visible yarn's projected area over the cell per unit projected area of the
    /// cell, seen from `wo` (0 where the eye sees no yarn).
    pub coverage: f64,
}

impl AnalyticModel {
    /// The facet model in use.
    pub fn facet(&self) -> FacetModel {
        self.facet
    }

    /// The model variant in use.
    pub fn variant(&self) -> Variant {
        self.variant
    }

    /// The independent units of the period (eq. 4.11's m units and their D_i).
    pub fn units(&self) -> Vec<UnitSummary> {
        self.units
            .iter()
            .map(|u| UnitSummary {
                group: u.seg.group,
                count: u.count,
                length: u.range.1 - u.range.0,
                table_sizes: [
                    u.side_plus.entries.len(),
                    u.side_minus.entries.len(),
                    u.seg.end_plus.entries.len(),
                    u.seg.end_minus.entries.len(),
                ],
            })
            .collect()
    }
}

mod around;
mod open_arcs;
pub use open_arcs::OpenArcs;
mod batch;

#[cfg(test)]
mod reference;

#[cfg(test)]
mod tests {
    use super::*;

    fn fabric(s: &str) -> Fabric {
        Fabric::from_json_str(s, "t").unwrap()
    }

    const TWILL: &str = r#"{"pattern": [[1,1,0],[0,1,1],[1,0,1]],
        "warp": {"radius": 1.5, "spacing": 3.1}, "weft": {"radius": 1.5, "spacing": 3.1}}"#;

    /// The masking and shadowing shares against the ray tracer on parallel cylinders, where
    /// the model's cross-section construction is exact; with the light at the eye, shadowing
    /// is masking on both sides.
    #[test]
    fn masking_and_shadowing_shares_match_the_truth_on_parallel_cylinders() {
        let f = fabric(
            r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2}, "weft": {"radius": 1, "spacing": 2}}"#,
        );
        let m = AnalyticModel::new(&f, FacetModel::Huo);
        let t = clothbake_truth::RayTracer::new(&f, FacetModel::Huo);
        let n = 100_000;
        for (wi, wo) in crate::directions::direction_set(12, 70.0) {
            let (seen, lit) = t.visible_and_lit(wi, wo, n, 3);
            // Binomial standard errors bound the stratified estimate's.
            let tol = |p: f64| 4.0 * (p * (1.0 - p) / n as f64).sqrt() + 1e-4;
            let (c, l) = (m.coverage(wo), m.lit_coverage(wi, wo));
            assert!(
                (c - seen).abs() < tol(seen),
                "coverage {c} vs traced {seen}"
            );
            assert!((l - lit).abs() < tol(lit), "lit {l} vs traced {lit}");
            assert!(l <= c && lit <= seen);
            assert_eq!(m.lit_coverage(wo, wo), c);
            assert_eq!(
                t.visible_and_lit(wo, wo, 2000, 5).0,
                t.visible_and_lit(wo, wo, 2000, 5).1
            );
        }
    }

    #[test]
    fn twill_has_three_independent_units() {
        // Diagonal shift symmetry: every warp float's first piece is alike, every second piece,
        // and every weft piece.
        let m = AnalyticModel::new(&fabric(TWILL), FacetModel::Huo);
        let u = m.units();
        assert_eq!(u.len(), 3, "{u:?}");
        assert_eq!(u.iter().map(|x| x.count).sum::<u32>(), 9);
    }

    #[test]
    fn normal_light_and_view_on_parallel_cylinders() {
        // Touching half cylinders (d = 2r): with L = E = +Z nothing is hidden, and
        // I_d = rho_d int_0^pi sin^2 / int_0^pi sin = rho_d pi / 4.
        let f = fabric(
            r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2},
            "weft": {"radius": 1, "spacing": 2}, }"#
                .replace(", }", "}")
                .as_str(),
        );
        let m = AnalyticModel::new(&f, FacetModel::Huo);
        let r = m.intensity(UnitVec3::Z, UnitVec3::Z);
        assert!((r.i_d[0] - 0.4 * PI / 4.0).abs() < 1e-12, "{:?}", r);
        // Specular: rho_s int_0^pi sin^n sin / 2 = rho_s int sin^11 / 2.
        let q = integrate(&mut |t: f64| t.sin().powi(11), 0.0, PI, 1e-14);
        assert!((r.i_s[0] - 0.3 * q / 2.0).abs() < 1e-12);
    }

    #[test]
    fn lone_cylinder_matches_brute_force_arc_average() {
        // One endless half cylinder, neighbours 1000 radii away: only self-shadowing and
        // self-blocking act. Reference: a plain Riemann sum over the half circle with
        // indicator functions, independent of the arc code.
        let f = fabric(
            r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 1000},
                "weft": {"radius": 0.5, "spacing": 1}}"#,
        );
        let m = AnalyticModel::new(&f, FacetModel::Huo);
        for (ti, pi, to, po) in [
            (30.0, 0.0, 50.0, 180.0),
            (70.0, 180.0, 20.0, 180.0),
            (45.0, 30.0, 60.0, 250.0),
        ] {
            let (wi, wo) = (
                UnitVec3::from_degrees(ti, pi),
                UnitVec3::from_degrees(to, po),
            );
            let (l, e) = (wi.get(), wo.get());
            let (mut num_d, mut num_s, mut den) = (0.0, 0.0, 0.0);
            let steps = 200_000;
            for k in 0..steps {
                let t = (k as f64 + 0.5) / steps as f64 * PI;
                let n = Vec3::new(t.cos(), 0.0, t.sin());
                let (nl, ne) = (n.dot(l), n.dot(e));
                if ne <= 0.0 {
                    continue;
                }
                den += ne;
                if nl > 0.0 {
                    let h = l + e;
                    num_d += nl * ne;
                    num_s += (n.dot(h) / h.length()).powi(10) * ne;
                }
            }
            let r = m.intensity(wi, wo);
            assert!(
                (r.i_d[0] - 0.4 * num_d / den).abs() < 1e-6,
                "{:?} vs {}",
                r.i_d,
                0.4 * num_d / den
            );
            assert!(
                (r.i_s[0] - 0.3 * num_s / den).abs() < 1e-6,
                "{:?} vs {}",
                r.i_s,
                0.3 * num_s / den
            );
        }
    }

    #[test]
    fn quadrature_path_matches_closed_form() {
        let f = fabric(TWILL);
        let m = AnalyticModel::new(&f, FacetModel::Huo);
        // Same exponent given as a non-integer-looking path: 10 + 1e-13 is not an integer.
        let mut mat = f.warp().material;
        mat.exponent = 10.0 + 1e-13;
        let m2 = AnalyticModel::new(&f.with_material(mat).unwrap(), FacetModel::Huo);
        for (a, b) in [
            ((30.0, 20.0), (45.0, 200.0)),
            ((60.0, 90.0), (10.0, 270.0)),
            ((5.0, 0.0), (70.0, 45.0)),
        ] {
            let wi = UnitVec3::from_degrees(a.0, a.1);
            let wo = UnitVec3::from_degrees(b.0, b.1);
            let x = m.intensity(wi, wo).i_s[0];
            let y = m2.intensity(wi, wo).i_s[0];
            assert!((x - y).abs() < 1e-8 * x.max(1e-3), "{x} {y}");
        }
    }

    /// A fabric file for `pattern` (rows of 0/1) with every length times `scale`, warp threads
    /// given their own float lengths.
    fn scaled(pattern: &[Vec<u8>], scale: f64, warp_segments: Option<&[f64]>) -> Fabric {
        let seg = warp_segments.map_or(String::new(), |v| {
            let v: Vec<f64> = v.iter().map(|x| x * scale).collect();
            format!(r#", "segment_length": {v:?}"#)
        });
        fabric(&format!(
            r#"{{"pattern": {pattern:?}, "warp": {{"radius": {}, "spacing": {}{seg}}},
                "weft": {{"radius": {}, "spacing": {}}}}}"#,
            1.5 * scale,
            3.1 * scale,
            1.5 * scale,
            3.1 * scale
        ))
    }

    fn directions() -> Vec<(UnitVec3, UnitVec3)> {
        (0..12)
            .map(|k| {
                (
                    UnitVec3::from_degrees(5.0 + 6.5 * k as f64, 31.0 * k as f64),
                    UnitVec3::from_degrees(80.0 - 6.0 * k as f64, 200.0 + 47.0 * k as f64),
                )
            })
            .collect()
    }

    #[test]
    fn a_tiled_period_reflects_as_its_tile() {
        // The twill repeated 20 x 20 times is the same cloth: one period of 3600 cells, pieces
        // merged into the twill's units with 400 times the counts, the same intensity.
        let tile: Vec<Vec<u8>> = vec![vec![1, 1, 0], vec![0, 1, 1], vec![1, 0, 1]];
        let big: Vec<Vec<u8>> = (0..60)
            .map(|j| (0..60).map(|i| tile[j % 3][i % 3]).collect())
            .collect();
        let small = AnalyticModel::new(&scaled(&tile, 1.0, None), FacetModel::Huo);
        let large = AnalyticModel::new(&scaled(&big, 1.0, None), FacetModel::Huo);
        let counts = |m: &AnalyticModel| m.units().iter().map(|u| u.count).collect::<Vec<_>>();
        assert_eq!(
            counts(&large),
            counts(&small).iter().map(|c| c * 400).collect::<Vec<_>>()
        );
        let opts = SecondaryOptions::default();
        for (wi, wo) in directions() {
            let (a, b) = (
                small.intensity_with(wi, wo, Some(&opts)),
                large.intensity_with(wi, wo, Some(&opts)),
            );
            let (x, y) = (a.total()[0], b.total()[0]);
            assert!((x - y).abs() <= 1e-12 * x.abs().max(1e-12), "{x} {y}");
        }
    }

    #[test]
    fn only_ratios_of_lengths_matter() {
        // A plain weave whose two warp threads have floats of different lengths: at scale 1e-9
        // the two kinds of piece differ by less than 1e-9 in absolute terms and must still stay
        // apart (they were merged once, giving 0.1386 instead of 0.1431 for one pair).
        let plain: Vec<Vec<u8>> = vec![vec![1, 0], vec![0, 1]];
        let seg = [1.0, 1.5];
        let one = AnalyticModel::new(&scaled(&plain, 1.0, Some(&seg)), FacetModel::Huo);
        for scale in [1e-9, 1e-3, 1e3, 1e8] {
            let other = AnalyticModel::new(&scaled(&plain, scale, Some(&seg)), FacetModel::Huo);
            assert_eq!(one.units().len(), other.units().len(), "scale {scale}");
            for (wi, wo) in directions() {
                let (x, y) = (
                    one.intensity(wi, wo).total()[0],
                    other.intensity(wi, wo).total()[0],
                );
                assert!(
                    (x - y).abs() <= 1e-12 * x.abs().max(1e-12),
                    "scale {scale}: {x} {y}"
                );
            }
        }
    }

    #[test]
    fn profiles_come_outward_and_scan_as_a_whole() {
        // scan_ordered needs each profile in order of u and every shape it can meet listed;
        // on varied fabrics (per-thread radii and heights, given float lengths, long floats)
        // its tables are those of the full scan of the whole profile.
        let sources = [
            TWILL.to_string(),
            r#"{"pattern": [[0,1,1,1,1],[1,1,0,1,1],[1,1,1,1,0],[1,0,1,1,1],[1,1,1,0,1]],
                "warp": {"radius": [1.5,1.2,1.5,1.0,1.4], "height": [0,0.3,-0.2,0,0.5], "spacing": 3.1},
                "weft": {"radius": 1.1, "spacing": [2.5,3.0,2.2,4.0,2.4], "segment_length": 2.0}}"#
                .to_string(),
            r#"{"pattern": [[1,0,0,1,0,1,1],[0,0,1,1,1,0,1],[1,1,0,0,1,0,0],[0,1,1,0,0,1,1]],
                "warp": {"radius": 1.5, "spacing": 3.1, "segment_length": [2,3,2,3,2,3,2]},
                "weft": {"radius": [1.0,1.5,1.0,1.5], "spacing": 3.1}}"#
                .to_string(),
        ];
        for src in &sources {
            let f = fabric(src);
            let geo = Geometry::new(&f);
            let discs = [disc_shapes(&f, Group::Warp), disc_shapes(&f, Group::Weft)];
            let mut tables = 0;
            for seg in &geo.segments {
                let (g, c) = (seg.group, seg.group.other());
                let check = |profile: Vec<Occluder>, shapes: &[(f64, f64)], u_max: f64| {
                    assert!(profile.windows(2).all(|w| w[0].u <= w[1].u), "{profile:?}");
                    assert!(profile.iter().all(|o| o.u <= u_max));
                    assert_eq!(
                        ActiveTable::scan_ordered(profile.iter().copied(), shapes, u_max),
                        ActiveTable::scan(&profile)
                    );
                };
                let top = equal_area_height(seg.radius, seg.height);
                if seg.extent.is_some() {
                    let mut shapes = discs[c as usize].clone();
                    shapes.push((0.0, top));
                    for dir in [1, -1] {
                        check(
                            end_profile(&geo, seg, top, dir).collect(),
                            &shapes,
                            3.0 * geo.period_along(g),
                        );
                        tables += 1;
                    }
                }
                for m in 0..seg.float.len as isize {
                    let k = seg.float.start as isize + m;
                    let y = f.group(c).threads[rem(k, f.weave().n(c))];
                    let mut shapes = discs[g as usize].clone();
                    shapes.push((0.0, equal_area_height(y.radius, y.height)));
                    for dir in [1, -1] {
                        check(
                            side_profile(&geo, seg, k, dir).collect(),
                            &shapes,
                            2.0 * geo.period_across(g),
                        );
                        tables += 1;
                    }
                }
            }
            assert!(tables >= 12, "{tables}");
        }
    }

    /// One pair's units (or slices) in AVX2 lanes (`intensity`) and four pairs in lanes
    /// (`intensity_batch`) give the bits of the unit-by-unit evaluation, on every shipped
    /// fabric and draft, every variant, random pairs with the edge pairs (the pole, the symmetry
    /// planes, grazing). Packs of units that differ in exponent, in endlessness or in having a
    /// specular lobe are split: a mixed fabric covers that.
    #[test]
    fn lanes_give_the_bits_of_the_units_one_by_one() {
        if !std::arch::is_x86_feature_detected!("avx2") {
            assert!(
                std::env::var("CI").as_deref() != Ok("true"),
                "CI=true: this test needs AVX2"
            );
            eprintln!("SKIPPED lanes_give_the_bits_of_the_units_one_by_one: no AVX2");
            return;
        }
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tables");
        let mut fabrics: Vec<(String, Fabric)> = std::fs::read_dir(&dir)
            .expect("tables/")
            .map(|e| e.expect("tables/ entry").path())
            .filter(|p| p.extension().is_some_and(|e| e == "json" || e == "wif"))
            .filter_map(|p| Some((p.display().to_string(), Fabric::from_path(&p).ok()?)))
            .collect();
        assert!(fabrics.len() >= 12, "{}", fabrics.len());
        // Warp and weft alike but for the weft's exponent and the warp's specular lobe.
        let mixed = r#"{"pattern": [[1, 1, 0], [0, 1, 1], [1, 0, 1]],
            "warp": {"radius": 1.5, "spacing": 3.1,
                     "material": {"albedo": 0.4, "specular": 0.0, "exponent": 10}},
            "weft": {"radius": 1.2, "spacing": 3.1,
                     "material": {"albedo": 0.5, "specular": 0.3, "exponent": 7}}}"#;
        fabrics.push((
            "mixed".into(),
            Fabric::from_json_str(mixed, "mixed.json").expect("mixed"),
        ));
        let mut rng = crate::rng::Rng::new(38);
        let mut dir = move || {
            let mu = 1e-6 + (1.0 - 1e-6) * rng.next_f64();
            UnitVec3::from_spherical(mu.acos(), std::f64::consts::TAU * rng.next_f64())
        };
        let mut pairs: Vec<(UnitVec3, UnitVec3)> = (0..300).map(|_| (dir(), dir())).collect();
        pairs.extend(crate::directions::edge_pairs());
        let bits = |r: &Reflection| (r.i_d.map(f64::to_bits), r.i_s.map(f64::to_bits));
        let (mut compared, mut sliced) = (0, 0);
        for (name, fabric) in &fabrics {
            for variant in [Variant::Refined, Variant::Thesis, Variant::Sliced] {
                let m = AnalyticModel::with_variant(fabric, FacetModel::Huo, variant)
                    .expect("the variant takes the period");
                if variant == Variant::Sliced {
                    // Units whole beside units in slices are left to the scalar evaluation.
                    let mixed = m.units.iter().any(|u| u.slices.is_empty());
                    assert_eq!(m.lanes.is_some(), !mixed, "{name} sliced");
                    sliced += usize::from(!mixed);
                } else {
                    assert!(m.lanes.is_some(), "{name}: not in lanes");
                }
                let mut batch = vec![Reflection::default(); pairs.len()];
                m.intensity_batch(&pairs, &mut batch);
                for (&(wi, wo), b) in pairs.iter().zip(&batch) {
                    let want = bits(&m.intensity_of_units(wi, wo, None));
                    let one = m.intensity(wi, wo);
                    assert_eq!(bits(&one), want, "{name} {variant:?} {wi:?} {wo:?}");
                    assert_eq!(bits(b), want, "{name} {variant:?} batch {wi:?} {wo:?}");
                    compared += 1;
                }
            }
        }
        assert!(compared > 12_000, "{compared}");
        assert!(sliced >= 12, "{sliced} sliced models in lanes");
    }

    #[test]
    fn merging_pieces_into_units_changes_nothing() {
        // Every piece its own unit is the definition; merged units must give the same direct
        // and secondary reflection. Random periods and an 8-satin: pieces alike in their own
        // geometry but beside different neighbour floats (this once merged them: I_2 off by up
        // to 0.5%).
        let mut rng = crate::rng::Rng::new(5);
        let mut periods: Vec<Vec<Vec<u8>>> = (0..3)
            .map(|k| {
                let n = 4 + 3 * k;
                (0..n)
                    .map(|_| (0..n).map(|_| (rng.next_u64() % 2) as u8).collect())
                    .collect()
            })
            .collect();
        periods.push(
            (0..8)
                .map(|j| (0..8).map(|i| u8::from((3 * j) % 8 != i)).collect())
                .collect(),
        );
        let opts = SecondaryOptions {
            method: SecondaryMethod::Analytic {
                ranges: Ranges::Full,
                orders: crate::interreflection::ORDERS_FAST,
            },
            kernel: Kernel::default(),
        };
        let mut merges = 0;
        for (p, variant) in periods.iter().flat_map(|p| {
            [
                (p, Variant::Refined),
                (p, Variant::Sliced),
                (p, Variant::Sliced3d),
            ]
        }) {
            let f = scaled(p, 1.0, None);
            let merged = AnalyticModel::with_variant(&f, FacetModel::Huo, variant)
                .expect("the variant takes the period");
            let single = AnalyticModel::build(&f, FacetModel::Huo, variant, false);
            merges += single.units().len() - merged.units().len();
            for (wi, wo) in directions() {
                let (a, b) = (
                    merged.intensity_with(wi, wo, Some(&opts)),
                    single.intensity_with(wi, wo, Some(&opts)),
                );
                let (x, y) = (a.total()[0], b.total()[0]);
                let (s, t) = (
                    a.secondary.unwrap().total()[0],
                    b.secondary.unwrap().total()[0],
                );
                assert!(
                    (x - y).abs() <= 1e-12 * y.abs().max(1e-12),
                    "{p:?}: {x} {y}"
                );
                assert!(
                    (s - t).abs() <= 1e-12 * t.abs().max(1e-12),
                    "{p:?}: I_2 {s} {t}"
                );
            }
        }
        assert!(merges > 100, "{merges}");
    }

    /// On parallel cylinders every slice's profile is the crossing row's, and the 3-D test meets
    /// only endless neighbours: `sliced` is `refined` to rounding, `sliced3d` to the bisection's
    /// precision (a sample spacing / 2^12 of the arc: within 1e-4), with and without the second
    /// bounce, and so is the coverage.
    #[test]
    fn sliced_variants_are_refined_on_parallel_cylinders() {
        let f = fabric(
            r#"{"pattern": [[1]], "warp": {"radius": 1, "spacing": 2.3}, "weft": {"radius": 1, "spacing": 2}}"#,
        );
        let opts = SecondaryOptions::default();
        let refined = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Refined)
            .expect("the variant takes the period");
        // (variant, relative tolerance, the smallest value it is relative to)
        for (variant, tol, floor) in [
            (Variant::Sliced, 1e-12, 1e-12),
            (Variant::Sliced3d, 1e-4, 1e-6),
        ] {
            let m = AnalyticModel::with_variant(&f, FacetModel::Huo, variant)
                .expect("the variant takes the period");
            assert_eq!(m.variant(), variant);
            for (wi, wo) in directions() {
                for secondary in [None, Some(&opts)] {
                    let (a, b) = (
                        refined.intensity_with(wi, wo, secondary),
                        m.intensity_with(wi, wo, secondary),
                    );
                    for (x, y) in a.total().into_iter().zip(b.total()) {
                        assert!(
                            (x - y).abs() <= tol * x.abs().max(floor),
                            "{variant:?}: {x} {y}"
                        );
                    }
                }
                let (c, d) = (refined.coverage(wo), m.coverage(wo));
                assert!((c - d).abs() <= tol, "{variant:?}: {c} {d}");
            }
        }
    }

    /// The sliced variant's masking against the ray tracer: where the crossing yarns lie far
    /// apart for their radius (the cotton poplin's wefts, 3.8 radii), the crossing row's
    /// equal-area rectangle hides 8% too much of the cloth (docs/science/model.md); the slices take
    /// the crossing cylinder only where it is and the neighbours' floats where they are.
    #[test]
    fn slices_see_what_the_micro_geometry_shows() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tables/cotton-poplin.json"
        );
        let f = Fabric::from_path(std::path::Path::new(path)).unwrap();
        let t = clothbake_truth::RayTracer::new(&f, FacetModel::Huo);
        let refined = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Refined)
            .expect("the variant takes the period");
        let sliced = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Sliced)
            .expect("the variant takes the period");
        let pairs = crate::directions::direction_set(24, 70.0);
        let (mut e_refined, mut e_sliced) = (0.0, 0.0);
        for &(wi, wo) in &pairs {
            let (seen, _) = t.visible_and_lit(wi, wo, 20_000, 9);
            e_refined += (refined.coverage(wo) / seen - 1.0).abs();
            e_sliced += (sliced.coverage(wo) / seen - 1.0).abs();
        }
        let n = pairs.len() as f64;
        let (e_refined, e_sliced) = (e_refined / n, e_sliced / n);
        assert!(e_refined > 0.05, "refined masking error {e_refined}");
        assert!(e_sliced < 0.006, "sliced masking error {e_sliced}");
    }
}
