//! A whole pushed fall (SPEC §3): the fall21 human stands (PD holding a stance), is pushed, and
//! reacts with PD control toward one key pose; joints have friction and range limits, links
//! touch the floor through penalty boxes. [`simulate_fall`] runs it as a plain function;
//! [`ecs`](super::ecs) runs the same phases as systems over components.
//!
//! Each step runs the phases in order: control (choose the active PD target), limits (monitor
//! range excursions), contact (friction anchors, per-link force statistics), dynamics step (the
//! integrator; every stage evaluates PD + joint model + contact + push and the ABA), record
//! (frames, rest detection, divergence checks).

pub mod components;
pub mod config;
pub mod ecs;
pub mod result;

pub use self::components::{
    BodyModel, ContactComponent, DamageRecord, FallParts, JointLimits, JointState, PdController,
    Recorder, Scratch, Workspace,
};
pub use self::config::{FallConfig, Ranges};
pub use self::result::{FallFrame, FallResult, SimError};

use crate::dynamics::forces::contact::{ContactModel, ContactState};
use crate::dynamics::crba::{cholesky_factor, cholesky_solve, crba};
use crate::dynamics::data::Data;
use crate::humanoid::body::{HumanBody, fall21_body};
use crate::dynamics::integrator::{Dynamics, Integrator, IntegratorWorkspace, step};
use crate::dynamics::kinematics::kinematics;
use crate::dynamics::forces::limits::joint_torque;
use crate::dynamics::forces::pd::pd_torque;
use crate::dynamics::spatial::ForceVec;
use crate::humanoid::ranges::RangeTable;
use glam::{DQuat, DVec3};
use std::sync::Arc;

fn cfg_err(field: &str, message: impl Into<String>) -> SimError {
    SimError::Config {
        field: field.into(),
        message: message.into(),
    }
}

fn check_len(field: &str, v: &[f64], n: usize) -> Result<(), SimError> {
    if v.len() != n {
        return Err(cfg_err(
            field,
            format!("needs {n} values (one per fall21 DOF), found {}", v.len()),
        ));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(cfg_err(field, format!("non-finite value {x}")));
    }
    Ok(())
}

fn positive(field: &str, x: f64) -> Result<(), SimError> {
    if !(x.is_finite() && x > 0.0) {
        return Err(cfg_err(
            field,
            format!("must be a positive number, found {x}"),
        ));
    }
    Ok(())
}

/// The stable step bound for a damped oscillator `ẍ = −ω²x − 2ζωẋ`: semi-implicit Euler
/// `h ≤ 2(√(1+ζ²) − ζ)/ω`; RK4 `h ≤ 2.5 / (ω(ζ + √(1+ζ²)))` (the real-axis limit is 2.78 and
/// the imaginary-axis limit 2.83 in units of `1/|λ|`).
pub fn stable_step(integrator: Integrator, omega: f64, zeta: f64) -> f64 {
    if omega <= 0.0 {
        return f64::INFINITY;
    }
    let s = (1.0 + zeta * zeta).sqrt();
    match integrator {
        Integrator::Rk4 => 2.5 / (omega * (zeta + s)),
        Integrator::SemiImplicitEuler { .. } => 2.0 * (s - zeta) / omega,
    }
}

fn scheme_name(i: Integrator) -> &'static str {
    match i {
        Integrator::Rk4 => "RK4",
        Integrator::SemiImplicitEuler {
            implicit_damping: true,
        } => "semi-implicit Euler (implicit damping)",
        Integrator::SemiImplicitEuler { .. } => "semi-implicit Euler",
    }
}

/// Checks the step against the contact and joint stiffnesses before running and, if it is too
/// large, names the most restrictive mode (its bound is the largest usable step): per link the
/// contact bound of [`ContactModel::link_frequency`]; per DOF `ω² = (k_p + k_lim)(H⁻¹)_jj`,
/// `2ζω = d (H⁻¹)_jj` (`d` the joint damping, zero when it is taken implicitly) with `H` the
/// joint-space inertia at the stance.
pub fn check_stability(cfg: &FallConfig, parts: &FallParts) -> Result<(), SimError> {
    let body = &parts.body.body;
    let cm = &parts.body.contact;
    let dt = cfg.dt_s;
    // The most restrictive mode: (bound, what, link, ω, ζ).
    let mut worst: Option<(f64, String, usize, f64, f64)> = None;
    let mut consider =
        |bound: f64, what: &dyn Fn() -> String, link: usize, omega: f64, zeta: f64| {
            if worst.as_ref().is_none_or(|w| bound < w.0) {
                worst = Some((bound, what(), link, omega, zeta));
            }
        };
    for i in 0..body.model.nbodies() {
        let (omega, zeta) = cm.link_frequency(i, &body.model.bodies[i].inertia);
        let bound = stable_step(cfg.integrator, omega, zeta);
        consider(bound, &|| "contact".to_string(), i, omega, zeta);
    }
    let model = &body.model;
    let nv = model.nv;
    let mut data = Data::new(model);
    crba(model, &mut data, &parts.state.q);
    let mut h = data.h.clone();
    cholesky_factor(&mut h, nv).map_err(|e| cfg_err("body", e.to_string()))?;
    let implicit = matches!(
        cfg.integrator,
        Integrator::SemiImplicitEuler {
            implicit_damping: true
        }
    );
    for (d, &k) in body.dof_v.iter().enumerate() {
        let mut e = vec![0.0; nv];
        e[k] = 1.0;
        cholesky_solve(&h, nv, &mut e);
        let w = e[k];
        let stiff = cfg.kp[d].max(cfg.stance_kp[d]) + cfg.limits.limit_kp;
        let damp = if implicit {
            0.0
        } else {
            cfg.kv[d].max(cfg.stance_kv[d]) + cfg.limits.limit_kv.max(cfg.limits.friction_kv)
        };
        let omega = (stiff * w).sqrt();
        let zeta = if omega > 0.0 {
            damp * w / (2.0 * omega)
        } else {
            0.0
        };
        let bound = stable_step(cfg.integrator, omega, zeta);
        let dof = &body.figure.dofs[d];
        consider(
            bound,
            &|| format!("joint {}", dof.name),
            dof.joint,
            omega,
            zeta,
        );
    }
    match worst {
        Some((bound, what, link, omega, zeta)) if dt > bound => Err(SimError::Unstable {
            what,
            body: body.link_names[link].clone(),
            omega,
            zeta,
            dt_s: dt,
            bound_s: bound,
            integrator: scheme_name(cfg.integrator),
        }),
        _ => Ok(()),
    }
}

/// Validates `cfg`, builds the body and its initial state (standing on the floor), and checks
/// the step against the stability bounds.
pub fn build_fall(cfg: &FallConfig) -> Result<FallParts, SimError> {
    positive("dt_s", cfg.dt_s)?;
    positive("duration_s", cfg.duration_s)?;
    positive("record_hz", cfg.record_hz)?;
    positive("gravity", cfg.gravity)?;
    let body = fall21_body(cfg.height_m, cfg.mass_kg, cfg.gravity)?;
    let n = body.dof_v.len();
    for (f, v) in [
        ("stance_pose_deg", &cfg.stance_pose_deg),
        ("stance_kp", &cfg.stance_kp),
        ("stance_kv", &cfg.stance_kv),
        ("key_pose_deg", &cfg.key_pose_deg),
        ("kp", &cfg.kp),
        ("kv", &cfg.kv),
    ] {
        check_len(f, v, n)?;
    }
    for (f, v) in [
        ("stance_kp", &cfg.stance_kp),
        ("stance_kv", &cfg.stance_kv),
        ("kp", &cfg.kp),
        ("kv", &cfg.kv),
    ] {
        if let Some(x) = v.iter().find(|x| **x < 0.0) {
            return Err(cfg_err(f, format!("gains must be ≥ 0, found {x}")));
        }
    }
    let c = &cfg.contact;
    for (f, x) in [
        ("contact.stiffness_per_kg", c.stiffness_per_kg),
        (
            "contact.tangential_stiffness_per_kg",
            c.tangential_stiffness_per_kg,
        ),
    ] {
        positive(f, x)?;
    }
    if !(c.damping_per_kg >= 0.0 && c.tangential_damping_per_kg >= 0.0 && c.friction >= 0.0) {
        return Err(cfg_err("contact", "damping and friction must be ≥ 0"));
    }
    if c.floor_normal.is_nan() || (c.floor_normal.length() - 1.0).abs() >= 1e-9 {
        return Err(cfg_err("contact.floor_normal", "must be a unit vector"));
    }
    for (f, x) in [
        ("limits.friction_kv", cfg.limits.friction_kv),
        ("limits.limit_kp", cfg.limits.limit_kp),
        ("limits.limit_kv", cfg.limits.limit_kv),
    ] {
        if !(x.is_finite() && x >= 0.0) {
            return Err(cfg_err(f, format!("must be ≥ 0, found {x}")));
        }
    }
    let push_link = body.link_index(&cfg.push.link).ok_or_else(|| {
        cfg_err(
            "push.link",
            format!(
                "'{}' is not a fall21 link ({:?})",
                cfg.push.link, body.link_names
            ),
        )
    })?;
    if !(cfg.push.force_n.is_finite()
        && cfg.push.duration_s >= 0.0
        && cfg.push.direction.length() > 0.0)
    {
        return Err(cfg_err(
            "push",
            "force must be finite, duration ≥ 0 and direction non-zero",
        ));
    }
    let mut weights = vec![1.0; body.link_names.len()];
    for (name, w) in &cfg.damage_weights {
        let i = body.link_index(name).ok_or_else(|| {
            cfg_err(
                "damage_weights",
                format!("'{name}' is not a fall21 link ({:?})", body.link_names),
            )
        })?;
        if !(w.is_finite() && *w >= 0.0) {
            return Err(cfg_err(
                "damage_weights",
                format!("weight of '{name}' must be ≥ 0, found {w}"),
            ));
        }
        weights[i] = *w;
    }
    let table = match &cfg.ranges {
        Ranges::Builtin(g) => RangeTable::builtin(*g),
        Ranges::Table(t) => t.clone(),
        Ranges::File(p) => RangeTable::load(p)?,
    };
    let ranges = table.for_model(&body.figure)?;
    let rad = |v: &[f64]| v.iter().map(|x| x.to_radians()).collect::<Vec<_>>();
    let stance = rad(&cfg.stance_pose_deg);

    // Stand the figure on the floor: lowest foot corner at the floor, less the static sink.
    let masses: Vec<f64> = body.model.bodies.iter().map(|b| b.inertia.mass).collect();
    let cm = ContactModel::new(&body.boxes, &masses, cfg.contact);
    let mut q = body.configuration(&stance, DVec3::ZERO, DQuat::IDENTITY);
    let mut data = Data::new(&body.model);
    let zeros = vec![0.0; body.model.nv];
    kinematics(&body.model, &mut data, &q, &zeros);
    let n_up = cfg.contact.floor_normal;
    let mut lowest = f64::INFINITY;
    for (i, corners) in cm.corners.iter().enumerate() {
        for &cl in corners {
            lowest = lowest.min(n_up.dot(data.pos[i] + data.rot[i] * cl));
        }
    }
    let sink = cfg.gravity / (4.0 * cfg.contact.stiffness_per_kg);
    let shift = n_up * (cfg.contact.floor_height - lowest - sink);
    for k in 0..3 {
        q[k] += shift[k];
    }

    let nl = body.link_names.len();
    let nv = body.model.nv;
    let frames = (cfg.duration_s * cfg.record_hz).floor() as usize + 1;
    let total_steps = (cfg.duration_s / cfg.dt_s).round() as u64;
    let body = Arc::new(body);
    let parts = FallParts {
        state: JointState {
            q,
            v: zeros,
            time_s: 0.0,
            steps: 0,
        },
        pd: PdController {
            stance_pose: stance,
            stance_kp: cfg.stance_kp.clone(),
            stance_kv: cfg.stance_kv.clone(),
            key_pose: rad(&cfg.key_pose_deg),
            kp: cfg.kp.clone(),
            kv: cfg.kv.clone(),
            control_start_s: cfg.control_start_s,
            reacting: false,
        },
        limits: JointLimits {
            ranges,
            params: cfg.limits,
            max_excursion: vec![0.0; n],
        },
        contact: ContactComponent {
            state: ContactState::new(nl),
            push: cfg.push.clone(),
            push_link,
            normal: vec![0.0; nl],
            penetration: 0.0,
            depth: vec![0.0; nl],
        },
        damage: DamageRecord {
            weights,
            peak: vec![0.0; nl],
            impulse: vec![0.0; nl],
            max_penetration: 0.0,
            max_depth: vec![0.0; nl],
        },
        recorder: Recorder {
            next_frame: 0,
            frames: Vec::with_capacity(frames),
            rest_energy: cfg.rest_kinetic_energy_j,
            rest_since: None,
            rest_after: cfg.push.start_s + cfg.push.duration_s,
            rest_hold: cfg.rest_hold_s,
            total_steps,
            stop_at_rest: cfg.stop_at_rest,
            dt: cfg.dt_s,
            hz: cfg.record_hz,
            integrator: cfg.integrator,
        },
        ws: Workspace {
            scratch: Scratch {
                data,
                f_ext: vec![ForceVec::ZERO; nl],
                tau: vec![0.0; nv],
                damping: vec![0.0; nv],
                armature: vec![0.0; nv],
                angles: vec![0.0; nv],
                normal: vec![0.0; nl],
                kinematics_at_step: None,
                step_start_ready: false,
            },
            iws: IntegratorWorkspace::new(&body.model),
            error: None,
        },
        body: BodyModel {
            body,
            contact: Arc::new(cm),
        },
    };
    check_stability(cfg, &parts)?;
    Ok(parts)
}

/// The force model of the fall, evaluated at every integrator stage: PD + joint model torques,
/// contact and push forces, then the ABA.
pub struct FallDynamics<'a> {
    /// Body.
    pub body: &'a HumanBody,
    /// Contact model.
    pub contact_model: &'a ContactModel,
    /// Controller.
    pub pd: &'a PdController,
    /// Limits.
    pub limits: &'a JointLimits,
    /// Contact anchors and push.
    pub contact: &'a ContactComponent,
    /// Buffers.
    pub ws: &'a mut Scratch,
}

impl Dynamics for FallDynamics<'_> {
    type Error = SimError;

    fn acceleration(
        &mut self,
        t: f64,
        q: &[f64],
        v: &[f64],
        implicit_dt: Option<f64>,
        qdd: &mut [f64],
    ) -> Result<(), SimError> {
        let model = &self.body.model;
        let ws = &mut *self.ws;
        if ws.step_start_ready {
            // First evaluation of the step: the contact phase already computed kinematics and
            // contact forces at exactly this state.
            ws.step_start_ready = false;
        } else {
            kinematics(model, &mut ws.data, q, v);
            ws.f_ext.fill(ForceVec::ZERO);
            self.contact_model
                .apply(&ws.data, &self.contact.state, &mut ws.f_ext, &mut ws.normal);
        }
        let push = &self.contact.push;
        if push.active(t) {
            let i = self.contact.push_link;
            let f = push.body_force(&ws.data, i);
            ws.f_ext[i] += f;
        }
        model.angles(q, &mut ws.angles);
        let pd = self.pd;
        let (target, kp, kv) = if pd.reacting {
            (&pd.key_pose, &pd.kp, &pd.kv)
        } else {
            (&pd.stance_pose, &pd.stance_kp, &pd.stance_kv)
        };
        for (d, &k) in self.body.dof_v.iter().enumerate() {
            let (th, thd) = (ws.angles[k], v[k]);
            let (t1, d1) = pd_torque(kp[d], kv[d], target[d], 0.0, th, thd);
            let (t2, d2) = joint_torque(&self.limits.params, self.limits.ranges[d], th, thd);
            ws.tau[k] = t1 + t2;
            ws.damping[k] = d1 + d2;
        }
        let arm = match implicit_dt {
            Some(h) => {
                for k in 0..ws.armature.len() {
                    ws.armature[k] = h * ws.damping[k];
                }
                Some(&ws.armature[..])
            }
            None => None,
        };
        crate::dynamics::aba::aba_passes(model, &mut ws.data, &ws.tau, &ws.f_ext, arm);
        qdd.copy_from_slice(&ws.data.qdd);
        if let Some(k) = qdd.iter().position(|x| !x.is_finite()) {
            let b = (0..model.nbodies())
                .rev()
                .find(|&b| model.v_idx[b] <= k)
                .unwrap_or(0);
            return Err(SimError::NonFinite {
                time_s: t,
                body: self.body.link_names[b].clone(),
                quantity: "joint acceleration".into(),
            });
        }
        Ok(())
    }
}

/// Control phase: the key pose becomes the PD target at `control_start_s`.
pub fn control_phase(state: &JointState, pd: &mut PdController) {
    pd.reacting = state.time_s >= pd.control_start_s;
}

/// Limits phase: the largest excursion past each DOF's range at the step start.
pub fn limits_phase(
    body: &BodyModel,
    state: &JointState,
    limits: &mut JointLimits,
    ws: &mut Workspace,
) {
    let ws = &mut ws.scratch;
    body.body.model.angles(&state.q, &mut ws.angles);
    for (d, &k) in body.body.dof_v.iter().enumerate() {
        let (lo, hi) = limits.ranges[d];
        let th = ws.angles[k];
        let ex = (lo - th).max(th - hi).max(0.0);
        limits.max_excursion[d] = limits.max_excursion[d].max(ex);
    }
}

/// Contact phase at the step start: updates the friction anchors, then records per link the
/// normal force (peak), its impulse over the coming step of `dt` seconds and the deepest
/// penetration.
pub fn contact_phase(
    body: &BodyModel,
    state: &JointState,
    contact: &mut ContactComponent,
    damage: &mut DamageRecord,
    dt: f64,
    ws: &mut Workspace,
) {
    let ws = &mut ws.scratch;
    let model = &body.body.model;
    if ws.kinematics_at_step != Some(state.steps) {
        kinematics(model, &mut ws.data, &state.q, &state.v);
    }
    ws.f_ext.fill(ForceVec::ZERO);
    contact.penetration = body.contact.update_and_apply(
        &ws.data,
        &mut contact.state,
        &mut ws.f_ext,
        &mut contact.normal,
        &mut contact.depth,
    );
    ws.step_start_ready = true;
    for i in 0..contact.normal.len() {
        let f = contact.normal[i];
        damage.peak[i] = damage.peak[i].max(f);
        damage.impulse[i] += f * dt;
        damage.max_depth[i] = damage.max_depth[i].max(contact.depth[i]);
    }
    damage.max_penetration = damage.max_penetration.max(contact.penetration);
}

/// Dynamics phase: one integrator step of the full force model.
pub fn dynamics_phase(
    body: &BodyModel,
    state: &mut JointState,
    pd: &PdController,
    limits: &JointLimits,
    contact: &ContactComponent,
    recorder: &Recorder,
    ws: &mut Workspace,
) -> Result<(), SimError> {
    let b = &*body.body;
    let JointState {
        q,
        v,
        time_s,
        steps,
    } = state;
    let Workspace { scratch, iws, .. } = ws;
    // The stages overwrite `data`: the cached kinematics will no longer match any state.
    scratch.kinematics_at_step = None;
    let mut dynm = FallDynamics {
        body: b,
        contact_model: &body.contact,
        pd,
        limits,
        contact,
        ws: scratch,
    };
    step(
        recorder.integrator,
        &b.model,
        iws,
        &mut dynm,
        *time_s,
        recorder.dt,
        q,
        v,
    )?;
    *steps += 1;
    *time_s = *steps as f64 * recorder.dt;
    Ok(())
}

/// Largest speed (m/s or rad/s) and position excursion (m) before a run counts as exploding:
/// far beyond any human motion (even a stiff PD snapping a hand reaches ~500 rad/s), so only a
/// numerical blow-up trips them.
const MAX_SPEED: f64 = 2000.0;
const MAX_EXTENT: f64 = 100.0;

/// Record phase after the step: divergence checks (non-finite or exploding state names the
/// body), frames at the record rate, and rest detection from the kinetic energy.
pub fn record_phase(
    body: &BodyModel,
    state: &JointState,
    recorder: &mut Recorder,
    ws: &mut Workspace,
) -> Result<(), SimError> {
    let b = &*body.body;
    let model = &b.model;
    let sc = &mut ws.scratch;
    let t = state.time_s;
    kinematics(model, &mut sc.data, &state.q, &state.v);
    sc.kinematics_at_step = Some(state.steps);
    let mut ke = 0.0;
    for i in 0..model.nbodies() {
        let (p, vel) = (sc.data.pos[i], sc.data.v[i]);
        let name = || b.link_names[i].clone();
        if !p.is_finite() || !sc.data.rot[i].is_finite() {
            return Err(SimError::NonFinite {
                time_s: t,
                body: name(),
                quantity: "position".into(),
            });
        }
        if !vel.is_finite() {
            return Err(SimError::NonFinite {
                time_s: t,
                body: name(),
                quantity: "velocity".into(),
            });
        }
        let speed = vel.ang.length().max(vel.lin.length());
        if speed > MAX_SPEED {
            return Err(SimError::Exploding {
                time_s: t,
                body: name(),
                quantity: "speed".into(),
                value: speed,
                limit: MAX_SPEED,
            });
        }
        if p.abs().max_element() > MAX_EXTENT {
            return Err(SimError::Exploding {
                time_s: t,
                body: name(),
                quantity: "position".into(),
                value: p.abs().max_element(),
                limit: MAX_EXTENT,
            });
        }
        ke += model.bodies[i].inertia.kinetic_energy(vel);
    }
    // Rest counts only once the push is over (a figure standing still before it is not
    // "at rest" on the floor).
    if ke < recorder.rest_energy && t >= recorder.rest_after {
        recorder.rest_since.get_or_insert(t);
    } else {
        recorder.rest_since = None;
    }
    if state.steps >= frame_step(recorder, recorder.next_frame) {
        recorder.frames.push(frame(b, state, sc));
        recorder.next_frame += 1;
    }
    Ok(())
}

/// The step at which frame `k` is taken: the one nearest to `k / hz`.
fn frame_step(rec: &Recorder, k: u64) -> u64 {
    (k as f64 / (rec.hz * rec.dt)).round() as u64
}

fn frame(b: &HumanBody, state: &JointState, sc: &mut Scratch) -> FallFrame {
    let q = &state.q;
    b.model.angles(q, &mut sc.angles);
    let angles = b.dof_v.iter().map(|&k| sc.angles[k]).collect();
    let head = b.link_index("head").unwrap_or(0);
    let head_com = sc.data.pos[head] + sc.data.rot[head] * b.model.bodies[head].inertia.com;
    FallFrame {
        time_s: state.time_s,
        root_position: DVec3::new(q[0], q[1], q[2]),
        root_orientation: DQuat::from_xyzw(q[3], q[4], q[5], q[6]),
        angles,
        head_height_m: head_com.y,
    }
}

/// One full step of all phases in order: control → limits → contact → dynamics step → record.
pub fn step_fall(parts: &mut FallParts) -> Result<(), SimError> {
    let FallParts {
        body,
        state,
        pd,
        limits,
        contact,
        damage,
        recorder,
        ws,
    } = parts;
    control_phase(state, pd);
    limits_phase(body, state, limits, ws);
    contact_phase(body, state, contact, damage, recorder.dt, ws);
    dynamics_phase(body, state, pd, limits, contact, recorder, ws)?;
    record_phase(body, state, recorder, ws)
}

/// The first frame (t = 0), recorded before stepping.
pub fn record_initial(parts: &mut FallParts) {
    let FallParts {
        body,
        state,
        recorder,
        ws,
        ..
    } = parts;
    kinematics(&body.body.model, &mut ws.scratch.data, &state.q, &state.v);
    ws.scratch.kinematics_at_step = Some(state.steps);
    let f = frame(&body.body, state, &mut ws.scratch);
    recorder.frames.push(f);
    recorder.next_frame = 1;
}

/// Collects the result of a finished run from its components; the damage is
/// `D = Σ w_i f_i` (eq. 5.1).
pub fn finish(
    body: &BodyModel,
    state: &JointState,
    limits: &JointLimits,
    damage: &DamageRecord,
    recorder: &Recorder,
) -> FallResult {
    let b = &body.body;
    let d = damage;
    let total = d.weights.iter().zip(&d.peak).map(|(w, f)| w * f).sum();
    let end = state.time_s;
    let rest_time_s = recorder
        .rest_since
        .filter(|&t0| end - t0 >= recorder.rest_hold);
    FallResult {
        dof_names: b.figure.dof_names(),
        link_names: b.link_names.clone(),
        frames: recorder.frames.clone(),
        record_hz: recorder.hz,
        damage: total,
        peak_vertical_force_n: d.peak.clone(),
        impulse_n_s: d.impulse.clone(),
        max_penetration_m: d.max_penetration,
        max_penetration_by_link_m: d.max_depth.clone(),
        max_limit_excursion_rad: limits.max_excursion.clone(),
        came_to_rest: rest_time_s.is_some(),
        rest_time_s,
        steps: state.steps,
        dt_s: recorder.dt,
        height_m: b.figure.height,
    }
}

/// Simulates one pushed fall from `config` and returns its record.
pub fn simulate_fall(config: &FallConfig) -> Result<FallResult, SimError> {
    let mut parts = build_fall(config)?;
    record_initial(&mut parts);
    while !parts.recorder.finished(&parts.state) {
        step_fall(&mut parts)?;
    }
    Ok(finish(
        &parts.body,
        &parts.state,
        &parts.limits,
        &parts.damage,
        &parts.recorder,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Largest |x| after `n` steps of `ẍ = −ω²x − 2ζωẋ` from x = 1 with the given scheme.
    fn oscillate(integrator: Integrator, omega: f64, zeta: f64, h: f64, n: usize) -> f64 {
        let f = |x: f64, v: f64| -omega * omega * x - 2.0 * zeta * omega * v;
        let (mut x, mut v) = (1.0f64, 0.0f64);
        let mut peak: f64 = 0.0;
        for _ in 0..n {
            match integrator {
                Integrator::SemiImplicitEuler { .. } => {
                    v += h * f(x, v);
                    x += h * v;
                }
                Integrator::Rk4 => {
                    let (k1x, k1v) = (v, f(x, v));
                    let (k2x, k2v) = (v + 0.5 * h * k1v, f(x + 0.5 * h * k1x, v + 0.5 * h * k1v));
                    let (k3x, k3v) = (v + 0.5 * h * k2v, f(x + 0.5 * h * k2x, v + 0.5 * h * k2v));
                    let (k4x, k4v) = (v + h * k3v, f(x + h * k3x, v + h * k3v));
                    x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
                    v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
                }
            }
            peak = peak.max(x.abs());
        }
        peak
    }

    #[test]
    fn the_step_bound_separates_stable_from_unstable() {
        let euler = Integrator::SemiImplicitEuler {
            implicit_damping: false,
        };
        for zeta in [0.0, 0.3, 1.0, 3.0] {
            let b = stable_step(euler, 100.0, zeta);
            assert!(
                oscillate(euler, 100.0, zeta, 0.99 * b, 20_000) < 10.0,
                "ζ={zeta}"
            );
            assert!(
                oscillate(euler, 100.0, zeta, 1.02 * b, 20_000) > 1e3,
                "ζ={zeta}"
            );
            // RK4's bound is conservative: stable at it.
            let r = stable_step(Integrator::Rk4, 100.0, zeta);
            assert!(
                oscillate(Integrator::Rk4, 100.0, zeta, r, 20_000) <= 1.0 + 1e-9,
                "ζ={zeta}"
            );
        }
    }
}
