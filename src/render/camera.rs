//! Orthographic views and camera framing: which world axes a view shows, how large a panel is,
//! and where a world point lands in it.
//!
//! The three-quarter view ([`View::ThreeQuarter`]) is chosen from the motion by
//! [`three_quarter`]: the rule is in its doc.
//!
//! Framing rule: one scale (metres per pixel) for every view of a picture, set by the vertical
//! extent of the whole motion (all frames, all tracks, and the floor y = 0); each panel is as
//! wide as the motion's horizontal extent, so figures do not jump. Only when a motion travels
//! further than the panel's maximum width does that axis *follow* the figure's root (floor ticks
//! every 0.5 m then show the travel); the panel is then just wide enough for the farthest any
//! point gets from the root.

use glam::{DVec2, DVec3};

use super::figure::Track;

/// An orthographic view of a figure (Y up, the figure faces +Z, its left is +X).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// Looking at the figure's front from +Z: screen right is +X (the figure's left appears on
    /// the viewer's right), screen up is +Y.
    Front,
    /// Looking at the figure's left side from +X: screen right is −Z (the figure faces the
    /// viewer's left), screen up is +Y.
    Side,
    /// Looking down from +Y: screen right is +X, screen up is −Z (the figure faces the viewer).
    Top,
    /// A three-quarter view from in front of the figure, to one side and a little above,
    /// chosen from the motion so that it reads (see [`three_quarter`]); alone ([`View::axes`])
    /// it is the default, 45° to the figure's left.
    ThreeQuarter,
}

impl View {
    /// The view's right-handed camera basis in world axes: (screen right, screen up, towards the
    /// viewer), with right × up = towards.
    pub fn axes(self) -> (DVec3, DVec3, DVec3) {
        match self {
            View::Front => (DVec3::X, DVec3::Y, DVec3::Z),
            View::Side => (DVec3::NEG_Z, DVec3::Y, DVec3::X),
            View::Top => (DVec3::X, DVec3::NEG_Z, DVec3::Y),
            View::ThreeQuarter => {
                let e = Eye::orbit(DEFAULT_AZIMUTH, ELEVATION);
                (e.right, e.up, e.towards)
            }
        }
    }

    /// Projects a world point onto the view plane: (p · right, p · up), metres.
    pub fn project(self, p: DVec3) -> DVec2 {
        let (r, u, _) = self.axes();
        DVec2::new(p.dot(r), p.dot(u))
    }

    /// Distance of a world point towards the viewer, p · towards (metres); larger is nearer.
    pub fn depth(self, p: DVec3) -> f64 {
        p.dot(self.axes().2)
    }

    /// Whether the view shows the floor y = 0 as a line.
    pub fn shows_floor(self) -> bool {
        !matches!(self, View::Top)
    }

    /// Caption of the view in pictures.
    pub fn caption(self) -> &'static str {
        match self {
            View::Front => "front",
            View::Side => "left side",
            View::Top => "top",
            View::ThreeQuarter => "three-quarter",
        }
    }
}

/// Elevation of the three-quarter view above the horizon (radians): 20°, high enough that the
/// floor, its grid and the shadow read, low enough that heights still do.
pub const ELEVATION: f64 = 20.0 * std::f64::consts::PI / 180.0;

/// Azimuth of the three-quarter view when the motion has no main direction (radians): 45° from
/// the figure's front towards its left.
const DEFAULT_AZIMUTH: f64 = std::f64::consts::FRAC_PI_4;

/// The three-quarter band: azimuths from 30° to 60° either side of the figure's front.
const BAND_DEG: (i32, i32) = (30, 60);

/// A camera's orthonormal basis in world axes (screen right, screen up, towards the viewer,
/// right × up = towards), with the view it came from and, for a three-quarter view, its
/// azimuth.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eye {
    /// The view.
    pub view: View,
    /// Screen right (unit, world).
    pub right: DVec3,
    /// Screen up (unit, world).
    pub up: DVec3,
    /// Towards the viewer (unit, world).
    pub towards: DVec3,
    /// Azimuth of a three-quarter view (radians, from the figure's front +Z towards its left
    /// +X about +Y); 0 for the other views.
    pub azimuth: f64,
}

impl Eye {
    /// The eye of a fixed view ([`View::axes`]).
    pub fn fixed(view: View) -> Eye {
        let (right, up, towards) = view.axes();
        Eye {
            view,
            right,
            up,
            towards,
            azimuth: if view == View::ThreeQuarter {
                DEFAULT_AZIMUTH
            } else {
                0.0
            },
        }
    }

    /// A three-quarter eye at `azimuth` φ (radians, from +Z towards +X about +Y) and
    /// `elevation` ε (radians above the horizon): towards = (sin φ cos ε, sin ε, cos φ cos ε),
    /// right = (cos φ, 0, −sin φ) (horizontal), up = towards × right.
    pub fn orbit(azimuth: f64, elevation: f64) -> Eye {
        let (sa, ca) = azimuth.sin_cos();
        let (se, ce) = elevation.sin_cos();
        let towards = DVec3::new(sa * ce, se, ca * ce);
        let right = DVec3::new(ca, 0.0, -sa);
        Eye {
            view: View::ThreeQuarter,
            right,
            up: towards.cross(right),
            towards,
            azimuth,
        }
    }

    /// The eye for `view` on `tracks`: [`three_quarter`] for [`View::ThreeQuarter`], the fixed
    /// axes otherwise.
    pub(crate) fn for_view(view: View, tracks: &[Track]) -> Eye {
        match view {
            View::ThreeQuarter => three_quarter(tracks),
            v => Eye::fixed(v),
        }
    }

    /// Projects a world point onto the view plane: (p · right, p · up), metres.
    pub fn project(&self, p: DVec3) -> DVec2 {
        DVec2::new(p.dot(self.right), p.dot(self.up))
    }

    /// Distance of a world point towards the viewer, p · towards (metres); larger is nearer.
    pub fn depth(&self, p: DVec3) -> f64 {
        p.dot(self.towards)
    }

    /// Whether the floor is seen from above at an angle (a plane with a grid) rather than
    /// edge-on (a line) or straight down.
    pub fn sees_floor_plane(&self) -> bool {
        self.view == View::ThreeQuarter
    }

    /// Caption of the view in pictures ("three-quarter, 60° left" for a three-quarter view).
    pub fn caption(&self) -> String {
        if self.view == View::ThreeQuarter {
            let deg = self.azimuth.to_degrees().round();
            let side = if deg >= 0.0 { "left" } else { "right" };
            format!("three-quarter, {}° {side}", deg.abs())
        } else {
            self.view.caption().to_string()
        }
    }
}

/// The three-quarter view that shows a motion best, for figures turned to face +Z.
///
/// Rule: the motion's main horizontal direction e is the major axis of Σ d dᵀ over the
/// horizontal displacement d of every point between consecutive frames, of every track. The
/// camera's azimuth φ (from the figure's front towards its left) is taken in the three-quarter
/// bands 30°–60° on either side, as the whole degree that puts e most across the screen
/// (largest |e · right(φ)|): a motion along the facing (a forward jump, a fall backwards) is
/// seen from 60° to the side, one across it (a fall sideways) from 30°, so that the travel is
/// never towards the camera and front and side both show. Ties go to the azimuth nearest 45° on
/// the figure's left; a motion without a main direction (the axes' variances within 20 % of
/// each other, or no motion) is seen from 45° on its left. The camera looks down at
/// [`ELEVATION`].
pub fn three_quarter(tracks: &[Track]) -> Eye {
    let (mut sxx, mut sxz, mut szz) = (0.0, 0.0, 0.0);
    for t in tracks {
        for w in t.frames.windows(2) {
            for (a, b) in w[0].iter().zip(&w[1]) {
                let (dx, dz) = (b.x - a.x, b.z - a.z);
                if dx.is_finite() && dz.is_finite() {
                    sxx += dx * dx;
                    sxz += dx * dz;
                    szz += dz * dz;
                }
            }
        }
    }
    // Eigenvalues of [[sxx, sxz], [sxz, szz]]: mean ± spread.
    let spread = (0.25 * (sxx - szz).powi(2) + sxz * sxz).sqrt();
    let total = sxx + szz;
    if !(total.is_finite() && total > 0.0 && spread / (0.5 * total) > 0.2) {
        return Eye::orbit(DEFAULT_AZIMUTH, ELEVATION);
    }
    // Major axis at angle θ from +X towards +Z: e = (cos θ, 0, sin θ).
    let theta = 0.5 * (2.0 * sxz).atan2(sxx - szz);
    let (lo, hi) = BAND_DEG;
    let best = (lo..=hi)
        .flat_map(|d| [d, -d])
        .map(|d| {
            let phi = (d as f64).to_radians();
            // e · right(φ) = cos θ cos φ − sin θ sin φ = cos(θ + φ).
            let across = (theta + phi).cos().abs();
            (across - 1e-4 * (phi - DEFAULT_AZIMUTH).abs(), phi)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map_or(DEFAULT_AZIMUTH, |(_, phi)| phi);
    Eye::orbit(best, ELEVATION)
}

/// Axis-aligned bounds in a view plane (metres).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Extent {
    pub min: DVec2,
    pub max: DVec2,
}

/// Bounds of every point of every frame of every track seen by `eye`, the floor included for
/// views that show it (height 0 for the edge-on views, every point's foot on the floor, where
/// its shadow falls, for the three-quarter view); and the largest distance, along each screen
/// axis, of any point from its frame's root (what a following camera must keep in view).
pub(crate) fn motion_extent(tracks: &[Track], eye: &Eye) -> (Extent, DVec2) {
    let mut min = DVec2::splat(f64::INFINITY);
    let mut max = DVec2::splat(f64::NEG_INFINITY);
    let mut reach = DVec2::ZERO;
    let plane = eye.sees_floor_plane();
    for t in tracks {
        let root = t.figure.root();
        for frame in t.frames {
            let r = eye.project(frame[root]);
            for &p in frame {
                let q = eye.project(p);
                min = min.min(q);
                max = max.max(q);
                reach = reach.max((q - r).abs());
                if plane {
                    let f = eye.project(DVec3::new(p.x, 0.0, p.z));
                    min = min.min(f);
                    max = max.max(f);
                    reach = reach.max((f - r).abs());
                }
            }
        }
    }
    if eye.view.shows_floor() && !plane {
        min.y = min.y.min(0.0);
        max.y = max.y.max(0.0);
    }
    (Extent { min, max }, reach)
}

/// The vertical screen extent of the motion seen by `eye`, floor included, at least 1 cm
/// (metres).
pub(crate) fn height_extent(tracks: &[Track], eye: &Eye) -> f64 {
    let (e, _) = motion_extent(tracks, eye);
    (e.max.y - e.min.y).max(0.01)
}

/// Scale and margin for pictures whose floor-showing panels are `height` pixels high, from the
/// motion seen by `eye`: margin pad = 0.06·h + 0.02 m around the motion's vertical screen
/// extent h, and metres per pixel mpp = (h + 2·pad) / height. Returns (mpp, pad).
pub(crate) fn scale_for(tracks: &[Track], eye: &Eye, height: u32) -> (f64, f64) {
    let h = height_extent(tracks, eye);
    let pad = 0.06 * h + 0.02;
    ((h + 2.0 * pad) / height.max(1) as f64, pad)
}

/// Largest panel side (pixels) whatever the motion: a point very far from the rest is drawn off
/// the panel rather than making a picture of millions of pixels.
pub(crate) const MAX_PANEL: u32 = 4096;

/// Size limits of a panel in pixels.
#[derive(Debug, Clone, Copy)]
pub(crate) struct PanelLimits {
    /// Panel height for views that show the floor (pixels); sets the scale.
    pub height: u32,
    /// Narrowest panel (pixels), so captions fit.
    pub min_width: u32,
    /// Widest panel before the camera follows the root (pixels).
    pub max_width: u32,
}

/// A camera for one view of one picture: scale, panel size and, per axis, fixed centre or
/// following the root.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Camera {
    pub eye: Eye,
    /// Metres per pixel, the same for every view of a picture.
    pub mpp: f64,
    /// Panel size (pixels).
    pub width: u32,
    pub height: u32,
    /// Per screen axis: whether it follows the root instead of staying at `centre`.
    pub follow: [bool; 2],
    /// Fixed centre of the panel in the view plane (metres), for axes that do not follow.
    pub centre: DVec2,
    /// The floor patch a three-quarter view draws: its corners (x, z) lowest and highest
    /// (metres), the motion's floor area grown by [`FLOOR_MARGIN`] and rounded out to 0.5 m.
    pub floor: (DVec2, DVec2),
}

/// Floor beyond the motion's points on every side of the floor patch (metres).
pub(crate) const FLOOR_MARGIN: f64 = 0.3;

/// The floor patch under `tracks` (see [`Camera::floor`]); empty (lowest above highest) when
/// no point is finite.
fn floor_area(tracks: &[Track]) -> (DVec2, DVec2) {
    let mut lo = DVec2::INFINITY;
    let mut hi = DVec2::NEG_INFINITY;
    for p in tracks.iter().flat_map(|t| t.frames.iter().flatten()) {
        let q = DVec2::new(p.x, p.z);
        if q.is_finite() {
            lo = lo.min(q);
            hi = hi.max(q);
        }
    }
    let step = 0.5;
    (
        ((lo - FLOOR_MARGIN) / step).floor() * step,
        ((hi + FLOOR_MARGIN) / step).ceil() * step,
    )
}

impl Camera {
    /// Frames `tracks` in `view` at `mpp` metres per pixel with a margin of `pad` metres, within
    /// `limits` (see the module doc for the rule).
    pub fn fit(tracks: &[Track], eye: Eye, mpp: f64, pad: f64, limits: PanelLimits) -> Camera {
        let (e, reach) = motion_extent(tracks, &eye);
        let mut size = [0u32; 2];
        let mut follow = [false; 2];
        for axis in 0..2 {
            if axis == 1 && eye.view.shows_floor() {
                // The scale was chosen so that the vertical extent fills this height.
                size[1] = limits.height;
                continue;
            }
            let need = ((e.max[axis] - e.min[axis] + 2.0 * pad) / mpp).ceil();
            let (lo, hi) = if axis == 1 {
                (limits.min_width, limits.max_width.max(limits.height))
            } else {
                (limits.min_width, limits.max_width)
            };
            // A following camera must still show every point around the root.
            let follow_size = ((2.0 * (reach[axis] + pad)) / mpp).ceil().max(lo as f64);
            if need <= hi as f64 || need <= follow_size {
                size[axis] = need.max(lo as f64).min(MAX_PANEL as f64) as u32;
            } else {
                size[axis] = follow_size.min(MAX_PANEL as f64) as u32;
                follow[axis] = true;
            }
        }
        Camera {
            eye,
            mpp,
            width: size[0].max(1),
            height: size[1].max(1),
            follow,
            centre: (e.min + e.max) * 0.5,
            floor: floor_area(tracks),
        }
    }

    /// Centre of the panel (view-plane metres) for a frame whose root is at `root` (world).
    pub fn centre_for(&self, root: DVec3) -> DVec2 {
        let r = self.eye.project(root);
        DVec2::new(
            if self.follow[0] { r.x } else { self.centre.x },
            if self.follow[1] { r.y } else { self.centre.y },
        )
    }

    /// Pixel position (x right, y down, panel-local) of view-plane point `q` (metres) when the
    /// panel is centred on `centre`: x = w/2 + (q.x − c.x)/mpp, y = h/2 − (q.y − c.y)/mpp.
    pub fn pixel(&self, centre: DVec2, q: DVec2) -> (f32, f32) {
        let d = (q - centre) / self.mpp;
        (
            (self.width as f64 * 0.5 + d.x) as f32,
            (self.height as f64 * 0.5 - d.y) as f32,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::figure::StickFigure;

    #[test]
    fn views_are_right_handed_and_put_the_left_on_the_viewers_right_in_front() {
        for v in [View::Front, View::Side, View::Top, View::ThreeQuarter] {
            let (r, u, t) = v.axes();
            assert!((r.cross(u) - t).length() < 1e-12, "{v:?}");
        }
        // The figure's left (+X) is screen right in the front view.
        assert!(View::Front.project(DVec3::X).x > 0.0);
        // Seen from its left side, the figure faces screen left.
        assert!(View::Side.project(DVec3::Z).x < 0.0);
        // From above, the figure's front (+Z) is screen down.
        assert!(View::Top.project(DVec3::Z).y < 0.0);
    }

    /// A figure of one point moving by `step` (m) a frame for 20 frames.
    fn mover(step: DVec3) -> (StickFigure, Vec<Vec<DVec3>>) {
        let f = StickFigure {
            names: vec!["Hips".into()],
            parents: vec![None],
        };
        let frames = (0..20).map(|k| vec![DVec3::Y + step * k as f64]).collect();
        (f, frames)
    }

    #[test]
    fn the_three_quarter_view_puts_the_motion_across_the_picture_from_in_front() {
        let az = |step: DVec3| {
            let (f, frames) = mover(step);
            let t = Track {
                figure: &f,
                frames: &frames,
                label: String::new(),
                frame_time: 0.1,
            };
            let eye = three_quarter(&[t]);
            // Orthonormal, right-handed, looking down at the elevation.
            assert!((eye.right.cross(eye.up) - eye.towards).length() < 1e-12);
            assert!((eye.towards.y - ELEVATION.sin()).abs() < 1e-12);
            // A three-quarter view: 30°–60° from the facing (+Z), in front of the figure.
            let horizontal = DVec3::new(eye.towards.x, 0.0, eye.towards.z).normalize();
            let off = horizontal.dot(DVec3::Z).acos().to_degrees();
            assert!((30.0 - 1e-9..=60.0 + 1e-9).contains(&off), "{off}°");
            eye.azimuth.to_degrees()
        };
        // Along the facing (a forward jump, a fall backwards): from the side's edge of the band,
        // on the figure's left.
        assert!((az(DVec3::Z * 0.05) - 60.0).abs() < 1e-9);
        assert!((az(-DVec3::Z * 0.05) - 60.0).abs() < 1e-9);
        // Across it (a fall sideways): from the front's edge.
        assert!((az(DVec3::X * 0.05) - 30.0).abs() < 1e-9);
        // Diagonal (forward and to the left): from the front right, square to the travel.
        assert!((az(DVec3::new(0.05, 0.0, 0.05)) + 45.0).abs() < 1e-9);
        // Up and down only: no main direction, 45° on the left.
        assert!((az(DVec3::Y * 0.05) - 45.0).abs() < 1e-9);
    }

    fn walker() -> (StickFigure, Vec<Vec<DVec3>>) {
        let f = StickFigure {
            names: vec!["Hips".into(), "Head".into()],
            parents: vec![None, Some(0)],
        };
        // Walks 6 m along +Z, 1.7 m tall.
        let frames = (0..61)
            .map(|k| {
                let z = k as f64 * 0.1;
                vec![DVec3::new(0.0, 1.0, z), DVec3::new(0.0, 1.7, z)]
            })
            .collect();
        (f, frames)
    }

    #[test]
    fn fixed_camera_fits_motion_and_following_camera_keeps_the_root_centred() {
        let (f, frames) = walker();
        let t = Track {
            figure: &f,
            frames: &frames,
            label: "w".into(),
            frame_time: 0.1,
        };
        let tracks = [t];
        let h = height_extent(&tracks, &Eye::fixed(View::Front));
        assert!((h - 1.7).abs() < 1e-12);
        let limits = PanelLimits {
            height: 200,
            min_width: 100,
            max_width: 300,
        };
        let mpp = (h + 0.2) / 200.0;
        // Front: narrow motion, fixed, minimum width.
        let front = Camera::fit(&tracks, Eye::fixed(View::Front), mpp, 0.1, limits);
        assert_eq!((front.width, front.height), (100, 200));
        assert_eq!(front.follow, [false, false]);
        // Floor (y = 0) and head (1.7 m) are inside the panel.
        let c = front.centre_for(frames[0][0]);
        let (_, y_floor) = front.pixel(c, DVec2::new(0.0, 0.0));
        let (_, y_head) = front.pixel(c, DVec2::new(0.0, 1.7));
        let pad_px = (0.1 / mpp) as f32;
        assert!((y_floor - (200.0 - pad_px)).abs() < 1e-3, "{y_floor}");
        assert!((y_head - pad_px).abs() < 1e-3, "{y_head}");
        // Side: 6 m of travel does not fit in 300 px, so x follows the root, in a panel of the
        // minimum width (the figure is a vertical line).
        let side = Camera::fit(&tracks, Eye::fixed(View::Side), mpp, 0.1, limits);
        assert_eq!(side.follow, [true, false]);
        assert_eq!(side.width, 100);
        let c = side.centre_for(frames[40][0]);
        let (x, _) = side.pixel(c, side.eye.project(frames[40][1]));
        assert!((x - 50.0).abs() < 1e-3);
    }
}
