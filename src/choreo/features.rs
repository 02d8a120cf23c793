//! Per-frame features of a dance motion given as global joint positions (metres, Y up, one
//! `Vec<DVec3>` per frame): the paper's motion intensity W(f), the pose rows Eros compares, and
//! the mirror image of a motion.

use glam::DVec3;

/// Speed |ẋ_i| of every joint in every frame (m/s): central differences, one-sided at the ends;
/// zeros for a single frame.
pub fn joint_speeds(positions: &[Vec<DVec3>], fps: f64) -> Vec<Vec<f64>> {
    let n = positions.len();
    (0..n)
        .map(|f| {
            let (a, b) = (f.saturating_sub(1), (f + 1).min(n - 1));
            let dt = (b - a) as f64 / fps;
            positions[f]
                .iter()
                .enumerate()
                .map(|(i, _)| {
                    if b == a {
                        0.0
                    } else {
                        (positions[b][i] - positions[a][i]).length() / dt
                    }
                })
                .collect()
        })
        .collect()
}

/// The motion intensity of the paper, W(f) = Σ_i α_i |ẋ_i(f)| (m/s with unit weights), for every
/// frame; `alpha` has one weight per joint (missing weights count as 0).
pub fn motion_intensity(positions: &[Vec<DVec3>], fps: f64, alpha: &[f64]) -> Vec<f64> {
    joint_speeds(positions, fps)
        .iter()
        .map(|s| s.iter().zip(alpha).map(|(v, a)| a * v).sum())
        .collect()
}

/// The time average of W(f) over the frames (0 for none): a segment's motion intensity.
pub fn mean_motion_intensity(positions: &[Vec<DVec3>], fps: f64, alpha: &[f64]) -> f64 {
    let w = motion_intensity(positions, fps, alpha);
    if w.is_empty() {
        0.0
    } else {
        w.iter().sum::<f64>() / w.len() as f64
    }
}

/// Pose rows for Eros: each frame's joint positions relative to the `root` joint, flattened
/// (x, y, z per joint), so that where the dancer stands does not matter but how the body moves
/// does.
pub fn pose_rows(positions: &[Vec<DVec3>], root: usize) -> Vec<Vec<f64>> {
    positions
        .iter()
        .map(|p| {
            let r = p.get(root).copied().unwrap_or(DVec3::ZERO);
            p.iter()
                .flat_map(|x| {
                    let d = *x - r;
                    [d.x, d.y, d.z]
                })
                .collect()
        })
        .collect()
}

/// For each joint name, the index of its mirror partner (`left…` ↔ `right…`, also `l_`/`r_`
/// prefixes), or itself when it has none.
pub fn mirror_partners(names: &[String]) -> Vec<usize> {
    let swap = |n: &str| -> Option<String> {
        let l = n.to_ascii_lowercase();
        for (a, b) in [
            ("left", "right"),
            ("right", "left"),
            ("l_", "r_"),
            ("r_", "l_"),
        ] {
            if let Some(rest) = l.strip_prefix(a) {
                return Some(format!("{b}{rest}"));
            }
        }
        if l.contains("left") {
            return Some(l.replace("left", "right"));
        }
        if l.contains("right") {
            return Some(l.replace("right", "left"));
        }
        None
    };
    names
        .iter()
        .enumerate()
        .map(|(i, n)| {
            swap(n)
                .and_then(|m| names.iter().position(|o| o.to_ascii_lowercase() == m))
                .unwrap_or(i)
        })
        .collect()
}

/// The mirror image of a motion in the sagittal plane (x → −x; a character's left is +X) with
/// every joint swapped with its partner from [`mirror_partners`].
pub fn mirror_motion(positions: &[Vec<DVec3>], partners: &[usize]) -> Vec<Vec<DVec3>> {
    positions
        .iter()
        .map(|p| {
            partners
                .iter()
                .map(|&j| {
                    let x = p[j];
                    DVec3::new(-x.x, x.y, x.z)
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_joint_on_a_circle_has_speed_r_omega() {
        let (r, w, fps) = (0.4, 3.0, 240.0);
        let pos: Vec<Vec<DVec3>> = (0..480)
            .map(|f| {
                let t = f as f64 / fps;
                vec![
                    DVec3::ZERO,
                    DVec3::new(r * (w * t).cos(), 1.0, r * (w * t).sin()),
                ]
            })
            .collect();
        let m = mean_motion_intensity(&pos, fps, &[1.0, 2.0]);
        assert!((m - 2.0 * r * w).abs() < 1e-3, "{m}");
        assert_eq!(motion_intensity(&pos, fps, &[1.0, 0.0])[10], 0.0);
    }

    #[test]
    fn partners_pair_left_and_right() {
        let names: Vec<String> = ["hips", "left_hand", "right_hand", "LeftFoot", "RightFoot"]
            .iter()
            .map(|s| s.to_string())
            .collect();
        assert_eq!(mirror_partners(&names), vec![0, 2, 1, 4, 3]);
    }
}
