//! `clothbake plot`: pictures of a BRDF, as PNG or SVG (the `plotters` crate).
//!
//! * Slices: f_r in the plane of incidence. For each phi_i a panel; in it one curve per
//!   theta_i of f_r(wi, wo) against the signed outgoing angle `s` in [-90, 90] degrees: `s > 0`
//!   is wo = (s, phi_i + 180) (the mirror side), `s < 0` is wo = (-s, phi_i) (the light's side).
//! * Hemisphere: f_r(wi, wo) for one wi over the outgoing hemisphere, as a disk whose radius is
//!   theta_o (equidistant polar projection: x = theta_o cos phi_o, y = theta_o sin phi_o, degrees)
//!   sampled at the centres of 3-degree x 5-degree (theta_o, phi_o) cells, one disk per source on
//!   a shared linear colour scale (viridis) with a colour bar.
//!
//! The plotted value is the mean of the three channels of f_r (1/sr). With two sources, the
//! second is dashed (slices) or drawn beside the first (hemisphere), and the title gives the
//! largest difference relative to the first source's largest value. Text is drawn with the
//! DejaVu Sans font built into the program (no system fonts are needed).

use crate::shade::Shader;
use clothbake_core::UnitVec3;
use clothbake_loader::Grid;
use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
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
        Grid::polar_centre_deg(r as u32, RINGS as u32),
        Grid::azimuth_centre_deg(p as u32, SECTORS as u32),
    )
}

static FONT: Once = Once::new();

fn register_font() {
    FONT.call_once(|| {
        // The bundled DejaVu Sans is a valid TrueType font.
        plotters::style::register_font("sans-serif", FontStyle::Normal, dejavu::sans::regular())
            .map_err(|_| ())
            .expect("the bundled font parses");
    });
}

/// The pixel size of a plot.
pub fn size(plot: &Plot, sources: usize) -> (u32, u32) {
    match plot {
        Plot::Slices { phi_i, .. } => (460 * phi_i.len().max(1) as u32, 420),
        Plot::Hemisphere { .. } => (420 * sources.max(1) as u32 + 110, 460),
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
        .label_font(("sans-serif", 11))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("{e:?}")
}

/// Draws `plot` of `sources` (one or two) on `root`.
pub fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    plot: &Plot,
    sources: &[Source<'_>],
) -> DrawResult<()> {
    register_font();
    root.fill(&WHITE).map_err(err)?;
    match plot {
        Plot::Slices { theta_i, phi_i } => draw_slices(root, theta_i, phi_i, sources),
        Plot::Hemisphere { theta_i, phi_i } => draw_hemisphere(root, *theta_i, *phi_i, sources),
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
        let mut caption = format!("f_r in the plane of incidence, phi_i = {phi} deg");
        if curves.len() == 2 {
            let a: Vec<f64> = curves[0].iter().flatten().map(|p| p.1).collect();
            let b: Vec<f64> = curves[1].iter().flatten().map(|p| p.1).collect();
            caption = format!(
                "phi_i = {phi} deg; max |{} - {}| = {:.2}% of max",
                sources[1].name,
                sources[0].name,
                rel_diff(&a, &b)
            );
        }
        let mut chart = ChartBuilder::on(panel)
            .caption(caption, ("sans-serif", 15))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(58)
            .build_cartesian_2d(-90f64..90f64, 0f64..ymax)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("theta_o (deg): < 0 light's side, > 0 mirror side")
            .y_desc("f_r (1/sr), mean of R, G, B")
            .label_style(("sans-serif", 12))
            .axis_desc_style(("sans-serif", 13))
            .draw()
            .map_err(err)?;
        for (si, (src, cs)) in sources.iter().zip(&curves).enumerate() {
            for (k, (c, &t)) in cs.iter().zip(theta_i).enumerate() {
                let colour = Palette99::pick(k).to_rgba();
                let label = format!("{}, theta_i {t}", src.name);
                let legend = move |(x, y): (i32, i32)| {
                    PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2))
                };
                if si == 0 {
                    chart
                        .draw_series(LineSeries::new(c.iter().copied(), colour.stroke_width(2)))
                        .map_err(err)?
                        .label(label)
                        .legend(legend);
                } else {
                    chart
                        .draw_series(DashedLineSeries::new(
                            c.iter().copied(),
                            6,
                            4,
                            colour.stroke_width(2),
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

fn draw_hemisphere<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    theta_i: f64,
    phi_i: f64,
    sources: &[Source<'_>],
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
    let title = if maps.len() == 2 {
        format!(
            "f_r (1/sr) for wi = ({theta_i}, {phi_i}) deg; max |{} - {}| = {:.2}% of max",
            sources[1].name,
            sources[0].name,
            rel_diff(&maps[0], &maps[1])
        )
    } else {
        format!("f_r (1/sr) over the outgoing hemisphere for wi = ({theta_i}, {phi_i}) deg")
    };
    let root = root.titled(&title, ("sans-serif", 16)).map_err(err)?;
    let (w, _) = root.dim_in_pixel();
    let (maps_area, bar_area) = root.split_horizontally(w.saturating_sub(110));
    let panels = maps_area.split_evenly((1, sources.len().max(1)));
    for ((panel, src), map) in panels.iter().zip(sources).zip(&maps) {
        let mut chart = ChartBuilder::on(panel)
            .caption(&src.name, ("sans-serif", 14))
            .margin(10)
            .x_label_area_size(40)
            .y_label_area_size(46)
            .build_cartesian_2d(-90f64..90f64, -90f64..90f64)
            .map_err(err)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc("theta_o cos phi_o (deg), +x weft")
            .y_desc("theta_o sin phi_o (deg), +y warp")
            .label_style(("sans-serif", 11))
            .axis_desc_style(("sans-serif", 12))
            .draw()
            .map_err(err)?;
        let cells = (0..RINGS).flat_map(|r| (0..SECTORS).map(move |p| (r, p)));
        chart
            .draw_series(cells.map(|(r, p)| {
                let t0 = r as f64 * 90.0 / RINGS as f64;
                let t1 = t0 + 90.0 / RINGS as f64;
                let p0 = (p as f64 * 360.0 / SECTORS as f64).to_radians();
                let p1 = ((p + 1) as f64 * 360.0 / SECTORS as f64).to_radians();
                let c = ViridisRGB::get_color_normalized(map[r * SECTORS + p], 0.0, vmax);
                Polygon::new(
                    vec![
                        (t0 * p0.cos(), t0 * p0.sin()),
                        (t1 * p0.cos(), t1 * p0.sin()),
                        (t1 * p1.cos(), t1 * p1.sin()),
                        (t0 * p1.cos(), t0 * p1.sin()),
                    ],
                    c.filled(),
                )
            }))
            .map_err(err)?;
        // The mirror direction of wi.
        let (mx, my) = (
            theta_i * (phi_i + 180.0).to_radians().cos(),
            theta_i * (phi_i + 180.0).to_radians().sin(),
        );
        chart
            .draw_series(std::iter::once(Cross::new(
                (mx, my),
                5,
                RED.stroke_width(2),
            )))
            .map_err(err)?
            .label("mirror direction of wi")
            .legend(|(x, y)| Cross::new((x + 8, y), 4, RED.stroke_width(2)));
        legend(&mut chart, SeriesLabelPosition::LowerRight)?;
    }
    // Colour bar.
    let mut bar = ChartBuilder::on(&bar_area)
        .margin_top(40)
        .margin_bottom(50)
        .margin_right(50)
        .y_label_area_size(0)
        .right_y_label_area_size(40)
        .build_cartesian_2d(0f64..1f64, 0f64..vmax)
        .map_err(err)?;
    bar.configure_mesh()
        .disable_mesh()
        .disable_x_axis()
        .y_desc("f_r (1/sr)")
        .label_style(("sans-serif", 11))
        .axis_desc_style(("sans-serif", 12))
        .draw()
        .map_err(err)?;
    let steps = 64;
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

/// Draws `plot` into `path` (PNG or SVG, by its extension), atomically.
pub fn write(
    path: &Path,
    plot: &Plot,
    sources: &[Source<'_>],
    overwrite: bool,
) -> Result<(), String> {
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
                let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
                draw(&root, plot, sources)?;
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
