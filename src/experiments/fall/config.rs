//! The configuration of a pushed fall: subject, joint ranges, PD gains and key pose, push,
//! step, integrator, contact and damage weights — everything a scene file (RON) gives.

use crate::dynamics::Integrator;
use crate::dynamics::forces::contact::ContactParams;
use crate::dynamics::forces::external::Push;
use crate::dynamics::forces::limits::JointLimitParams;
use crate::humanoid::strength::torque_limits;
use crate::humanoid::{AgeGroup, RangeTable};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Where the joint ranges come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Ranges {
    /// A built-in age group (`src/humanoid/data/fall21_{elderly,adult}.ron`).
    Builtin(AgeGroup),
    /// A user table (degrees), e.g. loaded with [`RangeTable::load`].
    Table(RangeTable),
    /// A range-table RON file (like `src/humanoid/data/fall21_elderly.ron`), read when the fall is
    /// built; a relative path is taken from the working directory.
    File(std::path::PathBuf),
}

/// Everything that defines one pushed fall. Angles in degrees, per fall21 DOF in model order.
/// In a scene file every field may be left out: it then takes its value from
/// [`FallConfig::paper`] for the elderly group (`FallConfig::default()`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FallConfig {
    /// Standing height (m).
    pub height_m: f64,
    /// Body mass (kg).
    pub mass_kg: f64,
    /// Gravitational acceleration magnitude (m/s²), acting along −Y.
    pub gravity: f64,
    /// Joint ranges (age group).
    pub ranges: Ranges,
    /// Joint-model gains (friction inside the range, spring and damper past it).
    pub limits: JointLimitParams,
    /// Strength: the PD torque range `(τ_min, τ_max)` per DOF (N·m, model order) the dynamics
    /// clamps to; [`FallConfig::paper`] takes [`torque_limits`] of the age group; `None` =
    /// unbounded.
    pub torque_limits_nm: Option<Vec<(f64, f64)>>,
    /// Initial standing pose (deg, 21 DOFs), held by the stance gains until `control_start_s`.
    pub stance_pose_deg: Vec<f64>,
    /// Stance PD stiffness per DOF (N·m/rad).
    pub stance_kp: Vec<f64>,
    /// Stance PD damping per DOF (N·m·s/rad).
    pub stance_kv: Vec<f64>,
    /// Key pose θ_d (deg, 21 DOFs) the reaction drives toward (θ̇_d = 0).
    pub key_pose_deg: Vec<f64>,
    /// PD stiffness k_p per DOF toward the key pose (N·m/rad) — a GA gene.
    pub kp: Vec<f64>,
    /// PD damping k_v per DOF (N·m·s/rad).
    pub kv: Vec<f64>,
    /// Time at which control switches from the stance to the key pose (s).
    pub control_start_s: f64,
    /// The push.
    pub push: Push,
    /// Time step (s).
    pub dt_s: f64,
    /// Integration scheme.
    pub integrator: Integrator,
    /// Sub-steps per step over the first `reaction_window_s` of the reaction (from
    /// `control_start_s`, where the key-pose PD takes over): each step of `dt_s` starting in
    /// that stretch is taken as this many sub-steps of `dt_s / reaction_substeps`, the floor's
    /// peaks seeing every one. 1 (the default) = none.
    #[serde(skip_serializing_if = "is_one")]
    pub reaction_substeps: u32,
    /// Length of that stretch (s); 0 (the default) = none.
    #[serde(skip_serializing_if = "is_zero")]
    pub reaction_window_s: f64,
    /// Simulated time (s), counted from the end of the settling phase.
    pub duration_s: f64,
    /// Longest settling phase before the run (s): the standing body is relaxed to rest first.
    pub settle_max_s: f64,
    /// Floor contact parameters.
    pub contact: ContactParams,
    /// Damage weight w_i per link name (links not listed weigh 1).
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub damage_weights: BTreeMap<String, f64>,
    /// Frames recorded per second.
    pub record_hz: f64,
    /// The body is at rest while its kinetic energy stays below this (J)…
    pub rest_kinetic_energy_j: f64,
    /// …for at least this long (s), up to the end of the run.
    pub rest_hold_s: f64,
    /// End the run as soon as the body has rested for `rest_hold_s` (saves most of the time
    /// of a GA evaluation; peaks and damage are unchanged, impulses stop accumulating).
    pub stop_at_rest: bool,
}

fn is_one(n: &u32) -> bool {
    *n == 1
}

fn is_zero(x: &f64) -> bool {
    *x == 0.0
}

/// The natural frequency (Hz) every joint's range limit is tuned to in [`FallConfig::paper`],
/// critically damped: a stop hard enough that the impact of a fall bends a joint at most a few
/// degrees past its range (a shared 300 N·m/rad spring let the wrist and waist overshoot by
/// 10–40°), soft enough that even the lightest DOF (the wrist, `(H⁻¹)_jj ≈ 570 /(kg·m²)`) stays
/// within the step's stability bound (ω h ≈ 0.9 of 2 at 0.9 ms).
pub const LIMIT_FREQUENCY_HZ: f64 = 150.0;

/// A per-DOF table in fall21 order from a function of the DOF name.
fn per_dof(names: &[String], f: impl Fn(&str) -> f64) -> Vec<f64> {
    names.iter().map(|n| f(n)).collect()
}

fn strip_side(n: &str) -> &str {
    n.trim_start_matches("left_").trim_start_matches("right_")
}

impl FallConfig {
    /// The paper's experiment for `group`: a 1.70 m, 65 kg subject standing with bent knees
    /// (34°: the elderly knee range of the paper's Table 1 starts at 32°, so both groups stand
    /// alike inside their ranges), pushed with 1000 N on the chest from the front for 0.1 s from
    /// t = 0.1 s; the reaction toward the key pose (here the stance itself) starts at 0.25 s;
    /// semi-implicit Euler with implicit damping at 0.5 ms (the stiffest mode, the foot's heel
    /// pad contact, bounds it at 0.92 ms) for 3 s after a settling phase of at most 3 s; PD
    /// torques capped at the group's strength ([`torque_limits`]); joint range limits tuned to
    /// [`LIMIT_FREQUENCY_HZ`] per DOF; damage weights protect the head most (w = 10).
    pub fn paper(group: AgeGroup) -> Self {
        let names = crate::humanoid::fall21().dof_names();
        let stance = per_dof(&names, |n| match strip_side(n) {
            "waist_flexion" => 5.0,
            "elbow" => 30.0,
            "hip_flexion" => 16.0,
            "knee" => 34.0,
            "ankle" => 17.0,
            _ => 0.0,
        });
        let gain = |n: &str| match strip_side(n) {
            "neck_flexion" | "neck_lateral" | "neck_rotation" => 40.0,
            "waist_flexion" | "waist_rotation" => 600.0,
            "shoulder_flexion" | "shoulder_rotation" => 60.0,
            "elbow" => 40.0,
            "wrist" => 8.0,
            "hip_flexion" | "hip_abduction" => 600.0,
            "knee" => 600.0,
            "ankle" => 400.0,
            _ => 50.0,
        };
        let kp = per_dof(&names, gain);
        let kv = per_dof(&names, |n| 0.1 * gain(n));
        let mut w = BTreeMap::new();
        for (link, wi) in [
            ("head", 10.0),
            ("torso", 2.0),
            ("pelvis", 2.0),
            ("right_upper_arm", 1.0),
            ("left_upper_arm", 1.0),
            ("right_forearm", 1.0),
            ("left_forearm", 1.0),
            ("right_hand", 0.5),
            ("left_hand", 0.5),
            ("right_thigh", 1.0),
            ("left_thigh", 1.0),
            ("right_shin", 1.0),
            ("left_shin", 1.0),
            ("right_foot", 0.2),
            ("left_foot", 0.2),
        ] {
            w.insert(link.to_string(), wi);
        }
        let h = 1.70;
        Self {
            height_m: h,
            mass_kg: 65.0,
            gravity: 9.81,
            ranges: Ranges::Builtin(group),
            limits: JointLimitParams {
                limit_frequency_hz: Some(LIMIT_FREQUENCY_HZ),
                ..JointLimitParams::default()
            },
            torque_limits_nm: Some(torque_limits(group)),
            stance_pose_deg: stance.clone(),
            stance_kp: kp.clone(),
            stance_kv: kv.clone(),
            key_pose_deg: stance,
            kp,
            kv,
            control_start_s: 0.25,
            push: crate::dynamics::forces::external::paper_push(0.1, 0.16 * h),
            dt_s: 5e-4,
            integrator: Integrator::SemiImplicitEuler {
                implicit_damping: true,
            },
            reaction_substeps: 1,
            reaction_window_s: 0.0,
            duration_s: 3.0,
            settle_max_s: 3.0,
            contact: ContactParams::default(),
            damage_weights: w,
            record_hz: 60.0,
            rest_kinetic_energy_j: 1.0,
            rest_hold_s: 0.3,
            stop_at_rest: false,
        }
    }
}

impl Default for FallConfig {
    /// The paper's experiment for the elderly group.
    fn default() -> Self {
        Self::paper(AgeGroup::Elderly)
    }
}
