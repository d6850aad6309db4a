//! The textures a fitted material is carried in: 8-bit maps over one period, with the exact
//! values a renderer decodes from them ([`Maps::decoded`]), so that a test can evaluate what
//! a file really holds.
//!
//! Rows run with v (+Y, the warp) from row 0 at v = 0; a writer whose image rows run the other
//! way (glTF: row 0 at the top, where its UV v = 0 lies) flips them ([`Maps::flipped`]).
//! Colours are sRGB-encoded (the targets' convention for colour textures), the other maps
//! linear.

use super::material::Fitted;
use super::Params;

/// One texture: `w` x `h` texels of `channels` bytes each, row-major.
#[derive(Clone, Debug, PartialEq)]
pub struct Map {
    /// Width in texels.
    pub w: usize,
    /// Height in texels.
    pub h: usize,
    /// Bytes per texel (3 or 4).
    pub channels: usize,
    /// The texels.
    pub data: Vec<u8>,
}

impl Map {
    /// The map as a PNG file's bytes.
    pub fn png(&self) -> Vec<u8> {
        let mut out = Vec::new();
        {
            let mut enc = png::Encoder::new(&mut out, self.w as u32, self.h as u32);
            enc.set_color(if self.channels == 4 {
                png::ColorType::Rgba
            } else {
                png::ColorType::Rgb
            });
            enc.set_depth(png::BitDepth::Eight);
            let mut wr = enc.write_header().expect("PNG header to memory");
            wr.write_image_data(&self.data).expect("PNG data to memory");
        }
        out
    }

    /// The same map with its rows in the opposite order.
    pub fn flipped(&self) -> Map {
        let row = self.w * self.channels;
        let mut data = Vec::with_capacity(self.data.len());
        for r in (0..self.h).rev() {
            data.extend_from_slice(&self.data[r * row..(r + 1) * row]);
        }
        Map {
            data,
            ..self.clone()
        }
    }
}

/// The map of `m` at its [`Fitted::texture_size`] whose texel holds `f` of its cell's
/// parameters (`channels` bytes).
pub fn raster(m: &Fitted, channels: usize, f: &dyn Fn(&Params) -> Vec<u8>) -> Map {
    let (w, h) = m.texture_size();
    Map {
        w,
        h,
        channels,
        data: m
            .texel_cells(w, h)
            .iter()
            .flat_map(|&k| f(&m.cells[k]))
            .collect(),
    }
}

/// The index of the texel of a `w` x `h` map (row 0 at v = 0) under the centre of cell `k`
/// of `m`: where a file's parameters for that cell are read back.
pub fn centre_texel(m: &Fitted, k: usize, w: usize, h: usize) -> usize {
    let (nu, _) = m.dims();
    let (i, j) = (k % nu, k / nu);
    let u = (0.5 * (m.u_edges[i] + m.u_edges[i + 1])).rem_euclid(1.0);
    let v = (0.5 * (m.v_edges[j] + m.v_edges[j + 1])).rem_euclid(1.0);
    ((v * h as f64) as usize).min(h - 1) * w + ((u * w as f64) as usize).min(w - 1)
}

/// The sRGB encoding of a linear value in [0, 1], to 8 bits.
pub fn srgb8(x: f64) -> u8 {
    let x = x.clamp(0.0, 1.0);
    let e = if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    };
    (e * 255.0).round() as u8
}

/// The linear value of an 8-bit sRGB code.
pub fn srgb_decode(b: u8) -> f64 {
    let e = b as f64 / 255.0;
    if e <= 0.04045 {
        e / 12.92
    } else {
        ((e + 0.055) / 1.055).powf(2.4)
    }
}

/// A linear value in [0, 1] to 8 bits.
pub fn unorm8(x: f64) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}

/// A signed value in [-1, 1] to 8 bits, as glTF's anisotropy direction (x * 0.5 + 0.5).
pub fn snorm8(x: f64) -> u8 {
    unorm8(0.5 * x + 0.5)
}

/// The maps of a textured material.
#[derive(Clone, Debug)]
pub struct Maps {
    /// Base colour, sRGB RGB.
    pub base: Map,
    /// Specular roughness, linear, in glTF's metallic-roughness layout (G roughness, B
    /// metallic = 0).
    pub roughness: Map,
    /// The rough direction and the anisotropy, as KHR_materials_anisotropy lays them out: R,
    /// G the direction's cosine and sine (x 0.5 + 0.5), B the anisotropy.
    pub anisotropy: Map,
    /// Sheen: RGB the (grey) sheen colour, sRGB; A its roughness, linear.
    pub sheen: Map,
}

impl Maps {
    /// The maps of `m` at its [`Fitted::texture_size`].
    pub fn new(m: &Fitted) -> Maps {
        let map = |channels: usize, f: &dyn Fn(&Params) -> Vec<u8>| raster(m, channels, f);
        Maps {
            base: map(3, &|p| p.base.iter().map(|&c| srgb8(c)).collect()),
            roughness: map(3, &|p| vec![0, unorm8(p.roughness), 0]),
            anisotropy: map(3, &|p| {
                let (s, c) = p.tangent_deg.to_radians().sin_cos();
                vec![snorm8(c), snorm8(s), unorm8(p.anisotropy)]
            }),
            sheen: map(4, &|p| {
                let g = srgb8(p.sheen);
                vec![g, g, g, unorm8(p.sheen_roughness)]
            }),
        }
    }

    /// The parameters a renderer decodes from texel `k` of the maps.
    pub fn decoded(&self, k: usize) -> Params {
        let b = &self.base.data[3 * k..3 * k + 3];
        let r = &self.roughness.data[3 * k..3 * k + 3];
        let a = &self.anisotropy.data[3 * k..3 * k + 3];
        let s = &self.sheen.data[4 * k..4 * k + 4];
        let dir = |x: u8| x as f64 / 255.0 * 2.0 - 1.0;
        Params {
            base: [srgb_decode(b[0]), srgb_decode(b[1]), srgb_decode(b[2])],
            roughness: r[1] as f64 / 255.0,
            anisotropy: a[2] as f64 / 255.0,
            tangent_deg: dir(a[1]).atan2(dir(a[0])).to_degrees(),
            sheen: srgb_decode(s[0]),
            sheen_roughness: s[3] as f64 / 255.0,
            diffuse_roughness: 0.0,
        }
    }

    /// `m` with each cell's parameters as the maps hold them (the texel at the cell's centre).
    pub fn quantised(&self, m: &Fitted) -> Fitted {
        let (w, h) = (self.base.w, self.base.h);
        let cells = (0..m.cells.len())
            .map(|k| self.decoded(centre_texel(m, k, w, h)))
            .collect();
        Fitted { cells, ..m.clone() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_codes_round_trip() {
        for b in 0..=255u8 {
            assert_eq!(srgb8(srgb_decode(b)), b);
        }
        assert!((srgb_decode(255) - 1.0).abs() < 1e-12 && srgb_decode(0) == 0.0);
    }

    #[test]
    fn png_bytes_decode_to_the_map() {
        let m = Map {
            w: 3,
            h: 2,
            channels: 4,
            data: (0..24).map(|x| (x * 10) as u8).collect(),
        };
        let bytes = m.png();
        let mut dec = png::Decoder::new(std::io::Cursor::new(bytes))
            .read_info()
            .unwrap();
        let mut buf = vec![0; dec.output_buffer_size()];
        let info = dec.next_frame(&mut buf).unwrap();
        assert_eq!((info.width, info.height), (3, 2));
        assert_eq!(&buf[..info.buffer_size()], &m.data[..]);
        assert_eq!(m.flipped().flipped(), m);
    }
}
