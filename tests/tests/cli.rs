//! The inputs the `clothbake` CLI ships, checked at library level: every fabric table in
//! `tables/` loads with `Fabric::from_path`, builds its micro-geometry, has the documented
//! weave and segment lengths, and (the thesis's samples) spells out the thesis's sec. 4.3
//! material. The fabric presets (real cloth, docs/reference/fabric-format.md) are checked against their
//! documented sources in `tests/tests/presets.rs`.
//! (Tests that drive the binary itself live in `crates/clothbake/tests/cli.rs`.)

use clothbake_core::fabric::{DEFAULT_ALBEDO, DEFAULT_EXPONENT, DEFAULT_SPECULAR};
use clothbake_core::{AnalyticModel, Fabric, FacetModel, Geometry, Group, Material, UnitVec3};
use std::path::Path;

use clothbake_tests::fixtures::{shipped_files, tables as tables_dir};

fn load(name: &str) -> Fabric {
    let p = tables_dir().join(format!("{name}.json"));
    Fabric::from_path(&p).unwrap_or_else(|e| panic!("{e}"))
}

/// Lengths of the finite floats of group `g`, sorted and deduplicated to 1e-9.
fn lengths(geo: &Geometry, g: Group) -> Vec<f64> {
    let mut v: Vec<f64> = geo
        .segments
        .iter()
        .filter(|s| s.group == g)
        .filter_map(|s| s.extent.map(|(a, b)| b - a))
        .collect();
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    v
}

fn close(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-9)
}

/// A shipped table and what it must contain.
struct Shipped {
    name: &'static str,
    /// (warp threads, weft threads) in the period.
    period: (usize, usize),
    /// Distinct lengths of the finite warp floats.
    warp_len: &'static [f64],
    /// Distinct lengths of the finite weft floats.
    weft_len: &'static [f64],
    /// One of the thesis's samples (the sec. 4.3 material), not a preset of real cloth.
    thesis: bool,
}

/// One of the thesis's samples.
const fn shipped(
    name: &'static str,
    period: (usize, usize),
    warp_len: &'static [f64],
    weft_len: &'static [f64],
) -> Shipped {
    Shipped {
        name,
        period,
        warp_len,
        weft_len,
        thesis: true,
    }
}

impl Shipped {
    /// This fabric as a preset of real cloth: float length (f + 1) s - 2 r over f crossing
    /// threads of spacing s and radius r (docs/reference/fabric-format.md).
    const fn real(self) -> Shipped {
        Shipped {
            thesis: false,
            ..self
        }
    }
}

const SHIPPED: [Shipped; 10] = [
    shipped("plain", (2, 2), &[3.2], &[3.2]),
    shipped("basket", (4, 4), &[6.3], &[6.3]),
    shipped("twill", (3, 3), &[6.3], &[3.2]),
    shipped("twill31", (4, 4), &[9.4], &[3.2]),
    shipped("satin5", (5, 5), &[12.5], &[3.2]),
    // One endless warp cylinder (no finite float); the weft never comes up.
    shipped("parallel", (1, 1), &[], &[]),
    // Warp over 1 weft: 2 x 0.3528 - 2 x 0.0924; weft over 1 warp: 2 x 0.1910 - 2 x 0.0924.
    shipped("cotton-poplin", (2, 2), &[0.5208], &[0.1972]).real(),
    // Over 2 at spacing 2.1167, radius 0.7056: 3 x 2.1167 - 2 x 0.7056.
    shipped("wool-twill", (4, 4), &[4.9389], &[4.9389]).real(),
    // Warp over 4 wefts (0.2222, r 0.0487): 5 x 0.2222 - 2 x 0.0487; weft over 1 warp (0.0833,
    // r 0.0398): 2 x 0.0833 - 2 x 0.0398.
    shipped("silk-charmeuse", (5, 5), &[1.0136], &[0.0870]).real(),
    // Warp over 1 weft: 2 x 0.3175 - 2 x 0.1117; weft over 1 warp: 2 x 0.2309 - 2 x 0.1117.
    shipped("polyester-taffeta", (2, 2), &[0.4116], &[0.2384]).real(),
];

#[test]
fn every_json_in_tables_is_listed_here() {
    let mut found: Vec<String> = shipped_files("json")
        .iter()
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    found.sort();
    let mut want: Vec<String> = SHIPPED.iter().map(|s| s.name.to_string()).collect();
    want.sort();
    assert_eq!(found, want);
}

#[test]
fn shipped_tables_load_and_build_their_geometry() {
    for Shipped {
        name,
        period: (nw, nf),
        warp_len,
        weft_len,
        ..
    } in SHIPPED
    {
        let f = load(name);
        assert_eq!(f.name(), name);
        assert_eq!((f.weave().n_warp(), f.weave().n_weft()), (nw, nf), "{name}");
        let geo = Geometry::new(&f);
        assert!(!geo.segments.is_empty(), "{name}");
        assert!(
            close(&lengths(&geo, Group::Warp), warp_len),
            "{name} warp: {:?}",
            lengths(&geo, Group::Warp)
        );
        assert!(
            close(&lengths(&geo, Group::Weft), weft_len),
            "{name} weft: {:?}",
            lengths(&geo, Group::Weft)
        );
        // The model runs on it (finite, non-negative).
        let r = AnalyticModel::new(&f, FacetModel::Huo).intensity(
            UnitVec3::from_degrees(45.0, 90.0),
            UnitVec3::from_degrees(30.0, 250.0),
        );
        for x in r.i_d.iter().chain(&r.i_s) {
            assert!(x.is_finite() && *x >= 0.0, "{name}: {r:?}");
        }
    }
}

#[test]
fn shipped_tables_use_the_thesis_material() {
    let thesis = Material {
        albedo: [DEFAULT_ALBEDO; 3],
        specular: DEFAULT_SPECULAR,
        exponent: DEFAULT_EXPONENT,
        translucency: 0.0,
    };
    assert_eq!(
        thesis,
        Material {
            albedo: [0.4; 3],
            specular: 0.3,
            exponent: 10.0,
            translucency: 0.0,
        }
    );
    for Shipped {
        name,
        thesis: sample,
        ..
    } in SHIPPED
    {
        let f = load(name);
        if sample {
            assert_eq!(f.warp().material, thesis, "{name}");
            assert_eq!(f.weft().material, thesis, "{name}");
        }
        // Written out explicitly in the file, not left to the defaults.
        let text = std::fs::read_to_string(tables_dir().join(format!("{name}.json"))).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        for g in ["warp", "weft"] {
            let m = &v[g]["material"];
            assert!(
                m["albedo"].is_number() || m["albedo"].is_array(),
                "{name}.{g}"
            );
            assert!(
                m["specular"].is_number() && m["exponent"].is_number(),
                "{name}.{g}"
            );
        }
        assert!(v["description"].is_string(), "{name}: give a description");
    }
}

#[test]
fn weaves_are_what_their_names_say() {
    // (name, warp float, weft float): every thread of the group floats over that many.
    for (name, warp_f, weft_f) in [
        ("plain", 1, 1),
        ("basket", 2, 2),
        ("twill", 2, 1),
        ("twill31", 3, 1),
        ("satin5", 4, 1),
    ] {
        let w = load(name).weave().clone();
        for (g, want) in [(Group::Warp, warp_f), (Group::Weft, weft_f)] {
            for t in 0..w.n(g) {
                let fl = w.floats(g, t);
                assert!(
                    fl.iter().all(|f| f.len == want && !f.endless),
                    "{name} {g:?} {t}: {fl:?}"
                );
            }
        }
    }
    // Satin: no two interlacings of neighbouring wefts are adjacent (move number 2 or 3).
    let w = load("satin5").weave().clone();
    let under = |r: usize| (0..5).find(|&c| !w.warp_over(c, r)).unwrap();
    for r in 0..5 {
        let d = (under((r + 1) % 5) + 5 - under(r)) % 5;
        assert!(d == 2 || d == 3, "row {r}: move {d}");
    }
    // The parallel-cylinder surface: one endless warp, no weft float.
    let w = load("parallel").weave().clone();
    assert!(w.floats(Group::Warp, 0)[0].endless);
    assert!(w.floats(Group::Weft, 0).is_empty());
}

#[test]
fn documented_example_loads() {
    // The complete example in docs/reference/fabric-format.md (the first ```json block) is valid.
    let doc = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/reference/fabric-format.md"),
    )
    .unwrap();
    let start = doc.find("```json\n").expect("a ```json block") + "```json\n".len();
    let end = start + doc[start..].find("```").unwrap();
    let f = Fabric::from_json_str(&doc[start..end], "docs/reference/fabric-format.md")
        .unwrap_or_else(|e| panic!("{e}"));
    Geometry::new(&f);
}
