//! Drawing bodies into panels with tiny-skia: colours, the body as shaded volumes sorted back
//! to front over its shadow, the floor (a line with ticks every 0.5 m seen edge-on, a patch
//! with a 0.5 m grid seen from above at an angle), the 1 m scale bar and the left/right key.
//! Shared by the pose picture, the filmstrip and the animation.

use ab_glyph::FontRef;
use glam::{DVec2, DVec3};
use tiny_skia::{Color, FillRule, LineCap, Paint, PathBuilder, Pixmap, Rect, Stroke, Transform};

use super::RenderError;
use super::camera::Camera;
use super::figure::{Side, Track};
use super::text::{Align, Pen, draw_text, text_width};
use super::volume::{Solid, Volumes};

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
/// Volumes on the mid-line (trunk, head), lit at full strength.
pub(crate) const TRUNK: [u8; 3] = [172, 172, 172];
/// Floor line and ticks.
pub(crate) const FLOOR: [u8; 3] = [120, 120, 120];
/// Ground below the floor line.
pub(crate) const GROUND: [u8; 3] = [236, 236, 236];
/// Panel frame.
pub(crate) const FRAME: [u8; 3] = [200, 200, 200];

/// Every colour drawn; anti-aliasing mixes each of them with white (the GIF palette is built
/// from these ramps).
pub(crate) const INKS: [[u8; 3]; 8] = [INK, LEFT, RIGHT, CENTRE, TRUNK, FLOOR, GROUND, FRAME];

/// The colour of a volume on `side` at full light.
pub(crate) fn side_colour(side: Side) -> [u8; 3] {
    match side {
        Side::Left => LEFT,
        Side::Right => RIGHT,
        Side::Centre => TRUNK,
    }
}

/// Light falling on the volumes: Lambert shading k = [`AMBIENT`] + [`DIFFUSE`]·max(0, n·l)
/// with n the surface normal and l the unit direction towards the light, from the viewer's
/// upper left: l ∝ −0.35·right + 0.8·up + 0.5·towards.
pub(crate) const AMBIENT: f64 = 0.5;
/// See [`AMBIENT`].
pub(crate) const DIFFUSE: f64 = 0.55;

/// `base` lit by `k`: darkened to k·base below 1, mixed towards white by k − 1 above.
pub(crate) fn shade(base: [u8; 3], k: f64) -> [u8; 3] {
    base.map(|c| {
        let c = c as f64;
        let v = if k <= 1.0 {
            c * k
        } else {
            c + (255.0 - c) * (k - 1.0)
        };
        v.round().clamp(0.0, 255.0) as u8
    })
}

/// Floor shadows: black at this opacity.
const SHADOW_ALPHA: u8 = 56;

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
    pub text: f32,
    pub small: f32,
}

impl Style {
    pub fn for_height(height: u32) -> Style {
        let h = height as f32;
        let bone = (h / 110.0).clamp(1.5, 5.0);
        Style {
            bone,
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
    if cam.eye.view.shows_floor() && !cam.eye.sees_floor_plane() {
        let (_, y0) = cam.pixel(cam.centre, glam::DVec2::ZERO);
        rect(&mut p, 0.0, y0, w, h - y0, GROUND);
        line(&mut p, (0.0, y0), (w, y0), 1.5, FLOOR);
    }
    if caption {
        let s = style.small;
        draw_text(
            &mut p,
            font,
            &cam.eye.caption(),
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

/// Draws frame `k` of `track` into a panel that already holds its background: the floor (ticks
/// every 0.5 m on the edge-on line, a grid of 0.5 m squares on the patch of a three-quarter
/// view; they move when the camera follows the root), the body's shadow (every volume
/// projected straight down onto y = 0, one union at [`SHADOW_ALPHA`]), then the volumes of
/// `body` from the farthest to the nearest (painter's order by the depth of their centres, so
/// near limbs cover far ones), each shaded by its surface normal against the light
/// ([`AMBIENT`]).
pub(crate) fn draw_body(
    p: &mut Pixmap,
    cam: &Camera,
    track: &Track,
    body: &Volumes,
    k: usize,
    style: Style,
) {
    let pts = &track.frames[k];
    let centre = cam.centre_for(pts[track.figure.root()]);
    let eye = cam.eye;
    let px = |q: DVec3| cam.pixel(centre, eye.project(q));
    if eye.sees_floor_plane() {
        floor_patch(p, cam, centre);
    } else if eye.view.shows_floor() {
        floor_ticks(p, cam, centre);
    } else {
        floor_grid(p, cam, centre);
    }
    let mut solids = body.solids(pts);
    if eye.view.shows_floor() {
        shadow(p, &solids, &px);
    }
    solids.sort_by(|a, b| eye.depth(a.0.centre()).total_cmp(&eye.depth(b.0.centre())));
    let light = (-0.35 * eye.right + 0.8 * eye.up + 0.5 * eye.towards).normalize();
    let lit = |n: DVec3| AMBIENT + DIFFUSE * n.dot(light).max(0.0);
    for (solid, side) in &solids {
        let base = side_colour(*side);
        match *solid {
            Solid::Cuboid { centre: c, axes } => {
                for (a, &axis) in axes.iter().enumerate() {
                    let n = axis.normalize_or_zero();
                    for sign in [1.0, -1.0] {
                        if sign * n.dot(eye.towards) <= 1e-9 {
                            continue;
                        }
                        let (u, v) = (axes[(a + 1) % 3], axes[(a + 2) % 3]);
                        let f = c + axis * sign;
                        let quad = [f + u + v, f + u - v, f - u - v, f - u + v].map(px);
                        let colour = shade(base, lit(n * sign));
                        polygon(p, &quad, colour);
                        outline(p, &quad, shade(base, 0.45), style.bone * 0.2);
                    }
                }
            }
            Solid::Capsule { a, b, radius } => {
                capsule(p, (px(a), px(b)), (a, b), radius, cam, light, base);
            }
        }
    }
    frame(p, cam.width as f32, cam.height as f32);
}

/// Layers of a capsule's shading, from the rim to the highlight.
const CAPSULE_LAYERS: usize = 4;

/// A capsule seen orthographically: the stadium of radius `radius` (m) around its projected
/// axis `ends` (pixels), shaded in [`CAPSULE_LAYERS`] nested stadiums that shrink towards the
/// brightest point (where the normal is the light's direction across the axis): the layer at
/// a fraction f of the radius gets k = [`AMBIENT`] + [`DIFFUSE`]·peak·√(1 − f²), the normal
/// there turned by asin f from the brightest one, peak the light's part across the axis.
fn capsule(
    p: &mut Pixmap,
    ends: ((f32, f32), (f32, f32)),
    axis: (DVec3, DVec3),
    radius: f64,
    cam: &Camera,
    light: DVec3,
    base: [u8; 3],
) {
    let eye = cam.eye;
    let u = (axis.1 - axis.0).normalize_or_zero();
    let across = (light - u * light.dot(u)).normalize_or_zero();
    let peak = light.dot(across).max(0.0);
    let r_px = (radius / cam.mpp) as f32;
    // Pixel offset from the axis to the brightest point (screen y points down).
    let off = (
        (across.dot(eye.right) * radius / cam.mpp) as f32,
        -(across.dot(eye.up) * radius / cam.mpp) as f32,
    );
    for i in 0..CAPSULE_LAYERS {
        let f = 1.0 - i as f32 / CAPSULE_LAYERS as f32;
        let shift = ((1.0 - f) * off.0, (1.0 - f) * off.1);
        let (a, b) = (
            (ends.0.0 + shift.0, ends.0.1 + shift.1),
            (ends.1.0 + shift.0, ends.1.1 + shift.1),
        );
        let k = AMBIENT + DIFFUSE * peak * (1.0 - (f as f64).powi(2)).sqrt();
        polygon(p, &stadium(a, b, r_px * f), shade(base, k));
    }
}

/// The outline of a stadium (a segment a–b grown by `r`, pixels) as a polygon: a half circle
/// of 9 points round each end.
fn stadium(a: (f32, f32), b: (f32, f32), r: f32) -> Vec<(f32, f32)> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let len = (dx * dx + dy * dy).sqrt();
    let (ux, uy) = if len > 1e-3 {
        (dx / len, dy / len)
    } else {
        (1.0, 0.0)
    };
    let mut out = Vec::with_capacity(18);
    for (c, start) in [(b, -0.5f32), (a, 0.5f32)] {
        for j in 0..9 {
            let t = (start + j as f32 / 8.0) * std::f32::consts::PI;
            let (s, co) = t.sin_cos();
            // Round the end: along the axis by cos t, across it by sin t.
            out.push((c.0 + r * (co * ux - s * uy), c.1 + r * (co * uy + s * ux)));
        }
    }
    out
}

/// The shadow of `solids` on the floor: each projected straight down onto y = 0 (a box's
/// corners, a capsule's two end circles of 12 points), its convex hull in the picture, all
/// hulls filled as one union in black at [`SHADOW_ALPHA`].
fn shadow(p: &mut Pixmap, solids: &[(Solid, Side)], px: &dyn Fn(DVec3) -> (f32, f32)) {
    let mut pb = PathBuilder::new();
    let down = |q: DVec3| px(DVec3::new(q.x, 0.0, q.z));
    for (solid, _) in solids {
        let pts: Vec<(f32, f32)> = match *solid {
            Solid::Cuboid { centre, axes } => (0..8)
                .map(|c| {
                    let s = |bit: usize| if c >> bit & 1 == 1 { 1.0 } else { -1.0 };
                    down(centre + axes[0] * s(0) + axes[1] * s(1) + axes[2] * s(2))
                })
                .collect(),
            Solid::Capsule { a, b, radius } => [a, b]
                .iter()
                .flat_map(|&e| {
                    (0..12).map(move |j| {
                        let t = j as f64 * std::f64::consts::TAU / 12.0;
                        e + DVec3::new(t.cos(), 0.0, t.sin()) * radius
                    })
                })
                .map(down)
                .collect(),
        };
        push_polygon(&mut pb, p, &convex_hull(pts));
    }
    if let Some(path) = pb.finish() {
        fill(p, &path, [0, 0, 0], SHADOW_ALPHA);
    }
}

/// The convex hull of `pts` (Andrew's monotone chain), counter-clockwise in picture axes; all
/// hulls turn the same way, so filled together by the non-zero rule they make their union.
/// Points that are not finite are left out.
pub(crate) fn convex_hull(mut pts: Vec<(f32, f32)>) -> Vec<(f32, f32)> {
    pts.retain(|q| q.0.is_finite() && q.1.is_finite());
    pts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: (f32, f32), a: (f32, f32), b: (f32, f32)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f32, f32)> = Vec::with_capacity(2 * pts.len());
    for pass in 0..2 {
        let start = hull.len();
        let seq: Box<dyn Iterator<Item = &(f32, f32)>> = if pass == 0 {
            Box::new(pts.iter())
        } else {
            Box::new(pts.iter().rev())
        };
        for &q in seq {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// Fills `path` in `c` at opacity `alpha`.
fn fill(p: &mut Pixmap, path: &tiny_skia::Path, c: [u8; 3], alpha: u8) {
    let mut paint = paint(c);
    paint.set_color_rgba8(c[0], c[1], c[2], alpha);
    p.fill_path(path, &paint, FillRule::Winding, Transform::identity(), None);
}

/// The closed path through `pts` (pixels), `None` when [`push_polygon`] adds nothing.
fn polygon_path(p: &Pixmap, pts: &[(f32, f32)]) -> Option<tiny_skia::Path> {
    let mut pb = PathBuilder::new();
    push_polygon(&mut pb, p, pts);
    pb.finish()
}

/// Fills the polygon `pts` (pixels) in `c`.
fn polygon(p: &mut Pixmap, pts: &[(f32, f32)], c: [u8; 3]) {
    if let Some(path) = polygon_path(p, pts) {
        fill(p, &path, c, 255);
    }
}

/// Strokes the closed outline of `pts` in `c`, `width` pixels wide.
fn outline(p: &mut Pixmap, pts: &[(f32, f32)], c: [u8; 3], width: f32) {
    let Some(path) = polygon_path(p, pts) else {
        return;
    };
    let stroke = Stroke {
        width,
        ..Stroke::default()
    };
    p.stroke_path(&path, &paint(c), &stroke, Transform::identity(), None);
}

/// Adds the closed polygon `pts` (pixels) to `pb`, unless it has fewer than 3 points, a point
/// that is not finite, or lies wholly off `p`. Far points are clamped to a border 10⁴ pixels
/// out, so the rasteriser never sees huge numbers.
fn push_polygon(pb: &mut PathBuilder, p: &Pixmap, pts: &[(f32, f32)]) {
    if pts.len() < 3 || !pts.iter().all(|q| q.0.is_finite() && q.1.is_finite()) {
        return;
    }
    let (w, h) = (p.width() as f32, p.height() as f32);
    let (x0, x1) = pts
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), q| {
            (a.min(q.0), b.max(q.0))
        });
    let (y0, y1) = pts
        .iter()
        .fold((f32::INFINITY, f32::NEG_INFINITY), |(a, b), q| {
            (a.min(q.1), b.max(q.1))
        });
    if x1 < 0.0 || y1 < 0.0 || x0 > w || y0 > h {
        return;
    }
    let far = 1e4;
    let clamp = |q: &(f32, f32)| (q.0.clamp(-far, w + far), q.1.clamp(-far, h + far));
    let first = clamp(&pts[0]);
    pb.move_to(first.0, first.1);
    for q in &pts[1..] {
        let q = clamp(q);
        pb.line_to(q.0, q.1);
    }
    pb.close();
}

/// Seen from above at an angle, the floor as a light patch with a grid of 0.5 m squares and a
/// darker border: the patch covers the motion's floor area ([`Camera::floor`]), and only the
/// part the panel sees is drawn, so a far-flung point costs nothing.
fn floor_patch(p: &mut Pixmap, cam: &Camera, centre: DVec2) {
    let eye = cam.eye;
    // The floor point under a view-plane point q: solve (x, z) from q = (P·right, P·up), y = 0.
    let (r, u) = (eye.right, eye.up);
    let det = r.x * u.z - r.z * u.x;
    if det.abs() < 1e-9 {
        return;
    }
    let on_floor =
        |q: DVec2| DVec2::new((q.x * u.z - r.z * q.y) / det, (r.x * q.y - q.x * u.x) / det);
    let half = DVec2::new(cam.width as f64, cam.height as f64) * 0.5 * cam.mpp;
    let corners = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .map(|(a, b)| on_floor(centre + DVec2::new(a * half.x, b * half.y)));
    let seen_lo = corners.iter().fold(DVec2::INFINITY, |a, c| a.min(*c));
    let seen_hi = corners.iter().fold(DVec2::NEG_INFINITY, |a, c| a.max(*c));
    let lo = cam.floor.0.max(seen_lo);
    let hi = cam.floor.1.min(seen_hi);
    if !(lo.x < hi.x && lo.y < hi.y) {
        return;
    }
    let px = |x: f64, z: f64| cam.pixel(centre, eye.project(DVec3::new(x, 0.0, z)));
    let quad = [
        px(lo.x, lo.y),
        px(hi.x, lo.y),
        px(hi.x, hi.y),
        px(lo.x, hi.y),
    ];
    polygon(p, &quad, GROUND);
    // 0.5 m squares, doubled until at most 100 lines cross the patch each way.
    let step = grid_step((hi - lo).max_element());
    for axis in 0..2 {
        let first = (lo[axis] / step).ceil() as i64;
        let last = (hi[axis] / step).floor() as i64;
        for m in first..=last {
            let v = m as f64 * step;
            let (a, b) = if axis == 0 {
                (px(v, lo.y), px(v, hi.y))
            } else {
                (px(lo.x, v), px(hi.x, v))
            };
            line(p, a, b, 1.0, FRAME);
        }
    }
    // The border, on the sides that are the patch's own edges (not where the panel cut it).
    let own = [
        lo.y == cam.floor.0.y,
        hi.x == cam.floor.1.x,
        hi.y == cam.floor.1.y,
        lo.x == cam.floor.0.x,
    ];
    for (i, _) in own.iter().enumerate().filter(|(_, o)| **o) {
        line(p, quad[i], quad[(i + 1) % 4], 1.5, FLOOR);
    }
}

/// The floor's grid spacing over `span` metres: 0.5 m, doubled until at most 100 lines cross
/// it (so a panel framed on a far-flung point draws a hundred lines, not billions).
fn grid_step(span: f64) -> f64 {
    let mut step = 0.5;
    while span / step > 100.0 && step.is_finite() {
        step *= 2.0;
    }
    step
}

/// Seen edge-on, ticks on the floor line every 0.5 m (coarser when the panel spans more than
/// 50 m).
fn floor_ticks(p: &mut Pixmap, cam: &Camera, centre: glam::DVec2) {
    let (_, y0) = cam.pixel(centre, glam::DVec2::ZERO);
    let half = cam.width as f64 * 0.5 * cam.mpp;
    let step = grid_step(2.0 * half);
    let first = ((centre.x - half) / step).floor() as i64;
    let last = ((centre.x + half) / step).ceil() as i64;
    for m in first..=last {
        let (x, _) = cam.pixel(centre, glam::DVec2::new(m as f64 * step, 0.0));
        line(p, (x, y0), (x, y0 + 5.0), 1.0, FLOOR);
    }
}

/// Seen from above, the floor as a light grid of 0.5 m squares (it moves when the camera
/// follows the root; coarser when the panel spans more than 50 m).
fn floor_grid(p: &mut Pixmap, cam: &Camera, centre: glam::DVec2) {
    let step = grid_step([cam.width, cam.height].into_iter().max().unwrap_or(0) as f64 * cam.mpp);
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
/// length written beside it, then the left/right colour key and, if given, `view` (the
/// caption of the one view every panel shares) in grey. Returns the width used.
#[allow(clippy::too_many_arguments)]
pub(crate) fn draw_key(
    p: &mut Pixmap,
    font: &FontRef,
    x: f32,
    y: f32,
    mpp: f64,
    max_bar_px: f64,
    style: Style,
    view: Option<&str>,
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
    if let Some(view) = view {
        cx += 12.0;
        draw_text(
            p,
            font,
            view,
            (cx, y),
            Pen {
                size: s,
                rgb: FLOOR,
                align: Align::Left,
            },
        );
        cx += text_width(font, view, s);
    }
    cx - x
}

/// Width in pixels that [`draw_key`] uses with the same arguments.
pub(crate) fn key_width(
    font: &FontRef,
    mpp: f64,
    max_bar_px: f64,
    style: Style,
    view: Option<&str>,
) -> f32 {
    let s = style.small;
    let len = scale_length(mpp, max_bar_px);
    let label = scale_label(len);
    let mut w = (len / mpp) as f32 + 8.0 + text_width(font, &label, s) + 24.0;
    for name in ["left", "right"] {
        w += 30.0 + text_width(font, name, s) + 18.0;
    }
    if let Some(view) = view {
        w += 12.0 + text_width(font, view, s);
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
    use crate::render::camera::{Eye, PanelLimits, View, scale_for};
    use crate::render::figure::StickFigure;
    use crate::render::volume::Shape;

    /// Hips with two straight legs (hip, knee, foot), feet `stance` m either side, 0.95 m tall.
    fn legs(stance: f64) -> (StickFigure, Vec<DVec3>) {
        let fig = StickFigure {
            names: [
                "Hips",
                "LeftUpLeg",
                "LeftLeg",
                "LeftFoot",
                "RightUpLeg",
                "RightLeg",
                "RightFoot",
            ]
            .map(String::from)
            .to_vec(),
            parents: vec![None, Some(0), Some(1), Some(2), Some(0), Some(4), Some(5)],
        };
        let p = |x: f64, y: f64| DVec3::new(x, y, 0.0);
        let pts = vec![
            p(0.0, 0.95),
            p(0.1, 0.9),
            p(stance, 0.48),
            p(stance, 0.0),
            p(-0.1, 0.9),
            p(-stance, 0.48),
            p(-stance, 0.0),
        ];
        (fig, pts)
    }

    /// Draws one frame of `track` in `eye`, 300 pixels high: the panel and its camera.
    fn draw(track: &Track, eye: Eye) -> (Pixmap, Camera) {
        let tracks = std::slice::from_ref(track);
        let (mpp, pad) = scale_for(tracks, &eye, 300);
        let limits = PanelLimits {
            height: 300,
            min_width: 300,
            max_width: 600,
        };
        let cam = Camera::fit(tracks, eye, mpp, pad, limits);
        let mut p = new_pixmap(cam.width, cam.height, WHITE).unwrap();
        let style = Style::for_height(300);
        draw_body(&mut p, &cam, track, &Volumes::of(track), 0, style);
        (p, cam)
    }

    /// Whether a pixel is in the left (blue) or right (vermillion) limb colour, at any shade.
    fn hue(c: tiny_skia::PremultipliedColorU8) -> Side {
        let (r, g, b) = (c.red() as i32, c.green() as i32, c.blue() as i32);
        if b > r + 50 && b > g {
            Side::Left
        } else if r > b + 80 && r > g + 40 {
            Side::Right
        } else {
            Side::Centre
        }
    }

    #[test]
    fn the_floor_grid_is_half_a_metre_until_a_hundred_lines_would_cross_it() {
        assert_eq!(grid_step(3.0), 0.5);
        assert_eq!(grid_step(50.0), 0.5);
        assert_eq!(grid_step(50.1), 1.0);
        // A panel framed on a point a billion kilometres away: about a hundred lines.
        let step = grid_step(4e12);
        assert!(4e12 / step <= 100.0 && 4e12 / step > 50.0, "{step}");
    }

    #[test]
    fn the_view_is_named_in_the_key_after_the_colours() {
        let font = crate::render::text::font().unwrap();
        let style = Style::for_height(400);
        let (mpp, bar) = (0.005, 300.0);
        let caption = "three-quarter, 60° left";
        let plain = key_width(font, mpp, bar, style, None);
        let with = key_width(font, mpp, bar, style, Some(caption));
        assert!(with > plain + 12.0 + 50.0, "{plain} → {with}");
        let inked = |view: Option<&str>| {
            let mut p = new_pixmap(with as u32 + 40, 40, WHITE).unwrap();
            let used = draw_key(&mut p, font, 10.0, 30.0, mpp, bar, style, view);
            let xs: Vec<u32> = (0..p.width())
                .filter(|&x| (0..p.height()).any(|y| p.pixel(x, y).unwrap().red() < 200))
                .collect();
            (used, *xs.last().unwrap())
        };
        let (used_plain, last_plain) = inked(None);
        let (used_with, last_with) = inked(Some(caption));
        assert!((used_plain - plain).abs() < 0.5 && (used_with - with).abs() < 0.5);
        // Without a view nothing is inked past the colour key; with one, its text is.
        assert!(
            last_plain as f32 <= 10.0 + plain + 1.0,
            "{last_plain} vs {plain}"
        );
        assert!(
            last_with as f32 > 10.0 + plain + 12.0,
            "{last_with} vs {plain}"
        );
        assert!(
            last_with as f32 <= 10.0 + with + 1.0,
            "{last_with} vs {with}"
        );
    }

    #[test]
    fn a_figure_standing_still_touches_the_floor_where_its_contact_projects() {
        let (fig, mut pts) = legs(0.15);
        let frames = vec![pts.clone()];
        let t = Track {
            figure: &fig,
            frames: &frames,
            label: String::new(),
            frame_time: 0.1,
        };
        // Lift the body so that the shins' capsules rest on the floor.
        let r = Volumes::of(&t)
            .shapes
            .iter()
            .find_map(|(s, _)| match *s {
                Shape::Capsule { to: 3, radius, .. } => Some(radius),
                _ => None,
            })
            .unwrap();
        for q in &mut pts {
            q.y += r;
        }
        let frames = vec![pts.clone()];
        let t = Track {
            frames: &frames,
            ..t
        };
        let eye = Eye::for_view(View::ThreeQuarter, std::slice::from_ref(&t));
        let (p, cam) = draw(&t, eye);
        let lowest = (0..p.height())
            .rev()
            .find(|&y| (0..p.width()).any(|x| hue(p.pixel(x, y).unwrap()) != Side::Centre))
            .unwrap() as f64;
        // The contact under each foot: the nearest point of the floor circle it touches.
        let centre = cam.centre_for(pts[0]);
        let contact = [3, 6]
            .iter()
            .map(|&i| {
                let q = DVec3::new(pts[i].x, 0.0, pts[i].z);
                cam.pixel(centre, eye.project(q)).1 as f64
            })
            .fold(f64::NEG_INFINITY, f64::max);
        // A resting sphere's outline reaches r(1 − cos ε) below its contact (about a pixel
        // here), anti-aliasing one more.
        assert!(
            (lowest - contact).abs() <= 2.0,
            "lowest body pixel at row {lowest}, contact projects to row {contact}"
        );
    }

    #[test]
    fn left_limbs_are_drawn_in_the_left_colour_and_right_limbs_in_the_right() {
        let (fig, pts) = legs(0.35);
        let frames = vec![pts.clone()];
        let t = Track {
            figure: &fig,
            frames: &frames,
            label: String::new(),
            frame_time: 0.1,
        };
        for view in [View::Front, View::ThreeQuarter] {
            let eye = Eye::for_view(view, std::slice::from_ref(&t));
            let (p, cam) = draw(&t, eye);
            let centre = cam.centre_for(pts[0]);
            for (knee, want) in [(2, Side::Left), (5, Side::Right)] {
                let (x, y) = cam.pixel(centre, eye.project(pts[knee]));
                let c = p.pixel(x as u32, y as u32).unwrap();
                assert_eq!(hue(c), want, "{view:?}: knee {knee} drawn in {c:?}");
            }
        }
    }

    #[test]
    fn a_nearer_volume_covers_a_farther_one_whatever_their_order() {
        // Two arms crossing in front of the viewer: one 0.5 m nearer than the other.
        let fig = StickFigure {
            names: ["Chest", "LeftHand", "RightHand"]
                .map(String::from)
                .to_vec(),
            parents: vec![None, Some(0), Some(0)],
        };
        for (left_z, want) in [(0.5, Side::Left), (-0.5, Side::Right)] {
            let frames = vec![vec![
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 1.4, left_z),
                DVec3::new(0.0, 1.4, -left_z),
            ]];
            let t = Track {
                figure: &fig,
                frames: &frames,
                label: String::new(),
                frame_time: 0.1,
            };
            // Seen from the front, both hands project onto the same pixel.
            let eye = Eye::fixed(View::Front);
            let (p, cam) = draw(&t, eye);
            let centre = cam.centre_for(frames[0][0]);
            let (x, y) = cam.pixel(centre, eye.project(frames[0][1]));
            let c = p.pixel(x as u32, y as u32).unwrap();
            assert_eq!(hue(c), want, "left hand at z = {left_z}: {c:?}");
        }
    }

    #[test]
    fn the_hull_of_points_is_convex_and_counter_clockwise() {
        let pts = vec![
            (0.0, 0.0),
            (2.0, 0.0),
            (1.0, 1.0),
            (2.0, 2.0),
            (0.0, 2.0),
            (1.0, 0.5),
        ];
        let hull = convex_hull(pts);
        assert_eq!(hull.len(), 4, "{hull:?}");
        assert!(!hull.contains(&(1.0, 1.0)) && !hull.contains(&(1.0, 0.5)));
        // Shoelace area: positive for counter-clockwise in (x, y).
        let area: f32 = (0..hull.len())
            .map(|i| {
                let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
                a.0 * b.1 - b.0 * a.1
            })
            .sum();
        assert!((area - 8.0).abs() < 1e-6, "{area}");
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
