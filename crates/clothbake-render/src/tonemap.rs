//! Tone mapping and image files.
//!
//! Display value of a linear pixel value V, per channel: `x = exposure * V`, then `clamp`
//! (x limited to [0, 1]) or `reinhard` (x / (1 + x)), then the sRGB transfer function
//! (IEC 61966-2-1: 12.92 x below 0.0031308, else 1.055 x^(1/2.4) - 0.055), rounded to 8 bits.
//! `exposure auto` is 1 / (the largest channel value in the image), so the brightest pixel
//! maps to 1 before the curve. EXR files hold the linear values V themselves (f32, no tone
//! mapping).

use clothbake_loader::{write_atomic_as, TableError};
use std::io::Write;
use std::path::Path;

/// The tone curve.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Curve {
    /// Clamp to [0, 1].
    #[default]
    Clamp,
    /// x / (1 + x).
    Reinhard,
}

/// A linear RGB image, rows from the top.
#[derive(Clone, Debug, PartialEq)]
pub struct Image {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height` pixels, row-major from the top-left.
    pub pixels: Vec<[f32; 3]>,
}

impl Image {
    /// The pixel at column `i`, row `j`.
    pub fn get(&self, i: u32, j: u32) -> [f32; 3] {
        self.pixels[(j * self.width + i) as usize]
    }

    /// The largest channel value (0 for an all-black image).
    pub fn max_value(&self) -> f32 {
        self.pixels
            .iter()
            .flat_map(|p| p.iter().copied())
            .fold(0.0, f32::max)
    }
}

/// The sRGB transfer function of a linear value in [0, 1].
pub fn srgb(x: f64) -> f64 {
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// The 8-bit display value of linear value `v` at `exposure` (see the module documentation).
pub fn display(v: f32, exposure: f64, curve: Curve) -> u8 {
    let x = (f64::from(v) * exposure).max(0.0);
    let x = match curve {
        Curve::Clamp => x.min(1.0),
        Curve::Reinhard => x / (1.0 + x),
    };
    (srgb(x) * 255.0).round().clamp(0.0, 255.0) as u8
}

/// The exposure of `auto`: 1 / the image's largest value (1 for a black image).
pub fn auto_exposure(img: &Image) -> f64 {
    let m = f64::from(img.max_value());
    if m > 0.0 && m.is_finite() {
        1.0 / m
    } else {
        1.0
    }
}

/// The tone-mapped 8-bit RGB bytes of `img`, row-major.
pub fn to_rgb8(img: &Image, exposure: f64, curve: Curve) -> Vec<u8> {
    img.pixels
        .iter()
        .flat_map(|p| p.map(|v| display(v, exposure, curve)))
        .collect()
}

/// Writes 8-bit RGB bytes as a PNG, atomically.
pub fn write_png_rgb8(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    overwrite: bool,
) -> Result<(), TableError> {
    write_atomic_as(path, "PNG image", overwrite, |w| {
        let mut enc = png::Encoder::new(w, width, height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        let mut wr = enc.write_header().map_err(std::io::Error::other)?;
        wr.write_image_data(rgb).map_err(std::io::Error::other)?;
        wr.finish().map_err(std::io::Error::other)
    })
}

/// Writes the linear values of `img` as an RGB f32 OpenEXR image, atomically.
pub fn write_exr(path: &Path, img: &Image, overwrite: bool) -> Result<(), TableError> {
    use exr::prelude::*;
    let (w, h) = (img.width as usize, img.height as usize);
    let layer = Layer::new(
        (w, h),
        LayerAttributes::named("rgb"),
        Encoding::FAST_LOSSLESS,
        SpecificChannels::rgb(|p: Vec2<usize>| {
            let v = img.pixels[p.y() * w + p.x()];
            (v[0], v[1], v[2])
        }),
    );
    let image = Image::from_layer(layer);
    write_atomic_as(path, "OpenEXR image", overwrite, |f| {
        image
            .write()
            .non_parallel()
            .to_buffered(&mut *f)
            .map_err(std::io::Error::other)?;
        f.flush()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_endpoints_and_continuity() {
        assert_eq!(srgb(0.0), 0.0);
        assert!((srgb(1.0) - 1.0).abs() < 1e-12);
        let e = 1e-9;
        assert!((srgb(0.0031308 - e) - srgb(0.0031308 + e)).abs() < 1e-6);
        // Middle grey 0.18 -> about 0.46 (118 of 255).
        assert_eq!(display(0.18, 1.0, Curve::Clamp), 118);
        assert_eq!(display(2.0, 1.0, Curve::Clamp), 255);
        assert_eq!(
            display(1.0, 1.0, Curve::Reinhard),
            display(0.5, 1.0, Curve::Clamp)
        );
        assert_eq!(display(-1.0, 1.0, Curve::Clamp), 0);
        assert_eq!(display(f32::NAN, 1.0, Curve::Clamp), 0);
    }
}
