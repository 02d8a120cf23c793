//! Text in pictures with the bundled DejaVu Sans font (`fonts/DejaVuSans.ttf`, licence in
//! `fonts/LICENSE-DejaVu.txt`), so that no system font library (fontconfig, freetype) is needed.
//! Glyphs are rasterised by `ab_glyph` and blended into a tiny-skia pixmap; the same font is
//! registered with plotters for [`super::plot`].

use std::sync::OnceLock;

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use tiny_skia::{Pixmap, PremultipliedColorU8};

use super::RenderError;

/// The bundled font file (DejaVu Sans, Bitstream Vera licence).
pub static FONT_TTF: &[u8] = include_bytes!("fonts/DejaVuSans.ttf");

/// The parsed bundled font.
pub(crate) fn font() -> Result<&'static FontRef<'static>, RenderError> {
    static FONT: OnceLock<Option<FontRef<'static>>> = OnceLock::new();
    FONT.get_or_init(|| FontRef::try_from_slice(FONT_TTF).ok())
        .as_ref()
        .ok_or_else(|| RenderError::Font("the bundled DejaVu Sans could not be parsed".into()))
}

/// Registers the bundled font with plotters as its `sans-serif` family (once per process).
pub(crate) fn register_plot_font() -> Result<(), RenderError> {
    static DONE: OnceLock<bool> = OnceLock::new();
    let ok = *DONE.get_or_init(|| {
        plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, FONT_TTF)
            .is_ok()
    });
    if ok {
        Ok(())
    } else {
        Err(RenderError::Font(
            "plotters rejected the bundled DejaVu Sans".into(),
        ))
    }
}

/// Horizontal placement of a text relative to its anchor x.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Align {
    Left,
    Centre,
    Right,
}

/// Width in pixels of `text` set at `size` pixels (the font's ascent − descent), kerning included.
pub(crate) fn text_width(font: &FontRef, text: &str, size: f32) -> f32 {
    let f = font.as_scaled(PxScale::from(size));
    let mut w = 0.0;
    let mut prev = None;
    for c in text.chars() {
        let id = f.glyph_id(c);
        if let Some(p) = prev {
            w += f.kern(p, id);
        }
        w += f.h_advance(id);
        prev = Some(id);
    }
    w
}

/// Ascent of the font at `size` pixels: how far capitals reach above the baseline, roughly.
pub(crate) fn ascent(font: &FontRef, size: f32) -> f32 {
    font.as_scaled(PxScale::from(size)).ascent()
}

/// How a text is set: size in pixels (the font's ascent − descent), opaque colour, alignment.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pen {
    pub size: f32,
    pub rgb: [u8; 3],
    pub align: Align,
}

/// Draws `text` with its baseline at `at.1` and its left edge, centre or right edge (as
/// `pen.align` says) at `at.0`, blending glyph coverage a into each pixel:
/// dst = (1 − a)·dst + a·rgb.
pub(crate) fn draw_text(pixmap: &mut Pixmap, font: &FontRef, text: &str, at: (f32, f32), pen: Pen) {
    let Pen { size, rgb, align } = pen;
    let (x, y) = at;
    let scale = PxScale::from(size);
    let f = font.as_scaled(scale);
    let w = text_width(font, text, size);
    let mut pen = match align {
        Align::Left => x,
        Align::Centre => x - w * 0.5,
        Align::Right => x - w,
    };
    let (pw, ph) = (pixmap.width() as i64, pixmap.height() as i64);
    let pixels = pixmap.pixels_mut();
    let mut prev = None;
    for c in text.chars() {
        let id = f.glyph_id(c);
        if let Some(p) = prev {
            pen += f.kern(p, id);
        }
        prev = Some(id);
        let glyph = id.with_scale_and_position(scale, point(pen, y));
        pen += f.h_advance(id);
        let Some(outline) = font.outline_glyph(glyph) else {
            continue;
        };
        let b = outline.px_bounds();
        let (x0, y0) = (b.min.x as i64, b.min.y as i64);
        outline.draw(|gx, gy, cov| {
            let (px, py) = (x0 + gx as i64, y0 + gy as i64);
            if px < 0 || py < 0 || px >= pw || py >= ph {
                return;
            }
            let a = cov.clamp(0.0, 1.0);
            let i = (py * pw + px) as usize;
            let d = pixels[i];
            let mix = |dc: u8, sc: u8| (dc as f32 * (1.0 - a) + sc as f32 * a).round() as u8;
            if let Some(p) = PremultipliedColorU8::from_rgba(
                mix(d.red(), rgb[0]),
                mix(d.green(), rgb[1]),
                mix(d.blue(), rgb[2]),
                255,
            ) {
                pixels[i] = p;
            }
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use tiny_skia::Color;

    #[test]
    fn text_is_drawn_where_asked_and_widths_grow_with_text() {
        let font = font().unwrap();
        assert!(text_width(font, "mm", 20.0) > text_width(font, "m", 20.0));
        let mut p = Pixmap::new(200, 50).unwrap();
        p.fill(Color::WHITE);
        draw_text(
            &mut p,
            font,
            "Hello",
            (100.0, 35.0),
            Pen {
                size: 24.0,
                rgb: [0, 0, 0],
                align: Align::Centre,
            },
        );
        let mut xs = Vec::new();
        for (i, px) in p.pixels().iter().enumerate() {
            if px.red() < 128 {
                xs.push((i % 200) as f32);
                assert!((i / 200) <= 36, "ink below the baseline in 'Hello'");
            }
        }
        assert!(!xs.is_empty());
        let mean = xs.iter().sum::<f32>() / xs.len() as f32;
        assert!(
            (mean - 100.0).abs() < 12.0,
            "centred text has mean x {mean}"
        );
    }

    #[test]
    fn plotters_accepts_the_bundled_font() {
        register_plot_font().unwrap();
    }
}
