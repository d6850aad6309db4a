//! Proof by a real client: Mitsuba 3 (its `measured` BSDF) renders a flat rectangle with the
//! RGL `.bsdf` we export, under a directional light seen by a perspective camera
//! (tests/python/mitsuba_render.py): the RGB file in `scalar_rgb`, the spectral file in
//! `scalar_spectral`, and the RGB file exported from a baked table (through the loader) in
//! `scalar_rgb`. The same image is computed here from the analytic model alone: on a flat plane
//! lit by a directional light of irradiance E, a pixel is E f_r(light, eye) cos(theta_light),
//! with the two directions Mitsuba reports for the ray through the pixel's centre, in the
//! surface frame its BSDF sees. Relative RMSE under 5%.
//!
//! Ignored, with the reason, when `python3` cannot import mitsuba and numpy (the build script
//! probes them); under `CI` they run and fail without them (.ci/run and `cargo xtask test`
//! install them). With `CLOTHBAKE_FIGURES=DIR` the two images of each test
//! are also written as PNG into DIR (docs/figures/ holds the committed ones).

use clothbake_core::{AnalyticBsdf, Bsdf};
use clothbake_core::{AnalyticModel, Fabric, FacetModel, UnitVec3, Vec3};
use clothbake_export::rgl;
use clothbake_tests::fixtures::{
    self, bake_and_open, coloured_twill, huo_bsdf, succeeded, temp_dir,
};
use clothbake_tests::probe::MITSUBA;
use std::path::Path;

const SCRIPT: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/python/mitsuba_render.py");
const RES: usize = 48;
/// Samples per pixel of the spectral render: each carries 4 wavelengths, and the colour noise
/// of wavelength sampling is several percent per pixel at the RGB render's 16.
const SPECTRAL_SPP: u32 = 256;

fn read_le<const N: usize, T>(path: &Path, f: fn([u8; N]) -> T) -> Vec<T> {
    std::fs::read(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .chunks_exact(N)
        .map(|c| f(c.try_into().unwrap()))
        .collect()
}

fn python(args: &[&str]) {
    succeeded(
        &format!("mitsuba_render.py {args:?}"),
        &fixtures::python(SCRIPT, args),
    );
}

/// The twill with a coloured albedo, so that the three channels differ.
fn fabric() -> Fabric {
    coloured_twill()
}

/// What one comparison found.
struct Compared {
    rel_rmse: f64,
    worst: f64,
    pixels: usize,
    mitsuba: String,
}

/// Exports `source` (f_r, 1/sr, RGB) as `colour` on the default grid, renders it with Mitsuba's
/// `variant`, and compares each inside pixel with E f_r_model(light, eye) cos(theta_light).
/// Writes `<prefix>_mitsuba.png` and `<prefix>_reference.png` under CLOTHBAKE_FIGURES if set.
fn render_and_compare(
    tag: &str,
    source: &dyn Bsdf,
    colour: rgl::Colour,
    variant: &str,
    spp: u32,
    prefix: &str,
) -> Compared {
    let dir = temp_dir(&format!("mitsuba-{tag}"));
    let f = fabric();
    let model = AnalyticModel::new(&f, FacetModel::Huo);
    let brdf = AnalyticBsdf::new(model.clone(), None);
    let fields = rgl::rgl_fields(source, &rgl::DEFAULT_GRID, "clothbake test: twill", colour);
    let bsdf = dir.join("twill.bsdf");
    clothbake_export::write_file(&bsdf, &rgl::tensor_file(&fields), true).unwrap();

    let out = dir.join("out");
    python(&[
        "render",
        bsdf.to_str().unwrap(),
        out.to_str().unwrap(),
        "--res",
        &RES.to_string(),
        "--spp",
        &spp.to_string(),
        "--variant",
        variant,
    ]);
    let scene: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("scene.json")).unwrap()).unwrap();
    let e = scene["irradiance"].as_f64().unwrap();
    let img = read_le(&out.join("render.f32"), f32::from_le_bytes);
    let pairs = read_le(&out.join("pairs.f64"), f64::from_le_bytes);
    let mask = std::fs::read(out.join("mask.u8")).unwrap();
    assert_eq!(
        (img.len(), pairs.len(), mask.len()),
        (RES * RES * 3, RES * RES * 6, RES * RES)
    );

    let mut reference = vec![0f32; RES * RES * 3];
    let (mut se, mut sr, mut n) = (0.0, 0.0, 0);
    let mut worst: f64 = 0.0;
    // Pixels on the rectangle's outline average plane and background: only pixels whose 8
    // neighbours' centres all hit the plane are compared.
    let inside = |p: usize| {
        let (x, y) = ((p % RES) as i64, (p / RES) as i64);
        (-1..=1).all(|dy| {
            (-1..=1).all(|dx| {
                let (u, v) = (x + dx, y + dy);
                (0..RES as i64).contains(&u)
                    && (0..RES as i64).contains(&v)
                    && mask[(v * RES as i64 + u) as usize] == 1
            })
        })
    };
    for p in 0..RES * RES {
        if !inside(p) {
            continue;
        }
        let q = &pairs[6 * p..6 * p + 6];
        let light = UnitVec3::new(Vec3::new(q[0], q[1], q[2])).unwrap();
        let eye = UnitVec3::new(Vec3::new(q[3], q[4], q[5])).unwrap();
        let fr = brdf.f(light, eye);
        for c in 0..3 {
            let want = e * fr[c] * light.cos_theta();
            let got = img[3 * p + c] as f64;
            reference[3 * p + c] = want as f32;
            se += (got - want).powi(2);
            sr += want * want;
            worst = worst.max((got - want).abs() / want.max(1e-3));
        }
        n += 1;
    }
    assert!(n > RES * RES / 3, "the rectangle covers only {n} pixels");
    if let Ok(figs) = std::env::var("CLOTHBAKE_FIGURES") {
        let bytes: Vec<u8> = reference.iter().flat_map(|v| v.to_le_bytes()).collect();
        std::fs::write(out.join("reference.f32"), bytes).unwrap();
        python(&["png", out.to_str().unwrap(), &figs, prefix]);
    }
    std::fs::remove_dir_all(&dir).unwrap();
    Compared {
        rel_rmse: (se / sr).sqrt(),
        worst,
        pixels: n,
        mitsuba: scene["mitsuba"].to_string(),
    }
}

fn report(what: &str, c: &Compared) {
    eprintln!(
        "Mitsuba {} {what} vs the model: relative RMSE {:.3}% over {} pixels, worst pixel {:.2}%",
        c.mitsuba,
        100.0 * c.rel_rmse,
        c.pixels,
        100.0 * c.worst
    );
    assert!(c.rel_rmse < 0.05, "relative RMSE {}", c.rel_rmse);
}

#[test]
#[cfg_attr(
    missing_mitsuba,
    ignore = "needs the mitsuba and numpy Python packages: python3 -m pip install mitsuba numpy, or run `cargo xtask test`"
)]
fn mitsuba_renders_the_exported_bsdfs_like_the_model() {
    // The model's own f_r as the RGB file in scalar_rgb, and as the spectral file: Mitsuba
    // samples wavelengths, interpolates `spectra` between our nodes, multiplies by its D65
    // light and integrates against the CIE curves into sRGB.
    MITSUBA.require();
    let model = huo_bsdf(&fabric());
    for (tag, colour, variant, spp, prefix, what) in [
        (
            "rgb",
            rgl::Colour::Rgb,
            "scalar_rgb",
            16,
            "rgl",
            "scalar_rgb, RGB file",
        ),
        (
            "spectral",
            rgl::Colour::Spectral,
            "scalar_spectral",
            SPECTRAL_SPP,
            "rgl_spectral",
            "scalar_spectral, spectral file",
        ),
    ] {
        let c = render_and_compare(tag, &model, colour, variant, spp, prefix);
        report(what, &c);
    }
}

#[test]
#[cfg_attr(
    missing_mitsuba,
    ignore = "needs the mitsuba and numpy Python packages: python3 -m pip install mitsuba numpy, or run `cargo xtask test`"
)]
fn mitsuba_renders_the_export_of_a_baked_table_like_the_model() {
    // The twill baked at the default grid (f16 EXR), exported through the loader's lookup.
    MITSUBA.require();
    let dir = temp_dir("baked-table");
    let lookup = bake_and_open(&fabric(), &dir.join("twill.exr"));
    let source = lookup;
    let c = render_and_compare(
        "table",
        &source,
        rgl::Colour::Rgb,
        "scalar_rgb",
        16,
        "rgl_table",
    );
    std::fs::remove_dir_all(&dir).unwrap();
    report("scalar_rgb, RGB file from the baked table", &c);
}
