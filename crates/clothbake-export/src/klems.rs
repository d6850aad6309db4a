//! Daylighting export: any [`Bsdf`] as an LBNL/Radiance BSDF XML file on the Klems basis
//! ("LBNL/Klems Full", 145 patches a hemisphere), and the datasheet figures fabric-shade makers
//! publish. Conventions, quadrature and the Radiance round trip: docs/guide/daylighting.md.
//!
//! * [`RINGS`], [`Patch`], [`patch_of`]: the basis, with each patch's solid angle and
//!   projected solid angle (Lambda) in closed form.
//! * [`evaluate`]: the four blocks (front/back reflection and transmission), each entry f
//!   averaged over its incident and outgoing patch, the straight-through [`Bsdf::openness`]
//!   on the transmission diagonals as O / Lambda.
//! * [`write_xml`]: the WindowElement file Radiance and WINDOW read ("Visible": CIE Y of the
//!   RGB; "Solar": the mean of R, G and B).
//! * [`Datasheet`]: openness factor, visible and solar transmittance and the reflectances at
//!   normal incidence.
//!
//! Frame: the cloth's +Z face is the file's "Front" (the outside of a window); in Radiance the
//! surface normal points into the room and the up vector along the cloth's warp (+Y), so that
//! clothbake's (x, y, z) is Radiance's BSDF frame's (-x, y, -z), a half turn about the warp.

use crate::Bsdf;
use clothbake_core::{UnitVec3, Vec3};
use rayon::prelude::*;
use std::f64::consts::PI;
use std::io::{self, Write};

/// One ring of the basis: polar bounds in degrees and the number of azimuth patches.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ring {
    /// Lower polar bound, degrees.
    pub lower: f64,
    /// Upper polar bound, degrees.
    pub upper: f64,
    /// Azimuth patches in the ring, centred on phi = 360 j / n_phi degrees.
    pub n_phi: usize,
}

/// The "LBNL/Klems Full" rings, from the normal to the horizon (as Radiance's `bsdf_m.c` and
/// LBNL WINDOW define them).
#[rustfmt::skip]
pub const RINGS: [Ring; 9] = [
    Ring { lower: 0.0, upper: 5.0, n_phi: 1 },
    Ring { lower: 5.0, upper: 15.0, n_phi: 8 },
    Ring { lower: 15.0, upper: 25.0, n_phi: 16 },
    Ring { lower: 25.0, upper: 35.0, n_phi: 20 },
    Ring { lower: 35.0, upper: 45.0, n_phi: 24 },
    Ring { lower: 45.0, upper: 55.0, n_phi: 24 },
    Ring { lower: 55.0, upper: 65.0, n_phi: 24 },
    Ring { lower: 65.0, upper: 75.0, n_phi: 16 },
    Ring { lower: 75.0, upper: 90.0, n_phi: 12 },
];

/// Patches of one hemisphere.
pub const PATCHES: usize = 145;

/// The name the file gives the basis.
pub const BASIS_NAME: &str = "LBNL/Klems Full";

/// Points across a patch (each way) that [`evaluate`] accepts.
pub const MAX_SAMPLES: usize = 8;

/// One patch of the basis, in the Klems angles of its hemisphere (radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    /// The patch's ring (index into [`RINGS`]).
    pub ring: usize,
    /// Polar bounds.
    pub theta: [f64; 2],
    /// Azimuth bounds (the first may be negative: patches are centred on their azimuth).
    pub phi: [f64; 2],
}

impl Patch {
    /// Patch `k` (0 to 144), numbered ring by ring from the normal, by azimuth within a ring.
    ///
    /// # Panics
    /// If `k` is 145 or more.
    pub fn new(k: usize) -> Patch {
        assert!(k < PATCHES, "Klems patch {k} out of 0..{PATCHES}");
        let mut j = k;
        for (r, ring) in RINGS.iter().enumerate() {
            if j < ring.n_phi {
                let d = 2.0 * PI / ring.n_phi as f64;
                return Patch {
                    ring: r,
                    theta: [ring.lower.to_radians(), ring.upper.to_radians()],
                    phi: [(j as f64 - 0.5) * d, (j as f64 + 0.5) * d],
                };
            }
            j -= ring.n_phi;
        }
        unreachable!("the rings hold {PATCHES} patches")
    }

    /// Solid angle: (phi1 - phi0)(cos theta0 - cos theta1).
    pub fn solid_angle(&self) -> f64 {
        (self.phi[1] - self.phi[0]) * (self.theta[0].cos() - self.theta[1].cos())
    }

    /// Projected solid angle Lambda = int cos(theta) dw = (phi1 - phi0)(sin^2 theta1 -
    /// sin^2 theta0) / 2.
    pub fn lambda(&self) -> f64 {
        let s = |t: f64| t.sin() * t.sin();
        0.5 * (self.phi[1] - self.phi[0]) * (s(self.theta[1]) - s(self.theta[0]))
    }

    /// `k` x `k` points of the patch, (theta, phi), each of equal projected solid angle: the
    /// midpoints of a k x k grid uniform in sin^2(theta) and in phi.
    pub fn points(&self, k: usize) -> Vec<(f64, f64)> {
        let s0 = self.theta[0].sin().powi(2);
        let s1 = self.theta[1].sin().powi(2);
        let mut out = Vec::with_capacity(k * k);
        for a in 0..k {
            let s = s0 + (a as f64 + 0.5) / k as f64 * (s1 - s0);
            let theta = s.sqrt().min(1.0).asin();
            for b in 0..k {
                let phi = self.phi[0] + (b as f64 + 0.5) / k as f64 * (self.phi[1] - self.phi[0]);
                out.push((theta, phi));
            }
        }
        out
    }
}

/// The patch holding the Klems angles (`theta`, `phi`) in radians (theta in [0, pi/2], any
/// phi): rings closed below, open above (theta = 90 degrees falls in the last ring), patches
/// centred on their azimuth, as Radiance's `fo_getndx`.
pub fn patch_of(theta: f64, phi: f64) -> usize {
    let deg = theta.to_degrees().clamp(0.0, 90.0);
    let mut first = 0;
    for (r, ring) in RINGS.iter().enumerate() {
        if deg < ring.upper || r == RINGS.len() - 1 {
            let azi = phi.to_degrees().rem_euclid(360.0);
            let j = ((azi / 360.0) * ring.n_phi as f64 + 0.5).floor() as usize % ring.n_phi;
            return first + j;
        }
        first += ring.n_phi;
    }
    unreachable!()
}

/// The four blocks of a Klems file, each a 145 x 145 matrix.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Block {
    /// Light on the front (+Z), reflected to the front.
    FrontReflection,
    /// Light on the front, transmitted to the back.
    FrontTransmission,
    /// Light on the back (-Z), reflected to the back.
    BackReflection,
    /// Light on the back, transmitted to the front.
    BackTransmission,
}

impl Block {
    /// All four, in the order the file holds them.
    pub const ALL: [Block; 4] = [
        Block::FrontTransmission,
        Block::FrontReflection,
        Block::BackTransmission,
        Block::BackReflection,
    ];

    /// The `WavelengthDataDirection` of the file.
    pub fn direction_name(self) -> &'static str {
        match self {
            Block::FrontReflection => "Reflection Front",
            Block::FrontTransmission => "Transmission Front",
            Block::BackReflection => "Reflection Back",
            Block::BackTransmission => "Transmission Back",
        }
    }

    /// BRDF or BTDF.
    pub fn data_type(self) -> &'static str {
        if self.transmits() {
            "BTDF"
        } else {
            "BRDF"
        }
    }

    /// Light on the front side.
    pub fn from_front(self) -> bool {
        matches!(self, Block::FrontReflection | Block::FrontTransmission)
    }

    /// Transmission (light leaves on the other side).
    pub fn transmits(self) -> bool {
        matches!(self, Block::FrontTransmission | Block::BackTransmission)
    }

    /// Light leaves on the front side.
    fn to_front(self) -> bool {
        self.from_front() != self.transmits()
    }

    /// The incident direction (toward the light, clothbake's frame) at Klems angles
    /// (`theta`, `phi`): azimuth -phi on the incident side (mirrored to -Z for the back).
    pub fn incident(self, theta: f64, phi: f64) -> UnitVec3 {
        side(
            Vec3::new(
                theta.sin() * phi.cos(),
                -theta.sin() * phi.sin(),
                theta.cos(),
            ),
            self.from_front(),
        )
    }

    /// The outgoing direction (toward the eye) at Klems angles (`theta`, `phi`): azimuth
    /// 180 degrees - phi on the outgoing side. A ray passing straight through keeps its patch.
    pub fn outgoing(self, theta: f64, phi: f64) -> UnitVec3 {
        side(
            Vec3::new(
                -theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ),
            self.to_front(),
        )
    }

    /// The patch of an incident direction `wi` on this block's incident side (`None` on the
    /// other side or at the horizon).
    pub fn incident_patch(self, wi: UnitVec3) -> Option<usize> {
        let v = on_side(wi, self.from_front())?;
        Some(patch_of(v.z.clamp(-1.0, 1.0).acos(), (-v.y).atan2(v.x)))
    }

    /// The patch of an outgoing direction `wo` on this block's outgoing side.
    pub fn outgoing_patch(self, wo: UnitVec3) -> Option<usize> {
        let v = on_side(wo, self.to_front())?;
        Some(patch_of(v.z.clamp(-1.0, 1.0).acos(), v.y.atan2(-v.x)))
    }
}

fn side(v: Vec3, front: bool) -> UnitVec3 {
    let v = if front { v } else { Vec3::new(v.x, v.y, -v.z) };
    UnitVec3::new(v).unwrap_or(UnitVec3::Z)
}

fn on_side(w: UnitVec3, front: bool) -> Option<Vec3> {
    let v = w.get();
    let ok = if front {
        w.above_horizon()
    } else {
        w.below_horizon()
    };
    ok.then_some(if front { v } else { Vec3::new(v.x, v.y, -v.z) })
}

/// One block: f in 1/sr, RGB, at `[outgoing * 145 + incident]` (rows outgoing, columns
/// incident, as the file's `IncidentDataStructure` "Columns").
#[derive(Clone, Debug, PartialEq)]
pub struct Matrix {
    /// The entries, row by row.
    pub values: Vec<[f64; 3]>,
}

impl Matrix {
    /// The entry for light in patch `incident` leaving in patch `outgoing`.
    pub fn get(&self, outgoing: usize, incident: usize) -> [f64; 3] {
        self.values[outgoing * PATCHES + incident]
    }

    /// The hemispherical share of light from patch `incident` that this block sends out,
    /// sum_o f Lambda_o, RGB.
    pub fn hemispherical(&self, incident: usize) -> [f64; 3] {
        let mut s = [0.0; 3];
        for o in 0..PATCHES {
            let l = Patch::new(o).lambda();
            let v = self.get(o, incident);
            for c in 0..3 {
                s[c] += v[c] * l;
            }
        }
        s
    }
}

/// The four blocks of a [`Bsdf`] on the Klems basis.
#[derive(Clone, Debug, PartialEq)]
pub struct Klems {
    /// In the order of [`Block::ALL`].
    pub blocks: [Matrix; 4],
    /// Points across a patch each way (k x k per patch).
    pub samples: usize,
}

impl Klems {
    /// The block `b`.
    pub fn block(&self, b: Block) -> &Matrix {
        &self.blocks[Block::ALL.iter().position(|&x| x == b).unwrap_or(0)]
    }
}

/// The most memory [`evaluate`] and [`write_xml`] hold, in bytes, on `threads` threads: the
/// four blocks (RGB, f64), the patches' directions and each thread's pairs and values.
pub fn peak_bytes(threads: usize) -> u64 {
    let blocks = 4 * (PATCHES * PATCHES * 24) as u64;
    let k4 = (MAX_SAMPLES as u64).pow(4);
    let directions = 2 * (PATCHES as u64) * (MAX_SAMPLES as u64).pow(2) * 24;
    let per_thread = k4 * (48 + 24) + (PATCHES * 24) as u64;
    let sheet = (DATASHEET_POINTS[0] * DATASHEET_POINTS[1] * (48 + 24)) as u64;
    blocks * 2 + directions + threads as u64 * per_thread + sheet + (PATCHES * 16) as u64
}

/// Evaluations of f that [`evaluate`] makes with `samples` points across a patch.
pub fn evaluations(samples: usize) -> u64 {
    4 * (PATCHES as u64).pow(2) * (samples as u64).pow(4)
}

/// The four blocks of `bsdf`: each entry the mean of f over `samples` x `samples` points of
/// its incident patch times as many of its outgoing patch (points of equal projected solid
/// angle, [`Patch::points`]: the Lambda-weighted average), plus, on the transmission
/// diagonals, the patch's mean openness divided by its Lambda. Runs on the current rayon pool;
/// deterministic.
///
/// # Panics
/// If `samples` is not in 1..=[`MAX_SAMPLES`].
pub fn evaluate(bsdf: &dyn Bsdf, samples: usize) -> Klems {
    assert!(
        (1..=MAX_SAMPLES).contains(&samples),
        "Klems samples {samples} out of 1..={MAX_SAMPLES}"
    );
    let points: Vec<Vec<(f64, f64)>> = (0..PATCHES)
        .map(|k| Patch::new(k).points(samples))
        .collect();
    let blocks = Block::ALL.map(|b| {
        let inc: Vec<Vec<UnitVec3>> = points
            .iter()
            .map(|p| p.iter().map(|&(t, f)| b.incident(t, f)).collect())
            .collect();
        let out: Vec<Vec<UnitVec3>> = points
            .iter()
            .map(|p| p.iter().map(|&(t, f)| b.outgoing(t, f)).collect())
            .collect();
        let n = samples * samples;
        let rows: Vec<Vec<[f64; 3]>> = (0..PATCHES)
            .into_par_iter()
            .map(|o| {
                let mut pairs = Vec::with_capacity(n * n);
                let mut vals = vec![[0.0; 3]; n * n];
                (0..PATCHES)
                    .map(|i| {
                        pairs.clear();
                        for &wi in &inc[i] {
                            for &wo in &out[o] {
                                pairs.push((wi, wo));
                            }
                        }
                        bsdf.f_batch(&pairs, &mut vals);
                        let mut s = [0.0; 3];
                        for v in &vals {
                            for c in 0..3 {
                                s[c] += v[c];
                            }
                        }
                        let mut m = s.map(|x| x / (n * n) as f64);
                        if b.transmits() && i == o {
                            let open: f64 =
                                inc[i].iter().map(|&w| bsdf.openness(w)).sum::<f64>() / n as f64;
                            let d = open / Patch::new(i).lambda();
                            m = m.map(|x| x + d);
                        }
                        m
                    })
                    .collect()
            })
            .collect();
        Matrix {
            values: rows.into_iter().flatten().collect(),
        }
    });
    Klems { blocks, samples }
}

/// A colour band of the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Band {
    /// CIE Y of the linear (Rec. 709) RGB: 0.2126 R + 0.7152 G + 0.0722 B.
    Visible,
    /// The mean of R, G and B: a grey stand-in for the solar band, which RGB albedos do not
    /// resolve (docs/guide/daylighting.md).
    Solar,
}

impl Band {
    /// The band's value of an RGB triple.
    pub fn of(self, c: [f64; 3]) -> f64 {
        match self {
            Band::Visible => crate::luminance(c),
            Band::Solar => (c[0] + c[1] + c[2]) / 3.0,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Band::Visible => "Visible",
            Band::Solar => "Solar",
        }
    }
}

/// What the file says about itself.
#[derive(Clone, Debug, Default)]
pub struct Description {
    /// The material's name (the fabric's).
    pub name: String,
    /// A comment placed at the top (where the BSDF came from).
    pub comment: String,
}

fn escape(s: &str) -> String {
    let mut o = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => o.push_str("&amp;"),
            '<' => o.push_str("&lt;"),
            '>' => o.push_str("&gt;"),
            '"' => o.push_str("&quot;"),
            '\'' => o.push_str("&apos;"),
            c if c.is_control() => o.push(' '),
            c => o.push(c),
        }
    }
    o
}

/// Writes `k` as an LBNL/Radiance BSDF XML file (WindowElement / Optical / Layer: the basis,
/// then the four blocks for "Visible" and for "Solar"), streamed; returns the bytes written.
/// A value that is not finite is an `InvalidData` error naming its block and patches.
pub fn write_xml<W: Write>(w: &mut W, k: &Klems, d: &Description) -> io::Result<u64> {
    let mut w = Counting { w, n: 0 };
    // An XML comment holds no "--" and does not end in "-".
    let mut comment = escape(&d.comment);
    while comment.contains("--") {
        comment = comment.replace("--", "- -");
    }
    writeln!(w, r#"<?xml version="1.0" encoding="UTF-8"?>"#)?;
    writeln!(
        w,
        r#"<WindowElement xmlns="http://windows.lbl.gov" xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:schemaLocation="http://windows.lbl.gov/BSDF-v1.4.xsd">"#
    )?;
    writeln!(w, "<!-- {comment} -->")?;
    writeln!(w, "<WindowElementType>System</WindowElementType>")?;
    writeln!(w, "<FileType>BSDF</FileType>")?;
    writeln!(w, "<Optical>\n<Layer>\n\t<Material>")?;
    writeln!(w, "\t\t<Name>{}</Name>", escape(&d.name))?;
    writeln!(w, "\t\t<Manufacturer>clothbake</Manufacturer>")?;
    writeln!(w, "\t\t<Thickness unit=\"Meter\">0</Thickness>")?;
    writeln!(w, "\t\t<DeviceType>Integral</DeviceType>")?;
    writeln!(w, "\t</Material>")?;
    writeln!(w, "\t<DataDefinition>")?;
    writeln!(
        w,
        "\t\t<IncidentDataStructure>Columns</IncidentDataStructure>"
    )?;
    writeln!(w, "\t\t<AngleBasis>")?;
    writeln!(w, "\t\t\t<AngleBasisName>{BASIS_NAME}</AngleBasisName>")?;
    for r in RINGS {
        let centre = if r.lower == 0.0 {
            0.0
        } else {
            0.5 * (r.lower + r.upper)
        };
        writeln!(
            w,
            "\t\t\t<AngleBasisBlock>\n\t\t\t\t<Theta>{centre}</Theta>\n\t\t\t\t<nPhis>{}</nPhis>\n\
             \t\t\t\t<ThetaBounds>\n\t\t\t\t\t<LowerTheta>{}</LowerTheta>\n\
             \t\t\t\t\t<UpperTheta>{}</UpperTheta>\n\t\t\t\t</ThetaBounds>\n\t\t\t</AngleBasisBlock>",
            r.n_phi, r.lower, r.upper
        )?;
    }
    writeln!(w, "\t\t</AngleBasis>\n\t</DataDefinition>")?;
    for band in [Band::Visible, Band::Solar] {
        for b in Block::ALL {
            let (source, detector) = match band {
                Band::Visible => ("CIE Illuminant D65 1nm.ssp", "ASTM E308 1931 Y.dsp"),
                Band::Solar => ("None", "None"),
            };
            writeln!(
                w,
                "\t<WavelengthData>\n\t\t<LayerNumber>System</LayerNumber>"
            )?;
            writeln!(
                w,
                "\t\t<Wavelength unit=\"Integral\">{}</Wavelength>",
                band.name()
            )?;
            writeln!(w, "\t\t<SourceSpectrum>{source}</SourceSpectrum>")?;
            writeln!(w, "\t\t<DetectorSpectrum>{detector}</DetectorSpectrum>")?;
            writeln!(w, "\t\t<WavelengthDataBlock>")?;
            writeln!(
                w,
                "\t\t\t<WavelengthDataDirection>{}</WavelengthDataDirection>",
                b.direction_name()
            )?;
            writeln!(w, "\t\t\t<ColumnAngleBasis>{BASIS_NAME}</ColumnAngleBasis>")?;
            writeln!(w, "\t\t\t<RowAngleBasis>{BASIS_NAME}</RowAngleBasis>")?;
            writeln!(
                w,
                "\t\t\t<ScatteringDataType>{}</ScatteringDataType>",
                b.data_type()
            )?;
            writeln!(w, "\t\t\t<ScatteringData>")?;
            let m = k.block(b);
            let mut line = String::with_capacity(PATCHES * 14);
            for o in 0..PATCHES {
                line.clear();
                for i in 0..PATCHES {
                    if i > 0 {
                        line.push_str(", ");
                    }
                    let v = band.of(m.get(o, i));
                    if !v.is_finite() {
                        return Err(io::Error::new(
                            io::ErrorKind::InvalidData,
                            format!(
                                "the BSDF gave {v} in {} at outgoing patch {o}, incident patch \
                                 {i}: a Klems file holds finite values only",
                                b.direction_name()
                            ),
                        ));
                    }
                    if v == 0.0 {
                        line.push('0');
                    } else {
                        use std::fmt::Write as _;
                        let _ = write!(line, "{v:.6e}");
                    }
                }
                writeln!(w, "{line}")?;
            }
            writeln!(w, "\t\t\t</ScatteringData>")?;
            writeln!(w, "\t\t</WavelengthDataBlock>\n\t</WavelengthData>")?;
        }
    }
    writeln!(w, "</Layer>\n</Optical>\n</WindowElement>")?;
    Ok(w.n)
}

struct Counting<'a, W> {
    w: &'a mut W,
    n: u64,
}

impl<W: Write> Write for Counting<'_, W> {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        let n = self.w.write(buf)?;
        self.n += n as u64;
        Ok(n)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.w.flush()
    }
}

/// The figures a fabric-shade datasheet gives, at normal incidence on the front unless named
/// otherwise; fractions in [0, 1] for a physical BSDF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Datasheet {
    /// Openness factor: the share of light from the normal passing straight through the gaps.
    pub openness: f64,
    /// Visible transmittance, direct (the openness) plus diffuse (f over the back hemisphere).
    pub visible_transmittance: f64,
    /// Solar transmittance, likewise ([`Band::Solar`]).
    pub solar_transmittance: f64,
    /// Visible reflectance of the front (light from +Z, hemispherical).
    pub visible_reflectance_front: f64,
    /// Visible reflectance of the back (light from -Z).
    pub visible_reflectance_back: f64,
    /// Solar reflectance of the front.
    pub solar_reflectance_front: f64,
    /// Solar reflectance of the back.
    pub solar_reflectance_back: f64,
}

/// Points per axis of the datasheet's hemispherical integrals (uniform in sin^2(theta) and
/// in phi: points of equal projected solid angle, midpoints).
pub const DATASHEET_POINTS: [usize; 2] = [96, 192];

/// The hemispherical integral int f(wi, w) |cos theta| dw over the side `front` (RGB).
fn hemispherical(bsdf: &dyn Bsdf, wi: UnitVec3, front: bool) -> [f64; 3] {
    let [nt, np] = DATASHEET_POINTS;
    let mut pairs = Vec::with_capacity(nt * np);
    for a in 0..nt {
        let s = (a as f64 + 0.5) / nt as f64;
        let st = s.sqrt();
        let ct = (1.0 - s).max(0.0).sqrt();
        for b in 0..np {
            let phi = (b as f64 + 0.5) / np as f64 * 2.0 * PI;
            let z = if front { ct } else { -ct };
            let wo =
                UnitVec3::new(Vec3::new(st * phi.cos(), st * phi.sin(), z)).unwrap_or(UnitVec3::Z);
            pairs.push((wi, wo));
        }
    }
    let mut vals = vec![[0.0; 3]; pairs.len()];
    bsdf.f_batch(&pairs, &mut vals);
    let mut s = [0.0; 3];
    for v in &vals {
        for c in 0..3 {
            s[c] += v[c];
        }
    }
    s.map(|x| x * PI / pairs.len() as f64)
}

impl Datasheet {
    /// The figures of `bsdf` (direct integrals of f and the openness, not through the Klems
    /// matrices).
    pub fn of(bsdf: &dyn Bsdf) -> Datasheet {
        let front = UnitVec3::Z;
        let back = UnitVec3::Z.reverse();
        let openness = bsdf.openness(front);
        let t = hemispherical(bsdf, front, false);
        let rf = hemispherical(bsdf, front, true);
        let rb = hemispherical(bsdf, back, false);
        Datasheet {
            openness,
            visible_transmittance: openness + Band::Visible.of(t),
            solar_transmittance: openness + Band::Solar.of(t),
            visible_reflectance_front: Band::Visible.of(rf),
            visible_reflectance_back: Band::Visible.of(rb),
            solar_reflectance_front: Band::Solar.of(rf),
            solar_reflectance_back: Band::Solar.of(rb),
        }
    }

    /// One line for people: percentages.
    pub fn summary(&self) -> String {
        let p = |x: f64| 100.0 * x;
        format!(
            "openness factor {:.2}%, visible transmittance {:.2}%, solar transmittance {:.2}%, \
             reflectance front {:.2}% visible / {:.2}% solar, back {:.2}% visible / {:.2}% \
             solar (normal incidence)",
            p(self.openness),
            p(self.visible_transmittance),
            p(self.solar_transmittance),
            p(self.visible_reflectance_front),
            p(self.solar_reflectance_front),
            p(self.visible_reflectance_back),
            p(self.solar_reflectance_back)
        )
    }
}

#[cfg(test)]
mod tests;
