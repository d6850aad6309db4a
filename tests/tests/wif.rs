//! WIF drafts (`tables/*.wif`, written by hand) against point papers derived by hand from the
//! weaving logic, and the documented colour and size mappings (`docs/reference/wif.md`).

use clothbake_core::wif::{parse, WifOptions};
use clothbake_core::{AnalyticModel, Fabric, FacetModel, Group, UnitVec3};
use std::path::Path;

use clothbake_tests::fixtures::{shipped_files, tables};

fn load(name: &str) -> Fabric {
    Fabric::from_path(&tables().join(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// The shipped draft `name`, after checking that its point paper (row by row, 1 where the warp
/// is over) is `rows`.
fn woven_as<const N: usize>(name: &str, rows: [[u8; N]; N]) -> Fabric {
    let f = load(name);
    assert_eq!(f.weave().to_rows(), rows.map(Vec::from), "{name}");
    f
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-12 * b.abs().max(1.0)
}

/// sRGB value v of a 0..hi range to linear albedo, written out here from IEC 61966-2-1.
fn lin(v: f64, hi: f64) -> f64 {
    let c = v / hi;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

#[test]
fn every_wif_in_tables_is_checked_here() {
    let found: Vec<String> = shipped_files("wif")
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(found, ["denim.wif", "gingham.wif", "twill22.wif"]);
}

#[test]
fn denim_is_the_warp_faced_3_1_twill() {
    // Straight draw (end e on shaft e), rising shed, pick p treads treadle p, and treadle t lifts
    // shafts t, t+1, t+2 (mod 4). Pick 1 lifts shafts 1,2,3: ends 1-3 over, end 4 under, so
    // row 0 = 1110; every later pick lifts the next three shafts, moving the under-cell one end
    // to the right (+X) and wrapping: 0111, 1011, 1101.
    let f = woven_as(
        "denim.wif",
        [[1, 1, 1, 0], [0, 1, 1, 1], [1, 0, 1, 1], [1, 1, 0, 1]],
    );
    // The same point paper as the hand-written JSON fabric of the 3/1 twill.
    assert_eq!(load("twill31.json").weave(), f.weave());
    assert_eq!(f.name(), "denim");
    // Indigo warp 21,46,110 and natural-cotton weft 200,195,180 of 0..255, decoded from sRGB.
    let indigo = [lin(21.0, 255.0), lin(46.0, 255.0), lin(110.0, 255.0)];
    let beige = [lin(200.0, 255.0), lin(195.0, 255.0), lin(180.0, 255.0)];
    for k in 0..3 {
        assert!(close(f.warp().material.albedo[k], indigo[k]), "{k}");
        assert!(close(f.weft().material.albedo[k], beige[k]), "{k}");
    }
    // Published sRGB decodings: 200 -> 0.5776, 110 -> 0.1559.
    assert!((beige[0] - 0.5776).abs() < 1e-4 && (indigo[2] - 0.1559).abs() < 1e-4);
    // Warp Spacing 0.03528 cm, Thickness 0.0343 cm: 0.3528 mm centre to centre, radius
    // 0.1715 mm; weft 0.04536 and 0.0287 cm: 0.4536 mm, radius 0.1435 mm.
    for (g, s, r) in [(f.warp(), 0.3528, 0.1715), (f.weft(), 0.4536, 0.1435)] {
        for y in &g.threads {
            assert!(close(y.spacing, s) && close(y.radius, r), "{y:?}");
            assert_eq!(y.albedo, None);
        }
        // [PRIVATE CLOTHBAKE MATERIAL]: Specular=0.04, Exponent=6 for both groups.
        assert_eq!((g.material.specular, g.material.exponent), (0.04, 6.0));
    }
}

#[test]
fn denim_reflects_like_the_json_twill_of_its_sizes() {
    // twill31.json (the same point paper) given the draft's sizes in mm by hand (warp 0.3528
    // apart, radius 0.1715; weft 0.4536, radius 0.1435) and the draft's material: the two give
    // the same reflection.
    let wif = load("denim.wif");
    let json = load("twill31.json")
        .with_groups(
            |g, y| {
                let (s, r) = match g {
                    Group::Warp => (0.3528, 0.1715),
                    Group::Weft => (0.4536, 0.1435),
                };
                for t in &mut y.threads {
                    (t.spacing, t.radius) = (s, r);
                }
                y.material = wif.group(g).material;
            },
            &clothbake_core::PlainNaming("twill31"),
        )
        .unwrap();
    let (a, b) = (
        AnalyticModel::new(&wif, FacetModel::Huo),
        AnalyticModel::new(&json, FacetModel::Huo),
    );
    for (ti, pi, to, po) in [(30.0, 0.0, 45.0, 180.0), (50.0, 80.0, 20.0, 300.0)] {
        let (wi, wo) = (
            UnitVec3::from_degrees(ti, pi),
            UnitVec3::from_degrees(to, po),
        );
        let (x, y) = (a.intensity(wi, wo).total(), b.intensity(wi, wo).total());
        for k in 0..3 {
            assert!((x[k] - y[k]).abs() <= 1e-9 * y[k], "{x:?} {y:?}");
        }
    }
}

#[test]
fn gingham_reduces_to_its_colour_repeat() {
    // Plain weave: ends alternate shafts 1, 2; pick p treads treadle 1 for odd p, 2 for even p,
    // each lifting its own shaft. Pick 1 raises the odd ends (columns 0, 2, ...): cell (i, j) is 1
    // where i + j is even. The weave repeats every 2 threads, but the colour stripes (4 red,
    // 4 white) every 8, and the draft writes 16: the period is 8 x 8.
    let f = load("gingham.wif");
    let want: Vec<Vec<u8>> = (0..8)
        .map(|j| (0..8).map(|i| ((i + j) % 2 == 0) as u8).collect())
        .collect();
    assert_eq!(f.weave().to_rows(), want);
    let red = [lin(800.0, 999.0), lin(80.0, 999.0), lin(80.0, 999.0)];
    let white = [lin(950.0, 999.0); 3];
    for g in [Group::Warp, Group::Weft] {
        for t in 0..8 {
            let want = if t < 4 { red } else { white };
            let got = f.group(g).albedo(t);
            assert!((0..3).all(|k| close(got[k], want[k])), "{g:?} {t}: {got:?}");
        }
    }
    // 0.0125 inch spacing, 0.012 inch thickness.
    let y = f.warp().threads[3];
    assert!(close(y.spacing, 0.0125 * 25.4) && close(y.radius, 0.006 * 25.4));
}

#[test]
fn twill22_liftplan_on_a_sinking_shed() {
    // Sinking shed: the listed shafts go down, taking their ends under the weft. Pick 1 sinks
    // shafts 1, 2: ends 1, 2 under, 3, 4 over: 0011. Each pick sinks the next pair: 1001, 1100,
    // 0110. Eight ends and picks written, two repeats of four.
    let want = [[0, 0, 1, 1], [1, 0, 0, 1], [1, 1, 0, 0], [0, 1, 1, 0]];
    let f = woven_as("twill22.wif", want);
    // No sizes and no colours in the draft: the documented defaults (0.31 mm, 0.30 mm thick;
    // the thesis's rho_d 0.4).
    for y in f.warp().threads.iter().chain(&f.weft().threads) {
        assert!(close(y.spacing, 0.31) && close(y.radius, 0.15), "{y:?}");
    }
    assert_eq!(f.warp().material.albedo, [0.4; 3]);
    // The same draft on a rising shed is the other face: every cell flipped.
    let text = std::fs::read_to_string(tables().join("twill22.wif")).unwrap();
    let rising = parse(
        &text.replace("Rising Shed=false", "Rising Shed=true"),
        "t.wif",
        &WifOptions::default(),
    )
    .unwrap();
    let flipped: Vec<Vec<u8>> = want
        .iter()
        .map(|r| r.iter().map(|&c| 1 - c).collect())
        .collect();
    assert_eq!(rising.weave().to_rows(), flipped);
}

#[test]
fn options_set_the_sizes_whether_the_draft_gives_them_or_not() {
    let o = WifOptions {
        radius: Some(0.1),
        spacing: Some(0.25),
    };
    // twill22.wif gives no sizes, denim.wif gives both (e.g. the warp's 0.1715 mm radius at
    // 0.3528 mm): the options win in both.
    for name in ["twill22.wif", "denim.wif"] {
        let text = std::fs::read_to_string(tables().join(name)).unwrap();
        let f = parse(&text, name, &o).unwrap();
        for y in f.warp().threads.iter().chain(&f.weft().threads) {
            assert!(
                close(y.radius, 0.1) && close(y.spacing, 0.25),
                "{name}: {y:?}"
            );
        }
        assert!(f.notes().is_empty());
    }
    // Only the one given: denim keeps its spacing, takes the radius.
    let text = std::fs::read_to_string(tables().join("denim.wif")).unwrap();
    let o = WifOptions {
        radius: Some(0.1),
        spacing: None,
    };
    let f = parse(&text, "denim.wif", &o).unwrap();
    assert!(close(f.warp().threads[0].radius, 0.1) && close(f.warp().threads[0].spacing, 0.3528));
    // A radius over half the spacing packs the yarns as a draft's thickness would: the warp's
    // to half its 0.3528 mm; the weft's 0.4536 mm leaves room for 0.2.
    let o = WifOptions {
        radius: Some(0.2),
        spacing: None,
    };
    let f = parse(&text, "denim.wif", &o).unwrap();
    assert!(close(f.weft().threads[0].radius, 0.2));
    assert!(
        close(f.warp().threads[0].radius, 0.1764),
        "{:?}",
        f.warp().threads[0]
    );
    assert!(
        f.notes()[0].contains("from --radius/--spacing"),
        "{:?}",
        f.notes()
    );
}

fn test_draft(name: &str) -> Fabric {
    Fabric::from_path(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("drafts")
            .join(name),
    )
    .unwrap_or_else(|e| panic!("{e}"))
}

/// The point paper of a draft from its design rules: end e (1-based) on shaft `shaft(e)`, pick
/// p moving `moved(p)`; a cell 1 where the end is raised (rising shed) or not (sinking).
fn design(
    ends: usize,
    picks: usize,
    shaft: impl Fn(usize) -> usize,
    moved: impl Fn(usize) -> Vec<usize>,
    rising: bool,
) -> Vec<Vec<u8>> {
    (1..=picks)
        .map(|p| {
            (1..=ends)
                .map(|e| u8::from(moved(p).contains(&shaft(e)) == rising))
                .collect()
        })
        .collect()
}

#[test]
fn herringbone8_dobby_draft_with_packed_yarns() {
    // tests/drafts/herringbone8.wif (CRLF lines, [CONTENTS], [NOTES], a PRIVATE section):
    // point threading 1..8..2 (14 ends, twice), treadle t ties shafts t, t+1, t+2 (mod 8),
    // treadled 1..8 twice, rising shed; warp stripes of 4 navy and 3 cream (period 7 in colour,
    // 14 in threading): the 28 x 16 draft is a 14 x 8 repeat.
    let f = test_draft("herringbone8.wif");
    let point = [1, 2, 3, 4, 5, 6, 7, 8, 7, 6, 5, 4, 3, 2];
    let want = design(
        14,
        8,
        |e| point[e - 1],
        |p| (0..3).map(|k| (p - 1 + k) % 8 + 1).collect(),
        true,
    );
    assert_eq!(f.weave().to_rows(), want);
    // Thickness .0213 cm at Spacing .0185 cm (warp), .0230 at .0200 (weft): round yarns of half
    // the spacing that touch, on the floor.
    for (g, r, s) in [(Group::Warp, 0.0925, 0.185), (Group::Weft, 0.1, 0.2)] {
        for y in &f.group(g).threads {
            assert!(
                close(y.radius, r) && close(y.spacing, s) && y.height == 0.0,
                "{y:?}"
            );
        }
    }
    assert_eq!(f.notes().len(), 2);
    assert!(
        f.notes()[0].starts_with(
            "warp: Thickness 0.02130 > Spacing 0.01850 (Centimeters); radius capped to 0.09250 mm"
        ),
        "{:?}",
        f.notes()
    );
    assert!(f.notes()[1].starts_with("weft: Thickness 0.02300 > Spacing 0.02000 (Centimeters)"));
    // Navy 20,30,80 on ends 1-4, cream on 5-7.
    assert!(close(f.warp().albedo(0)[2], lin(80.0, 255.0)));
    assert!(close(f.warp().albedo(4)[0], lin(235.0, 255.0)));
}

#[test]
fn advancing12_liftplan_draft_with_per_thread_thickness() {
    // tests/drafts/advancing12.wif: advancing threading (1234 2345 ... 12 1 2 3, 48 ends) on 12
    // shafts, liftplan pick p moving shafts p, p+1, p+2, p+6 (mod 12), sinking shed; every fourth
    // end (1, 5, ...) 7 decipoints thick, the others 6, all at spacing 5.
    let f = test_draft("advancing12.wif");
    let want = design(
        48,
        12,
        |e| (((e - 1) / 4) + (e - 1) % 4) % 12 + 1,
        |p| [0, 1, 2, 6].iter().map(|k| (p - 1 + k) % 12 + 1).collect(),
        false,
    );
    assert_eq!(f.weave().to_rows(), want);
    // Packing: pair (7, 6) scaled by 5/6.5, pair (6, 6) by 5/6; each end takes the smaller
    // factor of its two pairs. End 4k+1: 3.5 * 5/6.5; ends 4k+2, 4k+4 (next to a thick end):
    // 3 * 5/6.5; end 4k+3 (between two 6s): 3 * 5/6.
    let dp = 25.4 / 720.0;
    for (i, y) in f.warp().threads.iter().enumerate() {
        let r = match i % 4 {
            0 => 3.5 * 5.0 / 6.5,
            2 => 3.0 * 5.0 / 6.0,
            _ => 3.0 * 5.0 / 6.5,
        };
        assert!(
            close(y.radius, r * dp) && close(y.spacing, 5.0 * dp),
            "end {}: {y:?}",
            i + 1
        );
    }
    // The weft (5 thick at 5.5) fits and keeps radius 2.5 decipoints.
    assert!(close(f.weft().threads[0].radius, 2.5 * dp));
    assert_eq!(f.notes().len(), 1);
    assert!(
        f.notes()[0].starts_with("warp: 48 of 48 ends thicker than their spacing allows"),
        "{:?}",
        f.notes()
    );
}

#[test]
fn packed_drafts_match_the_ground_truth() {
    // The model on packed yarns (round, touching) against the ray tracer of the same geometry,
    // as tests/tests/ground_truth.rs does for the shipped fabrics (docs/reference/wif.md has the numbers:
    // mean 0.5-0.9%, worst 2-4%).
    use clothbake_tests::validate::compare;
    let pairs = clothbake_core::directions::direction_set(48, 70.0);
    for name in ["herringbone8.wif", "advancing12.wif"] {
        let f = test_draft(name);
        for facet in [FacetModel::Huo, FacetModel::Lewis] {
            let r = compare(&f, facet, &pairs, 40_000, 7);
            let (mean, max) = (r.mean_rel_err(), r.max_rel_err());
            eprintln!(
                "{name} {facet:?}: mean {mean:.4} max {max:.4} noise {:.4}",
                r.mean_noise()
            );
            assert!(
                mean < 0.03 && max < 0.10,
                "{name} {facet:?}: mean {mean} max {max}"
            );
            assert!(r.mean_noise() < 0.005);
        }
    }
}

#[test]
fn per_thread_sizes_give_centre_distances() {
    // [WARP SPACING] gives each end its own width; centres of ends i and i+1 are half the sum
    // apart. Ends of widths 0.4, 0.2, 0.4, 0.2 (decipoints, the default unit) repeat every 2.
    let body = "[WIF]\nVersion=1.1\n[WEAVING]\nShafts=2\n[WARP]\nThreads=4\nThickness=0.2\n\
        [WEFT]\nThreads=2\nSpacing=0.4\nThickness=0.2\n[WARP SPACING]\n1=0.4\n2=0.2\n3=0.4\n4=0.2\n\
        [THREADING]\n1=1\n2=2\n3=1\n4=2\n[LIFTPLAN]\n1=1\n2=2\n";
    let f = parse(body, "t.wif", &WifOptions::default()).unwrap();
    let dp = 25.4 / 720.0;
    assert_eq!(f.weave().n_warp(), 2);
    for y in &f.warp().threads {
        assert!(
            close(y.spacing, 0.3 * dp) && close(y.radius, 0.1 * dp),
            "{y:?}"
        );
    }
}

#[test]
fn malformed_drafts_name_file_section_and_line() {
    let text = std::fs::read_to_string(tables().join("denim.wif")).unwrap();
    let line = |needle: &str| text.lines().position(|l| l == needle).unwrap() + 1;
    let bad = |from: &str, to: &str| {
        parse(&text.replace(from, to), "denim.wif", &WifOptions::default()).unwrap_err()
    };
    let e = bad("3=3,4,1", "3=3,4,5");
    assert_eq!(
        (e.section.as_str(), e.line),
        ("TIEUP", Some(line("3=3,4,1")))
    );
    assert!(
        e.to_string().starts_with(&format!(
            "denim.wif: [TIEUP] line {}: 3=3,4,5: shaft 5 is beyond the 4 of [WEAVING] Shafts; ",
            line("3=3,4,1")
        )),
        "{e}"
    );
    let e = bad("1=21,46,110", "1=21,46");
    assert_eq!(
        (e.section.as_str(), e.line),
        ("COLOR TABLE", Some(line("1=21,46,110")))
    );
    let e = bad("Rising Shed=true", "Rising Shed=maybe");
    assert_eq!(
        (e.section.as_str(), e.line),
        ("WEAVING", Some(line("Rising Shed=true")))
    );
    // Through Fabric::from_path the error keeps section and line.
    let p = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bad-denim.wif");
    std::fs::write(&p, text.replace("4=4\n", "4=0\n")).unwrap();
    let e = Fabric::from_path(&p).unwrap_err().to_string();
    assert!(e.contains("bad-denim.wif: [THREADING] line"), "{e}");
    assert!(e.contains("end 4 is on no shaft"), "{e}");
}
