//! Orthographic views and camera framing: which world axes a view shows, how large a panel is,
//! and where a world point lands in it.
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
}

impl View {
    /// The view's right-handed camera basis in world axes: (screen right, screen up, towards the
    /// viewer), with right × up = towards.
    pub fn axes(self) -> (DVec3, DVec3, DVec3) {
        match self {
            View::Front => (DVec3::X, DVec3::Y, DVec3::Z),
            View::Side => (DVec3::NEG_Z, DVec3::Y, DVec3::X),
            View::Top => (DVec3::X, DVec3::NEG_Z, DVec3::Y),
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
        }
    }
}

/// Axis-aligned bounds in a view plane (metres).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Extent {
    pub min: DVec2,
    pub max: DVec2,
}

/// Bounds of every point of every frame of every track in `view`, the floor height 0 included
/// for views that show the floor; and the largest distance, along each screen axis, of any point
/// from its frame's root (what a following camera must keep in view).
pub(crate) fn motion_extent(tracks: &[Track], view: View) -> (Extent, DVec2) {
    let mut min = DVec2::splat(f64::INFINITY);
    let mut max = DVec2::splat(f64::NEG_INFINITY);
    let mut reach = DVec2::ZERO;
    for t in tracks {
        let root = t.figure.root();
        for frame in t.frames {
            let r = view.project(frame[root]);
            for &p in frame {
                let q = view.project(p);
                min = min.min(q);
                max = max.max(q);
                reach = reach.max((q - r).abs());
            }
        }
    }
    if view.shows_floor() {
        min.y = min.y.min(0.0);
        max.y = max.y.max(0.0);
    }
    (Extent { min, max }, reach)
}

/// The vertical (Y) extent of the motion including the floor, at least 1 cm (metres).
pub(crate) fn height_extent(tracks: &[Track]) -> f64 {
    let (e, _) = motion_extent(tracks, View::Front);
    (e.max.y - e.min.y).max(0.01)
}

/// Scale and margin for pictures whose floor-showing panels are `height` pixels high: margin
/// pad = 0.06·h + 0.02 m around the motion's vertical extent h, and metres per pixel
/// mpp = (h + 2·pad) / height. Returns (mpp, pad).
pub(crate) fn scale_for(tracks: &[Track], height: u32) -> (f64, f64) {
    let h = height_extent(tracks);
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
    pub view: View,
    /// Metres per pixel, the same for every view of a picture.
    pub mpp: f64,
    /// Panel size (pixels).
    pub width: u32,
    pub height: u32,
    /// Per screen axis: whether it follows the root instead of staying at `centre`.
    pub follow: [bool; 2],
    /// Fixed centre of the panel in the view plane (metres), for axes that do not follow.
    pub centre: DVec2,
}

impl Camera {
    /// Frames `tracks` in `view` at `mpp` metres per pixel with a margin of `pad` metres, within
    /// `limits` (see the module doc for the rule).
    pub fn fit(tracks: &[Track], view: View, mpp: f64, pad: f64, limits: PanelLimits) -> Camera {
        let (e, reach) = motion_extent(tracks, view);
        let mut size = [0u32; 2];
        let mut follow = [false; 2];
        for axis in 0..2 {
            if axis == 1 && view.shows_floor() {
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
            view,
            mpp,
            width: size[0].max(1),
            height: size[1].max(1),
            follow,
            centre: (e.min + e.max) * 0.5,
        }
    }

    /// Centre of the panel (view-plane metres) for a frame whose root is at `root` (world).
    pub fn centre_for(&self, root: DVec3) -> DVec2 {
        let r = self.view.project(root);
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
    use crate::render::figure::Figure;

    #[test]
    fn views_are_right_handed_and_put_the_left_on_the_viewers_right_in_front() {
        for v in [View::Front, View::Side, View::Top] {
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

    fn walker() -> (Figure, Vec<Vec<DVec3>>) {
        let f = Figure {
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
        let h = height_extent(&tracks);
        assert!((h - 1.7).abs() < 1e-12);
        let limits = PanelLimits {
            height: 200,
            min_width: 100,
            max_width: 300,
        };
        let mpp = (h + 0.2) / 200.0;
        // Front: narrow motion, fixed, minimum width.
        let front = Camera::fit(&tracks, View::Front, mpp, 0.1, limits);
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
        let side = Camera::fit(&tracks, View::Side, mpp, 0.1, limits);
        assert_eq!(side.follow, [true, false]);
        assert_eq!(side.width, 100);
        let c = side.centre_for(frames[40][0]);
        let (x, _) = side.pixel(c, side.view.project(frames[40][1]));
        assert!((x - 50.0).abs() < 1e-3);
    }
}
