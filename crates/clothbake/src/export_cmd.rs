//! `clothbake export`: the BRDF of the analytic model (`--weave`) or of a baked table
//! (`--table`, through the loader's lookup) as an RGL `.bsdf` (RGB for Mitsuba 3, spectral for
//! pbrt-v4 and Mitsuba's spectral variants), a MERL binary, a Klems BSDF XML for daylighting
//! tools (with the datasheet figures), and/or fitted standard materials
//! (glTF, MaterialX, USD, Blender: `export_fitted`), each written atomically.
//! Formats and conventions: `docs/guide/export.md`.

use crate::cli::{ExportArgs, Faces};
use crate::error::CliError;
use crate::resolve::{self, preflight};
use clothbake_bake::memory;
use clothbake_bake::two_faced::TwoFaced;
use clothbake_core::symmetry::{symmetries, Symmetry};
use clothbake_core::{AnalyticBsdf, AnalyticModel, Fabric, FacetModel, Variant};
use clothbake_export::fitted::material::{Cells, Source};
use clothbake_export::{self as export, klems, merl, rgl, spectrum, Bsdf};
use std::fmt::Write as _;
use std::path::PathBuf;
use std::time::Instant;

/// Runs `clothbake export` and returns the summary for stdout (empty with --quiet).
pub fn run(args: &ExportArgs) -> Result<String, CliError> {
    let outputs: Vec<&PathBuf> = [
        &args.rgl,
        &args.rgl_spectral,
        &args.merl,
        &args.klems,
        &args.gltf,
        &args.mtlx,
        &args.usd,
        &args.blender,
    ]
    .into_iter()
    .flatten()
    .collect();
    if outputs.is_empty() {
        return Err(CliError::new(
            "nothing to export",
            "give --rgl OUT.bsdf (Mitsuba 3), --rgl-spectral OUT.bsdf (pbrt-v4, Mitsuba 3 \
             spectral), --merl OUT.binary, --klems OUT.xml (daylighting: Radiance, WINDOW), or a fitted material: --gltf OUT.glb (the web), \
             --mtlx OUT.mtlx (MaterialX), --usd OUT.usda, --blender OUT.py",
        ));
    }
    for (i, a) in outputs.iter().enumerate() {
        if outputs[..i].contains(a) {
            return Err(CliError::new(
                format!("two outputs name the same file {}", a.display()),
                "give each format its own output path",
            ));
        }
    }
    match (&args.weave, &args.table) {
        (Some(_), Some(_)) => Err(CliError::new(
            "--weave and --table both given",
            "export either the model of a fabric (--weave FILE) or a baked table (--table T)",
        )),
        (None, None) => Err(CliError::new(
            "nothing to export from",
            "give --weave FILE (the analytic model of a fabric) or --table T.exr|T.bin (a baked \
             table)",
        )),
        (Some(weave), None) if args.faces == Faces::Two => {
            let reflection_only = [
                (&args.rgl, "--rgl"),
                (&args.rgl_spectral, "--rgl-spectral"),
                (&args.merl, "--merl"),
                (&args.gltf, "--gltf"),
                (&args.mtlx, "--mtlx"),
                (&args.usd, "--usd"),
                (&args.blender, "--blender"),
            ];
            if let Some((_, flag)) = reflection_only.iter().find(|(o, _)| o.is_some()) {
                return Err(CliError::new(
                    format!("{flag} holds reflection only, and --faces two transmits"),
                    format!("export the two-faced cloth with --klems alone, or drop --faces two for {flag}"),
                ));
            }
            let b = &args.bounces;
            if let Some(flag) = (b.bounces != 1)
                .then_some("--bounces")
                .or(b.secondary_flag())
            {
                return Err(CliError::new(
                    format!(
                        "{flag} does not apply to the two-faced cloth: its f holds every bounce"
                    ),
                    format!("drop {flag}"),
                ));
            }
            let (fabric, facet, variant) = model_of(args, weave)?;
            let tf = TwoFaced::new(&fabric, facet, variant.into())?;
            let threads = resolve::thread_count(args.run.threads);
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .map_err(|e| CliError::line(format!("cannot start {threads} threads: {e}")))?
                .install(|| tf.prepare());
            let source = format!(
                "fabric {}; the two-faced cloth (docs/science/transmission.md): analytic direct reflection \
                 (facet {}, variant {}) and openness, the rest path-traced on a coarse grid",
                fabric.name(),
                facet_name(facet),
                Variant::from(variant).name(),
            );
            write_all(args, &tf, None, fabric.name(), &source, false, 0)
        }
        (Some(weave), None) => {
            let secondary = args.bounces.options()?;
            let secondary = (args.bounces.bounces == 2).then_some(secondary);
            let (fabric, facet, variant) = model_of(args, weave)?;
            let model = AnalyticModel::with_variant(&fabric, facet, variant.into())?;
            let variant_name = model.variant().name();
            let analytic = AnalyticBsdf::new(model, secondary);
            let (u_edges, v_edges) = analytic.model().cells().edge_fractions();
            // Full transport: the analytic terms plus the path-traced orders (docs/science/transport.md).
            let full = (args.bounces.bounces > 2)
                .then(|| {
                    clothbake_bake::transport::FullTransport::new(
                        &fabric,
                        facet,
                        variant.into(),
                        args.bounces.bounces,
                    )
                })
                .transpose()?;
            let brdf: &dyn Bsdf = match &full {
                Some(f) => f,
                None => &analytic,
            };
            // The crossing cells resolve the fitted materials' textures (the model without
            // its yarns answers a point with its cell); full transport has no cells.
            let cells = full.is_none().then_some(Cells {
                bsdf: &analytic,
                u_edges,
                v_edges,
            });
            let source = format!(
                "fabric {}; f_r cos(theta_light) of the analytic model (facet {}, variant {}, \
                 bounces {})",
                fabric.name(),
                facet_name(facet),
                variant_name,
                args.bounces.bounces
            );
            // A fabric unchanged by a half turn has a BRDF unchanged by it: half the rotations.
            let half_turn = symmetries(&fabric).contains(&Symmetry::Rotate180);
            write_all(args, brdf, cells, fabric.name(), &source, half_turn, 0)
        }
        (None, Some(table)) => {
            refuse_model_options(args)?;
            let options = clothbake_loader::Options {
                sampling: false,
                point_level: false,
                ..Default::default()
            };
            let lookup = clothbake_loader::Brdf::open(table, options).map_err(|e| match e {
                // The loader's own fix names its Rust types; here the command that works.
                clothbake_loader::TableError::WrongKind { .. } => CliError::new(
                    format!(
                        "{}: a two-faced table (reflection and transmission over the sphere), \
                         which the exports from a table do not take",
                        table.display()
                    ),
                    "export the two-faced cloth from its fabric: clothbake export --weave \
                     FABRIC --faces two --klems OUT.xml",
                ),
                other => other.into(),
            })?;
            refuse_existing(args)?;
            let meta = lookup.meta();
            let g = meta.grid;
            let name = Fabric::from_json_str(&meta.fabric_json, "table metadata").map_or_else(
                |_| "(unreadable fabric metadata)".to_string(),
                |f| f.name().to_string(),
            );
            let source = format!(
                "fabric {name}; f_r cos(theta_light) looked up (quadrilinear interpolation) in \
                 the table {} ({}, {} x {} x {} x {} cells, bake options {}); the table's fabric \
                 file: {}",
                table.display(),
                meta.tool,
                g.n_theta_i,
                g.n_phi_i,
                g.n_theta_o,
                g.n_phi_o,
                meta.options_json,
                meta.fabric_json
            );
            // A spatial table resolves the crossing cells (its point level is off: a point
            // answers with its cell).
            let cells = meta.spatial.as_ref().map(|s| Cells {
                bsdf: &lookup,
                u_edges: s.u_edges.clone(),
                v_edges: s.v_edges.clone(),
            });
            // No half-turn shortcut for a table: lookups are cheap, and the interpolated table
            // need not be exactly symmetric.
            let held = lookup.memory_bytes() as u64;
            write_all(args, &lookup, cells, &name, &source, false, held)
        }
    }
}

/// An error for each model option given with --table (a table holds what it was baked with).
/// The fabric of --weave with the material options, its outputs checked, and the model's
/// facet and variant.
fn model_of(
    args: &ExportArgs,
    weave: &std::path::Path,
) -> Result<(Fabric, FacetModel, crate::cli::VariantArg), CliError> {
    let fabric = resolve::fabric_of(weave, &args.material)?;
    refuse_existing(args)?;
    let facet = FacetModel::from(args.facet.unwrap_or(crate::cli::FacetArg::Huo));
    let variant = args.variant.unwrap_or_default();
    resolve::variant(weave, &fabric, variant)?;
    Ok((fabric, facet, variant))
}

fn refuse_model_options(args: &ExportArgs) -> Result<(), CliError> {
    let m = &args.material;
    let b = &args.bounces;
    let given = [
        args.facet.is_some().then_some("--facet"),
        args.variant.is_some().then_some("--variant"),
        (b.bounces != 1).then_some("--bounces"),
        b.secondary_flag(),
        m.albedo.is_some().then_some("--albedo"),
        m.specular.is_some().then_some("--specular"),
        m.exponent.is_some().then_some("--exponent"),
        m.translucency.is_some().then_some("--translucency"),
        (args.faces == Faces::Two).then_some("--faces"),
    ];
    match given.into_iter().flatten().next() {
        Some(flag) => Err(CliError::new(
            format!("{flag} applies to the model, not to a table"),
            "drop it (a table holds what it was baked with), or export the model with --weave",
        )),
        None => Ok(()),
    }
}

/// Checks every output before any work is done ([`preflight`]).
fn refuse_existing(args: &ExportArgs) -> Result<(), CliError> {
    crate::export_fitted::check_stems(args)?;
    let fitted = crate::export_fitted::outputs(args);
    let mut outputs: Vec<(&std::path::Path, &str)> = [
        (&args.rgl, "RGL file"),
        (&args.rgl_spectral, "spectral RGL file"),
        (&args.merl, "MERL file"),
        (&args.klems, "Klems BSDF XML file"),
    ]
    .into_iter()
    .filter_map(|(p, what)| Some((p.as_deref()?, what)))
    .collect();
    outputs.extend(fitted.iter().map(|(p, what)| (p.as_path(), what.as_str())));
    let inputs: Vec<&std::path::Path> = [&args.weave, &args.table]
        .into_iter()
        .filter_map(|p| p.as_deref())
        .collect();
    preflight(&outputs, args.run.force, &inputs)
}

/// Writes every requested file from `brdf`, which holds `held` bytes (a loaded table's);
/// `source` opens the RGL description.
fn write_all(
    args: &ExportArgs,
    brdf: &dyn Bsdf,
    cells: Option<Cells<'_>>,
    name: &str,
    source: &str,
    half_turn: bool,
    held: u64,
) -> Result<String, CliError> {
    let threads = resolve::thread_count(args.run.threads);
    let g = args.rgl_res.0;
    let n_cells = cells
        .as_ref()
        .map_or(1, |c| (c.u_edges.len() - 1) * (c.v_edges.len() - 1));
    check_memory(args, threads, held, n_cells)?;
    let pool = resolve::thread_pool(threads)?;
    let mut summary = String::new();
    let src = Source {
        average: brdf,
        cells,
    };
    // Fitted on the pool; written from this thread, where the command's outputs are batched
    // (moved into place together).
    summary += &crate::export_fitted::write(args, &src, name, &pool)?;
    // One evaluation of the slices serves both RGL files.
    let mut slices = None;
    for (out, colour) in [
        (&args.rgl, rgl::Colour::Rgb),
        (&args.rgl_spectral, rgl::Colour::Spectral),
    ] {
        let Some(out) = out else { continue };
        let start = Instant::now();
        let w = &spectrum::WAVELENGTHS;
        let colour_words = match colour {
            rgl::Colour::Rgb => "RGB (linear sRGB)".to_string(),
            rgl::Colour::Spectral => format!(
                "spectral, {} wavelengths {}-{} nm, linear upsampling of linear sRGB \
                 (docs/guide/export.md)",
                w.len(),
                w[0],
                w[w.len() - 1]
            ),
        };
        let description = format!(
            "clothbake {}: {source}; {colour_words}; view-direction grid {} x {} (+1), slices \
             {} x {}",
            env!("CARGO_PKG_VERSION"),
            g.n_theta,
            g.n_phi,
            g.n_slice,
            g.n_slice
        );
        let slices = slices.get_or_insert_with(|| pool.install(|| rgl::rgl_slices(brdf, &g)));
        // Streamed from the slices: nothing the size of the file is held.
        let fields = rgl::lazy_fields_of(slices, &description, colour);
        let mut size = 0;
        clothbake_loader::write_atomic_as(out, "exported file", args.run.force, |w| {
            size = rgl::write_tensor_file(w, &fields)?;
            Ok(())
        })?;
        let _ = writeln!(
            summary,
            "wrote {}: RGL tensor file ({}), view grid {} x {} (+1), slices {} x {}, {:.1} MB, \
             {:.2} s",
            out.display(),
            match colour {
                rgl::Colour::Rgb => "RGB",
                rgl::Colour::Spectral => "spectral",
            },
            g.n_theta,
            g.n_phi,
            g.n_slice,
            g.n_slice,
            size as f64 / 1e6,
            start.elapsed().as_secs_f64()
        );
    }
    if let Some(out) = &args.merl {
        let start = Instant::now();
        let table = pool.install(|| merl::merl_table(brdf, args.phi_samples, half_turn));
        export::write_file(out, &merl::merl_bytes(&table), args.run.force)?;
        let a = table.anisotropy;
        let _ = writeln!(
            summary,
            "wrote {}: MERL binary 90 x 90 x 180, averaged over {} rotations about the normal, \
             {:.2} s; anisotropy lost: relative spread over phi {:.1}% (luminance-weighted), \
             {:.1}% at most",
            out.display(),
            args.phi_samples,
            start.elapsed().as_secs_f64(),
            100.0 * a.weighted,
            100.0 * a.max
        );
    }
    if let Some(out) = &args.klems {
        let start = Instant::now();
        let k = pool.install(|| klems::evaluate(brdf, args.klems_samples));
        let description = klems::Description {
            name: name.to_string(),
            comment: format!(
                "clothbake {}: {source}; Klems entries averaged over {n} x {n} points of each \
                 patch (docs/guide/daylighting.md)",
                env!("CARGO_PKG_VERSION"),
                n = args.klems_samples
            ),
        };
        let mut size = 0;
        clothbake_loader::write_atomic_as(out, "exported file", args.run.force, |w| {
            size = klems::write_xml(w, &k, &description)?;
            Ok(())
        })?;
        let sheet = pool.install(|| klems::Datasheet::of(brdf));
        let _ = writeln!(
            summary,
            "wrote {}: LBNL/Radiance BSDF XML, Klems basis 145 x 145, front and back reflection \
             and transmission, Visible and Solar, {n} x {n} points a patch, {:.1} MB, {:.2} s\n\
             datasheet: {}",
            out.display(),
            size as f64 / 1e6,
            start.elapsed().as_secs_f64(),
            sheet.summary(),
            n = args.klems_samples
        );
    }
    Ok(if args.run.quiet {
        String::new()
    } else {
        summary
    })
}

/// The most memory the export takes (the program's [`memory::BASE_BYTES`], `held` bytes of a
/// loaded table, the RGL slices held and in evaluation, the MERL table; `RglGrid::peak_bytes`,
/// `merl::peak_bytes`), refused before any work when the machine has less available.
fn check_memory(
    args: &ExportArgs,
    threads: usize,
    held: u64,
    cells: usize,
) -> Result<(), CliError> {
    let rgl = if args.rgl.is_some() || args.rgl_spectral.is_some() {
        args.rgl_res.0.peak_bytes(threads)
    } else {
        0
    };
    let merl = args
        .merl
        .as_ref()
        .map_or(0, |_| merl::peak_bytes(args.phi_samples, threads));
    let fitted = if crate::export_fitted::wanted(args) {
        clothbake_export::fitted::material::Fitted::peak_bytes(cells)
    } else {
        0
    };
    let klems = args
        .klems
        .as_ref()
        .map_or(0, |_| klems::peak_bytes(threads));
    let need = memory::BASE_BYTES + held + rgl + merl + fitted + klems;
    match memory::available_bytes() {
        Some(have) if need > have => Err(CliError::new(
            format!(
                "this export needs up to {} of memory, but {} is available",
                memory::describe(need),
                memory::describe(have)
            ),
            "give a smaller --rgl-res (the slices hold 16 bytes a texel) or fewer --threads",
        )),
        _ => Ok(()),
    }
}

fn facet_name(f: FacetModel) -> &'static str {
    match f {
        FacetModel::Huo => "huo",
        FacetModel::Lewis => "lewis",
    }
}
