//! The value parsers behind the options: numbers in their ranges, directions, grids; each
//! error names the value and the fix.

use super::*;

pub(super) fn number(s: &str, what: &str) -> Result<f64, String> {
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

pub(super) fn direction(s: &str, max: f64) -> Result<Direction, String> {
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

pub(super) fn unit_interval(s: &str, what: &str, fix: &str) -> Result<f64, String> {
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
pub(super) fn non_negative(s: &str, what: &str, fix: &str) -> Result<f64, String> {
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
