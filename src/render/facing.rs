//! Views oriented by the figure: every track is turned about the vertical axis so that the
//! figure faces +Z, so "front" shows its front and "side" its left side whatever way the
//! motion faced in its file.
//!
//! The figure's left is the mean over the motion of (mean of its left limb roots − mean of its
//! right limb roots), horizontal: a limb root is a point on one side (by
//! [`super::Figure::sides`]) hanging from a mid-line point: hips, clavicles or shoulders, not the
//! swinging hands and feet. Its facing is left × up. A figure without sides is drawn as it is.

use glam::{DQuat, DVec3};

use super::figure::{Side, Track};

/// The turn about +Y that makes `track`'s figure face +Z (identity without named sides).
pub(crate) fn facing_turn(track: &Track) -> DQuat {
    let sides = track.figure.sides();
    let limb_root: Vec<bool> = (0..sides.len())
        .map(|i| {
            sides[i] != Side::Centre
                && track.figure.parents[i].is_some_and(|p| sides[p] == Side::Centre)
        })
        .collect();
    let mut lateral = DVec3::ZERO;
    for frame in track.frames {
        let mean = |want: Side| {
            let (sum, n) = frame
                .iter()
                .zip(&sides)
                .zip(&limb_root)
                .filter(|((_, s), root)| **s == want && **root)
                .fold((DVec3::ZERO, 0usize), |(a, n), ((p, _), _)| (a + *p, n + 1));
            (n > 0).then(|| sum / n as f64)
        };
        if let (Some(l), Some(r)) = (mean(Side::Left), mean(Side::Right)) {
            lateral += l - r;
        }
    }
    let facing = DVec3::new(lateral.x, 0.0, lateral.z).cross(DVec3::Y);
    if facing.length() < 1e-9 {
        return DQuat::IDENTITY;
    }
    // Facing = R_y(θ)·Z with θ = atan2(f.x, f.z); turning by −θ brings it onto +Z.
    DQuat::from_rotation_y(-facing.x.atan2(facing.z))
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
mod tests {
    use super::*;
    use crate::render::Figure;

    #[test]
    fn a_figure_facing_plus_x_is_turned_to_face_plus_z() {
        let fig = Figure {
            names: vec!["pelvis".into(), "left_hip".into(), "right_hip".into()],
            parents: vec![None, Some(0), Some(0)],
        };
        // Facing +X: its left is −Z.
        let frames = vec![vec![
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, -0.1),
            DVec3::new(0.0, 1.0, 0.1),
        ]];
        let t = Track {
            figure: &fig,
            frames: &frames,
            label: "t".into(),
            frame_time: 0.1,
        };
        let q = facing_turn(&t);
        assert!((q * DVec3::X - DVec3::Z).length() < 1e-12);
        // Its left hip ends up on +X, the engine's left.
        assert!((q * frames[0][1]).x > 0.09);
    }
}
