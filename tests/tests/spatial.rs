//! The model resolved over the weave period (docs/science/spatial.md): the local reflection at a point
//! against the period's average (their coverage-weighted mean), against the ray-traced ground
//! truth per crossing cell, and what it shows of each weave.

use clothbake_core::{
    AnalyticModel, Cell, Fabric, FacetModel, LocalReflection, PeriodPoint, SecondaryOptions,
    UnitVec3,
};
use clothbake_truth::RayTracer;
use std::collections::HashMap;
use std::path::Path;

fn tables() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tables")
}

fn fabric(file: &str) -> Fabric {
    Fabric::from_path(&tables().join(file)).unwrap()
}

/// Every shipped fabric (JSON and WIF) by file name.
fn shipped() -> Vec<String> {
    let files = clothbake_bake::golden::fabric_files(&tables()).unwrap();
    assert!(files.len() >= 9, "{files:?}");
    files
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect()
}

fn pairs() -> Vec<(UnitVec3, UnitVec3)> {
    [
        ((0.0, 0.0), (0.0, 0.0)),
        ((30.0, 0.0), (45.0, 90.0)),
        ((60.0, 20.0), (10.0, 200.0)),
        ((45.0, 135.0), (45.0, 315.0)),
        ((70.0, 270.0), (65.0, 30.0)),
    ]
    .iter()
    .map(|&((a, b), (c, d))| (UnitVec3::from_degrees(a, b), UnitVec3::from_degrees(c, d)))
    .collect()
}

#[test]
fn coverage_weighted_mean_over_a_fine_grid_is_the_average() {
    // The contract: within 0.5% on a fine grid of points. Grid points sample each cell
    // in proportion to its area; irregular drafts are not multiples of the grid, hence the
    // tolerance rather than rounding error.
    const N: usize = 240;
    for file in &shipped() {
        let file = file.as_str();
        let model = AnalyticModel::new(&fabric(file), FacetModel::Huo);
        for two in [false, true] {
            let opts = two.then(SecondaryOptions::default);
            for (wi, wo) in pairs() {
                let avg = model.intensity_with(wi, wo, opts.as_ref()).total();
                // Each grid point evaluated through its cell (the local reflection is constant
                // over a cell: `intensity_at` is `intensity_in` of `cell_at`), once per cell.
                let mut memo: HashMap<Cell, LocalReflection> = HashMap::new();
                let (mut num, mut den) = ([0.0; 3], 0.0);
                for j in 0..N {
                    for i in 0..N {
                        let p = PeriodPoint::new(
                            (i as f64 + 0.5) / N as f64,
                            (j as f64 + 0.5) / N as f64,
                        )
                        .unwrap();
                        let l = *memo
                            .entry(model.cells().cell_at(p))
                            .or_insert_with(|| model.intensity_at(wi, wo, p, opts.as_ref()));
                        let t = l.reflection.total();
                        for k in 0..3 {
                            num[k] += l.coverage * t[k];
                        }
                        den += l.coverage;
                    }
                }
                let c = model.coverage(wo);
                assert!(
                    (den / (N * N) as f64 - c).abs() <= 0.005 * c,
                    "{file}: mean coverage {} vs directional {c}",
                    den / (N * N) as f64
                );
                for k in 0..3 {
                    let mean = num[k] / den;
                    assert!(
                        (mean - avg[k]).abs() <= 0.005 * avg[k],
                        "{file} two={two}: spatial mean {mean} vs average {}",
                        avg[k]
                    );
                }
            }
        }
    }
}

/// Worst relative error of any cell, mean over cells and worst absolute coverage error, of the
/// model against the truth at one direction pair; cells with under 2000 truth hits are left
/// out of the errors of I (their truth is too noisy) but not of the coverage.
fn cell_errors(
    model: &AnalyticModel,
    truth: &RayTracer,
    wi: UnitVec3,
    wo: UnitVec3,
    seed: u64,
) -> (f64, f64, f64) {
    let cells = truth.render_cells(wi, wo, 400_000, seed);
    let (nx, ny) = model.cells().dims();
    assert_eq!(cells.len(), nx * ny);
    // The cells partition the period's hits: their hit-weighted mean is the period's estimate
    // from the same rays.
    let whole = truth.render(wi, wo, 400_000, seed);
    let hits: usize = cells.iter().map(|c| c.hits).sum();
    assert_eq!(hits, whole.yarn_hits);
    let mean: f64 = cells
        .iter()
        .map(|c| c.reflection.total()[1] * c.hits as f64)
        .sum::<f64>()
        / hits as f64;
    assert!((mean - whole.reflection.total()[1]).abs() <= 1e-9 * mean);
    let (mut worst, mut sum, mut count, mut worst_cov) = (0.0f64, 0.0, 0, 0.0f64);
    for j in 0..ny {
        for i in 0..nx {
            let m = model.intensity_in(wi, wo, Cell { warp: i, weft: j }, None);
            let t = &cells[j * nx + i];
            worst_cov = worst_cov.max((m.coverage - t.coverage).abs());
            if t.hits < 2000 {
                continue;
            }
            let (mi, ti) = (m.reflection.total()[1], t.reflection.total()[1]);
            let rel = (mi - ti).abs() / ti;
            worst = worst.max(rel);
            sum += rel;
            count += 1;
        }
    }
    (worst, sum / count.max(1) as f64, worst_cov)
}

/// The presets of real cloth (docs/reference/fabric-format.md): real yarn counts, so warp and weft
/// spacings differ and the yarns are thinner than their spacing in one direction, unlike the
/// thesis's nearly touching, equal yarns the per-cell contract below was set on.
const PRESETS: [&str; 5] = [
    "cotton-poplin.json",
    "denim.wif",
    "polyester-taffeta.json",
    "silk-charmeuse.json",
    "wool-twill.json",
];

#[test]
fn each_cell_matches_the_ray_traced_truth() {
    // The averaged model's contract against the truth (tests/tests/ground_truth.rs): mean
    // relative error under 4%, worst direction under 12%. Per cell the model makes the same
    // error as on average: measured worst cell 9.1% (gingham at wi 70/270, wo 65/30), worst
    // coverage difference 0.027 (docs/results/validation.md).
    for file in &shipped() {
        let file = file.as_str();
        if PRESETS.contains(&file) {
            continue;
        }
        cells_within(file, 0.12, 0.04, 0.04);
    }
}

/// Holds every cell of `file` against the truth at [`pairs`]: the worst cell's relative error
/// under `worst`, the coverage's error under `coverage` at each pair, and the mean cell error
/// over the pairs under `mean`.
fn cells_within(file: &str, worst: f64, coverage: f64, mean: f64) {
    let f = fabric(file);
    let model = AnalyticModel::new(&f, FacetModel::Huo);
    let truth = RayTracer::new(&f, FacetModel::Huo);
    let mut means = Vec::new();
    for (n, (wi, wo)) in pairs().into_iter().enumerate() {
        let (w, m, c) = cell_errors(&model, &truth, wi, wo, 11 + n as u64);
        eprintln!("{file:13} pair {n}: mean {m:.4} worst {w:.4} coverage {c:.4}");
        assert!(w < worst, "{file} pair {n}: worst cell {w}");
        assert!(c < coverage, "{file} pair {n}: coverage off by {c}");
        means.push(m);
    }
    let m = means.iter().sum::<f64>() / means.len() as f64;
    assert!(m < mean, "{file}: mean cell error {m}");
}

#[test]
fn each_cell_of_the_presets_stays_within_the_measured_bounds() {
    // The per-cell model is weaker where yarns leave gaps in one direction: on the presets
    // (measured, docs/science/spatial.md) worst cell 21% (wool-twill, silk-charmeuse at the grazing
    // pairs), coverage off by up to 0.21, mean cell error 1.5% (denim) to 4.8% (wool-twill).
    // Bounds a little above those: a regression detector, and the documented limit.
    for file in PRESETS {
        cells_within(file, 0.25, 0.25, 0.06);
    }
}

#[test]
fn warp_and_weft_floats_and_the_gingham_checks_differ() {
    let (wi, wo) = (
        UnitVec3::from_degrees(60.0, 0.0),
        UnitVec3::from_degrees(20.0, 180.0),
    );
    // Twill 2/1 (pattern row 0 = 1,1,0): warp 0 over weft 0, weft 0 over warp 2. Light and eye
    // in the x-z plane: the half vector is perpendicular to the warp's axis (y), not to the
    // weft's (x), so only the warp floats show the specular highlight.
    let twill = AnalyticModel::new(&fabric("twill.json"), FacetModel::Huo);
    let warp = twill.intensity_in(wi, wo, Cell { warp: 0, weft: 0 }, None);
    let weft = twill.intensity_in(wi, wo, Cell { warp: 2, weft: 0 }, None);
    let (a, b) = (warp.reflection.total()[0], weft.reflection.total()[0]);
    assert!((a - b).abs() > 0.1 * a.max(b), "twill: {a} vs {b}");
    // The diagonal: cell (i, j) shows the same unit as (i + 1, j + 1).
    for j in 0..3 {
        for i in 0..3 {
            let here = twill.intensity_in(wi, wo, Cell { warp: i, weft: j }, None);
            let next = twill.intensity_in(
                wi,
                wo,
                Cell {
                    warp: (i + 1) % 3,
                    weft: (j + 1) % 3,
                },
                None,
            );
            // The same unit; the cell areas may differ in the last bit (edges from sums).
            assert_eq!(here.reflection, next.reflection);
            assert!((here.coverage - next.coverage).abs() <= 1e-12 * here.coverage);
        }
    }
    // Gingham: each check colour, a distinct RGB per combination of thread colours.
    let f = fabric("gingham.wif");
    let g = AnalyticModel::new(&f, FacetModel::Huo);
    let (nx, ny) = g.cells().dims();
    let mut colours: Vec<[f64; 3]> = Vec::new();
    for j in 0..ny {
        for i in 0..nx {
            let c = g.intensity_in(wi, UnitVec3::Z, Cell { warp: i, weft: j }, None);
            let d = c.reflection.i_d;
            let chroma = d.map(|x| x / (d[0] + d[1] + d[2]));
            if !colours
                .iter()
                .any(|o| (0..3).all(|k| (o[k] - chroma[k]).abs() < 1e-9))
            {
                colours.push(chroma);
            }
        }
    }
    let threads: std::collections::HashSet<[u64; 3]> =
        [clothbake_core::Group::Warp, clothbake_core::Group::Weft]
            .iter()
            .flat_map(|&g| (0..f.group(g).threads.len()).map(move |t| (g, t)))
            .map(|(g, t)| f.thread_material(g, t).albedo.map(f64::to_bits))
            .collect();
    assert!(
        threads.len() >= 2,
        "gingham has {} thread colours",
        threads.len()
    );
    assert_eq!(colours.len(), threads.len(), "{colours:?}");
}
