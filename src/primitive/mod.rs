//! Motor primitives: Ijspeert-style dynamical movement primitives (DMPs) learned from joint-angle
//! trajectories, adjusted (goal, duration), connected and blended (SPEC §1, the paper
//! `primitive-blending.ja.txt`).
//!
//! The kernel works on plain data and knows nothing about skeletons:
//!
//! - in: a [`Trajectory`] — a time step `dt` (s), DOF names and `frames × dofs` values (radians, or
//!   metres for the root translation DOFs), row-major;
//! - out: a [`Primitive`] (one DMP per DOF sharing one canonical phase), rollouts as
//!   [`Trajectory`] or [`Samples`] at requested times, blends, sequences and jump events.
//!
//! **Root motion** is carried as six ordinary DOFs named [`ROOT_DOF_NAMES`]: translation
//! `root_tx, root_ty, root_tz` (metres) and the root orientation as a rotation vector
//! `root_rx, root_ry, root_rz` (radians; the caller keeps it continuous, i.e. unwrapped). They share
//! the canonical phase with the joint DOFs and are learned, adjusted and blended like them.
//!
//! **Shared canonical phase.** The paper's canonical variable x runs from s to g of each DOF and
//! enters the kernels only through x̃ = (x − s)/(g − s). For the second-order system
//! `τ v̇ = α_v(β_v(g − x) − v), τ ẋ = v` the normalised x̃ obeys the same equation with s = 0, g = 1,
//! independently of s and g, so one phase x̃ ∈ [0, 1] is computed once for all DOFs
//! ([`CanonicalSystem`]); the paper's per-DOF canonical velocity is v = (g − s)·ṽ, with ṽ the shared
//! phase velocity. This is exactly the paper's equations for every DOF and removes the g = s division.
//!
//! **Time.** τ is the movement duration in seconds. All dynamics are integrated in normalised time
//! u = t/τ ∈ [0, 1] over the movement, so playing a primitive at τ′ = 2τ traces the same path in
//! twice the time (velocities halve). See [`rollout`] for the integrator.
//!
//! **Wiring** (plain data in and out):
//!
//! ```
//! use marionette::primitive::synthetic::knee_jump;
//! use marionette::primitive::{blend, BlendPlacement, Gamma, LearnConfig, Primitive, Relearn, Trajectory};
//!
//! let fps = 120.0;
//! let demo = |peak_deg: f64, secs: f64| {
//!     let knee = knee_jump(peak_deg.to_radians(), secs, fps);
//!     Trajectory::from_columns(1.0 / fps, vec!["left_knee".into()], &[knee]).unwrap()
//! };
//! let cfg = LearnConfig::default(); // the paper's Ijspeert 2002, ridge fit
//! let low = Primitive::learn("low jump", &demo(70.0, 0.9), &cfg).unwrap();
//! let normal = Primitive::learn("normal jump", &demo(110.0, 1.2), &cfg).unwrap();
//! assert!(normal.fit.median_angle_rmse_deg().unwrap() < 0.5);
//! // The paper's high jump: A = low, B = normal, same span, γ = −0.5, learned again as one.
//! let span = BlendPlacement { a_start: 0.0, a_end: 1.2, b_start: 0.0, b_end: 1.2 };
//! let high = blend(&low.primitive, &normal.primitive, &span, &Gamma::Constant(-0.5),
//!                  1.0 / fps, Relearn::Whole, &cfg).unwrap();
//! let played: Trajectory = high.primitives[0].primitive.rollout(1.0 / fps, None).unwrap();
//! let peak = played.column(0).into_iter().fold(f64::MIN, f64::max).to_degrees();
//! assert!(peak > 80.0); // deeper than the normal jump's crouch
//! ```
//!
//! Files: [`canonical`] (shared phase), [`basis`] (kernels), [`dmp`] (one-DOF transformation
//! system, formulations), [`definition`] (the multi-DOF primitive as data and its invariants),
//! [`learn`] (LWR and ridge), [`rollout`] (fixed-step integrator), [`primitive`] (learn, adjust,
//! sample, fit, RON io), [`mod@connect`], [`mod@blend`], [`events`]; the ECS players are in
//! [`crate::ecs`].

pub(crate) mod basis;
pub(crate) mod blend;
pub(crate) mod canonical;
pub(crate) mod connect;
pub(crate) mod definition;
pub(crate) mod dmp;
pub(crate) mod error;
pub(crate) mod events;
pub(crate) mod learn;
#[allow(clippy::module_inception)] // the brief names the file `primitive/primitive.rs`
pub(crate) mod primitive;
pub(crate) mod rollout;
pub mod synthetic;
pub(crate) mod trajectory;

pub use basis::Basis;
pub use blend::{
    Arrangement, BlendPlacement, BlendResult, GAMMA_MAX, GAMMA_MIN, Gamma, Relearn, blend,
};
pub use connect::{Connected, HANDOVER_WINDOW_S, HandOver, Junction, connect};

pub use canonical::{CanonicalSystem, Phase};

pub use dmp::{Formulation, SpatialScaling};
pub use error::PrimitiveError;
pub use events::{EventConfig, JumpEvents, find_jump_events};

pub use learn::{KernelCount, LearnConfig, Regression, learn_dofs};
pub use primitive::{
    DofFit, DofPrimitive, FitReport, Learned, PRIMITIVE_FORMAT_VERSION, Primitive, ROOT_DOF_NAMES,
};
pub use rollout::{DofState, Rollout, Samples};
pub use trajectory::{DofUnit, Trajectory};
