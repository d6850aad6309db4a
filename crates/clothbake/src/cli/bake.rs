//! `clothbake bake` and `merge`: the bake's options (grid, model, bounces, output, shards,
//! checkpoints) and the table format.

use super::*;

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
