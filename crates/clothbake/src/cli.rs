//! The command line: clap definitions and the value parsers behind them.
//!
//! Layout: `clothbake --weave FILE [options]` (default mode: bake a table, the same as
//! `clothbake bake --weave FILE [options]`), `clothbake eval --weave FILE --wi THETA,PHI
//! --wo THETA,PHI [...]`, `clothbake info TABLE` and `clothbake diff A B`. The bake options live
//! in [`BakeOpts`], flattened into both [`Cli`] (default mode) and [`BakeCmd`] (the subcommand).

use crate::error::CliError;
use clap::{Args, Parser, Subcommand, ValueEnum};
pub use clothbake_bake::settings::{parse_orders, parse_sampling};
use clothbake_bake::settings::{Bounces, Naming};
use clothbake_bake::shard::{parse_shard_id, ShardId};
use clothbake_core::interreflection::{Orders, Sampling};
use clothbake_core::{FacetModel, Kernel, SecondaryOptions, UnitVec3, Variant};
use clothbake_loader::Grid;
use clothbake_truth::Caps;
use std::path::PathBuf;

pub use clothbake_bake::settings::{DEFAULT_SAMPLES, DEFAULT_SEED};

/// Bake the BRDF of woven cloth, derived from its yarn geometry (Huo 1993), into tables.
#[derive(Parser, Debug)]
#[command(
    name = "clothbake",
    version,
    args_conflicts_with_subcommands = true,
    override_usage = "clothbake --weave FILE [BAKE OPTIONS]   (bake a table: `clothbake bake --help`)\n       \
                      clothbake <COMMAND> [OPTIONS]",
    after_help = "Without a subcommand, `clothbake --weave FILE [options]` bakes a table: the options of \
                  `clothbake bake`, listed by `clothbake bake --help`. Angles are in degrees: theta from \
                  the macro normal +Z (0 to 90), phi from +X (the weft direction) toward +Y (the warp \
                  direction). Fabric files: see docs/reference/fabric-format.md and `clothbake fabrics`; baking: \
                  docs/guide/baking.md."
)]
pub struct Cli {
    /// What to do; without a subcommand clothbake bakes the fabric given with --weave.
    #[command(subcommand)]
    pub command: Option<Command>,

    /// Fabric description to bake into a BRDF table (JSON, see docs/reference/fabric-format.md, or a
    /// WIF weaving draft, *.wif, see docs/reference/wif.md), or a shipped fabric's name (`clothbake
    /// fabrics`), e.g. twill.
    #[arg(long, value_name = "FILE")]
    pub weave: Option<PathBuf>,

    /// Options of the default mode (baking a table).
    #[command(flatten)]
    pub bake: BakeOpts,
}

/// The subcommands.
#[derive(Subcommand, Debug)]
pub enum Command {
    /// Bake a fabric's BRDF into a table (the default mode, spelled out).
    Bake(BakeCmd),
    /// Evaluate the reflection of a fabric for one light and one eye direction.
    Eval(EvalArgs),
    /// Describe a baked table: metadata, value range, directional albedo.
    Info(InfoArgs),
    /// Compare two baked tables of the same grid; exit 1 when they differ beyond the tolerance.
    Diff(DiffArgs),
    /// Export a fabric's BRDF (the model's or a baked table's) for other renderers: the RGL
    /// `.bsdf` of Mitsuba 3's `measured` BSDF (RGB) or of pbrt-v4 and Mitsuba's spectral
    /// variants (spectral), or the isotropic MERL binary (averaged over rotations about the
    /// normal).
    Export(ExportArgs),
    /// Merge the shard files of a bake (`bake --shard K/N`) into the table (docs/guide/cluster.md).
    Merge(MergeArgs),
    /// Render a picture (PNG, optionally EXR) of cloth shaded with a table or the model.
    Render(RenderArgs),
    /// Plot a BRDF: slices in the plane of incidence or a hemisphere map (PNG, SVG).
    Plot(PlotArgs),
    /// List the shipped fabrics (usable by name: `--weave twill`).
    Fabrics,
    /// Print a shell completion script on stdout, e.g. `clothbake completions bash >
    /// ~/.local/share/bash-completion/completions/clothbake`.
    Completions(CompletionsArgs),
    /// Print a man page (roff) on stdout, e.g. `clothbake man | man -l -`, `clothbake man bake`.
    Man(ManArgs),
}

/// `clothbake completions`.
#[derive(Args, Debug)]
pub struct CompletionsArgs {
    /// The shell to complete in.
    #[arg(value_enum, value_name = "SHELL")]
    pub shell: clap_complete::Shell,
}

/// `clothbake man`.
#[derive(Args, Debug)]
pub struct ManArgs {
    /// The subcommand whose page to print, e.g. bake [default: the top-level page].
    #[arg(value_name = "COMMAND")]
    pub command: Option<String>,
}

/// The argument ids of [`Cli`] that its help shows; the rest, the default mode's bake options,
/// are listed by `clothbake bake --help` (the same options) instead.
const TOP_LEVEL_SHOWN: [&str; 3] = ["weave", "help", "version"];

/// The command line that `clothbake` parses: [`Cli`] with the default mode's bake options kept
/// out of the top-level help, so that `clothbake -h` shows the commands. Completions use
/// [`Cli::command`] itself, which completes every option.
pub fn command() -> clap::Command {
    use clap::CommandFactory;
    Cli::command().mut_args(|a| {
        if TOP_LEVEL_SHOWN.contains(&a.get_id().as_str()) {
            a
        } else {
            a.hide(true)
        }
    })
}

/// The names of the subcommands, in the order of `clothbake --help`.
pub fn subcommand_names() -> Vec<String> {
    command()
        .get_subcommands()
        .map(|c| c.get_name().to_string())
        .collect()
}

/// `clothbake bake`.
#[derive(Args, Debug)]
pub struct BakeCmd {
    /// Fabric description to bake (JSON, see docs/reference/fabric-format.md, or a WIF draft, *.wif, see
    /// docs/reference/wif.md), e.g. tables/twill.json, or a shipped fabric's name (`clothbake fabrics`).
    #[arg(long, value_name = "FILE")]
    pub weave: PathBuf,

    /// The bake options.
    #[command(flatten)]
    pub opts: BakeOpts,
}

/// Options of a bake (default mode and `clothbake bake`).
#[derive(Args, Debug, Clone)]
pub struct BakeOpts {
    /// Output table [default: <fabric file stem>.exr (or .bin with --format bin) in the current
    /// folder].
    #[arg(short = 'o', long, value_name = "PATH")]
    pub output: Option<PathBuf>,

    /// Grid: cells of theta_i, phi_i, theta_o, phi_o (cell-centred; see docs/reference/table-format.md).
    #[arg(long, value_name = "NTI,NPI,NTO,NPO", value_parser = parse_res, default_value = "32,64,32,64")]
    pub res: Option<Grid>,

    /// --format, --precision.
    #[command(flatten)]
    pub table: TableFormatArgs,

    /// --threads, --quiet, --force.
    #[command(flatten)]
    pub run: RunFlags,

    /// Facet reflection model: the thesis's Phong-like terms or Lewis's modified Phong.
    #[arg(long, value_enum, default_value_t = FacetArg::Huo)]
    pub facet: FacetArg,

    /// Analytic variant: eq. 3.6 on the rectangle top as printed (thesis) or averaged over the
    /// arc's true heights (see docs/science/model.md) [default: refined].
    #[arg(long, value_enum)]
    pub variant: Option<VariantArg>,

    /// Analytic model (thesis ch. 3-5) or the ray-traced ground truth of the direct reflection
    /// (slow: for small grids).
    #[arg(long, value_enum, default_value_t = Method::Analytic)]
    pub method: Method,

    /// Rays per cell for --method raytrace [default: 100000].
    #[arg(long, value_name = "N", value_parser = parse_samples)]
    pub samples: Option<usize>,

    /// Random seed for --method raytrace (cell c uses seed + c) [default: 1].
    #[arg(long, value_name = "S", value_parser = parse_seed)]
    pub seed: Option<u64>,

    /// End caps for --method raytrace: excluded from the average (default) or shaded.
    #[arg(long, value_enum)]
    pub caps: Option<CapsArg>,

    /// Bounces and the secondary reflection's options.
    #[command(flatten)]
    pub bounces: BounceArgs,

    /// Also tabulate the weave up close (docs/science/spatial.md): each class of the period's crossing
    /// cells beside the average, so that renderers show the weave below one period per pixel
    /// (render --periods, Brdf::eval_at). Analytic model, --bounces 1 or 2.
    #[arg(long)]
    pub spatial: bool,

    /// `one` face over the thesis's floor (reflection only), or the `two`-faced cloth (no
    /// floor: light through the gaps and translucent yarns, the back the inverted weave;
    /// docs/science/transmission.md): a table over the whole sphere, --res's polar counts per side.
    #[arg(long, value_enum, default_value_t = Faces::One)]
    pub faces: Faces,

    /// With --faces two: eye rays per node of the path-traced rest (the light through and
    /// between the yarns; docs/science/transmission.md) [default: 8192]. Its noise falls as 1/sqrt(N).
    #[arg(long, value_name = "N", value_parser = parse_paths)]
    pub paths: Option<usize>,

    /// Material overrides, applied to both yarn groups.
    #[command(flatten)]
    pub material: MaterialArgs,

    /// Bake only shard K of N (K 0-based, 0 to N-1) of the (theta_i, phi_i) rows into a shard
    /// file [default output: <fabric stem>-K-of-N.shard]; `auto`: K and N from a SLURM job
    /// array or a Kubernetes Indexed Job (with --shards). Merge with `clothbake merge`.
    #[arg(long, value_name = "K/N|auto", value_parser = parse_shard)]
    pub shard: Option<ShardArg>,

    /// With --shard auto: the number of shards (required with Kubernetes' JOB_COMPLETION_INDEX;
    /// with SLURM it must equal SLURM_ARRAY_TASK_COUNT).
    #[arg(long, value_name = "N", value_parser = parse_shard_count)]
    pub shards: Option<u32>,

    /// Continue an interrupted bake from its checkpoint (<output>.checkpoint), if there is one.
    #[arg(long)]
    pub resume: bool,

    /// Seconds between checkpoints of the finished rows [default: 60].
    #[arg(long, value_name = "SECS", value_parser = parse_seconds)]
    pub checkpoint_every: Option<f64>,

    /// Yarn sizes for a WIF draft that gives none.
    #[command(flatten)]
    pub draft: DraftArgs,
}

/// The flags of every command that works on all cores and writes files (bake, export,
/// render): `--threads`, `--quiet`, `--force`.
#[derive(Args, Debug, Clone, Copy)]
pub struct RunFlags {
    /// Worker threads [default: all cores]; the output does not depend on it.
    #[arg(long, value_name = "N", value_parser = parse_threads)]
    pub threads: Option<usize>,

    /// Print nothing but errors (no progress bar, no summary line).
    #[arg(long, short = 'q')]
    pub quiet: bool,

    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

/// The flags of a command that writes files on one thread (merge): `--quiet`, `--force`.
#[derive(Args, Debug, Clone, Copy)]
pub struct WriteFlags {
    /// Print nothing but errors (no summary line).
    #[arg(long, short = 'q')]
    pub quiet: bool,

    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

/// `--shard` values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShardArg {
    /// Shard K of N, given.
    Fixed(ShardId),
    /// From the scheduler's environment.
    Auto,
}

/// The format of a table a command writes (bake, merge).
#[derive(Args, Debug, Clone, Copy)]
pub struct TableFormatArgs {
    /// Table format [default: from the output's extension, .exr or .bin; otherwise exr].
    #[arg(long, value_enum)]
    pub format: Option<FormatArg>,

    /// Sample precision of an EXR table (f16: about 3 digits, at most 65504) [default: f16].
    #[arg(long, value_enum)]
    pub precision: Option<PrecisionArg>,
}

/// `clothbake merge`.
#[derive(Args, Debug)]
pub struct MergeArgs {
    /// The table to write (.exr or .bin).
    #[arg(short = 'o', long, value_name = "TABLE")]
    pub output: PathBuf,

    /// Every shard file of the bake (any order).
    #[arg(value_name = "SHARD", required = true)]
    pub shards: Vec<PathBuf>,

    /// --format, --precision.
    #[command(flatten)]
    pub table: TableFormatArgs,

    /// --quiet, --force.
    #[command(flatten)]
    pub out: WriteFlags,
}

/// Parses `--shard K/N` or `auto`.
pub fn parse_shard(s: &str) -> Result<ShardArg, String> {
    if s.trim() == "auto" {
        return Ok(ShardArg::Auto);
    }
    parse_shard_id(s).map(ShardArg::Fixed)
}

/// Parses `--shards N` (N >= 1).
pub fn parse_shard_count(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "--shards `{s}` is not a whole number of at least 1; give the number of shards, e.g. --shards 4"
        )),
    }
}

/// Parses `--checkpoint-every SECS` (finite, >= 0; 0 saves after every row).
pub fn parse_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && (0.0..=1e9).contains(&x) => Ok(x),
        _ => Err(format!(
            "--checkpoint-every `{s}` is not a number of seconds; give e.g. --checkpoint-every 300"
        )),
    }
}

/// `clothbake info`.
#[derive(Args, Debug)]
pub struct InfoArgs {
    /// A baked table (.exr or .bin).
    #[arg(value_name = "TABLE")]
    pub table: PathBuf,
}

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

/// Facet material overrides (the ranges of fabric files, see `clothbake_core::fabric`).
#[derive(Args, Debug, Default, Clone, Copy, PartialEq)]
pub struct MaterialArgs {
    /// Diffuse albedo rho_d, one value or R,G,B, each in [0, 1].
    #[arg(long, value_name = "R,G,B|X", value_parser = parse_albedo, allow_hyphen_values = true)]
    pub albedo: Option<[f64; 3]>,

    /// Specular coefficient rho_s in [0, 1].
    #[arg(long, value_name = "X", value_parser = parse_specular, allow_hyphen_values = true)]
    pub specular: Option<f64>,

    /// Specular exponent n >= 0 (cloth: 6 to 15).
    #[arg(long, value_name = "N", value_parser = parse_exponent, allow_hyphen_values = true)]
    pub exponent: Option<f64>,

    /// Translucency tau in [0, 1]: the yarn's diffuse transmittance as a share of its diffuse
    /// albedo (t = tau rho_d, with rho_d (1 + tau) + rho_s <= 1); only the two-faced cloth shows
    /// it (docs/science/transmission.md).
    #[arg(long, value_name = "X", value_parser = parse_translucency, allow_hyphen_values = true)]
    pub translucency: Option<f64>,
}

/// Yarn sizes for a WIF draft, in place of its `[WARP]` / `[WEFT]` sizes (docs/reference/wif.md).
#[derive(Args, Debug, Default, Clone, Copy, PartialEq)]
pub struct DraftArgs {
    /// WIF drafts only: yarn radius in mm of every thread, replacing the draft's Thickness
    /// [default: the draft's, else from the spacing in the ratio 1.5 : 3.1, else 0.15].
    #[arg(long, value_name = "MM", value_parser = parse_length)]
    pub radius: Option<f64>,

    /// WIF drafts only: thread spacing (centre to centre) in mm of every thread, replacing the
    /// draft's Spacing [default: the draft's, else from the thickness in the ratio 3.1 : 3.0,
    /// else 0.31].
    #[arg(long, value_name = "MM", value_parser = parse_length)]
    pub spacing: Option<f64>,
}

impl DraftArgs {
    /// The core's options for reading a draft.
    pub fn options(&self) -> clothbake_core::WifOptions {
        clothbake_core::WifOptions {
            radius: self.radius,
            spacing: self.spacing,
        }
    }

    /// True when a size was given.
    pub fn any(&self) -> bool {
        self.radius.is_some() || self.spacing.is_some()
    }
}

/// Parses a positive length in mm (`--radius`, `--spacing`).
pub fn parse_length(s: &str) -> Result<f64, String> {
    const FIX: &str = "give a positive length in millimetres, e.g. 0.15";
    let x = number(s, "length").map_err(|e| format!("{e}; {FIX}"))?;
    if !(x > 0.0 && x.is_finite()) {
        return Err(format!("length {x} is not positive; {FIX}"));
    }
    Ok(x)
}

/// Which cloth: the thesis's over its floor, or the two-faced one (docs/science/transmission.md).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Faces {
    /// One face over the thesis's opaque floor.
    One,
    /// Two faces, no floor: light through the gaps and the yarns.
    Two,
}

/// How to compute the reflection.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// The thesis's analytic direct-reflection model.
    Analytic,
    /// Monte Carlo ray tracing of the explicit micro-geometry (ground truth).
    Raytrace,
}

impl Method {
    /// Name as on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Analytic => "analytic",
            Method::Raytrace => "raytrace",
        }
    }
}

/// `--facet` values (mirrors `clothbake_core::FacetModel`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FacetArg {
    /// Thesis eqs 4.6 and 4.8: I_d = rho_d N.L, I_s = rho_s (N.H)^n.
    Huo,
    /// Lewis's reciprocal, energy-conserving modified Phong.
    Lewis,
}

impl From<FacetArg> for FacetModel {
    fn from(f: FacetArg) -> FacetModel {
        match f {
            FacetArg::Huo => FacetModel::Huo,
            FacetArg::Lewis => FacetModel::Lewis,
        }
    }
}

/// `--variant` values (mirrors `clothbake_core::Variant`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum VariantArg {
    /// Eq. 3.6 as printed, on the equal-area rectangle's top.
    Thesis,
    /// Eq. 3.6 averaged over the arc (default).
    Refined,
    /// Refined, with the side profiles taken slice by slice along each piece: closer to the
    /// ground truth (docs/science/model.md), about 2.5x the cost.
    Sliced,
    /// Sliced, with what hides each slice's side taken in 3-D through the floats around the
    /// piece: the closest to the ground truth (docs/science/model.md); a bake takes 3 to 13 times as
    /// long, one pair at a time about 200 times.
    Sliced3d,
}

impl From<VariantArg> for Variant {
    fn from(v: VariantArg) -> Variant {
        match v {
            VariantArg::Thesis => Variant::Thesis,
            VariantArg::Refined => Variant::Refined,
            VariantArg::Sliced => Variant::Sliced,
            VariantArg::Sliced3d => Variant::Sliced3d,
        }
    }
}

impl From<Variant> for VariantArg {
    fn from(v: Variant) -> VariantArg {
        match v {
            Variant::Thesis => VariantArg::Thesis,
            Variant::Refined => VariantArg::Refined,
            Variant::Sliced => VariantArg::Sliced,
            Variant::Sliced3d => VariantArg::Sliced3d,
        }
    }
}

/// The model's own default ([`Variant::default`]): written once, in clothbake-core.
impl Default for VariantArg {
    fn default() -> VariantArg {
        Variant::default().into()
    }
}

/// `--caps` values (mirrors `clothbake_core::Caps`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum CapsArg {
    /// Caps occlude but are not averaged (default).
    Excluded,
    /// Caps are shaded and averaged like the cylinder sides.
    Shaded,
}

impl From<CapsArg> for Caps {
    fn from(c: CapsArg) -> Caps {
        match c {
            CapsArg::Excluded => Caps::Excluded,
            CapsArg::Shaded => Caps::Shaded,
        }
    }
}

/// `--format` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum FormatArg {
    /// OpenEXR image (docs/reference/table-format.md).
    Exr,
    /// The checksummed binary file, f32 (docs/reference/table-format.md).
    Bin,
}

impl FormatArg {
    /// The file extension (and command-line name).
    pub fn ext(self) -> &'static str {
        match self {
            FormatArg::Exr => "exr",
            FormatArg::Bin => "bin",
        }
    }
}

/// `--precision` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PrecisionArg {
    /// 16-bit half floats.
    F16,
    /// 32-bit floats.
    F32,
}

/// `--bounces`, `--secondary`, `--kernel`: shared by `eval` and the bake.
#[derive(Args, Debug, Clone, Copy, PartialEq)]
pub struct BounceArgs {
    /// 1: direct reflection; 2: adds the secondary reflection I_2 between neighbouring parallel
    /// threads (thesis ch. 5; much slower); N (3 to 64) or all: the direct term plus every
    /// bounce from the second to N path-traced on the micro-geometry, every yarn
    /// (docs/science/transport.md). With `eval --method raytrace` the path tracer estimates every order.
    #[arg(long, value_name = "1|2|N|all", value_parser = parse_bounces, default_value = "1")]
    pub bounces: u32,

    /// With --bounces 2: the secondary reflection's analytic solution (sec. 5.3) or the
    /// thesis's two-level ray-traced sampling (sec. 5.2) [default: analytic].
    #[arg(long, value_enum)]
    pub secondary: Option<SecondaryArg>,

    /// With --bounces 2: weight of the second bounce, the rendering equation's (radiometric)
    /// or the thesis's as printed (larger by pi N.w) [default: radiometric].
    #[arg(long, value_enum)]
    pub kernel: Option<KernelArg>,

    /// With --bounces 2 (analytic): the quadrature orders, `default` (11,5,3: about 0.6% mean
    /// error of I_2), `fast` (7,3,3: under 2%, about 1.5 times faster) or THETA,BETA,AXIAL:
    /// Gauss-Legendre nodes along C1 and across C2 in all, along the axis per lobe panel
    /// (docs/science/interreflection.md) [default: default].
    #[arg(long, value_name = "default|fast|T,B,A", value_parser = parse_orders)]
    pub orders: Option<Orders>,

    /// With --bounces 2 --secondary raytrace: first-level samples, step (radians across C2 and
    /// length along the axis), axial half-length l0, and the patches' solid angle, `exact`
    /// (Siegel & Howell, the thesis's) or `area` (eq. 5.16, about 3 times cheaper)
    /// [default: 32,0.2,1.5,exact: the thesis's].
    #[arg(long, value_name = "N,STEP,L0,exact|area", value_parser = parse_sampling)]
    pub sampling: Option<Sampling>,
}

impl BounceArgs {
    /// The settings as the library takes them.
    pub fn settings(&self) -> Bounces {
        Bounces {
            bounces: self.bounces,
            sampled: self.secondary.map(|s| s == SecondaryArg::Raytrace),
            kernel: self.kernel.map(Kernel::from),
            orders: self.orders,
            sampling: self.sampling,
        }
    }

    /// The first of --secondary, --kernel, --orders and --sampling given, if any: the flags
    /// that set the secondary reflection (what --bounces 2 needs, and a table refuses).
    pub fn secondary_flag(&self) -> Option<&'static str> {
        self.settings().secondary_given().map(|name| match name {
            "secondary" => "--secondary",
            "kernel" => "--kernel",
            "orders" => "--orders",
            _ => "--sampling",
        })
    }

    /// The secondary-reflection options (also for --bounces 1, where they are unused); the
    /// library's rules ([`Bounces::options`]).
    pub fn options(&self) -> Result<SecondaryOptions, CliError> {
        self.settings().options(Naming::Cli).map_err(CliError::line)
    }
}

/// `--secondary` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SecondaryArg {
    /// The analytical solution (thesis sec. 5.3).
    Analytic,
    /// The thesis's two-level ray-traced sampling (sec. 5.2).
    Raytrace,
}

/// `--kernel` values (mirrors `clothbake_core::Kernel`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum KernelArg {
    /// As printed in the thesis: facet intensities times the projected solid angle.
    Thesis,
    /// The rendering equation: facet intensities times d omega / pi.
    Radiometric,
}

impl From<KernelArg> for Kernel {
    fn from(k: KernelArg) -> Kernel {
        match k {
            KernelArg::Thesis => Kernel::Thesis,
            KernelArg::Radiometric => Kernel::Radiometric,
        }
    }
}

/// A direction given on the command line, in degrees.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Direction {
    /// Polar angle from +Z, in [0, 90] (to 180 where a command takes the whole sphere).
    pub theta: f64,
    /// Azimuth from +X toward +Y, any finite value.
    pub phi: f64,
}

impl Direction {
    /// The unit vector.
    pub fn unit(self) -> UnitVec3 {
        UnitVec3::from_degrees(self.theta, self.phi)
    }

    /// False at the horizon (theta = 90), where nothing is lit or seen.
    pub fn above_horizon(self) -> bool {
        self.theta < 90.0
    }

    /// An error unless theta lies in [0, 90] (a cloth over its floor has nothing below).
    pub fn check_upper(self) -> Result<(), String> {
        if (0.0..=90.0).contains(&self.theta) {
            return Ok(());
        }
        Err(format!(
            "theta {} is outside [0, 90]; give the polar angle from the normal +Z, 0 (overhead) \
             to 90 (horizon): directions below the surface need the two-faced cloth \
             (eval --faces two)",
            self.theta
        ))
    }
}

fn number(s: &str, what: &str) -> Result<f64, String> {
    let t = s.trim();
    match t.parse::<f64>() {
        Ok(x) if x.is_finite() => Ok(x),
        Ok(_) => Err(format!("{what} `{t}` is not a finite number")),
        Err(_) => Err(format!("{what} `{t}` is not a number")),
    }
}

/// Parses `THETA,PHI` in degrees; theta must lie in [0, 180] (the commands that take only the
/// upper hemisphere check [`Direction::check_upper`]).
pub fn parse_sphere_direction(s: &str) -> Result<Direction, String> {
    direction(s, 180.0)
}

/// Parses `THETA,PHI` in degrees; theta must lie in [0, 90].
pub fn parse_direction(s: &str) -> Result<Direction, String> {
    direction(s, 90.0)
}

fn direction(s: &str, max: f64) -> Result<Direction, String> {
    const FIX: &str =
        "write THETA,PHI in degrees, e.g. 45,90 (theta from +Z, 0 to 90; phi from +X toward +Y)";
    let parts: Vec<&str> = s.split(',').collect();
    let [t, p] = parts.as_slice() else {
        return Err(format!(
            "expected two numbers separated by a comma, found {}; {FIX}",
            if parts.len() == 1 {
                "one".to_string()
            } else {
                parts.len().to_string()
            }
        ));
    };
    let theta = number(t, "theta").map_err(|e| format!("{e}; {FIX}"))?;
    let phi = number(p, "phi").map_err(|e| format!("{e}; {FIX}"))?;
    let d = Direction { theta, phi };
    if max > 90.0 && !(0.0..=max).contains(&theta) {
        return Err(format!(
            "theta {theta} is outside [0, 90] (or [0, 180] with --faces two); give the polar \
             angle from the normal +Z, 0 (overhead) to 90 (horizon), past 90 behind the cloth"
        ));
    }
    if max <= 90.0 {
        d.check_upper()?;
    }
    Ok(d)
}

/// Parses a point of the weave period, `U,V` in period fractions.
pub fn parse_period_point(s: &str) -> Result<clothbake_core::PeriodPoint, String> {
    const FIX: &str = "write U,V in fractions of the weave period, e.g. 0.25,0.5 (U along the weft +X, V along the warp +Y)";
    let parts: Vec<&str> = s.split(',').collect();
    let [u, v] = parts.as_slice() else {
        return Err(format!(
            "expected two numbers separated by a comma, found {}; {FIX}",
            parts.len()
        ));
    };
    let u = number(u, "U").map_err(|e| format!("{e}; {FIX}"))?;
    let v = number(v, "V").map_err(|e| format!("{e}; {FIX}"))?;
    clothbake_core::PeriodPoint::new(u, v).ok_or_else(|| format!("U and V must be finite; {FIX}"))
}

/// Parses a sample count, 1 to [`clothbake_bake::settings::MAX_SAMPLES`].
pub fn parse_samples(s: &str) -> Result<usize, String> {
    clothbake_bake::settings::parse_samples(s, "--samples")
}

/// Parses the two-faced bake's rays per node (the rule of [`parse_samples`]).
pub fn parse_paths(s: &str) -> Result<usize, String> {
    clothbake_bake::settings::parse_samples(s, "--paths")
}

/// Parses a random seed, a whole number from 0 to 2^64 - 1.
pub fn parse_seed(s: &str) -> Result<u64, String> {
    let t = s.trim();
    match t.parse::<u64>() {
        Ok(n) => Ok(n),
        Err(_) if clothbake_bake::settings::is_whole(t) => Err(format!(
            "--seed {t} is too large (at most {}, 2^64 - 1); give a smaller whole number, e.g. \
             --seed 1",
            u64::MAX
        )),
        Err(_) => Err(format!(
            "`{t}` is not a whole number from 0 to {}; give e.g. --seed 1",
            u64::MAX
        )),
    }
}

fn unit_interval(s: &str, what: &str, fix: &str) -> Result<f64, String> {
    let x = number(s, what).map_err(|e| format!("{e}; {fix}"))?;
    if !(0.0..=1.0).contains(&x) {
        return Err(format!("{what} {x} is outside [0, 1]; {fix}"));
    }
    Ok(x)
}

/// Parses a diffuse albedo: one number or `R,G,B`, each in [0, 1].
pub fn parse_albedo(s: &str) -> Result<[f64; 3], String> {
    const FIX: &str = "give one number or R,G,B, each between 0 and 1, e.g. 0.4 or 0.5,0.2,0.1";
    let parts: Vec<&str> = s.split(',').collect();
    match parts.as_slice() {
        [x] => Ok([unit_interval(x, "albedo", FIX)?; 3]),
        [r, g, b] => Ok([
            unit_interval(r, "albedo R", FIX)?,
            unit_interval(g, "albedo G", FIX)?,
            unit_interval(b, "albedo B", FIX)?,
        ]),
        _ => Err(format!(
            "expected 1 or 3 comma-separated values, found {}; {FIX}",
            parts.len()
        )),
    }
}

/// Parses a specular coefficient rho_s in [0, 1].
pub fn parse_specular(s: &str) -> Result<f64, String> {
    unit_interval(
        s,
        "specular",
        "give a specular coefficient rho_s between 0 and 1, e.g. 0.3",
    )
}

/// Parses a translucency in [0, 1].
pub fn parse_translucency(s: &str) -> Result<f64, String> {
    unit_interval(
        s,
        "translucency",
        "give a translucency between 0 (opaque yarn) and 1 (no absorption), e.g. 0.5",
    )
}

/// A number >= 0 named `what`, or the error with `fix`.
fn non_negative(s: &str, what: &str, fix: &str) -> Result<f64, String> {
    let x = number(s, what).map_err(|e| format!("{e}; {fix}"))?;
    if x < 0.0 {
        return Err(format!("{what} {x} is negative; {fix}"));
    }
    Ok(x)
}

/// Parses a specular exponent n >= 0.
pub fn parse_exponent(s: &str) -> Result<f64, String> {
    non_negative(
        s,
        "exponent",
        "give a non-negative specular exponent n (cloth: 6 to 15), e.g. 10",
    )
}

/// Parses `--res NTI,NPI,NTO,NPO`: four whole numbers of cells, each at least 1, at most
/// 2^31 cells in all.
pub fn parse_res(s: &str) -> Result<Grid, String> {
    const FIX: &str = "give four whole numbers of cells NTI,NPI,NTO,NPO (theta_i, phi_i, theta_o, \
                       phi_o), e.g. 32,64,32,64";
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    if parts.len() != 4 {
        return Err(format!(
            "expected 4 comma-separated numbers, found {}; {FIX}",
            parts.len()
        ));
    }
    let mut n = [0u32; 4];
    for (k, (p, name)) in parts.iter().zip(["NTI", "NPI", "NTO", "NPO"]).enumerate() {
        n[k] = match p.parse::<u32>() {
            Ok(0) => {
                return Err(format!(
                    "{name} is 0; every axis needs at least 1 cell; {FIX}"
                ))
            }
            Ok(x) => x,
            Err(_) if clothbake_bake::settings::is_whole(p) => {
                return Err(format!(
                    "{name} {p} is too large (at most {}, the limit of 2^31 cells in all); {FIX}",
                    clothbake_loader::MAX_CELLS
                ))
            }
            Err(_) => {
                return Err(format!(
                    "{name} `{p}` is not a whole number of cells; {FIX}"
                ))
            }
        };
    }
    let g = Grid::new(n[0], n[1], n[2], n[3]);
    // Exact: a u128 holds any product of four u32 (a u64 product could wrap).
    let cells: u128 = n.iter().map(|&x| u128::from(x)).product();
    if cells > u128::from(clothbake_loader::MAX_CELLS) {
        return Err(format!(
            "{cells} cells is more than the limit of 2^31; use a coarser grid, e.g. 32,64,32,64"
        ));
    }
    Ok(g)
}

/// Parses `--threads N`, 1 <= N <= `MAX_THREADS` (1024).
pub fn parse_threads(s: &str) -> Result<usize, String> {
    clothbake_bake::settings::parse_threads(s, "--threads")
}

/// Parses `--bounces 1|2|N|all`: 1 the direct reflection, 2 the thesis's analytic second
/// bounce, N > 2 or `all` the direct term plus the path-traced orders 2 to N (docs/science/transport.md).
pub fn parse_bounces(s: &str) -> Result<u32, String> {
    const FIX: &str = "give 1 (direct reflection), 2 (direct and the thesis's secondary \
                       reflection, ch. 5), a whole number N from 3 to 64 or `all` (every \
                       bounce, path-traced from the second on; docs/science/transport.md)";
    match s.trim() {
        "all" => Ok(clothbake_bake::transport::ALL_BOUNCES),
        t => match t.parse::<u32>() {
            Ok(n @ 1..=64) => Ok(n),
            _ => Err(format!("`{t}` bounces is not supported; {FIX}")),
        },
    }
}

/// Parses a non-negative finite tolerance.
pub fn parse_tolerance(s: &str) -> Result<f64, String> {
    non_negative(s, "tolerance", "give a non-negative number, e.g. 1e-6")
}

/// The analytic model's facet terms and variant (eval, render, plot).
#[derive(Args, Debug, Clone, Copy)]
pub struct ModelArgs {
    /// Facet reflection model: the thesis's Phong-like terms or Lewis's modified Phong.
    #[arg(long, value_enum, default_value_t = FacetArg::Huo)]
    pub facet: FacetArg,

    /// Analytic variant: eq. 3.6 on the rectangle top as printed (thesis) or averaged over the
    /// arc's true heights (refined, the default; see docs/science/model.md).
    #[arg(long, value_enum, default_value_t = VariantArg::default())]
    pub variant: VariantArg,
}

/// Where the BRDF of `render` and `plot` comes from, and the model's options.
#[derive(Args, Debug, Clone)]
pub struct BrdfArgs {
    /// Shade with the analytic model of this fabric (JSON, see docs/reference/fabric-format.md, a WIF
    /// draft, or a shipped fabric's name).
    #[arg(long, value_name = "FILE")]
    pub weave: Option<PathBuf>,

    /// Shade with this baked table (.exr or .bin); with `plot`, up to two to compare.
    #[arg(long, value_name = "TABLE")]
    pub table: Vec<PathBuf>,

    /// With --weave: --facet, --variant.
    #[command(flatten)]
    pub model: ModelArgs,

    /// With --weave: bounces and the secondary reflection's options (--bounces 2 is slow: about
    /// 0.5 ms a shading point).
    #[command(flatten)]
    pub bounces: BounceArgs,

    /// With --weave: the part of the reflection shown: total (I_1, + I_2 with --bounces 2),
    /// direct (I_1), secondary (I_2 alone) or iss (I_ss alone); the last two need --bounces 2.
    #[arg(long, value_enum, default_value_t = ComponentArg::Total)]
    pub component: ComponentArg,

    /// With --weave: material overrides, applied to both yarn groups.
    #[command(flatten)]
    pub material: MaterialArgs,
}

/// `--component` values (mirrors `clothbake_render::shade::Component`).
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum ComponentArg {
    /// I_1, plus I_2 with --bounces 2.
    Total,
    /// The direct reflection I_1 = I_d + I_s.
    Direct,
    /// The secondary reflection I_2 alone.
    Secondary,
    /// The specular-specular secondary reflection I_ss alone.
    Iss,
}

/// `--scene` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneArg {
    /// A cloth draped as a smooth bicubic-spline height field, side 60, resting on average on z = 0.
    Drape,
    /// The unit sphere at the origin; warp along the meridians, weft along the parallels.
    Sphere,
    /// A flat disk of radius 5 on z = 0 (thesis sec. 5.4).
    Disk,
    /// A flat square swatch of side 60 on z = 0.
    Swatch,
}

/// `--tonemap` values.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum TonemapArg {
    /// Clamp exposure * V to [0, 1], then sRGB.
    Clamp,
    /// x / (1 + x) of x = exposure * V, then sRGB.
    Reinhard,
}

/// `clothbake render`.
#[derive(Args, Debug)]
#[command(
    after_help = "Pixel value (linear, per channel): V = E f_r(wi, wo) C + rho_a s(N) pi f_r(w_k, wo): \
                  a sun toward --light (a disk of 6 degrees' radius: C = cos(theta_i) while it is \
                  up, falling to 0 over a penumbra as it sets, no seam at the terminator) and a sky \
                  over a dim ground (w_k: the normal tilted toward the sky; s(N) from 1 facing up \
                  to 0.2 facing down), directions in the surface's local frame (+X weft, +Y warp, \
                  +Z normal), f_r in 1/sr, E the sun's irradiance on a surface facing it (default pi: \
                  a white Lambertian surface facing it shows 1; facing up it shows rho_a in the sky's \
                  light). V = 0 where the eye sees the back of the surface. \
                  PNG: x = exposure * V, clamped to [0, 1] (or x / (1 + x) with --tonemap reinhard), \
                  sRGB-encoded to 8 bits. EXR: V itself, f32. World: +Z up. See docs/guide/render.md."
)]
pub struct RenderArgs {
    /// The BRDF: --weave FILE (the model) or --table FILE.
    #[command(flatten)]
    pub brdf: BrdfArgs,

    /// The scene.
    #[arg(long, value_enum, default_value_t = SceneArg::Drape)]
    pub scene: SceneArg,

    /// Eye position (world units; the drape and swatch span -30 to 30 in x and y).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,-55,45")]
    pub eye: [f64; 3],

    /// The point the camera looks at.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0,0")]
    pub look_at: [f64; 3],

    /// Direction toward the directional light (normalised here).
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_vec3, allow_hyphen_values = true, default_value = "0,0.707,0.707")]
    pub light: [f64; 3],

    /// Vertical field of view in degrees [default: fits the scene].
    #[arg(long, value_name = "DEG", value_parser = parse_fov)]
    pub fov: Option<f64>,

    /// Image size in pixels: W (square) or W,H.
    #[arg(long, value_name = "W[,H]", value_parser = parse_image_size, default_value = "512")]
    pub res: (u32, u32),

    /// Anti-aliasing: N x N stratified samples per pixel.
    #[arg(long, value_name = "N", value_parser = parse_aa, default_value = "2")]
    pub aa: u32,

    /// Show the weave: N weave periods across the scene's width, f_r looked up at each point of
    /// the period through the pixel's footprint (a table baked with --spatial, or the model;
    /// an averaged table looks the same at any N). Without it: the averaged BRDF everywhere.
    #[arg(long, value_name = "N", value_parser = parse_periods)]
    pub periods: Option<f64>,

    /// Show the gaps between the yarns: each pixel scaled by the coverage of its footprint
    /// (the cloth over black; a table baked with --spatial or the model carries the coverage,
    /// an averaged table counts as opaque).
    #[arg(long)]
    pub gaps: bool,

    /// The ground-truth picture (with --weave and --periods): each sample's ray continues into
    /// the fabric's explicit yarns, tiled over the surface in its tangent frame, with a shadow
    /// ray through the same yarns; with --bounces N (or all), a path a point with every bounce
    /// up to N between the yarns. The reference every level of detail is measured against
    /// (docs/science/spatial.md).
    #[arg(long)]
    pub truth: bool,

    /// With --weave: the `two`-faced cloth (no floor: light through the gaps and translucent
    /// yarns, the back the inverted weave; docs/science/transmission.md), lit and seen from either
    /// side: a --light below the cloth backlights it, and the gaps show what lies behind.
    #[arg(long, value_enum, default_value_t = Faces::One)]
    pub faces: Faces,

    /// The sky's strength rho_a: a white Lambertian surface facing up shows rho_a in the sky's
    /// light (the thesis's ambient coefficient; sec. 4.3 uses 0.3); 0: the sun alone.
    #[arg(long, value_name = "RHO_A", value_parser = parse_ambient, default_value = "0.3")]
    pub ambient: f64,

    /// Irradiance E of the directional light on a surface facing it [default: pi].
    #[arg(long, value_name = "E", value_parser = parse_irradiance)]
    pub irradiance: Option<f64>,

    /// Exposure: a factor, or `auto` (1 / the largest pixel value).
    #[arg(long, value_name = "X|auto", value_parser = parse_exposure, default_value = "1")]
    pub exposure: Exposure,

    /// Tone curve of the PNG.
    #[arg(long, value_enum, default_value_t = TonemapArg::Clamp)]
    pub tonemap: TonemapArg,

    /// Output PNG.
    #[arg(short = 'o', long, value_name = "PATH", default_value = "render.png")]
    pub output: PathBuf,

    /// Also write the linear image as OpenEXR (RGB f32).
    #[arg(long, value_name = "PATH")]
    pub exr: Option<PathBuf>,

    /// --threads, --quiet, --force.
    #[command(flatten)]
    pub run: RunFlags,
}

/// `--exposure` values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Exposure {
    /// A fixed factor.
    Factor(f64),
    /// 1 / the largest pixel value.
    Auto,
}

/// `--kind` values of `plot`.
#[derive(ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub enum PlotKind {
    /// f_r in the plane of incidence, one panel per phi_i, one curve per theta_i.
    Slices,
    /// f_r over the outgoing hemisphere for one wi.
    Hemisphere,
    /// The anisotropy: f_r against the outgoing azimuth, one curve per theta_o, for one wi.
    Polar,
}

/// `clothbake plot`.
#[derive(Args, Debug)]
#[command(
    after_help = "Sources: --weave FILE (the model), --table FILE (once or twice); two sources are \
                  compared in one plot (the second dashed, or beside the first). Values: f_r in 1/sr, \
                  mean of R, G, B. Slices: x is theta_o in the plane of incidence, negative on the \
                  light's side (phi_o = phi_i), positive on the mirror side (phi_o = phi_i + 180). \
                  Hemisphere: x = theta_o cos phi_o, y = theta_o sin phi_o (degrees). Polar: radius f_r, \
                  angle phi_o, one curve per --theta-o. See docs/guide/render.md."
)]
pub struct PlotArgs {
    /// The BRDFs: --weave FILE and/or --table FILE, two sources at most.
    #[command(flatten)]
    pub brdf: BrdfArgs,

    /// What to plot.
    #[arg(long, value_enum, default_value_t = PlotKind::Slices)]
    pub kind: PlotKind,

    /// Slices: polar angles of incidence, degrees (one curve each).
    #[arg(long, value_name = "LIST", value_parser = parse_theta_list, value_delimiter = ',', default_value = "0,30,60,75")]
    pub theta_i: Vec<f64>,

    /// Slices: azimuths of incidence, degrees (one panel each).
    #[arg(long, value_name = "LIST", value_parser = parse_angle_list, value_delimiter = ',', allow_hyphen_values = true, default_value = "0,45,90")]
    pub phi_i: Vec<f64>,

    /// Polar: outgoing polar angles, degrees (one curve each).
    #[arg(long, value_name = "LIST", value_parser = parse_theta_list, value_delimiter = ',', default_value = "20,45,70")]
    pub theta_o: Vec<f64>,

    /// Hemisphere and polar: the direction toward the light, THETA,PHI in degrees.
    #[arg(long, value_name = "THETA,PHI", value_parser = parse_direction, allow_hyphen_values = true, default_value = "45,0")]
    pub wi: Direction,

    /// Output files, .png or .svg (repeat for both) [default: plot.png and plot.svg].
    #[arg(short = 'o', long, value_name = "PATH")]
    pub output: Vec<PathBuf>,

    /// Overwrite existing output files.
    #[arg(long)]
    pub force: bool,
}

/// Parses `X,Y,Z`: three finite numbers.
pub fn parse_vec3(s: &str) -> Result<[f64; 3], String> {
    const FIX: &str = "write X,Y,Z, three numbers separated by commas, each from -1000000 to \
                       1000000 (the scenes span about 100 units), e.g. 0,-55,45";
    let parts: Vec<&str> = s.split(',').collect();
    let [x, y, z] = parts.as_slice() else {
        return Err(format!(
            "expected 3 comma-separated numbers, found {}; {FIX}",
            parts.len()
        ));
    };
    let coordinate = |p: &str, name: &str| {
        let v = number(p, name).map_err(|e| format!("{e}; {FIX}"))?;
        if v.abs() > MAX_COORDINATE {
            return Err(format!("{name} {v} is outside [-1000000, 1000000]; {FIX}"));
        }
        Ok(v)
    };
    Ok([
        coordinate(x, "X")?,
        coordinate(y, "Y")?,
        coordinate(z, "Z")?,
    ])
}

/// The largest magnitude of a render's coordinates and light components (`--eye`,
/// `--look-at`, `--light`): far beyond the scenes (about 100 units across), and small enough
/// that every product and sum of the camera's and the light's arithmetic stays finite.
pub const MAX_COORDINATE: f64 = 1e6;

/// The largest `--irradiance` and `--exposure`: a pixel value (at most 1e30 1/sr, a table's
/// limit, times the irradiance) and its exposed value stay finite in f32.
pub const MAX_LIGHT: f64 = 1e6;

/// Parses a field of view in (0, 180) degrees.
pub fn parse_fov(s: &str) -> Result<f64, String> {
    const FIX: &str = "give the vertical field of view in degrees, between 0 and 180, e.g. 40";
    let x = number(s, "field of view").map_err(|e| format!("{e}; {FIX}"))?;
    if !(x > 0.0 && x < 180.0) {
        return Err(format!("field of view {x} is outside (0, 180); {FIX}"));
    }
    Ok(x)
}

/// Parses `W` or `W,H`, each 1 to 16384 pixels.
pub fn parse_image_size(s: &str) -> Result<(u32, u32), String> {
    const FIX: &str =
        "give the image size in pixels, W or W,H, each 1 to 16384, e.g. 512 or 640,480";
    let parse = |p: &str| match p.trim().parse::<u32>() {
        Ok(n) if (1..=16384).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{}` is not a size from 1 to 16384; {FIX}",
            p.trim()
        )),
    };
    let parts: Vec<&str> = s.split(',').collect();
    match parts.as_slice() {
        [w] => parse(w).map(|w| (w, w)),
        [w, h] => Ok((parse(w)?, parse(h)?)),
        _ => Err(format!(
            "expected 1 or 2 comma-separated sizes, found {}; {FIX}",
            parts.len()
        )),
    }
}

/// Parses `--aa N`, 1 to 16.
pub fn parse_aa(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if (1..=16).contains(&n) => Ok(n),
        _ => Err(format!(
            "`{}` is not a whole number from 1 to 16; give the samples per pixel side, e.g. --aa 2",
            s.trim()
        )),
    }
}

/// Parses `--width`: a footprint's side in periods, 0 to 10^6.
pub fn parse_width(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(w) if (0.0..=1e6).contains(&w) => Ok(w),
        _ => Err(format!(
            "`{}` is not a footprint width from 0 to 1000000 periods; give e.g. --width 0.1 \
             (0: the point itself)",
            s.trim()
        )),
    }
}

/// Parses `--periods`: a number of weave periods, more than 0 and at most 10^6.
pub fn parse_periods(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(n) if n > 0.0 && n <= 1e6 => Ok(n),
        _ => Err(format!(
            "`{}` is not a number of weave periods from just above 0 to 1000000; give e.g. \
             --periods 12",
            s.trim()
        )),
    }
}

/// Parses rho_a in [0, 1].
pub fn parse_ambient(s: &str) -> Result<f64, String> {
    unit_interval(
        s,
        "ambient",
        "give the sky's strength rho_a between 0 and 1, e.g. 0.3",
    )
}

/// Parses an irradiance from 0 to [`MAX_LIGHT`].
pub fn parse_irradiance(s: &str) -> Result<f64, String> {
    const FIX: &str = "give an irradiance from 0 to 1000000, e.g. 3.14159 (pi, the default)";
    let x = non_negative(s, "irradiance", FIX)?;
    if x > MAX_LIGHT {
        return Err(format!("irradiance {x} is more than 1000000; {FIX}"));
    }
    Ok(x)
}

/// Parses `--exposure X|auto`, X > 0.
pub fn parse_exposure(s: &str) -> Result<Exposure, String> {
    const FIX: &str = "give a positive factor up to 1000000, e.g. 1.5, or auto";
    if s.trim().eq_ignore_ascii_case("auto") {
        return Ok(Exposure::Auto);
    }
    let x = number(s, "exposure").map_err(|e| format!("{e}; {FIX}"))?;
    if x <= 0.0 {
        return Err(format!("exposure {x} is not positive; {FIX}"));
    }
    if x > MAX_LIGHT {
        return Err(format!("exposure {x} is more than 1000000; {FIX}"));
    }
    Ok(Exposure::Factor(x))
}

/// Parses one angle of a comma-separated list of angles in degrees.
pub fn parse_angle_list(s: &str) -> Result<f64, String> {
    number(s, "angle")
        .map_err(|e| format!("{e}; give angles in degrees separated by commas, e.g. 0,45,90"))
}

/// Parses one polar angle of a comma-separated list, each in [0, 90).
pub fn parse_theta_list(s: &str) -> Result<f64, String> {
    const FIX: &str =
        "give polar angles in degrees from 0 to below 90, separated by commas, e.g. 0,30,60";
    let x = number(s, "theta").map_err(|e| format!("{e}; {FIX}"))?;
    if !(0.0..90.0).contains(&x) {
        return Err(format!("theta {x} is outside [0, 90); {FIX}"));
    }
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;
    use clothbake_core::interreflection::ORDERS_FAST;

    #[test]
    fn clap_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    #[test]
    fn secondary_orders_and_sampling() {
        assert_eq!(parse_orders("fast").unwrap(), ORDERS_FAST);
        assert_eq!(parse_orders(" default ").unwrap(), Orders::default());
        let o = parse_orders("8, 4, 2").unwrap();
        assert_eq!((o.theta, o.beta, o.axial, o.tol), (8, 4, 2, 0.0));
        let p = parse_sampling("28,0.15,3,area").unwrap();
        assert_eq!(
            (p.first_level, p.d_alpha, p.d_l, p.l0, p.exact_solid_angle),
            (28, 0.15, 0.15, 3.0, false)
        );
        assert!(parse_sampling("32,0.2,1.5,exact").unwrap() == Sampling::default());
        for bad in ["", "1,2", "0,1,1", "1,1,65", "a,1,1", "-1,1,1"] {
            let e = parse_orders(bad).unwrap_err();
            assert!(!e.contains('\n') && e.contains("THETA,BETA,AXIAL"), "{e}");
        }
        for bad in [
            "",
            "32,0.2,1.5",
            "0,0.2,1.5,exact",
            "32,2,1.5,exact",
            "32,0.2,-1,area",
        ] {
            let e = parse_sampling(bad).unwrap_err();
            assert!(!e.contains('\n') && e.contains("N,STEP,L0"), "{e}");
        }
    }

    #[test]
    fn directions() {
        assert_eq!(
            parse_direction("45,90").unwrap(),
            Direction {
                theta: 45.0,
                phi: 90.0
            }
        );
        assert_eq!(
            parse_direction(" 0 , -30.5 ").unwrap(),
            Direction {
                theta: 0.0,
                phi: -30.5
            }
        );
        assert!(parse_direction("90,0").unwrap().theta == 90.0);
        for bad in [
            "45", "45,", "a,1", "1,2,3", "91,0", "-1,0", "nan,0", "45,inf", "",
        ] {
            let e = parse_direction(bad).unwrap_err();
            assert!(!e.contains('\n'), "{e}");
        }
        assert!(parse_direction("91,0")
            .unwrap_err()
            .contains("outside [0, 90]"));
    }

    #[test]
    fn materials() {
        assert_eq!(parse_albedo("0.5").unwrap(), [0.5; 3]);
        assert_eq!(parse_albedo("0.5,0.2,0.1").unwrap(), [0.5, 0.2, 0.1]);
        assert!(parse_albedo("0.5,1.2,0.1")
            .unwrap_err()
            .contains("albedo G 1.2"));
        assert!(parse_albedo("0.5,0.2").is_err());
        assert!(parse_albedo("nan").is_err());
        assert!(parse_specular("1.0").is_ok());
        assert!(parse_specular("-0.1").is_err());
        assert_eq!(parse_exponent("0").unwrap(), 0.0);
        assert!(parse_exponent("-1").is_err());
        assert!(parse_exponent("inf").is_err());
        assert!(parse_samples("0").is_err());
        assert_eq!(parse_samples("10").unwrap(), 10);
    }

    #[test]
    fn grids() {
        assert_eq!(
            parse_res("32,64,32,64").unwrap(),
            clothbake_bake::DEFAULT_GRID
        );
        assert_eq!(parse_res(" 1, 2 ,3,4").unwrap().n_phi_o, 4);
        for (bad, needle) in [
            ("32,64,32", "found 3"),
            ("32,64,32,64,1", "found 5"),
            ("0,64,32,64", "NTI is 0"),
            ("32,x,32,64", "NPI `x`"),
            ("32,64,-1,64", "NTO `-1`"),
            ("32,64,32,6.5", "NPO `6.5`"),
            ("2048,2048,2048,2048", "2^31"),
        ] {
            let e = parse_res(bad).unwrap_err();
            assert!(e.contains(needle) && !e.contains('\n'), "{bad}: {e}");
        }
        assert!(parse_threads("0").is_err());
        assert_eq!(parse_threads("3").unwrap(), 3);
        assert!(parse_bounces("0").unwrap_err().contains("give 1"));
        assert!(parse_bounces("65").unwrap_err().contains("give 1"));
        assert_eq!(parse_bounces("3").unwrap(), 3);
        assert_eq!(
            parse_bounces(" all").unwrap(),
            clothbake_bake::transport::ALL_BOUNCES
        );
        assert_eq!(parse_bounces("2").unwrap(), 2);
        assert!(parse_tolerance("-1").is_err());
        assert!(parse_tolerance("inf").is_err());
        assert_eq!(parse_tolerance("1e-3").unwrap(), 1e-3);
    }
}
