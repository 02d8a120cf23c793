//! A looping GIF of one or more motions side by side (each in the three-quarter view chosen
//! from the motions, its body as shaded volumes), subsampled to a chosen frame rate and
//! quantised to a small fixed palette.
//!
//! The drawing uses few colours ([`super::canvas::INKS`]) on white, anti-aliasing mixes each
//! of them with white and shading darkens the limbs' colours, so the palette is the 16-step
//! ramp from white to every ink and an 8-step ramp from each limb colour down to
//! [`super::canvas::AMBIENT`] of it. A 32×32×32
//! lookup table maps 5-bit-per-channel RGB to the nearest palette entry once; each pixel then
//! costs one table look-up. Frames are drawn and quantised in parallel (rayon), in chunks; each
//! frame after the first stores only the rectangle that changed, unchanged pixels in it
//! transparent (so most of the page is encoded once); the rectangles are LZW-compressed in
//! parallel and written in order.

use std::borrow::Cow;
use std::path::Path;
use std::sync::OnceLock;

use ab_glyph::FontRef;
use rayon::prelude::*;
use tiny_skia::Pixmap;

use super::camera::{Camera, Eye, PanelLimits, View, scale_for};
use super::canvas::{
    AMBIENT, INK, INKS, LEFT, RIGHT, Style, WHITE, blit, draw_body, draw_key, key_width,
    new_pixmap, panel_background, shade, sheet_size,
};
use super::figure::{Track, validate_tracks};
use super::text::{Align, Pen, ascent, draw_text, font};
use super::volume::Volumes;
use super::{RenderError, require_extension, write};

/// Height of each view (pixels).
const PANEL_HEIGHT: u32 = 320;
const MARGIN: u32 = 12;
/// Gap between tracks (pixels).
const TRACK_GAP: u32 = 24;
/// Steps of each white-to-ink ramp in the palette.
const LEVELS: usize = 16;
/// Steps of each shaded limb colour's ramp in the palette.
const DARK_LEVELS: usize = 8;
/// Most frames in one GIF (an hour at 25 frames per second).
pub const MAX_GIF_FRAMES: usize = 90_000;
/// Frames drawn and compressed per parallel batch (bounds memory).
const CHUNK: usize = 48;
/// The highest frame rate: GIF delays are whole hundredths of a second and viewers slow down
/// delays under 0.02 s.
pub const MAX_GIF_FPS: f64 = 50.0;

/// The fixed palette as RGB triples: for each ink c and level l = 0 … 15 the mix
/// white + (c − white) · l/15; then for each limb colour c and level l = 1 … 8 the shade
/// c · (1 − (1 − AMBIENT) · l/8).
fn palette() -> Vec<[u8; 3]> {
    let mut p = Vec::with_capacity(PALETTE_SIZE);
    for c in INKS {
        for l in 0..LEVELS {
            let a = l as f32 / (LEVELS - 1) as f32;
            p.push(c.map(|ch| (255.0 + (ch as f32 - 255.0) * a).round() as u8));
        }
    }
    for c in [LEFT, RIGHT] {
        for l in 1..=DARK_LEVELS {
            p.push(shade(
                c,
                1.0 - (1.0 - AMBIENT) * l as f64 / DARK_LEVELS as f64,
            ));
        }
    }
    p
}

/// Colours in [`palette`].
const PALETTE_SIZE: usize = INKS.len() * LEVELS + 2 * DARK_LEVELS;

/// Nearest palette entry (squared RGB distance) for every 5-bit-per-channel colour, indexed by
/// (r >> 3) << 10 | (g >> 3) << 5 | (b >> 3).
fn lookup() -> &'static [u8] {
    static LUT: OnceLock<Vec<u8>> = OnceLock::new();
    LUT.get_or_init(|| {
        let pal = palette();
        (0..32 * 32 * 32u32)
            .map(|key| {
                // The 5-bit value v stands for 8-bit (v << 3) | (v >> 2): 0 → 0, 31 → 255.
                let rgb =
                    [key >> 10, (key >> 5) & 31, key & 31].map(|v| ((v << 3) | (v >> 2)) as i32);
                let mut best = (i32::MAX, 0u8);
                for (i, p) in pal.iter().enumerate() {
                    let d: i32 = (0..3).map(|c| (rgb[c] - p[c] as i32).pow(2)).sum();
                    if d < best.0 {
                        best = (d, i as u8);
                    }
                }
                best.1
            })
            .collect()
    })
}

/// Palette index of an opaque pixel (premultiplied = straight colour when alpha is 255).
fn index(c: tiny_skia::PremultipliedColorU8, lut: &[u8]) -> u8 {
    lut[((c.red() as usize >> 3) << 10)
        | ((c.green() as usize >> 3) << 5)
        | (c.blue() as usize >> 3)]
}

/// Writes the palette indices of `src` into the `stride`-wide index image `dst` with the
/// top-left corner at (`x`, `y`); `src` must lie inside `dst`.
fn quantise_into(dst: &mut [u8], stride: usize, src: &Pixmap, x: u32, y: u32, lut: &[u8]) {
    let w = src.width() as usize;
    for (r, row) in src.pixels().chunks_exact(w).enumerate() {
        let d0 = (y as usize + r) * stride + x as usize;
        for (d, &c) in dst[d0..d0 + w].iter_mut().zip(row) {
            *d = index(c, lut);
        }
    }
}

/// Delay of GIF frame `k` at `fps` in hundredths of a second, rounded so that the delays add
/// up to the true elapsed time: round(100(k+1)/fps) − round(100k/fps).
fn delay(k: usize, fps: f64) -> u16 {
    let at = |k: usize| (100.0 * k as f64 / fps).round();
    (at(k + 1) - at(k)).clamp(1.0, u16::MAX as f64) as u16
}

/// Writes a looping GIF of `tracks` at `path`: each track in the three-quarter view chosen from
/// all the tracks' motion ([`super::camera::three_quarter`], after each is turned to face +Z),
/// drawn as volumes over its shadow ([`super::volume`]), its label above, all tracks in one
/// row at one scale and one framing of the whole motion.
/// GIF frame k shows time t = k/fps (header "t = … s"), each track at its nearest frame (held
/// after its end), for k = 0 … ⌊T·fps⌋ with T the longest duration. `fps` must be in
/// (0, [`MAX_GIF_FPS`]]; 25 is a good choice.
pub fn animation_gif(tracks: &[Track], fps: f64, path: &Path) -> Result<(), RenderError> {
    require_extension(path, "gif")?;
    validate_tracks(tracks)?;
    if !(fps.is_finite() && fps > 0.0 && fps <= MAX_GIF_FPS) {
        return Err(RenderError::InvalidArgument(format!(
            "GIF frame rate must be in (0, {MAX_GIF_FPS}] frames per second, got {fps}"
        )));
    }
    let turned = super::facing::turned_frames(tracks);
    let turned_tracks = super::facing::with_frames(tracks, &turned);
    let tracks = &turned_tracks[..];
    let font = font()?;
    let eye = Eye::for_view(View::ThreeQuarter, tracks);
    let (mpp, pad) = scale_for(tracks, &eye, PANEL_HEIGHT);
    let limits = PanelLimits {
        height: PANEL_HEIGHT,
        min_width: PANEL_HEIGHT * 3 / 5,
        max_width: PANEL_HEIGHT * 8 / 5,
    };
    let cam = Camera::fit(tracks, eye, mpp, pad, limits);
    let style = Style::for_height(PANEL_HEIGHT);
    let page = Page::draw(tracks, &cam, font, style, mpp)?;
    let (width, panel_y) = (page.width, page.panel_y);

    let duration = tracks.iter().map(Track::duration).fold(0.0, f64::max);
    let steps = (duration * fps + 1e-9).floor();
    if steps >= MAX_GIF_FRAMES as f64 {
        return Err(RenderError::InvalidArgument(format!(
            "{duration} s at {fps} frames per second is more than {MAX_GIF_FRAMES} GIF frames"
        )));
    }
    let frames = steps as usize + 1;
    let bodies: Vec<Volumes> = tracks.iter().map(Volumes::of).collect();
    let lut = lookup();
    let time_base = MARGIN as f32 + ascent(font, style.text);
    let mut still = vec![0u8; (width * page.height) as usize];
    quantise_into(&mut still, width as usize, &page.sheet, 0, 0, lut);
    // The strip that holds the time label.
    let clock = tiny_skia::IntRect::from_xywh(0, 0, width, MARGIN + page.header)
        .and_then(|r| page.sheet.clone_rect(r))
        .ok_or_else(|| RenderError::Encode("empty GIF header".into()))?;

    // Frame k: the still page with the clock and the panels drawn over it, as palette indices.
    let render = |k: usize| -> Vec<u8> {
        let t = k as f64 / fps;
        let mut img = still.clone();
        let mut strip = clock.clone();
        let label = format!("t = {t:.2} s");
        let pen = Pen {
            size: style.text,
            rgb: INK,
            align: Align::Left,
        };
        draw_text(&mut strip, font, &label, (MARGIN as f32, time_base), pen);
        quantise_into(&mut img, width as usize, &strip, 0, 0, lut);
        for ((track, &origin), body) in tracks.iter().zip(&page.origins).zip(&bodies) {
            let mut panel = page.background.clone();
            draw_body(&mut panel, &cam, track, body, track.frame_at(t), style);
            quantise_into(&mut img, width as usize, &panel, origin, panel_y, lut);
        }
        img
    };
    let bytes = encode_gif(&page, frames, fps, render)?;
    write(path, &bytes)
}

/// The GIF's unchanging page: header row (the time), per track a label and an empty panel, the
/// key under them.
struct Page {
    /// The page drawn: labels, empty panels, key.
    sheet: Pixmap,
    /// Size (pixels).
    width: u32,
    height: u32,
    /// The size as GIF stores it.
    size16: (u16, u16),
    /// Height of the header row that holds the time (pixels).
    header: u32,
    /// Top of the panels (pixels).
    panel_y: u32,
    /// Left edge of each track's panel (pixels).
    origins: Vec<u32>,
    /// An empty panel (floor and shadow-free background).
    background: Pixmap,
}

impl Page {
    /// Lays out and draws the page for `tracks` seen by `cam` at `mpp` metres a pixel. Errors:
    /// a page too large (for the sheet, or over GIF's 65535 pixels a side).
    fn draw(
        tracks: &[Track],
        cam: &Camera,
        font: &FontRef,
        style: Style,
        mpp: f64,
    ) -> Result<Page, RenderError> {
        // Layout: header (time), then per track a label row and its panel, then the key.
        let header = (style.text * 1.8) as u32;
        let label_row = (style.text * 1.6) as u32;
        let footer = (style.small * 2.4) as u32;
        let block_w = cam.width;
        let n = tracks.len() as u64;
        let row = n * block_w as u64 + (n - 1) * TRACK_GAP as u64;
        let height = MARGIN + header + label_row + PANEL_HEIGHT + footer;
        sheet_size(row + 2 * MARGIN as u64, height as u64)?;
        let row_w = row as u32;
        let caption = cam.eye.caption();
        let key_w = key_width(font, mpp, row_w as f64 * 0.6, style, Some(&caption)) as u32;
        let width = 2 * MARGIN + row_w.max(key_w);
        let (Ok(w16), Ok(h16)) = (u16::try_from(width), u16::try_from(height)) else {
            return Err(RenderError::InvalidArgument(format!(
                "a {width}×{height} picture exceeds the GIF limit of 65535 pixels a side"
            )));
        };

        // The unchanging sheet: labels, empty panels, key.
        let mut sheet = new_pixmap(width, height, WHITE)?;
        let panel_y = MARGIN + header + label_row;
        let label_base = (MARGIN + header) as f32 + ascent(font, style.text);
        let mut origins = Vec::new();
        let background = panel_background(cam, font, style, false)?;
        for (i, track) in tracks.iter().enumerate() {
            let x = MARGIN + i as u32 * (block_w + TRACK_GAP);
            let lx = x as f32;
            draw_text(
                &mut sheet,
                font,
                &track.label,
                (lx, label_base),
                Pen {
                    size: style.text,
                    rgb: INK,
                    align: Align::Left,
                },
            );
            blit(&mut sheet, &background, x, panel_y);
            origins.push(x);
        }
        let key_base = (panel_y + PANEL_HEIGHT) as f32 + style.small * 1.7;
        draw_key(
            &mut sheet,
            font,
            MARGIN as f32,
            key_base,
            mpp,
            row_w as f64 * 0.6,
            style,
            Some(&caption),
        );
        Ok(Page {
            sheet,
            width,
            height,
            size16: (w16, h16),
            header,
            panel_y,
            origins,
            background,
        })
    }
}

/// The looping GIF of `frames` frames of `page`'s size, frame k drawn by `render` (palette
/// indices) and shown at time k/`fps`: drawn and LZW-compressed in parallel chunks, each frame
/// after the first only its changed part, an unchanged frame adding its delay to the one
/// before.
fn encode_gif(
    page: &Page,
    frames: usize,
    fps: f64,
    render: impl Fn(usize) -> Vec<u8> + Sync + Send,
) -> Result<Vec<u8>, RenderError> {
    let (w16, h16) = page.size16;
    let mut pal: Vec<u8> = palette().into_iter().flatten().collect();
    pal.extend([255, 255, 255]); // TRANSPARENT: never drawn, marks unchanged pixels
    let gif_err = |e: gif::EncodingError| RenderError::Encode(format!("GIF: {e}"));
    let mut encoder = gif::Encoder::new(Vec::new(), w16, h16, &pal).map_err(gif_err)?;
    encoder.set_repeat(gif::Repeat::Infinite).map_err(gif_err)?;
    let (w, h) = (page.width as usize, page.height as usize);
    let mut previous: Option<Vec<u8>> = None;
    // A frame waits until the next one is known: an unchanged next frame only adds its delay.
    let mut pending: Option<gif::Frame<'static>> = None;
    for start in (0..frames).step_by(CHUNK) {
        let end = (start + CHUNK).min(frames);
        let images: Vec<Vec<u8>> = (start..end).into_par_iter().map(&render).collect();
        let mut batch: Vec<Option<gif::Frame<'static>>> = Vec::with_capacity(images.len());
        for (i, img) in images.into_iter().enumerate() {
            let k = start + i;
            let frame = match &previous {
                None => Some(gif::Frame {
                    width: w16,
                    height: h16,
                    buffer: Cow::Owned(img.clone()),
                    ..gif::Frame::default()
                }),
                Some(prev) => changed_part(prev, &img, w, h),
            };
            batch.push(frame.map(|f| gif::Frame {
                delay: delay(k, fps),
                ..f
            }));
            previous = Some(img);
        }
        batch
            .par_iter_mut()
            .flatten()
            .for_each(|f| f.make_lzw_pre_encoded());
        for (i, frame) in batch.into_iter().enumerate() {
            match frame {
                Some(f) => {
                    if let Some(p) = pending.replace(f) {
                        encoder.write_lzw_pre_encoded_frame(&p).map_err(gif_err)?;
                    }
                }
                None => {
                    if let Some(p) = pending.as_mut() {
                        p.delay = p.delay.saturating_add(delay(start + i, fps));
                    }
                }
            }
        }
    }
    if let Some(p) = pending {
        encoder.write_lzw_pre_encoded_frame(&p).map_err(gif_err)?;
    }
    encoder.into_inner().map_err(gif_err)
}

/// Palette index that marks a pixel as unchanged from the previous frame.
const TRANSPARENT: u8 = PALETTE_SIZE as u8;

/// The part of `next` (w×h palette indices) that differs from `prev`, as a frame over the
/// bounding rectangle of the changed pixels, unchanged pixels inside it set to [`TRANSPARENT`]
/// (drawn over the previous frame, which stays); `None` when nothing changed.
fn changed_part(prev: &[u8], next: &[u8], w: usize, h: usize) -> Option<gif::Frame<'static>> {
    let (mut x0, mut y0, mut x1, mut y1) = (w, h, 0, 0);
    for y in 0..h {
        let (a, b) = (&prev[y * w..(y + 1) * w], &next[y * w..(y + 1) * w]);
        if a == b {
            continue;
        }
        let first = a.iter().zip(b).position(|(p, q)| p != q)?;
        let last = w
            - 1
            - a.iter()
                .rev()
                .zip(b.iter().rev())
                .position(|(p, q)| p != q)?;
        x0 = x0.min(first);
        x1 = x1.max(last);
        y0 = y0.min(y);
        y1 = y1.max(y);
    }
    if x0 > x1 {
        return None;
    }
    let mut buf = Vec::with_capacity((x1 - x0 + 1) * (y1 - y0 + 1));
    for y in y0..=y1 {
        for x in x0..=x1 {
            let (p, q) = (prev[y * w + x], next[y * w + x]);
            buf.push(if p == q { TRANSPARENT } else { q });
        }
    }
    Some(gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0 + 1) as u16,
        height: (y1 - y0 + 1) as u16,
        transparent: Some(TRANSPARENT),
        dispose: gif::DisposalMethod::Keep,
        buffer: Cow::Owned(buf),
        ..gif::Frame::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn palette_holds_every_ink_and_white_exactly() {
        let pal = palette();
        assert!(pal.len() <= 256);
        let lut = lookup();
        for c in INKS.iter().chain([&WHITE]) {
            let px = tiny_skia::PremultipliedColorU8::from_rgba(c[0], c[1], c[2], 255).unwrap();
            let idx = index(px, lut);
            let p = pal[idx as usize];
            let err: i32 = (0..3)
                .map(|i| (p[i] as i32 - c[i] as i32).abs())
                .max()
                .unwrap();
            assert!(err <= 8, "ink {c:?} maps to {p:?}");
            if *c == WHITE {
                assert_eq!(p, WHITE, "white background stays white");
            }
        }
    }

    #[test]
    fn only_the_changed_rectangle_is_stored_and_the_rest_is_transparent() {
        let (w, h) = (6, 4);
        let prev = vec![0u8; w * h];
        assert!(changed_part(&prev, &prev, w, h).is_none());
        let mut next = prev.clone();
        next[w + 2] = 5; // (2, 1)
        next[2 * w + 4] = 7; // (4, 2)
        let f = changed_part(&prev, &next, w, h).unwrap();
        assert_eq!((f.left, f.top, f.width, f.height), (2, 1, 3, 2));
        let t = TRANSPARENT;
        assert_eq!(f.buffer.as_ref(), &[5, t, t, t, t, 7]);
        assert_eq!(f.transparent, Some(TRANSPARENT));
        // Replaying the rectangle over the previous frame gives the next one.
        let mut replay = prev.clone();
        for y in 0..f.height as usize {
            for x in 0..f.width as usize {
                let i = f.buffer[y * f.width as usize + x];
                if i != TRANSPARENT {
                    replay[(y + f.top as usize) * w + x + f.left as usize] = i;
                }
            }
        }
        assert_eq!(replay, next);
    }

    #[test]
    fn delays_add_up_to_elapsed_time() {
        let total: u32 = (0..30).map(|k| delay(k, 30.0) as u32).sum();
        assert_eq!(total, 100);
        assert_eq!(delay(0, 25.0), 4);
    }
}
