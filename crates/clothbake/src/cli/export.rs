//! `clothbake info`, `export` and `diff`: what reads or converts a table.

use super::*;

/// `clothbake export`.
#[derive(Args, Debug)]
#[command(
    after_help = "--gltf, --mtlx, --usd and --blender write standard materials fitted to the \
                  cloth (per crossing cell where the source resolves cells), and print how \
                  far each is from the averaged BRDF. The MERL format is isotropic and cloth is not: each MERL cell holds f_r \
                  averaged over rotations about the normal (--phi-samples angles) and over \
                  swapping light and eye; the spread lost is printed. The RGL file keeps the \
                  anisotropy. --klems writes the daylighting file and prints the datasheet \
                  (docs/guide/daylighting.md). See docs/guide/export.md."
)]
pub struct ExportArgs {
    /// Export the analytic model of this fabric (JSON, see docs/reference/fabric-format.md, or a WIF
    /// draft), e.g. tables/twill.json, or a shipped fabric's name. Give this or --table.
    #[arg(long, value_name = "FILE")]
    pub weave: Option<PathBuf>,

    /// Export a baked table instead (.exr or .bin), read with the loader's interpolation; the
    /// model options do not apply. Give this or --weave.
    #[arg(long, value_name = "T.exr|T.bin")]
    pub table: Option<PathBuf>,

    /// Write the RGL material-database tensor file (RGB) that Mitsuba 3's RGB variants read.
    #[arg(long, value_name = "OUT.bsdf")]
    pub rgl: Option<PathBuf>,

    /// Write the spectral RGL tensor file (360-840 nm, upsampled from RGB) that pbrt-v4 and
    /// Mitsuba 3's spectral variants read.
    #[arg(long, value_name = "OUT.bsdf")]
    pub rgl_spectral: Option<PathBuf>,

    /// Write the 90x90x180 MERL binary (isotropic: averaged over rotations about the normal).
    #[arg(long, value_name = "OUT.binary")]
    pub merl: Option<PathBuf>,

    /// Write an LBNL/Radiance BSDF XML file on the Klems basis (145 x 145: front and back
    /// reflection and transmission, Visible and Solar) for daylighting tools (Radiance,
    /// WINDOW), and print the datasheet figures (openness, transmittance, reflectance at
    /// normal incidence). See docs/guide/daylighting.md.
    #[arg(long, value_name = "OUT.xml")]
    pub klems: Option<PathBuf>,

    /// Klems: points across a patch each way (K x K a patch; each entry averages K^4 pairs).
    #[arg(long, value_name = "K", value_parser = parse_klems_samples, default_value = "3")]
    pub klems_samples: usize,

    /// With --weave: `one` face over the thesis's floor (reflection only), or the `two`-faced
    /// cloth (no floor: light through the gaps and translucent yarns, the back the inverted
    /// weave; docs/science/transmission.md), which only --klems can hold.
    #[arg(long, value_enum, default_value_t = Faces::One)]
    pub faces: Faces,

    /// Write a glTF 2.0 binary (`.glb`): a swatch with the fitted material
    /// (KHR_materials_sheen, KHR_materials_anisotropy, textures over one period).
    #[arg(long, value_name = "OUT.glb")]
    pub gltf: Option<PathBuf>,

    /// Write a MaterialX 1.39 document with the fitted OpenPBR material (`open_pbr_surface`);
    /// its texture maps go beside it as OUT.base.png, OUT.scalars.png, OUT.tangent.png.
    #[arg(long, value_name = "OUT.mtlx")]
    pub mtlx: Option<PathBuf>,

    /// Write a USD stage (`.usda`): the fitted OpenPBR material with a UsdPreviewSurface
    /// fallback, bound to a swatch mesh; its maps go beside it as for --mtlx.
    #[arg(long, value_name = "OUT.usda")]
    pub usd: Option<PathBuf>,

    /// Write a Blender module: run inside Blender, it builds the fitted material as a
    /// Principled BSDF node tree.
    #[arg(long, value_name = "OUT.py")]
    pub blender: Option<PathBuf>,

    /// Fitted materials: weave periods per UV unit (the textures' tiling).
    #[arg(long, value_name = "P", value_parser = parse_periods_per_uv, default_value = "8")]
    pub periods_per_uv: f64,

    /// RGL grid: polar and azimuth steps of the view direction, nodes per side of each slice.
    #[arg(long, value_name = "NT,NP,NS", value_parser = parse_rgl_res, default_value = "16,24,32")]
    pub rgl_res: RglResArg,

    /// MERL: rotations about the normal averaged per cell.
    #[arg(long, value_name = "N", value_parser = parse_phi_samples, default_value = "16")]
    pub phi_samples: usize,

    /// Facet reflection model: the thesis's Phong-like terms or Lewis's modified Phong
    /// [default: huo].
    #[arg(long, value_enum)]
    pub facet: Option<FacetArg>,

    /// Analytic variant (see docs/science/model.md) [default: refined].
    #[arg(long, value_enum)]
    pub variant: Option<VariantArg>,

    /// Bounces and the secondary reflection's options.
    #[command(flatten)]
    pub bounces: BounceArgs,

    /// Material overrides, applied to both yarn groups.
    #[command(flatten)]
    pub material: MaterialArgs,

    /// --threads, --quiet, --force.
    #[command(flatten)]
    pub run: RunFlags,
}

/// `--rgl-res NT,NP,NS` (see `clothbake_export::rgl::RglGrid`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RglResArg(pub clothbake_export::rgl::RglGrid);

/// Parses `--rgl-res NT,NP,NS`: three whole numbers, each from 2 to 1024.
pub fn parse_rgl_res(s: &str) -> Result<RglResArg, String> {
    const FIX: &str = "give three whole numbers NT,NP,NS (polar and azimuth steps of the view \
                       direction, nodes per slice side), each from 2 to 1024, e.g. 16,24,32";
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 3 {
        return Err(format!(
            "expected 3 comma-separated numbers, found {}; {FIX}",
            parts.len()
        ));
    }
    let mut n = [0usize; 3];
    for (k, p) in parts.iter().enumerate() {
        n[k] = p
            .parse::<usize>()
            .map_err(|_| format!("`{p}` is not a whole number; {FIX}"))?;
    }
    let g = clothbake_export::rgl::RglGrid {
        n_theta: n[0],
        n_phi: n[1],
        n_slice: n[2],
    };
    g.validate().map_err(|e| format!("{e}; {FIX}"))?;
    Ok(RglResArg(g))
}

/// Parses `--periods-per-uv P`: a number from 1/1024 to 1024.
pub fn parse_periods_per_uv(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(p) if p.is_finite() && (1.0 / 1024.0..=1024.0).contains(&p) => Ok(p),
        _ => Err(format!(
            "`{s}` is not a number from 1/1024 to 1024; give the weave periods per UV unit, \
             e.g. 8"
        )),
    }
}

/// Parses `--phi-samples N`, 1 <= N <= 4096.
pub fn parse_phi_samples(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=4096).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{}` is not a number of rotations from 1 to 4096; give e.g. --phi-samples 16",
            s.trim()
        )),
    }
}

/// Parses `--klems-samples K`: a whole number from 1 to `klems::MAX_SAMPLES`.
pub fn parse_klems_samples(s: &str) -> Result<usize, String> {
    let max = clothbake_export::klems::MAX_SAMPLES;
    match s.trim().parse::<usize>() {
        Ok(n) if (1..=max).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{}` is not a number of points across a Klems patch from 1 to {max}; give e.g. \
             --klems-samples 3",
            s.trim()
        )),
    }
}

/// `clothbake diff`.
#[derive(Args, Debug)]
pub struct DiffArgs {
    /// The reference table.
    #[arg(value_name = "A")]
    pub a: PathBuf,

    /// The table compared with A (same grid).
    #[arg(value_name = "B")]
    pub b: PathBuf,

    /// Relative tolerance: a value passes when |a - b| <= ABS + REL |a| [default: 1e-6].
    #[arg(long, value_name = "REL", value_parser = parse_tolerance, allow_hyphen_values = true)]
    pub tol: Option<f64>,

    /// Absolute tolerance, 1/sr [default: 1e-7].
    #[arg(long = "abs", value_name = "ABS", value_parser = parse_tolerance, allow_hyphen_values = true)]
    pub abs_tol: Option<f64>,
}

/// `clothbake eval`.
#[derive(Args, Debug)]
pub struct EvalArgs {
    /// Fabric description (JSON, see docs/reference/fabric-format.md, or a WIF draft, *.wif, see
    /// docs/reference/wif.md), e.g. tables/twill.json, or a shipped fabric's name (`clothbake fabrics`).
    #[arg(long, value_name = "FILE")]
    pub weave: PathBuf,

    /// Direction toward the light, in degrees: theta from +Z (0 to 90; to 180 with --faces
    /// two, the light behind the cloth), phi from +X toward +Y.
    #[arg(long, value_name = "THETA,PHI", value_parser = parse_sphere_direction, allow_hyphen_values = true)]
    pub wi: Direction,

    /// Direction toward the eye, in degrees: theta from +Z (0 to 90; to 180 with --faces two,
    /// the eye behind the cloth), phi from +X toward +Y.
    #[arg(long, value_name = "THETA,PHI", value_parser = parse_sphere_direction, allow_hyphen_values = true)]
    pub wo: Direction,

    /// The cloth: `one` face over the thesis's opaque floor (reflection only), or `two` faces
    /// and no floor: light through the gaps and translucent yarns, the back the inverted weave
    /// (docs/science/transmission.md). With `two`, f covers the whole sphere and every bounce, and the
    /// report adds the openness along --wi.
    #[arg(long, value_enum, default_value_t = Faces::One)]
    pub faces: Faces,

    /// Analytic model (thesis ch. 3-4) or the ray-traced ground truth of the same geometry.
    #[arg(long, value_enum, default_value_t = Method::Analytic)]
    pub method: Method,

    /// Number of samples for --method raytrace [default: 100000].
    #[arg(long, value_name = "N", value_parser = parse_samples)]
    pub samples: Option<usize>,

    /// Random seed for --method raytrace [default: 1].
    #[arg(long, value_name = "S", value_parser = parse_seed)]
    pub seed: Option<u64>,

    /// --facet, --variant.
    #[command(flatten)]
    pub model: ModelArgs,

    /// Ray tracer: whether rays ending on a segment's flat end cap are averaged (shaded) or, like
    /// floor hits, left out (excluded, the default: the analytic model has no caps).
    #[arg(long, value_enum, default_value_t = CapsArg::Excluded)]
    pub caps: CapsArg,

    /// Bounces and the secondary reflection's options (with --method raytrace and --bounces 2
    /// the path tracer estimates I_2).
    #[command(flatten)]
    pub bounces: BounceArgs,

    /// Material overrides, applied to both yarn groups.
    #[command(flatten)]
    pub material: MaterialArgs,

    /// Yarn sizes for a WIF draft that gives none.
    #[command(flatten)]
    pub draft: DraftArgs,

    /// A point of the weave period, U,V in period fractions (U along the weft +X, V along the
    /// warp +Y; any finite numbers, wrapped): the reflection of the yarn over that crossing
    /// instead of the period's average, with its coverage (docs/science/spatial.md). Analytic only.
    #[arg(long, value_name = "U,V", value_parser = parse_period_point, allow_hyphen_values = true)]
    pub at: Option<clothbake_core::PeriodPoint>,

    /// With --at: the side of the footprint around the point, in periods (0: the point itself;
    /// 1 or more: the whole period). The footprint's level of detail answers: the yarns traced
    /// at the point (one bounce), the crossing cells, or the period (docs/science/spatial.md).
    #[arg(long, value_name = "W", value_parser = parse_width, requires = "at", allow_hyphen_values = true)]
    pub width: Option<f64>,

    /// Print one JSON object instead of a table: keys I_d, I_s, I (reflected intensity for unit
    /// incident intensity) and brdf (1/sr), each [r, g, b]; with --bounces 2 also I_ss, I_sd,
    /// I_ds, I_dd and I_2 (I is then I_1 + I_2); raytrace adds std_err ([r, g, b], null when
    /// too few samples to estimate it) and samples; the analytic model adds
    /// directional_coverage, and with --at also at ([u, v]), cell ([warp, weft]), on_top ("warp"
    /// or "weft") and coverage. With --bounces N > 2 or all: orders (I_1, I_2, ...) and
    /// orders_std_err, I_2_parallel, I_2_perpendicular, I_2_split_std_err, I_multiple,
    /// I_multiple_std_err, paths, seed and converged (docs/science/transport.md).
    #[arg(long)]
    pub json: bool,
}
