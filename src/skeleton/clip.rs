//! A clip: a skeleton and its motion as local translations and rotations per frame, in metres.

use glam::{DQuat, DVec3};

use super::euler::{euler_to_quat, quat_to_euler};
use super::fk::{Transform, forward_kinematics};
use super::{Joint, Skeleton};
use crate::bvh::{Bvh, BvhJoint, Channel};

/// Errors building a clip.
#[derive(Debug, thiserror::Error)]
pub enum ClipError {
    /// The BVH has no joints or no frames.
    #[error("the motion has {what}")]
    Empty { what: &'static str },
    /// A unit scale that is not a positive finite number.
    #[error("unit scale must be a positive finite number of metres per file unit, found {0}")]
    BadScale(f64),
    /// A time window that is empty or reaches outside the clip.
    #[error(
        "time window {start_s:.3}..{end_s:.3} s is empty or reaches outside the clip, which spans \
         0..{duration_s:.3} s"
    )]
    Window {
        /// Start asked for, seconds.
        start_s: f64,
        /// End asked for, seconds.
        end_s: f64,
        /// The clip's duration, seconds.
        duration_s: f64,
    },
    /// A figure whose size in metres is not a human's: a wrong unit scale or garbage offsets.
    #[error(
        "the figure is {size_m:.4} m tall (or wide) at {scale} m per file unit, outside the human \
         range {min_m}..{max_m} m: give the right unit scale (metres per file unit)"
    )]
    FigureSize {
        /// The figure's size, metres.
        size_m: f64,
        /// The unit scale used.
        scale: f64,
        /// Smallest size accepted.
        min_m: f64,
        /// Largest size accepted.
        max_m: f64,
    },
    /// More frames × joints than [`MAX_FRAME_JOINTS`].
    #[error("{frames} frames × {joints} joints is more than the {max} joint poses a clip may hold")]
    TooLarge {
        /// Frames.
        frames: usize,
        /// Joints.
        joints: usize,
        /// The limit.
        max: usize,
    },
}

/// Most joint poses (frames × joints) a clip may hold: 20 million, about 1.1 GB of
/// translations and rotations (CMU's 23 s forward jumps hold 85 000).
pub const MAX_FRAME_JOINTS: usize = 20_000_000;

/// The sizes a figure may have, metres (its height, or its largest rest-pose side): a toddler
/// to well over the tallest human, so that a wrong unit scale is an error, not a 26 km figure.
pub const FIGURE_SIZE_M: (f64, f64) = (0.3, 3.0);

/// A motion on a skeleton: for every frame, one local translation and one local rotation per
/// joint (row-major, `frame * joints + joint`). Metres, seconds.
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// The skeleton (offsets in metres).
    pub skeleton: Skeleton,
    /// Seconds per frame.
    pub frame_time: f64,
    /// Local translation of every joint in every frame, metres (the rest offset, or the position
    /// channels where the joint has them).
    pub translations: Vec<DVec3>,
    /// Local rotation of every joint in every frame.
    pub rotations: Vec<DQuat>,
}

/// Metres per file unit for the usual BVH units: metres, centimetres, millimetres, inches, and
/// the CMU "cmuconvert" unit (1/0.45 inch ≈ 0.0564 m).
const CANDIDATE_UNITS: [f64; 5] = [1.0, 0.01, 0.001, 0.0254, 0.0254 / 0.45];

/// Metres per file unit estimated from the standing height: the candidate unit that makes the
/// figure's median vertical extent (over up to 64 sampled frames, head to feet) closest to an
/// adult's 1.70 m (in ratio). `extent_units` is that median extent in file units.
pub fn estimate_unit_scale(extent_units: f64) -> f64 {
    let mut best = CANDIDATE_UNITS[0];
    let mut best_err = f64::INFINITY;
    for &u in &CANDIDATE_UNITS {
        let err = (extent_units * u / 1.70).ln().abs();
        if err < best_err {
            best = u;
            best_err = err;
        }
    }
    best
}

/// How one joint's BVH channels map onto its rotation and translation.
struct ChannelPlan {
    rot_axes: Vec<usize>,
    rot_idx: Vec<usize>,
    pos: Vec<(usize, usize)>,
}

impl ChannelPlan {
    /// The plan of joint `j`'s channels: its rotation axes and their channel indices in order,
    /// and its position channels.
    fn of(j: &BvhJoint) -> ChannelPlan {
        let mut rot_axes = vec![];
        let mut rot_idx = vec![];
        let mut pos = vec![];
        for (k, c) in j.channels.iter().enumerate() {
            if c.is_rotation() {
                rot_axes.push(c.axis());
                rot_idx.push(j.first_channel + k);
            } else {
                pos.push((j.first_channel + k, c.axis()));
            }
        }
        ChannelPlan {
            rot_axes,
            rot_idx,
            pos,
        }
    }
}

impl Clip {
    /// Number of joints.
    pub fn joint_count(&self) -> usize {
        self.skeleton.joints.len()
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.rotations
            .len()
            .checked_div(self.joint_count())
            .unwrap_or(0)
    }

    /// Duration in seconds (frames × frame time).
    pub fn duration(&self) -> f64 {
        self.frame_count() as f64 * self.frame_time
    }

    /// Local translations of frame `f`.
    pub fn frame_translations(&self, f: usize) -> &[DVec3] {
        let n = self.joint_count();
        &self.translations[f * n..(f + 1) * n]
    }

    /// Local rotations of frame `f`.
    pub fn frame_rotations(&self, f: usize) -> &[DQuat] {
        let n = self.joint_count();
        &self.rotations[f * n..(f + 1) * n]
    }

    /// Global transforms of every joint at frame `f`.
    pub fn globals(&self, f: usize, out: &mut Vec<Transform>) {
        out.resize(self.joint_count(), Transform::IDENTITY);
        forward_kinematics(
            &self.skeleton,
            self.frame_translations(f),
            self.frame_rotations(f),
            out,
        );
    }

    /// Drawable points (joints then End Sites, see [`Skeleton::point_names`]) of every frame.
    pub fn point_frames(&self) -> Vec<Vec<DVec3>> {
        let mut g = vec![];
        (0..self.frame_count())
            .map(|f| {
                self.globals(f, &mut g);
                let mut pts = vec![];
                self.skeleton.points(&g, &mut pts);
                pts
            })
            .collect()
    }

    /// Builds a clip from a BVH file's content. Rotation channels compose in their listed order
    /// (see [`euler_to_quat`]); position channels replace the rest offset (the common reading,
    /// Blender's and three.js's). `unit_scale` is metres per file unit; `None` estimates it from
    /// the standing height ([`estimate_unit_scale`]).
    pub fn from_bvh(bvh: &Bvh, unit_scale: Option<f64>) -> Result<Clip, ClipError> {
        if bvh.joints.is_empty() {
            return Err(ClipError::Empty { what: "no joints" });
        }
        let frames = bvh.frame_count();
        if frames == 0 {
            return Err(ClipError::Empty { what: "no frames" });
        }
        let n = bvh.joints.len();
        if frames.saturating_mul(n) > MAX_FRAME_JOINTS {
            return Err(ClipError::TooLarge {
                frames,
                joints: n,
                max: MAX_FRAME_JOINTS,
            });
        }
        let mut clip = Clip {
            skeleton: Skeleton {
                joints: bvh
                    .joints
                    .iter()
                    .map(|j| Joint {
                        name: j.name.clone(),
                        parent: j.parent,
                        offset: j.offset,
                        end_site: j.end_site,
                    })
                    .collect(),
            },
            frame_time: bvh.frame_time,
            translations: Vec::with_capacity(frames * n),
            rotations: Vec::with_capacity(frames * n),
        };
        // Per joint: rotation axes and their channel indices, and the (channel index, axis) of
        // position channels.
        let plans: Vec<ChannelPlan> = bvh.joints.iter().map(ChannelPlan::of).collect();
        let mut angles = Vec::with_capacity(3);
        for f in 0..frames {
            let values = bvh.frame(f);
            for (j, plan) in plans.iter().enumerate() {
                let mut t = bvh.joints[j].offset;
                for &(idx, axis) in &plan.pos {
                    t[axis] = values[idx];
                }
                angles.clear();
                angles.extend(plan.rot_idx.iter().map(|&i| values[i].to_radians()));
                clip.translations.push(t);
                clip.rotations.push(euler_to_quat(&plan.rot_axes, &angles));
            }
        }
        let scale = match unit_scale {
            Some(s) if s.is_finite() && s > 0.0 => s,
            Some(s) => return Err(ClipError::BadScale(s)),
            None => estimate_unit_scale(clip.median_vertical_extent()),
        };
        clip.scale(scale);
        let size = clip.figure_size();
        let (min_m, max_m) = FIGURE_SIZE_M;
        if !(size.is_finite() && (min_m..=max_m).contains(&size)) {
            return Err(ClipError::FigureSize {
                size_m: size,
                scale,
                min_m,
                max_m,
            });
        }
        Ok(clip)
    }

    /// The figure's size, metres: the larger of its median vertical extent over the motion
    /// and the largest side of its rest pose's bounding box (a lying figure is still its height).
    pub fn figure_size(&self) -> f64 {
        let rest = self.skeleton.rest_points();
        let (lo, hi) = rest.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(a, b), p| (a.min(*p), b.max(*p)),
        );
        (hi - lo).max_element().max(self.median_vertical_extent())
    }

    /// Multiplies every length (offsets, end sites, translations) by `s`.
    pub fn scale(&mut self, s: f64) {
        for j in &mut self.skeleton.joints {
            j.offset *= s;
            j.end_site = j.end_site.map(|e| e * s);
        }
        for t in &mut self.translations {
            *t *= s;
        }
    }

    /// Median over up to 64 evenly sampled frames of the figure's vertical extent (max − min of
    /// the points' Y), in the clip's current units.
    pub fn median_vertical_extent(&self) -> f64 {
        let frames = self.frame_count();
        let samples = frames.min(64);
        let mut g = vec![];
        let mut pts = vec![];
        let mut extents: Vec<f64> = (0..samples)
            .map(|i| {
                let f = i * frames / samples;
                self.globals(f, &mut g);
                self.skeleton.points(&g, &mut pts);
                let hi = pts.iter().map(|p| p.y).fold(f64::MIN, f64::max);
                let lo = pts.iter().map(|p| p.y).fold(f64::MAX, f64::min);
                hi - lo
            })
            .collect();
        extents.sort_by(f64::total_cmp);
        extents[extents.len() / 2]
    }

    /// The frames whose times lie in `[start_s, end_s)` (seconds from the clip's start); a
    /// window reaching outside `0..duration` (by more than half a frame) is an error, not
    /// silently cut.
    pub fn window(&self, start_s: f64, end_s: f64) -> Result<Clip, ClipError> {
        let first = (start_s / self.frame_time).round().max(0.0) as usize;
        let last = ((end_s / self.frame_time).round() as usize).min(self.frame_count());
        let outside = end_s > self.duration() + 0.5 * self.frame_time;
        if !(start_s.is_finite() && end_s.is_finite()) || start_s < 0.0 || outside || first >= last
        {
            return Err(ClipError::Window {
                start_s,
                end_s,
                duration_s: self.duration(),
            });
        }
        let n = self.joint_count();
        Ok(Clip {
            skeleton: self.skeleton.clone(),
            frame_time: self.frame_time,
            translations: self.translations[first * n..last * n].to_vec(),
            rotations: self.rotations[first * n..last * n].to_vec(),
        })
    }

    /// The clip as BVH content with rotation channels in ZXY order (see
    /// [`Clip::to_bvh_with_order`]).
    pub fn to_bvh(&self) -> Bvh {
        self.to_bvh_with_order([2, 0, 1])
    }

    /// The clip as BVH content: every joint gets 3 rotation channels in `order` (axes 0 = X,
    /// 1 = Y, 2 = Z, e.g. `[2, 0, 1]` for `Zrotation Xrotation Yrotation`), preceded by 3
    /// position channels on the root and wherever a joint's translation ever differs from its
    /// offset. Metres, degrees.
    pub fn to_bvh_with_order(&self, order: [usize; 3]) -> Bvh {
        let rot_channel =
            |a: usize| [Channel::Xrotation, Channel::Yrotation, Channel::Zrotation][a];
        let n = self.joint_count();
        let frames = self.frame_count();
        let moving: Vec<bool> = (0..n)
            .map(|j| {
                self.skeleton.joints[j].parent.is_none()
                    || (0..frames).any(|f| {
                        (self.translations[f * n + j] - self.skeleton.joints[j].offset).length()
                            > 1e-9
                    })
            })
            .collect();
        let mut joints = vec![];
        let mut first = 0;
        for (j, sj) in self.skeleton.joints.iter().enumerate() {
            let mut channels = vec![];
            if moving[j] {
                channels.extend([Channel::Xposition, Channel::Yposition, Channel::Zposition]);
            }
            channels.extend(order.map(rot_channel));
            let count = channels.len();
            joints.push(BvhJoint {
                name: sj.name.clone(),
                parent: sj.parent,
                offset: sj.offset,
                channels,
                first_channel: first,
                end_site: sj.end_site,
            });
            first += count;
        }
        let mut motion = Vec::with_capacity(frames * first);
        for f in 0..frames {
            for (j, &moves) in moving.iter().enumerate() {
                if moves {
                    let t = self.translations[f * n + j];
                    motion.extend([t.x, t.y, t.z]);
                }
                let e = quat_to_euler(order, self.rotations[f * n + j]);
                motion.extend(e.iter().map(|a| a.to_degrees()));
            }
        }
        Bvh {
            joints,
            frame_time: self.frame_time,
            channel_count: first,
            motion,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_estimates() {
        assert_eq!(estimate_unit_scale(1.75), 1.0);
        assert_eq!(estimate_unit_scale(172.0), 0.01);
        assert_eq!(estimate_unit_scale(1650.0), 0.001);
        assert!((estimate_unit_scale(30.0) - 0.0254 / 0.45).abs() < 1e-12);
        assert_eq!(estimate_unit_scale(68.0), 0.0254);
    }
}
