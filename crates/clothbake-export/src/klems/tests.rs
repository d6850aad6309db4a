//! The basis against its closed forms, the block conventions against Radiance's (restated
//! here from `bsdf_m.c`, not from the module), and a synthetic two-faced BSDF whose Klems
//! entries and datasheet figures have closed forms.

use super::*;
use clothbake_core::Rgb;

#[test]
fn the_rings_hold_145_patches_that_close_the_hemisphere() {
    assert_eq!(RINGS.iter().map(|r| r.n_phi).sum::<usize>(), PATCHES);
    assert_eq!(RINGS[0].lower, 0.0);
    assert_eq!(RINGS[8].upper, 90.0);
    for w in RINGS.windows(2) {
        assert_eq!(w[0].upper, w[1].lower);
    }
    // Numbered ring by ring: the first patch of ring r follows the previous rings' patches.
    let mut k = 0;
    for (r, ring) in RINGS.iter().enumerate() {
        for j in 0..ring.n_phi {
            let p = Patch::new(k);
            assert_eq!(p.ring, r);
            let d = 360.0 / ring.n_phi as f64;
            assert!((p.phi[0].to_degrees() - (j as f64 - 0.5) * d).abs() < 1e-9);
            k += 1;
        }
    }
}

#[test]
fn lambdas_sum_to_pi_and_solid_angles_to_two_pi() {
    let lambda: f64 = (0..PATCHES).map(|k| Patch::new(k).lambda()).sum();
    let omega: f64 = (0..PATCHES).map(|k| Patch::new(k).solid_angle()).sum();
    assert!((lambda - PI).abs() < 1e-12, "{lambda}");
    assert!((omega - 2.0 * PI).abs() < 1e-12, "{omega}");
    // Each closed form against a midpoint rule in theta (2000 steps a ring).
    for k in 0..PATCHES {
        let p = Patch::new(k);
        let n = 2000;
        let dt = (p.theta[1] - p.theta[0]) / n as f64;
        let (mut l, mut o) = (0.0, 0.0);
        for a in 0..n {
            let t = p.theta[0] + (a as f64 + 0.5) * dt;
            l += t.cos() * t.sin() * dt;
            o += t.sin() * dt;
        }
        let dp = p.phi[1] - p.phi[0];
        assert!((p.lambda() - l * dp).abs() < 1e-7 * p.lambda(), "{k}");
        assert!(
            (p.solid_angle() - o * dp).abs() < 1e-7 * p.solid_angle(),
            "{k}"
        );
    }
}

/// Whether the Klems angles (theta, phi) lie within patch `p`'s bounds (azimuth modulo 2 pi).
fn inside(p: &Patch, theta: f64, phi: f64) -> bool {
    let lo = p.phi[0];
    let a = (phi - lo).rem_euclid(2.0 * PI);
    theta >= p.theta[0] && theta <= p.theta[1] && a <= p.phi[1] - lo
}

#[test]
fn every_direction_falls_in_exactly_one_patch() {
    // A grid uniform in projected solid angle (sin^2 theta, phi): each direction is in the
    // patch `patch_of` names and in no other (off the boundaries), and each patch gets the
    // share Lambda / pi of the directions.
    let (ns, np) = (1000, 720);
    let mut count = vec![0usize; PATCHES];
    for a in 0..ns {
        let s = (a as f64 + 0.5) / ns as f64;
        let theta = s.sqrt().asin();
        for b in 0..np {
            let phi = (b as f64 + 0.37) / np as f64 * 2.0 * PI;
            let k = patch_of(theta, phi);
            count[k] += 1;
            assert!(inside(&Patch::new(k), theta, phi), "{theta} {phi} -> {k}");
            let holders = (0..PATCHES)
                .filter(|&j| inside(&Patch::new(j), theta, phi))
                .count();
            assert_eq!(holders, 1, "{theta} {phi}");
        }
    }
    for (k, &c) in count.iter().enumerate() {
        let share = c as f64 / (ns * np) as f64;
        let p = Patch::new(k);
        let want = p.lambda() / PI;
        // The grid resolves a patch's share to a row of s in its ring and a column of phi.
        let tol = (1.0 / ns as f64 + 1.0 / np as f64) / RINGS[p.ring].n_phi as f64;
        assert!((share - want).abs() < tol, "{k}: {share} vs {want}");
    }
    // Boundaries as Radiance's fo_getndx: rings closed below; the horizon in the last ring.
    assert_eq!(patch_of(5f64.to_radians(), 0.0), 1);
    assert_eq!(patch_of(4.999f64.to_radians(), 1.0), 0);
    assert_eq!(patch_of(FRAC_PI_2, 0.0), PATCHES - 12);
    assert_eq!(patch_of(10f64.to_radians(), 22.6f64.to_radians()), 2);
    assert_eq!(patch_of(10f64.to_radians(), -22.4f64.to_radians()), 1);
    assert_eq!(patch_of(10f64.to_radians(), -22.6f64.to_radians()), 8);
}

use std::f64::consts::FRAC_PI_2;

/// Radiance's direction of a Klems angle pair for each role (`bsdf_m.c`: front exiting
/// `fo` = (cos phi sin theta, sin phi sin theta, cos theta); front incident `fi` negates x and
/// y, back incident `bi` all three, back exiting `bo` z; vectors point away from the surface),
/// the block's roles as Radiance loads WINDOW's names ("front and back are reversed":
/// Transmission Front -> incident bi, exiting fo; Reflection Front -> bi, bo; Transmission
/// Back -> fi, bo; Reflection Back -> fi, fo), and Radiance's BSDF frame in clothbake's: a
/// half turn about the warp, (x, y, z) -> (-x, y, -z).
fn radiance(b: Block, theta: f64, phi: f64) -> (Vec3, Vec3) {
    let fo = Vec3::new(
        phi.cos() * theta.sin(),
        phi.sin() * theta.sin(),
        theta.cos(),
    );
    let fi = Vec3::new(-fo.x, -fo.y, fo.z);
    let bi = Vec3::new(-fo.x, -fo.y, -fo.z);
    let bo = Vec3::new(fo.x, fo.y, -fo.z);
    let (i, o) = match b {
        Block::FrontTransmission => (bi, fo),
        Block::FrontReflection => (bi, bo),
        Block::BackTransmission => (fi, bo),
        Block::BackReflection => (fi, fo),
    };
    let to_cloth = |v: Vec3| Vec3::new(-v.x, v.y, -v.z);
    (to_cloth(i), to_cloth(o))
}

#[test]
fn block_directions_follow_radiance_and_straight_through_is_the_diagonal() {
    for b in Block::ALL {
        for k in 0..PATCHES {
            let p = Patch::new(k);
            for (theta, phi) in p.points(3) {
                let (ri, ro) = radiance(b, theta, phi);
                let (wi, wo) = (b.incident(theta, phi), b.outgoing(theta, phi));
                assert!((wi.get() - ri).length() < 1e-12, "{b:?} {k}");
                assert!((wo.get() - ro).length() < 1e-12, "{b:?} {k}");
                assert_eq!(b.incident_patch(wi), Some(k), "{b:?}");
                assert_eq!(b.outgoing_patch(wo), Some(k), "{b:?}");
                assert_eq!(b.incident_patch(wi.reverse()), None);
                if b.transmits() {
                    // Light passing straight through leaves in the patch it came in.
                    assert_eq!(b.outgoing_patch(wi.reverse()), Some(k), "{b:?}");
                } else {
                    // Mirror reflection, too, stays on the diagonal (the Klems convention).
                    let m = crate::reflect(
                        wi,
                        if b.from_front() {
                            UnitVec3::Z
                        } else {
                            UnitVec3::Z.reverse()
                        },
                    );
                    assert_eq!(b.outgoing_patch(m.unwrap()), Some(k), "{b:?}");
                }
            }
        }
    }
}

/// A two-faced test cloth: Lambertian-like reflection of albedo `a` on the front and `b` on
/// the back, transmission `t`, each times (1 + kappa x_i x_o) (reciprocal, anisotropic,
/// hemispherically neutral), and openness O0 cos^2(theta) from either side.
struct Sheer {
    a: Rgb,
    b: Rgb,
    t: Rgb,
    kappa: f64,
    open: f64,
}

impl Bsdf for Sheer {
    fn f(&self, wi: UnitVec3, wo: UnitVec3) -> Rgb {
        let rho = match (
            wi.above_horizon(),
            wi.below_horizon(),
            wo.above_horizon(),
            wo.below_horizon(),
        ) {
            (true, _, true, _) => self.a,
            (_, true, _, true) => self.b,
            (true, _, _, true) | (_, true, true, _) => self.t,
            _ => return [0.0; 3],
        };
        let g = 1.0 + self.kappa * wi.x * wo.x;
        rho.map(|r| r / PI * g)
    }
    fn openness(&self, wi: UnitVec3) -> f64 {
        if wi.above_horizon() || wi.below_horizon() {
            self.open * wi.z * wi.z
        } else {
            0.0
        }
    }
}

const A: Rgb = [0.5, 0.4, 0.3];
const B: Rgb = [0.2, 0.25, 0.3];
const T: Rgb = [0.1, 0.15, 0.05];

fn sheer(kappa: f64) -> Sheer {
    Sheer {
        a: A,
        b: B,
        t: T,
        kappa,
        open: 0.12,
    }
}

/// The patch mean of O0 cos^2 theta weighted by cos theta: linear in s = sin^2 theta, so
/// O0 (1 - (s0 + s1) / 2).
fn mean_openness(k: usize, o0: f64) -> f64 {
    let p = Patch::new(k);
    let s = |t: f64| t.sin() * t.sin();
    o0 * (1.0 - 0.5 * (s(p.theta[0]) + s(p.theta[1])))
}

fn close(x: f64, y: f64, tol: f64) -> bool {
    (x - y).abs() <= tol * (1.0 + y.abs())
}

#[test]
fn isotropic_entries_equal_their_closed_forms() {
    let k = evaluate(&sheer(0.0), 2);
    for b in Block::ALL {
        let rho = match b {
            Block::FrontReflection => A,
            Block::BackReflection => B,
            _ => T,
        };
        let m = k.block(b);
        for o in 0..PATCHES {
            for i in 0..PATCHES {
                let d = if b.transmits() && i == o {
                    mean_openness(i, 0.12) / Patch::new(i).lambda()
                } else {
                    0.0
                };
                for (got, r) in m.get(o, i).into_iter().zip(rho) {
                    assert!(close(got, r / PI + d, 1e-12), "{b:?} {o} {i}");
                }
            }
        }
    }
}

#[test]
fn hemispherical_sums_and_reciprocity_hold_for_an_anisotropic_cloth() {
    let s = sheer(0.8);
    let k = evaluate(&s, 3);
    // The half turn of a patch: rings have an even number of patches (or one).
    let half = |p: usize| {
        let q = Patch::new(p);
        let n = RINGS[q.ring].n_phi;
        let first: usize = RINGS[..q.ring].iter().map(|r| r.n_phi).sum();
        first + (p - first + n / 2) % n
    };
    for i in 0..PATCHES {
        // The anisotropic term integrates to zero over the outgoing hemisphere.
        let h = k.block(Block::FrontReflection).hemispherical(i);
        let t = k.block(Block::FrontTransmission).hemispherical(i);
        let hb = k.block(Block::BackReflection).hemispherical(i);
        let o = mean_openness(i, 0.12);
        for c in 0..3 {
            assert!(close(h[c], A[c], 1e-12), "{i}: {h:?}");
            assert!(close(hb[c], B[c], 1e-12), "{i}: {hb:?}");
            assert!(close(t[c], T[c] + o, 1e-12), "{i}: {t:?}");
        }
        // Reciprocity: f(wi, wo) = f(wo, wi). Swapping the roles maps outgoing patch o to
        // incident patch half(o), within a block for reflection and between the two
        // transmission blocks.
        for o in 0..PATCHES {
            let pairs = [
                (Block::FrontReflection, Block::FrontReflection),
                (Block::BackReflection, Block::BackReflection),
                (Block::FrontTransmission, Block::BackTransmission),
            ];
            for (p, q) in pairs {
                let x = k.block(p).get(o, i);
                let y = k.block(q).get(half(i), half(o));
                for c in 0..3 {
                    assert!(close(x[c], y[c], 1e-12), "{p:?} {o} {i}: {x:?} {y:?}");
                }
            }
        }
    }
    // Not trivially symmetric: the anisotropic term moves entries away from rho / pi.
    let m = k.block(Block::FrontReflection);
    let spread = (0..PATCHES * PATCHES)
        .map(|n| (m.values[n][0] - A[0] / PI).abs())
        .fold(0.0, f64::max);
    assert!(spread > 0.05 * A[0] / PI, "{spread}");
}

#[test]
fn the_datasheet_equals_its_closed_forms() {
    let d = Datasheet::of(&sheer(0.8));
    let y = crate::luminance;
    let mean = |c: Rgb| (c[0] + c[1] + c[2]) / 3.0;
    let want = [
        (d.openness, 0.12),
        (d.visible_transmittance, 0.12 + y(T)),
        (d.solar_transmittance, 0.12 + mean(T)),
        (d.visible_reflectance_front, y(A)),
        (d.visible_reflectance_back, y(B)),
        (d.solar_reflectance_front, mean(A)),
        (d.solar_reflectance_back, mean(B)),
    ];
    for (k, (got, w)) in want.into_iter().enumerate() {
        assert!(close(got, w, 1e-12), "{k}: {got} vs {w}");
    }
    assert!(
        d.summary().contains("openness factor 12.00%"),
        "{}",
        d.summary()
    );
}

#[test]
fn a_one_faced_reflector_has_no_transmission_and_no_back() {
    let s = Sheer {
        a: A,
        b: [0.0; 3],
        t: [0.0; 3],
        kappa: 0.3,
        open: 0.0,
    };
    let k = evaluate(&s, 1);
    for b in [
        Block::FrontTransmission,
        Block::BackTransmission,
        Block::BackReflection,
    ] {
        assert!(k.block(b).values.iter().all(|v| *v == [0.0; 3]), "{b:?}");
    }
    let d = Datasheet::of(&s);
    assert_eq!((d.openness, d.visible_transmittance), (0.0, 0.0));
}

#[test]
fn the_xml_holds_the_basis_and_eight_matrices_in_row_order() {
    let k = evaluate(&sheer(0.8), 1);
    let mut bytes = Vec::new();
    let n = write_xml(
        &mut bytes,
        &k,
        &Description {
            name: "sheer <&>".into(),
            comment: "a --- test -".into(),
        },
    )
    .unwrap();
    assert_eq!(n, bytes.len() as u64);
    let text = String::from_utf8(bytes).unwrap();
    assert!(text.contains("<Name>sheer &lt;&amp;&gt;</Name>"));
    let comment = text
        .split("<!--")
        .nth(1)
        .unwrap()
        .split("-->")
        .next()
        .unwrap();
    assert!(
        !comment.contains("--") && comment.contains("test"),
        "{comment}"
    );
    assert!(text.contains("<IncidentDataStructure>Columns</IncidentDataStructure>"));
    assert_eq!(text.matches("<AngleBasisBlock>").count(), 9);
    assert!(text.contains("<Theta>82.5</Theta>\n\t\t\t\t<nPhis>12</nPhis>"));
    let blocks: Vec<&str> = text.split("<ScatteringData>\n").skip(1).collect();
    assert_eq!(blocks.len(), 8);
    for (n, blk) in blocks.iter().enumerate() {
        let band = if n < 4 { Band::Visible } else { Band::Solar };
        let b = Block::ALL[n % 4];
        let head = text.split("<ScatteringData>\n").nth(n).unwrap();
        assert!(head.ends_with(&format!(
            "<WavelengthDataDirection>{}</WavelengthDataDirection>\n\t\t\t<ColumnAngleBasis>LBNL/Klems Full</ColumnAngleBasis>\n\t\t\t<RowAngleBasis>LBNL/Klems Full</RowAngleBasis>\n\t\t\t<ScatteringDataType>{}</ScatteringDataType>\n\t\t\t",
            b.direction_name(),
            b.data_type()
        )));
        let data = blk.split("\t\t\t</ScatteringData>").next().unwrap();
        let rows: Vec<&str> = data.lines().collect();
        assert_eq!(rows.len(), PATCHES);
        for (o, row) in rows.iter().enumerate() {
            let vals: Vec<f64> = row.split(", ").map(|v| v.parse().unwrap()).collect();
            assert_eq!(vals.len(), PATCHES);
            for (i, v) in vals.into_iter().enumerate() {
                let want = band.of(k.block(b).get(o, i));
                assert!(close(v, want, 1e-6), "{n} {o} {i}");
            }
        }
    }
}

#[test]
fn a_value_that_is_not_finite_is_refused_with_its_place() {
    let mut k = evaluate(&sheer(0.0), 1);
    k.blocks[2].values[3 * PATCHES + 7] = [f64::NAN; 3];
    let e = write_xml(&mut Vec::new(), &k, &Description::default()).unwrap_err();
    assert_eq!(e.kind(), io::ErrorKind::InvalidData);
    let m = e.to_string();
    assert!(
        m.contains("Transmission Back") && m.contains("outgoing patch 3, incident patch 7"),
        "{m}"
    );
}
