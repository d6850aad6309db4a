//! The Radiance round trip of the daylighting export (docs/guide/daylighting.md): Radiance (the
//! binaries and BSDF library the `pyradiance` package ships) reads the Klems XML that
//! `clothbake_export::klems` writes for a two-faced test cloth (transmission, a straight-through
//! delta lobe, different faces, anisotropic), and
//!
//! * lights a closed room with black walls through a window filled with it under a uniform sky:
//!   the irradiance at sensors in the room within 2% of clothbake's own integral of the same
//!   `Bsdf` over the window and the sky (computed here from `f` and `openness`, not from the
//!   file);
//! * looks the BSDF up (Radiance's `SDevalBSDF`) at directions given in Radiance's frame: each
//!   value is the Klems entry of the patches clothbake's frame convention maps them to, so
//!   front and back, rows and columns, and the azimuths are where Radiance expects them.
//!
//! Ignored, with the reason, when `python3` cannot import pyradiance (the build script probes
//! it); under `CI` it runs and fails without it (`cargo xtask test` installs it).

use clothbake_core::{Bsdf, Rgb, UnitVec3, Vec3};
use clothbake_export::klems::{self, Block, Description, Patch};
use clothbake_tests::fixtures::{self, succeeded, temp_dir};
use clothbake_tests::probe::PYRADIANCE;
use std::f64::consts::PI;
use std::path::Path;

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/python/radiance_room.py");

/// A two-faced test cloth, grey: reflection `a` (front) and `b` (back), diffuse transmission
/// `t`, each times 1 + kappa x_i x_o + lambda (x_i + x_o) (reciprocal, not symmetric under a
/// half turn about the normal nor under swapping the roles of the patches, positive), and the
/// openness O0 |cos theta| through the gaps.
struct Shade {
    a: f64,
    b: f64,
    t: f64,
    kappa: f64,
    lambda: f64,
    open: f64,
}

const SHADE: Shade = Shade {
    a: 0.45,
    b: 0.25,
    t: 0.12,
    kappa: 0.3,
    lambda: 0.3,
    open: 0.15,
};

impl Bsdf for Shade {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        let (i_up, i_down) = (wi.above_horizon(), wi.below_horizon());
        let (o_up, o_down) = (wo.above_horizon(), wo.below_horizon());
        let rho = if i_up && o_up {
            self.a
        } else if i_down && o_down {
            self.b
        } else if (i_up && o_down) || (i_down && o_up) {
            self.t
        } else {
            0.0
        };
        [rho / PI * (1.0 + self.kappa * wi.x * wo.x + self.lambda * (wi.x + wo.x)); 3]
    }
    fn openness(&self, wi: UnitVec3) -> f64 {
        self.open * wi.z.abs()
    }
}

/// The shade exported as a Klems XML file into `dir`.
fn export(dir: &Path) -> (std::path::PathBuf, klems::Klems) {
    let k = klems::evaluate(&SHADE, 4);
    let path = dir.join("shade.xml");
    clothbake_loader::write_atomic_as(&path, "test file", true, |w| {
        klems::write_xml(
            w,
            &k,
            &Description {
                name: "test shade".into(),
                comment: "clothbake test: a two-faced grey shade".into(),
            },
        )
        .map(|_| ())
    })
    .unwrap();
    (path, k)
}

/// Room coordinates (Radiance's scene: x across the window, y into the room, z up) to
/// clothbake's frame on the window: the cloth's front (+Z) faces outside (-y), its warp (+Y)
/// is up (+z): (x, y, z) -> (x, z, -y).
fn to_cloth(v: Vec3) -> UnitVec3 {
    UnitVec3::new(Vec3::new(v.x, v.z, -v.y)).unwrap()
}

/// Radiance that the window sends into the room along `wo` (room frame, toward the eye),
/// per unit sky radiance: int over the outside of f(wi, wo) cos(theta_i) dw_i (a midpoint rule
/// in sin^2 theta and phi, points of equal projected solid angle) plus the openness of the
/// light from -wo.
fn transmitted(wo: Vec3) -> f64 {
    let wo = to_cloth(wo);
    let (ns, np) = (24, 48);
    let mut s = 0.0;
    for a in 0..ns {
        let s2 = (a as f64 + 0.5) / ns as f64;
        let (st, ct) = (s2.sqrt(), (1.0 - s2).sqrt());
        for b in 0..np {
            let phi = (b as f64 + 0.5) / np as f64 * 2.0 * PI;
            let wi = UnitVec3::new(Vec3::new(st * phi.cos(), st * phi.sin(), ct)).unwrap();
            s += SHADE.f(wi, wo)[1];
        }
    }
    s * PI / (ns * np) as f64 + SHADE.openness(wo.reverse())
}

/// The room of radiance_room.py: the window is the wall y = 0, 4 m wide (x), 3 m high (z).
const WINDOW: [f64; 2] = [4.0, 3.0];

/// Irradiance at `p` on a surface of normal `n` (room frame) from the window alone (the other
/// walls are black): int over the window of L(wo) cos(theta_sensor) cos(theta_window) / r^2
/// dA, a midpoint rule of 120 x 90 points.
fn irradiance(p: Vec3, n: Vec3) -> f64 {
    let (nx, nz) = (120, 90);
    let da = WINDOW[0] * WINDOW[1] / (nx * nz) as f64;
    let mut e = 0.0;
    for i in 0..nx {
        for j in 0..nz {
            let q = Vec3::new(
                (i as f64 + 0.5) / nx as f64 * WINDOW[0],
                0.0,
                (j as f64 + 0.5) / nz as f64 * WINDOW[1],
            );
            let v = q - p;
            let r = v.length();
            let u = v * (1.0 / r);
            let cs = n.dot(u);
            if cs <= 0.0 {
                continue;
            }
            e += transmitted(u * -1.0) * cs * u.y.abs() / (r * r) * da;
        }
    }
    e
}

#[test]
#[cfg_attr(
    missing_pyradiance,
    ignore = "needs the pyradiance Python package (pip install pyradiance; cargo xtask test installs it)"
)]
fn radiance_lights_a_room_through_the_exported_shade_as_clothbake_integrates_it() {
    PYRADIANCE.require();
    let dir = temp_dir("daylighting-room");
    let (xml, _) = export(&dir);
    // Sensors: facing the window 1 m behind its centre; on the workplane (0.8 m, facing up) at
    // 1 m and at 2.5 m into the room; facing the window 3 m in and off to the side.
    let sensors: [[f64; 6]; 4] = [
        [2.0, 1.0, 1.5, 0.0, -1.0, 0.0],
        [2.0, 1.0, 0.8, 0.0, 0.0, 1.0],
        [2.0, 2.5, 0.8, 0.0, 0.0, 1.0],
        [1.0, 3.0, 1.2, 0.0, -1.0, 0.0],
    ];
    let json = serde_json::to_string(&sensors).unwrap();
    let out = succeeded(
        "radiance_room.py room",
        &fixtures::python(
            SCRIPT,
            &[
                "room",
                xml.to_str().unwrap(),
                dir.join("room").to_str().unwrap(),
                &json,
            ],
        ),
    );
    let got: serde_json::Value = serde_json::from_str(&out).unwrap();
    let mut worst: f64 = 0.0;
    for (k, s) in sensors.iter().enumerate() {
        let radiance = got["irradiance"][k].as_f64().unwrap();
        let spread = got["spread"][k].as_f64().unwrap();
        let ours = irradiance(Vec3::new(s[0], s[1], s[2]), Vec3::new(s[3], s[4], s[5]));
        let rel = (radiance - ours) / ours;
        eprintln!(
            "sensor {k} {s:?}: Radiance {radiance:.5} (+-{:.2}%), clothbake {ours:.5}, {:+.2}%",
            100.0 * spread,
            100.0 * rel
        );
        assert!(ours > 0.01, "{ours}");
        worst = worst.max(rel.abs());
    }
    eprintln!("{}; worst {:.2}%", got["radiance"], 100.0 * worst);
    assert!(
        worst < 0.02,
        "Radiance and clothbake differ by {:.2}%",
        100.0 * worst
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// The vector of clothbake's direction `w` in Radiance's BSDF frame (z the surface normal into
/// the room, y the up vector: clothbake's -z and +y), as (theta, phi) in degrees.
fn radiance_angles(w: UnitVec3) -> [f64; 2] {
    let v = Vec3::new(-w.x, w.y, -w.z);
    [
        v.z.clamp(-1.0, 1.0).acos().to_degrees(),
        v.y.atan2(v.x).to_degrees(),
    ]
}

#[test]
#[cfg_attr(
    missing_pyradiance,
    ignore = "needs the pyradiance Python package (pip install pyradiance; cargo xtask test installs it)"
)]
fn radiance_looks_up_each_block_where_clothbake_put_it() {
    PYRADIANCE.require();
    let dir = temp_dir("daylighting-query");
    let (xml, k) = export(&dir);
    // Patch centres of a spread of pairs in every block.
    let mut queries = Vec::new();
    let mut want = Vec::new();
    for b in Block::ALL {
        for (o, i) in [
            (0, 0),
            (3, 17),
            (17, 3),
            (40, 40),
            (60, 100),
            (130, 9),
            (144, 77),
        ] {
            let centre = |p: usize| {
                let q = Patch::new(p);
                let t = if p == 0 {
                    0.0
                } else {
                    0.5 * (q.theta[0] + q.theta[1])
                };
                (t, 0.5 * (q.phi[0] + q.phi[1]))
            };
            let (ti, pi) = centre(i);
            let (to, po) = centre(o);
            let wi = b.incident(ti, pi);
            let wo = b.outgoing(to, po);
            let [a, c] = radiance_angles(wo);
            let [d, e] = radiance_angles(wi);
            queries.push([a, c, d, e]);
            want.push(klems::Band::Visible.of(k.block(b).get(o, i)));
        }
    }
    let out = succeeded(
        "radiance_room.py query",
        &fixtures::python(
            SCRIPT,
            &[
                "query",
                xml.to_str().unwrap(),
                &serde_json::to_string(&queries).unwrap(),
            ],
        ),
    );
    let got: Vec<f64> = serde_json::from_str(&out).unwrap();
    assert_eq!(got.len(), want.len());
    for (n, (g, w)) in got.iter().zip(&want).enumerate() {
        let b = Block::ALL[n / 7];
        assert!(
            (g - w).abs() <= 1e-3 * w.abs() + 1e-6,
            "{b:?} query {n} {:?}: Radiance {g}, clothbake's entry {w}",
            queries[n]
        );
    }
    // The entries differ enough that a swapped row and column, or front and back, would not
    // pass: (3, 17) against (17, 3) in each block, front against back reflection.
    for b in 0..4 {
        let (x, y) = (want[7 * b + 1], want[7 * b + 2]);
        assert!((x - y).abs() > 0.05 * x, "{:?}: {x} {y}", Block::ALL[b]);
    }
    let (fr, br) = (want[7 + 3], want[7 * 3 + 3]);
    assert!((fr - br).abs() > 0.2 * fr, "{fr} {br}");
    assert_eq!(Block::ALL[1], Block::FrontReflection);
    assert_eq!(Block::ALL[3], Block::BackReflection);
    assert_eq!(want.len(), 4 * 7);
    // Radiance's checkBSDF swaps incident and outgoing vectors through its own reading of the
    // file: the test cloth is reciprocal (and anisotropic), so with the conventions right each
    // component's reciprocity error is nil; it names the front "Exterior".
    let report = succeeded(
        "radiance_room.py check",
        &fixtures::python(SCRIPT, &["check", xml.to_str().unwrap()]),
    );
    eprintln!("{report}");
    let errors = report.split("Reciprocity Error").nth(1).unwrap();
    let mut rows = 0;
    for line in errors.lines().skip(1).filter(|l| !l.trim().is_empty()) {
        let cols: Vec<&str> = line.split('\t').collect();
        let worst: f64 = cols.last().unwrap().trim().parse().unwrap();
        assert!(worst < 0.5, "checkBSDF: {line}\n{report}");
        rows += 1;
    }
    assert_eq!(rows, 3, "{report}");
    let exterior = report
        .lines()
        .find(|l| l.starts_with("Exterior Refl"))
        .unwrap();
    let lambertian: f64 = exterior.split_whitespace().nth(2).unwrap().parse().unwrap();
    // Radiance's Lambertian part of a matrix is its smallest entry times pi: of the front
    // reflection 0.45 (1 - 0.3 X_i X_o + 0.3 (X_i + X_o)) at its smallest, well above the back's
    // 0.25 times the same factor.
    let interior = report
        .lines()
        .find(|l| l.starts_with("Interior Refl"))
        .unwrap();
    let back: f64 = interior.split_whitespace().nth(2).unwrap().parse().unwrap();
    assert!((lambertian / back - 0.45 / 0.25).abs() < 0.01, "{report}");
    std::fs::remove_dir_all(&dir).ok();
}
