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

/// How the length a segment's end hides is taken (thesis eq. 3.6).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Variant {
    /// As printed: the hidden length on the flat top (height pi r / 4, eq. 3.1) of the
    /// segment's equal-area rectangle.
    Thesis,
    /// Eq. 3.6 evaluated at the true height r sin(theta) + h of every point of the arc and
    /// averaged over the arc with the projected-width weight N.E (closed form). The hidden length
    /// is clamped to [0, segment length] point by point, which the rectangle's single height
    /// cannot do: low points beside a crossing thread are hidden even when the rectangle's top
    /// is not. Default: it halves the model's error against the ray-traced ground truth.
    #[default]
    Refined,
    /// `refined`, with each piece's cross-section profile taken slice by slice along the piece
    /// instead of once for its crossing row (docs/science/model.md, "The sliced variant"): the
    /// neighbours' floats that reach into the piece from the next rows, seen end-on, and the
    /// crossing cylinder only where it is, at its true height there, in place of its
    /// equal-area rectangle along the whole piece. Slices where the profile is constant are
    /// exact; the slices under a crossing cylinder are split in [`SLICE_PARTS`] parts.
    Sliced,
    /// `sliced`, with what hides each slice's side taken in three dimensions (docs/science/model.md,
    /// "The sliced3d variant"): the rays that leave the slice's arc toward the light or the eye
    /// are followed through the floats around the piece, each a finite cylinder, in place of
    /// the slice's 2-D profile of its own row. Pieces are one unit only where their
    /// surroundings agree too; evaluated slice by slice, without the lanes: far slower than
    /// the others.
    Sliced3d,
}

/// Parts each slice of a piece under a crossing cylinder is split into by [`Variant::Sliced`]
/// (its profile taken at the middle of each part).
pub const SLICE_PARTS: usize = 4;

/// The most cells (warp x weft threads) a period may have for [`Variant::Sliced3d`], whose
/// preprocessing grows faster than the period (docs/reference/limits.md): about a minute and two
/// gigabytes at this size for a random period.
pub const SLICED3D_MAX_CELLS: usize = 16_384;

/// Whether `variant` takes `fabric`'s period: `Err((problem, fix))` for [`Variant::Sliced3d`]
/// on a period of more than [`SLICED3D_MAX_CELLS`] cells. Callers check before
/// [`AnalyticModel::with_variant`], which would take minutes and gigabytes past it.
pub fn check_variant(fabric: &Fabric, variant: Variant) -> Result<(), (String, String)> {
    let w = fabric.weave();
    let cells = w.n_warp() * w.n_weft();
    if variant == Variant::Sliced3d && cells > SLICED3D_MAX_CELLS {
        return Err((
            format!(
                "the variant sliced3d takes a period of at most {SLICED3D_MAX_CELLS} cells, and \
                 this one has {} x {} = {cells}",
                w.n_warp(),
                w.n_weft()
            ),
            "use the variant sliced or refined for it (docs/reference/limits.md)".to_string(),
        ));
    }
    Ok(())
}

/// Parts each slice of a piece is split into by [`Variant::Sliced3d`]: under a crossing
/// cylinder, elsewhere (what hides the arc taken at the middle of each part).
pub const SLICE3D_PARTS: (usize, usize) = (8, 2);

impl Variant {
    /// Name as used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Variant::Thesis => "thesis",
            Variant::Refined => "refined",
            Variant::Sliced => "sliced",
            Variant::Sliced3d => "sliced3d",
        }
    }
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

/// A direction as the units of one group see it, computed once per evaluation rather than per
/// unit (issue 22): the projection on their cross-section plane in polar form, the elevation
/// their side tables are read at, and its axial component with the elevation their end tables
/// are read at.
#[derive(Clone, Copy, Debug)]
struct View {
    /// Projection on the cross-section plane.
    p: Polar,
    /// Elevation from the side it comes from: (psi, mirrored: from the -c side); `None` in the
    /// plane of the axis and the normal (|V.c| <= EPS).
    side: Option<(Elevation, bool)>,
    /// Component along the axis.
    va: f64,
    /// Elevation along the axis from the end it comes from; `None` across it (|V.a| <= EPS).
    end: Option<Elevation>,
    /// [`Variant::Sliced3d`]: the place of the direction's open arcs in the model's store,
    /// where kept ([`AnalyticModel::keep_open_arcs`]).
    kept: Option<u32>,
}

impl View {
    /// The views of `v` from the warp's units and from the weft's. A warp's cross-section is
    /// the XZ plane and its axis Y, a weft's the other way round, so the two share the
    /// direction's two elevations atan2(z, |x|) and atan2(z, |y|).
    fn both(v: Vec3) -> [View; 2] {
        let (ex, ey) = (Elevation::of(v.z, v.x.abs()), Elevation::of(v.z, v.y.abs()));
        [
            View::new(v.x, v.y, v.z, ex, ey),
            View::new(v.y, v.x, v.z, ey, ex),
        ]
    }

    /// The view of a direction with components `vc` across, `va` along and `vz` up, and
    /// elevations `ec` = atan2(vz, |vc|) and `ea` = atan2(vz, |va|).
    fn new(vc: f64, va: f64, vz: f64, ec: Elevation, ea: Elevation) -> View {
        let mirrored = vc < 0.0;
        let norm = (vc * vc + vz * vz).sqrt();
        let p = Polar {
            p: Projected { c: vc, z: vz },
            angle: if mirrored { PI - ec.psi } else { ec.psi },
            norm,
            cos: if mirrored { -ec.cos } else { ec.cos },
            sin: ec.sin,
        };
        View {
            p,
            side: (vc.abs() > EPS).then_some((ec, mirrored)),
            va,
            end: (va.abs() > EPS).then_some(ea),
            kept: None,
        }
    }
}

/// The views of light and eye (and of the Huo half vector) for the units of one group.
#[derive(Clone, Copy, Debug)]
struct Views {
    l: View,
    e: View,
    /// The projected unit half vector (L + E) / |L + E|, for the Huo facets' closed form.
    h: Heading,
}

impl Views {
    /// The views of the warp's units and of the weft's.
    fn both(wi: UnitVec3, wo: UnitVec3) -> [Views; 2] {
        let (l, e) = (wi.get(), wo.get());
        let [lw, lf] = View::both(l);
        let [ew, ef] = View::both(e);
        let h = l + e;
        let h = h * (1.0 / h.length());
        let hp = |c: f64| Heading::new(Projected { c, z: h.z });
        [
            Views {
                l: lw,
                e: ew,
                h: hp(h.x),
            },
            Views {
                l: lf,
                e: ef,
                h: hp(h.y),
            },
        ]
    }
}

/// What of a unit the eye sees.
struct Visible {
    /// The visible arc of the cross-section (above the floor, not self- or neighbour-hidden).
    arc: ArcTrig,
    /// The interval along the axis the ends' occluders leave visible.
    along: (f64, f64),
    /// Visible length l_v within the piece.
    l_v: f64,
    /// Projected width of the visible arc, with |E_p|.
    width: f64,
}

/// The sums of eq. 4.11 over the units, in the units' order: the visible projected area
/// sum_i D_i S_v,i and the lit terms sum_i D_i l_vi,i r_i (diffuse factor times albedo, specular
/// intensity). One place for the weighting, whatever computed the units' terms (unit by unit, or
/// a pair's units in AVX2 lanes).
#[derive(Default)]
struct Sums {
    s_total: f64,
    i_d: [f64; 3],
    i_s: f64,
}

impl Sums {
    /// Adds unit `u`'s visible projected area, l_v times the visible arc's projected width,
    /// times its multiplicity D_i (eq. 4.3).
    #[inline(always)]
    fn seen(&mut self, u: &Unit, l_v: f64, width: f64) {
        self.s_total += u.count as f64 * l_v * width;
    }

    /// Adds unit `u`'s lit terms: lit and visible length `l_vi`, and the arc integrals of the
    /// diffuse factor `kd` and the specular intensity `ks` (eqs 4.4-4.10).
    #[inline(always)]
    fn lit(&mut self, u: &Unit, l_vi: f64, kd: f64, ks: f64) {
        let w = u.count as f64 * l_vi * u.seg.radius;
        for (acc, a) in self.i_d.iter_mut().zip(u.seg.material.albedo) {
            *acc += w * kd * a;
        }
        self.i_s += w * ks;
    }

    /// Adds unit `u`'s visible area and, where some of it is lit, its lit terms (`seen`,
    /// `lit`).
    #[inline(always)]
    fn add(&mut self, u: &Unit, l_v: f64, width: f64, lit: Option<(f64, f64, f64)>) {
        self.seen(u, l_v, width);
        if let Some((l_vi, kd, ks)) = lit {
            self.lit(u, l_vi, kd, ks);
        }
    }

    /// I_d and I_s, the lit terms over the visible area (eq. 4.11); zero where nothing is
    /// visible.
    #[inline(always)]
    fn reflection(&self) -> Reflection {
        let s = self.s_total;
        if s <= 0.0 {
            return Reflection::default();
        }
        Reflection {
            i_d: self.i_d.map(|x| x / s),
            i_s: [self.i_s / s; 3],
            secondary: None,
        }
    }
}

/// A sliced unit's sums over its slices ([`Variant::Sliced`]), in the slices' order: the
/// visible length and area, the lit length and the lit-length-weighted arc integrals. One place
/// for them, whether the slices were evaluated one by one or in AVX2 lanes.
#[derive(Default)]
struct SliceSums {
    l_v: f64,
    s_v: f64,
    l_vi: f64,
    kd: f64,
    ks: f64,
}

impl SliceSums {
    /// Adds a slice's visible length `l_v` and area `l_v` times `width`.
    #[inline(always)]
    fn seen(&mut self, l_v: f64, width: f64) {
        self.l_v += l_v;
        self.s_v += l_v * width;
    }

    /// Adds a slice's lit and visible length `l_vi` and its arc integrals `kd`, `ks`.
    #[inline(always)]
    fn lit(&mut self, l_vi: f64, kd: f64, ks: f64) {
        self.l_vi += l_vi;
        self.kd += l_vi * kd;
        self.ks += l_vi * ks;
    }

    /// The unit's visible length, its width S_v / l_v, and its lit length with the integrals'
    /// lit-length-weighted means; `None` where no slice is visible.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    fn unit(&self) -> Option<(f64, f64, Option<(f64, f64, f64)>)> {
        if self.l_v <= 0.0 {
            return None;
        }
        let lit = (self.l_vi > 0.0).then(|| (self.l_vi, self.kd / self.l_vi, self.ks / self.l_vi));
        Some((self.l_v, self.s_v / self.l_v, lit))
    }
}

/// A unit's share of eq. 4.11 for one pair of directions, before the multiplicity D_i.
struct UnitTerms {
    /// Visible length l_v along the axis (within the piece).
    l_v: f64,
    /// Projected width of the visible arc (with |E_p|): S_v = l_v * width (eq. 4.3).
    width: f64,
    /// Secondary reflection per unit visible length from each neighbour pair asked for, from
    /// the +c and the -c side, with the number of pieces beside that pair (empty with one
    /// bounce).
    secondary: Vec<([Secondary; 2], u32)>,
    /// Lit and visible length l_vi and the arc integrals of the facet's diffuse factor and
    /// specular intensity (eqs 4.4-4.10); `None` where no point is both lit and visible.
    lit: Option<(f64, f64, f64)>,
}

fn frame(g: Group) -> (Vec3, Vec3) {
    // (c: across the segment, a: along its axis)
    match g {
        Group::Warp => (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)),
        Group::Weft => (Vec3::new(0.0, 1.0, 0.0), Vec3::new(1.0, 0.0, 0.0)),
    }
}

fn rem(k: isize, n: usize) -> usize {
    k.rem_euclid(n as isize) as usize
}

/// The copy (period shift) of segment `s`'s extent that covers axis coordinate `p`.
fn extent_near(s: &Segment, p: f64, period: f64) -> (f64, f64) {
    let (e0, e1) = s.extent.expect("finite float");
    let q = ((p - 0.5 * (e0 + e1)) / period).round();
    (e0 + q * period, e1 + q * period)
}

/// The occluder thread `seg.thread + dir * m` (same group) presents at crossing `cross` in the
/// cross-section of `seg`: that thread seen end-on where it is on top, else the crossing thread's
/// float over it seen side-on (its equal-area rectangle, eq. 3.1). Also returns the rectangle's
/// identity (segment, copy) so runs of the same float can be merged.
fn occluder_at(
    geo: &Geometry,
    seg: &Segment,
    m: isize,
    cross: isize,
    dir: isize,
) -> (Occluder, Option<(usize, i64)>) {
    let g = seg.group;
    let c = g.other();
    let weave = &geo.fabric.weave();
    let (ng, nc) = (weave.n(g), weave.n(c));
    let tt = seg.thread as isize + dir * m;
    let p = geo.position(g, tt);
    if weave.on_top(g, rem(tt, ng), rem(cross, nc)) {
        let yarn = geo.fabric.group(g).threads[rem(tt, ng)];
        (
            Occluder {
                u: dir as f64 * (p - seg.axis),
                z: yarn.height,
                rho: yarn.radius,
            },
            None,
        )
    } else {
        let cross_yarn = geo.fabric.group(c).threads[rem(cross, nc)];
        let si = geo
            .segment_at(c, rem(cross, nc), tt)
            .expect("crossing thread is on top");
        let (e0, e1) = extent_near(&geo.segments[si], p, geo.period_across(g));
        let u = if dir > 0 {
            e0 - seg.axis
        } else {
            seg.axis - e1
        };
        let z = equal_area_height(cross_yarn.radius, cross_yarn.height);
        (
            Occluder { u, z, rho: 0.0 },
            Some((si, (e0 * 1e6).round() as i64)),
        )
    }
}

/// Occluders on one side (`dir` = +1 or -1 along c) of the cross-section of `seg` at crossing
/// `cross` (the thesis's profile, sec. 3.2): one period of neighbours plus the segment's own
/// repetition, a float spanning several neighbours counted once; produced on demand, outward
/// (non-decreasing u: each neighbour, disc or rectangle, lies beyond the previous one).
fn side_profile<'a>(
    geo: &'a Geometry,
    seg: &'a Segment,
    cross: isize,
    dir: isize,
) -> impl Iterator<Item = Occluder> + 'a {
    let mut last_box = None;
    (1..=geo.fabric.weave().n(seg.group) as isize).filter_map(move |m| {
        let (o, id) = occluder_at(geo, seg, m, cross, dir);
        if id.is_some() && id == last_box {
            return None;
        }
        last_box = id;
        Some(o)
    })
}

/// Occluders beyond one end (`dir` = +1: the +axis end) of a finite segment, along its axis:
/// crossing threads seen end-on (discs) and the thread's own next floats (rectangles);
/// produced on demand, outward.
fn end_profile<'a>(
    geo: &'a Geometry,
    seg: &'a Segment,
    top: f64,
    dir: isize,
) -> impl Iterator<Item = Occluder> + 'a {
    let g = seg.group;
    let c = g.other();
    let weave = geo.fabric.weave();
    let nc = weave.n(c);
    let (y0, y1) = seg.extent.expect("finite float");
    let (a, f) = (seg.float.start as isize, seg.float.len as isize);
    let mut last_box = None;
    (0..nc as isize).filter_map(move |j| {
        let k = if dir > 0 { a + f + j } else { a - 1 - j };
        let p = geo.position(c, k);
        if weave.on_top(g, seg.thread, rem(k, nc)) {
            let si = geo.segment_at(g, seg.thread, k).expect("own float");
            let (e0, e1) = extent_near(&geo.segments[si], p, geo.period_along(g));
            let key = (si, (e0 * 1e6).round() as i64);
            if last_box == Some(key) {
                return None;
            }
            last_box = Some(key);
            let u = if dir > 0 { e0 - y1 } else { y0 - e1 };
            Some(Occluder {
                u,
                z: top,
                rho: 0.0,
            })
        } else {
            let yarn = geo.fabric.group(c).threads[rem(k, nc)];
            let u = if dir > 0 { p - y1 } else { y0 - p };
            last_box = None;
            Some(Occluder {
                u,
                z: yarn.height,
                rho: yarn.radius,
            })
        }
    })
}

/// The occluders on one side (`dir` = +1 or -1 along c) of the cross-section of `seg` over the
/// slice `(y0, y1)` of its piece over crossing `k`, as the micro-geometry has them there
/// ([`Variant::Sliced`]): each neighbour whose float covers the slice's middle, seen end-on;
/// else the crossing thread floating over that neighbour where its cylinder covers the middle,
/// as the near top corner of its float at the cylinder's mean height over the slice (the
/// slice's equal-area rectangle, eq. 3.1's rule along the axis); else nothing (the floor
/// shows). Outward, a float over several neighbours counted once.
fn slice_profile<'a>(
    geo: &'a Geometry,
    seg: &'a Segment,
    k: isize,
    (y0, y1): (f64, f64),
    dir: isize,
) -> impl Iterator<Item = Occluder> + 'a {
    let y = 0.5 * (y0 + y1);
    let g = seg.group;
    let c = g.other();
    let weave = geo.fabric.weave();
    let (ng, nc) = (weave.n(g), weave.n(c));
    let mut last_box = None;
    (1..=ng as isize).filter_map(move |m| {
        let tt = seg.thread as isize + dir * m;
        let t = rem(tt, ng);
        let found = (k - 2..=k + 2).find_map(|kk| {
            if weave.on_top(g, t, rem(kk, nc)) {
                let si = geo.segment_at(g, t, kk).expect("own float");
                let s = &geo.segments[si];
                let covers = s.extent.is_none_or(|_| {
                    let (e0, e1) = extent_near(s, geo.position(c, kk), geo.period_along(g));
                    e0 <= y && y <= e1
                });
                covers.then(|| {
                    let yarn = geo.fabric.group(g).threads[t];
                    let p = geo.position(g, tt);
                    let disc = Occluder {
                        u: dir as f64 * (p - seg.axis),
                        z: yarn.height,
                        rho: yarn.radius,
                    };
                    (disc, None)
                })
            } else {
                let cy = geo.fabric.group(c).threads[rem(kk, nc)];
                let d = y - geo.position(c, kk);
                (d.abs() < cy.radius).then(|| {
                    let (o, id) = occluder_at(geo, seg, m, kk, dir);
                    let p = geo.position(c, kk);
                    let z = cy.height + mean_chord_height(cy.radius, y0 - p, y1 - p);
                    (Occluder { z, ..o }, id)
                })
            }
        });
        let Some((o, id)) = found else {
            last_box = None;
            return None;
        };
        if id.is_some() && id == last_box {
            return None;
        }
        last_box = id;
        Some(o)
    })
}

/// Whether two active tables have the same entries to within `tol` (lengths) and `tol` radians,
/// as the unit keys compare them: slices mirror images of one another across a crossing
/// cylinder's axis agree only to rounding.
fn tables_alike(a: &ActiveTable, b: &ActiveTable, tol: f64) -> bool {
    a.entries.len() == b.entries.len()
        && a.entries
            .iter()
            .zip(&b.entries)
            .all(|((pa, oa), (pb, ob))| {
                (pa - pb).abs() <= KEY_TOLERANCE
                    && (oa.u - ob.u).abs() <= tol
                    && (oa.z - ob.z).abs() <= tol
                    && (oa.rho - ob.rho).abs() <= tol
            })
}

/// The mean over `d` in (a, b) of sqrt(r^2 - d^2), taken as 0 outside (-r, r): the mean height
/// above its axis of a cylinder of radius `r` seen side-on, over part of its width.
fn mean_chord_height(r: f64, a: f64, b: f64) -> f64 {
    // Integral of sqrt(r^2 - d^2): (d sqrt(r^2 - d^2) + r^2 asin(d / r)) / 2.
    // A cut at the cylinder's edge lands within rounding of +-r, where the square root is
    // ill-conditioned (an error e in d moves it by sqrt(2 r e)): such a d is the edge.
    let f = |d: f64| {
        let d = if r - d.abs() <= 1e-9 * r {
            r.copysign(d)
        } else {
            d
        };
        0.5 * (d * ((r - d) * (r + d)).sqrt() + r * r * (d / r).asin())
    };
    (f(b) - f(a)) / (b - a)
}

/// The slices of the piece of `seg` over crossing `k` with range `range` ([`Variant::Sliced`]):
/// cut where a crossing cylinder begins or ends and where a float of the nearest two neighbours
/// on either side does; the parts under a crossing cylinder split in `parts.0`, the others in
/// `parts.1`. Each is its range and the coordinate its profile is taken at (its middle).
fn slices_of(
    geo: &Geometry,
    seg: &Segment,
    k: isize,
    range: (f64, f64),
    parts: (usize, usize),
) -> Vec<((f64, f64), f64)> {
    let g = seg.group;
    let c = g.other();
    let weave = geo.fabric.weave();
    let (ng, nc) = (weave.n(g), weave.n(c));
    let (lo, hi) = range;
    let mut cuts = vec![lo, hi];
    let mut under: Vec<(f64, f64)> = Vec::new();
    for kk in k - 2..=k + 2 {
        let r = geo.fabric.group(c).threads[rem(kk, nc)].radius;
        let p = geo.position(c, kk);
        cuts.extend([p - r, p + r]);
        under.push((p - r, p + r));
        for tt in [-2, -1, 1, 2].map(|m| rem(seg.thread as isize + m, ng)) {
            if let Some(si) = geo.segment_at(g, tt, kk) {
                if geo.segments[si].extent.is_some() {
                    let (e0, e1) = extent_near(&geo.segments[si], p, geo.period_along(g));
                    cuts.extend([e0, e1]);
                }
            }
        }
    }
    // Cuts closer than this to one another are one (rounding of the same position).
    let tiny = 1e-9 * (hi - lo);
    cuts.retain(|&x| x >= lo && x <= hi);
    cuts.sort_by(f64::total_cmp);
    cuts.dedup_by(|a, b| *a - *b <= tiny);
    *cuts.last_mut().expect("two cuts") = hi;
    let mut out = Vec::new();
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b - a <= tiny {
            continue;
        }
        let mid = 0.5 * (a + b);
        let n = if under.iter().any(|&(x0, x1)| x0 < mid && mid < x1) {
            parts.0
        } else {
            parts.1
        };
        for j in 0..n {
            let y0 = a + (b - a) * j as f64 / n as f64;
            let y1 = if j + 1 == n {
                b
            } else {
                a + (b - a) * (j + 1) as f64 / n as f64
            };
            out.push(((y0, y1), 0.5 * (y0 + y1)));
        }
    }
    out
}

/// The distinct (radius, height) of a group's threads: the shapes its threads take as discs in
/// a profile.
fn disc_shapes(fabric: &Fabric, g: Group) -> Vec<(f64, f64)> {
    let mut out: Vec<(f64, f64)> = Vec::new();
    for y in &fabric.group(g).threads {
        if !out.iter().any(|&(r, h)| r == y.radius && h == y.height) {
            out.push((y.radius, y.height));
        }
    }
    out
}

/// Two pieces are one unit when every component of their keys agrees to within this.
const KEY_TOLERANCE: f64 = 1e-9;

/// The unit of length of unit keys: the fabric's smallest radius. Only ratios of lengths
/// matter, so keys compare lengths relative to the yarns: a fabric scaled down must not merge
/// pieces that differ, nor one scaled up keep apart pieces that differ by rounding.
fn key_length_unit(fabric: &Fabric) -> f64 {
    [Group::Warp, Group::Weft]
        .iter()
        .flat_map(|&g| fabric.group(g).threads.iter().map(|y| y.radius))
        .fold(f64::INFINITY, f64::min)
}

/// The key of a unit's neighbour pair, written into `key`: the unit, then each neighbour's
/// distance, radius, height and float extent along the axis relative to the piece (lengths
/// divided by `unit`; an endless float as +-1e300).
fn neighbour_key(unit_id: usize, nbs: &[Option<Neighbour>; 2], unit: f64, key: &mut Vec<f64>) {
    let along = |x: f64| {
        if x.is_finite() {
            x / unit
        } else {
            x.signum() * 1e300
        }
    };
    key.clear();
    key.push(unit_id as f64);
    for nb in nbs {
        key.extend(nb.map_or([0.0; 5], |n| {
            [
                n.d / unit,
                n.radius / unit,
                n.height / unit,
                along(n.axial.0),
                along(n.axial.1),
            ]
        }));
    }
}

/// Appends an active table to a unit key, lengths divided by `unit`.
fn table_key(t: &ActiveTable, unit: f64, out: &mut Vec<f64>) {
    out.push(t.entries.len() as f64);
    for (psi, o) in &t.entries {
        out.extend([*psi, o.u / unit, o.z / unit, o.rho / unit]);
    }
}

impl AnalyticModel {
    /// Preprocesses the weave period with the default [`Variant::Refined`].
    pub fn new(fabric: &Fabric, facet: FacetModel) -> Self {
        Self::with_variant(fabric, facet, Variant::default())
    }

    /// Preprocesses the weave period: pieces, active-occluder tables (the cylinder scan),
    /// and independent units with their multiplicities.
    pub fn with_variant(fabric: &Fabric, facet: FacetModel, variant: Variant) -> Self {
        Self::build(fabric, facet, variant, true)
    }

    /// The preprocessing; `merge` false keeps every piece its own unit (tests: merging must
    /// not change the intensity).
    fn build(fabric: &Fabric, facet: FacetModel, variant: Variant, merge: bool) -> Self {
        let geo = Geometry::new(fabric);
        let grid = CellGrid::new(&geo.warp_pos, geo.period.0, &geo.weft_pos, geo.period.1);
        let (nx, ny) = grid.dims();
        let mut cell_units = vec![(u32::MAX, 0); nx * ny];
        let mut units: Vec<Unit> = Vec::new();
        let mut index = UnitIndex::new(KEY_TOLERANCE);
        // Classes: the unit keys without the diffuse albedos.
        let mut classes = UnitIndex::new(KEY_TOLERANCE);
        let mut unit_class: Vec<u32> = Vec::new();
        let mut class_unit: Vec<u32> = Vec::new();
        // Neighbour pairs of each unit: keys [unit, neighbours...] -> (unit, its variant).
        let mut pairs = UnitIndex::new(KEY_TOLERANCE);
        let mut pair_at: Vec<(usize, usize)> = Vec::new();
        let unit_len = key_length_unit(fabric);
        let discs = [
            disc_shapes(fabric, Group::Warp),
            disc_shapes(fabric, Group::Weft),
        ];
        // Buffers reused from piece to piece: the shapes a profile can hold and the keys.
        let mut end_shapes: Vec<(f64, f64)> = Vec::new();
        let mut side_shapes: Vec<(f64, f64)> = Vec::new();
        let mut key: Vec<f64> = Vec::new();
        let mut pair_key: Vec<f64> = Vec::new();
        for seg in &geo.segments {
            let g = seg.group;
            let c = g.other();
            let top = equal_area_height(seg.radius, seg.height);
            // What the profiles can hold (scan_ordered): along the axis, the crossing threads
            // end-on and this thread's own floats side-on, within a period and a half.
            end_shapes.clear();
            end_shapes.extend_from_slice(&discs[c as usize]);
            end_shapes.push((0.0, top));
            let end_u = 3.0 * geo.period_along(g);
            let (end_plus, end_minus) = match seg.extent {
                Some(_) => (
                    ActiveTable::scan_ordered(end_profile(&geo, seg, top, 1), &end_shapes, end_u),
                    ActiveTable::scan_ordered(end_profile(&geo, seg, top, -1), &end_shapes, end_u),
                ),
                None => Default::default(),
            };
            let data = SegmentData {
                group: g,
                radius: seg.radius,
                height: seg.height,
                top,
                floor: ArcTrig::new(Arc::above_floor(seg.radius, seg.height)),
                extent: seg.extent,
                end_plus,
                end_minus,
                material: fabric.thread_material(g, seg.thread),
            };
            let mid = |k: isize| 0.5 * (geo.position(c, k - 1) + geo.position(c, k));
            let a = seg.float.start as isize;
            let f = seg.float.len as isize;
            for m in 0..f {
                let k = a + m;
                let lo = match seg.extent {
                    Some((y0, _)) if m == 0 => y0,
                    _ => mid(k),
                };
                let hi = match seg.extent {
                    Some((_, y1)) if m == f - 1 => y1,
                    _ => mid(k + 1),
                };
                // Across it: the parallel threads end-on and crossing thread k side-on, within
                // a period.
                let cross_yarn = fabric.group(c).threads[rem(k, geo.fabric.weave().n(c))];
                side_shapes.clear();
                side_shapes.extend_from_slice(&discs[g as usize]);
                side_shapes.push((0.0, equal_area_height(cross_yarn.radius, cross_yarn.height)));
                let side_u = 2.0 * geo.period_across(g);
                let neighbour = |dir: isize| {
                    let (o, id) = occluder_at(&geo, seg, 1, k, dir);
                    if id.is_some() {
                        return None;
                    }
                    let t = seg.thread as isize + dir;
                    let nt = rem(t, geo.fabric.weave().n(g));
                    let yarn = geo.fabric.group(g).threads[nt];
                    let mid = 0.5 * (lo + hi);
                    let axial = match geo.segment_at(g, nt, k).map(|i| &geo.segments[i]) {
                        Some(s) if s.extent.is_some() => {
                            let (e0, e1) = extent_near(s, geo.position(c, k), geo.period_along(g));
                            (e0 - mid, e1 - mid)
                        }
                        _ => (f64::NEG_INFINITY, f64::INFINITY),
                    };
                    Some(Neighbour {
                        d: o.u,
                        radius: yarn.radius,
                        height: yarn.height,
                        axial,
                        material: geo.fabric.thread_material(g, nt),
                    })
                };
                let nbs = [neighbour(1), neighbour(-1)];
                let side_plus =
                    ActiveTable::scan_ordered(side_profile(&geo, seg, k, 1), &side_shapes, side_u);
                let side_minus =
                    ActiveTable::scan_ordered(side_profile(&geo, seg, k, -1), &side_shapes, side_u);
                let mut slices: Vec<Slice> = Vec::new();
                let around =
                    (variant == Variant::Sliced3d).then(|| around::Around::of(&geo, seg, (lo, hi)));
                if variant == Variant::Sliced3d {
                    // Each slice sees its own surroundings (`around`): one range a slice, and no
                    // side tables (what hides its arc is found in 3-D).
                    for (range, _) in slices_of(&geo, seg, k, (lo, hi), SLICE3D_PARTS) {
                        slices.push(Slice {
                            ranges: vec![range],
                            side_plus: ActiveTable::default(),
                            side_minus: ActiveTable::default(),
                        });
                    }
                } else if variant == Variant::Sliced {
                    for (range, _) in slices_of(&geo, seg, k, (lo, hi), (SLICE_PARTS, 1)) {
                        let table = |dir| {
                            let profile: Vec<Occluder> =
                                slice_profile(&geo, seg, k, range, dir).collect();
                            ActiveTable::scan(&profile)
                        };
                        let (plus, minus) = (table(1), table(-1));
                        let alike = |a: &ActiveTable, b: &ActiveTable| {
                            tables_alike(a, b, KEY_TOLERANCE * unit_len)
                        };
                        match slices
                            .iter_mut()
                            .find(|s| alike(&s.side_plus, &plus) && alike(&s.side_minus, &minus))
                        {
                            Some(s) => s.ranges.push(range),
                            None => slices.push(Slice {
                                ranges: vec![range],
                                side_plus: plus,
                                side_minus: minus,
                            }),
                        }
                    }
                }
                // Key: everything the unit's reflection depends on, relative to its segment,
                // lengths in units of `unit_len`.
                let origin = seg.extent.map_or(lo, |e| e.0);
                key.clear();
                key.extend([
                    g as u8 as f64,
                    seg.radius / unit_len,
                    seg.height / unit_len,
                    seg.extent.map_or(-1.0, |e| (e.1 - e.0) / unit_len),
                    (lo - origin) / unit_len,
                    (hi - origin) / unit_len,
                ]);
                let mat = data.material;
                key.extend([mat.specular, mat.exponent]);
                for t in [&side_plus, &side_minus, &data.end_plus, &data.end_minus] {
                    table_key(t, unit_len, &mut key);
                }
                for sl in &slices {
                    key.push(sl.ranges.len() as f64);
                    for r in &sl.ranges {
                        key.extend([(r.0 - origin) / unit_len, (r.1 - origin) / unit_len]);
                    }
                    table_key(&sl.side_plus, unit_len, &mut key);
                    table_key(&sl.side_minus, unit_len, &mut key);
                }
                if let Some(a) = &around {
                    a.key(origin, unit_len, &mut key);
                }
                // The class key: the unit key without the albedos that follow.
                let class_len = key.len();
                key.extend(mat.albedo);
                // Per-thread colours: the neighbours' albedos enter the secondary reflection.
                for nb in &nbs {
                    key.extend(nb.map_or([-1.0; 3], |n| n.material.albedo));
                }
                let cell = grid.index(grid.crossing(g, seg.thread, k));
                let Some(i) = merge.then(|| index.find_or_insert(&key)).flatten() else {
                    if merge {
                        neighbour_key(units.len(), &nbs, unit_len, &mut pair_key);
                        pairs.find_or_insert(&pair_key);
                        pair_at.push((units.len(), 0));
                    }
                    let found = merge.then(|| classes.find_or_insert(&key[..class_len]));
                    let class = match found.flatten() {
                        Some(c) => c as u32,
                        None => {
                            class_unit.push(units.len() as u32);
                            class_unit.len() as u32 - 1
                        }
                    };
                    unit_class.push(class);
                    cell_units[cell] = (units.len() as u32, 0);
                    units.push(Unit {
                        seg: data.clone(),
                        range: (lo, hi),
                        neighbours: vec![(nbs, 1)],
                        side_plus,
                        side_minus,
                        count: 1,
                        slices,
                        around,
                        first_slice: 0,
                    });
                    continue;
                };
                units[i].count += 1;
                // The neighbours' sizes, distance and float extent along the axis.
                neighbour_key(i, &nbs, unit_len, &mut pair_key);
                let variant = match pairs.find_or_insert(&pair_key) {
                    Some(v) => {
                        units[i].neighbours[pair_at[v].1].1 += 1;
                        pair_at[v].1
                    }
                    None => {
                        pair_at.push((i, units[i].neighbours.len()));
                        units[i].neighbours.push((nbs, 1));
                        units[i].neighbours.len() - 1
                    }
                };
                cell_units[cell] = (i as u32, variant as u32);
            }
        }
        // Classes with the second bounce: a cell's class and its neighbours' geometry.
        let mut bounce_index = UnitIndex::new(KEY_TOLERANCE);
        let mut bounce_unit: Vec<(u32, u32)> = Vec::new();
        let bounce_class = cell_units
            .iter()
            .map(|&(u, var)| {
                let nbs = &units[u as usize].neighbours[var as usize].0;
                neighbour_key(
                    unit_class[u as usize] as usize,
                    nbs,
                    unit_len,
                    &mut pair_key,
                );
                match bounce_index.find_or_insert(&pair_key) {
                    Some(b) => b as u32,
                    None => {
                        bounce_unit.push((u, var));
                        bounce_unit.len() as u32 - 1
                    }
                }
            })
            .collect();
        let mut first_slice = 0;
        for u in units.iter_mut().filter(|u| u.around.is_some()) {
            u.first_slice = first_slice;
            first_slice += u.slices.len();
        }
        AnalyticModel {
            arc_store: open_arcs::ArcStore::default(),
            arcs_key: open_arcs::model_key(&units),
            facet,
            variant,
            lanes: if variant == Variant::Sliced3d {
                None
            } else {
                batch::lanes(facet, &units)
            },
            units,
            grid,
            cell_units,
            unit_class,
            class_unit,
            bounce_class,
            bounce_unit,
        }
    }

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

    /// Directly reflected intensity toward `wo` for unit light from `wi` (eq. 4.11): the
    /// visible-area-weighted average over the units of the period. Zero when either direction
    /// is at or below the horizon.
    pub fn intensity(&self, wi: UnitVec3, wo: UnitVec3) -> Reflection {
        self.intensity_with(wi, wo, None)
    }

    /// As [`AnalyticModel::intensity`], adding the secondary reflection I_2 between adjacent
    /// parallel cylinders (thesis ch. 5; for cloth, sec. 5.4's approximation) when `secondary`
    /// is given. I_2 is averaged over the same visible projected area as I_1.
    pub fn intensity_with(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
    ) -> Reflection {
        if secondary.is_none() && wi.above_horizon() && wo.above_horizon() {
            if let Some(r) = self.intensity_in_lanes(wi, wo) {
                return r;
            }
        }
        self.intensity_of_units(wi, wo, secondary)
    }

    /// [`AnalyticModel::intensity_with`] unit by unit (what the lanes are checked against).
    fn intensity_of_units(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
    ) -> Reflection {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return Reflection {
                secondary: secondary.map(|_| Secondary::default()),
                ..Reflection::default()
            };
        }
        let mut sums = Sums::default();
        let mut i_2 = Secondary::default();
        let views = self.views(wi, wo);
        for u in &self.units {
            let v = &views[u.seg.group as usize];
            let Some(t) = self.unit_terms(u, &u.neighbours, v, wi, wo, secondary, false) else {
                continue;
            };
            sums.add(u, t.l_v, t.width, t.lit);
            for (s, n) in &t.secondary {
                i_2.add_scaled(&both_sides(s), f64::from(*n) * t.l_v);
            }
        }
        let (direct, s_total) = (sums.reflection(), sums.s_total);
        Reflection {
            secondary: secondary.map(|_| {
                if s_total <= 0.0 {
                    Secondary::default()
                } else {
                    i_2.scaled(1.0 / s_total)
                }
            }),
            ..direct
        }
    }

    /// What of unit `u` is visible from the eye's view `e`: `None` where nothing is.
    fn visible(&self, u: &Unit, e: &View) -> Option<Visible> {
        let arc = self.side_arc(u, e).meet(&u.seg.floor);
        self.visible_of(u, std::slice::from_ref(&u.range), e, arc)
    }

    /// The visible length l_v and projected width of unit `u` from the eye's view `e`, whose
    /// product is its visible projected area S_v (eq. 4.3); of its slices summed with
    /// [`Variant::Sliced`] (the width then S_v / l_v).
    fn seen_area(&self, u: &Unit, e: &View) -> Option<(f64, f64)> {
        if u.slices.is_empty() {
            return self.visible(u, e).map(|v| (v.l_v, v.width));
        }
        let (l_v, s_v) = u
            .slices
            .iter()
            .enumerate()
            .filter_map(|(k, sl)| self.slice_visible(u, k, sl, e))
            .fold((0.0, 0.0), |(l, s), v| (l + v.l_v, s + v.l_v * v.width));
        (l_v > 0.0).then(|| (l_v, s_v / l_v))
    }

    /// What of the slice `sl` (its `k`th) of unit `u` the eye's view `e` sees ([`Visible`]
    /// over the slice's ranges).
    fn slice_visible(&self, u: &Unit, k: usize, sl: &Slice, e: &View) -> Option<Visible> {
        self.visible_of(u, &sl.ranges, e, self.slice_arc(u, k, sl, e))
    }

    /// As [`AnalyticModel::visible`] over the parts `ranges` of the piece, given the arc of the
    /// cross-section that faces the eye above the floor and not behind the side neighbour.
    fn visible_of(
        &self,
        u: &Unit,
        ranges: &[(f64, f64)],
        e: &View,
        arc: ArcTrig,
    ) -> Option<Visible> {
        let seg = &u.seg;
        if arc.arc.is_empty() {
            return None;
        }
        let along = self.end_interval(u, e, &arc, e.p.p);
        let l_v: f64 = ranges.iter().map(|&r| overlap(r, along)).sum();
        if l_v <= 0.0 {
            return None;
        }
        Some(Visible {
            arc,
            along,
            l_v,
            width: projected_width(seg.radius, &arc, e.p.p),
        })
    }

    /// Unit `u`'s terms of eq. 4.11 (and of I_2 with `secondary`, from threads of albedo 1 when
    /// `white`) for light from `wi` seen from `wo` (both above the horizon; `views` of its
    /// group): `None` where nothing of it is visible.
    #[allow(clippy::too_many_arguments)]
    fn unit_terms(
        &self,
        u: &Unit,
        variants: &[([Option<Neighbour>; 2], u32)],
        views: &Views,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
        white: bool,
    ) -> Option<UnitTerms> {
        if !u.slices.is_empty() {
            return self.sliced_terms(u, variants, views, wi, wo, secondary, white);
        }
        let seg = &u.seg;
        // The eye's and the light's arcs first: two independent chains of divisions and
        // square roots that the processor can overlap.
        let seen = self.side_arc(u, &views.e).meet(&seg.floor);
        let lit = self.side_arc(u, &views.l).meet(&seg.floor);
        let v = self.visible_of(u, std::slice::from_ref(&u.range), &views.e, seen)?;
        let ep = views.e.p.p;
        let vi = v.arc.meet(&lit);
        let lit_len = self.end_interval(u, &views.l, &vi, ep);
        let secondary = secondary.map_or_else(Vec::new, |opts| {
            let (l, e) = (wi.get(), wo.get());
            variants
                .iter()
                .map(|(nbs, n)| {
                    let sides = self.secondary(u, nbs, opts, l, e, (v.arc.arc, lit.arc), white);
                    (sides, *n)
                })
                .collect()
        });
        let l_vi = overlap(u.range, meet(v.along, lit_len));
        let lit = (!vi.arc.is_empty() && l_vi > 0.0).then(|| {
            let (kd, ks) = self.arc_integral(&seg.material, seg.group, &vi, views, wi, wo);
            (l_vi, kd, ks)
        });
        Some(UnitTerms {
            l_v: v.l_v,
            width: v.width,
            secondary,
            lit,
        })
    }

    /// [`AnalyticModel::unit_terms`] of a unit in slices ([`Variant::Sliced`]): each slice's
    /// visible area, lit length and arc integrals summed, given back as one piece's terms (the
    /// width is S_v / l_v, the integrals the lit-length-weighted means, the secondary
    /// reflection per unit visible length).
    #[allow(clippy::too_many_arguments)]
    fn sliced_terms(
        &self,
        u: &Unit,
        variants: &[([Option<Neighbour>; 2], u32)],
        views: &Views,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
        white: bool,
    ) -> Option<UnitTerms> {
        let seg = &u.seg;
        let ep = views.e.p.p;
        let mut sums = SliceSums::default();
        let mut sec: Vec<([Secondary; 2], u32)> = match secondary {
            Some(_) => variants
                .iter()
                .map(|(_, n)| ([Secondary::default(); 2], *n))
                .collect(),
            None => Vec::new(),
        };
        for (k, sl) in u.slices.iter().enumerate() {
            let Some(v) = self.slice_visible(u, k, sl, &views.e) else {
                continue;
            };
            let lit = self.slice_arc(u, k, sl, &views.l);
            sums.seen(v.l_v, v.width);
            if let Some(opts) = secondary {
                let (l, e) = (wi.get(), wo.get());
                for ((acc, _), (nbs, _)) in sec.iter_mut().zip(variants) {
                    let sides = self.secondary(u, nbs, opts, l, e, (v.arc.arc, lit.arc), white);
                    for (a, s) in acc.iter_mut().zip(&sides) {
                        a.add_scaled(s, v.l_v);
                    }
                }
            }
            let vi = v.arc.meet(&lit);
            let lit_len = self.end_interval(u, &views.l, &vi, ep);
            let lit_along = meet(v.along, lit_len);
            let li: f64 = sl.ranges.iter().map(|&r| overlap(r, lit_along)).sum();
            if !vi.arc.is_empty() && li > 0.0 {
                let (d, s) = self.arc_integral(&seg.material, seg.group, &vi, views, wi, wo);
                sums.lit(li, d, s);
            }
        }
        let (l_v, width, lit) = sums.unit()?;
        for (acc, _) in &mut sec {
            *acc = acc.map(|a| a.scaled(1.0 / l_v));
        }
        Some(UnitTerms {
            l_v,
            width,
            secondary: sec,
            lit,
        })
    }

    /// The period's crossing cells.
    pub fn cells(&self) -> &CellGrid {
        &self.grid
    }

    /// The reflection at point `at` of the period (docs/science/spatial.md): eq. 4.11 restricted to the
    /// unit over the cell containing `at`, with the cell's coverage. The coverage-weighted mean
    /// over the period of the local reflection is [`AnalyticModel::intensity_with`].
    pub fn intensity_at(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        at: PeriodPoint,
        secondary: Option<&SecondaryOptions>,
    ) -> LocalReflection {
        self.intensity_in(wi, wo, self.grid.cell_at(at), secondary)
    }

    /// As [`AnalyticModel::intensity_at`], for a cell.
    pub fn intensity_in(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        cell: Cell,
        secondary: Option<&SecondaryOptions>,
    ) -> LocalReflection {
        let empty = LocalReflection {
            reflection: Reflection {
                secondary: secondary.map(|_| Secondary::default()),
                ..Reflection::default()
            },
            coverage: 0.0,
        };
        if !(wi.above_horizon() && wo.above_horizon()) {
            return empty;
        }
        let (unit, variant) = self.cell_units[self.grid.index(cell)];
        let u = &self.units[unit as usize];
        let variants = std::slice::from_ref(&u.neighbours[variant as usize]);
        let views = self.views(wi, wo)[u.seg.group as usize];
        let Some(t) = self.unit_terms(u, variants, &views, wi, wo, secondary, false) else {
            return empty;
        };
        let s_v = t.l_v * t.width;
        let coverage = self.cell_coverage(cell, s_v, wo);
        let (i_d, i_s) = match t.lit {
            Some((l_vi, kd, ks)) => {
                let w = l_vi * u.seg.radius / s_v;
                (u.seg.material.albedo.map(|a| w * kd * a), [w * ks; 3])
            }
            None => ([0.0; 3], [0.0; 3]),
        };
        LocalReflection {
            reflection: Reflection {
                i_d,
                i_s,
                secondary: secondary.map(|_| {
                    t.secondary.first().map_or_else(Secondary::default, |s| {
                        both_sides(&s.0).scaled(1.0 / t.width)
                    })
                }),
            },
            coverage,
        }
    }

    /// c(x; wo) of a cell whose unit shows visible projected area `s_v`.
    fn cell_coverage(&self, cell: Cell, s_v: f64, wo: UnitVec3) -> f64 {
        let (px, py) = self.grid.period();
        s_v / (self.grid.area_fraction(cell) * px * py * wo.cos_theta())
    }

    /// Number of classes of the period's units (see [`ClassTerms`]).
    pub fn classes(&self) -> usize {
        self.class_unit.len()
    }

    /// Each class's direct reflection for light from `wi` seen from `wo`, written to `out`
    /// (one entry per class; zero below the horizon). For every cell, rho_d `diffuse` +
    /// `specular` is the f_r of [`AnalyticModel::intensity_in`] without secondary reflection,
    /// and `visible` over the cell's area share its coverage.
    pub fn class_terms(&self, wi: UnitVec3, wo: UnitVec3, out: &mut [ClassTerms]) {
        assert_eq!(out.len(), self.classes(), "one entry per class");
        out.fill(ClassTerms::default());
        if !(wi.above_horizon() && wo.above_horizon()) {
            return;
        }
        let views = self.views(wi, wo);
        for (o, &u) in out.iter_mut().zip(&self.class_unit) {
            let u = &self.units[u as usize];
            let v = &views[u.seg.group as usize];
            let Some(t) = self.unit_terms(u, &[], v, wi, wo, None, false) else {
                continue;
            };
            let (visible, d, s) = self.direct_terms(u, &t, wi, wo);
            o.visible = visible;
            // Each is a non-negative quantity; near the horizon a lit arc of almost no length
            // leaves rounding of either sign (-1.2e-28 seen on the taffeta at 87 degrees),
            // which a table may not hold.
            o.diffuse = d.max(0.0);
            o.specular = s.max(0.0);
        }
    }

    /// A class's visible share of the period and its direct f_r at unit diffuse albedo and
    /// specular, not yet clamped at 0, from its unit `u`'s terms `t` ([`ClassTerms`]).
    fn direct_terms(&self, u: &Unit, t: &UnitTerms, wi: UnitVec3, wo: UnitVec3) -> (f64, f64, f64) {
        let s_v = t.l_v * t.width;
        let (px, py) = self.grid.period();
        let visible = s_v / (px * py * wo.cos_theta());
        let (d, s) = t.lit.map_or((0.0, 0.0), |(l_vi, kd, ks)| {
            let w = l_vi * u.seg.radius / s_v;
            let [d, s, _] = intensity_to_brdf([w * kd, w * ks, 0.0], wi);
            (d, s)
        });
        (visible, d, s)
    }

    /// Each class's visible share of the period seen from `wo`, as [`ClassTerms::visible`]
    /// (the classes of [`AnalyticModel::classes_with`] `secondary`), without the facet terms or
    /// the second bounce (0 below the horizon).
    pub fn class_visible(&self, wo: UnitVec3, secondary: bool, out: &mut [f64]) {
        let units: Vec<u32> = if secondary {
            self.bounce_unit.iter().map(|&(u, _)| u).collect()
        } else {
            self.class_unit.clone()
        };
        assert_eq!(out.len(), units.len(), "one entry per class");
        out.fill(0.0);
        if !wo.above_horizon() {
            return;
        }
        let views = View::both(wo.get());
        let (px, py) = self.grid.period();
        for (o, &u) in out.iter_mut().zip(&units) {
            let u = &self.units[u as usize];
            if let Some((l_v, width)) = self.seen_area(u, &views[u.seg.group as usize]) {
                *o = l_v * width / (px * py * wo.cos_theta());
            }
        }
    }

    /// The period's averaged f_r (RGB, 1/sr) from [`AnalyticModel::class_terms`]' `terms`:
    /// each unit's rho_d D + S weighted by its multiplicity times its class's visible area
    /// (eq. 4.11). Equal to the f_r of [`AnalyticModel::intensity`] to rounding, without
    /// evaluating any unit again.
    pub fn average_of_classes(&self, terms: &[ClassTerms]) -> [f64; 3] {
        assert_eq!(terms.len(), self.classes(), "one entry per class");
        let (mut num, mut den) = ([0.0; 3], 0.0);
        for (u, &c) in self.units.iter().zip(&self.unit_class) {
            let t = &terms[c as usize];
            let w = f64::from(u.count) * t.visible;
            for (n, a) in num.iter_mut().zip(u.seg.material.albedo) {
                *n += w * (a * t.diffuse + t.specular);
            }
            den += w;
        }
        if den > 0.0 {
            num.map(|n| n / den)
        } else {
            [0.0; 3]
        }
    }

    /// Number of classes with the second bounce (`secondary`) or without: with it, cells of
    /// one class beside neighbours of different geometry are apart.
    pub fn classes_with(&self, secondary: bool) -> usize {
        if secondary {
            self.bounce_unit.len()
        } else {
            self.classes()
        }
    }

    /// Each cell's class (with the second bounce when `secondary`) and the albedos its
    /// [`ClassTerms`] are multiplied by, by [`CellGrid::index`].
    pub fn cell_classes_with(&self, secondary: bool) -> Vec<CellClass> {
        self.cell_units
            .iter()
            .zip(&self.bounce_class)
            .map(|(&(u, var), &b)| {
                let unit = &self.units[u as usize];
                let nbs = &unit.neighbours[var as usize].0;
                CellClass {
                    class: if secondary {
                        b
                    } else {
                        self.unit_class[u as usize]
                    },
                    albedo: unit.seg.material.albedo,
                    neighbours: nbs.map(|n| n.map_or([0.0; 3], |n| n.material.albedo)),
                }
            })
            .collect()
    }

    /// As [`AnalyticModel::class_terms`], with the second bounce when `secondary` is given:
    /// one entry per class of [`AnalyticModel::classes_with`]. For every cell, its
    /// [`CellClass`]'s albedos and its class's terms give the f_r of
    /// [`AnalyticModel::intensity_in`] with the same `secondary`.
    pub fn class_terms_with(
        &self,
        wi: UnitVec3,
        wo: UnitVec3,
        secondary: Option<&SecondaryOptions>,
        out: &mut [ClassTerms],
    ) {
        let Some(opts) = secondary else {
            return self.class_terms(wi, wo, out);
        };
        assert_eq!(out.len(), self.bounce_unit.len(), "one entry per class");
        out.fill(ClassTerms::default());
        if !(wi.above_horizon() && wo.above_horizon()) {
            return;
        }
        let views = self.views(wi, wo);
        // I_2 of a cell is its piece's, per unit visible length, over the visible width.
        let f = |x: f64, width: f64| intensity_to_brdf([x / width, 0.0, 0.0], wi)[0];
        for (o, &(u, var)) in out.iter_mut().zip(&self.bounce_unit) {
            let u = &self.units[u as usize];
            let v = &views[u.seg.group as usize];
            let variants = std::slice::from_ref(&u.neighbours[var as usize]);
            let Some(t) = self.unit_terms(u, variants, v, wi, wo, Some(opts), true) else {
                continue;
            };
            let (visible, d, s) = self.direct_terms(u, &t, wi, wo);
            o.visible = visible;
            // Threads of albedo 1: each component is the same in every channel.
            let sides = &t.secondary[0].0;
            let own = f(sides[0].sd[0] + sides[1].sd[0], t.width);
            let none = f(sides[0].ss[0] + sides[1].ss[0], t.width);
            // Each is non-negative; rounding near the horizon may leave either sign (as in
            // `class_terms`), which a table may not hold.
            o.diffuse = (d + own).max(0.0);
            o.specular = (s + none).max(0.0);
            o.neighbour = sides.map(|p| f(p.ds[0], t.width).max(0.0));
            o.both = sides.map(|p| f(p.dd[0], t.width).max(0.0));
        }
    }

    /// A cell's f_r (RGB, 1/sr) from its [`CellClass`] and its class's [`ClassTerms`].
    pub fn cell_f(cell: &CellClass, t: &ClassTerms) -> [f64; 3] {
        std::array::from_fn(|c| {
            let a = cell.albedo[c];
            let [p, m] = cell.neighbours;
            a * t.diffuse
                + t.specular
                + p[c] * (t.neighbour[0] + a * t.both[0])
                + m[c] * (t.neighbour[1] + a * t.both[1])
        })
    }

    /// The period's averaged f_r (RGB, 1/sr) from the cells' classes (`cells`, of
    /// [`AnalyticModel::cell_classes_with`]) and their `terms`: each cell's f_r weighted by its
    /// class's visible area (eq. 4.11 over the pieces, one piece a cell). Equal to the f_r of
    /// [`AnalyticModel::intensity_with`] to rounding.
    pub fn average_of_cells(&self, cells: &[CellClass], terms: &[ClassTerms]) -> [f64; 3] {
        let (mut num, mut den) = ([0.0; 3], 0.0);
        for c in cells {
            let t = &terms[c.class as usize];
            let f = Self::cell_f(c, t);
            for (n, f) in num.iter_mut().zip(f) {
                *n += t.visible * f;
            }
            den += t.visible;
        }
        if den > 0.0 {
            num.map(|n| n / den)
        } else {
            [0.0; 3]
        }
    }

    /// The coverage c(x; wo) of a cell alone, as [`AnalyticModel::intensity_in`] reports it,
    /// without the facet terms (0 below the horizon).
    pub fn coverage_in(&self, cell: Cell, wo: UnitVec3) -> f64 {
        if !wo.above_horizon() {
            return 0.0;
        }
        let (unit, _) = self.cell_units[self.grid.index(cell)];
        let u = &self.units[unit as usize];
        self.seen_area(u, &View::both(wo.get())[u.seg.group as usize])
            .map_or(0.0, |(l_v, width)| {
                self.cell_coverage(cell, l_v * width, wo)
            })
    }

    /// The directional coverage C(wo): the period mean of the coverage, the visible yarn's
    /// projected area per unit projected area of the period (0 below the horizon).
    pub fn coverage(&self, wo: UnitVec3) -> f64 {
        if !wo.above_horizon() {
            return 0.0;
        }
        let views = View::both(wo.get());
        let s: f64 = self
            .units
            .iter()
            .filter_map(|u| {
                let (l_v, width) = self.seen_area(u, &views[u.seg.group as usize])?;
                Some(u.count as f64 * l_v * width)
            })
            .sum();
        let (px, py) = self.grid.period();
        s / (px * py * wo.cos_theta())
    }

    /// The model's share of the period's projected area, seen from `wo`, that is visible, faces
    /// the light `wi` and is lit: the sum of D_i l_vi times the projected width of the lit and
    /// visible arc (eqs 4.2-4.3), per unit projected area. With [`AnalyticModel::coverage`] it
    /// splits the model's error into masking and shadowing (docs/science/model.md, "Where the error
    /// comes from"); 0 below the horizon.
    pub fn lit_coverage(&self, wi: UnitVec3, wo: UnitVec3) -> f64 {
        if !(wi.above_horizon() && wo.above_horizon()) {
            return 0.0;
        }
        let views = Views::both(wi, wo);
        let s: f64 = self
            .units
            .iter()
            .map(|u| {
                let v = &views[u.seg.group as usize];
                let lit_area = |ranges: &[(f64, f64)], seen: ArcTrig, lit: ArcTrig| {
                    let seen = self.visible_of(u, ranges, &v.e, seen)?;
                    let vi = seen.arc.meet(&lit);
                    let lit_len = self.end_interval(u, &v.l, &vi, v.e.p.p);
                    let lit_along = meet(seen.along, lit_len);
                    let l_vi: f64 = ranges.iter().map(|&r| overlap(r, lit_along)).sum();
                    Some(l_vi * projected_width(u.seg.radius, &vi, v.e.p.p))
                };
                // The unit's parts: its whole range with its own tables, or its slices.
                let lit_area: f64 = if u.slices.is_empty() {
                    let arc = |w: &View| self.side_arc(u, w).meet(&u.seg.floor);
                    lit_area(std::slice::from_ref(&u.range), arc(&v.e), arc(&v.l)).unwrap_or(0.0)
                } else {
                    u.slices
                        .iter()
                        .enumerate()
                        .filter_map(|(k, sl)| {
                            let arc = |w: &View| self.slice_arc(u, k, sl, w);
                            lit_area(&sl.ranges, arc(&v.e), arc(&v.l))
                        })
                        .sum()
                };
                u.count as f64 * lit_area
            })
            .sum();
        let (px, py) = self.grid.period();
        s / (px * py * wo.cos_theta())
    }

    /// Secondary reflection reaching the eye from the visible arc of unit `u`, per unit length,
    /// from each parallel neighbour of `nbs` (+c side, -c side; zero where there is none), the
    /// threads of albedo 1 when `white` (the colourless components of
    /// [`ClassTerms`]). The neighbour's lit arc is taken equal to the unit's own (exact for the
    /// parallel-cylinder surface, where all cylinders are alike).
    #[allow(clippy::too_many_arguments)]
    fn secondary(
        &self,
        u: &Unit,
        nbs: &[Option<Neighbour>; 2],
        opts: &SecondaryOptions,
        l: Vec3,
        e: Vec3,
        (vis, lit): (Arc, Arc),
        white: bool,
    ) -> [Secondary; 2] {
        let (c, a) = frame(u.seg.group);
        let mut out = [Secondary::default(); 2];
        let colour = |m: Material| {
            if white {
                Material {
                    albedo: [1.0; 3],
                    ..m
                }
            } else {
                m
            }
        };
        for (k, (side, nb)) in [(1.0, &nbs[0]), (-1.0, &nbs[1])].into_iter().enumerate() {
            let Some(nb) = nb else { continue };
            let local = |v: Vec3| Vec3::new(side * v.dot(c), v.dot(a), v.z);
            let mirror = |arc: Arc| {
                if side > 0.0 {
                    arc
                } else {
                    Arc {
                        lo: PI - arc.hi,
                        hi: PI - arc.lo,
                    }
                }
            };
            let pair = Pair {
                r1: u.seg.radius,
                h1: u.seg.height,
                r2: nb.radius,
                h2: nb.height,
                d: nb.d,
                m1: colour(u.seg.material),
                m2: colour(nb.material),
                facet: self.facet,
                kernel: opts.kernel,
            };
            let setting = Setting {
                l: local(l),
                e: local(e),
                vis1: mirror(vis),
                lit2: mirror(lit),
                axial: nb.axial,
            };
            let part = match opts.method {
                SecondaryMethod::Analytic { ranges, orders } => {
                    secondary_analytic(&pair, &setting, ranges, orders)
                }
                SecondaryMethod::Sampling(p) => two_level_sampling(&pair, &setting, p),
            };
            out[k] = part;
        }
        out
    }

    /// Arc of the unit's cross-section that faces `v` and is not hidden by a neighbour on the
    /// side `v` comes from (self-shadowing/blocking plus eqs 3.4-3.5 via the active table).
    fn side_arc(&self, u: &Unit, v: &View) -> ArcTrig {
        side_arc_in(&u.seg, (&u.side_plus, &u.side_minus), v)
    }

    /// The arc of slice `sl` (its `k`th) of unit `u` that faces `v` above the floor and that
    /// nothing beside it hides: by the slice's side tables, or ([`Variant::Sliced3d`]) by the
    /// floats around the piece at the middle of the slice's one range (kept, where `v`'s
    /// direction's arcs are).
    fn slice_arc(&self, u: &Unit, k: usize, sl: &Slice, v: &View) -> ArcTrig {
        let seg = &u.seg;
        match &u.around {
            Some(around) => {
                if let Some(place) = v.kept {
                    return self.arc_store.arc(place, u.first_slice + k);
                }
                let (y0, y1) = sl.ranges[0];
                let arc = ArcTrig::facing(&v.p).meet(&seg.floor);
                around.open_arc(seg.radius, seg.height, 0.5 * (y0 + y1), v, arc)
            }
            None => side_arc_in(seg, sl.tables(), v).meet(&seg.floor),
        }
    }

    /// [`Views::both`], with the places of the directions' open arcs where kept.
    fn views(&self, wi: UnitVec3, wo: UnitVec3) -> [Views; 2] {
        let mut views = Views::both(wi, wo);
        let (l, e) = (self.arc_store.find(wi), self.arc_store.find(wo));
        if l.is_some() || e.is_some() {
            for v in &mut views {
                v.l.kept = l;
                v.e.kept = e;
            }
        }
        views
    }
}

/// [`AnalyticModel::side_arc`] of a segment with the side tables `(plus, minus)`.
fn side_arc_in(
    seg: &SegmentData,
    (plus, minus): (&ActiveTable, &ActiveTable),
    v: &View,
) -> ArcTrig {
    let mut arc = ArcTrig::facing(&v.p);
    let Some((psi, mirrored)) = v.side else {
        return arc;
    };
    let table = if mirrored { minus } else { plus };
    let Some(o) = table.active(psi.psi) else {
        return arc;
    };
    match occluded_arc_at(seg.radius, seg.height, o, &psi) {
        ArcOcclusion::None => {}
        ArcOcclusion::All => {
            arc.arc.hi = arc.arc.lo;
            arc.hi = arc.lo;
        }
        ArcOcclusion::UpTo(t, (s, c)) if mirrored => {
            // pi - t
            if PI - t < arc.arc.hi {
                arc.arc.hi = PI - t;
                arc.hi = (s, -c);
            }
        }
        ArcOcclusion::UpTo(t, sc) => {
            if t > arc.arc.lo {
                arc.arc.lo = t;
                arc.lo = sc;
            }
        }
    }
    arc
}

impl AnalyticModel {
    /// Interval along the axis not hidden by the occluders at the end that direction `v` comes
    /// from (eq. 3.6 via the active table). `arc` and `e` give the points and weights the
    /// refined variant averages over.
    fn end_interval(&self, u: &Unit, v: &View, arc: &ArcTrig, e: Projected) -> (f64, f64) {
        let Some((y0, y1)) = u.seg.extent else {
            return (f64::NEG_INFINITY, f64::INFINITY);
        };
        let Some(psi) = v.end else {
            return (y0, y1);
        };
        if u.around.is_some() {
            // Sliced3d: what lies along the axis hides the arc itself (`slice_arc`).
            return (y0, y1);
        }
        let seg = &u.seg;
        let table = if v.va > 0.0 {
            &seg.end_plus
        } else {
            &seg.end_minus
        };
        let hidden = table.active(psi.psi).map_or(0.0, |o| match self.variant {
            Variant::Thesis => occluded_length(seg.top, o, &psi),
            Variant::Refined | Variant::Sliced | Variant::Sliced3d => {
                mean_occluded_length(seg.radius, seg.height, o, &psi, arc, e, y1 - y0)
            }
        });
        if v.va > 0.0 {
            (y0, y1 - hidden)
        } else {
            (y0 + hidden, y1)
        }
    }

    /// Integrals over the arc of the facet's diffuse factor and specular intensity, each times
    /// N.E (the cos(theta - theta_E) correction of eqs 4.7 and 4.9, times |E_p|).
    fn arc_integral(
        &self,
        m: &Material,
        g: Group,
        arc: &ArcTrig,
        views: &Views,
        wi: UnitVec3,
        wo: UnitVec3,
    ) -> (f64, f64) {
        let kd = diffuse_integral(arc, views.l.p.p, views.e.p.p);
        if m.specular == 0.0 {
            return (kd, 0.0);
        }
        if self.facet == FacetModel::Huo {
            let e = Heading::from(&views.e.p);
            if let Some(s) = huo_specular_integral(arc, &views.h, &e, m.exponent) {
                return (kd, m.specular * s);
            }
        }
        let arc = arc.arc;
        // Quadrature of the facet model, split at the specular peak.
        let (c, _) = frame(g);
        let (l, e) = (wi.get(), wo.get());
        let mut f = |t: f64| {
            let n = c * t.cos() + Vec3::new(0.0, 0.0, t.sin());
            self.facet.intensity(m, n, l, e).specular * n.dot(e).max(0.0)
        };
        let h = l + e;
        let peak = Projected {
            c: h.dot(c),
            z: h.z,
        }
        .angle()
        .clamp(arc.lo, arc.hi);
        let tol = 1e-10 * (arc.hi - arc.lo);
        let s = integrate(&mut f, arc.lo, peak, tol) + integrate(&mut f, peak, arc.hi, tol);
        (kd, s)
    }
}

/// The secondary reflection from both sides, summed in the order of sec. 5.4's two
/// neighbours (+c, then -c).
fn both_sides(s: &[Secondary; 2]) -> Secondary {
    let mut out = Secondary::default();
    out.add_scaled(&s[0], 1.0);
    out.add_scaled(&s[1], 1.0);
    out
}

fn meet(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0.max(b.0), a.1.min(b.1))
}

fn overlap(a: (f64, f64), b: (f64, f64)) -> f64 {
    let (lo, hi) = meet(a, b);
    (hi - lo).max(0.0)
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

    #[test]
    fn periods_beyond_the_limits_are_refused() {
        use crate::fabric::{check_period, MAX_CELLS, MAX_THREADS};
        assert!(check_period(1024, 1024).is_ok());
        assert!(check_period(MAX_THREADS, 16).is_ok());
        let (problem, fix) = check_period(MAX_THREADS + 1, 1).unwrap_err();
        assert!(problem.contains("65537 warp threads"), "{problem}");
        assert!(fix.contains("docs/reference/limits.md"), "{fix}");
        let (problem, _) = check_period(1025, 1024).unwrap_err();
        assert!(
            problem.contains(&format!("1049600 cells, more than the {MAX_CELLS}")),
            "{problem}"
        );
        // The one constructor refuses such a period, naming the field, before any work on it.
        let rows = vec![vec![true, false]; MAX_CELLS / 2 + 1];
        let e = Fabric::from_json_str(
            &format!(
                r#"{{"pattern": {:?}, "warp": {{"radius": 1, "spacing": 2}}, "weft": {{"radius": 1, "spacing": 2}}}}"#,
                rows.iter().map(|r| r.iter().map(|&b| b as u8).collect::<Vec<_>>()).collect::<Vec<_>>()
            ),
            "big.json",
        )
        .unwrap_err();
        assert_eq!(e.field, "pattern");
        assert!(e.problem.contains("weft threads (rows)"), "{e}");
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
                let m = AnalyticModel::with_variant(fabric, FacetModel::Huo, variant);
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
            let merged = AnalyticModel::with_variant(&f, FacetModel::Huo, variant);
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
        let refined = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Refined);
        // (variant, relative tolerance, the smallest value it is relative to)
        for (variant, tol, floor) in [
            (Variant::Sliced, 1e-12, 1e-12),
            (Variant::Sliced3d, 1e-4, 1e-6),
        ] {
            let m = AnalyticModel::with_variant(&f, FacetModel::Huo, variant);
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
        let refined = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Refined);
        let sliced = AnalyticModel::with_variant(&f, FacetModel::Huo, Variant::Sliced);
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
