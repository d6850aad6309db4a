//! `cargo xtask lod`: the level-of-detail pictures against the ground-truth pictures, into the
//! table of `docs/results/validation.md` (between its `lod-validation` markers).
//!
//! For each case (a flat swatch and a sphere; the twill, satin5, gingham and the wool twill
//! preset; two lights) and each of six distances, from 32 pixels across a thread down to 0.1
//! pixel per period, the same camera and pixel samples render the one-bounce model through its
//! footprints (`Shader::model`: point, cells, period), with the default variant (`refined`),
//! with `sliced` and with `sliced3d`, and the ground truth (`Shader::truth`, twice with
//! different jitter, shared by the three). The relative RMSE is the RMS difference between the level of
//! detail and the mean of the two truths, with the truths' own noise (estimated from their
//! difference) subtracted, over the mean truth value of the pixels that see the cloth.
//! Ambient 0 (the reflected light alone), opaque cloth, 16 x 16 samples a pixel: with 8 x 8 the
//! level-of-detail picture's own sampling noise where the levels hand over, which `compare`
//! does not take out, reached 3% (1.2% with 16 x 16 on the same case).

use clothbake_core::{Fabric, FacetModel, Variant};
use clothbake_render::camera::Camera;
use clothbake_render::scene::Scene;
use clothbake_render::shade::{Component, Lighting, Shader};
use clothbake_render::tonemap::Image;
use clothbake_render::{render, render_weave};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::atomic::AtomicBool;

const RES: u32 = 64;
const AA: u32 = 16;
/// Pixels per period at the image centre, nearest first: 32 pixels a thread (times the threads
/// of the period) down to 0.1.
const STEPS: usize = 6;

fn image(
    scene: &Scene,
    camera: &Camera,
    light: &Lighting,
    s: &Shader,
    periods: Option<f64>,
) -> Image {
    let never = AtomicBool::new(false);
    match periods {
        Some(_) => render_weave(scene, camera, light, s, AA, periods, &|_| {}, &never),
        None => render(scene, camera, light, s, AA, &|_| {}, &never),
    }
    .expect("never cancelled")
}

/// (relative RMSE with the truth's noise taken out, the truth's relative noise), over the
/// pixels the truth sees cloth in.
fn compare(lod: &Image, t1: &Image, t2: &Image) -> (f64, f64) {
    let (mut se, mut noise, mut sum, mut n) = (0.0, 0.0, 0.0, 0usize);
    for ((l, a), b) in lod.pixels.iter().zip(&t1.pixels).zip(&t2.pixels) {
        let seen = a.iter().chain(b).any(|&x| x > 0.0) || l.iter().any(|&x| x > 0.0);
        if !seen {
            continue;
        }
        n += 1;
        for c in 0..3 {
            let t = 0.5 * f64::from(a[c] + b[c]);
            se += (f64::from(l[c]) - t).powi(2);
            // The variance of the mean of two: a quarter of the squared difference.
            noise += 0.25 * f64::from(a[c] - b[c]).powi(2);
            sum += t;
        }
    }
    let mean = sum / (3 * n.max(1)) as f64;
    let rmse = ((se - noise).max(0.0) / (3 * n.max(1)) as f64).sqrt();
    let sd = (noise / (3 * n.max(1)) as f64).sqrt();
    (rmse / mean, sd / mean)
}

/// The largest absolute difference between two pictures, over the largest value of the second.
fn max_diff(a: &Image, b: &Image) -> f64 {
    let mut d = 0.0f64;
    let mut top = 0.0f64;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            d = d.max(f64::from((p[c] - q[c]).abs()));
            top = top.max(f64::from(q[c]));
        }
    }
    d / top.max(1e-30)
}

/// The crossing cells' model values against the point level's mean over each cell (parallax
/// included): per shipped fabric, the mean and worst relative error of the channel-mean f_r
/// (cells whose point-level coverage is under 0.1 left out) and the worst coverage difference,
/// over 12 direction pairs up to 70 degrees, 32 x 32 jittered points a cell.
fn cells_table(root: &Path) -> String {
    use clothbake_core::rng::Rng;
    use clothbake_core::{AnalyticModel, Cell};
    let pairs = clothbake_core::directions::direction_set(12, 70.0);
    let mut rows = String::new();
    for path in clothbake_bake::golden::fabric_files(&root.join("tables")).expect("tables") {
        let f = Fabric::from_path(&path).expect("shipped fabric");
        let model = AnalyticModel::new(&f, FacetModel::Huo);
        let yarns = clothbake_core::point::yarns(&f, FacetModel::Huo).expect("a small period");
        let (eu, ev) = model.cells().edge_fractions();
        let (nx, ny) = model.cells().dims();
        let mean = |x: [f64; 3]| (x[0] + x[1] + x[2]) / 3.0;
        let (mut sum, mut n, mut worst, mut worst_cov) = (0.0, 0, 0.0f64, 0.0f64);
        let mut rng = Rng::new(9);
        for &(wi, wo) in &pairs {
            for j in 0..ny {
                for i in 0..nx {
                    let m = model.intensity_in(wi, wo, Cell { warp: i, weft: j }, None);
                    let f_cell = clothbake_core::intensity_to_brdf(m.reflection.total(), wi);
                    let (mut fc, mut c) = (0.0, 0.0);
                    let k = 32;
                    for a in 0..k {
                        for b in 0..k {
                            let u = eu[i]
                                + (eu[i + 1] - eu[i]) * (a as f64 + rng.next_f64()) / k as f64;
                            let v = ev[j]
                                + (ev[j + 1] - ev[j]) * (b as f64 + rng.next_f64()) / k as f64;
                            let l = yarns.look(u, v, wi, wo);
                            fc += l.coverage * mean(l.f);
                            c += l.coverage;
                        }
                    }
                    let c_pt = c / (k * k) as f64;
                    worst_cov = worst_cov.max((c_pt - m.coverage).abs());
                    if c_pt < 0.1 || mean(f_cell) <= 0.0 {
                        continue;
                    }
                    let rel = (mean(f_cell) - fc / c).abs() / (fc / c);
                    sum += rel;
                    n += 1;
                    worst = worst.max(rel);
                }
            }
        }
        writeln!(
            rows,
            "| {} | {} | {:.1}% | {:.1}% | {:.2} |",
            path.file_stem().unwrap_or_default().to_string_lossy(),
            nx * ny,
            100.0 * sum / n.max(1) as f64,
            100.0 * worst,
            worst_cov
        )
        .unwrap();
    }
    format!(
        "The crossing cells (the model's pieces, attributed where the yarn lies) against the \
         point level's mean over each cell of the reference plane (parallax included), 12 \
         direction pairs up to 70 degrees, 32 x 32 jittered points a cell; f_r's relative \
         error where the point level's coverage is at least 0.1:\n\n\
         | fabric | cells | mean rel. err | worst cell | worst coverage diff |\n|---|---|---|---|---|\n{rows}"
    )
}

/// Writes the table.
pub fn run(root: &Path) {
    let fabrics = [
        "twill.json",
        "satin5.json",
        "gingham.wif",
        "wool-twill.json",
    ];
    let scenes = [
        ("swatch", clothbake_core::Vec3::new(0.0, -55.0, 45.0)),
        ("sphere", clothbake_core::Vec3::new(0.0, -3.0, 2.4)),
    ];
    let lights = [
        ("front", clothbake_core::Vec3::new(0.0, -0.5, 0.866)),
        ("side", clothbake_core::Vec3::new(0.8, 0.3, 0.52)),
    ];
    // The default variant, the sliced one and sliced3d (docs/science/model.md), against the same
    // truths.
    let variants = [Variant::Refined, Variant::Sliced, Variant::Sliced3d];
    let mut rows = String::new();
    let mut worst = [0.0f64; 3];
    let mut far_equal = 0.0f64;
    for name in fabrics {
        let fabric = Fabric::from_path(&root.join("tables").join(name)).expect("shipped fabric");
        let threads = fabric.weave().n_warp().max(fabric.weave().n_weft()) as f64;
        let models = variants.map(|v| {
            Shader::model(&fabric, FacetModel::Huo, v, None, Component::Total).expect("one bounce")
        });
        let truth = [1, 2].map(|seed| Shader::truth(&fabric, FacetModel::Huo, seed, None));
        for (scene_name, eye) in scenes {
            let scene = Scene::by_name(scene_name).expect("scene");
            let (lo, hi) = scene.bounds();
            let look = clothbake_core::Vec3::new(0.0, 0.0, 0.0);
            let fov = Camera::fitting_fov(eye, look, RES, RES, lo, hi);
            let camera = Camera::new(eye, look, fov, RES, RES).expect("camera");
            // Pixels per scene length at the look-at point.
            let per_length = f64::from(RES) / (2.0 * (eye - look).length() * camera.tan_half);
            let near = 32.0 * threads;
            for (light_name, l) in lights {
                let lighting = Lighting {
                    light: l * (1.0 / l.length()),
                    irradiance: std::f64::consts::PI,
                    ambient: 0.0,
                };
                let mut cells = [Vec::new(), Vec::new(), Vec::new()];
                for step in 0..STEPS {
                    // Pixels per period, geometric from `near` to 0.1.
                    let ppp = near * (0.1 / near).powf(step as f64 / (STEPS - 1) as f64);
                    let periods = scene.width() * per_length / ppp;
                    let [t1, t2] = [&truth[0], &truth[1]]
                        .map(|t| image(&scene, &camera, &lighting, t, Some(periods)));
                    for (k, model) in models.iter().enumerate() {
                        let lod = image(&scene, &camera, &lighting, model, Some(periods));
                        let (err, noise) = compare(&lod, &t1, &t2);
                        worst[k] = worst[k].max(err);
                        if step == STEPS - 1 && variants[k] != Variant::Sliced3d {
                            // A tenth of that again: every sample's footprint a period or more
                            // (the rule's property, not the variant's: sliced3d, far slower,
                            // is left out of this check).
                            let averaged = image(&scene, &camera, &lighting, model, None);
                            let far =
                                image(&scene, &camera, &lighting, model, Some(10.0 * periods));
                            far_equal = far_equal.max(max_diff(&far, &averaged));
                        }
                        cells[k].push(format!("{:.1}% ({:.1}%)", 100.0 * err, 100.0 * noise));
                    }
                }
                for (v, cells) in variants.iter().zip(&cells) {
                    writeln!(
                        rows,
                        "| {} | {scene_name} | {light_name} | {} | {} |",
                        name.split('.').next().unwrap_or(name),
                        v.name(),
                        cells.join(" | ")
                    )
                    .unwrap();
                    eprintln!(
                        "{name} {scene_name} {light_name} {}: {}",
                        v.name(),
                        cells.join(", ")
                    );
                }
            }
        }
    }
    let mut out = String::new();
    writeln!(
        out,
        "<!-- lod-validation:begin -->\n## Levels of detail against the ground-truth pictures\n\n\
         Written by `cargo xtask lod` (method: docs/science/spatial.md, \"Validation of the levels\"). \
         Relative RMSE of the level-of-detail picture against the ground-truth picture (the \
         truth's own noise, in brackets, taken out), {RES} x {RES} pixels, {AA} x {AA} samples \
         a pixel, ambient 0, one bounce, Huo facets. Distances in pixels per period at the \
         image centre, from 32 pixels a thread (1) to 0.1 pixel a period (6), geometric \
         between; each case with the default variant (`refined`), with `sliced` and with `sliced3d` \
         (docs/science/model.md), against the same truths. Worst: {:.1}% (refined), {:.1}% (sliced), \
         {:.1}% (sliced3d). At 0.01 pixel a period, where every sample's footprint is a \
         period or more, the level-of-detail picture differs from the averaged render by at \
         most {:.1e} of its largest value (refined and sliced).\n\n\
         | fabric | scene | light | variant | 1 | 2 | 3 | 4 | 5 | 6 |\n|---|---|---|---|---|---|---|---|---|---|\n{rows}\
         \n{}<!-- lod-validation:end -->",
        100.0 * worst[0],
        100.0 * worst[1],
        100.0 * worst[2],
        far_equal,
        cells_table(root)
    )
    .unwrap();
    crate::replace_section(
        &root.join("docs/results/validation.md"),
        "lod-validation",
        &out,
    );
    println!("{out}");
}
