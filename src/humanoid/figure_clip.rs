//! A motion on a model: DOF angle trajectories plus root motion.

use glam::{DQuat, DVec3};

use crate::humanoid::{Figure, FigureError, rotation_vector_near};
use crate::primitive::Trajectory;

/// Names of the root channels in a primitive trajectory: translation (m), then orientation as a
/// rotation vector (rad).
pub const ROOT_CHANNELS: [&str; 6] = [
    "root_tx", "root_ty", "root_tz", "root_rx", "root_ry", "root_rz",
];
use crate::skeleton::Clip;

/// A motion expressed on one of the engine's models (a [`Figure`]): per frame, every DOF angle
/// (radians, model order, unwrapped over time), the root (pelvis) position in metres and its
/// orientation.
#[derive(Clone, Debug, PartialEq)]
pub struct FigureClip {
    /// The model, with offsets taken from the source skeleton.
    pub model: Figure,
    /// Seconds per frame.
    pub frame_time: f64,
    /// Pelvis position per frame, metres.
    pub root_translation: Vec<DVec3>,
    /// Pelvis orientation per frame.
    pub root_rotation: Vec<DQuat>,
    /// DOF angles, `frames × dofs`, radians.
    pub angles: Vec<f64>,
}

impl FigureClip {
    /// An empty clip on `model` at `frame_time` seconds per frame, with room for `frames` frames.
    pub fn with_capacity(model: Figure, frame_time: f64, frames: usize) -> FigureClip {
        let dofs = model.dofs.len();
        FigureClip {
            model,
            frame_time,
            root_translation: Vec::with_capacity(frames),
            root_rotation: Vec::with_capacity(frames),
            angles: Vec::with_capacity(frames * dofs),
        }
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.root_translation.len()
    }

    /// Number of DOFs of the model.
    pub fn dof_count(&self) -> usize {
        self.model.dofs.len()
    }

    /// DOF angles of frame `f`, radians.
    pub fn frame_angles(&self, f: usize) -> &[f64] {
        let d = self.dof_count();
        &self.angles[f * d..(f + 1) * d]
    }

    /// One DOF's angle over time, radians.
    pub fn dof_series(&self, dof: usize) -> Vec<f64> {
        (0..self.frame_count())
            .map(|f| self.angles[f * self.dof_count() + dof])
            .collect()
    }

    /// Root orientation as rotation vectors, unwrapped over time (no flips between v and
    /// v − 2π·v̂), radians.
    pub fn root_rotation_vectors(&self) -> Vec<DVec3> {
        let mut out: Vec<DVec3> = Vec::with_capacity(self.root_rotation.len());
        for q in &self.root_rotation {
            let v = rotation_vector_near(*q, out.last().copied());
            out.push(v);
        }
        out
    }

    /// The frames whose times lie in `[start_s, end_s)`; `None` if that is empty.
    pub fn window(&self, start_s: f64, end_s: f64) -> Option<FigureClip> {
        let first = (start_s / self.frame_time).round().max(0.0) as usize;
        let last = ((end_s / self.frame_time).round().max(0.0) as usize).min(self.frame_count());
        if first >= last {
            return None;
        }
        let d = self.dof_count();
        Some(FigureClip {
            model: self.model.clone(),
            frame_time: self.frame_time,
            root_translation: self.root_translation[first..last].to_vec(),
            root_rotation: self.root_rotation[first..last].to_vec(),
            angles: self.angles[first * d..last * d].to_vec(),
        })
    }

    /// The motion as a plain clip on the model's skeleton (for FK, pictures and BVH output).
    pub fn to_clip(&self) -> Clip {
        let skeleton = self.model.skeleton();
        let n = skeleton.joints.len();
        let frames = self.frame_count();
        let mut translations = Vec::with_capacity(frames * n);
        let mut rotations = vec![DQuat::IDENTITY; frames * n];
        for f in 0..frames {
            translations.extend(skeleton.joints.iter().map(|j| j.offset));
            translations[f * n] = self.root_translation[f];
            let rot = &mut rotations[f * n..(f + 1) * n];
            self.model.local_rotations(self.frame_angles(f), rot);
            rot[0] = self.root_rotation[f];
        }
        Clip {
            skeleton,
            frame_time: self.frame_time,
            translations,
            rotations,
        }
    }

    /// The motion as a primitive trajectory: the model's DOFs (radians) followed by the root
    /// channels `root_tx, root_ty, root_tz` (metres) and `root_rx, root_ry, root_rz` (the
    /// pelvis orientation as a rotation vector, unwrapped over time, radians).
    pub fn to_trajectory(&self) -> Trajectory {
        let d = self.dof_count();
        let mut names = self.model.dof_names();
        names.extend(ROOT_CHANNELS.iter().map(|s| s.to_string()));
        let rv = self.root_rotation_vectors();
        let mut values = Vec::with_capacity(self.frame_count() * (d + 6));
        for (f, r) in rv.iter().enumerate() {
            values.extend_from_slice(self.frame_angles(f));
            let t = self.root_translation[f];
            values.extend([t.x, t.y, t.z, r.x, r.y, r.z]);
        }
        Trajectory {
            dt: self.frame_time,
            names,
            values,
        }
    }

    /// A motion on `model` from a trajectory holding every model DOF (by name) and the six root
    /// channels of [`FigureClip::to_trajectory`].
    pub fn from_trajectory(model: &Figure, traj: &Trajectory) -> Result<FigureClip, FigureError> {
        let index = |name: &str| {
            traj.names
                .iter()
                .position(|n| n == name)
                .ok_or_else(|| FigureError::MissingChannel(name.to_string()))
        };
        let dof_cols: Vec<usize> = model
            .dofs
            .iter()
            .map(|d| index(&d.name))
            .collect::<Result<_, _>>()?;
        let root_cols: Vec<usize> = ROOT_CHANNELS
            .iter()
            .map(|n| index(n))
            .collect::<Result<_, _>>()?;
        let frames = traj.frames();
        let mut clip = FigureClip {
            model: model.clone(),
            frame_time: traj.dt,
            root_translation: Vec::with_capacity(frames),
            root_rotation: Vec::with_capacity(frames),
            angles: Vec::with_capacity(frames * dof_cols.len()),
        };
        for k in 0..frames {
            let row = traj.frame(k);
            clip.angles.extend(dof_cols.iter().map(|&c| row[c]));
            let r = |i: usize| row[root_cols[i]];
            clip.root_translation.push(DVec3::new(r(0), r(1), r(2)));
            clip.root_rotation
                .push(DQuat::from_scaled_axis(DVec3::new(r(3), r(4), r(5))));
        }
        Ok(clip)
    }

    /// Height of each foot's lowest point (its ankle joint or the ankle's End Site, the toe) at
    /// every frame, `[left, right]`, metres.
    pub fn foot_heights(&self) -> [Vec<f64>; 2] {
        let clip = self.to_clip();
        let ankle = |name: &str| clip.skeleton.index(name);
        let sides = [ankle("left_ankle"), ankle("right_ankle")];
        let mut g = vec![];
        let mut out = [
            Vec::with_capacity(clip.frame_count()),
            Vec::with_capacity(clip.frame_count()),
        ];
        for f in 0..clip.frame_count() {
            clip.globals(f, &mut g);
            for (k, a) in sides.iter().enumerate() {
                let h = a.map_or(f64::NAN, |a| {
                    let e = clip.skeleton.joints[a].end_site.unwrap_or_default();
                    g[a].translation
                        .y
                        .min((g[a].translation + g[a].rotation * e).y)
                });
                out[k].push(h);
            }
        }
        out
    }

    /// Lifts the root wherever a foot point (ankle joints and their End Sites) is below
    /// `floor_y`, by exactly how far it is below, and nowhere else: the floor constraint on a
    /// rollout whose reproduction error puts a foot a few millimetres through the floor. The
    /// lift is continuous (the positive part of a continuous depth). Returns the largest lift,
    /// metres.
    pub fn lift_above_floor(&mut self, floor_y: f64) -> f64 {
        let [left, right] = self.foot_heights();
        let mut largest: f64 = 0.0;
        for ((t, l), r) in self.root_translation.iter_mut().zip(&left).zip(&right) {
            let depth = floor_y - l.min(*r);
            if depth > 0.0 {
                t.y += depth;
                largest = largest.max(depth);
            }
        }
        largest
    }

    /// Keeps the feet on the floor: outside the `airborne` spans (seconds) the root is raised or
    /// lowered so that the lowest foot point (ankle joints and their End Sites) is at
    /// `floor_y`; inside a span the correction is interpolated linearly between its ends, so a
    /// flight keeps its arc. Blending and extrapolating joint angles and root height separately
    /// does not keep legs and root consistent (an extrapolated crouch lifts the feet); this puts
    /// the contact back. Returns the largest correction applied, metres.
    pub fn keep_feet_on_floor(&mut self, airborne: &[(f64, f64)], floor_y: f64) -> f64 {
        let [left, right] = self.foot_heights();
        let lowest: Vec<f64> = left.iter().zip(&right).map(|(l, r)| l.min(*r)).collect();
        let n = lowest.len();
        let frame =
            |t: f64| ((t / self.frame_time).round().max(0.0) as usize).min(n.saturating_sub(1));
        let mut correction: Vec<f64> = lowest.iter().map(|h| floor_y - h).collect();
        for &(a, b) in airborne {
            let (fa, fb) = (frame(a), frame(b));
            if fb <= fa {
                continue;
            }
            let (ca, cb) = (correction[fa], correction[fb]);
            for (k, c) in correction.iter_mut().enumerate().take(fb).skip(fa + 1) {
                let u = (k - fa) as f64 / (fb - fa) as f64;
                *c = ca + u * (cb - ca);
            }
        }
        for (t, c) in self.root_translation.iter_mut().zip(&correction) {
            t.y += c;
        }
        correction.iter().fold(0.0, |m, c| m.max(c.abs()))
    }

    /// The angles as CSV: header `frame,time_s,<dof>,…`, degrees, one row per frame.
    pub fn angles_csv(&self) -> String {
        let mut s = String::from("frame,time_s");
        for d in &self.model.dofs {
            s.push(',');
            s.push_str(&d.name);
        }
        s.push('\n');
        for f in 0..self.frame_count() {
            s.push_str(&format!("{f},{:.6}", f as f64 * self.frame_time));
            for a in self.frame_angles(f) {
                s.push_str(&format!(",{:.4}", a.to_degrees()));
            }
            s.push('\n');
        }
        s
    }
}
