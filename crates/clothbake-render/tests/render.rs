//! Renders and plots checked against properties and the model itself, never against a stored
//! picture of their own output: determinism across thread counts, the mirror symmetry of a
//! symmetric weave on the sphere, brightness orderings, and a swatch pixel recomputed from the
//! camera's stated conventions and the model directly.

use clothbake_core::{AnalyticModel, Fabric, FacetModel, UnitVec3, Variant, Vec3};
use clothbake_render::camera::Camera;
use clothbake_render::plot::{self, Plot, Source};
use clothbake_render::scene::Scene;
use clothbake_render::shade::{Component, Lighting, Shader};
use clothbake_render::tonemap::Image;
use clothbake_render::{render, scene::Drape};
use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn fabric(name: &str) -> Fabric {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tables")
        .join(format!("{name}.json"));
    Fabric::from_path(&p).unwrap()
}

fn shader(f: &Fabric) -> Shader {
    Shader::model(f, FacetModel::Huo, Variant::Refined, None, Component::Total).unwrap()
}

fn unit(v: Vec3) -> Vec3 {
    v * (1.0 / v.length())
}

fn lighting(light: Vec3, ambient: f64) -> Lighting {
    Lighting {
        light: unit(light),
        irradiance: PI,
        ambient,
    }
}

fn draw(scene: &Scene, cam: &Camera, l: &Lighting, s: &Shader, aa: u32, threads: usize) -> Image {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .unwrap()
        .install(|| render(scene, cam, l, s, aa, &|_| {}, &AtomicBool::new(false)))
        .unwrap()
}

fn mean(img: &Image) -> f64 {
    img.pixels
        .iter()
        .map(|p| f64::from(p[0] + p[1] + p[2]) / 3.0)
        .sum::<f64>()
        / img.pixels.len() as f64
}

#[test]
fn renders_are_bit_identical_for_any_thread_count() {
    let s = shader(&fabric("twill"));
    let scene = Scene::Drape(Drape::default());
    let cam = Camera::new(Vec3::new(-45.0, 45.0, 80.0), Vec3::default(), 50.0, 40, 30).unwrap();
    let l = lighting(Vec3::new(0.0, 0.707, 0.707), 0.3);
    let a = draw(&scene, &cam, &l, &s, 2, 1);
    let b = draw(&scene, &cam, &l, &s, 2, 2);
    let bits = |i: &Image| -> Vec<u32> { i.pixels.iter().flatten().map(|x| x.to_bits()).collect() };
    assert_eq!(bits(&a), bits(&b));
    // Not a blank image: the cloth covers part of the frame and is lit unevenly.
    let lit = a.pixels.iter().filter(|p| p[0] > 0.0).count();
    assert!(lit > 200 && lit < 1200, "{lit} of 1200 pixels on the cloth");
}

/// The sphere under the plain weave (mirror-symmetric in x and y) with the eye and the light in
/// the plane x = 0: mirroring the world in x maps the scene onto itself and, at each point,
/// the local frame to its mirror in x (weft -> -weft), under which the plain weave's BRDF is
/// invariant; so the image is mirror-symmetric left to right.
#[test]
fn sphere_of_a_symmetric_weave_is_mirror_symmetric() {
    let s = shader(&fabric("plain"));
    let scene = Scene::Sphere { radius: 1.0 };
    let (w, h) = (40, 32);
    let cam = Camera::new(Vec3::new(0.0, -10.0, 10.0), Vec3::default(), 10.0, w, h).unwrap();
    let sym = draw(
        &scene,
        &cam,
        &lighting(Vec3::new(0.0, -0.5, 0.87), 0.0),
        &s,
        1,
        2,
    );
    let asym = draw(
        &scene,
        &cam,
        &lighting(Vec3::new(0.6, -0.5, 0.6), 0.0),
        &s,
        1,
        2,
    );
    let worst = |img: &Image| {
        let mut worst = 0.0f64;
        for j in 0..h {
            for i in 0..w / 2 {
                let (a, b) = (img.get(i, j), img.get(w - 1 - i, j));
                for k in 0..3 {
                    let d = f64::from((a[k] - b[k]).abs())
                        / f64::from(a[k].abs().max(b[k].abs()).max(1e-3));
                    worst = worst.max(d);
                }
            }
        }
        worst
    };
    assert!(sym.pixels.iter().filter(|p| p[0] > 0.01).count() > 300);
    assert!(worst(&sym) < 1e-4, "asymmetry {}", worst(&sym));
    // The measure does see an asymmetric light.
    assert!(worst(&asym) > 0.1, "{}", worst(&asym));
}

#[test]
fn brightness_follows_the_physics() {
    let scene = Scene::swatch(30.0);
    let cam = Camera::new(Vec3::new(0.0, -55.0, 45.0), Vec3::default(), 40.0, 24, 24).unwrap();
    let twill = fabric("twill");
    let s = shader(&twill);
    // Light at normal incidence against light 75 degrees from the normal (same azimuth plane).
    let t = 75f64.to_radians();
    let normal = draw(
        &scene,
        &cam,
        &lighting(Vec3::new(0.0, 0.0, 1.0), 0.0),
        &s,
        1,
        2,
    );
    let grazing = draw(
        &scene,
        &cam,
        &lighting(Vec3::new(0.0, t.sin(), t.cos()), 0.0),
        &s,
        1,
        2,
    );
    assert!(
        mean(&normal) > 1.5 * mean(&grazing),
        "{} vs {}",
        mean(&normal),
        mean(&grazing)
    );
    // A higher diffuse albedo is brighter at every pixel on the cloth.
    let bright = twill
        .with_groups(
            |_, g| g.material.albedo = [0.6; 3],
            &clothbake_core::PlainNaming("bright"),
        )
        .unwrap();
    let l = lighting(Vec3::new(0.0, 0.707, 0.707), 0.3);
    let a = draw(&scene, &cam, &l, &s, 1, 2);
    let b = draw(&scene, &cam, &l, &shader(&bright), 1, 2);
    let mut on = 0;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        if p[0] > 0.0 {
            on += 1;
            assert!(q[0] > p[0], "{q:?} <= {p:?}");
        }
    }
    assert!(on > 100);
    // Seen from below, the cloth shows its back: black. Lit from below: only the sky, the same
    // picture as with the sun put out.
    let below = Camera::new(Vec3::new(0.0, -55.0, -45.0), Vec3::default(), 40.0, 8, 8).unwrap();
    assert!(draw(&scene, &below, &l, &s, 1, 1)
        .pixels
        .iter()
        .all(|p| *p == [0.0; 3]));
    let under = draw(
        &scene,
        &cam,
        &lighting(Vec3::new(0.0, 0.0, -1.0), 0.3),
        &s,
        1,
        1,
    );
    let dark = Lighting {
        irradiance: 0.0,
        ..lighting(Vec3::new(0.0, 0.707, 0.707), 0.3)
    };
    let sky = draw(&scene, &cam, &dark, &s, 1, 1);
    assert_eq!(under.pixels, sky.pixels);
    assert!(sky.pixels.iter().filter(|p| p[0] > 0.01).count() > 100);
}

/// Pixel (i, j) recomputed from the camera's documented conventions, the plane z = 0, the sun
/// and sky of docs/guide/render.md and the analytic model, without the renderer's camera, scene,
/// frame or shading code.
#[test]
fn swatch_pixels_equal_the_model_at_their_directions() {
    let twill = fabric("twill");
    let s = shader(&twill);
    let model = AnalyticModel::new(&twill, FacetModel::Huo);
    let (w, h, fov) = (16u32, 12u32, 50.0f64);
    let eye = Vec3::new(7.0, -40.0, 30.0);
    let light = unit(Vec3::new(-0.3, 0.6, 0.75));
    let cam = Camera::new(eye, Vec3::new(2.0, 3.0, 0.0), fov, w, h).unwrap();
    let l = Lighting {
        light,
        irradiance: 2.0,
        ambient: 0.25,
    };
    let img = draw(&Scene::swatch(30.0), &cam, &l, &s, 1, 2);
    // The stated convention: forward to the target, right = forward x Z, up = right x forward.
    let f = unit(Vec3::new(2.0, 3.0, 0.0) - eye);
    let r = unit(f.cross(Vec3::new(0.0, 0.0, 1.0)));
    let u = r.cross(f);
    let th = (fov.to_radians() / 2.0).tan();
    let mut checked = 0;
    for j in 0..h {
        for i in 0..w {
            let x = (2.0 * (i as f64 + 0.5) / w as f64 - 1.0) * th * w as f64 / h as f64;
            let y = (1.0 - 2.0 * (j as f64 + 0.5) / h as f64) * th;
            let d = unit(f + r * x + u * y);
            let p = eye + d * (-eye.z / d.z);
            if p.x.abs() > 29.0 || p.y.abs() > 29.0 {
                continue;
            }
            let wi = UnitVec3::new(light).unwrap();
            let wo = UnitVec3::new(eye - p).unwrap();
            let i_total = model.intensity(wi, wo).total();
            // The sky on a surface facing up: looked up from the normal, weight rho_a pi, so
            // that it adds rho_a pi f_r(N, wo) = rho_a I(N, wo).
            let i_sky = model.intensity(UnitVec3::Z, wo).total();
            for (k, &ik) in i_total.iter().enumerate() {
                let fr = ik / (PI * wi.cos_theta());
                let want = 0.25 * i_sky[k] + fr * wi.cos_theta() * 2.0;
                let got = f64::from(img.get(i, j)[k]);
                assert!(
                    (got - want).abs() < 1e-5 * want,
                    "pixel {i},{j}: {got} vs {want}"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked}");
}

/// The luminance of one column of the twill sphere across the terminator, and how sharply its
/// slope changes there: the largest change of the first difference from one row to the next,
/// over the mean size of the first differences of the 8 rows on either side, within 24 rows of
/// the terminator (a crease: the slope changes by more than its own size within a row), and
/// the mean slope on the shadow side over that on the lit side (0: a flat shadow).
fn terminator(col: &[f64], at: usize) -> (f64, f64) {
    let d: Vec<f64> = col.windows(2).map(|w| w[1] - w[0]).collect();
    let mut worst = 0.0f64;
    for j in at - 24..at + 24 {
        let around: Vec<f64> = d[j - 9..j - 1]
            .iter()
            .chain(&d[j + 1..j + 9])
            .copied()
            .collect();
        let scale = around.iter().map(|x| x.abs()).sum::<f64>() / around.len() as f64;
        worst = worst.max((d[j] - d[j - 1]).abs() / scale.max(1e-12));
    }
    let slope = |r: std::ops::Range<usize>| {
        let n = r.len() as f64;
        d[r].iter().map(|x| x.abs()).sum::<f64>() / n
    };
    (worst, slope(at + 4..at + 24) / slope(at - 24..at - 4))
}

/// The sun sets over a penumbra and the sky shades the rest: no crease at the terminator of the
/// twill sphere and no flat shadow. The same measure on the old shading (a flat ambient 0.3 plus
/// a point light), computed here from the model at the pixels' own directions, finds both.
#[test]
fn the_terminator_has_no_seam() {
    let twill = fabric("twill");
    let s = shader(&twill);
    let model = AnalyticModel::new(&twill, FacetModel::Huo);
    // Eye and light 45 degrees up on either side: the terminator crosses the middle of the image.
    let eye = Vec3::new(0.0, -10.0, 10.0);
    let light = unit(Vec3::new(0.0, 1.0, 1.0));
    let (h, fov) = (256u32, 10.0f64);
    let cam = Camera::new(eye, Vec3::default(), fov, 1, h).unwrap();
    let img = draw(
        &Scene::Sphere { radius: 1.0 },
        &cam,
        &lighting(light, 0.3),
        &s,
        1,
        2,
    );
    let lum = |p: [f64; 3]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let new: Vec<f64> = (0..h).map(|j| lum(img.get(0, j).map(f64::from))).collect();
    // The column through the sphere's centre, from the camera's documented conventions.
    let f = unit(-eye);
    let r = unit(f.cross(Vec3::new(0.0, 0.0, 1.0)));
    let u = r.cross(f);
    let th = (fov.to_radians() / 2.0).tan();
    let (mut old, mut at) = (Vec::new(), None);
    for j in 0..h {
        let y = (1.0 - 2.0 * (j as f64 + 0.5) / h as f64) * th;
        let d = unit(f + u * y);
        let b = eye.dot(d);
        let disc = b * b - (eye.dot(eye) - 1.0);
        if disc <= 0.0 {
            old.push(0.0);
            continue;
        }
        let n = unit(eye + d * (-b - disc.sqrt()));
        // Sphere frame (docs/guide/render.md): weft east = Z x N, warp = N x weft.
        let east = unit(Vec3::new(0.0, 0.0, 1.0).cross(n));
        let north = n.cross(east);
        let to = |v: Vec3| Vec3::new(v.dot(east), v.dot(north), v.dot(n));
        let (wi, wo) = (to(light), to(-d));
        if wi.z < 0.0 && at.is_none() {
            at = Some(j as usize);
        }
        let i = match (UnitVec3::new(wi), UnitVec3::new(wo)) {
            (Some(wi), Some(wo)) if wi.above_horizon() && wo.above_horizon() => {
                lum(model.intensity(wi, wo).total())
            }
            _ => 0.0,
        };
        old.push(0.3 + i);
    }
    let at = at.expect("the terminator is in the picture");
    assert!(new[at] > 0.0 && new[at - 30] > new[at] && new[at] > new[at + 30]);
    let (crease, shade) = terminator(&new, at);
    let (old_crease, old_shade) = terminator(&old, at);
    eprintln!("terminator at row {at}: crease {crease:.3} (flat ambient {old_crease:.3}), shadow slope / lit slope {shade:.3} ({old_shade:.3})");
    assert!(crease < 1.0, "a crease at the terminator: {crease}");
    assert!(shade > 0.05, "a flat shadow: {shade}");
    // The measure finds the seam of the old shading.
    assert!(
        old_crease > 1.0 && old_shade < 0.01,
        "{old_crease} {old_shade}"
    );
}

#[test]
fn secondary_components_need_two_bounces() {
    let f = fabric("parallel");
    assert!(Shader::model(
        &f,
        FacetModel::Huo,
        Variant::Refined,
        None,
        Component::Secondary
    )
    .is_err());
    let opts = clothbake_core::SecondaryOptions::default();
    let total = Shader::model(
        &f,
        FacetModel::Huo,
        Variant::Refined,
        Some(opts),
        Component::Total,
    )
    .unwrap();
    let direct = Shader::model(
        &f,
        FacetModel::Huo,
        Variant::Refined,
        Some(opts),
        Component::Direct,
    )
    .unwrap();
    let second = Shader::model(
        &f,
        FacetModel::Huo,
        Variant::Refined,
        Some(opts),
        Component::Secondary,
    )
    .unwrap();
    let iss = Shader::model(
        &f,
        FacetModel::Huo,
        Variant::Refined,
        Some(opts),
        Component::SecondarySpecular,
    )
    .unwrap();
    let (wi, wo) = (
        UnitVec3::from_degrees(30.0, 180.0),
        UnitVec3::from_degrees(40.0, 0.0),
    );
    let (t, d, s2, ss) = (
        total.f_r(wi, wo),
        direct.f_r(wi, wo),
        second.f_r(wi, wo),
        iss.f_r(wi, wo),
    );
    for k in 0..3 {
        assert!((t[k] - d[k] - s2[k]).abs() <= 1e-6 * t[k]);
        assert!(s2[k] > 0.0 && ss[k] > 0.0 && ss[k] < s2[k]);
    }
}

/// A table baked from the twill and looked up by the loader renders the swatch like the model
/// itself, up to the table's interpolation error.
#[test]
fn table_shader_agrees_with_the_model() {
    use clothbake_bake::{bake, BakeOptions};
    use clothbake_render::shade::Shader;
    let twill = fabric("twill");
    let opts = BakeOptions {
        grid: clothbake_loader::Grid::new(16, 32, 16, 32),
        ..BakeOptions::default()
    };
    let table = bake(&twill, &opts, &|_| {}, &AtomicBool::new(false))
        .unwrap()
        .table;
    let path = temp("twill-16.bin");
    clothbake_loader::write_binary(&path, &table, true).unwrap();
    let ts = Shader::table(&path).unwrap();
    let ms = shader(&twill);
    let scene = Scene::swatch(30.0);
    let cam = Camera::new(Vec3::new(0.0, -55.0, 45.0), Vec3::default(), 60.0, 24, 24).unwrap();
    let l = lighting(Vec3::new(0.0, 0.707, 0.707), 0.0);
    let (a, b) = (
        draw(&scene, &cam, &l, &ms, 1, 2),
        draw(&scene, &cam, &l, &ts, 1, 2),
    );
    let (mut n, mut sum, mut worst) = (0, 0.0, 0.0f64);
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        if p[0] > 0.0 {
            let d = f64::from((p[0] - q[0]).abs() / p[0]);
            (n, sum, worst) = (n + 1, sum + d, worst.max(d));
        }
    }
    assert!(n > 200);
    assert!(
        sum / f64::from(n) < 0.03 && worst < 0.15,
        "mean {} worst {worst}",
        sum / f64::from(n)
    );
}

fn temp(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

#[test]
fn plots_draw_text_axes_and_both_sources() {
    let (a, b) = (fabric("twill"), fabric("basket"));
    let (sa, sb) = (shader(&a), shader(&b));
    let sources = [
        Source {
            name: "twill".into(),
            shader: &sa,
        },
        Source {
            name: "basket".into(),
            shader: &sb,
        },
    ];
    // The slice values are the BRDF at the stated directions of the plane of incidence.
    let sl = plot::slice(&sa, 30.0, 90.0);
    let wi = UnitVec3::from_degrees(30.0, 90.0);
    let at = |s: f64| sl.iter().find(|p| (p.0 - s).abs() < 1e-9).unwrap().1;
    let mean3 = |f: [f32; 3]| f64::from(f[0] + f[1] + f[2]) / 3.0;
    assert!((at(29.5) - mean3(sa.f_r(wi, UnitVec3::from_degrees(29.5, 270.0)))).abs() < 1e-6);
    assert!((at(-29.5) - mean3(sa.f_r(wi, UnitVec3::from_degrees(29.5, 90.0)))).abs() < 1e-6);
    for (p, name) in [
        (
            Plot::Slices {
                theta_i: vec![0.0, 45.0],
                phi_i: vec![0.0, 90.0],
            },
            "slices",
        ),
        (
            Plot::Hemisphere {
                theta_i: 40.0,
                phi_i: 90.0,
            },
            "hemi",
        ),
        (
            Plot::Polar {
                theta_i: 45.0,
                phi_i: 90.0,
                theta_o: vec![20.0, 60.0],
            },
            "polar",
        ),
    ] {
        let svg = temp(&format!("plot-{name}.svg"));
        let png_path = temp(&format!("plot-{name}.png"));
        plot::write(&svg, &p, &sources, true).unwrap();
        plot::write(&png_path, &p, &sources, true).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.contains("<text") && text.contains("f_r (1/sr)") && text.contains("basket"));
        assert!(text.contains("% of max"), "the comparison is stated");
        // The PNG decodes at the stated size and holds dark (text, axes) and coloured pixels.
        let dec = png::Decoder::new(std::io::BufReader::new(
            std::fs::File::open(&png_path).unwrap(),
        ));
        let mut reader = dec.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), plot::size(&p, 2));
        let px: Vec<&[u8]> = buf[..info.buffer_size()].chunks(3).collect();
        let dark = px.iter().filter(|c| c.iter().all(|&v| v < 60)).count();
        let colour = px
            .iter()
            .filter(|c| c.iter().max().unwrap() - c.iter().min().unwrap() > 80)
            .count();
        assert!(
            dark > 500 && colour > 500,
            "{name}: dark {dark}, colour {colour}"
        );
    }
    // The polar curve's values are the BRDF at (theta_o, phi_o).
    let c = plot::azimuth_curve(&sa, 45.0, 90.0, 60.0);
    assert_eq!(c.len(), 360);
    let wi = UnitVec3::from_degrees(45.0, 90.0);
    for &(p, v) in c.iter().step_by(37) {
        assert!((v - mean3(sa.f_r(wi, UnitVec3::from_degrees(60.0, p)))).abs() < 1e-6);
    }
    // The twill's f_r depends on the outgoing azimuth (the anisotropy the plot shows): its
    // polar curve is not a circle.
    let (lo, hi) = c
        .iter()
        .fold((f64::MAX, 0f64), |(l, h), &(_, v)| (l.min(v), h.max(v)));
    assert!(hi > 1.1 * lo, "{lo} {hi}");
    assert!(plot::write(
        &temp("plot.jpg"),
        &Plot::Hemisphere {
            theta_i: 1.0,
            phi_i: 0.0
        },
        &sources,
        true
    )
    .is_err());
}
