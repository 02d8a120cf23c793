//! What a fall keeps while it runs: frames at the record rate, rest detection from the kinetic
//! energy, when the run is over, and the damage weights; and the [`FallResult`] it yields.

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};

use super::config::FallConfig;
use super::result::{
    FallFrame, FallResult, LinkImpact, PeakTorque, PelvisImpact, TorqueSaturation,
};
use crate::dynamics::Data;
use crate::dynamics::forces::contact::ContactStats;
use crate::dynamics::pipeline::{State, StepMonitor};
use crate::humanoid::HumanBody;

/// Frames, rest detection and the end of the run.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct FallRecorder {
    /// Frames so far; frame `k` is the state at the step nearest to `k / hz`.
    pub frames: Vec<FallFrame>,
    /// Index of the next frame to record.
    pub next_frame: u64,
    /// Frame rate (Hz).
    pub hz: f64,
    /// Physics step (s).
    pub dt: f64,
    /// Steps to run in total.
    pub total_steps: u64,
    /// Rest threshold on the kinetic energy (J).
    pub rest_energy: f64,
    /// Start of the current rest interval (s).
    pub rest_since: Option<f64>,
    /// Rest is only detected from this time on (the end of the push, s).
    pub rest_after: f64,
    /// Hold time (s).
    pub rest_hold: f64,
    /// End the run once the body has rested for the hold time.
    pub stop_at_rest: bool,
    /// Damage weight w_i per link.
    pub weights: Vec<f64>,
    /// The step the last record was taken at.
    pub recorded_step: Option<u64>,
    /// Length of the settling phase that preceded the run (s).
    pub settle_s: f64,
    /// Start of the push (s): the standing figures are taken before it.
    pub push_start: f64,
    /// Before the push: the largest kinetic energy (J) and the smallest and largest total foot
    /// force (N).
    pub before_push: StandingStart,
    /// Pelvis: first time its centre of mass moves down faster than 0.1 m/s after the push
    /// starts (s), the start of descent.
    pub descent_start_s: Option<f64>,
    /// Floor height (m), level floor.
    pub floor_height: f64,
    /// Highest the pelvis box's lowest corner rose above the floor after the pelvis's first
    /// touchdown (m): the rebound.
    pub pelvis_rebound_m: f64,
    /// Strength `(τ_min, τ_max)` per DOF (N·m; empty = unbounded), for the peak torques.
    pub torque_limits: Vec<(f64, f64)>,
    angles: Vec<f64>,
}

/// The standing start before the push: the body's weight (N), the smallest and largest total
/// normal force on the feet (N) and the largest kinetic energy (J) over the steps before it.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct StandingStart {
    /// Body weight `M g` (N).
    pub weight_n: f64,
    /// Smallest total foot normal force before the push (N).
    pub min_foot_force_n: f64,
    /// Largest total foot normal force before the push (N).
    pub max_foot_force_n: f64,
    /// Largest kinetic energy before the push (J).
    pub max_kinetic_energy_j: f64,
    /// Length of the settling phase that found this rest (s).
    pub settle_s: f64,
}

impl FallRecorder {
    /// The recorder of the fall `cfg` (damage weights `weights` per link, a body of `nv`
    /// velocity DOFs).
    pub fn new(cfg: &FallConfig, weights: Vec<f64>, nv: usize) -> Self {
        let frames = (cfg.duration_s * cfg.record_hz).floor() as usize + 1;
        Self {
            frames: Vec::with_capacity(frames),
            next_frame: 0,
            hz: cfg.record_hz,
            dt: cfg.dt_s,
            total_steps: (cfg.duration_s / cfg.dt_s).round() as u64,
            rest_energy: cfg.rest_kinetic_energy_j,
            rest_since: None,
            rest_after: cfg.push.start_s + cfg.push.duration_s,
            rest_hold: cfg.rest_hold_s,
            torque_limits: cfg.torque_limits_nm.clone().unwrap_or_default(),
            stop_at_rest: cfg.stop_at_rest,
            weights,
            recorded_step: None,
            settle_s: 0.0,
            push_start: cfg.push.start_s,
            before_push: StandingStart {
                weight_n: cfg.mass_kg * cfg.gravity,
                min_foot_force_n: f64::INFINITY,
                max_foot_force_n: 0.0,
                max_kinetic_energy_j: 0.0,
                settle_s: 0.0,
            },
            descent_start_s: None,
            floor_height: cfg.contact.floor_height,
            pelvis_rebound_m: 0.0,
            angles: vec![0.0; nv],
        }
    }

    /// True once the run is over for `state`: all steps taken, or (with `stop_at_rest`) the
    /// body has stayed at rest for the hold time.
    pub fn finished(&self, state: &State) -> bool {
        state.steps >= self.total_steps
            || (self.stop_at_rest
                && self
                    .rest_since
                    .is_some_and(|t0| state.time_s - t0 >= self.rest_hold))
    }

    /// Records `state` (whose kinematics are in `data`; `monitor` what the steps saw): at step
    /// 0 the first frame; after a step the standing start (before the push), the pelvis's
    /// descent and rebound, the rest detection (kinetic energy below the threshold once the
    /// push is over) and a frame when one is due.
    pub fn record(&mut self, body: &HumanBody, state: &State, data: &Data, monitor: &StepMonitor) {
        if self.recorded_step == Some(state.steps) {
            return;
        }
        self.recorded_step = Some(state.steps);
        if state.steps == 0 {
            let f = self.frame(body, state, data);
            self.frames.push(f);
            self.next_frame = 1;
            return;
        }
        let model = &body.model;
        let t = state.time_s;
        // The kinetic energy `Σ ½ vᵢᵀ Iᵢ vᵢ` (J), each term at least zero (rounding can leave a
        // resting body's a hair below it): whole up to the push, whose maximum is reported;
        // after it only as far as the rest test needs, since a partial sum of such terms that
        // reaches the threshold stays there.
        let terms = || {
            (0..model.nbodies()).map(|i| {
                let k = model.bodies()[i].inertia.kinetic_energy(data.v[i]);
                if k < 0.0 { 0.0 } else { k }
            })
        };
        let whole = (t <= self.push_start).then(|| terms().fold(0.0, |sum, k| sum + k));
        // The monitor's sample is the floor at the start of the step that just ended.
        let step_start = t - self.dt;
        if step_start < self.push_start {
            let feet: f64 = body
                .link_names
                .iter()
                .zip(&monitor.sample.normal)
                .filter(|(n, _)| n.ends_with("_foot"))
                .map(|(_, f)| f)
                .sum();
            let b = &mut self.before_push;
            b.min_foot_force_n = b.min_foot_force_n.min(feet);
            b.max_foot_force_n = b.max_foot_force_n.max(feet);
            if let Some(ke) = whole {
                b.max_kinetic_energy_j = b.max_kinetic_energy_j.max(ke);
            }
        }
        let p = body.link_index("pelvis").unwrap_or(0);
        let com = model.bodies()[p].inertia.com;
        let vp = data.rot[p] * (data.v[p].lin + data.v[p].ang.cross(com));
        if self.descent_start_s.is_none() && t >= self.push_start && vp.y < -0.1 {
            self.descent_start_s = Some(t);
        }
        if monitor.contact.touchdown_s[p].is_some() {
            // Rebound: how high the pelvis box's lowest corner lifts off the floor after the
            // pelvis first touched it.
            // A corner `c` is at height `pos.y + (row 1 of rot)·c`: the lowest is the centre's
            // less the half extents along that row's magnitudes.
            let b = &body.boxes[p];
            let up = data.rot[p].row(1);
            let lowest = data.pos[p].y + up.dot(b.center) - up.abs().dot(b.half);
            self.pelvis_rebound_m = self.pelvis_rebound_m.max(lowest - self.floor_height);
        }
        // Rest counts only once the push is over (a figure standing still before it is not
        // "at rest" on the floor).
        let at_rest = t >= self.rest_after
            && match whole {
                Some(ke) => ke < self.rest_energy,
                None => below(terms(), self.rest_energy),
            };
        if at_rest {
            self.rest_since.get_or_insert(t);
        } else {
            self.rest_since = None;
        }
        if state.steps >= self.frame_step(self.next_frame) {
            let f = self.frame(body, state, data);
            self.frames.push(f);
            self.next_frame += 1;
        }
    }

    /// The step at which frame `k` is taken: the one nearest to `k / hz`.
    fn frame_step(&self, k: u64) -> u64 {
        (k as f64 / (self.hz * self.dt)).round() as u64
    }

    fn frame(&mut self, b: &HumanBody, state: &State, data: &Data) -> FallFrame {
        let q = &state.q;
        b.model.angles(q, &mut self.angles);
        let angles = b.dof_v.iter().map(|&k| self.angles[k]).collect();
        let head = b.link_index("head").unwrap_or(0);
        let head_com = data.pos[head] + data.rot[head] * b.model.bodies()[head].inertia.com;
        FallFrame {
            time_s: state.time_s,
            root_position: DVec3::new(q[0], q[1], q[2]),
            root_orientation: DQuat::from_xyzw(q[3], q[4], q[5], q[6]),
            angles,
            head_height_m: head_com.y,
        }
    }

    /// The result of the run so far; the damage is `D = Σ w_i f_i` (eq. 5.1) over the peak
    /// normal forces `f_i` of `monitor`.
    pub fn result(&self, body: &HumanBody, state: &State, monitor: &StepMonitor) -> FallResult {
        let c = &monitor.contact;
        let damage = self.weights.iter().zip(&c.peak).map(|(w, f)| w * f).sum();
        let impacts = self.link_impacts(body, c);
        let p = body.link_index("pelvis").unwrap_or(0);
        let pelvis_touch = c.touchdown_s[p];
        let strength = torque_saturation(body, monitor);
        let peak_torques = self.peak_torques(body, monitor);
        let mut standing = self.before_push;
        standing.settle_s = self.settle_s;
        let end = state.time_s;
        let rest_time_s = self.rest_since.filter(|&t0| end - t0 >= self.rest_hold);
        FallResult {
            dof_names: body.figure.dof_names(),
            link_names: body.link_names.clone(),
            frames: self.frames.clone(),
            record_hz: self.hz,
            damage,
            peak_vertical_force_n: c.peak.clone(),
            impulse_n_s: c.impulse.clone(),
            max_penetration_m: c.max_penetration,
            max_penetration_by_link_m: c.max_depth.clone(),
            max_limit_excursion_rad: monitor.max_excursion.clone(),
            came_to_rest: rest_time_s.is_some(),
            rest_time_s,
            steps: state.steps,
            dt_s: self.dt,
            height_m: body.figure.height,
            impacts,
            pelvis: PelvisImpact {
                impact_velocity_m_s: pelvis_touch.map(|_| -c.touchdown_velocity[p]),
                descent_start_s: self.descent_start_s,
                touchdown_s: pelvis_touch,
                descent_time_s: pelvis_touch
                    .zip(self.descent_start_s)
                    .map(|(t1, t0)| t1 - t0),
                rebound_m: self.pelvis_rebound_m,
            },
            standing,
            torque_saturation: strength,
            peak_torques,
        }
    }

    /// Each link's impact: touchdown, velocity, peak force, impulse, energy, penetration and
    /// its weighted share of the damage.
    fn link_impacts(&self, body: &HumanBody, c: &ContactStats) -> Vec<LinkImpact> {
        (0..body.link_names.len())
            .map(|i| LinkImpact {
                link: body.link_names[i].clone(),
                touchdown_s: c.touchdown_s[i],
                impact_velocity_m_s: -c.touchdown_velocity[i],
                peak_force_n: c.peak[i],
                impulse_n_s: c.impulse[i],
                energy_absorbed_j: c.absorbed_j[i],
                max_penetration_m: c.max_depth[i],
                damage_weight: self.weights[i],
                damage_n: self.weights[i] * c.peak[i],
            })
            .collect()
    }

    /// Each DOF's peak torque against its strength in the peak's direction.
    fn peak_torques(&self, body: &HumanBody, monitor: &StepMonitor) -> Vec<PeakTorque> {
        body.figure
            .dofs
            .iter()
            .enumerate()
            .map(|(d, dof)| {
                let peak = monitor.peak_torque[d];
                let limit = match self.torque_limits.get(d) {
                    Some(&(lo, _)) if peak < 0.0 => lo,
                    Some(&(_, hi)) => hi,
                    None => f64::INFINITY,
                };
                PeakTorque {
                    dof: dof.name.clone(),
                    peak_nm: peak,
                    limit_nm: limit,
                    fraction: if limit == 0.0 { 0.0 } else { peak / limit },
                    bound: monitor.first_saturated_s[d].is_some(),
                }
            })
            .collect()
    }
}

/// The DOFs whose torque reached their strength: when first, and for how long.
fn torque_saturation(body: &HumanBody, monitor: &StepMonitor) -> Vec<TorqueSaturation> {
    body.figure
        .dofs
        .iter()
        .enumerate()
        .filter_map(|(d, dof)| {
            monitor.first_saturated_s[d].map(|first| TorqueSaturation {
                dof: dof.name.clone(),
                first_s: first,
                duration_s: monitor.saturated_s[d],
            })
        })
        .collect()
}

/// Whether the sum of the nonnegative `terms` (in order) stays below `limit`, adding only until
/// it does not: the same answer as comparing the whole sum, since floating-point partial sums
/// of nonnegative terms never decrease. A NaN term answers false.
fn below(terms: impl Iterator<Item = f64>, limit: f64) -> bool {
    let mut sum = 0.0;
    for k in terms {
        sum += k;
        let still_below = sum < limit;
        if !still_below {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::below;

    /// Stopping at the limit answers as the whole sum does: over terms spanning twenty orders
    /// of magnitude, limits placed at, just above and just below every partial sum.
    #[test]
    fn below_answers_as_the_whole_sum_does() {
        let terms: Vec<f64> = (0..24)
            .map(|i| {
                let x = ((i * 7919) % 97) as f64 / 97.0;
                x * 10f64.powi((i % 21) - 10)
            })
            .collect();
        let mut partial = 0.0;
        let mut limits = vec![0.0, f64::INFINITY, f64::MIN_POSITIVE];
        for &k in &terms {
            partial += k;
            limits.extend([partial, partial.next_up(), partial.next_down()]);
        }
        let whole: f64 = terms.iter().fold(0.0, |s, k| s + k);
        for limit in limits {
            assert_eq!(
                below(terms.iter().copied(), limit),
                whole < limit,
                "{limit}"
            );
        }
        assert!(below(std::iter::empty(), 1.0));
        assert!(!below([0.1, f64::NAN, 0.1].into_iter(), 1.0));
    }
}
