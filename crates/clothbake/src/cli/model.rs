//! `clothbake eval` and the options every command that builds the model shares: the facet,
//! the variant, the material and draft options, the bounces, directions.

use super::*;

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
