//! `clothbake export --gltf/--mtlx/--usd/--blender`: fitted standard materials
//! (docs/guide/export.md, "Fitted materials").

use crate::cli::ExportArgs;
use crate::error::CliError;
use clothbake_bake::output::same_file;
use clothbake_export::fits::Fits;
use clothbake_export::fitted::material::{Fitted, Source};
use clothbake_export::fitted::microfacet::Albedos;
use clothbake_export::fitted::IOR;
use clothbake_export::{self as export, gltf, openpbr};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The outputs of the fitted targets with what each is, for the check of the command's outputs
/// as one set; the maps beside the MaterialX and USD files included (whether or not the
/// material turns out textured: that is known only after the fit), each named with the file
/// that refers to it. Nothing is merged here: a map that names the same file as another output
/// is a clash the check reports (only the maps that the MaterialX and the USD file share, by
/// one stem in one folder, are one output: [`map_stems`]).
pub fn outputs(args: &ExportArgs) -> Vec<(PathBuf, String)> {
    let mut out: Vec<(PathBuf, String)> = Vec::new();
    for (p, what) in [
        (&args.gltf, "glTF file"),
        (&args.mtlx, "MaterialX file"),
        (&args.usd, "USD file"),
        (&args.blender, "Blender module"),
    ] {
        if let Some(p) = p {
            out.push((p.clone(), what.to_string()));
        }
    }
    for (dir, stem, owners) in map_stems(args) {
        let of = owners
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(" and ");
        for m in openpbr::map_names(&stem) {
            out.push((dir.join(m), format!("texture map of {of}")));
        }
    }
    out
}

/// The stem of an output's file name, which its maps are named after ("cloth" without one).
fn stem(p: &Path) -> String {
    p.file_stem()
        .map_or_else(|| "cloth".into(), |s| s.to_string_lossy().into_owned())
}

/// The folders and stems of the MaterialX and USD outputs (their maps' names), with the
/// outputs that refer to them: one entry for a MaterialX and a USD file of one stem in one
/// folder, however the folder is spelled (`x.mtlx` and `./x.usda` share their maps).
fn map_stems(args: &ExportArgs) -> Vec<(PathBuf, String, Vec<PathBuf>)> {
    let mut v: Vec<(PathBuf, String, Vec<PathBuf>)> = Vec::new();
    for p in [&args.mtlx, &args.usd].into_iter().flatten() {
        let dir = p.parent().map(Path::to_path_buf).unwrap_or_default();
        let stem = stem(p);
        let probe = dir.join(openpbr::map_names(&stem)[0].as_str());
        let shared = v
            .iter_mut()
            .find(|(d, s, _)| same_file(&d.join(openpbr::map_names(s)[0].as_str()), &probe));
        match shared {
            Some((_, _, owners)) => owners.push(p.clone()),
            None => v.push((dir, stem, vec![p.clone()])),
        }
    }
    v
}

/// Refuses MaterialX and USD outputs whose file stem cannot name their maps inside those files
/// (a USD asset path ends at `@`; quotes, backslashes and control characters would break the
/// XML or USDA text): the maps are named after the stem.
pub fn check_stems(args: &ExportArgs) -> Result<(), CliError> {
    for p in [&args.mtlx, &args.usd].into_iter().flatten() {
        let bad = stem(p)
            .chars()
            .find(|c| c.is_control() || matches!(c, '@' | '"' | '\\' | '<' | '>' | '&'));
        if let Some(c) = bad {
            return Err(CliError::new(
                format!(
                    "{}: the file name holds {c:?}, which cannot stand in the names of its \
                     texture maps inside the file",
                    p.display()
                ),
                "name the --mtlx/--usd output without @, quotes, backslashes, <, >, & or \
                 control characters",
            ));
        }
    }
    Ok(())
}

/// Whether any fitted target was asked for.
pub fn wanted(args: &ExportArgs) -> bool {
    args.gltf.is_some() || args.mtlx.is_some() || args.usd.is_some() || args.blender.is_some()
}

fn percent(r: &clothbake_export::fitted::fit::Residual) -> String {
    format!(
        "albedo error {:.1}% mean, {:.1}% max; L2 of f_r cos {:.1}%",
        100.0 * r.albedo_mean,
        100.0 * r.albedo_max,
        100.0 * r.l2
    )
}

/// Fits (on `pool`) and writes every fitted target asked for; returns the summary lines.
pub fn write(
    args: &ExportArgs,
    src: &Source<'_>,
    name: &str,
    pool: &rayon::ThreadPool,
) -> Result<String, CliError> {
    let mut summary = String::new();
    if !wanted(args) {
        return Ok(summary);
    }
    let start = Instant::now();
    let tables = Albedos::new(IOR);
    let p = args.periods_per_uv;
    let force = args.run.force;
    let want_openpbr = args.mtlx.is_some() || args.usd.is_some() || args.blender.is_some();
    let fits = pool.install(|| Fits::new(src, &tables, args.gltf.is_some(), want_openpbr));
    if let Some(c) = &src.cells {
        let n = (c.u_edges.len() - 1) * (c.v_edges.len() - 1);
        if !Fitted::fits_per_cell(n) {
            let _ = writeln!(
                summary,
                "note: the period has {n} crossing cells, more than the {} fitted one by one; \
                 one material is fitted to the whole cloth (no textures)",
                clothbake_export::fitted::material::MAX_CELLS
            );
        }
    }
    if let Some(out) = &args.gltf {
        let file = gltf::glb(&fits.gltf, name, p);
        export::write_file(out, &file.bytes, force)?;
        let _ = writeln!(
            summary,
            "wrote {}: glTF 2.0 (KHR_materials_sheen, KHR_materials_anisotropy), {}, {} periods \
             per UV unit; against the averaged BRDF: {}",
            out.display(),
            texture_words(&fits.gltf),
            p,
            percent(&fits.gltf_residual)
        );
    }
    if want_openpbr {
        let m = &fits.openpbr;
        let maps = (!m.is_uniform()).then(|| openpbr::OpenPbrMaps::new(m));
        for (dir, stem, _) in map_stems(args) {
            if let Some(maps) = &maps {
                let names = openpbr::map_names(&stem);
                // MaterialX and USD put texture coordinate (0, 0) at the lower left.
                for (n, map) in names.iter().zip([&maps.base, &maps.scalars, &maps.tangent]) {
                    export::write_file(&dir.join(n), &map.flipped().png(), force)?;
                }
            }
        }
        let names_for = |path: &Path| maps.as_ref().map(|_| openpbr::map_names(&stem(path)));
        if let Some(out) = &args.mtlx {
            let doc = openpbr::mtlx(m, name, names_for(out).as_ref(), p);
            export::write_file(out, doc.as_bytes(), force)?;
            let _ = writeln!(
                summary,
                "wrote {}: MaterialX 1.39 open_pbr_surface, {}; against the averaged BRDF: {}",
                out.display(),
                texture_words(m),
                percent(&fits.openpbr_residual)
            );
        }
        if let Some(out) = &args.usd {
            let doc = openpbr::usda(m, name, names_for(out).as_ref(), p);
            export::write_file(out, doc.as_bytes(), force)?;
            let _ = writeln!(
                summary,
                "wrote {}: USD, OpenPBR (MaterialX) with a UsdPreviewSurface fallback, on a \
                 swatch mesh, {}; against the averaged BRDF: {}",
                out.display(),
                texture_words(m),
                percent(&fits.openpbr_residual)
            );
        }
        if let Some(out) = &args.blender {
            let (src_py, _) = openpbr::blender(m, name, p);
            export::write_file(out, src_py.as_bytes(), force)?;
            let _ = writeln!(
                summary,
                "wrote {}: Blender module (Principled BSDF; run it inside Blender), {}; \
                 against the averaged BRDF under Cycles' rules: {}",
                out.display(),
                texture_words(m),
                percent(&fits.blender_residual)
            );
        }
    }
    let _ = writeln!(
        summary,
        "fitted in {:.1} s (what the residuals measure: docs/guide/export.md, \"Fitted materials\")",
        start.elapsed().as_secs_f64()
    );
    Ok(summary)
}

fn texture_words(m: &Fitted) -> String {
    if m.is_uniform() {
        "one set of parameters for the whole cloth".into()
    } else {
        let (w, h) = m.texture_size();
        let (nu, nv) = m.dims();
        format!("textures {w} x {h} over one period of {nu} x {nv} crossing cells")
    }
}
