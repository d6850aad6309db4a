//! `clothbake render` and `plot`: the picture's scene, camera, light and tone mapping.

use super::*;

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
