//! Drawing stick figures into panels with tiny-skia: colours, the figure itself (bones sorted
//! back to front, joints as dots), the floor with ticks every 0.5 m, the 1 m scale bar and the
//! left/right key. Shared by the pose picture, the filmstrip and the animation.

use ab_glyph::FontRef;
use glam::DVec3;
use tiny_skia::{Color, FillRule, LineCap, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use super::RenderError;
use super::camera::Camera;
use super::figure::{Side, Track};
use super::text::{Align, Pen, draw_text, text_width};

/// Page background.
pub(crate) const WHITE: [u8; 3] = [255, 255, 255];
/// Text and joint dots.
pub(crate) const INK: [u8; 3] = [30, 30, 30];
/// Bones of the figure's left (Okabe–Ito blue).
pub(crate) const LEFT: [u8; 3] = [0, 114, 178];
/// Bones of the figure's right (Okabe–Ito vermillion).
pub(crate) const RIGHT: [u8; 3] = [213, 94, 0];
/// Bones on the mid-line.
pub(crate) const CENTRE: [u8; 3] = [85, 85, 85];
/// Floor line and ticks.
pub(crate) const FLOOR: [u8; 3] = [120, 120, 120];
/// Ground below the floor line.
pub(crate) const GROUND: [u8; 3] = [236, 236, 236];
/// Panel frame.
pub(crate) const FRAME: [u8; 3] = [200, 200, 200];

/// Every colour drawn; anti-aliasing mixes each of them with white (the GIF palette is built
/// from these ramps).
pub(crate) const INKS: [[u8; 3]; 7] = [INK, LEFT, RIGHT, CENTRE, FLOOR, GROUND, FRAME];

/// The colour of a bone ending at a point on `side`.
pub(crate) fn side_colour(side: Side) -> [u8; 3] {
    match side {
        Side::Left => LEFT,
        Side::Right => RIGHT,
        Side::Centre => CENTRE,
    }
}

fn colour(c: [u8; 3]) -> Color {
    Color::from_rgba8(c[0], c[1], c[2], 255)
}

fn paint(c: [u8; 3]) -> Paint<'static> {
    let mut p = Paint::default();
    p.set_color(colour(c));
    p.anti_alias = true;
    p
}

/// A new pixmap filled with `fill`.
pub(crate) fn new_pixmap(width: u32, height: u32, fill: [u8; 3]) -> Result<Pixmap, RenderError> {
    let mut p = Pixmap::new(width, height).ok_or_else(|| {
        RenderError::InvalidArgument(format!("cannot make a {width}×{height} pixel image"))
    })?;
    p.fill(colour(fill));
    Ok(p)
}

/// Largest picture side (pixels).
pub(crate) const MAX_SIDE: u64 = 32_000;

/// Checks a picture size computed in u64 (so that no sum overflows) against [`MAX_SIDE`].
pub(crate) fn sheet_size(width: u64, height: u64) -> Result<(u32, u32), RenderError> {
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(RenderError::InvalidArgument(format!(
            "the picture would be {width}×{height} pixels; at most {MAX_SIDE} a side"
        )));
    }
    Ok((width as u32, height as u32))
}

/// Line widths and text sizes for a panel `height` pixels high (about 1/120 of it for bones).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Style {
    pub bone: f32,
    pub dot: f32,
    pub text: f32,
    pub small: f32,
}

impl Style {
    pub fn for_height(height: u32) -> Style {
        let h = height as f32;
        let bone = (h / 110.0).clamp(1.5, 5.0);
        Style {
            bone,
            dot: bone * 0.95,
            text: (h / 20.0).clamp(13.0, 20.0),
            small: (h / 26.0).clamp(11.0, 16.0),
        }
    }
}

/// Clips segment a–b to the rectangle [lo.0, hi.0] × [lo.1, hi.1] (Liang–Barsky: with
/// p(t) = a + t(b − a), keep the t ∈ [0, 1] where every bound holds). `None` if nothing is left
/// or a coordinate is not finite. Keeps far-off points from reaching the rasteriser.
pub(crate) fn clip_segment(
    a: (f32, f32),
    b: (f32, f32),
    lo: (f32, f32),
    hi: (f32, f32),
) -> Option<((f32, f32), (f32, f32))> {
    if ![a.0, a.1, b.0, b.1].iter().all(|v| v.is_finite()) {
        return None;
    }
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let (mut t0, mut t1) = (0.0f32, 1.0f32);
    for (p, q) in [
        (-dx, a.0 - lo.0),
        (dx, hi.0 - a.0),
        (-dy, a.1 - lo.1),
        (dy, hi.1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let r = q / p;
            if p < 0.0 {
                t0 = t0.max(r);
            } else {
                t1 = t1.min(r);
            }
        }
    }
    (t0 <= t1).then_some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// Strokes segment a–b, clipped to the pixmap grown by a 16-pixel border.
fn line(pixmap: &mut Pixmap, a: (f32, f32), b: (f32, f32), width: f32, c: [u8; 3]) {
    let (w, h) = (pixmap.width() as f32, pixmap.height() as f32);
    let Some((a, b)) = clip_segment(a, b, (-16.0, -16.0), (w + 16.0, h + 16.0)) else {
        return;
    };
    let mut pb = PathBuilder::new();
    pb.move_to(a.0, a.1);
    pb.line_to(b.0, b.1);
    if let Some(path) = pb.finish() {
        let stroke = Stroke {
            width,
            line_cap: LineCap::Round,
            ..Stroke::default()
        };
        pixmap.stroke_path(&path, &paint(c), &stroke, Transform::identity(), None);
    }
}

fn rect(pixmap: &mut Pixmap, x: f32, y: f32, w: f32, h: f32, c: [u8; 3]) {
    if let Some(r) = Rect::from_xywh(x, y, w, h) {
        pixmap.fill_rect(r, &paint(c), Transform::identity(), None);
    }
}

/// Fills a disc of radius `r` at `at`, if it is on the pixmap.
fn dot(pixmap: &mut Pixmap, at: (f32, f32), r: f32, c: [u8; 3]) {
    let (w, h) = (pixmap.width() as f32, pixmap.height() as f32);
    if !(at.0 > -r && at.1 > -r && at.0 < w + r && at.1 < h + r) {
        return;
    }
    if let Some(path) = PathBuilder::from_circle(at.0, at.1, r) {
        pixmap.fill_path(
            &path,
            &paint(c),
            FillRule::Winding,
            Transform::identity(),
            None,
        );
    }
}

/// The unchanging part of a panel: white, the ground below y = 0 in light grey, a thin frame,
/// and, if `caption`, the view's name in the top-left corner.
pub(crate) fn panel_background(
    cam: &Camera,
    font: &FontRef,
    style: Style,
    caption: bool,
) -> Result<Pixmap, RenderError> {
    let mut p = new_pixmap(cam.width, cam.height, WHITE)?;
    let (w, h) = (cam.width as f32, cam.height as f32);
    if cam.view.shows_floor() {
        let (_, y0) = cam.pixel(cam.centre, glam::DVec2::ZERO);
        rect(&mut p, 0.0, y0, w, h - y0, GROUND);
        line(&mut p, (0.0, y0), (w, y0), 1.5, FLOOR);
    }
    if caption {
        let s = style.small;
        draw_text(
            &mut p,
            font,
            cam.view.caption(),
            (6.0, 4.0 + s),
            Pen {
                size: s,
                rgb: FLOOR,
                align: Align::Left,
            },
        );
    }
    frame(&mut p, w, h);
    Ok(p)
}

fn frame(p: &mut Pixmap, w: f32, h: f32) {
    rect(p, 0.0, 0.0, w, 1.0, FRAME);
    rect(p, 0.0, h - 1.0, w, 1.0, FRAME);
    rect(p, 0.0, 0.0, 1.0, h, FRAME);
    rect(p, w - 1.0, 0.0, 1.0, h, FRAME);
}

/// Draws frame `k` of `track` into a panel that already holds its background: floor ticks every
/// 0.5 m (they move when the camera follows the root), then the bones from the farthest to the
/// nearest (painter's order by the depth of their midpoints, so near limbs cover far ones),
/// then the joints as dots. `sides` is `track.figure.sides()`, computed once per track.
pub(crate) fn draw_figure(
    p: &mut Pixmap,
    cam: &Camera,
    track: &Track,
    sides: &[Side],
    k: usize,
    style: Style,
) {
    let pts = &track.frames[k];
    let fig = track.figure;
    let centre = cam.centre_for(pts[fig.root()]);
    let px = |q: DVec3| cam.pixel(centre, cam.view.project(q));
    if cam.view.shows_floor() {
        floor_ticks(p, cam, centre);
    } else {
        floor_grid(p, cam, centre);
    }
    let proxy = ground_proxy(fig, pts);
    let mut bones: Vec<(f64, usize, usize)> = fig
        .parents
        .iter()
        .enumerate()
        .filter(|(_, par)| par.is_none() || **par != proxy)
        .filter_map(|(i, par)| par.map(|j| (cam.view.depth((pts[i] + pts[j]) * 0.5), j, i)))
        .collect();
    bones.sort_by(|a, b| a.0.total_cmp(&b.0));
    for &(_, j, i) in &bones {
        line(p, px(pts[j]), px(pts[i]), style.bone, side_colour(sides[i]));
    }
    for (i, &q) in pts.iter().enumerate() {
        if Some(i) != proxy {
            dot(p, px(q), style.dot, INK);
        }
    }
    frame(p, cam.width as f32, cam.height as f32);
}

/// The root when it is a ground proxy, not a part of the body (as Bandai's `joint_Root` on the
/// floor under `Hips`): a root with one child, lower than a tenth of the figure's height above
/// its lowest point and farther from that child than a quarter of the height. Its bone would
/// be drawn as a third leg, so it is not drawn.
pub(crate) fn ground_proxy(fig: &super::figure::Figure, pts: &[DVec3]) -> Option<usize> {
    let root = fig.root();
    let mut children = fig
        .parents
        .iter()
        .enumerate()
        .filter(|(_, par)| **par == Some(root));
    let (child, _) = children.next()?;
    if children.next().is_some() {
        return None;
    }
    let lo = pts.iter().map(|q| q.y).fold(f64::INFINITY, f64::min);
    let hi = pts.iter().map(|q| q.y).fold(f64::NEG_INFINITY, f64::max);
    let h = hi - lo;
    (h > 0.0 && pts[root].y - lo < 0.1 * h && (pts[child] - pts[root]).length() > 0.25 * h)
        .then_some(root)
}

fn floor_ticks(p: &mut Pixmap, cam: &Camera, centre: glam::DVec2) {
    let (_, y0) = cam.pixel(centre, glam::DVec2::ZERO);
    let half = cam.width as f64 * 0.5 * cam.mpp;
    let step = 0.5;
    let first = ((centre.x - half) / step).floor() as i64;
    let last = ((centre.x + half) / step).ceil() as i64;
    for m in first..=last {
        let (x, _) = cam.pixel(centre, glam::DVec2::new(m as f64 * step, 0.0));
        line(p, (x, y0), (x, y0 + 5.0), 1.0, FLOOR);
    }
}

/// Seen from above, the floor as a light grid of 0.5 m squares (it moves when the camera
/// follows the root).
fn floor_grid(p: &mut Pixmap, cam: &Camera, centre: glam::DVec2) {
    let step = 0.5;
    let (w, h) = (cam.width as f32, cam.height as f32);
    for axis in 0..2 {
        let half = [cam.width, cam.height][axis] as f64 * 0.5 * cam.mpp;
        let first = ((centre[axis] - half) / step).floor() as i64;
        let last = ((centre[axis] + half) / step).ceil() as i64;
        for m in first..=last {
            let mut q = centre;
            q[axis] = m as f64 * step;
            let (x, y) = cam.pixel(centre, q);
            if axis == 0 {
                line(p, (x, 0.0), (x, h), 1.0, FRAME);
            } else {
                line(p, (0.0, y), (w, y), 1.0, FRAME);
            }
        }
    }
}

/// Copies `src` into `dst` with its top-left corner at (`x`, `y`), clipped to `dst`.
pub(crate) fn blit(dst: &mut Pixmap, src: &Pixmap, x: u32, y: u32) {
    let (dw, dh) = (dst.width(), dst.height());
    if x >= dw || y >= dh {
        return;
    }
    let w = src.width().min(dw - x) as usize;
    let rows = src.height().min(dh - y) as usize;
    let sw = src.width() as usize;
    let sp = src.pixels();
    let dp = dst.pixels_mut();
    for r in 0..rows {
        let d0 = (y as usize + r) * dw as usize + x as usize;
        dp[d0..d0 + w].copy_from_slice(&sp[r * sw..r * sw + w]);
    }
}

/// The longest of 1, 0.5, 0.2, 0.1, … m whose bar is at most `max_px` pixels at `mpp` metres
/// per pixel (1 m for any human-sized picture).
pub(crate) fn scale_length(mpp: f64, max_px: f64) -> f64 {
    let mut len = 1.0;
    let steps = [0.5, 0.4, 0.5];
    let mut i = 0;
    while len / mpp > max_px && len > 1e-6 {
        len *= steps[i % 3];
        i += 1;
    }
    len
}

/// "1 m", "50 cm", …: the text beside a scale bar of `len` metres.
fn scale_label(len: f64) -> String {
    if len >= 1.0 {
        format!("{len} m")
    } else {
        format!("{} cm", (len * 100.0).round())
    }
}

/// Draws the footer key at (`x`, `y` = baseline): a scale bar of [`scale_length`] with its
/// length written beside it, then the left/right colour key. Returns the width used.
pub(crate) fn draw_key(
    p: &mut Pixmap,
    font: &FontRef,
    x: f32,
    y: f32,
    mpp: f64,
    max_bar_px: f64,
    style: Style,
) -> f32 {
    let s = style.small;
    let len = scale_length(mpp, max_bar_px);
    let bar = (len / mpp) as f32;
    let yb = y - s * 0.35;
    line(p, (x, yb), (x + bar, yb), 2.0, INK);
    line(p, (x, yb - 4.0), (x, yb + 4.0), 1.5, INK);
    line(p, (x + bar, yb - 4.0), (x + bar, yb + 4.0), 1.5, INK);
    let label = scale_label(len);
    let mut cx = x + bar + 8.0;
    draw_text(
        p,
        font,
        &label,
        (cx, y),
        Pen {
            size: s,
            rgb: INK,
            align: Align::Left,
        },
    );
    cx += text_width(font, &label, s) + 24.0;
    for (name, c) in [("left", LEFT), ("right", RIGHT)] {
        line(p, (cx, yb), (cx + 24.0, yb), style.bone.max(2.5), c);
        cx += 30.0;
        draw_text(
            p,
            font,
            name,
            (cx, y),
            Pen {
                size: s,
                rgb: INK,
                align: Align::Left,
            },
        );
        cx += text_width(font, name, s) + 18.0;
    }
    cx - x
}

/// Width in pixels that [`draw_key`] uses with the same arguments.
pub(crate) fn key_width(font: &FontRef, mpp: f64, max_bar_px: f64, style: Style) -> f32 {
    let s = style.small;
    let len = scale_length(mpp, max_bar_px);
    let label = scale_label(len);
    let mut w = (len / mpp) as f32 + 8.0 + text_width(font, &label, s) + 24.0;
    for name in ["left", "right"] {
        w += 30.0 + text_width(font, name, s) + 18.0;
    }
    w
}

/// Encodes a pixmap as PNG bytes.
pub(crate) fn encode_png(p: &Pixmap) -> Result<Vec<u8>, RenderError> {
    p.encode_png()
        .map_err(|e| RenderError::Encode(format!("PNG: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_root_on_the_floor_under_the_hips_is_a_ground_proxy_and_a_pelvis_root_is_not() {
        // root (on the floor) → hips 0.9 m up → two legs down to the floor, a spine up.
        let names = [
            "root", "hips", "l_knee", "l_foot", "r_knee", "r_foot", "head",
        ];
        let fig = super::super::figure::Figure {
            names: names.iter().map(|s| s.to_string()).collect(),
            parents: vec![None, Some(0), Some(1), Some(2), Some(1), Some(4), Some(1)],
        };
        let y = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let pts = [
            y(0.0, 0.0),
            y(0.0, 0.9),
            y(0.1, 0.45),
            y(0.1, 0.0),
            y(-0.1, 0.45),
            y(-0.1, 0.0),
            y(0.0, 1.7),
        ];
        assert_eq!(ground_proxy(&fig, &pts), Some(0));
        // The same body without the floor root: the hips are the root, with three children.
        let body = super::super::figure::Figure {
            names: fig.names[1..].to_vec(),
            parents: vec![None, Some(0), Some(1), Some(0), Some(3), Some(0)],
        };
        assert_eq!(ground_proxy(&body, &pts[1..]), None);
    }

    #[test]
    fn scale_bar_is_one_metre_when_it_fits_and_a_round_fraction_otherwise() {
        assert_eq!(scale_length(0.01, 200.0), 1.0);
        assert_eq!(scale_length(0.01, 60.0), 0.5);
        assert_eq!(scale_length(0.01, 45.0), 0.2);
        assert_eq!(scale_length(0.01, 15.0), 0.1);
    }

    #[test]
    fn segments_are_clipped_to_the_rectangle() {
        let (lo, hi) = ((0.0, 0.0), (10.0, 10.0));
        // Inside: unchanged.
        assert_eq!(
            clip_segment((1.0, 1.0), (9.0, 5.0), lo, hi),
            Some(((1.0, 1.0), (9.0, 5.0)))
        );
        // Crossing: cut at x = 10.
        let ((_, _), (x, y)) = clip_segment((5.0, 5.0), (1e14, 5.0), lo, hi).unwrap();
        assert!((x - 10.0).abs() < 1e-3 && (y - 5.0).abs() < 1e-3);
        // Outside or not finite: nothing.
        assert_eq!(clip_segment((20.0, 0.0), (30.0, 5.0), lo, hi), None);
        assert_eq!(clip_segment((1.0, 1.0), (f32::INFINITY, 5.0), lo, hi), None);
    }

    #[test]
    fn blit_copies_and_clips() {
        let mut dst = new_pixmap(10, 10, WHITE).unwrap();
        let src = new_pixmap(4, 4, INK).unwrap();
        blit(&mut dst, &src, 8, 1);
        let dark = |x: u32, y: u32| dst.pixel(x, y).unwrap().red() == INK[0];
        assert!(dark(8, 1) && dark(9, 4));
        assert!(!dark(7, 1) && !dark(8, 5) && !dark(8, 0));
    }
}
