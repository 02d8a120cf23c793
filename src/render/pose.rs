//! One pose: the front, the side and the three-quarter view of a frame, side by side, in one
//! PNG, the body drawn as volumes.

use std::path::Path;

use ab_glyph::FontRef;
use tiny_skia::Pixmap;

use super::camera::{Camera, Eye, PanelLimits, View, scale_for};
use super::canvas::{
    INK, Style, WHITE, blit, draw_body, draw_key, encode_png, key_width, new_pixmap,
    panel_background, sheet_size,
};
use super::figure::Track;
use super::text::{Align, Pen, ascent, draw_text, font};
use super::volume::Volumes;
use super::{RenderError, require_extension, write};

/// Height of each view (pixels).
const PANEL_HEIGHT: u32 = 360;
/// Outer margin and gap between panels (pixels).
const MARGIN: u32 = 16;
const GAP: u32 = 12;

/// Draws frame `frame` of `track` as a PNG at `path`: the front view (the figure's left on the
/// viewer's right), its left side view and the three-quarter view chosen from the motion
/// ([`super::camera::three_quarter`]), side by side at the same scale, framed on the whole
/// track so pictures of different frames line up; header with the track label, frame index and
/// time t = frame · frame_time (s); footer with a 1 m scale bar and the left/right colour key.
pub fn pose_png(track: &Track, frame: usize, path: &Path) -> Result<(), RenderError> {
    require_extension(path, "png")?;
    track.validate()?;
    if frame >= track.frames.len() {
        return Err(RenderError::FrameOutOfRange {
            track: track.label.clone(),
            frame,
            len: track.frames.len(),
        });
    }
    let turned = super::facing::turned_frames(std::slice::from_ref(track));
    let turned_tracks = super::facing::with_frames(std::slice::from_ref(track), &turned);
    let track = &turned_tracks[0];
    let font = font()?;
    let (cams, mpp) = pose_cameras(track);
    let style = Style::for_height(PANEL_HEIGHT);

    let header = (style.text * 2.0) as u32;
    let footer = (style.small * 2.6) as u32;
    // Panels are at most MAX_PANEL wide, so these sums stay far below u32::MAX.
    let panels_w = cams.iter().map(|c| c.width).sum::<u32>() + 2 * GAP;
    let key_w = key_width(font, mpp, panels_w as f64 * 0.6, style, None) as u32;
    let width = 2 * MARGIN + panels_w.max(key_w);
    let height = MARGIN + header + PANEL_HEIGHT + footer + MARGIN / 2;
    sheet_size(width as u64, height as u64)?;
    let mut sheet = new_pixmap(width, height, WHITE)?;

    draw_header(&mut sheet, font, style, track, frame);

    let body = Volumes::of(track);
    let mut x = MARGIN + (width - 2 * MARGIN - panels_w) / 2;
    let y = MARGIN + header;
    for cam in &cams {
        let mut panel = panel_background(cam, font, style, true)?;
        draw_body(&mut panel, cam, track, &body, frame, style);
        blit(&mut sheet, &panel, x, y);
        x += cam.width + GAP;
    }
    let key_base = (y + PANEL_HEIGHT) as f32 + style.small * 1.9;
    draw_key(
        &mut sheet,
        font,
        MARGIN as f32,
        key_base,
        mpp,
        panels_w as f64 * 0.6,
        style,
        None,
    );
    write(path, &encode_png(&sheet)?)
}

/// The front, side and three-quarter cameras on `track`, at one scale (metres per pixel, also
/// returned): the one that fits the tallest.
fn pose_cameras(track: &Track) -> ([Camera; 3], f64) {
    let tracks = std::slice::from_ref(track);
    let eyes = [
        Eye::fixed(View::Front),
        Eye::fixed(View::Side),
        Eye::for_view(View::ThreeQuarter, tracks),
    ];
    // One scale for the three: the one that fits the tallest.
    let (mpp, pad) = eyes
        .iter()
        .map(|e| scale_for(tracks, e, PANEL_HEIGHT))
        .fold((0.0, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    let limits = PanelLimits {
        height: PANEL_HEIGHT,
        min_width: PANEL_HEIGHT * 11 / 20,
        max_width: PANEL_HEIGHT * 2,
    };
    (eyes.map(|e| Camera::fit(tracks, e, mpp, pad, limits)), mpp)
}

/// The header of the sheet: the track's label on the left, the frame and its time on the
/// right.
fn draw_header(sheet: &mut Pixmap, font: &FontRef, style: Style, track: &Track, frame: usize) {
    let base = MARGIN as f32 + ascent(font, style.text);
    draw_text(
        sheet,
        font,
        &track.label,
        (MARGIN as f32, base),
        Pen {
            size: style.text,
            rgb: INK,
            align: Align::Left,
        },
    );
    let when = format!(
        "frame {frame}   t = {:.2} s",
        frame as f64 * track.frame_time
    );
    let right = (sheet.width() - MARGIN) as f32;
    draw_text(
        sheet,
        font,
        &when,
        (right, base),
        Pen {
            size: style.small,
            rgb: INK,
            align: Align::Right,
        },
    );
}
