//! What a pushed fall reports ([`FallResult`], frame by frame and per link) and why one can
//! fail ([`SimError`]: bad configuration, an unstable step, or a runaway state with its time,
//! body and quantity).

pub use super::recorder::StandingStart;
use crate::dynamics::EquilibriumError;
use crate::dynamics::pipeline::StepError;
use crate::humanoid::HumanError;
use crate::humanoid::RangeError;
use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

/// One recorded frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FallFrame {
    /// Time (s).
    pub time_s: f64,
    /// Pelvis (root) position, world (m).
    pub root_position: DVec3,
    /// Pelvis orientation (body → world).
    pub root_orientation: DQuat,
    /// Every fall21 DOF angle in model order (rad).
    pub angles: Vec<f64>,
    /// Height of the head's centre of mass above the floor (m).
    pub head_height_m: f64,
}

/// The outcome of a fall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FallResult {
    /// DOF names (fall21 model order), matching `FallFrame::angles`.
    pub dof_names: Vec<String>,
    /// Link names, matching the per-link vectors.
    pub link_names: Vec<String>,
    /// Frames at `record_hz`: frame `k` is the state at the step nearest to `k / record_hz`.
    pub frames: Vec<FallFrame>,
    /// Frame rate of `frames` (Hz).
    pub record_hz: f64,
    /// Damage `D = Σ w_i f_i` (N): the paper's eq. 5.1.
    pub damage: f64,
    /// Peak vertical (normal) floor force per link, f_i (N).
    pub peak_vertical_force_n: Vec<f64>,
    /// Normal impulse per link (N·s).
    pub impulse_n_s: Vec<f64>,
    /// Deepest corner penetration into the floor over the run (m).
    pub max_penetration_m: f64,
    /// Deepest corner penetration per link over the run (m).
    pub max_penetration_by_link_m: Vec<f64>,
    /// Largest excursion of any DOF past its range over the run (rad), per DOF.
    pub max_limit_excursion_rad: Vec<f64>,
    /// True if the kinetic energy stayed below the rest threshold for the hold time at the end.
    pub came_to_rest: bool,
    /// Time from which the body stayed at rest (s).
    pub rest_time_s: Option<f64>,
    /// Integration steps taken.
    pub steps: u64,
    /// Time step (s).
    pub dt_s: f64,
    /// Standing height of the simulated subject (m).
    pub height_m: f64,
    /// The impact of every link (link order).
    pub impacts: Vec<LinkImpact>,
    /// The pelvis's descent and impact, to set beside falls of real older adults.
    pub pelvis: PelvisImpact,
    /// The standing start before the push.
    pub standing: StandingStart,
    /// Every DOF whose PD torque reached its strength limit: when first, and for how long.
    pub torque_saturation: Vec<TorqueSaturation>,
    /// Per DOF its peak PD torque against its strength limit.
    #[serde(default)]
    pub peak_torques: Vec<PeakTorque>,
}

/// One link's impact with the floor over a fall.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LinkImpact {
    /// Link name.
    pub link: String,
    /// First step start at which it touched the floor (s), if it did.
    pub touchdown_s: Option<f64>,
    /// Speed into the floor of its contact box's centre at touchdown (m/s, positive = downward).
    pub impact_velocity_m_s: f64,
    /// Peak normal force (N).
    pub peak_force_n: f64,
    /// Normal impulse (N·s).
    pub impulse_n_s: f64,
    /// Energy the normal contact absorbed, `∫ −Σ f_n ż dt` (J).
    pub energy_absorbed_j: f64,
    /// Deepest corner penetration (m).
    pub max_penetration_m: f64,
    /// Damage weight w_i.
    pub damage_weight: f64,
    /// Its share of the damage, `w_i f_i` (N).
    pub damage_n: f64,
}

/// The pelvis in the fall, to set beside video analyses of real falls of older adults: a hip
/// impact velocity of about 2.1 ± 0.6 m/s and a descent time of 0.58 ± 0.26 s from the start of
/// descent (the values issue 9 quotes; the study is Choi, Wakeling & Robinovitch 2015,
/// *Kinematic analysis of video-captured falls experienced by older adults in long-term care*,
/// J. Biomech. 48:911–920).
#[derive(Clone, Copy, Debug, PartialEq, Default, Serialize, Deserialize)]
pub struct PelvisImpact {
    /// Speed into the floor of the pelvis box's centre at touchdown (m/s).
    pub impact_velocity_m_s: Option<f64>,
    /// Start of descent: first time after the push starts that the pelvis's centre of mass
    /// moves down faster than 0.1 m/s (s).
    pub descent_start_s: Option<f64>,
    /// Touchdown of the pelvis (s).
    pub touchdown_s: Option<f64>,
    /// Touchdown − start of descent (s).
    pub descent_time_s: Option<f64>,
    /// Rebound: the highest the pelvis box's lowest corner rose above the floor after the
    /// pelvis first touched it (m).
    pub rebound_m: f64,
}

/// A DOF's largest PD torque against its strength limit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PeakTorque {
    /// DOF name.
    pub dof: String,
    /// The PD torque of largest magnitude (N·m, signed, after the strength clamp).
    pub peak_nm: f64,
    /// The strength limit on that side (N·m, signed; infinite when unbounded).
    pub limit_nm: f64,
    /// `peak / limit` (1 = the limit bound).
    pub fraction: f64,
    /// The limit bound at some step.
    pub bound: bool,
}

/// A DOF whose PD torque reached its strength limit.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TorqueSaturation {
    /// DOF name.
    pub dof: String,
    /// First time at the limit (s).
    pub first_s: f64,
    /// Time spent at the limit (s).
    pub duration_s: f64,
}

impl FallResult {
    /// The recorded motion as a clip on the fall21 model (scaled to the subject's height), ready
    /// for BVH output and pictures.
    pub fn to_figure_clip(&self) -> crate::humanoid::FigureClip {
        crate::humanoid::FigureClip {
            model: crate::humanoid::fall21().scaled_to_height(self.height_m),
            frame_time: 1.0 / self.record_hz,
            root_translation: self.frames.iter().map(|f| f.root_position).collect(),
            root_rotation: self.frames.iter().map(|f| f.root_orientation).collect(),
            angles: self
                .frames
                .iter()
                .flat_map(|f| f.angles.iter().copied())
                .collect(),
        }
    }
}

/// Why a fall could not be simulated.
#[derive(Debug, thiserror::Error)]
pub enum SimError {
    /// A configuration field is invalid.
    #[error("fall configuration: {field}: {message}")]
    Config {
        /// Field name.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The body could not be built.
    #[error(transparent)]
    Body(#[from] HumanError),
    /// The joint ranges could not be resolved.
    #[error(transparent)]
    Ranges(#[from] RangeError),
    /// The step is too large for a stiffness (checked before running).
    #[error(
        "dt = {dt_s} s exceeds the {integrator} stability bound {bound_s:.3e} s for the {what} of '{body}' \
         (natural frequency {omega:.1} rad/s, damping ratio {zeta:.2}); lower dt_s or the {what} stiffness"
    )]
    Unstable {
        /// `"contact"` or `"joint <dof name>"`.
        what: String,
        /// Link concerned.
        body: String,
        /// Natural frequency bound (rad/s).
        omega: f64,
        /// Damping ratio.
        zeta: f64,
        /// Step given (s).
        dt_s: f64,
        /// Largest stable step (s).
        bound_s: f64,
        /// Scheme name.
        integrator: &'static str,
    },
    /// A step went wrong: a non-finite or runaway state, with time, body and value.
    #[error(transparent)]
    Step(#[from] StepError),
    /// The settled standing body has no static equilibrium near where it came to rest.
    #[error("settling the standing body: {0}")]
    Equilibrium(#[from] EquilibriumError),
}
