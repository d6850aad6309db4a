//! The RGL material database's tensor-file `.bsdf` (Dupuy & Jakob 2018, "An adaptive
//! parameterization for efficient material acquisition and rendering"), as Mitsuba 3's
//! `measured` BSDF (RGB flavour; spectral flavour in its spectral variants) and pbrt-v4's
//! `measured` material (spectral flavour only) read it. Layout and parameterisation:
//! `docs/guide/export.md`.
//!
//! The file is a `tensor_file`: a header naming fields (name, element type, shape, offset) and
//! their little-endian data. The reader interpolates, for the view direction v (its
//! "theta_i, phi_i"), a table `rgb[phi_i][theta_i][channel][y][x]` over the unit square: it maps
//! the half vector m of (v, light) to u_m = (sqrt(theta_m / (pi/2)), (phi_m + pi) / (2 pi)),
//! inverts the warp `vndf` at u_m and bilinearly interpolates the table there, then multiplies
//! by ndf(u_m) / (4 sigma(u_v)) when `jacobian` is 1. Here:
//!
//! * `vndf` is constant, so its warp is the identity: the rgb grid is uniform in u_m;
//! * `ndf` = 1 and `sigma` = 1/4 (constant), so that factor is exactly 1 and
//!   `rgb = f_r(light, v) cos theta_light`, the value Mitsuba's `eval` returns;
//! * `luminance` (the reader's importance-sampling density over the same square) is the
//!   luminance of `rgb` times the reader's Jacobian from u_m to solid angle, plus 1% of its mean.
//!
//! The view direction's nodes: theta_k = k (pi/2) / n_theta, k < n_theta; phi_j = -pi + 2 pi j /
//! n_phi, j <= n_phi (the last node repeats the first: no symmetry reduction, which both
//! Mitsuba 3 and pbrt-v4 accept).

use super::{luminance, reflect, spectrum, Bsdf};
use clothbake_core::UnitVec3;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::io::{self, Write};

/// The file's magic: "tensor_file" and a NUL.
pub const MAGIC: &[u8; 12] = b"tensor_file\0";
/// Format version written (major, minor).
pub const VERSION: [u8; 2] = [1, 0];

/// Element types of a tensor field, with their codes in the file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dtype {
    /// Unsigned bytes (code 1).
    U8,
    /// 32-bit IEEE floats (code 10).
    F32,
}

impl Dtype {
    /// The type's code in a tensor file.
    pub fn code(self) -> u8 {
        match self {
            Dtype::U8 => 1,
            Dtype::F32 => 10,
        }
    }
}

/// One named field of a tensor file: element type, shape (outermost first) and the data as
/// little-endian bytes.
#[derive(Clone, Debug, PartialEq)]
pub struct Field {
    /// Field name, e.g. "rgb".
    pub name: String,
    /// Element type.
    pub dtype: Dtype,
    /// Shape, outermost dimension first (row-major data).
    pub shape: Vec<u64>,
    /// The elements, little-endian.
    pub data: Vec<u8>,
}

impl Field {
    /// A float32 field; `values.len()` must be the product of `shape`.
    pub fn f32(name: &str, shape: &[u64], values: &[f32]) -> Field {
        assert_eq!(values.len() as u64, shape.iter().product::<u64>());
        Field {
            name: name.into(),
            dtype: Dtype::F32,
            shape: shape.to_vec(),
            data: values.iter().flat_map(|v| v.to_le_bytes()).collect(),
        }
    }

    /// A byte field of shape [len].
    pub fn bytes(name: &str, b: &[u8]) -> Field {
        Field {
            name: name.into(),
            dtype: Dtype::U8,
            shape: vec![b.len() as u64],
            data: b.to_vec(),
        }
    }
}

/// A field of a tensor file whose data is made as the file is written
/// ([`write_tensor_file`]), so that no copy of a large field is held: element type, shape and a
/// function writing the little-endian elements.
pub struct LazyField<'a> {
    /// Field name, e.g. "rgb".
    pub name: String,
    /// Element type.
    pub dtype: Dtype,
    /// Shape, outermost dimension first (row-major data).
    pub shape: Vec<u64>,
    data: WriteData<'a>,
}

/// What writes a [`LazyField`]'s data.
type WriteData<'a> = Box<dyn Fn(&mut dyn Write) -> io::Result<()> + Sync + 'a>;

impl<'a> LazyField<'a> {
    /// A field of `shape` whose f32 elements `data` writes, in order (through [`put_f32s`]).
    pub fn f32_with(
        name: &str,
        shape: &[u64],
        data: impl Fn(&mut dyn Write) -> io::Result<()> + Sync + 'a,
    ) -> LazyField<'a> {
        LazyField {
            name: name.into(),
            dtype: Dtype::F32,
            shape: shape.to_vec(),
            data: Box::new(data),
        }
    }

    /// A field written from its bytes.
    pub fn of(f: &'a Field) -> LazyField<'a> {
        LazyField {
            name: f.name.clone(),
            dtype: f.dtype,
            shape: f.shape.clone(),
            data: Box::new(move |w| w.write_all(&f.data)),
        }
    }

    /// The size of the field's data in bytes.
    pub fn byte_len(&self) -> u64 {
        let size = match self.dtype {
            Dtype::U8 => 1,
            Dtype::F32 => 4,
        };
        self.shape.iter().product::<u64>() * size
    }

    /// The field with its data made (what [`tensor_file`] takes).
    pub fn to_field(&self) -> Field {
        let mut data = Vec::with_capacity(self.byte_len() as usize);
        (self.data)(&mut data).expect("writing to memory cannot fail");
        Field {
            name: self.name.clone(),
            dtype: self.dtype,
            shape: self.shape.clone(),
            data,
        }
    }
}

/// Writes `values` as little-endian f32 through a small buffer.
pub fn put_f32s(w: &mut dyn Write, values: impl IntoIterator<Item = f32>) -> io::Result<()> {
    let mut buf = Vec::with_capacity(1 << 16);
    for v in values {
        buf.extend_from_slice(&v.to_le_bytes());
        if buf.len() >= 1 << 16 {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)
}

/// Serialises fields into a tensor file: magic, version (u8 major, minor), u32 field count, then
/// per field u16 name length, name, u16 rank, u8 type code, u64 data offset, rank x u64 shape;
/// then each field's data, starting at a multiple of 8 bytes. All integers little-endian.
pub fn tensor_file(fields: &[Field]) -> Vec<u8> {
    let lazy: Vec<LazyField<'_>> = fields.iter().map(LazyField::of).collect();
    let mut out = Vec::new();
    write_tensor_file(&mut out, &lazy).expect("writing to memory cannot fail");
    out
}

/// Writes the tensor file of `fields` (the layout of [`tensor_file`]) to `out`, each field's
/// data made as it is written; returns the file's size in bytes. An error when a field writes
/// another number of bytes than its shape holds (a bug in the caller).
pub fn write_tensor_file(out: &mut dyn Write, fields: &[LazyField<'_>]) -> io::Result<u64> {
    let header: u64 = 12
        + 2
        + 4
        + fields
            .iter()
            .map(|f| 2 + f.name.len() as u64 + 2 + 1 + 8 + 8 * f.shape.len() as u64)
            .sum::<u64>();
    let align = |x: u64| x.div_ceil(8) * 8;
    let mut offsets = Vec::with_capacity(fields.len());
    let mut at = align(header);
    for f in fields {
        offsets.push(at);
        at = align(at + f.byte_len());
    }
    let mut head = Vec::with_capacity(header as usize);
    head.extend_from_slice(MAGIC);
    head.extend_from_slice(&VERSION);
    head.extend_from_slice(&(fields.len() as u32).to_le_bytes());
    for (f, &off) in fields.iter().zip(&offsets) {
        head.extend_from_slice(&(f.name.len() as u16).to_le_bytes());
        head.extend_from_slice(f.name.as_bytes());
        head.extend_from_slice(&(f.shape.len() as u16).to_le_bytes());
        head.push(f.dtype.code());
        head.extend_from_slice(&off.to_le_bytes());
        for &s in &f.shape {
            head.extend_from_slice(&s.to_le_bytes());
        }
    }
    debug_assert_eq!(head.len() as u64, header);
    let mut w = Counted { inner: out, n: 0 };
    w.write_all(&head)?;
    for (f, &off) in fields.iter().zip(&offsets) {
        w.pad_to(off)?;
        let before = w.n;
        (f.data)(&mut w)?;
        if w.n - before != f.byte_len() {
            return Err(io::Error::other(format!(
                "field {} wrote {} bytes for a shape of {} (a bug)",
                f.name,
                w.n - before,
                f.byte_len()
            )));
        }
    }
    w.pad_to(at)?;
    Ok(at)
}

/// A writer counting the bytes written.
struct Counted<'w> {
    inner: &'w mut dyn Write,
    n: u64,
}

impl Counted<'_> {
    fn pad_to(&mut self, at: u64) -> io::Result<()> {
        let zeros = [0u8; 8];
        while self.n < at {
            let k = (at - self.n).min(8) as usize;
            self.write_all(&zeros[..k])?;
        }
        Ok(())
    }
}

impl Write for Counted<'_> {
    fn write(&mut self, b: &[u8]) -> io::Result<usize> {
        let k = self.inner.write(b)?;
        self.n += k as u64;
        Ok(k)
    }
    fn flush(&mut self) -> io::Result<()> {
        self.inner.flush()
    }
}

/// Resolution of an RGL export.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RglGrid {
    /// Polar nodes of the view direction (>= 2): theta_k = k 90 / n degrees.
    pub n_theta: usize,
    /// Azimuth intervals of the view direction (>= 2): n + 1 nodes from -180 to 180 degrees.
    pub n_phi: usize,
    /// Nodes per side of each (theta, phi) slice over the half-vector square (>= 2).
    pub n_slice: usize,
}

/// The default export grid: 16 polar and 24 azimuth steps of the view direction, 32 x 32 nodes
/// per slice (about 8 MB).
pub const DEFAULT_GRID: RglGrid = RglGrid {
    n_theta: 16,
    n_phi: 24,
    n_slice: 32,
};

impl RglGrid {
    /// Slices evaluated and held: one per view-direction node, the repeated phi = pi
    /// excluded.
    pub fn slices(&self) -> u64 {
        self.n_phi as u64 * self.n_theta as u64
    }

    /// An upper bound on the memory an RGL export of this grid takes besides the program,
    /// in bytes, with `threads` workers (the RGB and the spectral file alike, one or both):
    /// the slices held (16 bytes a texel: rgb and luminance f32, and 64 bytes a slice), each
    /// worker's slice in evaluation (at most 192 bytes a texel: the direction pairs, their
    /// values, the texels and the luminance in f64, counted with room), and the writer's
    /// buffers (1 MiB and 64 KiB). The files are streamed from the slices
    /// ([`lazy_fields_of`], [`write_tensor_file`]): nothing the size of a file is held.
    pub fn peak_bytes(&self, threads: usize) -> u64 {
        let texels = (self.n_slice as u64).pow(2);
        let workers = (threads.max(1) as u64).min(self.slices());
        self.slices() * (16 * texels + 64) + workers * 192 * texels + (1 << 20) + (1 << 16)
    }

    /// An error message naming the bad count, or `Ok`.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v, max) in [
            ("theta", self.n_theta, 1024),
            ("phi", self.n_phi, 1024),
            ("slice", self.n_slice, 1024),
        ] {
            if !(2..=max).contains(&v) {
                return Err(format!(
                    "the {name} resolution {v} is out of range; give a value from 2 to {max}"
                ));
            }
        }
        let bytes =
            (self.n_phi as u64 + 1) * self.n_theta as u64 * (self.n_slice as u64).pow(2) * 16;
        if bytes > 2 << 30 {
            return Err(format!(
                "the tables would take {:.1} GB; lower the resolution",
                bytes as f64 / 1e9
            ));
        }
        Ok(())
    }

    /// The view direction's polar nodes, radians.
    pub fn theta_nodes(&self) -> Vec<f64> {
        (0..self.n_theta)
            .map(|k| k as f64 * (PI / 2.0) / self.n_theta as f64)
            .collect()
    }

    /// The view direction's azimuth nodes, radians, -pi to pi inclusive.
    pub fn phi_nodes(&self) -> Vec<f64> {
        (0..=self.n_phi)
            .map(|j| -PI + 2.0 * PI * j as f64 / self.n_phi as f64)
            .collect()
    }
}

/// The half vector at node (x, y) of a slice of `n` nodes per side: theta_m = u_x^2 pi/2, phi_m =
/// (2 u_y - 1) pi with u = (x, y) / (n - 1), the readers' square-root polar mapping. Also returns
/// u_x.
pub fn slice_half_vector(x: usize, y: usize, n: usize) -> (UnitVec3, f64) {
    let ux = x as f64 / (n - 1) as f64;
    let uy = y as f64 / (n - 1) as f64;
    (
        UnitVec3::from_spherical(ux * ux * PI / 2.0, (2.0 * uy - 1.0) * PI),
        ux,
    )
}

/// The tables of one view direction v: rgb (3 x n x n, channel-major) and luminance (n x n).
fn slice(brdf: &dyn Bsdf, v: UnitVec3, n: usize) -> (Vec<f32>, Vec<f32>) {
    let mut rgb = vec![0f32; 3 * n * n];
    let mut lum = vec![0f64; n * n];
    // The slice's texels that reflect into the upper hemisphere, evaluated in one batch.
    let mut texels = Vec::with_capacity(n * n);
    let mut pairs = Vec::with_capacity(n * n);
    for y in 0..n {
        for x in 0..n {
            let (m, ux) = slice_half_vector(x, y, n);
            let cos_vm = v.dot(m.get());
            let Some(l) = reflect(v, m).filter(|l| cos_vm > 0.0 && l.above_horizon()) else {
                continue;
            };
            texels.push((x, y, m, ux, cos_vm));
            pairs.push((l, v));
        }
    }
    let mut fs = vec![[0.0; 3]; pairs.len()];
    brdf.f_batch(&pairs, &mut fs);
    for (&(x, y, m, ux, cos_vm), (&(l, _), f)) in texels.iter().zip(pairs.iter().zip(&fs)) {
        // What the reader returns: f_r(light, view) cos(theta_light).
        let f = f.map(|c| c * l.cos_theta());
        for (c, fc) in f.iter().enumerate() {
            rgb[(c * n + y) * n + x] = *fc as f32;
        }
        // d omega_light / d u_m (the readers' Jacobian): 2 pi^2 u_x sin(theta_m) 4 (v.m).
        let sin_m = (1.0 - m.cos_theta().powi(2)).max(0.0).sqrt();
        lum[y * n + x] = luminance(f).max(0.0) * 2.0 * PI * PI * ux * sin_m * 4.0 * cos_vm;
    }
    let mean = lum.iter().sum::<f64>() / lum.len() as f64;
    let floor = if mean > 0.0 { 0.01 * mean } else { 1.0 };
    (rgb, lum.iter().map(|&l| (l + floor) as f32).collect())
}

/// How an RGL file carries colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Colour {
    /// A `rgb` field [phi_i, theta_i, 3, n, n]: Mitsuba 3's RGB variants.
    Rgb,
    /// `wavelengths` [25] (nm) and `spectra` [phi_i, theta_i, 25, n, n], the `rgb` values
    /// upsampled by [`spectrum::Upsampling`]: pbrt-v4 and Mitsuba 3's spectral variants. No
    /// `rgb` field: Mitsuba's RGB variants refuse any file with `wavelengths`.
    Spectral,
}

/// The evaluated tables of an RGL export: per view-direction node (j < n_phi, k < n_theta), the
/// `rgb` slice (3 x n x n, channel-major) and the `luminance` slice (n x n). Shared by the RGB
/// and the spectral file of one export.
pub struct Slices {
    grid: RglGrid,
    slices: Vec<(Vec<f32>, Vec<f32>)>,
}

/// Evaluates `brdf` on every slice of `grid`. Deterministic: slices are evaluated in parallel on
/// the current rayon pool and collected in order.
pub fn rgl_slices(brdf: &dyn Bsdf, grid: &RglGrid) -> Slices {
    let (nt, np, n) = (grid.n_theta, grid.n_phi + 1, grid.n_slice);
    let thetas = grid.theta_nodes();
    let phis = grid.phi_nodes();
    // Slice (j, k) for j < n_phi; the node phi = pi repeats phi = -pi (copied, not re-evaluated).
    let slices = (0..(np - 1) * nt)
        .into_par_iter()
        .map(|s| {
            let (j, k) = (s / nt, s % nt);
            slice(brdf, UnitVec3::from_spherical(thetas[k], phis[j]), n)
        })
        .collect();
    Slices {
        grid: *grid,
        slices,
    }
}

/// The fields of a `.bsdf` file for `brdf` on `grid`: [`rgl_slices`] then [`fields_of`].
pub fn rgl_fields(
    brdf: &dyn Bsdf,
    grid: &RglGrid,
    description: &str,
    colour: Colour,
) -> Vec<Field> {
    fields_of(&rgl_slices(brdf, grid), description, colour)
}

/// The fields of a `.bsdf` file from evaluated slices, in the order written: description,
/// jacobian, theta_i, phi_i, ndf, sigma, vndf, luminance, then `rgb` or `wavelengths` and
/// `spectra` (see [`Colour`]; the readers find fields by name). Made in memory: for a file,
/// [`lazy_fields_of`] and [`write_tensor_file`] hold nothing but the slices.
pub fn fields_of(slices: &Slices, description: &str, colour: Colour) -> Vec<Field> {
    lazy_fields_of(slices, description, colour)
        .iter()
        .map(LazyField::to_field)
        .collect()
}

/// [`fields_of`] with the large fields (luminance, rgb, spectra) made from the slices as the
/// file is written.
pub fn lazy_fields_of<'a>(
    slices: &'a Slices,
    description: &str,
    colour: Colour,
) -> Vec<LazyField<'a>> {
    let grid = &slices.grid;
    let (nt, np, n) = (grid.n_theta, grid.n_phi + 1, grid.n_slice);
    let thetas = grid.theta_nodes();
    let phis = grid.phi_nodes();
    // Slice (j, k); the node phi = pi (j = n_phi) repeats phi = -pi.
    let slice_at = move |j: usize, k: usize| &slices.slices[(j % (np - 1)) * nt + k];
    let every = move || (0..np).flat_map(move |j| (0..nt).map(move |k| slice_at(j, k)));
    let (npu, ntu, nu) = (np as u64, nt as u64, n as u64);
    let f32s = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let eager = |f: Field| LazyField {
        name: f.name,
        dtype: f.dtype,
        shape: f.shape,
        data: Box::new(move |w: &mut dyn Write| w.write_all(&f.data)),
    };
    let mut fields = vec![
        eager(Field::bytes("description", description.as_bytes())),
        eager(Field::bytes("jacobian", &[1])),
        eager(Field::f32("theta_i", &[ntu], &f32s(&thetas))),
        eager(Field::f32("phi_i", &[npu], &f32s(&phis))),
        eager(Field::f32("ndf", &[2, 2], &[1.0; 4])),
        eager(Field::f32("sigma", &[2, 2], &[0.25; 4])),
        eager(Field::f32(
            "vndf",
            &[npu, ntu, 2, 2],
            &vec![1.0; np * nt * 4],
        )),
        LazyField::f32_with("luminance", &[npu, ntu, nu, nu], move |w| {
            every().try_for_each(|s| put_f32s(w, s.1.iter().copied()))
        }),
    ];
    match colour {
        Colour::Rgb => fields.push(LazyField::f32_with(
            "rgb",
            &[npu, ntu, 3, nu, nu],
            move |w| every().try_for_each(|s| put_f32s(w, s.0.iter().copied())),
        )),
        Colour::Spectral => {
            let nw = spectrum::WAVELENGTHS.len();
            fields.push(eager(Field::f32(
                "wavelengths",
                &[nw as u64],
                &f32s(&spectrum::WAVELENGTHS),
            )));
            let basis = spectrum::Upsampling::new();
            fields.push(LazyField::f32_with(
                "spectra",
                &[npu, ntu, nw as u64, nu, nu],
                move |w| {
                    every().try_for_each(|s| {
                        let rgb = &s.0;
                        basis.basis().iter().try_for_each(|b| {
                            put_f32s(
                                w,
                                (0..n * n).map(|i| {
                                    (0..3)
                                        .map(|c| b[c] * f64::from(rgb[c * n * n + i]))
                                        .sum::<f64>() as f32
                                }),
                            )
                        })
                    })
                },
            ));
        }
    }
    fields
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_u64(b: &[u8], at: usize) -> u64 {
        u64::from_le_bytes(b[at..at + 8].try_into().unwrap())
    }

    #[test]
    fn tensor_file_layout() {
        let fields = [
            Field::bytes("ab", b"xyz"),
            Field::f32("c", &[2, 1], &[1.5, -2.0]),
        ];
        let b = tensor_file(&fields);
        assert_eq!(&b[..12], b"tensor_file\0");
        assert_eq!(&b[12..14], &[1, 0]);
        assert_eq!(u32::from_le_bytes(b[14..18].try_into().unwrap()), 2);
        // Field "ab": name length, name, rank 1, u8, offset, shape [3].
        assert_eq!(&b[18..20], &[2, 0]);
        assert_eq!(&b[20..22], b"ab");
        assert_eq!(&b[22..24], &[1, 0]);
        assert_eq!(b[24], 1);
        let off_ab = read_u64(&b, 25) as usize;
        assert_eq!(read_u64(&b, 33), 3);
        // Field "c": rank 2, f32, shape [2, 1].
        assert_eq!(&b[41..43], &[1, 0]);
        assert_eq!(b[43], b'c');
        assert_eq!(&b[44..46], &[2, 0]);
        assert_eq!(b[46], 10);
        let off_c = read_u64(&b, 47) as usize;
        assert_eq!((read_u64(&b, 55), read_u64(&b, 63)), (2, 1));
        // Header ends at 71; data 8-aligned.
        assert_eq!(off_ab, 72);
        assert_eq!(&b[72..75], b"xyz");
        assert_eq!(off_c, 80);
        assert_eq!(f32::from_le_bytes(b[80..84].try_into().unwrap()), 1.5);
        assert_eq!(f32::from_le_bytes(b[84..88].try_into().unwrap()), -2.0);
        assert_eq!(b.len(), 88);
    }

    #[test]
    fn lambertian_slices_hold_rho_cos_over_pi() {
        // f_r = rho / pi: every rgb node whose light is above the horizon holds rho cos / pi.
        let rho = 0.5;
        let brdf = clothbake_core::FromFn(|wi: UnitVec3, wo: UnitVec3| {
            if wi.above_horizon() && wo.above_horizon() {
                [rho / PI; 3]
            } else {
                [0.0; 3]
            }
        });
        let g = RglGrid {
            n_theta: 3,
            n_phi: 4,
            n_slice: 5,
        };
        let fields = rgl_fields(&brdf, &g, "test", Colour::Rgb);
        let rgb = &fields[8];
        assert_eq!(rgb.shape, vec![5, 3, 3, 5, 5]);
        let vals: Vec<f32> = rgb
            .data
            .chunks(4)
            .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
            .collect();
        let (thetas, phis) = (g.theta_nodes(), g.phi_nodes());
        let mut lit = 0;
        for j in 0..5 {
            for k in 0..3 {
                let v = UnitVec3::from_spherical(thetas[k], phis[j]);
                for y in 0..5 {
                    for x in 0..5 {
                        let (m, _) = slice_half_vector(x, y, 5);
                        let l = reflect(v, m).unwrap();
                        let want = if l.above_horizon() && v.dot(m.get()) > 0.0 {
                            lit += 1;
                            rho * l.cos_theta() / PI
                        } else {
                            0.0
                        };
                        for c in 0..3 {
                            let got = vals[(((j * 3 + k) * 3 + c) * 5 + y) * 5 + x] as f64;
                            assert!((got - want).abs() < 1e-7, "{got} {want}");
                        }
                    }
                }
            }
        }
        assert!(lit > 100);
    }

    #[test]
    fn grids_out_of_range_are_refused() {
        assert!(DEFAULT_GRID.validate().is_ok());
        let e = RglGrid {
            n_slice: 1,
            ..DEFAULT_GRID
        }
        .validate()
        .unwrap_err();
        assert!(e.contains("slice resolution 1"), "{e}");
    }
}
