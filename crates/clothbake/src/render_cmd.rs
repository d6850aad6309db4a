//! `clothbake render` and `clothbake plot`: the command-line side of `clothbake_render` and
//! `clothbake_render::plot` (building the shader, checking outputs, progress, summary line).

use crate::cli::{
    BrdfArgs, ComponentArg, Exposure, Faces, PlotArgs, PlotKind, RenderArgs, SceneArg, TonemapArg,
};
use crate::error::{table_error, CliError};
use crate::resolve::{self, preflight, progress_bar};
use clothbake_core::{FacetModel, Vec3};
use clothbake_render::camera::{Camera, CameraError};
use clothbake_render::plot::{self, Plot, Source};
use clothbake_render::scene::Scene;
use clothbake_render::shade::{Component, Lighting, Shader};
use clothbake_render::tonemap::{self, Curve};
use clothbake_render::{self as renderer};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Instant;

/// The model shader of `--weave`, with its options checked.
fn model_shader(weave: &Path, b: &BrdfArgs) -> Result<Shader, CliError> {
    let opts = b.bounces.options()?;
    let secondary = (b.bounces.bounces == 2).then_some(opts);
    let component = match b.component {
        ComponentArg::Total => Component::Total,
        ComponentArg::Direct => Component::Direct,
        ComponentArg::Secondary => Component::Secondary,
        ComponentArg::Iss => Component::SecondarySpecular,
    };
    let fabric = resolve::fabric_of(weave, &b.material)?;
    let variant = resolve::variant(weave, &fabric, b.model.variant)?;
    if b.bounces.bounces > 2 {
        // Full transport: the analytic terms plus the path-traced orders (docs/science/transport.md),
        // whole only.
        if component != Component::Total {
            return Err(CliError::new(
                format!(
                    "--component {} with --bounces {}: full transport is drawn whole",
                    component_name(b.component),
                    clothbake_bake::transport::bounces_name(b.bounces.bounces)
                ),
                "use --component total, or --bounces 2 for the secondary reflection's parts",
            ));
        }
        let ft = clothbake_bake::transport::FullTransport::new(
            &fabric,
            FacetModel::from(b.model.facet),
            variant,
            b.bounces.bounces,
        )?;
        return Ok(Shader::new(Box::new(ft)));
    }
    Shader::model(
        &fabric,
        FacetModel::from(b.model.facet),
        variant,
        secondary,
        component,
    )
    .map_err(|m| {
        CliError::new(
            format!("--component {}: {m}", component_name(b.component)),
            "add --bounces 2, or use --component total or direct",
        )
    })
}

fn component_name(c: ComponentArg) -> &'static str {
    match c {
        ComponentArg::Total => "total",
        ComponentArg::Direct => "direct",
        ComponentArg::Secondary => "secondary",
        ComponentArg::Iss => "iss",
    }
}

/// The two-faced cloth's shader of `render --faces two`: the fabric of --weave, whole, averaged
/// over the period, or a two-faced table (--table, baked with --faces two).
fn two_faced_shader(a: &RenderArgs) -> Result<Shader, CliError> {
    if let ([table], None) = (a.brdf.table.as_slice(), &a.brdf.weave) {
        let shader = table_shader(table)?;
        if !shader.is_two_faced() {
            return Err(CliError::new(
                format!(
                    "{} is a one-faced table (reflection over the floor), and --faces two draws \
                     the two-faced cloth",
                    table.display()
                ),
                "bake the table with --faces two, or drop --faces two",
            ));
        }
        return Ok(shader);
    }
    let Some(weave) = &a.brdf.weave else {
        return Err(CliError::new(
            "--faces two draws a fabric's two-faced cloth, and no --weave or --table was given",
            "give --weave FILE (e.g. tables/basket.json) or a table baked with --faces two",
        ));
    };
    let b = &a.brdf.bounces;
    let refused = [
        ("--table", !a.brdf.table.is_empty()),
        ("--truth", a.truth),
        ("--periods", a.periods.is_some()),
        ("--gaps", a.gaps),
        ("--bounces", b.bounces != 1),
        ("--component", a.brdf.component != ComponentArg::Total),
    ];
    if let Some((flag, _)) = refused.iter().find(|(_, given)| *given) {
        return Err(CliError::new(
            format!(
                "{flag} does not apply with --faces two: the two-faced cloth is drawn whole \
                 (every bounce, averaged over the period, its gaps as openness)"
            ),
            format!("drop {flag}, or drop --faces two"),
        ));
    }
    let fabric = resolve::fabric_of(weave, &a.brdf.material)?;
    let variant = resolve::variant(weave, &fabric, a.brdf.model.variant)?;
    Shader::two_faced(&fabric, FacetModel::from(a.brdf.model.facet), variant)
        .map_err(CliError::line)
}

/// The ground truth's shader of `render --truth`: the fabric of --weave, one bounce, with
/// --periods.
fn truth_shader(a: &RenderArgs) -> Result<Shader, CliError> {
    let b = &a.brdf;
    let Some(weave) = &b.weave else {
        return Err(CliError::new(
            "--truth traces a fabric's yarns, and no --weave was given",
            "give --weave FILE (e.g. tables/twill.json) with --truth",
        ));
    };
    if a.periods.is_none() {
        return Err(CliError::new(
            "--truth needs --periods: the yarns are tiled over the surface N periods across",
            "add --periods N (e.g. --periods 8)",
        ));
    }
    if b.component != ComponentArg::Total || b.bounces.secondary_flag().is_some() {
        return Err(CliError::new(
            "--truth traces the yarns whole: --component and the secondary-reflection options do not apply",
            "drop --component, --secondary, --kernel, --orders and --sampling with --truth",
        ));
    }
    // Every bounce up to --bounces N (all: the highest order full transport follows), a
    // path a point, with Russian roulette and the radiometric kernel as full transport has.
    let paths = (b.bounces.bounces > 1).then(|| clothbake_truth::PathOptions {
        max_bounces: (b.bounces.bounces as usize).min(clothbake_bake::transport::MAX_ORDER),
        ..clothbake_truth::PathOptions::default()
    });
    let fabric = resolve::fabric_of(weave, &b.material)?;
    Ok(Shader::truth(
        &fabric,
        FacetModel::from(b.model.facet),
        1,
        paths,
    ))
}

/// The shader of a baked table (the loader's interpolated lookup).
fn table_shader(path: &Path) -> Result<Shader, CliError> {
    Shader::table(path).map_err(|e| table_error(&e))
}

/// Options that only apply to the model, given with --table.
fn check_model_only(b: &BrdfArgs) -> Result<(), CliError> {
    let model_only = b.bounces.bounces != 1
        || b.bounces.secondary_flag().is_some()
        || b.component != ComponentArg::Total
        || b.material != Default::default();
    if model_only {
        return Err(CliError::new(
            "--bounces, --secondary, --kernel, --orders, --sampling, --component and the \
             material overrides apply only to the model (--weave); a table already holds its \
             BRDF",
            "drop them, or bake a table with those options",
        ));
    }
    Ok(())
}

/// A named BRDF source.
type Named = (String, Shader);

/// The sources named on the command line, in order: tables first, then the model.
fn sources(b: &BrdfArgs, most: usize) -> Result<Vec<Named>, CliError> {
    let n = b.table.len() + usize::from(b.weave.is_some());
    if n == 0 {
        return Err(CliError::new(
            "no BRDF given",
            "give --weave FILE (the model, e.g. tables/twill.json) or --table FILE (a baked table)",
        ));
    }
    if n > most {
        return Err(CliError::new(
            format!("{n} BRDF sources given, at most {most} here",),
            if most == 1 {
                "give either --weave FILE or one --table FILE"
            } else {
                "give two of --weave FILE and --table FILE to compare"
            },
        ));
    }
    if !b.table.is_empty() && b.weave.is_none() {
        check_model_only(b)?;
    }
    let mut out: Vec<Named> = Vec::new();
    for t in &b.table {
        out.push((file_name(t), table_shader(t)?));
    }
    if let Some(w) = &b.weave {
        out.push((format!("model {}", file_name(w)), model_shader(w, b)?));
    }
    Ok(out)
}

/// The files a BRDF is read from (its fabric file and tables): no output may be one of them.
fn inputs(b: &BrdfArgs) -> Vec<&Path> {
    b.weave
        .iter()
        .chain(&b.table)
        .map(PathBuf::as_path)
        .collect()
}

fn file_name(p: &Path) -> String {
    p.file_name().map_or_else(
        || p.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    )
}

fn vec3(v: [f64; 3]) -> Vec3 {
    Vec3::new(v[0], v[1], v[2])
}

/// The render's progress line: rows of pixels.
const RENDER_BAR: &str = "{elapsed_precise} [{wide_bar}] {percent:>3}% {pos}/{len} rows, ETA {eta}";

/// Runs `clothbake render`; returns the summary line.
pub fn run_render(a: &RenderArgs) -> Result<String, CliError> {
    let shader = if a.faces == Faces::Two {
        two_faced_shader(a)?
    } else {
        let mut srcs = sources(&a.brdf, 1)?;
        srcs.pop().expect("one source").1
    };
    let shader = if a.truth { truth_shader(a)? } else { shader };
    let shader = if a.gaps { shader.with_gaps() } else { shader };
    let mut outputs = vec![(a.output.as_path(), "PNG image")];
    if let Some(e) = &a.exr {
        outputs.push((e.as_path(), "OpenEXR image"));
    }
    preflight(&outputs, a.run.force, &inputs(&a.brdf))?;
    let scene = Scene::by_name(match a.scene {
        SceneArg::Drape => "drape",
        SceneArg::Sphere => "sphere",
        SceneArg::Disk => "disk",
        SceneArg::Swatch => "swatch",
    })
    .expect("a known scene");
    let light = vec3(a.light);
    if light.length() < 1e-12 {
        return Err(CliError::new(
            "--light 0,0,0 has no direction",
            "give the direction toward the light, e.g. --light 0,0.707,0.707",
        ));
    }
    let (eye, look_at) = (vec3(a.eye), vec3(a.look_at));
    let fov = a.fov.unwrap_or_else(|| {
        let (lo, hi) = scene.bounds();
        Camera::fitting_fov(eye, look_at, a.res.0, a.res.1, lo, hi)
    });
    let (w, h) = a.res;
    let camera = Camera::new(eye, look_at, fov, w, h).map_err(|e| match e {
        CameraError::EyeAtTarget => CliError::new(
            "--eye and --look-at are the same point",
            "move the eye away from the point it looks at",
        ),
        CameraError::BadFov(f) => CliError::new(
            format!("field of view {f} is outside (0, 180) degrees"),
            "give --fov between 0 and 180",
        ),
    })?;
    let lighting = Lighting {
        light: light * (1.0 / light.length()),
        irradiance: a.irradiance.unwrap_or(std::f64::consts::PI),
        ambient: a.ambient,
    };
    let threads = resolve::thread_count(a.run.threads);
    let pool = resolve::thread_pool(threads)?;
    let start = Instant::now();
    let bar = progress_bar(u64::from(h), RENDER_BAR, a.run.quiet);
    let shown = AtomicU64::new(0);
    let progress = |n: u64| {
        if let Some(b) = &bar {
            b.set_position(shown.fetch_max(n, Ordering::Relaxed).max(n));
        }
    };
    let never = AtomicBool::new(false);
    let img = pool
        .install(|| {
            renderer::render_weave(
                &scene, &camera, &lighting, &shader, a.aa, a.periods, &progress, &never,
            )
        })
        .expect("never cancelled");
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let exposure = match a.exposure {
        Exposure::Factor(x) => x,
        Exposure::Auto => tonemap::auto_exposure(&img),
    };
    let curve = match a.tonemap {
        TonemapArg::Clamp => Curve::Clamp,
        TonemapArg::Reinhard => Curve::Reinhard,
    };
    let rgb = tonemap::to_rgb8(&img, exposure, curve);
    tonemap::write_png_rgb8(&a.output, w, h, &rgb, a.run.force)?;
    let mut wrote = a.output.display().to_string();
    if let Some(e) = &a.exr {
        tonemap::write_exr(e, &img, a.run.force)?;
        wrote = format!("{wrote} and {}", e.display());
    }
    if a.run.quiet {
        return Ok(String::new());
    }
    Ok(format!(
        "wrote {wrote}: {w}x{h} pixels, {} samples each, fov {fov:.1} deg, exposure {exposure:.4}, \
         max value {:.4}, {:.2} s on {threads} thread{}\n",
        a.aa * a.aa,
        img.max_value(),
        start.elapsed().as_secs_f64(),
        if threads == 1 { "" } else { "s" },
    ))
}

/// Runs `clothbake plot`; returns the summary line.
pub fn run_plot(a: &PlotArgs) -> Result<String, CliError> {
    let outputs: Vec<PathBuf> = if a.output.is_empty() {
        vec!["plot.png".into(), "plot.svg".into()]
    } else {
        a.output.clone()
    };
    for o in &outputs {
        let ext = o
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        if !matches!(ext.as_deref(), Some("png" | "svg")) {
            return Err(CliError::new(
                format!("{}: unknown plot format", o.display()),
                "name the output .png or .svg (repeat -o for both)",
            ));
        }
    }
    let kinds: Vec<(&Path, &str)> = outputs.iter().map(|o| (o.as_path(), "plot")).collect();
    preflight(&kinds, a.force, &inputs(&a.brdf))?;
    let p = match a.kind {
        PlotKind::Slices => Plot::Slices {
            theta_i: a.theta_i.clone(),
            phi_i: a.phi_i.clone(),
        },
        PlotKind::Hemisphere | PlotKind::Polar => {
            if !a.wi.above_horizon() {
                return Err(CliError::new(
                    "--wi is at the horizon, where nothing is lit",
                    "give theta below 90, e.g. --wi 45,0",
                ));
            }
            if a.kind == PlotKind::Hemisphere {
                Plot::Hemisphere {
                    theta_i: a.wi.theta,
                    phi_i: a.wi.phi,
                }
            } else {
                Plot::Polar {
                    theta_i: a.wi.theta,
                    phi_i: a.wi.phi,
                    theta_o: a.theta_o.clone(),
                }
            }
        }
    };
    if let Err(t) = p.check() {
        let flag = t.list.replace('_', "-");
        return Err(CliError::new(
            format!(
                "--{flag} lists {} angles, more than the {} one plot holds",
                t.len, t.max
            ),
            format!("give at most {} angles (or draw several plots)", t.max),
        ));
    }
    let srcs = sources(&a.brdf, 2)?;
    let sources: Vec<Source<'_>> = srcs
        .iter()
        .map(|(name, s)| Source {
            name: name.clone(),
            shader: s,
        })
        .collect();
    for o in &outputs {
        plot::write(o, &p, &sources, a.force).map_err(|m| {
            CliError::new(
                format!("cannot draw the plot: {m}"),
                "check the output path",
            )
        })?;
    }
    Ok(format!(
        "wrote {}\n",
        outputs
            .iter()
            .map(|o| o.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ))
}
