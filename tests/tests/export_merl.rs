//! The MERL binary read back by an independent reader: the published MERL lookup (half and
//! difference angles by two rotations, truncating index maps, the square-root theta_h map, the
//! three channel scales), written here from the format's description, not from the writer.
//!
//! * The analytic model: for a few (light, eye) pairs, the value the reader finds equals the
//!   model's average over rotations about the normal (and over swapping light and eye) at the
//!   centre of the cell the reader picked, computed here with our own rotations.
//! * A Lambertian BRDF rho/pi: every cell with both directions above the horizon reads rho/pi
//!   in all three channels, and nothing is reported as anisotropy.

use clothbake_core::{AnalyticBsdf, Bsdf, FromFn};
use clothbake_core::{AnalyticModel, Fabric, FacetModel, UnitVec3, Vec3};
use clothbake_export::merl::{merl_bytes, merl_table};
use std::f64::consts::PI;
use std::path::Path;

/// A MERL file as the reference reader sees it.
struct Merl {
    data: Vec<f64>,
}

impl Merl {
    fn parse(bytes: &[u8]) -> Merl {
        let dims: Vec<i32> = (0..3)
            .map(|k| i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap()))
            .collect();
        assert_eq!(dims, [90, 90, 180]);
        let n = 90 * 90 * 180;
        assert_eq!(bytes.len(), 12 + 3 * n * 8);
        let data = bytes[12..]
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        Merl { data }
    }

    /// The published lookup: cell indices of (light, eye), then value times the channel scales.
    fn lookup(&self, light: Vec3, eye: Vec3) -> ((usize, usize, usize), [f64; 3]) {
        let (ih, id, ip) = Merl::cell(light, eye);
        let i = ip + 180 * (id + 90 * ih);
        let n = 90 * 90 * 180;
        let scale = [1.0 / 1500.0, 1.15 / 1500.0, 1.66 / 1500.0];
        (
            (ih, id, ip),
            std::array::from_fn(|c| self.data[c * n + i] * scale[c]),
        )
    }

    /// The cell (theta_h, theta_d, phi_d indices) of a (light, eye) pair.
    fn cell(light: Vec3, eye: Vec3) -> (usize, usize, usize) {
        let h = normalize(light + eye);
        let (th, ph) = (h.z.clamp(-1.0, 1.0).acos(), h.y.atan2(h.x));
        // diff = light rotated by -phi_h about the normal, then by -theta_h about the binormal.
        let d = rotate_z(light, -ph);
        let d = rotate_y(d, -th);
        let (td, mut pd) = (d.z.clamp(-1.0, 1.0).acos(), d.y.atan2(d.x));
        let ih = if th <= 0.0 {
            0
        } else {
            ((th / (PI / 2.0) * 90.0 * 90.0).sqrt() as usize).min(89)
        };
        let id = ((td / (PI / 2.0) * 90.0) as usize).min(89);
        if pd < 0.0 {
            pd += PI;
        }
        let ip = ((pd / PI * 180.0) as usize).min(179);
        (ih, id, ip)
    }
}

fn normalize(v: Vec3) -> Vec3 {
    v * (1.0 / v.length())
}

fn rotate_z(v: Vec3, a: f64) -> Vec3 {
    let (s, c) = a.sin_cos();
    Vec3::new(c * v.x - s * v.y, s * v.x + c * v.y, v.z)
}

fn rotate_y(v: Vec3, a: f64) -> Vec3 {
    let (s, c) = a.sin_cos();
    Vec3::new(c * v.x + s * v.z, v.y, -s * v.x + c * v.z)
}

/// The (light, eye) pair at the centre of cell (ih, id, ip), half vector in the xz plane.
fn cell_centre_pair(ih: usize, id: usize, ip: usize) -> (Vec3, Vec3) {
    let th = ((ih as f64 + 0.5) / 90.0).powi(2) * PI / 2.0;
    let td = (id as f64 + 0.5) / 90.0 * PI / 2.0;
    let pd = (ip as f64 + 0.5) / 180.0 * PI;
    let d = Vec3::new(td.sin() * pd.cos(), td.sin() * pd.sin(), td.cos());
    let light = rotate_y(d, th);
    let h = Vec3::new(th.sin(), 0.0, th.cos());
    let eye = h * (2.0 * light.dot(h)) - light;
    (light, eye)
}

fn unit(v: Vec3) -> UnitVec3 {
    UnitVec3::new(v).unwrap()
}

#[test]
fn the_merl_reader_finds_the_models_rotation_average() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables/twill.json");
    let f = Fabric::from_path(&path).unwrap();
    let model = AnalyticModel::new(&f, FacetModel::Huo);
    let pairs = [
        (30.0, 0.0, 45.0, 180.0),
        (40.0, 90.0, 30.0, 250.0),
        (10.0, 20.0, 60.0, 200.0),
        (55.0, 300.0, 50.0, 140.0),
        (20.0, 45.0, 25.0, 60.0),
    ];
    // The whole table from the model takes half a minute on two cores: the model is evaluated
    // only on the theta_h rows of the checked pairs (found from the directions, by the reader's
    // own index map), and gives 0 elsewhere.
    let rows: Vec<usize> = pairs
        .iter()
        .map(|&(tl, pl, te, pe)| {
            Merl::cell(
                UnitVec3::from_degrees(tl, pl).get(),
                UnitVec3::from_degrees(te, pe).get(),
            )
            .0
        })
        .collect();
    let full = AnalyticBsdf::new(model.clone(), None);
    let brdf = FromFn(|a: UnitVec3, b: UnitVec3| {
        if rows.contains(&Merl::cell(a.get(), b.get()).0) {
            full.f(a, b)
        } else {
            [0.0; 3]
        }
    });
    // Four rotations (0, 90, 180, 270 degrees); the twill is unchanged by a half turn.
    let rotations = 4;
    let table = merl_table(&brdf, rotations, true);
    let merl = Merl::parse(&merl_bytes(&table));
    let mut checked = 0;
    for (tl, pl, te, pe) in pairs {
        let light = UnitVec3::from_degrees(tl, pl).get();
        let eye = UnitVec3::from_degrees(te, pe).get();
        let ((ih, id, ip), got) = merl.lookup(light, eye);
        let (a, b) = cell_centre_pair(ih, id, ip);
        let mut want = [0.0; 3];
        for s in 0..rotations {
            let r = 2.0 * PI * s as f64 / rotations as f64;
            let (a, b) = (unit(rotate_z(a, r)), unit(rotate_z(b, r)));
            let (x, y) = (full.f(a, b), full.f(b, a));
            for c in 0..3 {
                want[c] += 0.5 * (x[c] + y[c]) / rotations as f64;
            }
        }
        for c in 0..3 {
            assert!(want[c] > 0.0);
            assert!(
                (got[c] - want[c]).abs() <= 1e-9 * want[c],
                "light {tl},{pl} eye {te},{pe} cell ({ih},{id},{ip}) channel {c}: file {} \
                 model {}",
                got[c],
                want[c]
            );
        }
        checked += 1;
    }
    assert_eq!(checked, 5);
    // The twill is anisotropic: averaging loses a measurable spread.
    assert!(table.anisotropy.weighted > 0.01, "{:?}", table.anisotropy);
}

#[test]
fn a_lambertian_brdf_gives_a_constant_table() {
    let rho = [0.5, 0.3, 0.8];
    let brdf = FromFn(|wi: UnitVec3, wo: UnitVec3| {
        if wi.above_horizon() && wo.above_horizon() {
            rho.map(|r| r / PI)
        } else {
            [0.0; 3]
        }
    });
    let table = merl_table(&brdf, 3, false);
    let merl = Merl::parse(&merl_bytes(&table));
    assert_eq!(table.anisotropy.weighted, 0.0);
    let mut lit = 0;
    for ih in 0..90 {
        for id in 0..90 {
            for ip in (0..180).step_by(7) {
                let (a, b) = cell_centre_pair(ih, id, ip);
                if a.z <= 1e-9 || b.z <= 1e-9 {
                    continue;
                }
                // Look the cell up through a rotated copy of its centre: the table is isotropic.
                let (a, b) = (rotate_z(a, 1.0 + ih as f64), rotate_z(b, 1.0 + ih as f64));
                let (cell, v) = merl.lookup(a, b);
                assert_eq!(cell, (ih, id, ip));
                for c in 0..3 {
                    assert!((v[c] - rho[c] / PI).abs() < 1e-12, "{cell:?} {v:?}");
                }
                lit += 1;
            }
        }
    }
    assert!(lit > 50_000, "{lit}");
}
