//! `clothbake plot`: pictures of a BRDF, as PNG or SVG (the `plotters` crate).
//!
//! * Slices: f_r in the plane of incidence. For each phi_i a panel; in it one curve per
//!   theta_i of f_r(wi, wo) against the signed outgoing angle `s` in [-90, 90] degrees: `s > 0`
//!   is wo = (s, phi_i + 180) (the mirror side), `s < 0` is wo = (-s, phi_i) (the light's side).
//! * Hemisphere: f_r(wi, wo) for one wi over the outgoing hemisphere, as a disk whose radius is
//!   theta_o (equidistant polar projection: x = theta_o cos phi_o, y = theta_o sin phi_o, degrees)
//!   sampled at the centres of 3-degree x 5-degree (theta_o, phi_o) cells and interpolated
//!   bilinearly in (theta_o, phi_o) between them ([`hemisphere_at`]), one disk per source on a
//!   shared linear colour scale (viridis) with a colour bar.
//! * Polar: the anisotropy, f_r(wi, wo) against the outgoing azimuth phi_o at fixed elevations
//!   theta_o, drawn in polar form (radius f_r, angle phi_o), one closed curve per theta_o.
//!
//! The plotted value is the mean of the three channels of f_r (1/sr). With two sources, the
//! second is dashed (slices, polar) or drawn beside the first (hemisphere), and the title gives
//! the largest difference relative to the first source's largest value. Curves use the
//! Okabe-Ito colours (distinguishable with the common colour-vision deficiencies; its yellow,
//! faint on white, is left out) at a 2.5-pixel stroke. Text is the DejaVu Sans font built into
//! the program (no system fonts are needed); PNG text is typeset by [`crate::typeset`].

use crate::shade::Shader;
use crate::typeset::Typeset;
use clothbake_core::UnitVec3;
use clothbake_loader::Axis;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::ReverseCoordTranslate;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use plotters::style::text_anchor::{HPos, Pos, VPos};
use std::path::Path;
use std::sync::Once;

/// One BRDF to plot, with its legend name.
pub struct Source<'a> {
    /// Legend name (e.g. the table's file name, or "model").
    pub name: String,
    /// The BRDF.
    pub shader: &'a Shader,
}

/// What to plot.
#[derive(Clone, Debug, PartialEq)]
pub enum Plot {
    /// Slices in the plane of incidence, theta_i and phi_i in degrees.
    Slices {
        /// Polar angles of incidence (one curve each).
        theta_i: Vec<f64>,
        /// Azimuths of incidence (one panel each).
        phi_i: Vec<f64>,
    },
    /// The hemisphere map for wi = (theta, phi) in degrees.
    Hemisphere {
        /// Polar angle of incidence.
        theta_i: f64,
        /// Azimuth of incidence.
        phi_i: f64,
    },
    /// Polar plots of f_r against phi_o for wi = (theta, phi) in degrees, one curve per
    /// outgoing elevation.
    Polar {
        /// Polar angle of incidence.
        theta_i: f64,
        /// Azimuth of incidence.
        phi_i: f64,
        /// Outgoing polar angles (one curve each), below 90.
        theta_o: Vec<f64>,
    },
}

/// Curve colours: the Okabe-Ito palette (Okabe and Ito 2008) without its yellow, in the order
/// blue, vermillion, bluish green, reddish purple, orange, sky blue, black.
pub const PALETTE: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(230, 159, 0),
    RGBColor(86, 180, 233),
    RGBColor(0, 0, 0),
];

/// Curve stroke width in pixels.
const STROKE: u32 = 3;

fn colour(k: usize) -> RGBColor {
    PALETTE[k % PALETTE.len()]
}

/// A tick label: degrees as whole numbers with a degree sign.
fn degrees(v: &f64) -> String {
    let r = v.round();
    format!("{}°", if r == 0.0 { 0.0 } else { r })
}

/// Tick labels for values spanning `range`: as many decimals as a tenth of the range needs,
/// trailing zeros dropped ("0.05", "0.1", "0.15").
fn value_ticks(range: f64) -> impl Fn(&f64) -> String {
    let step = (range / 10.0).max(1e-12);
    let decimals = (-step.log10().floor()).clamp(0.0, 8.0) as usize;
    move |v: &f64| {
        let s = format!("{v:.decimals$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        if s == "-0" {
            "0".into()
        } else {
            s
        }
    }
}

/// Mean of the three channels of f_r.
fn value(s: &Shader, wi: UnitVec3, wo: UnitVec3) -> f64 {
    let f = s.f_r(wi, wo);
    (f64::from(f[0]) + f64::from(f[1]) + f64::from(f[2])) / 3.0
}

/// The outgoing direction of signed angle `s` (degrees) in the plane of incidence of azimuth
/// `phi_i`.
pub fn plane_direction(s: f64, phi_i: f64) -> UnitVec3 {
    if s >= 0.0 {
        UnitVec3::from_degrees(s, phi_i + 180.0)
    } else {
        UnitVec3::from_degrees(-s, phi_i)
    }
}

/// The slice of `s` for wi = (theta_i, phi_i): (signed angle, value) at 1-degree steps from
/// -89.5 to 89.5.
pub fn slice(s: &Shader, theta_i: f64, phi_i: f64) -> Vec<(f64, f64)> {
    let wi = UnitVec3::from_degrees(theta_i, phi_i);
    (0..180)
        .map(|k| {
            let a = -89.5 + k as f64;
            (a, value(s, wi, plane_direction(a, phi_i)))
        })
        .collect()
}

/// Cells of the hemisphere map: theta_o rings of 3 degrees, phi_o sectors of 5 degrees.
const RINGS: usize = 30;
const SECTORS: usize = 72;

/// The hemisphere map of `s` for wi = (theta_i, phi_i): `RINGS x SECTORS` values at the cell
/// centres, ring-major.
pub fn hemisphere(s: &Shader, theta_i: f64, phi_i: f64) -> Vec<f64> {
    let wi = UnitVec3::from_degrees(theta_i, phi_i);
    let mut v = Vec::with_capacity(RINGS * SECTORS);
    for r in 0..RINGS {
        for p in 0..SECTORS {
            let (t, ph) = cell_centre(r, p);
            v.push(value(s, wi, UnitVec3::from_degrees(t, ph)));
        }
    }
    v
}

fn cell_centre(r: usize, p: usize) -> (f64, f64) {
    (
        Axis::polar(RINGS as u32).centre_deg(r as u32),
        Axis::azimuth(SECTORS as u32).centre_deg(p as u32),
    )
}

/// The hemisphere map `map` (from [`hemisphere`]) at (theta_o, phi_o) in degrees, bilinear in
/// (theta_o, phi_o) between the cell centres: periodic in phi_o; between the pole and the first
/// ring toward the first ring's mean (the pole's value, the same from every azimuth); past the
/// last ring's centre the last ring's value (no extrapolation toward the horizon).
pub fn hemisphere_at(map: &[f64], theta: f64, phi: f64) -> f64 {
    let (dt, dp) = (90.0 / RINGS as f64, 360.0 / SECTORS as f64);
    let ft = (theta / dt - 0.5).clamp(-0.5, (RINGS - 1) as f64);
    let fp = (phi / dp - 0.5).rem_euclid(SECTORS as f64);
    let (p0, wp) = (fp.floor() as usize % SECTORS, fp - fp.floor());
    let p1 = (p0 + 1) % SECTORS;
    let ring = |r: usize| map[r * SECTORS + p0] * (1.0 - wp) + map[r * SECTORS + p1] * wp;
    if ft < 0.0 {
        let pole = map[..SECTORS].iter().sum::<f64>() / SECTORS as f64;
        let w = 2.0 * (ft + 0.5); // 0 at the pole, 1 at the first ring's centre
        return pole * (1.0 - w) + ring(0) * w;
    }
    let r0 = (ft.floor() as usize).min(RINGS - 1);
    let r1 = (r0 + 1).min(RINGS - 1);
    let wt = ft - r0 as f64;
    ring(r0) * (1.0 - wt) + ring(r1) * wt
}

static FONT: Once = Once::new();

/// Registers the bundled font with plotters (for tests that draw text outside [`draw`]).
#[cfg(test)]
pub(crate) fn tests_register_font() {
    register_font();
}

fn register_font() {
    FONT.call_once(|| {
        // The bundled DejaVu Sans is a valid TrueType font.
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .map_err(|_| ())
            .expect("the bundled font parses");
    });
}

/// Most curves one plot holds (`theta_i` of slices, `theta_o` of polar plots): past these the
/// palette's colours repeat twice over and the curves cannot be told apart.
pub const MAX_CURVES: usize = 12;

/// Most panels (`phi_i` of slices) one plot holds: each is 500 pixels wide.
pub const MAX_PANELS: usize = 8;

/// A list of a [`Plot`] with more entries than the plot holds.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TooMany {
    /// The list: `"theta_i"`, `"phi_i"` or `"theta_o"`.
    pub list: &'static str,
    /// Its length.
    pub len: usize,
    /// The most it may hold ([`MAX_CURVES`] or [`MAX_PANELS`]).
    pub max: usize,
}

impl Plot {
    /// Checks the lengths of the plot's lists against [`MAX_CURVES`] and [`MAX_PANELS`]
    /// (which also bound the picture's size); names the first list past its limit.
    pub fn check(&self) -> Result<(), TooMany> {
        let lists: &[(&'static str, usize, usize)] = match self {
            Plot::Slices { theta_i, phi_i } => &[
                ("theta_i", theta_i.len(), MAX_CURVES),
                ("phi_i", phi_i.len(), MAX_PANELS),
            ],
            Plot::Hemisphere { .. } => &[],
            Plot::Polar { theta_o, .. } => &[("theta_o", theta_o.len(), MAX_CURVES)],
        };
        match lists.iter().find(|(_, len, max)| len > max) {
            Some(&(list, len, max)) => Err(TooMany { list, len, max }),
            None => Ok(()),
        }
    }
}

/// The pixel size of a plot.
pub fn size(plot: &Plot, sources: usize) -> (u32, u32) {
    match plot {
        Plot::Slices { phi_i, .. } => (500 * phi_i.len().max(1) as u32, 440),
        Plot::Hemisphere { .. } => (440 * sources.max(1) as u32 + 110, 480),
        Plot::Polar { .. } => (900, 660),
    }
}

/// Largest |a - b| relative to the largest |a|, in percent.
fn rel_diff(a: &[f64], b: &[f64]) -> f64 {
    let m = a.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    let d = a
        .iter()
        .zip(b)
        .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()));
    if m > 0.0 {
        100.0 * d / m
    } else {
        0.0
    }
}

type DrawResult<T> = Result<T, String>;

/// Draws the series labels of `chart` in a framed, lightly opaque box at `position`.
fn legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    position: SeriesLabelPosition,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(position)
        .label_font(("sans-serif", 13))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("{e:?}")
}

/// Draws `plot` of `sources` (one or two) on `root`, hemisphere maps as a fine mesh.
pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &Plot,
    sources: &[Source<'_>],
) -> DrawResult<()> {
    draw_with(root, plot, sources, Fill::Mesh)
}

/// Draws `plot` of `sources` (one or two) on `root`, hemisphere maps filled as `fill` says.
pub fn draw_with<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &Plot,
    sources: &[Source<'_>],
    fill: Fill,
) -> DrawResult<()> {
    register_font();
    root.fill(&WHITE).map_err(err)?;
    match plot {
        Plot::Slices { theta_i, phi_i } => draw_slices(root, theta_i, phi_i, sources),
        Plot::Hemisphere { theta_i, phi_i } => {
            draw_hemisphere(root, *theta_i, *phi_i, sources, fill)
        }
        Plot::Polar {
            theta_i,
            phi_i,
            theta_o,
        } => draw_polar(root, *theta_i, *phi_i, theta_o, sources),
    }
}

fn draw_slices<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    theta_i: &[f64],
    phi_i: &[f64],
    sources: &[Source<'_>],
) -> DrawResult<()> {
    let panels = root.split_evenly((1, phi_i.len().max(1)));
    for (panel, &phi) in panels.iter().zip(phi_i) {
        let curves: Vec<Vec<Vec<(f64, f64)>>> = sources
            .iter()
            .map(|s| theta_i.iter().map(|&t| slice(s.shader, t, phi)).collect())
            .collect();
        let ymax = curves
            .iter()
            .flatten()
            .flatten()
            .fold(0.0f64, |m, p| m.max(p.1))
            .max(1e-6)
            * 1.08;
        let mut caption = format!("f_r in the plane of incidence, φᵢ = {}", degrees(&phi));
        if curves.len() == 2 {
            let a: Vec<f64> = curves[0].iter().flatten().map(|p| p.1).collect();
            let b: Vec<f64> = curves[1].iter().flatten().map(|p| p.1).collect();
            caption = format!(
                "φᵢ = {}: max |{} − {}| = {:.2}% of max",
                degrees(&phi),
                sources[1].name,
                sources[0].name,
                rel_diff(&a, &b)
            );
        }
        let mut chart = ChartBuilder::on(panel)
            .caption(caption, ("sans-serif", 17))
            .margin(14)
            .x_label_area_size(46)
            .y_label_area_size(62)
            .build_cartesian_2d(-90f64..90f64, 0f64..ymax)
            .map_err(err)?;
        chart
            .configure_mesh()
            .light_line_style(RGBColor(236, 236, 236))
            .bold_line_style(RGBColor(200, 200, 200))
            .x_labels(10)
            .x_label_formatter(&degrees)
            .y_label_formatter(&value_ticks(ymax))
            .x_desc("θₒ: < 0 on the light's side, > 0 on the mirror side")
            .y_desc("f_r (1/sr), mean of R, G, B")
            .label_style(("sans-serif", 14))
            .axis_desc_style(("sans-serif", 15))
            .draw()
            .map_err(err)?;
        for (si, (src, cs)) in sources.iter().zip(&curves).enumerate() {
            for (k, (c, &t)) in cs.iter().zip(theta_i).enumerate() {
                let colour = colour(k);
                let label = format!("{}, θᵢ = {}", src.name, degrees(&t));
                let legend = move |(x, y): (i32, i32)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(STROKE))
                };
                if si == 0 {
                    chart
                        .draw_series(LineSeries::new(
                            c.iter().copied(),
                            colour.stroke_width(STROKE),
                        ))
                        .map_err(err)?
                        .label(label)
                        .legend(legend);
                } else {
                    chart
                        .draw_series(DashedLineSeries::new(
                            c.iter().copied(),
                            8,
                            5,
                            colour.stroke_width(STROKE),
                        ))
                        .map_err(err)?
                        .label(format!("{label} (dashed)"))
                        .legend(legend);
                }
            }
        }
        legend(&mut chart, SeriesLabelPosition::UpperLeft)?;
    }
    Ok(())
}

/// How a hemisphere map is filled: every pixel (bitmaps) or a fine polar mesh of polygons
/// (vector output), both with the bilinear [`hemisphere_at`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Fill {
    /// One interpolated value per pixel.
    Pixels,
    /// Polygons of 1.5 x 3 degrees (theta_o x phi_o), each at its centre's interpolated value.
    Mesh,
}

/// Fills the disk theta_o <= 90 of `chart` with `map` on the colour scale 0..vmax.
fn fill_disk<DB: DrawingBackend>(
    chart: &mut ChartContext<'_, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    map: &[f64],
    vmax: f64,
    fill: Fill,
) -> DrawResult<()> {
    match fill {
        Fill::Pixels => {
            let area = chart.plotting_area();
            let (x0, y0) = area.get_base_pixel();
            let (w, h) = area.dim_in_pixel();
            let spec = area.as_coord_spec().clone();
            let plain = area.strip_coord_spec();
            for j in 0..h as i32 {
                for i in 0..w as i32 {
                    let Some((x, y)) = spec.reverse_translate((x0 + i, y0 + j)) else {
                        continue;
                    };
                    let t = x.hypot(y);
                    if t > 90.0 {
                        continue;
                    }
                    let ph = y.atan2(x).to_degrees().rem_euclid(360.0);
                    let c = ViridisRGB::get_color_normalized(hemisphere_at(map, t, ph), 0.0, vmax);
                    plain.draw_pixel((i, j), &c).map_err(err)?;
                }
            }
        }
        Fill::Mesh => {
            let (rings, sectors) = (60usize, 120usize);
            let (dt, dp) = (90.0 / rings as f64, 360.0 / sectors as f64);
            let cells = (0..rings).flat_map(|r| (0..sectors).map(move |p| (r, p)));
            chart
                .draw_series(cells.map(|(r, p)| {
                    let (t0, t1) = (r as f64 * dt, (r + 1) as f64 * dt);
                    let (p0, p1) = (p as f64 * dp, (p + 1) as f64 * dp);
                    let v = hemisphere_at(map, 0.5 * (t0 + t1), 0.5 * (p0 + p1));
                    let (p0, p1) = (p0.to_radians(), p1.to_radians());
                    Polygon::new(
                        vec![
                            (t0 * p0.cos(), t0 * p0.sin()),
                            (t1 * p0.cos(), t1 * p0.sin()),
                            (t1 * p1.cos(), t1 * p1.sin()),
                            (t0 * p1.cos(), t0 * p1.sin()),
                        ],
                        ViridisRGB::get_color_normalized(v, 0.0, vmax).filled(),
                    )
                }))
                .map_err(err)?;
        }
    }
    Ok(())
}

/// "(θ, φ)" of a direction in degrees.
fn direction(theta: f64, phi: f64) -> String {
    format!("({}, {})", degrees(&theta), degrees(&phi))
}

fn draw_hemisphere<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    theta_i: f64,
    phi_i: f64,
    sources: &[Source<'_>],
    fill: Fill,
) -> DrawResult<()> {
    let maps: Vec<Vec<f64>> = sources
        .iter()
        .map(|s| hemisphere(s.shader, theta_i, phi_i))
        .collect();
    let vmax = maps
        .iter()
        .flatten()
        .fold(0.0f64, |m, &x| m.max(x))
        .max(1e-9);
    let wi = direction(theta_i, phi_i);
    let title = if maps.len() == 2 {
        format!(
            "f_r (1/sr) for ωᵢ = {wi}: max |{} − {}| = {:.2}% of max",
            sources[1].name,
            sources[0].name,
            rel_diff(&maps[0], &maps[1])
        )
    } else {
        format!("f_r (1/sr) over the outgoing hemisphere, ωᵢ = {wi}")
    };
    let root = root.titled(&title, ("sans-serif", 18)).map_err(err)?;
    let (w, _) = root.dim_in_pixel();
    let (maps_area, bar_area) = root.split_horizontally(w.saturating_sub(110));
    let panels = maps_area.split_evenly((1, sources.len().max(1)));
    for ((panel, src), map) in panels.iter().zip(sources).zip(&maps) {
        let mut chart = ChartBuilder::on(panel)
            .caption(&src.name, ("sans-serif", 16))
            .margin(10)
            .x_label_area_size(44)
            .y_label_area_size(52)
            .build_cartesian_2d(-90f64..90f64, -90f64..90f64)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_labels(7)
            .y_labels(7)
            .x_label_formatter(&degrees)
            .y_label_formatter(&degrees)
            .x_desc("θₒ cos φₒ  (+x: weft)")
            .y_desc("θₒ sin φₒ  (+y: warp)")
            .label_style(("sans-serif", 13))
            .axis_desc_style(("sans-serif", 14))
            .draw()
            .map_err(err)?;
        fill_disk(&mut chart, map, vmax, fill)?;
        // The mirror direction of wi.
        let (mx, my) = (
            theta_i * (phi_i + 180.0).to_radians().cos(),
            theta_i * (phi_i + 180.0).to_radians().sin(),
        );
        let mark = RGBColor(213, 94, 0); // Okabe-Ito vermillion
        chart
            .draw_series(std::iter::once(Cross::new(
                (mx, my),
                6,
                mark.stroke_width(3),
            )))
            .map_err(err)?
            .label("mirror direction of ωᵢ")
            .legend(move |(x, y)| Cross::new((x + 8, y), 5, mark.stroke_width(3)));
        legend(&mut chart, SeriesLabelPosition::LowerRight)?;
    }
    // Colour bar.
    let mut bar = ChartBuilder::on(&bar_area)
        .margin_top(40)
        .margin_bottom(50)
        .margin_right(50)
        .y_label_area_size(0)
        .right_y_label_area_size(48)
        .build_cartesian_2d(0f64..1f64, 0f64..vmax)
        .map_err(err)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_label_formatter(&value_ticks(vmax))
        .y_desc("f_r (1/sr)")
        .label_style(("sans-serif", 13))
        .axis_desc_style(("sans-serif", 14))
        .draw()
        .map_err(err)?;
    let steps = 128;
    bar.draw_series((0..steps).map(|k| {
        let (a, b) = (
            vmax * k as f64 / steps as f64,
            vmax * (k + 1) as f64 / steps as f64,
        );
        Rectangle::new(
            [(0.0, a), (1.0, b)],
            ViridisRGB::get_color_normalized(0.5 * (a + b), 0.0, vmax).filled(),
        )
    }))
    .map_err(err)?;
    Ok(())
}

/// The polar curve of `s` for wi = (theta_i, phi_i) at outgoing elevation `theta_o`: (phi_o,
/// value) at 1-degree steps from 0.5 to 359.5.
pub fn azimuth_curve(s: &Shader, theta_i: f64, phi_i: f64, theta_o: f64) -> Vec<(f64, f64)> {
    let wi = UnitVec3::from_degrees(theta_i, phi_i);
    (0..360)
        .map(|k| {
            let p = 0.5 + k as f64;
            (p, value(s, wi, UnitVec3::from_degrees(theta_o, p)))
        })
        .collect()
}

fn draw_polar<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    theta_i: f64,
    phi_i: f64,
    theta_o: &[f64],
    sources: &[Source<'_>],
) -> DrawResult<()> {
    let curves: Vec<Vec<Vec<(f64, f64)>>> = sources
        .iter()
        .map(|s| {
            theta_o
                .iter()
                .map(|&t| azimuth_curve(s.shader, theta_i, phi_i, t))
                .collect()
        })
        .collect();
    let fmax = curves
        .iter()
        .flatten()
        .flatten()
        .fold(0.0f64, |m, p| m.max(p.1))
        .max(1e-9);
    let wi = direction(theta_i, phi_i);
    let title = if curves.len() == 2 {
        let a: Vec<f64> = curves[0].iter().flatten().map(|p| p.1).collect();
        let b: Vec<f64> = curves[1].iter().flatten().map(|p| p.1).collect();
        format!(
            "f_r (1/sr) against φₒ, ωᵢ = {wi}: max |{} − {}| = {:.2}% of max",
            sources[1].name,
            sources[0].name,
            rel_diff(&a, &b)
        )
    } else {
        format!("f_r (1/sr) against the outgoing azimuth φₒ, ωᵢ = {wi}")
    };
    let root = root.titled(&title, ("sans-serif", 18)).map_err(err)?;
    let (w, h) = root.dim_in_pixel();
    let (disk, key) = root.split_horizontally(h.min(w.saturating_sub(260)));
    let r = fmax * 1.12;
    let mut chart = ChartBuilder::on(&disk)
        .margin(40)
        .margin_left(70)
        .build_cartesian_2d(-r..r, -r..r)
        .map_err(err)?;
    let mut entries: Vec<(String, RGBColor, bool)> = Vec::new();
    // Grid: circles at round values of f_r, spokes every 30 degrees.
    let grid = RGBColor(200, 200, 200);
    let text = RGBColor(90, 90, 90);
    let label = value_ticks(fmax);
    let step = nice_step(fmax / 4.0);
    let mut ring = step;
    while ring <= fmax * 1.0001 {
        let pts: Vec<(f64, f64)> = (0..=360)
            .map(|k| {
                let a = f64::from(k).to_radians();
                (ring * a.cos(), ring * a.sin())
            })
            .collect();
        chart
            .draw_series(std::iter::once(PathElement::new(pts, grid.stroke_width(1))))
            .map_err(err)?;
        let a = 75f64.to_radians();
        chart
            .draw_series(std::iter::once(Text::new(
                label(&ring),
                (ring * a.cos(), ring * a.sin()),
                ("sans-serif", 13).into_font().color(&text),
            )))
            .map_err(err)?;
        ring += step;
    }
    for k in 0..12 {
        let a = f64::from(k * 30);
        let (c, s) = (a.to_radians().cos(), a.to_radians().sin());
        chart
            .draw_series(std::iter::once(PathElement::new(
                vec![(0.0, 0.0), (fmax * c, fmax * s)],
                grid.stroke_width(1),
            )))
            .map_err(err)?;
        let name = match k {
            0 => "0° (+x weft)".to_string(),
            3 => "90° (+y warp)".to_string(),
            _ => degrees(&a),
        };
        let pos = Pos::new(
            if c > 0.3 {
                HPos::Left
            } else if c < -0.3 {
                HPos::Right
            } else {
                HPos::Center
            },
            if s > 0.3 {
                VPos::Bottom
            } else if s < -0.3 {
                VPos::Top
            } else {
                VPos::Center
            },
        );
        chart
            .draw_series(std::iter::once(Text::new(
                name,
                (fmax * 1.03 * c, fmax * 1.03 * s),
                ("sans-serif", 13).into_font().color(&text).pos(pos),
            )))
            .map_err(err)?;
    }
    // The azimuths of the light and of its mirror direction.
    let light = RGBColor(120, 120, 120);
    for (a, dashed) in [(phi_i, false), (phi_i + 180.0, true)] {
        let (c, s) = (a.to_radians().cos(), a.to_radians().sin());
        let line = vec![(0.0, 0.0), (fmax * c, fmax * s)];
        if dashed {
            chart
                .draw_series(DashedLineSeries::new(line, 6, 6, light.stroke_width(2)))
                .map_err(err)?;
        } else {
            chart
                .draw_series(std::iter::once(PathElement::new(
                    line,
                    light.stroke_width(2),
                )))
                .map_err(err)?;
        }
    }
    for (si, cs) in curves.iter().enumerate() {
        for (k, (c, &t)) in cs.iter().zip(theta_o).enumerate() {
            let colour = colour(k);
            let mut pts: Vec<(f64, f64)> = c
                .iter()
                .map(|&(p, f)| {
                    let a = p.to_radians();
                    (f * a.cos(), f * a.sin())
                })
                .collect();
            pts.push(pts[0]);
            entries.push((format!("θₒ = {}", degrees(&t)), colour, si == 1));
            if si == 0 {
                chart
                    .draw_series(std::iter::once(PathElement::new(
                        pts,
                        colour.stroke_width(STROKE),
                    )))
                    .map_err(err)?;
            } else {
                chart
                    .draw_series(DashedLineSeries::new(
                        pts,
                        8,
                        5,
                        colour.stroke_width(STROKE),
                    ))
                    .map_err(err)?;
            }
        }
    }
    // The key, beside the disk: the sources, then one line per curve.
    let font = ("sans-serif", 14).into_font();
    let mut y = 60;
    for (si, src) in sources.iter().enumerate() {
        let style = if si == 0 { "solid" } else { "dashed" };
        key.draw(&Text::new(
            format!("{} ({style}):", src.name),
            (0, y),
            font.clone(),
        ))
        .map_err(err)?;
        y += 24;
        for (name, colour, dashed) in entries.iter().filter(|e| e.2 == (si == 1)) {
            let line = vec![(4, y + 8), (34, y + 8)];
            if *dashed {
                key.draw(&PathElement::new(
                    vec![(4, y + 8), (14, y + 8)],
                    colour.stroke_width(STROKE),
                ))
                .map_err(err)?;
                key.draw(&PathElement::new(
                    vec![(22, y + 8), (34, y + 8)],
                    colour.stroke_width(STROKE),
                ))
                .map_err(err)?;
            } else {
                key.draw(&PathElement::new(line, colour.stroke_width(STROKE)))
                    .map_err(err)?;
            }
            key.draw(&Text::new(name.clone(), (44, y), font.clone()))
                .map_err(err)?;
            y += 22;
        }
        y += 12;
    }
    key.draw(&PathElement::new(
        vec![(4, y + 8), (34, y + 8)],
        light.stroke_width(2),
    ))
    .map_err(err)?;
    key.draw(&Text::new(
        "azimuth of the light, φᵢ",
        (44, y),
        font.clone(),
    ))
    .map_err(err)?;
    y += 22;
    key.draw(&PathElement::new(
        vec![(4, y + 8), (14, y + 8)],
        light.stroke_width(2),
    ))
    .map_err(err)?;
    key.draw(&PathElement::new(
        vec![(22, y + 8), (34, y + 8)],
        light.stroke_width(2),
    ))
    .map_err(err)?;
    key.draw(&Text::new("its mirror, φᵢ + 180°", (44, y), font))
        .map_err(err)?;
    Ok(())
}

/// A round step (1, 2 or 5 times a power of ten) of about `x`.
fn nice_step(x: f64) -> f64 {
    let p = 10f64.powf(x.log10().floor());
    let m = x / p;
    p * if m < 1.5 {
        1.0
    } else if m < 3.5 {
        2.0
    } else if m < 7.5 {
        5.0
    } else {
        10.0
    }
}

/// Draws `plot` into `path` (PNG or SVG, by its extension), atomically.
pub fn write(
    path: &Path,
    plot: &Plot,
    sources: &[Source<'_>],
    overwrite: bool,
) -> Result<(), String> {
    if let Err(t) = plot.check() {
        return Err(format!(
            "{} angles in {}, more than the {} a plot holds",
            t.len, t.list, t.max
        ));
    }
    let (w, h) = size(plot, sources.len());
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let fail = |e: clothbake_loader::TableError| e.to_string();
    match ext.as_deref() {
        Some("png") => {
            let mut buf = vec![0u8; (w * h * 3) as usize];
            {
                let backend = Typeset::new(BitMapBackend::with_buffer(&mut buf, (w, h)));
                let root = backend.into_drawing_area();
                draw_with(&root, plot, sources, Fill::Pixels)?;
                root.present().map_err(err)?;
            }
            crate::tonemap::write_png_rgb8(path, w, h, &buf, overwrite).map_err(fail)
        }
        Some("svg") => {
            let mut s = String::new();
            {
                let root = SVGBackend::with_string(&mut s, (w, h)).into_drawing_area();
                draw(&root, plot, sources)?;
                root.present().map_err(err)?;
            }
            clothbake_loader::write_atomic_as(path, "SVG plot", overwrite, |f| {
                std::io::Write::write_all(f, s.as_bytes())
            })
            .map_err(fail)
        }
        _ => Err(format!(
            "{}: unknown plot format; name the output .png or .svg",
            path.display()
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_past_their_limits_are_named() {
        let slices = |curves: usize, panels: usize| Plot::Slices {
            theta_i: vec![10.0; curves],
            phi_i: vec![0.0; panels],
        };
        assert_eq!(slices(MAX_CURVES, MAX_PANELS).check(), Ok(()));
        let t = slices(MAX_CURVES + 1, 1).check().unwrap_err();
        assert_eq!((t.list, t.len, t.max), ("theta_i", 13, 12));
        assert_eq!(slices(1, MAX_PANELS + 1).check().unwrap_err().list, "phi_i");
        let polar = Plot::Polar {
            theta_i: 30.0,
            phi_i: 0.0,
            theta_o: vec![20.0; MAX_CURVES + 1],
        };
        assert_eq!(polar.check().unwrap_err().list, "theta_o");
        // The largest plot allowed stays a modest picture.
        let (w, h) = size(&slices(MAX_CURVES, MAX_PANELS), 2);
        assert!(u64::from(w) * u64::from(h) * 3 < 16 << 20);
    }

    /// A map whose cell (r, p) holds 1000 r + p: bilinear in the cell indices.
    fn ramp() -> Vec<f64> {
        (0..RINGS)
            .flat_map(|r| (0..SECTORS).map(move |p| 1000.0 * r as f64 + p as f64))
            .collect()
    }

    #[test]
    fn the_hemisphere_is_interpolated_between_cell_centres() {
        let m = ramp();
        let (dt, dp) = (90.0 / RINGS as f64, 360.0 / SECTORS as f64);
        let centre = |r: usize, p: usize| ((r as f64 + 0.5) * dt, (p as f64 + 0.5) * dp);
        // At a cell centre: the cell's value.
        for (r, p) in [(0, 0), (7, 13), (RINGS - 1, SECTORS - 1)] {
            let (t, ph) = centre(r, p);
            assert!((hemisphere_at(&m, t, ph) - m[r * SECTORS + p]).abs() < 1e-9);
        }
        // Halfway between centres: the mean (the ramp is linear in both indices).
        let (t, ph) = centre(4, 10);
        let v = hemisphere_at(&m, t + 0.5 * dt, ph + 0.5 * dp);
        assert!((v - (4500.0 + 10.5)).abs() < 1e-9, "{v}");
        // Periodic in phi: between the last sector and the first.
        let v = hemisphere_at(&m, centre(3, 0).0, 0.0);
        assert!(
            (v - (3000.0 + 0.5 * (SECTORS - 1) as f64)).abs() < 1e-9,
            "{v}"
        );
        assert_eq!(
            hemisphere_at(&m, 20.0, 10.0),
            hemisphere_at(&m, 20.0, 370.0)
        );
        // The pole: the first ring's mean, from every azimuth; the rim: the last ring's value.
        let pole = (0..SECTORS).map(|p| p as f64).sum::<f64>() / SECTORS as f64;
        for ph in [0.0, 90.0, 271.0] {
            assert!((hemisphere_at(&m, 0.0, ph) - pole).abs() < 1e-9);
        }
        let rim = hemisphere_at(&m, 90.0, centre(0, 5).1);
        assert!(
            (rim - (1000.0 * (RINGS - 1) as f64 + 5.0)).abs() < 1e-9,
            "{rim}"
        );
    }

    #[test]
    fn tick_labels_are_clean() {
        assert_eq!(degrees(&-80.0), "-80°");
        assert_eq!(degrees(&-0.2), "0°");
        let t = value_ticks(0.4);
        assert_eq!(
            (t(&0.05), t(&0.1), t(&0.0), t(&-0.0)),
            ("0.05".into(), "0.1".into(), "0".into(), "0".into())
        );
        let t = value_ticks(0.004);
        assert_eq!(t(&0.0025), "0.0025");
        assert_eq!(value_ticks(300.0)(&150.0), "150");
        assert_eq!(
            (nice_step(0.03), nice_step(0.07), nice_step(0.25)),
            (0.02, 0.05, 0.2)
        );
    }
}
