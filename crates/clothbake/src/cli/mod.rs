//! The command line: clap definitions and the value parsers behind them.
//!
//! Layout: `clothbake --weave FILE [options]` (default mode: bake a table, the same as
//! `clothbake bake --weave FILE [options]`), `clothbake eval --weave FILE --wi THETA,PHI
//! --wo THETA,PHI [...]`, `clothbake info TABLE` and `clothbake diff A B`. The bake options live
//! in [`BakeOpts`], flattened into both [`Cli`] (default mode) and [`BakeCmd`] (the subcommand).
//!
//! One file a command's options (`bake`, `model` for eval and the model's shared options,
//! `export` for info, export and diff, `render` for render and plot) and `values` for the
//! parsers; this one holds the top level.

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

mod bake;
mod export;
mod model;
mod render;
mod values;

pub use bake::*;
pub use export::*;
pub use model::*;
pub use render::*;
pub use values::*;

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
