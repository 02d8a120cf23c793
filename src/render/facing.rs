//! Views oriented by the figure: every track is turned about the vertical axis so that the
//! figure faces +Z, so "front" shows its front and "side" its left side whatever way the
//! motion faced in its file.
//!
//! The figure's left is the mean over the motion of (mean of its left limb roots − mean of its
//! right limb roots), horizontal: a limb root is a point on one side (by
//! [`super::StickFigure::sides`]) hanging from a mid-line point: hips, clavicles or shoulders,
//! not the swinging hands and feet. Its facing is left × up. A figure without sides is drawn as
//! it is.

use glam::{DQuat, DVec3};

use super::figure::{Side, Track};

/// Which points of `track`'s figure are limb roots: a point on one side hanging from a
/// mid-line point.
fn limb_roots(track: &Track) -> (Vec<Side>, Vec<bool>) {
    let sides = track.figure.sides();
    let limb_root: Vec<bool> = (0..sides.len())
        .map(|i| {
            sides[i] != Side::Centre
                && track.figure.parents[i].is_some_and(|p| sides[p] == Side::Centre)
        })
        .collect();
    (sides, limb_root)
}

/// Mean of the left limb roots minus mean of the right ones in one frame (`None` without both).
fn lateral(frame: &[DVec3], sides: &[Side], limb_root: &[bool]) -> Option<DVec3> {
    let mean = |want: Side| {
        let (sum, n) = frame
            .iter()
            .zip(sides)
            .zip(limb_root)
            .filter(|((_, s), root)| **s == want && **root)
            .fold((DVec3::ZERO, 0usize), |(a, n), ((p, _), _)| (a + *p, n + 1));
        (n > 0).then(|| sum / n as f64)
    };
    Some(mean(Side::Left)? - mean(Side::Right)?)
}

/// The turn about +Y that brings a figure whose left is `lateral` to face +Z (facing =
/// left × up); identity when `lateral` has no horizontal part.
fn turn_for(lateral: DVec3) -> DQuat {
    let facing = DVec3::new(lateral.x, 0.0, lateral.z).cross(DVec3::Y);
    if facing.length() < 1e-9 {
        return DQuat::IDENTITY;
    }
    // Facing = R_y(θ)·Z with θ = atan2(f.x, f.z); turning by −θ brings it onto +Z.
    DQuat::from_rotation_y(-facing.x.atan2(facing.z))
}

/// The turn about +Y that makes `track`'s figure face +Z over the whole motion (its mean
/// facing; identity without named sides).
pub(crate) fn facing_turn(track: &Track) -> DQuat {
    let (sides, limb_root) = limb_roots(track);
    let sum = track
        .frames
        .iter()
        .filter_map(|f| lateral(f, &sides, &limb_root))
        .fold(DVec3::ZERO, |a, l| a + l);
    turn_for(sum)
}

/// Every track's frames turned so that *each frame* faces +Z: the whole motion is turned by
/// its [`facing_turn`] (so the path it travels is as [`turned_frames`] draws it), then each
/// frame's pose is turned about its root's vertical line by what its own facing (the limb
/// roots of that frame) still differs from +Z. A filmstrip's "front" cell is then the figure's
/// front at that instant however it turned in between.
pub(crate) fn turned_frames_each(tracks: &[Track]) -> Vec<Vec<Vec<DVec3>>> {
    tracks
        .iter()
        .map(|t| {
            let q = facing_turn(t);
            let (sides, limb_root) = limb_roots(t);
            let root = t.figure.root();
            t.frames
                .iter()
                .map(|f| {
                    let turned: Vec<DVec3> = f.iter().map(|p| q * *p).collect();
                    let own =
                        lateral(&turned, &sides, &limb_root).map_or(DQuat::IDENTITY, turn_for);
                    let pivot = turned
                        .get(root)
                        .map_or(DVec3::ZERO, |r| DVec3::new(r.x, 0.0, r.z));
                    turned.iter().map(|p| pivot + own * (*p - pivot)).collect()
                })
                .collect()
        })
        .collect()
}

/// Every track's frames turned by its [`facing_turn`].
pub(crate) fn turned_frames(tracks: &[Track]) -> Vec<Vec<Vec<DVec3>>> {
    tracks
        .iter()
        .map(|t| {
            let q = facing_turn(t);
            t.frames
                .iter()
                .map(|f| f.iter().map(|p| q * *p).collect())
                .collect()
        })
        .collect()
}

/// `tracks` with their frames replaced by `frames` (from [`turned_frames`]).
pub(crate) fn with_frames<'a>(
    tracks: &[Track<'a>],
    frames: &'a [Vec<Vec<DVec3>>],
) -> Vec<Track<'a>> {
    tracks
        .iter()
        .zip(frames)
        .map(|(t, f)| Track {
            figure: t.figure,
            frames: f,
            label: t.label.clone(),
            frame_time: t.frame_time,
        })
        .collect()
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::render::StickFigure;

    /// A pelvis with its two hips.
    fn hips() -> StickFigure {
        StickFigure {
            names: vec!["pelvis".into(), "left_hip".into(), "right_hip".into()],
            parents: vec![None, Some(0), Some(0)],
        }
    }

    /// A track of `frames` at 10 frames/s (shared with the filmstrip tests).
    pub(crate) fn track<'a>(fig: &'a StickFigure, frames: &'a [Vec<DVec3>]) -> Track<'a> {
        Track {
            figure: fig,
            frames,
            label: "t".into(),
            frame_time: 0.1,
        }
    }

    #[test]
    fn a_figure_facing_plus_x_is_turned_to_face_plus_z() {
        let fig = hips();
        // Facing +X: its left is −Z.
        let frames = vec![vec![
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, -0.1),
            DVec3::new(0.0, 1.0, 0.1),
        ]];
        let t = track(&fig, &frames);
        let q = facing_turn(&t);
        assert!((q * DVec3::X - DVec3::Z).length() < 1e-12);
        // Its left hip ends up on +X, the engine's left.
        assert!((q * frames[0][1]).x > 0.09);
    }

    #[test]
    fn each_frame_is_turned_by_its_own_facing_about_its_root() {
        let fig = hips();
        // A figure at x = 2 that turns from facing +Z (left +X) to facing +X (left −Z) and on
        // to facing −Z (left −X): a half turn, mean facing +X.
        let at = |left: DVec3| {
            let c = DVec3::new(2.0, 1.0, 0.0);
            vec![c, c + 0.1 * left, c - 0.1 * left]
        };
        let frames = vec![at(DVec3::X), at(-DVec3::Z), at(-DVec3::X)];
        let t = track(&fig, &frames);
        let q = facing_turn(&t);
        let turned = turned_frames_each(std::slice::from_ref(&t));
        for (k, f) in turned[0].iter().enumerate() {
            // Every frame's left hip on +X of its root: facing +Z.
            let left = f[1] - f[0];
            assert!(
                (left - DVec3::new(0.1, 0.0, 0.0)).length() < 1e-12,
                "frame {k}: {left}"
            );
            // The root where the whole-motion turn puts it.
            assert!((f[0] - q * frames[k][0]).length() < 1e-12);
        }
    }
}
