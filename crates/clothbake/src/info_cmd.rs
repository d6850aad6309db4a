//! `clothbake info TABLE`: what a baked table holds.

use crate::cli::InfoArgs;
use crate::error::CliError;
use clothbake_bake::albedo::{directional_albedo, reflected_and_transmitted};
use clothbake_loader::{read_table, Table};
use std::fmt::Write as _;
use std::io::Read;
use std::path::Path;

/// The incident polar angles at which the albedo is reported, degrees.
pub const ALBEDO_THETAS: [f64; 4] = [0.0, 30.0, 60.0, 80.0];

fn format_name(path: &Path) -> &'static str {
    let mut head = [0u8; 4];
    let ok = std::fs::File::open(path)
        .and_then(|mut f| f.read_exact(&mut head))
        .is_ok();
    if ok && head == clothbake_loader::EXR_MAGIC {
        "OpenEXR"
    } else {
        "binary"
    }
}

/// Minimum, maximum and mean of each channel of the averaged RGB.
pub fn channel_stats(t: &Table) -> [[f64; 3]; 3] {
    let mut min = [f64::INFINITY; 3];
    let mut max = [f64::NEG_INFINITY; 3];
    let mut sum = [0.0; 3];
    let rgb = &t.values[..3 * t.meta.grid.len()];
    for c in rgb.chunks_exact(3) {
        for k in 0..3 {
            let v = f64::from(c[k]);
            min[k] = min[k].min(v);
            max[k] = max[k].max(v);
            sum[k] += v;
        }
    }
    let n = (rgb.len() / 3).max(1) as f64;
    [min, max, sum.map(|s| s / n)]
}

/// The layout of a spatial table: its classes and, for periods up to 32 threads wide, the
/// class of each crossing cell (weft rows from v = 0 upward, warp columns from u = 0).
fn spatial_lines(s: &mut String, sp: &clothbake_loader::Spatial) {
    let (nx, ny) = sp.dims();
    let _ = writeln!(
        s,
        "spatial    {} class{} over {nx} x {ny} crossing cells (warp x weft; docs/science/spatial.md); \
         each cell shows its class's f_r at its thread's albedo{}",
        sp.classes,
        if sp.classes == 1 { "" } else { "es" },
        if sp.secondary {
            ", with the second bounce from its neighbours' albedos"
        } else {
            ""
        }
    );
    if nx <= 32 {
        for j in 0..ny.min(32) {
            let row: Vec<String> = (0..nx)
                .map(|i| format!("{:>3}", sp.cell_class[j * nx + i]))
                .collect();
            let _ = writeln!(s, "  weft {j:<3}{}", row.join(""));
        }
        if ny > 32 {
            let _ = writeln!(s, "  ... ({} more weft rows)", ny - 32);
        }
    }
}

/// Runs `clothbake info` and returns the text to print.
pub fn run(args: &InfoArgs) -> Result<String, CliError> {
    let t = read_table(&args.table)?;
    let m = &t.meta;
    let g = m.grid;
    let mut s = String::new();
    let fabric = serde_json::from_str::<serde_json::Value>(&m.fabric_json).ok();
    let fabric_name = fabric
        .as_ref()
        .and_then(|v| v["name"].as_str().map(str::to_string))
        .unwrap_or_else(|| "(unnamed)".to_string());
    // What reading the fabric did to it (a WIF draft's packed yarns; Fabric::notes).
    let notes: Vec<String> = fabric
        .as_ref()
        .and_then(|v| v["notes"].as_array().cloned())
        .unwrap_or_default()
        .iter()
        .filter_map(|n| n.as_str().map(str::to_string))
        .collect();
    let _ = writeln!(
        s,
        "table      {} ({} format, version {})",
        args.table.display(),
        format_name(&args.table),
        m.format_version
    );
    let _ = writeln!(s, "tool       {}", m.tool);
    let _ = writeln!(s, "fabric     {fabric_name}");
    for n in &notes {
        let _ = writeln!(s, "note       {n}");
    }
    let _ = writeln!(
        s,
        "grid       theta_i {} x phi_i {} x theta_o {} x phi_o {} = {} cells, centring {} \
         (values at cell centres)",
        g.n_theta_i,
        g.n_phi_i,
        g.n_theta_o,
        g.n_phi_o,
        g.len(),
        m.centring
    );
    let _ = writeln!(s, "quantity   {} in {}", m.quantity, m.units);
    let _ = writeln!(s, "symmetry   {}", m.symmetry);
    let _ = writeln!(s, "options    {}", m.options_json);
    if let Some(sp) = &m.spatial {
        spatial_lines(&mut s, sp);
    }
    if let Some(y) = &m.yarns {
        let _ = writeln!(
            s,
            "yarns      {} yarn segments of the period: footprints under a crossing cell trace them (the point level, docs/science/spatial.md)",
            y.yarns().len()
        );
    }
    let [min, max, mean] = channel_stats(&t);
    let _ = writeln!(s, "values     {:>12} {:>12} {:>12}", "R", "G", "B");
    for (name, v) in [("min", min), ("max", max), ("mean", mean)] {
        let _ = writeln!(
            s,
            "  {name:<8} {:>12.6e} {:>12.6e} {:>12.6e}",
            v[0], v[1], v[2]
        );
    }
    if g.faces == clothbake_loader::Faces::Two {
        two_faced_lines(&mut s, &t);
        return Ok(s);
    }
    let pi = g.phi_i().cell_of_deg(0.0);
    let _ = writeln!(
        s,
        "directional albedo (sum over the outgoing cells of f_r times the cell's integral of \
         cos theta_o d omega), phi_i {:.2} (row {pi}, nearest 0):",
        g.phi_i_deg(pi)
    );
    let _ = writeln!(
        s,
        "  {:<28} {:>9} {:>9} {:>9}",
        "theta_i asked -> row used", "R", "G", "B"
    );
    for want in ALBEDO_THETAS {
        let ti = g.theta_i().cell_of_deg(want);
        let a = directional_albedo(&t, ti, pi);
        let _ = writeln!(
            s,
            "  {:<28} {:>9.4} {:>9.4} {:>9.4}",
            format!("{want:>2} -> row {ti} ({:.2} deg)", g.theta_i_deg(ti)),
            a[0],
            a[1],
            a[2]
        );
    }
    Ok(s)
}

/// A two-faced table's sides, openness and the light from each side's incident rows: reflected
/// on its side, transmitted to the other (f_r's integrals), and straight through.
fn two_faced_lines(s: &mut String, t: &Table) {
    let g = t.meta.grid;
    let openness = t.meta.openness.as_deref().unwrap_or_default();
    let _ = writeln!(
        s,
        "faces      two (docs/science/transmission.md): theta 0 to 90 from the front (+Z), 90 to 180 from \
         the back; each side {} polar cells; the openness (light straight through the gaps) \
         per incident cell",
        g.n_theta_i / 2
    );
    let pi = g.phi_i().cell_of_deg(0.0);
    let _ = writeln!(
        s,
        "light from each side, phi_i {:.2} (row {pi}, nearest 0): reflected R, transmitted T \
         (f_r's integrals, mean of RGB) and straight through O",
        g.phi_i_deg(pi)
    );
    let _ = writeln!(
        s,
        "  {:<36} {:>8} {:>8} {:>8} {:>8}",
        "side, theta_i asked -> row used", "R", "T", "O", "R+T+O"
    );
    let mean = |a: [f64; 3]| (a[0] + a[1] + a[2]) / 3.0;
    for (side, flip) in [("front", false), ("back", true)] {
        for want in ALBEDO_THETAS {
            let theta = if flip { 180.0 - want } else { want };
            let ti = g.theta_i().cell_of_deg(theta);
            let (r, tr) = reflected_and_transmitted(t, ti, pi);
            let o = openness
                .get((ti * g.n_phi_i + pi) as usize)
                .map_or(0.0, |&o| f64::from(o));
            let (r, tr) = (mean(r), mean(tr));
            let _ = writeln!(
                s,
                "  {:<36} {:>8.4} {:>8.4} {:>8.4} {:>8.4}",
                format!(
                    "{side} {want:>2} -> row {ti} ({:.2} deg)",
                    g.theta_i_deg(ti)
                ),
                r,
                tr,
                o,
                r + tr + o
            );
        }
    }
}
