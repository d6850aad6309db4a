//! `clothbake export`: the analytic model's BRDF as an RGL `.bsdf` (Mitsuba 3) and/or a MERL
//! binary, each written atomically. Formats and conventions: `docs/export.md`.

use crate::cli::ExportArgs;
use crate::error::CliError;
use crate::eval_cmd::apply_material;
use clothbake::export::{self, merl, rgl};
use clothbake_core::symmetry::{symmetries, Symmetry};
use clothbake_core::{AnalyticModel, Fabric, FacetModel};
use clothbake_loader::TableError;
use std::fmt::Write as _;
use std::time::Instant;

/// Runs `clothbake export` and returns the summary for stdout (empty with --quiet).
pub fn run(args: &ExportArgs) -> Result<String, CliError> {
    if args.rgl.is_none() && args.merl.is_none() {
        return Err(CliError::new(
            "nothing to export",
            "give --rgl OUT.bsdf (Mitsuba 3) and/or --merl OUT.binary",
        ));
    }
    if args.rgl.is_some() && args.rgl == args.merl {
        return Err(CliError::new(
            "--rgl and --merl name the same file",
            "give each format its own output path",
        ));
    }
    let secondary = args.bounces.options()?;
    let secondary = (args.bounces.bounces == 2).then_some(secondary);
    let fabric = Fabric::from_path(&args.weave)?;
    let fabric = apply_material(fabric, &args.material);
    for out in [&args.rgl, &args.merl].into_iter().flatten() {
        if !args.force && std::fs::symlink_metadata(out).is_ok() {
            return Err(TableError::AlreadyExists { path: out.clone() }.into());
        }
    }
    let facet = FacetModel::from(args.facet);
    let model = AnalyticModel::with_variant(&fabric, facet, args.variant.into());
    let brdf = export::model_brdf(&model, secondary);
    let threads = crate::bake_cmd::thread_count(args.threads);
    let pool = crate::bake_cmd::thread_pool(threads)?;
    let mut summary = String::new();
    if let Some(out) = &args.rgl {
        let start = Instant::now();
        let g = args.rgl_res.0;
        let description = format!(
            "clothbake {}: fabric {}; f_r cos(theta_light) of the analytic model (facet {}, \
             variant {}, bounces {}); view-direction grid {} x {} (+1), slices {} x {}",
            env!("CARGO_PKG_VERSION"),
            fabric.name,
            facet_name(facet),
            model.variant().name(),
            args.bounces.bounces,
            g.n_theta,
            g.n_phi,
            g.n_slice,
            g.n_slice
        );
        let fields = pool.install(|| rgl::rgl_fields(&brdf, &g, &description));
        let bytes = rgl::tensor_file(&fields);
        export::write_file(out, &bytes, args.force)?;
        let _ = writeln!(
            summary,
            "wrote {}: RGL tensor file (RGB), view grid {} x {} (+1), slices {} x {}, {:.1} MB, \
             {:.2} s",
            out.display(),
            g.n_theta,
            g.n_phi,
            g.n_slice,
            g.n_slice,
            bytes.len() as f64 / 1e6,
            start.elapsed().as_secs_f64()
        );
    }
    if let Some(out) = &args.merl {
        let start = Instant::now();
        // A fabric unchanged by a half turn has a BRDF unchanged by it: half the rotations.
        let half_turn = symmetries(&fabric).contains(&Symmetry::Rotate180);
        let table = pool.install(|| merl::merl_table(&brdf, args.phi_samples, half_turn));
        export::write_file(out, &merl::merl_bytes(&table), args.force)?;
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
    Ok(if args.quiet { String::new() } else { summary })
}

fn facet_name(f: FacetModel) -> &'static str {
    match f {
        FacetModel::Huo => "huo",
        FacetModel::Lewis => "lewis",
    }
}
