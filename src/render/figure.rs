//! What is drawn: a stick figure's topology ([`StickFigure`]), a motion of it ([`Track`]), the
//! left/right rule that colours its limbs ([`side_from_name`]) and the checks that turn bad input
//! into a [`RenderError`] before anything is drawn.

use glam::DVec3;

use super::RenderError;
use crate::skeleton::Skeleton;
pub use crate::skeleton::{Side, side_from_name};

/// A stick figure's topology: one point per joint or end site; `parents[i]` is the point it
/// hangs from (`None` for a root). Each point with a parent is drawn as a bone from the parent
/// to the point, each point as a dot.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StickFigure {
    /// Point names (joint or end-site names); they decide the limb colour, see [`side_from_name`].
    pub names: Vec<String>,
    /// `parents[i]`: index of the point that point `i` hangs from, `None` for a root.
    pub parents: Vec<Option<usize>>,
}

/// A motion to draw: global point positions per frame (metres, Y up, figure faces +Z, its left
/// is +X), sampled every `frame_time` seconds.
#[derive(Debug, Clone)]
pub struct Track<'a> {
    /// The topology shared by every frame.
    pub figure: &'a StickFigure,
    /// `frames[k][i]`: global position of point `i` at time `k · frame_time` (metres).
    pub frames: &'a [Vec<DVec3>],
    /// Name shown above the track (e.g. "adult, before evolution").
    pub label: String,
    /// Time between frames (seconds), e.g. 1/120 for 120 Hz capture; gives the time labels and
    /// the GIF's subsampling.
    pub frame_time: f64,
}

impl StickFigure {
    /// The stick figure of `skeleton`: its point names and parents (joints, then End Sites).
    pub fn of(skeleton: &Skeleton) -> Self {
        StickFigure {
            names: skeleton.point_names(),
            parents: skeleton.point_parents(),
        }
    }

    /// The side of every point: [`side_from_name`] of its name, or, when that is
    /// [`Side::Centre`], the side of its parent (so an unnamed end site below `LeftHand` is left).
    /// Points may be listed in any order; on a cyclic figure (which [`StickFigure::validate`]
    /// rejects) the walk stops after as many steps as there are points.
    pub fn sides(&self) -> Vec<Side> {
        let n = self.names.len();
        let mut memo: Vec<Option<Side>> = vec![None; n];
        for i in 0..n {
            // Walk up until a decided point, then fill the chain back down.
            let mut chain = Vec::new();
            let mut j = Some(i);
            let mut decided = Side::Centre;
            while let Some(k) = j {
                if let Some(s) = memo[k] {
                    decided = s;
                    break;
                }
                let own = side_from_name(&self.names[k]);
                chain.push(k);
                if own != Side::Centre || chain.len() > n {
                    decided = own;
                    break;
                }
                j = self.parents.get(k).copied().flatten();
            }
            // Points up the chain that name no side themselves take the decided side.
            for &k in chain.iter().rev() {
                let own = side_from_name(&self.names[k]);
                let s = if own == Side::Centre { decided } else { own };
                memo[k] = Some(s);
                decided = s;
            }
        }
        memo.into_iter()
            .map(|s| s.unwrap_or(Side::Centre))
            .collect()
    }

    /// Checks the topology: as many names as parents, at least one point, every parent index in
    /// range, and no point its own ancestor.
    pub fn validate(&self) -> Result<(), RenderError> {
        let n = self.names.len();
        if self.parents.len() != n {
            return Err(RenderError::BadFigure(format!(
                "{n} names but {} parents",
                self.parents.len()
            )));
        }
        if n == 0 {
            return Err(RenderError::Empty("the figure has no points".into()));
        }
        for (i, p) in self.parents.iter().enumerate() {
            if let Some(p) = *p
                && p >= n
            {
                return Err(RenderError::BadFigure(format!(
                    "point {i} ('{}') hangs from point {p}, but the figure has {n} points",
                    self.names[i]
                )));
            }
        }
        for i in 0..n {
            let mut j = self.parents[i];
            let mut steps = 0;
            while let Some(k) = j {
                steps += 1;
                if k == i || steps > n {
                    return Err(RenderError::BadFigure(format!(
                        "point {i} ('{}') is its own ancestor",
                        self.names[i]
                    )));
                }
                j = self.parents[k];
            }
        }
        Ok(())
    }

    /// Index of the first root (a point without parent); the camera follows it when a motion
    /// travels further than a panel shows.
    pub fn root(&self) -> usize {
        self.parents.iter().position(Option::is_none).unwrap_or(0)
    }
}

impl Track<'_> {
    /// Duration from first to last frame (seconds): `(frames − 1) · frame_time`.
    pub fn duration(&self) -> f64 {
        self.frames.len().saturating_sub(1) as f64 * self.frame_time
    }

    /// The frame shown at time `t` (seconds): the nearest sample, held at the ends.
    pub fn frame_at(&self, t: f64) -> usize {
        let last = self.frames.len().saturating_sub(1);
        if t.is_nan() || t <= 0.0 {
            return 0;
        }
        ((t / self.frame_time).round() as usize).min(last)
    }

    /// Checks everything drawing relies on: a valid figure, a positive finite frame time, at
    /// least one frame, every frame with one position per point, every position finite.
    pub fn validate(&self) -> Result<(), RenderError> {
        self.figure.validate()?;
        if !(self.frame_time.is_finite() && self.frame_time > 0.0) {
            return Err(RenderError::InvalidArgument(format!(
                "track '{}': frame time must be a positive number of seconds, got {}",
                self.label, self.frame_time
            )));
        }
        if self.frames.is_empty() {
            return Err(RenderError::Empty(format!(
                "track '{}' has no frames",
                self.label
            )));
        }
        let n = self.figure.names.len();
        for (k, frame) in self.frames.iter().enumerate() {
            if frame.len() != n {
                return Err(RenderError::PointCount {
                    track: self.label.clone(),
                    frame: k,
                    got: frame.len(),
                    expected: n,
                });
            }
            if let Some(i) = frame.iter().position(|p| !p.is_finite()) {
                return Err(RenderError::NonFinite {
                    track: self.label.clone(),
                    frame: k,
                    point: i,
                    name: self.figure.names[i].clone(),
                    value: [frame[i].x, frame[i].y, frame[i].z],
                });
            }
        }
        Ok(())
    }
}

/// Validates a non-empty list of tracks.
pub(crate) fn validate_tracks(tracks: &[Track]) -> Result<(), RenderError> {
    if tracks.is_empty() {
        return Err(RenderError::Empty("no tracks to draw".into()));
    }
    tracks.iter().try_for_each(Track::validate)
}

/// The root when it is a ground proxy, not a part of the body (as Bandai's `joint_Root` on the
/// floor under `Hips`): a root with one child, lower than a tenth of the figure's height above
/// its lowest point and farther from that child than a quarter of the height. Its bone would
/// be drawn as a third leg, so it is not drawn.
pub(crate) fn ground_proxy(fig: &StickFigure, pts: &[DVec3]) -> Option<usize> {
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn end_sites_inherit_their_parents_side() {
        let f = StickFigure {
            names: ["Hips", "LeftHand", "Site", "Neck", "RightFoot", "Toe_End"]
                .map(String::from)
                .to_vec(),
            parents: vec![None, Some(0), Some(1), Some(0), Some(0), Some(4)],
        };
        use Side::*;
        assert_eq!(f.sides(), vec![Centre, Left, Left, Centre, Right, Right]);
    }

    #[test]
    fn bad_topologies_are_errors() {
        let cyc = StickFigure {
            names: vec!["a".into(), "b".into()],
            parents: vec![Some(1), Some(0)],
        };
        assert!(matches!(cyc.validate(), Err(RenderError::BadFigure(_))));
        let out = StickFigure {
            names: vec!["a".into()],
            parents: vec![Some(3)],
        };
        assert!(matches!(out.validate(), Err(RenderError::BadFigure(_))));
        let uneven = StickFigure {
            names: vec!["a".into()],
            parents: vec![],
        };
        assert!(matches!(uneven.validate(), Err(RenderError::BadFigure(_))));
    }

    #[test]
    fn non_finite_and_miscounted_frames_name_the_frame_and_point() {
        let f = StickFigure {
            names: vec!["Hips".into(), "Head".into()],
            parents: vec![None, Some(0)],
        };
        let frames = vec![
            vec![DVec3::ZERO, DVec3::Y],
            vec![DVec3::ZERO, DVec3::new(0.0, f64::NAN, 0.0)],
        ];
        let t = Track {
            figure: &f,
            frames: &frames,
            label: "x".into(),
            frame_time: 0.01,
        };
        match t.validate() {
            Err(RenderError::NonFinite { frame, point, .. }) => {
                assert_eq!((frame, point), (1, 1))
            }
            other => panic!("expected NonFinite, got {other:?}"),
        }
        let short = vec![vec![DVec3::ZERO]];
        let t = Track {
            frames: &short,
            ..t
        };
        assert!(matches!(
            t.validate(),
            Err(RenderError::PointCount {
                frame: 0,
                got: 1,
                expected: 2,
                ..
            })
        ));
    }

    #[test]
    fn frame_at_rounds_and_holds() {
        let f = StickFigure {
            names: vec!["a".into()],
            parents: vec![None],
        };
        let frames = vec![vec![DVec3::ZERO]; 11];
        let t = Track {
            figure: &f,
            frames: &frames,
            label: String::new(),
            frame_time: 0.1,
        };
        assert!((t.duration() - 1.0).abs() < 1e-12);
        assert_eq!(t.frame_at(0.0), 0);
        assert_eq!(t.frame_at(0.26), 3);
        assert_eq!(t.frame_at(5.0), 10);
        assert_eq!(t.frame_at(-1.0), 0);
    }

    #[test]
    fn a_root_on_the_floor_under_the_hips_is_a_ground_proxy_and_a_pelvis_root_is_not() {
        // root (on the floor) → hips 0.9 m up → two legs down to the floor, a spine up.
        let names = [
            "root", "hips", "l_knee", "l_foot", "r_knee", "r_foot", "head",
        ];
        let fig = StickFigure {
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
        let body = StickFigure {
            names: fig.names[1..].to_vec(),
            parents: vec![None, Some(0), Some(1), Some(0), Some(3), Some(0)],
        };
        assert_eq!(ground_proxy(&body, &pts[1..]), None);
    }
}
