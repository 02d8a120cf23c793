//! A motion on a model: DOF angle trajectories plus root motion.

use glam::{DQuat, DVec3};

use crate::model::Model;
use crate::skeleton::Clip;

/// A motion expressed on one of the engine's models: per frame, every DOF angle (radians, model
/// order, unwrapped over time), the root (pelvis) position in metres and its orientation.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelClip {
    /// The model, with offsets taken from the source skeleton.
    pub model: Model,
    /// Seconds per frame.
    pub frame_time: f64,
    /// Pelvis position per frame, metres.
    pub root_translation: Vec<DVec3>,
    /// Pelvis orientation per frame.
    pub root_rotation: Vec<DQuat>,
    /// DOF angles, `frames × dofs`, radians.
    pub angles: Vec<f64>,
}

impl ModelClip {
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
            let q = if q.w < 0.0 { -*q } else { *q };
            let mut v = q.to_scaled_axis();
            if let Some(prev) = out.last() {
                let angle = v.length();
                if angle > 1e-9 {
                    let dir = v / angle;
                    let k = ((prev.dot(dir) - angle) / std::f64::consts::TAU).round();
                    let alt = dir * (angle + std::f64::consts::TAU * k);
                    if (alt - *prev).length() < (v - *prev).length() {
                        v = alt;
                    }
                }
            }
            out.push(v);
        }
        out
    }

    /// The frames whose times lie in `[start_s, end_s)`; `None` if that is empty.
    pub fn window(&self, start_s: f64, end_s: f64) -> Option<ModelClip> {
        let first = (start_s / self.frame_time).round().max(0.0) as usize;
        let last = ((end_s / self.frame_time).round().max(0.0) as usize).min(self.frame_count());
        if first >= last {
            return None;
        }
        let d = self.dof_count();
        Some(ModelClip {
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
