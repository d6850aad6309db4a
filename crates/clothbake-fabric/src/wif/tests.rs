use super::*;

fn draft(body: &str) -> String {
    format!("[WIF]\nVersion=1.1\n{body}")
}

fn err(body: &str) -> WifError {
    parse(&draft(body), "t.wif", &WifOptions::default()).unwrap_err()
}

#[test]
fn srgb_decode_end_points_and_mid_grey() {
    assert_eq!(srgb_to_linear(0.0), 0.0);
    assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-15);
    // sRGB 188/255 is about linear 0.5 (the well-known mid grey).
    assert!((srgb_to_linear(188.0 / 255.0) - 0.5).abs() < 0.005);
    // The two branches meet at the threshold.
    let t = 0.04045;
    assert!((t / 12.92 - ((t + 0.055) / 1.055f64).powf(2.4)).abs() < 1e-6);
}

#[test]
fn minimal_period_finds_the_smallest_divisor() {
    let v = [1, 2, 1, 2, 1, 2];
    assert_eq!(minimal_period(6, |a, b| v[a] == v[b]), 2);
    let w = [1, 2, 3, 1, 2, 4];
    assert_eq!(minimal_period(6, |a, b| w[a] == w[b]), 6);
    // 5 ends of a 2-end repeat: not a whole number of repeats, kept whole.
    let x = [1, 2, 1, 2, 1];
    assert_eq!(minimal_period(5, |a, b| x[a] == x[b]), 5);
}

#[test]
fn resolve_sizes_precedence() {
    let none = WifOptions::default();
    assert_eq!(
        resolve_sizes((Some(1.0), Some(0.5)), (None, None), &none),
        (1.0, 0.5)
    );
    let (s, t) = resolve_sizes((Some(3.1), None), (None, None), &none);
    assert_eq!(s, 3.1);
    assert!((t - 3.0).abs() < 1e-12);
    // The other group's sizes before the defaults; the options before both.
    assert_eq!(
        resolve_sizes((None, None), (Some(2.0), Some(1.0)), &none),
        (2.0, 1.0)
    );
    let o = WifOptions {
        radius: Some(0.2),
        spacing: Some(0.5),
    };
    assert_eq!(
        resolve_sizes((None, None), (Some(2.0), Some(1.0)), &o),
        (0.5, 0.4)
    );
    // ... and before the draft's own sizes, one at a time.
    assert_eq!(
        resolve_sizes((Some(1.0), Some(0.5)), (None, None), &o),
        (0.5, 0.4)
    );
    let radius_only = WifOptions {
        radius: Some(0.2),
        spacing: None,
    };
    assert_eq!(
        resolve_sizes((Some(1.0), Some(0.5)), (None, None), &radius_only),
        (1.0, 0.4)
    );
    assert_eq!(
        resolve_sizes((None, None), (None, None), &none),
        (DEFAULT_SPACING_MM, DEFAULT_THICKNESS_MM)
    );
}

const PLAIN: &str = "[WEAVING]\nShafts=2\nTreadles=2\n[WARP]\nThreads=2\n[WEFT]\nThreads=2\n\
    [THREADING]\n1=1\n2=2\n[TIEUP]\n1=1\n2=2\n[TREADLING]\n1=1\n2=2\n";

#[test]
fn errors_name_section_and_line() {
    // Line numbers count from the draft's first line: [WIF] 1, Version 2, [WEAVING] 3,
    // Shafts 4, ..., [THREADING] 10, [TIEUP] 13 with 2=... on 15, [TREADLING] 16, 1=... 17.
    let e = err(&PLAIN.replace("2=2\n[TREADLING]", "2=3\n[TREADLING]"));
    assert_eq!((e.section.as_str(), e.line), ("TIEUP", Some(15)));
    assert!(
        e.problem
            .contains("shaft 3 is beyond the 2 of [WEAVING] Shafts"),
        "{e}"
    );
    assert!(e.to_string().starts_with("t.wif: [TIEUP] line 15: "), "{e}");

    let e = err(&PLAIN.replace("[THREADING]\n1=1\n2=2", "[THREADING]\n1=1"));
    assert_eq!((e.section.as_str(), e.line), ("THREADING", Some(10)));
    assert!(e.problem.contains("end 2 of 2 has no entry"), "{e}");

    let e = err(&PLAIN.replace("[TREADLING]\n1=1", "[TREADLING]\n1=x"));
    assert_eq!((e.section.as_str(), e.line), ("TREADLING", Some(17)));

    let e = err(&PLAIN.replace("Shafts=2", "Shafts two"));
    assert_eq!((e.section.as_str(), e.line), ("WEAVING", Some(4)));

    let e = err(&PLAIN.replace("[TIEUP]\n1=1\n2=2\n", ""));
    assert_eq!(e.section, "TIEUP");

    let e = err(&format!("{PLAIN}[TIEUP]\n1=1\n"));
    assert!(e.problem.contains("second time (first at line 13)"), "{e}");

    let e = err(&format!(
        "{PLAIN}[COLOR TABLE]\n1=300,0,0\n[WARP COLORS]\n1=1\n"
    ));
    assert_eq!(e.section, "COLOR TABLE");
    assert!(
        e.problem
            .contains("outside the [COLOR PALETTE] range 0,255"),
        "{e}"
    );

    let e = err(&format!("{PLAIN}[WARP COLORS]\n1=4\n"));
    assert_eq!(e.section, "WARP COLORS");
    assert!(
        e.problem.contains("colour 4 is not in the [COLOR TABLE]"),
        "{e}"
    );

    let e = err(&PLAIN
        .replace("Units", "")
        .replace("[WARP]\n", "[WARP]\nUnits=furlongs\n"));
    assert!(e.problem.contains("Units=furlongs"), "{e}");

    let e = parse("[DRAFT]\n1=1\n", "x.wif", &WifOptions::default()).unwrap_err();
    assert!(e.problem.contains("no [WIF] section"), "{e}");
}

#[test]
fn the_private_section_sets_the_facet_material() {
    let ok = |section: &str| {
        parse(
            &draft(&format!("{PLAIN}{section}")),
            "t.wif",
            &WifOptions::default(),
        )
        .unwrap()
    };
    // Absent: the thesis's rho_s 0.3 and n 10 for both groups.
    let f = ok("");
    assert_eq!(
        (f.warp().material.specular, f.weft().material.exponent),
        (0.3, 10.0)
    );
    // Both groups, then one group's own key winning; keys case-insensitive.
    let f = ok("[PRIVATE CLOTHBAKE MATERIAL]
Specular=0.05
exponent=4 ; broad
Weft Specular=0.5
");
    let (w, f_) = (f.warp().material, f.weft().material);
    assert_eq!(
        (w.specular, w.exponent, f_.specular, f_.exponent),
        (0.05, 4.0, 0.5, 4.0)
    );
    // The albedo stays the colours' (none here: the default).
    assert_eq!(w.albedo, Material::default().albedo);
    // Switched off in [CONTENTS]: ignored. Another program's private section: ignored.
    let f = ok("[PRIVATE CLOTHBAKE MATERIAL]
Specular=0.05
[PRIVATE OTHER]
Specular=x
");
    assert_eq!(f.warp().material.specular, 0.05);
    let body = format!(
        "[CONTENTS]
PRIVATE CLOTHBAKE MATERIAL=false
{PLAIN}[PRIVATE CLOTHBAKE MATERIAL]
Specular=0.05
"
    );
    let f = parse(&draft(&body), "t.wif", &WifOptions::default()).unwrap();
    assert_eq!(f.warp().material.specular, 0.3);
}

#[test]
fn the_private_section_refuses_what_it_cannot_use() {
    // [PRIVATE CLOTHBAKE MATERIAL] is line 19 of the draft, its first key line 20.
    let at = |key: &str| {
        err(&format!(
            "{PLAIN}[PRIVATE CLOTHBAKE MATERIAL]
{key}
"
        ))
    };
    let e = at("Specular=1.5");
    assert_eq!(
        e.to_string(),
        "t.wif: [PRIVATE CLOTHBAKE MATERIAL] line 20: Specular=1.5 is outside [0, 1]; \
         give the specular coefficient rho_s between 0 and 1, e.g. 0.05"
    );
    for bad in ["Warp Specular=-0.1", "Specular=nan", "Specular="] {
        assert!(at(bad).problem.contains("is outside [0, 1]"), "{bad}");
    }
    for bad in ["Exponent=-1", "Weft Exponent=inf", "Exponent=ten"] {
        assert!(at(bad).problem.contains("is not a number >= 0"), "{bad}");
    }
    let e = at("Specularity=0.1");
    assert_eq!(e.line, Some(20));
    assert!(
        e.problem
            .contains("key `Specularity` is not one clothbake reads"),
        "{e}"
    );
    assert!(e.fix.contains("Warp Specular"), "{e}");
}

#[test]
fn contents_can_switch_a_section_off() {
    // A [LIFTPLAN] marked false in [CONTENTS] is ignored: the treadling is woven.
    let body = format!("[CONTENTS]\nLIFTPLAN=false\n{PLAIN}[LIFTPLAN]\n1=1,2\n2=1,2\n");
    let f = parse(&draft(&body), "t.wif", &WifOptions::default()).unwrap();
    assert_eq!(f.weave().to_rows(), vec![vec![1, 0], vec![0, 1]]);
    let body = format!("{PLAIN}[LIFTPLAN]\n1=1,2\n2=1,2\n");
    let f = parse(&draft(&body), "t.wif", &WifOptions::default()).unwrap();
    assert_eq!(f.weave().to_rows(), vec![vec![1]]);
}

#[test]
fn yarns_thicker_than_their_spacing_are_packed_and_noted() {
    // Warp: Thickness 1.2 cm at Spacing 1 cm: round yarns of radius 5 mm (half the spacing)
    // that touch, the draft's 6 mm noted; the weft fits and keeps its radius exactly.
    let body = PLAIN
        .replace(
            "[WARP]\nThreads=2",
            "[WARP]\nThreads=2\nSpacing=1\nThickness=1.2\nUnits=centimeters",
        )
        .replace(
            "[WEFT]\nThreads=2",
            "[WEFT]\nThreads=2\nSpacing=1\nThickness=0.9\nUnits=centimeters",
        );
    let f = parse(&draft(&body), "t.wif", &WifOptions::default()).unwrap();
    for y in &f.warp().threads {
        assert_eq!((y.radius, y.spacing, y.height), (5.0, 10.0, 0.0));
    }
    assert_eq!(f.weft().threads[0].radius, 0.5 * (0.9 * 10.0));
    assert_eq!(
        f.notes(),
        [
            "warp: Thickness 1.200 > Spacing 1.000 (centimeters); radius capped to 5.000 mm, \
          half the spacing (round yarns that touch), instead of 6.000 mm"
        ]
    );
    // The notes travel with the fabric's JSON (baked tables keep it).
    let back = Fabric::from_json_str(&f.to_json().to_string(), "t.json").unwrap();
    assert_eq!(back.notes(), f.notes());
    // A draft whose yarns fit has no note.
    let plain = parse(&draft(PLAIN), "t.wif", &WifOptions::default()).unwrap();
    assert!(plain.notes().is_empty() && plain.to_json().get("notes").is_none());
}

#[test]
fn packing_caps_only_the_threads_that_would_overlap() {
    use crate::yarn::{packed_radii, spacing_fits};
    // Threads 1 and 2 overlap (0.6 + 0.7 > 1.0); 3 fits both neighbours.
    let radii = [0.4, 0.6, 0.7, 0.3];
    let spacing = [1.1, 1.0, 1.2, 0.8];
    let (r, capped) = packed_radii(&radii, &spacing);
    assert_eq!(capped, 2);
    assert_eq!((r[0], r[3]), (0.4, 0.3));
    let f = 1.0 / 1.3;
    assert!((r[1] - 0.6 * f).abs() < 1e-15 && (r[2] - 0.7 * f).abs() < 1e-15);
    assert!((r[1] + r[2] - 1.0).abs() < 1e-15);
    for i in 0..4 {
        assert!(spacing_fits(spacing[i], r[i], r[(i + 1) % 4]), "{i}");
    }
    // A thread between two overlapping pairs takes the smaller factor.
    let (r, _) = packed_radii(&[1.0, 1.0, 0.5], &[1.5, 1.0, 2.0]);
    assert!((r[1] - 1.0 / 1.5).abs() < 1e-15, "{r:?}");
    assert!(r[0] + r[1] <= 1.5 * (1.0 + 1e-15) && r[1] + r[2] <= 1.0 * (1.0 + 1e-15));
}

#[test]
fn counts_and_numbers_are_bounded_before_anything_is_allocated() {
    // Threads of a billion, or more than usize holds: "too large", not "not a whole number".
    for n in ["1000000000", "99999999999999999999999"] {
        let e = err(&PLAIN.replace("[WARP]\nThreads=2", &format!("[WARP]\nThreads={n}")));
        assert_eq!((e.section.as_str(), e.line), ("WARP", Some(7)), "{e}");
        assert!(
            e.problem.contains(&format!(
                "Threads={n}: the number of warp ends is too large, at most 65536"
            )),
            "{e}"
        );
    }
    let e = err(&PLAIN.replace("Threads=2", "Threads=two"));
    assert!(e.problem.contains("is not a whole number"), "{e}");
    // A threading line numbered past the limit, with no Threads to bound it.
    let e = err(&PLAIN
        .replace("[WARP]\nThreads=2\n", "")
        .replace("[THREADING]\n1=1", "[THREADING]\n70000=1"));
    assert_eq!(e.section, "THREADING");
    assert!(
        e.problem
            .contains("the end number is too large, at most 65536"),
        "{e}"
    );
    let e = err(&PLAIN.replace("[TREADLING]\n1=1", "[TREADLING]\n1=123456789012345678901"));
    assert!(e.problem.contains("a treadle number is too large"), "{e}");
    // 5000 x 5000 ends and picks: refused before the drawdown is made.
    let mut body = String::from("[WARP]\nThreads=5000\n[WEFT]\nThreads=5000\n[THREADING]\n");
    for k in 1..=5000 {
        body += &format!("{k}={}\n", k % 8 + 1);
    }
    body += "[LIFTPLAN]\n";
    for k in 1..=5000 {
        body += &format!("{k}={}\n", k % 8 + 1);
    }
    let e = err(&body);
    assert!(
        e.problem
            .contains("5000 ends x 5000 picks = 25000000 cells, more than the 16777216"),
        "{e}"
    );
}

#[test]
fn a_repeat_beyond_the_period_limit_is_refused() {
    // 2048 ends on 2048 shafts, a straight draw, and 1024 picks lifting one shaft each: no
    // smaller repeat, 2^21 cells.
    let mut body = String::from("[WARP]\nThreads=2048\n[WEFT]\nThreads=1024\n[THREADING]\n");
    for e in 1..=2048 {
        body += &format!("{e}={e}\n");
    }
    body += "[LIFTPLAN]\n";
    for p in 1..=1024 {
        body += &format!("{p}={p}\n");
    }
    let e = err(&body);
    assert!(
        e.problem
            .contains("the draft's repeat is 2048 ends x 1024 picks")
            && e.problem.contains("2097152 cells, more than the 1048576"),
        "{e}"
    );
}

#[test]
fn quoted_text_is_clipped() {
    let long = "x".repeat(500);
    let e = err(&PLAIN.replace("[TREADLING]\n1=1", &format!("[TREADLING]\n1={long}")));
    assert!(
        e.problem.len() < 200 && !e.problem.contains(&"x".repeat(61)),
        "{e}"
    );
    assert!(e.problem.contains("..."), "{e}");
}

#[test]
fn the_drawdown_bits_are_the_weaving_rule() {
    // End i on shafts threading[i], pick j moving lift[j]: over where raised == rising.
    let threading = vec![vec![1], vec![2, 3], vec![4]];
    let lift = vec![vec![1, 4], vec![3], vec![], vec![2]];
    for rising in [true, false] {
        let dd = drawdown(&threading, &lift, rising);
        for (i, t) in threading.iter().enumerate() {
            for (j, l) in lift.iter().enumerate() {
                let raised = t.iter().any(|s| l.contains(s));
                assert_eq!(dd.over(i, j), raised == rising, "{i} {j}");
            }
        }
    }
}
