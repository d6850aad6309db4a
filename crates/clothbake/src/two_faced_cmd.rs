//! `clothbake eval --faces two`: the two-faced cloth (docs/science/transmission.md) for one light and
//! one eye direction anywhere on the sphere: f (reflection on either face, or transmission) and
//! the openness along the light.

use crate::cli::{EvalArgs, Method, DEFAULT_SAMPLES, DEFAULT_SEED};
use crate::error::CliError;
use crate::resolve;
use clothbake_bake::two_faced::{TwoFaced, MAX_BOUNCES};
use clothbake_core::{Bsdf, FacetModel, UnitVec3};
use clothbake_truth::RayTracer;
use serde_json::json;

/// What the pair (wi, wo) measures on the two-faced cloth.
fn kind(wi: UnitVec3, wo: UnitVec3) -> &'static str {
    match (wi.z > 0.0, wo.z > 0.0) {
        (true, true) => "reflection off the front",
        (false, false) => "reflection off the back",
        (true, false) => "transmission, light on the front",
        (false, true) => "transmission, light on the back",
    }
}

/// Runs `eval --faces two`.
pub fn run(args: &EvalArgs) -> Result<String, CliError> {
    let b = &args.bounces;
    let refused = [
        ("--at", args.at.is_some()),
        ("--bounces", b.bounces != 1),
        ("--secondary", b.secondary.is_some()),
        ("--kernel", b.kernel.is_some()),
        ("--orders", b.orders.is_some()),
        ("--sampling", b.sampling.is_some()),
    ];
    if let Some((flag, _)) = refused.iter().find(|(_, given)| *given) {
        return Err(CliError::new(
            format!(
                "{flag} does not apply to the two-faced cloth: its f holds every bounce, \
                 averaged over the period"
            ),
            format!("drop {flag}, or drop --faces two"),
        ));
    }
    if args.method == Method::Analytic && (args.samples.is_some() || args.seed.is_some()) {
        return Err(CliError::new(
            "--samples and --seed apply only to the ray tracer here (the model's path-traced \
             rest has fixed nodes)",
            "add --method raytrace, or drop them",
        ));
    }
    let (wi, wo) = (args.wi.unit(), args.wo.unit());
    let sided = |w: UnitVec3| w.above_horizon() || w.below_horizon();
    let fabric = resolve::fabric(&args.weave, &args.draft, &args.material)?;
    let facet = FacetModel::from(args.model.facet);
    let (f, std_err, openness, how) = match args.method {
        Method::Analytic => {
            let variant = resolve::variant(&args.weave, &fabric, args.model.variant)?;
            let tf = TwoFaced::new(&fabric, facet, variant)?;
            (
                tf.f(wi, wo),
                None,
                tf.openness(wi),
                "analytic direct reflection and openness, the rest path-traced on a coarse grid",
            )
        }
        Method::Raytrace => {
            let samples = args.samples.unwrap_or(DEFAULT_SAMPLES);
            let seed = args.seed.unwrap_or(DEFAULT_SEED);
            let rt = RayTracer::two_faced(&fabric, facet);
            let (f, e) = if sided(wi) && sided(wo) {
                rt.render_sphere(wi, wo, samples, seed, MAX_BOUNCES)
            } else {
                ([0.0; 3], [0.0; 3])
            };
            (
                f,
                Some(e),
                rt.openness(wi, samples, seed),
                "ray tracer of the two-faced micro-geometry, every bounce",
            )
        }
    };
    let kind = kind(wi, wo);
    if args.json {
        let mut v = json!({
            "faces": "two",
            "kind": kind,
            "f": f,
            "openness": openness,
            "method": how,
        });
        if let Some(e) = std_err {
            v["std_err"] = json!(e);
        }
        return Ok(format!("{v}\n"));
    }
    let mut out = format!(
        "{} (two-faced cloth), {kind}\n  f          {:.6} {:.6} {:.6} 1/sr\n",
        fabric.name(),
        f[0],
        f[1],
        f[2]
    );
    if let Some(e) = std_err {
        out += &format!("  std. error {:.6} {:.6} {:.6}\n", e[0], e[1], e[2]);
    }
    out += &format!(
        "  openness   {openness:.6} (the share of the light from --wi passing straight \
         through the gaps)\n  method     {how}\n"
    );
    Ok(out)
}
