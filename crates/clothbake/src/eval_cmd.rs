//! `clothbake eval`: the reflection of a fabric for one light and one eye direction.

use crate::cli::{EvalArgs, Method, DEFAULT_SAMPLES, DEFAULT_SEED};
use crate::error::CliError;
use crate::report::{self, Report};
use crate::resolve;
use clothbake_bake::transport::Transport;
use clothbake_core::interreflection::Ranges;
use clothbake_core::{
    AnalyticBsdf, AnalyticModel, Bsdf, Component, Fabric, FacetModel, Footprint, Level, Reflection,
    Secondary, SecondaryMethod, SecondaryOptions, UnitVec3, Variant,
};
use clothbake_truth::pathtracer::PathOptions;
use clothbake_truth::{Caps, RayTracer};

/// Runs `clothbake eval` and returns the text to print on stdout.
pub fn run(args: &EvalArgs) -> Result<String, CliError> {
    for (flag, d) in [("--wi", args.wi), ("--wo", args.wo)] {
        d.check_upper()
            .map_err(|e| CliError::line(format!("{flag}: {e}")))?;
    }
    let full = args.bounces.bounces > 2;
    if args.method == Method::Analytic && !full && (args.samples.is_some() || args.seed.is_some()) {
        return Err(CliError::new(
            "--samples and --seed apply only to the ray tracer and the path-traced bounces",
            "add --method raytrace or --bounces all, or drop them",
        ));
    }
    if full && args.at.is_some() {
        return Err(CliError::new(
            "--at resolves the direct reflection per crossing cell; the path-traced bounces of \
             --bounces N > 2 or all are the period's average",
            "drop --at or use --bounces 1 or 2",
        ));
    }
    let opts = args.bounces.options()?;
    let b = &args.bounces;
    let solution = [
        ("--secondary", b.secondary.is_some()),
        ("--orders", b.orders.is_some()),
        ("--sampling", b.sampling.is_some()),
    ];
    if let (Method::Raytrace, Some((flag, _))) =
        (args.method, solution.iter().find(|(_, given)| *given))
    {
        return Err(CliError::new(
            format!(
                "{flag} sets the analytic model's solution of I_2; with --method raytrace the \
                 path tracer computes I_2"
            ),
            format!("drop {flag} or use --method analytic"),
        ));
    }
    if args.at.is_some() && args.method == Method::Raytrace {
        return Err(CliError::new(
            "--at evaluates the analytic model at a point of the period; the ray tracer \
             answers only the period's average here",
            "drop --at or --method raytrace",
        ));
    }
    let kernel = opts.kernel;
    let secondary = (args.bounces.bounces == 2).then_some(opts);
    let fabric = resolve::fabric(&args.weave, &args.draft, &args.material)?;
    let facet = FacetModel::from(args.model.facet);
    let (wi, wo) = (args.wi.unit(), args.wo.unit());
    let horizon = !(args.wi.above_horizon() && args.wo.above_horizon());

    let mut local = None;
    let mut footprint_seen = None;
    let transport = full.then(|| {
        let samples = args.samples.unwrap_or(DEFAULT_SAMPLES);
        let seed = args.seed.unwrap_or(DEFAULT_SEED);
        let tracer = RayTracer::new(&fabric, facet).with_caps(args.caps.into());
        Transport::new(tracer, args.bounces.bounces, samples, seed)
    });
    let (reflection, raytrace) = match args.method {
        Method::Analytic => {
            let variant = resolve::variant(&args.weave, &fabric, args.model.variant)?;
            let model = AnalyticModel::with_variant(&fabric, facet, variant)?;
            let coverage = if horizon { 0.0 } else { model.coverage(wo) };
            let at = args.at.map(|p| (p, model.cells().cell_at(p)));
            // With --at the footprint's reflection replaces the period's in the report.
            let r = if horizon || at.is_some() {
                Reflection {
                    secondary: secondary.map(|_| Secondary::default()),
                    ..Reflection::default()
                }
            } else {
                model.intensity_with(wi, wo, secondary.as_ref())
            };
            // With --at, the footprint through the BSDF (docs/science/spatial.md): f_r and coverage
            // from one call, at the level of detail its width asks for.
            let seen = at.map(|(p, _)| {
                let fp = Footprint {
                    u: p.u(),
                    v: p.v(),
                    width: args.width.unwrap_or(0.0),
                };
                footprint(&fabric, model, secondary, fp, wi, wo)
            });
            local = Some(report::Local {
                directional_coverage: coverage,
                warp_on_top: at
                    .is_some_and(|(_, cell)| fabric.weave().warp_over(cell.warp, cell.weft)),
                at: at.map(|(p, cell)| (p, cell, seen.map_or(0.0, |s| s.1))),
            });
            footprint_seen = seen.map(|s| s.0);
            (r, None)
        }
        Method::Raytrace => {
            let samples = args.samples.unwrap_or(DEFAULT_SAMPLES);
            let seed = args.seed.unwrap_or(DEFAULT_SEED);
            let tracer = RayTracer::new(&fabric, facet).with_caps(args.caps.into());
            let (r, std_err) = if horizon {
                (
                    Reflection {
                        secondary: secondary.map(|_| Secondary::default()),
                        ..Reflection::default()
                    },
                    [0.0; 3],
                )
            } else if full {
                // The direct reflection by the ray tracer; the later orders below.
                let est = tracer.render(wi, wo, samples, seed);
                (est.reflection, est.std_err)
            } else if args.bounces.bounces == 2 {
                // The path tracer: orders 1 and 2, I_2 split into its four components.
                let opts = PathOptions {
                    max_bounces: 2,
                    kernel,
                    roulette_from: 9,
                    first_order: 1,
                };
                let p = tracer.render_paths(wi, wo, samples, seed, opts);
                let direct = tracer.render(wi, wo, samples, seed);
                let mut r = direct.reflection;
                r.secondary = Some(p.secondary);
                let err = std::array::from_fn(|c| direct.std_err[c].hypot(p.std_err[1][c]));
                (r, err)
            } else {
                let est = tracer.render(wi, wo, samples, seed);
                (est.reflection, est.std_err)
            };
            (r, Some(report::Raytrace { std_err, samples }))
        }
    };
    let transport = transport.map(|t| {
        let p = t.multiple(wi, wo);
        let direct = reflection.direct();
        let direct_err = raytrace.map_or([0.0; 3], |r| r.std_err);
        // Orders past the last one any path reached carry nothing: leave them out.
        let last = p
            .orders
            .iter()
            .rposition(|o| o.iter().any(|&x| x != 0.0))
            .unwrap_or(0)
            .max(1);
        let mut orders = vec![direct];
        orders.extend_from_slice(&p.orders[1..=last.min(p.orders.len() - 1)]);
        let mut std_err = vec![direct_err];
        std_err.extend_from_slice(&p.std_err[1..orders.len()]);
        report::Transport {
            total: std::array::from_fn(|c| direct[c] + p.multiple[c]),
            orders,
            std_err,
            i2_split: p.i2_split,
            i2_split_err: p.i2_split_err,
            multiple: (p.multiple, p.multiple_err),
            paths: t.paths(),
            seed: t.seed(),
        }
    });
    let brdf = if horizon {
        [0.0; 3]
    } else if let Some(f) = &footprint_seen {
        f.i.map(|i| i / (std::f64::consts::PI * wi.cos_theta()))
    } else if let Some(t) = &transport {
        clothbake_core::intensity_to_brdf(t.total, wi)
    } else {
        reflection.brdf(wi)
    };
    let bounces = match args.bounces.bounces {
        1 => "1 bounce".to_string(),
        n if n > 2 => format!(
            "{} bounces (orders 2 and up path-traced, radiometric kernel)",
            clothbake_bake::transport::bounces_name(n)
        ),
        n => format!("{n} bounces"),
    };
    let settings = match args.method {
        Method::Analytic => format!(
            "variant {}, {bounces}",
            Variant::from(args.model.variant).name()
        ),
        Method::Raytrace => format!("caps {}, {bounces}", Caps::from(args.caps).name()),
    };
    let secondary = secondary.map(|o| match args.method {
        Method::Analytic => describe_secondary(&o),
        Method::Raytrace => format!("path tracer, {} kernel", o.kernel.name()),
    });
    let rep = Report {
        fabric_name: fabric.name(),
        file: &args.weave,
        notes: fabric.notes(),
        method: args.method,
        facet,
        settings,
        secondary,
        wi: args.wi,
        wo: args.wo,
        horizon,
        reflection,
        brdf,
        raytrace,
        local,
        transport,
        footprint: footprint_seen,
    };
    Ok(if args.json { rep.json() } else { rep.table() })
}

/// The reflection of a footprint through the model's BSDF (`Bsdf::local`), with the fabric's
/// yarns for the point level at one bounce, and its coverage. With two bounces its I_2 from the
/// same footprint (`Component::Secondary`: the crossing cells or the period).
fn footprint(
    fabric: &Fabric,
    model: AnalyticModel,
    secondary: Option<SecondaryOptions>,
    at: Footprint,
    wi: UnitVec3,
    wo: UnitVec3,
) -> (report::AtFootprint, f64) {
    let facet = model.facet();
    let i2_bsdf = secondary.and_then(|_| {
        AnalyticBsdf::new(model.clone(), secondary).with_component(Component::Secondary)
    });
    let mut bsdf = AnalyticBsdf::new(model, secondary);
    if secondary.is_none() {
        if let Some(y) = clothbake_core::point::yarns(fabric, facet) {
            bsdf = bsdf.with_yarns(y);
        }
    }
    // The point level answers only where the BSDF has the yarns (one bounce, a period of at
    // most MAX_YARNS segments).
    let traced = bsdf.yarns().is_some();
    let level = match at.level(bsdf.cell_width()) {
        Level::Period => "the period (averaged)",
        Level::Local { point, points, .. } if traced && point >= 1.0 => {
            if points == 1 {
                "the point (the yarns traced)"
            } else {
                "the point level over the footprint (the yarns traced)"
            }
        }
        Level::Local { point, .. } if traced && point > 0.0 => {
            "the point level and the crossing cells, blended"
        }
        Level::Local { .. } => "the crossing cells",
    };
    let l = bsdf.local(at, wi, wo);
    let k = std::f64::consts::PI * wi.cos_theta();
    let i2 = i2_bsdf.map(|b| b.f_at(at, wi, wo).map(|f| f * k));
    (
        report::AtFootprint {
            width: at.width,
            level,
            i: l.f.map(|f| f * k),
            i2,
        },
        l.coverage,
    )
}

/// How the analytic model computes I_2, in words: the solution with its quadrature orders or
/// sampling settings, and the kernel.
pub fn describe_secondary(o: &SecondaryOptions) -> String {
    let how = match &o.method {
        SecondaryMethod::Analytic { ranges, orders } => {
            let nodes = if orders.tol > 0.0 {
                format!(
                    "adaptive along C1 (tol {}), {},{}",
                    orders.tol, orders.beta, orders.axial
                )
            } else {
                format!("{},{},{}", orders.theta, orders.beta, orders.axial)
            };
            let ranges = match ranges {
                Ranges::Full => "full ranges".to_string(),
                Ranges::Thesis { .. } => "the thesis's ranges".to_string(),
            };
            format!("analytic solution (sec. 5.3), orders {nodes} (theta,beta,axial), {ranges}")
        }
        SecondaryMethod::Sampling(p) => format!(
            "two-level sampling (sec. 5.2), {} first-level samples, steps {} rad and {}, l0 {}, \
             {} solid angles",
            p.first_level,
            p.d_alpha,
            p.d_l,
            p.l0,
            if p.exact_solid_angle { "exact" } else { "area" }
        ),
    };
    format!("{how}, {} kernel", o.kernel.name())
}

#[cfg(test)]
mod tests {
    use crate::cli::Direction;

    #[test]
    fn horizon_direction() {
        assert!(!Direction {
            theta: 90.0,
            phi: 0.0
        }
        .above_horizon());
        assert!(Direction {
            theta: 89.9,
            phi: 0.0
        }
        .above_horizon());
    }
}
