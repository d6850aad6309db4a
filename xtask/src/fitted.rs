//! `cargo xtask fitted`: the residuals of the fitted standard materials for every shipped
//! fabric (the analytic model, Huo facets, one bounce, per crossing cell), into the table of
//! `docs/guide/export.md` between its `fitted-residuals` markers. The numbers are those
//! `clothbake export --weave F --gltf --mtlx --blender` prints (the same library calls);
//! crates/clothbake/tests/export_fitted_cli.rs holds the table to the command's output.

use clothbake_core::{AnalyticBsdf, AnalyticModel, Fabric, FacetModel};
use clothbake_export::fits::Fits;
use clothbake_export::fitted::fit::Residual;
use clothbake_export::fitted::material::{Cells, Source};
use clothbake_export::fitted::microfacet::Albedos;
use clothbake_export::fitted::IOR;
use clothbake_tests::fixtures::shipped_files;
use std::fmt::Write as _;
use std::path::Path;

fn cell(r: &Residual) -> String {
    format!(
        "{:.1}% / {:.1}% / {:.1}%",
        100.0 * r.albedo_mean,
        100.0 * r.albedo_max,
        100.0 * r.l2
    )
}

/// The task: see the module documentation.
pub fn run(root: &Path) {
    let t = Albedos::new(IOR);
    let mut rows = String::new();
    let shipped = [shipped_files("json"), shipped_files("wif")].concat();
    for path in shipped {
        let fabric = Fabric::from_path(&path).expect("a shipped fabric reads");
        let b = AnalyticBsdf::new(AnalyticModel::new(&fabric, FacetModel::Huo), None);
        let (u_edges, v_edges) = b.model().cells().edge_fractions();
        let (nu, nv) = (u_edges.len() - 1, v_edges.len() - 1);
        let src = Source {
            average: &b,
            cells: Some(Cells {
                bsdf: &b,
                u_edges,
                v_edges,
            }),
        };
        let start = std::time::Instant::now();
        let f = Fits::new(&src, &t, true, true);
        let file = path.file_name().unwrap().to_string_lossy().into_owned();
        eprintln!("{file}: {:.1} s", start.elapsed().as_secs_f64());
        writeln!(
            rows,
            "| {file} | {nu} x {nv} | {} | {} | {} |",
            cell(&f.gltf_residual),
            cell(&f.openpbr_residual),
            cell(&f.blender_residual)
        )
        .unwrap();
    }
    let out = format!(
        "<!-- fitted-residuals:begin -->\nWritten by `cargo xtask fitted`: each shipped fabric's \
         analytic model (Huo facets, one bounce) fitted per crossing cell, as the files hold \
         it, against the averaged BRDF. Each entry: the directional albedo's relative error, \
         mean / maximum over view directions, then the relative L2 error of f_r cos(theta_i) \
         over all pairs of directions.\n\n\
         | fabric | cells | glTF (specification) | OpenPBR (MaterialX, USD) | Blender (Cycles) |\n\
         |---|---|---|---|---|\n{rows}<!-- fitted-residuals:end -->"
    );
    crate::replace_section(&root.join("docs/guide/export.md"), "fitted-residuals", &out);
    println!("{out}");
}
