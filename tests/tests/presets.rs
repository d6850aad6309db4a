//! The presets of real cloth (docs/reference/fabric-format.md, "Presets of real cloth"): each file
//! against the documented table (ends and picks per cm, yarn diameters, rho_s, n), the model
//! finite and positive on them, and what their inputs imply about their look: the denim's
//! reflection is blue (an indigo warp over most of the surface, a beige weft adding nearly the
//! same to every channel) and as light as measured indigo denim, a filament satin's highlight stands out from its diffuse reflection more
//! than any plain weave's, and the woollen twill's least.

use clothbake_core::directions::direction_set;
use clothbake_core::{AnalyticModel, Fabric, FacetModel, UnitVec3};
use clothbake_tests::fixtures::{root, tables};

/// One row of the documented table.
#[derive(Debug)]
struct Row {
    file: String,
    ends_per_cm: f64,
    picks_per_cm: f64,
    warp_diameter: f64,
    weft_diameter: f64,
    specular: f64,
    exponent: f64,
}

/// The rows of the table under "## Presets of real cloth" in docs/reference/fabric-format.md.
fn documented() -> Vec<Row> {
    let text = std::fs::read_to_string(root().join("docs/reference/fabric-format.md")).unwrap();
    let section = text
        .split("## Presets of real cloth")
        .nth(1)
        .expect("docs/reference/fabric-format.md has the presets section");
    let num = |s: &str| -> f64 { s.trim().parse().unwrap_or_else(|_| panic!("`{s}`")) };
    section
        .lines()
        .take_while(|l| !l.starts_with("## "))
        .filter(|l| l.starts_with("| `tables/"))
        .map(|l| {
            let c: Vec<&str> = l.split('|').map(str::trim).collect();
            // c[0] is empty (the line starts with |).
            Row {
                file: c[1].trim_matches('`').trim_start_matches("tables/").into(),
                ends_per_cm: num(c[3]),
                picks_per_cm: num(c[4]),
                warp_diameter: num(c[5]),
                weft_diameter: num(c[6]),
                specular: num(c[8]),
                exponent: num(c[9]),
            }
        })
        .collect()
}

fn load(file: &str) -> Fabric {
    Fabric::from_path(&tables().join(file)).unwrap_or_else(|e| panic!("{e}"))
}

/// Mean over R, G, B of the thesis's intensity I (Huo facets).
fn mean_i(f: &Fabric, wi: UnitVec3, wo: UnitVec3) -> f64 {
    let i = AnalyticModel::new(f, FacetModel::Huo)
        .intensity(wi, wo)
        .total();
    (i[0] + i[1] + i[2]) / 3.0
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

#[test]
fn every_preset_matches_its_documented_counts_sizes_and_material() {
    let rows = documented();
    let files: Vec<&str> = rows.iter().map(|r| r.file.as_str()).collect();
    assert_eq!(
        files,
        [
            "denim.wif",
            "cotton-poplin.json",
            "silk-charmeuse.json",
            "polyester-taffeta.json",
            "wool-twill.json"
        ]
    );
    for r in &rows {
        let f = load(&r.file);
        // Spacing (mm) = 10 / (threads per cm); the table rounds to 4 digits.
        for (g, count, diameter) in [
            (f.warp(), r.ends_per_cm, r.warp_diameter),
            (f.weft(), r.picks_per_cm, r.weft_diameter),
        ] {
            for y in &g.threads {
                assert!(rel(y.spacing, 10.0 / count) < 5e-4, "{r:?}: {y:?}");
                assert!(rel(2.0 * y.radius, diameter) < 2e-3, "{r:?}: {y:?}");
            }
            assert_eq!(g.material.specular, r.specular, "{r:?}");
            assert_eq!(g.material.exponent, r.exponent, "{r:?}");
            // Energy: the highlight and the diffuse part together reflect at most all light.
            let rho_d = g.material.albedo.iter().fold(0.0f64, |m, x| m.max(*x));
            assert!(rho_d + g.material.specular <= 1.0, "{r:?}");
        }
    }
}

#[test]
fn the_model_is_finite_and_positive_on_every_preset() {
    for r in documented() {
        let f = load(&r.file);
        for facet in [FacetModel::Huo, FacetModel::Lewis] {
            let m = AnalyticModel::new(&f, facet);
            for (wi, wo) in direction_set(24, 70.0) {
                let i = m.intensity(wi, wo).total();
                for x in i {
                    assert!(x.is_finite() && x > 0.0, "{}: {wi:?} {wo:?} {i:?}", r.file);
                }
            }
        }
    }
}

#[test]
fn denim_reflects_blue() {
    // Off the mirror direction (mostly diffuse): the indigo warp covers most of what is seen and
    // the beige weft adds nearly the same to every channel, so blue leads; the white
    // highlight cannot reverse that either.
    let f = load("denim.wif");
    for (wi, wo) in [((40.0, 0.0), (30.0, 120.0)), ((30.0, 90.0), (50.0, 200.0))] {
        let i = AnalyticModel::new(&f, FacetModel::Huo)
            .intensity(
                UnitVec3::from_degrees(wi.0, wi.1),
                UnitVec3::from_degrees(wo.0, wo.1),
            )
            .total();
        assert!(i[2] > i[0] && i[2] > i[1], "{wi:?} {wo:?}: {i:?}");
    }
}

/// CIE L* of a preset as a colour instrument sees it: diffuse light, the eye 8 degrees off the
/// normal (d/8), specular included; the reflectance factor R = (1 / pi) of the integral of I
/// over the incident hemisphere (midpoint rule in cos(theta_i) and phi_i, 48 x 96), per linear
/// sRGB channel; Y = 0.2126 R + 0.7152 G + 0.0722 B (D65); L* = 116 f(Y) - 16 (CIE 15).
fn lightness_d8(f: &Fabric) -> f64 {
    let m = AnalyticModel::new(f, FacetModel::Huo);
    let wo = UnitVec3::from_degrees(8.0, 45.0);
    let (nu, nphi) = (48, 96);
    let mut r = [0.0; 3];
    for a in 0..nu {
        let mu = (a as f64 + 0.5) / nu as f64;
        for b in 0..nphi {
            let phi = 360.0 * (b as f64 + 0.5) / nphi as f64;
            let wi = UnitVec3::from_degrees(mu.acos().to_degrees(), phi);
            let i = m.intensity(wi, wo).total();
            for k in 0..3 {
                // d omega = d mu d phi; (1 / pi) * (1 / nu) * (2 pi / nphi).
                r[k] += i[k] * 2.0 / (nu * nphi) as f64;
            }
        }
    }
    let y = 0.2126 * r[0] + 0.7152 * r[1] + 0.0722 * r[2];
    let fy = if y > (6.0f64 / 29.0).powi(3) {
        y.cbrt()
    } else {
        y / (3.0 * (6.0f64 / 29.0).powi(2)) + 4.0 / 29.0
    };
    116.0 * fy - 16.0
}

/// The denim's lightness lies in the range a colour instrument measures on indigo denim: L*
/// about 30 for a dark shade to 60 for a light one (H. Mercer, "Shade control in indigo
/// dyeing", part 2, denimsandjeans.com; docs/reference/fabric-format.md).
#[test]
fn denim_lightness_is_that_of_measured_indigo_shades() {
    let l = lightness_d8(&load("denim.wif"));
    eprintln!("denim: L* (d/8) {l:.1}");
    assert!((30.0..=60.0).contains(&l), "L* {l}");
    // The measure sees lightness: the same cloth in white yarn (albedo 0.95) is near 100.
    let white = load("denim.wif")
        .with_groups(
            |_, g| g.material.albedo = [0.95; 3],
            &clothbake_core::PlainNaming("white"),
        )
        .unwrap();
    assert!(lightness_d8(&white) > 85.0, "{}", lightness_d8(&white));
}

#[test]
fn satin_sheen_outshines_plain_weaves_and_wool_is_matte() {
    // Light at 45 degrees in the warp's plane (phi 90: the satin's warp floats run along +Y):
    // the highlight at the mirror direction over the reflection seen from overhead.
    let wi = UnitVec3::from_degrees(45.0, 90.0);
    let ratio = |file: &str| {
        let f = load(file);
        mean_i(&f, wi, UnitVec3::from_degrees(45.0, 270.0))
            / mean_i(&f, wi, UnitVec3::from_degrees(0.0, 0.0))
    };
    let silk = ratio("silk-charmeuse.json");
    for plain in ["cotton-poplin.json", "polyester-taffeta.json", "plain.json"] {
        assert!(silk > ratio(plain), "{silk} vs {plain} {}", ratio(plain));
    }
    // The weave alone, same material (the thesis's): the satin's long warp floats over the
    // plain weave's short ones.
    assert!(ratio("satin5.json") > ratio("plain.json"));
    // Filament polyester is glossier than staple cotton of the same weave.
    assert!(ratio("polyester-taffeta.json") > ratio("cotton-poplin.json"));
    // Woollen yarn: no highlight to speak of, less than the other single-colour presets, and
    // below the overhead view.
    let wool = ratio("wool-twill.json");
    for other in [
        "cotton-poplin.json",
        "silk-charmeuse.json",
        "polyester-taffeta.json",
    ] {
        assert!(wool < ratio(other), "{wool} vs {other}");
    }
    assert!(wool < 1.0, "{wool}");
}
