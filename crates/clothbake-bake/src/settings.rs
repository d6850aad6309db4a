//! The bake options as a user gives them (command-line flags, Python keywords), checked and
//! resolved into [`BakeOptions`] by one set of rules, with messages in the caller's spelling
//! ([`Naming`]).

use crate::sweep::{check_options, BakeBounces, BakeOptions, Method, DEFAULT_GRID};
use clothbake_core::interreflection::{Orders, Ranges, Sampling, ORDERS_FAST};
use clothbake_core::{FacetModel, Kernel, SecondaryMethod, SecondaryOptions, Variant};
use clothbake_loader::{Faces, Grid};
use clothbake_truth::Caps;

/// The most worker threads a command starts (`--threads`): far more than cores gains nothing
/// (the work is CPU-bound) and a pool of 100 000 threads takes minutes to start, during which
/// SIGTERM waits.
pub const MAX_THREADS: usize = 1024;

/// Checks a worker thread count given as text: a whole number from 1 to [`MAX_THREADS`].
/// `flag` spells the option in messages (`--threads`).
pub fn parse_threads(s: &str, flag: &str) -> Result<usize, String> {
    let t = s.trim();
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let too_many = || {
        format!(
            "{flag} {t} is too large (at most {MAX_THREADS}); this machine has {cores} cores: \
             give e.g. {flag} {cores}, or leave it out to use them all"
        )
    };
    match t.parse::<usize>() {
        Ok(0) => Err(format!(
            "the thread count must be at least 1; give e.g. {flag} 2 (or leave it out to use \
             all cores)"
        )),
        Ok(n) if n > MAX_THREADS => Err(too_many()),
        Ok(n) => Ok(n),
        Err(_) if is_whole(t) => Err(too_many()),
        Err(_) => Err(format!(
            "`{t}` is not a whole number of threads; give e.g. {flag} 2"
        )),
    }
}

/// Whether `s` is written as a whole number (ASCII digits, an optional leading `+`), however
/// large.
pub fn is_whole(s: &str) -> bool {
    let d = s.strip_prefix('+').unwrap_or(s);
    !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit())
}

/// Rays per cell of the ray tracer unless given.
pub const DEFAULT_SAMPLES: usize = 100_000;

/// The most rays (or paths) per direction pair: 2^24 = 16,777,216, 168 times the default
/// (a standard error 13 times smaller), about 3 s of the ray tracer and 20 s of the path
/// tracer of `--bounces all` on one core; the work of a bake is this times its bounded grid.
pub const MAX_SAMPLES: usize = 1 << 24;

/// Checks a sample count given as text: a whole number from 1 to [`MAX_SAMPLES`]. `flag`
/// spells the option in messages (`--samples`).
pub fn parse_samples(s: &str, flag: &str) -> Result<usize, String> {
    let t = s.trim();
    let fix = format!(
        "give a whole number from 1 to {MAX_SAMPLES} (2^24), e.g. {flag} {DEFAULT_SAMPLES}"
    );
    match t.parse::<usize>() {
        Ok(0) => Err(format!(
            "{flag} 0: the sample count must be at least 1; {fix}"
        )),
        Ok(n) if n <= MAX_SAMPLES => Ok(n),
        Err(_) if !is_whole(t) => Err(format!("`{t}` is not a whole number of samples; {fix}")),
        _ => Err(format!(
            "{flag} {t} is too large (at most {MAX_SAMPLES}); {fix}"
        )),
    }
}
/// The ray tracer's base seed unless given.
pub const DEFAULT_SEED: u64 = 1;

/// How messages spell an option: `--samples` and `--method raytrace` on the command line,
/// `samples=` and `method="raytrace"` in Python.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Naming {
    /// Command-line flags.
    Cli,
    /// Python keyword arguments.
    Python,
}

impl Naming {
    /// The option `name` (`samples`): `--samples` or `samples=`.
    pub fn flag(self, name: &str) -> String {
        match self {
            Naming::Cli => format!("--{name}"),
            Naming::Python => format!("{name}="),
        }
    }

    /// The option `name` set to the word `value`: `--method raytrace` or `method="raytrace"`.
    pub fn word(self, name: &str, value: &str) -> String {
        match self {
            Naming::Cli => format!("--{name} {value}"),
            Naming::Python => format!("{name}=\"{value}\""),
        }
    }

    /// The switch `name` turned on: `--resume` or `resume=True`.
    pub fn switch(self, name: &str) -> String {
        match self {
            Naming::Cli => format!("--{name}"),
            Naming::Python => format!("{name}=True"),
        }
    }

    /// Doing it again the same way: `the same command` or `bake() again`.
    pub fn again(self) -> &'static str {
        match self {
            Naming::Cli => "run the same command",
            Naming::Python => "call bake() again",
        }
    }

    /// The option `name` set to the number `value`: `--bounces 2` or `bounces=2`.
    pub fn number(self, name: &str, value: &str) -> String {
        match self {
            Naming::Cli => format!("--{name} {value}"),
            Naming::Python => format!("{name}={value}"),
        }
    }
}

/// Every bake option as given; `None`: not given (the default applies).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Settings {
    /// The grid [default: [`DEFAULT_GRID`]].
    pub grid: Option<Grid>,
    /// Facet model.
    pub facet: FacetModel,
    /// The ray tracer instead of the analytic model.
    pub raytrace: bool,
    /// Analytic variant [default: refined].
    pub variant: Option<Variant>,
    /// Ray tracer: rays per cell.
    pub samples: Option<usize>,
    /// Ray tracer: base seed.
    pub seed: Option<u64>,
    /// Ray tracer: end caps.
    pub caps: Option<Caps>,
    /// The secondary-reflection settings.
    pub bounces: Bounces,
    /// A spatially varying table (docs/science/spatial.md).
    pub spatial: bool,
    /// The two-faced cloth over the sphere (docs/science/transmission.md): the grid's polar counts
    /// are per side.
    pub faces: Faces,
    /// A two-faced bake's eye rays per node of its path-traced rest.
    pub paths: Option<usize>,
}

/// The bounces and the secondary reflection's settings as given.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounces {
    /// 1, 2, N > 2 or `clothbake_bake::transport::ALL_BOUNCES` (docs/science/transport.md).
    pub bounces: u32,
    /// `Some(true)`: the two-level sampling; `Some(false)`: the analytic solution [default].
    pub sampled: Option<bool>,
    /// Weight of the second bounce [default: radiometric].
    pub kernel: Option<Kernel>,
    /// Quadrature orders of the analytic solution.
    pub orders: Option<Orders>,
    /// Parameters of the two-level sampling.
    pub sampling: Option<Sampling>,
}

impl Default for Bounces {
    fn default() -> Self {
        Bounces {
            bounces: 1,
            sampled: None,
            kernel: None,
            orders: None,
            sampling: None,
        }
    }
}

impl Bounces {
    /// The first secondary-reflection option given, if any (`secondary`, `kernel`, `orders`,
    /// `sampling`).
    pub fn secondary_given(&self) -> Option<&'static str> {
        [
            ("secondary", self.sampled.is_some()),
            ("kernel", self.kernel.is_some()),
            ("orders", self.orders.is_some()),
            ("sampling", self.sampling.is_some()),
        ]
        .into_iter()
        .find_map(|(name, given)| given.then_some(name))
    }

    /// The secondary-reflection options (also for one bounce, where they are unused); an
    /// error when one is given without two bounces, orders with the sampling or sampling
    /// parameters with the analytic solution.
    pub fn options(&self, n: Naming) -> Result<SecondaryOptions, String> {
        let f = |name| n.flag(name);
        if self.bounces == 1 && self.secondary_given().is_some() {
            return Err(format!(
                "{}, {}, {} and {} apply only to the secondary reflection; add {} or drop them",
                f("secondary"),
                f("kernel"),
                f("orders"),
                f("sampling"),
                n.number("bounces", "2")
            ));
        }
        if self.bounces > 2 {
            if let Some(name) = self.secondary_given() {
                return Err(format!(
                    "{} sets the thesis's analytic second bounce, which {} does not use: there \
                     every order from the second on is path-traced on the micro-geometry \
                     (radiometric kernel); drop {} or use {}",
                    f(name),
                    n.number("bounces", &crate::transport::bounces_name(self.bounces)),
                    f(name),
                    n.number("bounces", "2")
                ));
            }
        }
        let method = match (self.sampled, self.orders, self.sampling) {
            (None | Some(false), orders, None) => SecondaryMethod::Analytic {
                ranges: Ranges::Full,
                orders: orders.unwrap_or_default(),
            },
            (Some(true), None, sampling) => SecondaryMethod::Sampling(sampling.unwrap_or_default()),
            (Some(true), Some(_), _) => {
                return Err(format!(
                    "{} sets the analytic solution's quadrature, not the sampling's; drop {}, or \
                     {} (and give {} instead)",
                    f("orders"),
                    f("orders"),
                    n.word("secondary", "raytrace"),
                    f("sampling")
                ))
            }
            (_, _, Some(_)) => {
                return Err(format!(
                    "{} sets the two-level sampling ({}), not the analytic solution; add {}, or \
                     drop {} (and give {} instead)",
                    f("sampling"),
                    n.word("secondary", "raytrace"),
                    n.word("secondary", "raytrace"),
                    f("sampling"),
                    f("orders")
                ))
            }
        };
        Ok(SecondaryOptions {
            method,
            kernel: self.kernel.unwrap_or(Kernel::Radiometric),
        })
    }
}

impl Settings {
    /// The bake options: the option combinations checked (ray-tracer options need the ray
    /// tracer, the variant the analytic model, two bounces the analytic model), the defaults
    /// filled in, and [`check_options`] passed. Messages name the options as `n` spells them.
    pub fn options(&self, n: Naming) -> Result<BakeOptions, String> {
        let f = |name| n.flag(name);
        if !self.raytrace && (self.samples.is_some() || self.seed.is_some() || self.caps.is_some())
        {
            return Err(format!(
                "{}, {} and {} apply only to the ray tracer; add {} or drop them",
                f("samples"),
                f("seed"),
                f("caps"),
                n.word("method", "raytrace")
            ));
        }
        if self.raytrace && self.variant.is_some() {
            return Err(format!(
                "{} applies only to the analytic model; drop {} or use {}",
                f("variant"),
                f("variant"),
                n.word("method", "analytic")
            ));
        }
        let secondary = self.bounces.options(n)?;
        if self.bounces.bounces == 2 && self.raytrace {
            return Err(format!(
                "{} needs the analytic model: the ray tracer bakes the direct reflection only; \
                 use {} with {} ({} selects the thesis's two-level sampling of the secondary \
                 reflection)",
                n.number("bounces", "2"),
                n.word("method", "analytic"),
                n.number("bounces", "2"),
                n.word("secondary", "raytrace")
            ));
        }
        if self.spatial && (self.raytrace || self.bounces.bounces > 2) {
            return Err(format!(
                "{} tabulates the analytic model's direct and secondary reflection; drop {} or \
                 use {} and {} or 2 (the path-traced orders of every bounce and the ray tracer's \
                 tables are averaged over the period)",
                f("spatial"),
                f("spatial"),
                n.word("method", "analytic"),
                n.number("bounces", "1")
            ));
        }
        if self.faces == Faces::Two {
            let given = [
                (self.raytrace, n.word("method", "raytrace")),
                (self.bounces.bounces != 1, f("bounces")),
                (self.spatial, f("spatial")),
            ];
            if let Some((_, name)) = given.into_iter().find(|g| g.0) {
                return Err(format!(
                    "{} bakes the two-faced cloth's model (docs/science/transmission.md): the analytic \
                     direct reflection with every other bounce path-traced, averaged over the \
                     period; drop {name}",
                    n.word("faces", "two")
                ));
            }
        }
        if self.faces == Faces::One && self.paths.is_some() {
            return Err(format!(
                "{} sets the two-faced cloth's path-traced rest; add {} or drop it",
                f("paths"),
                n.word("faces", "two")
            ));
        }
        // The counts' ranges, each 1 to a power of two.
        for (name, count, max) in [
            ("paths", self.paths, crate::sweep::MAX_PATHS),
            ("samples", self.samples, MAX_SAMPLES),
        ] {
            if let Some(k) = count.filter(|&k| k == 0 || k > max) {
                return Err(format!(
                    "{} is out of range; give a whole number from 1 to {max} (2^{})",
                    n.number(name, &k.to_string()),
                    max.trailing_zeros()
                ));
            }
        }
        let method = if self.raytrace {
            Method::Raytrace {
                samples: self.samples.unwrap_or(DEFAULT_SAMPLES),
                seed: self.seed.unwrap_or(DEFAULT_SEED),
                caps: self.caps.unwrap_or(Caps::Excluded),
            }
        } else {
            Method::Analytic {
                variant: self.variant.unwrap_or_default(),
            }
        };
        let grid = self.grid.unwrap_or(DEFAULT_GRID);
        if self.faces == Faces::Two {
            let cells = 4 * grid.len() as u128;
            if cells > u128::from(clothbake_loader::MAX_CELLS) {
                return Err(format!(
                    "{} {},{},{},{} with {} holds its cells on each side of the cloth: {cells} \
                     cells is more than the limit of 2^31; give a coarser {}",
                    f("res"),
                    grid.n_theta_i,
                    grid.n_phi_i,
                    grid.n_theta_o,
                    grid.n_phi_o,
                    n.word("faces", "two"),
                    f("res")
                ));
            }
        }
        let options = BakeOptions {
            grid: match self.faces {
                Faces::One => grid,
                Faces::Two => grid.two_faced(),
            },
            facet: self.facet,
            method,
            bounces: BakeBounces::of(self.bounces.bounces, secondary),
            spatial: self.spatial,
            paths: self.paths.unwrap_or(crate::two_faced::PATHS),
        };
        check_options(&options).map_err(|e| e.to_string())?;
        Ok(options)
    }
}

/// Parses quadrature orders: `default`, `fast` or THETA,BETA,AXIAL (whole numbers; theta and
/// beta 1 to 64 nodes in all, axial 1 to 16 a panel, the largest tabulated Gauss-Legendre
/// rule).
pub fn parse_orders(s: &str) -> Result<Orders, String> {
    const FIX: &str = "give `default`, `fast` or three whole numbers THETA,BETA,AXIAL, e.g. \
                       11,5,3 (theta and beta 1 to 64, axial 1 to 16)";
    match s.trim() {
        "default" => return Ok(Orders::default()),
        "fast" => return Ok(ORDERS_FAST),
        _ => {}
    }
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [t, b, a] = parts.as_slice() else {
        return Err(format!(
            "expected `default`, `fast` or 3 comma-separated numbers, found {} values; {FIX}",
            parts.len()
        ));
    };
    Ok(Orders {
        theta: whole_in(t, "THETA", 64, FIX)?,
        tol: 0.0,
        beta: whole_in(b, "BETA", 64, FIX)?,
        axial: whole_in(a, "AXIAL", 16, FIX)?,
    })
}

/// A whole number from 1 to `max` named `name`, or the error with `fix`.
fn whole_in(p: &str, name: &str, max: usize, fix: &str) -> Result<usize, String> {
    match p.parse::<usize>() {
        Ok(x) if (1..=max).contains(&x) => Ok(x),
        Ok(x) => Err(format!("{name} {x} is outside 1 to {max}; {fix}")),
        Err(_) => Err(format!("{name} `{p}` is not a whole number; {fix}")),
    }
}

/// Parses the two-level sampling's `N,STEP,L0,exact|area`: N first-level samples (1 to
/// 10000), a step in (0, 1] and a half-length l0 in (0, 1000] (fabric units), and the solid
/// angle.
pub fn parse_sampling(s: &str) -> Result<Sampling, String> {
    const FIX: &str = "give N,STEP,L0,exact|area, e.g. 32,0.2,1.5,exact (the thesis's) or \
                       28,0.15,3,area";
    let parts: Vec<&str> = s.split(',').map(str::trim).collect();
    let [n, step, l0, solid] = parts.as_slice() else {
        return Err(format!(
            "expected 4 comma-separated values, found {}; {FIX}",
            parts.len()
        ));
    };
    let first_level = whole_in(n, "N", 10_000, FIX)?;
    let within = |p: &str, name: &str, max: f64| {
        let x = match p.parse::<f64>() {
            Ok(x) if x.is_finite() => x,
            Ok(_) => return Err(format!("{name} `{p}` is not a finite number; {FIX}")),
            Err(_) => return Err(format!("{name} `{p}` is not a number; {FIX}")),
        };
        if x > 0.0 && x <= max {
            Ok(x)
        } else {
            Err(format!("{name} {x} is outside (0, {max}]; {FIX}"))
        }
    };
    let step = within(step, "STEP", 1.0)?;
    let l0 = within(l0, "L0", 1000.0)?;
    let exact_solid_angle = match *solid {
        "exact" => true,
        "area" => false,
        other => {
            return Err(format!(
                "solid angle `{other}` is neither `exact` nor `area`; {FIX}"
            ))
        }
    };
    Ok(Sampling {
        first_level,
        d_alpha: step,
        d_l: step,
        l0,
        exact_solid_angle,
    })
}
