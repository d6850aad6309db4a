//! `cargo xtask ch5`: the comparisons of thesis sec. 5.4, printed and written to
//! `docs/results/interreflection.md`.
//!
//! Assumptions the text leaves open (also in docs/science/interreflection.md):
//! * sphere: radius 1 at the origin, 48 x 48 pixels of a pinhole camera at the eye looking at the
//!   origin; the cylinders follow the sphere's longitudes (local warp axis = the tangent toward
//!   the north pole +z); surface points where L or E is below the local horizon are skipped;
//! * disk: on z = 0, sampled on a 41 x 41 grid over its bounding square, light 75 degrees above
//!   the plane, either with the sphere test's azimuth, L = (0, -cos 75, sin 75), on a disk of
//!   radius 5, or beyond the disk from the eye, L = (0, cos 75, sin 75), on disks of radius 5
//!   and 10; the cylinders along +y (reading A, parallel to the light's azimuth) and, in tables
//!   of their own, along +x (reading B: light and eye in the cylinders' cross-section plane);
//! * eye at (0, -10, 10) for both, so E varies over the surface (perspective);
//! * "ray-traced solution" = the two-level sampling with the thesis's steps (first level 32,
//!   d_alpha = d_l = 0.2, l0 = 1.5); "analytical" = the thesis's ranges (C_max 0.3, l0 1.5)
//!   for the reproduction, and the full ranges for the corrected numbers.

use clothbake_core::interreflection::{Orders, Ranges, Sampling};
use clothbake_core::{
    AnalyticModel, Fabric, FacetModel, Kernel, SecondaryMethod, SecondaryOptions, UnitVec3, Vec3,
};
use clothbake_truth::pathtracer::PathOptions;
use clothbake_truth::RayTracer;
use std::fmt::Write as _;

/// The parallel-cylinder surface of thesis sec. 5.4 (r 1, d 2, rho_d 0.4) with specular
/// `rho_s` and exponent `n`: the surface of `ch5`, `figures` and `ir-accuracy`.
pub(crate) fn pf(n: f64, rho_s: f64) -> Fabric {
    let json = format!(
        r#"{{"name": "parallel cylinders", "pattern": [[1]],
            "warp": {{"radius": 1, "spacing": 2, "material": {{"albedo": 0.4, "specular": {rho_s}, "exponent": {n}}}}},
            "weft": {{"radius": 1, "spacing": 2}}}}"#
    );
    Fabric::from_json_str(&json, "ch5").expect("valid")
}

fn unit(v: Vec3) -> Vec3 {
    v * (1.0 / v.length())
}

/// Light and eye in the local frame (x across the cylinders, y along, z normal) of a surface
/// point `p` with normal `n` and cylinder direction `axis`.
fn local(l: Vec3, eye: Vec3, p: Vec3, n: Vec3, axis: Vec3) -> Option<(UnitVec3, UnitVec3)> {
    let a = unit(axis - n * axis.dot(n));
    let c = a.cross(n);
    let e = unit(eye - p);
    let to = |v: Vec3| UnitVec3::new(Vec3::new(v.dot(c), v.dot(a), v.dot(n)));
    let (li, eo) = (to(l)?, to(e)?);
    (li.above_horizon() && eo.above_horizon()).then_some((li, eo))
}

const THESIS_SAMPLING: SecondaryMethod = SecondaryMethod::Sampling(Sampling {
    first_level: 32,
    d_alpha: 0.2,
    d_l: 0.2,
    l0: 1.5,
    exact_solid_angle: true,
});

fn thesis_analytic() -> SecondaryMethod {
    SecondaryMethod::Analytic {
        ranges: Ranges::Thesis {
            c_max: 0.3,
            l0: 1.5,
        },
        orders: Orders::default(),
    }
}

fn full_analytic() -> SecondaryMethod {
    SecondaryMethod::Analytic {
        ranges: Ranges::Full,
        orders: Orders::default(),
    }
}

fn correlation(x: &[f64], y: &[f64]) -> f64 {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let (mut sxy, mut sxx, mut syy) = (0.0, 0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx).powi(2);
        syy += (b - my).powi(2);
    }
    sxy / (sxx * syy).sqrt()
}

fn sphere(out: &mut String) {
    let m = AnalyticModel::new(&pf(1.0, 0.7), FacetModel::Huo);
    let eye = Vec3::new(0.0, -10.0, 10.0);
    let l = unit(Vec3::new(0.0, -0.5, 0.87));
    // Pinhole camera looking at the origin; the sphere fills about 80% of the frame.
    let fwd = unit(-eye);
    let right = unit(fwd.cross(Vec3::new(0.0, 0.0, 1.0)));
    let up = right.cross(fwd);
    let half = 1.2 / eye.length();
    let res = 48;
    let mut pts = Vec::new();
    for j in 0..res {
        for i in 0..res {
            let (u, v) = (
                ((i as f64 + 0.5) / res as f64 * 2.0 - 1.0) * half,
                ((j as f64 + 0.5) / res as f64 * 2.0 - 1.0) * half,
            );
            let d = unit(fwd + right * u + up * v);
            // Ray-sphere (radius 1, centre 0).
            let b = eye.dot(d);
            let c = eye.dot(eye) - 1.0;
            let disc = b * b - c;
            if disc <= 0.0 {
                continue;
            }
            let p = eye + d * (-b - disc.sqrt());
            let n = unit(p);
            if let Some(dirs) = local(l, eye, p, n, Vec3::new(0.0, 0.0, 1.0)) {
                pts.push(dirs);
            }
        }
    }
    writeln!(out, "## Sphere test (Figs 5.8-5.9)\n\nLight toward (0, -0.5, 0.87) normalised (azimuth -y), eye at (0, -10, 10) (azimuth -y), cylinder axes along the meridians (toward the north pole +z); unit sphere at the origin. {} lit and visible pixels; rho_d 0.4, rho_s 0.7, n 1, d 2, r 1, h 0.\n", pts.len()).unwrap();
    writeln!(out, "| kernel | analytical | ray-traced (two-level) | correlation of I_ss | mean rel. diff of I_ss | mean I_ss/I_s (analytical) |\n|---|---|---|---|---|---|").unwrap();
    for kernel in [Kernel::Thesis, Kernel::Radiometric] {
        for (aname, am, sname, sm) in [
            (
                "thesis ranges",
                thesis_analytic(),
                "thesis steps",
                THESIS_SAMPLING,
            ),
            (
                "full ranges",
                full_analytic(),
                "steps 0.1, l0 12",
                SecondaryMethod::Sampling(Sampling {
                    first_level: 32,
                    d_alpha: 0.1,
                    d_l: 0.1,
                    l0: 12.0,
                    exact_solid_angle: true,
                }),
            ),
        ] {
            let (mut a, mut s, mut ratio) = (Vec::new(), Vec::new(), 0.0);
            for &(wi, wo) in &pts {
                let ra = m.intensity_with(wi, wo, Some(&SecondaryOptions { method: am, kernel }));
                let rs = m.intensity_with(wi, wo, Some(&SecondaryOptions { method: sm, kernel }));
                a.push(ra.secondary.unwrap().ss[0]);
                s.push(rs.secondary.unwrap().ss[0]);
                ratio += ra.secondary.unwrap().ss[0] / ra.i_s[0].max(1e-12) / pts.len() as f64;
            }
            let rel = a
                .iter()
                .zip(&s)
                .filter(|(_, y)| **y > 1e-9)
                .map(|(x, y)| (x - y).abs() / y)
                .sum::<f64>()
                / a.len() as f64;
            writeln!(
                out,
                "| {kernel:?} | {aname} | {sname} | {:.4} | {:.1}% | {:.3} |",
                correlation(&a, &s),
                100.0 * rel,
                ratio
            )
            .unwrap();
        }
    }
}

/// The two readings of the disk's cylinders (the thesis does not say how they lie): along +y,
/// parallel to the light's and the eye's azimuth, or along +x, so that light and eye lie in
/// the cylinders' cross-section plane.
#[derive(Clone, Copy)]
enum Reading {
    AlongY,
    AlongX,
}

/// Where the light is, seen from the disk's centre: on the eye's side (azimuth -y, as the
/// sphere test) or on the far side of the disk from the eye (azimuth +y); 75 degrees high.
#[derive(Clone, Copy, PartialEq)]
enum Light {
    EyeSide,
    Beyond,
}

fn disk(out: &mut String) {
    writeln!(out, "\n## Disk test: the readings\n\nThe thesis states neither how the cylinders lie on the disk, nor the light's azimuth, nor the disk's radius. In every table the disk lies on z = 0 centred at the origin, the eye is at (0, -10, 10) (azimuth -y, so the eye direction varies over the disk) and the light is a direction 75 degrees above the disk; each title names the rest:\n\n* **light on the eye's side**: toward (0, -cos 75, sin 75), azimuth -y like the eye (the sphere test's azimuth); disk radius 5;\n* **light beyond the disk**: toward (0, +cos 75, sin 75), azimuth +y, on the far side of the disk from the eye; disk radius 5 and 10;\n* **cylinders along y** (reading A): axes along +y, in the vertical plane of the light and the eye; **cylinders along x** (reading B): axes along +x, so that the light and the eye lie in the cylinders' cross-section plane.\n\nEach disk is sampled on a 41 x 41 grid over its bounding square (steps of radius / 20), the points inside the disk where the light and the eye are above the plane.").unwrap();
    for (light, radius, reading) in [
        (Light::EyeSide, 5.0, Reading::AlongY),
        (Light::EyeSide, 5.0, Reading::AlongX),
        (Light::Beyond, 5.0, Reading::AlongY),
        (Light::Beyond, 5.0, Reading::AlongX),
        (Light::Beyond, 10.0, Reading::AlongY),
        (Light::Beyond, 10.0, Reading::AlongX),
    ] {
        disk_reading(out, light, radius, reading);
    }
}

fn disk_reading(out: &mut String, light: Light, radius: f64, reading: Reading) {
    let (axis, which) = match reading {
        Reading::AlongY => (Vec3::new(0.0, 1.0, 0.0), "cylinders along y"),
        Reading::AlongX => (Vec3::new(1.0, 0.0, 0.0), "cylinders along x"),
    };
    let eye = Vec3::new(0.0, -10.0, 10.0);
    let t = 75f64.to_radians();
    let (l, where_light) = match light {
        Light::EyeSide => (
            Vec3::new(0.0, -t.cos(), t.sin()),
            "light on the eye's side (azimuth -y)",
        ),
        Light::Beyond => (
            Vec3::new(0.0, t.cos(), t.sin()),
            "light beyond the disk (azimuth +y)",
        ),
    };
    let step = radius / 20.0;
    let mut pts = Vec::new();
    for j in 0..41 {
        for i in 0..41 {
            let p = Vec3::new(-radius + step * i as f64, -radius + step * j as f64, 0.0);
            if p.length() <= radius {
                if let Some(d) = local(l, eye, p, Vec3::new(0.0, 0.0, 1.0), axis) {
                    pts.push(d);
                }
            }
        }
    }
    let mut settings = vec![
        (
            "as the thesis computed it: thesis kernel, thesis ranges (C_max 0.3, l0 1.5)",
            Kernel::Thesis,
            thesis_analytic(),
        ),
        (
            "thesis kernel, full ranges",
            Kernel::Thesis,
            full_analytic(),
        ),
    ];
    if let (Light::EyeSide, Reading::AlongY) = (light, reading) {
        settings.push((
            "radiometric kernel, full ranges (physically right)",
            Kernel::Radiometric,
            full_analytic(),
        ));
    }
    for (title, kernel, method) in settings {
        writeln!(out, "\n## Disk test (Table 5.2, Fig. 5.14), {where_light}, {which}, radius {radius}: {title}\n\nLight toward ({:.3}, {:.3}, {:.3}), eye at (0, -10, 10), cylinder axes along {}; disk radius {radius}, {} disk points; rho_d 0.4, rho_s 0.7, d 2, r 1, h 0.\n", l.x, l.y, l.z, if let Reading::AlongY = reading { "+y" } else { "+x" }, pts.len()).unwrap();
        writeln!(out, "| n | max I_ss | max I_ss/I_s | max I_2 | max I_2/I_1 | share I_ss | share I_sd | share I_ds | share I_dd |\n|---|---|---|---|---|---|---|---|---|").unwrap();
        for n in [
            1.0, 2.0, 4.0, 8.0, 12.0, 16.0, 20.0, 24.0, 32.0, 40.0, 55.0, 70.0, 90.0,
        ] {
            let m = AnalyticModel::new(&pf(n, 0.7), FacetModel::Huo);
            let (mut mss, mut mr, mut m2, mut m21) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
            let mut share = [0.0; 4];
            for &(wi, wo) in &pts {
                let r = m.intensity_with(wi, wo, Some(&SecondaryOptions { method, kernel }));
                let s = r.secondary.unwrap();
                let i2 = s.total()[0];
                mss = mss.max(s.ss[0]);
                mr = mr.max(s.ss[0] / r.i_s[0].max(1e-12));
                m2 = m2.max(i2);
                m21 = m21.max(i2 / r.direct()[0].max(1e-12));
                for (k, c) in [s.ss, s.sd, s.ds, s.dd].iter().enumerate() {
                    share[k] += c[0];
                }
            }
            let tot: f64 = share.iter().sum::<f64>().max(1e-300);
            writeln!(
                out,
                "| {n} | {mss:.4} | {mr:.3} | {m2:.4} | {m21:.3} | {:.0}% | {:.0}% | {:.0}% | {:.0}% |",
                100.0 * share[0] / tot,
                100.0 * share[1] / tot,
                100.0 * share[2] / tot,
                100.0 * share[3] / tot
            )
            .unwrap();
            eprintln!("disk {where_light} {which} radius {radius} n {n}: max I_2 {m2:.4}");
        }
    }
}

fn convergence(out: &mut String, root: &std::path::Path) {
    writeln!(out, "\n## Convergence of inter-reflection (path tracer, radiometric, huo facets)\n\nI_k / I_1 for bounce orders k = 2..6, averaged over 8 direction pairs up to 60 degrees (`directions::direction_set`), 40 000 paths each; rho_d 0.4, rho_s 0.3 (sec. 4.3) for the twill, rho_d 0.4, rho_s 0.7 (sec. 5.4) for the parallel cylinders.\n").unwrap();
    writeln!(out, "| surface | n | I_2/I_1 | I_3/I_1 | I_4/I_1 | I_5/I_1 | I_6/I_1 |\n|---|---|---|---|---|---|---|").unwrap();
    let pairs = clothbake_core::directions::direction_set(8, 60.0);
    for (name, rho_s) in [("parallel", 0.7), ("twill", 0.3)] {
        for n in [1.0, 4.0, 10.0, 40.0] {
            let f = if name == "parallel" {
                pf(n, rho_s)
            } else {
                Fabric::from_path(&root.join("tables/twill.json"))
                    .unwrap()
                    .with_groups(
                        |_, g| g.material.exponent = n,
                        &clothbake_core::PlainNaming("twill"),
                    )
                    .unwrap()
            };
            let rt = RayTracer::new(&f, FacetModel::Huo);
            let mut ratio = [0.0; 5];
            for (k, &(wi, wo)) in pairs.iter().enumerate() {
                let p = rt.render_paths(
                    wi,
                    wo,
                    40_000,
                    100 + k as u64,
                    PathOptions {
                        max_bounces: 6,
                        kernel: Kernel::Radiometric,
                        roulette_from: 7,
                        first_order: 1,
                    },
                );
                for (o, r) in ratio.iter_mut().enumerate() {
                    *r += p.orders[o + 1][0] / p.orders[0][0] / pairs.len() as f64;
                }
            }
            writeln!(
                out,
                "| {name} | {n} | {:.4} | {:.4} | {:.4} | {:.4} | {:.4} |",
                ratio[0], ratio[1], ratio[2], ratio[3], ratio[4]
            )
            .unwrap();
            eprintln!("convergence {name} n {n}: {ratio:?}");
        }
    }
    out.push_str("\nThe orders do not fall monotonically at n = 1 on the parallel surface: I_6 > I_5 (and I_8 > I_7, docs/science/transport.md), while I_4 stays just under I_3. This is neither noise (with 10 times the paths: I_3 0.1069 +- 0.0003, I_4 0.1044 +- 0.0004, I_5 0.0551 +- 0.0003, I_6 0.0701 +- 0.0005) nor Russian roulette (this table uses none; with roulette from order 4 the same within the errors). Two causes, both measured in docs/science/transport.md: in the grooves' cross-section a path alternates between the two walls of a groove, so the parity of the order decides whether its last vertex lies on the lit wall (light and eye on opposite sides: the even orders carry the light; on one side: the odd ones), and the sec. 5.4 facets at n = 1 (rho_d 0.4, rho_s 0.7) reflect 1.1 to 1.6 times the light they receive, so the orders do not decay geometrically (along the grooves they grow).\n\n");
}

/// Runs the chapter 5 comparisons and writes `docs/results/interreflection.md`.
pub fn run(root: &std::path::Path) {
    let mut out = String::from(
        "# Chapter 5 results (generated by `cargo xtask ch5`; do not edit)\n\nSee docs/science/interreflection.md for the method and the assumptions.\n\n",
    );
    sphere(&mut out);
    disk(&mut out);
    convergence(&mut out, root);
    print!("{out}");
    std::fs::write(root.join("docs/results/interreflection.md"), &out).unwrap();
}
