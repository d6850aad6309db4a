//! Plot text for bitmap backends, typeset with each glyph's own metrics.
//!
//! plotters' `ab_glyph` text drawing puts every glyph's bitmap at the pen position, ignoring
//! the glyph's left side bearing, so narrow glyphs drift against their neighbours ("-80.0"
//! reads "-80. 0", "twill.json, theta_i" reads "twill json. theta_j"). [`Typeset`] wraps a
//! backend and draws text itself with the bundled DejaVu Sans: the pen advances by each
//! glyph's advance width plus kerning, each outline is placed at its own bounds on a common
//! baseline, and its coverage is blended into the text colour. Everything else is passed
//! through to the wrapped backend.

use ab_glyph::{point, Font, FontRef, GlyphId, PxScale, ScaleFont};
use plotters_backend::text_anchor::{HPos, VPos};
use plotters_backend::{
    BackendColor, BackendCoord, BackendStyle, BackendTextStyle, DrawingBackend, DrawingErrorKind,
};

/// A drawing backend whose text is typeset with the glyphs' metrics (see the module).
pub struct Typeset<B> {
    inner: B,
    font: FontRef<'static>,
}

/// The laid-out glyphs of one line: (glyph, pen x), the width, ascent and descent in pixels.
struct Line {
    glyphs: Vec<(GlyphId, f32)>,
    width: f32,
    ascent: f32,
    descent: f32,
}

impl<B: DrawingBackend> Typeset<B> {
    /// Wraps `inner`.
    pub fn new(inner: B) -> Self {
        Typeset {
            inner,
            // The bundled DejaVu Sans is a valid TrueType font.
            font: FontRef::try_from_slice(dejavu::sans::regular())
                .expect("the bundled font parses"),
        }
    }

    /// Whether the font has a glyph for every character of `text`.
    pub fn covers(&self, text: &str) -> bool {
        text.chars().all(|c| self.font.glyph_id(c).0 != 0)
    }

    fn layout(&self, size: f64, text: &str) -> Line {
        let sf = self.font.as_scaled(PxScale::from(size as f32));
        let (mut pen, mut prev, mut glyphs) = (0.0f32, None, Vec::with_capacity(text.len()));
        for c in text.chars() {
            let id = sf.glyph_id(c);
            if let Some(p) = prev {
                pen += sf.kern(p, id);
            }
            glyphs.push((id, pen));
            pen += sf.h_advance(id);
            prev = Some(id);
        }
        Line {
            glyphs,
            width: pen,
            ascent: sf.ascent(),
            descent: sf.descent(),
        }
    }
}

impl<B: DrawingBackend> DrawingBackend for Typeset<B> {
    type ErrorType = B::ErrorType;

    fn get_size(&self) -> (u32, u32) {
        self.inner.get_size()
    }

    fn ensure_prepared(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.ensure_prepared()
    }

    fn present(&mut self) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.present()
    }

    fn draw_pixel(
        &mut self,
        point: BackendCoord,
        color: BackendColor,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_pixel(point, color)
    }

    fn draw_line<S: BackendStyle>(
        &mut self,
        from: BackendCoord,
        to: BackendCoord,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_line(from, to, style)
    }

    fn draw_rect<S: BackendStyle>(
        &mut self,
        upper_left: BackendCoord,
        bottom_right: BackendCoord,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_rect(upper_left, bottom_right, style, fill)
    }

    fn draw_path<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        path: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_path(path, style)
    }

    fn draw_circle<S: BackendStyle>(
        &mut self,
        center: BackendCoord,
        radius: u32,
        style: &S,
        fill: bool,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.draw_circle(center, radius, style, fill)
    }

    fn fill_polygon<S: BackendStyle, I: IntoIterator<Item = BackendCoord>>(
        &mut self,
        vert: I,
        style: &S,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.fill_polygon(vert, style)
    }

    fn blit_bitmap(
        &mut self,
        pos: BackendCoord,
        size: (u32, u32),
        src: &[u8],
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        self.inner.blit_bitmap(pos, size, src)
    }

    fn estimate_text_size<TStyle: BackendTextStyle>(
        &self,
        text: &str,
        style: &TStyle,
    ) -> Result<(u32, u32), DrawingErrorKind<Self::ErrorType>> {
        let l = self.layout(style.size(), text);
        Ok((l.width.ceil() as u32, (l.ascent - l.descent).ceil() as u32))
    }

    fn draw_text<TStyle: BackendTextStyle>(
        &mut self,
        text: &str,
        style: &TStyle,
        pos: BackendCoord,
    ) -> Result<(), DrawingErrorKind<Self::ErrorType>> {
        let color = style.color();
        if color.alpha == 0.0 {
            return Ok(());
        }
        let l = self.layout(style.size(), text);
        let height = l.ascent - l.descent;
        let dx = match style.anchor().h_pos {
            HPos::Left => 0.0,
            HPos::Right => -l.width,
            HPos::Center => -l.width / 2.0,
        };
        let dy = match style.anchor().v_pos {
            VPos::Top => 0.0,
            VPos::Center => -height / 2.0,
            VPos::Bottom => -height,
        };
        let trans = style.transform();
        let (w, h) = self.inner.get_size();
        let scale = PxScale::from(style.size() as f32);
        let mut pixels = Vec::new();
        for &(id, x) in &l.glyphs {
            let glyph = id.with_scale_and_position(scale, point(dx + x, dy + l.ascent));
            let Some(outline) = self.font.outline_glyph(glyph) else {
                continue; // a space
            };
            let b = outline.px_bounds();
            outline.draw(|gx, gy, coverage| {
                if coverage > 0.0 {
                    let (x, y) = (b.min.x as i32 + gx as i32, b.min.y as i32 + gy as i32);
                    pixels.push((trans.transform(x, y), coverage));
                }
            });
        }
        for ((x, y), coverage) in pixels {
            let (x, y) = (pos.0 + x, pos.1 + y);
            if x >= 0 && y >= 0 && (x as u32) < w && (y as u32) < h {
                let c = BackendColor {
                    alpha: color.alpha * f64::from(coverage.min(1.0)),
                    rgb: color.rgb,
                };
                self.inner.draw_pixel((x, y), c)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use plotters::prelude::*;

    /// The ink columns of `text` typeset at 20 px: for each column of the image, any pixel
    /// darker than mid-grey.
    fn ink(text: &str) -> Vec<bool> {
        let (w, h) = (200u32, 40u32);
        let mut buf = vec![255u8; (w * h * 3) as usize];
        {
            let root =
                Typeset::new(BitMapBackend::with_buffer(&mut buf, (w, h))).into_drawing_area();
            root.draw(&Text::new(text, (10, 8), ("sans-serif", 20).into_font()))
                .unwrap();
            root.present().unwrap();
        }
        (0..w as usize)
            .map(|x| (0..h as usize).any(|y| buf[(y * w as usize + x) * 3] < 128))
            .collect()
    }

    /// Runs of ink and of gaps: (is ink, length), from the first ink column to the last.
    fn runs(cols: &[bool]) -> Vec<(bool, usize)> {
        let first = cols.iter().position(|&c| c).unwrap();
        let last = cols.iter().rposition(|&c| c).unwrap();
        let mut out: Vec<(bool, usize)> = Vec::new();
        for &c in &cols[first..=last] {
            match out.last_mut() {
                Some((k, n)) if *k == c => *n += 1,
                _ => out.push((c, 1)),
            }
        }
        out
    }

    #[test]
    fn a_full_stop_sits_in_the_middle_of_its_advance() {
        crate::plot::tests_register_font();
        // "0.0": ink 0, gap, ink ., gap, ink 0. DejaVu's full stop has equal side bearings,
        // so the gaps either side of it are equal to a pixel (plotters' own drawing puts the
        // dot at the left of its advance: "0. 0").
        let r = runs(&ink("0.0"));
        assert_eq!(r.len(), 5, "{r:?}");
        let (left, right) = (r[1].1 as i64, r[3].1 as i64);
        assert!((left - right).abs() <= 1, "{r:?}");
    }

    #[test]
    fn the_font_has_every_character_the_plots_use() {
        let mut buf = [0u8; 3];
        let t = Typeset::new(BitMapBackend::with_buffer(&mut buf, (1, 1)));
        assert!(t.covers("θφωᵢₒᵣ°−±|%()=,.:;+-_0123456789 fr/sr ABCDEFGHIJKLMNOPQRSTUVWXYZ abcdefghijklmnopqrstuvwxyz"));
    }
}
