//! What a primitive is, as data: M = {T, D_j | j = 1..N_DOF} (the paper's eq. 6) with one
//! D = {s, g, w_i} per DOF, its invariants ([`Primitive::validate`]) and plain accessors. The
//! lowest file of the primitive's own: [`learn`](super::learn) builds [`DofPrimitive`]s,
//! [`rollout`](super::rollout) plays a [`Primitive`], and [`primitive`](super::primitive)
//! (learning, adjusting, sampling, fit reports, RON files) uses both, so dependencies point one
//! way.

use serde::{Deserialize, Serialize};

use super::basis::Basis;
use super::dmp::{Formulation, SpatialScaling};
use super::error::{PrimitiveError, Result, require_finite, require_positive};

/// Version of the primitive RON format written by this build (and the newest it reads).
pub const PRIMITIVE_FORMAT_VERSION: u32 = 1;

/// Names of the root-motion DOFs: translation (metres) and orientation as a rotation vector
/// (radians), learned and played like any joint DOF.
pub const ROOT_DOF_NAMES: [&str; 6] = [
    "root_tx", "root_ty", "root_tz", "root_rx", "root_ry", "root_rz",
];

/// The DMP of one DOF: the paper's D = {s, g, w_i} (the gains, τ and the kernels c_i, σ_i are
/// shared by the primitive).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DofPrimitive {
    /// DOF name (e.g. `left_knee`, `root_ty`).
    pub name: String,
    /// Start s = θ(0) of the demonstration (rad, or m).
    pub start: f64,
    /// Goal g (rad, or m); change it to scale the motion in space.
    pub goal: f64,
    /// θ′(0) = τ·θ̇(0): the demonstration's initial rate in normalised time (0 for a clip that
    /// starts at rest; a clip starting mid-motion keeps its velocity, scaled with the duration).
    pub start_rate: f64,
    /// How the forcing follows the goal (see [`SpatialScaling`]).
    pub scaling: SpatialScaling,
    /// Kernel weights w_i at the demonstration's amplitude (paper's w_i = these / (g_d − s_d)).
    pub weights: Vec<f64>,
}

/// A motor primitive: one DMP per DOF sharing one canonical phase. Saved as RON with a
/// `format_version`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Primitive {
    /// Format version ([`PRIMITIVE_FORMAT_VERSION`] when written by this build).
    pub format_version: u32,
    /// Human-readable name (`jump`, `knee kick`…).
    pub name: String,
    /// DMP formulation and gains, shared by all DOFs.
    pub formulation: Formulation,
    /// τ: the movement duration in seconds (the paper's T); change it to scale in time.
    pub duration: f64,
    /// The kernels, shared by all DOFs.
    pub basis: Basis,
    /// One DMP per DOF.
    pub dofs: Vec<DofPrimitive>,
}

impl Primitive {
    /// Checks every invariant: version, duration > 0, formulation, basis, unique non-empty DOF
    /// names, one weight per kernel, finite numbers, non-zero scaling references.
    pub fn validate(&self) -> Result<()> {
        if self.format_version == 0 {
            return Err(PrimitiveError::InvalidParameter {
                field: "format_version".into(),
                reason: format!(
                    "versions start at 1 (this build writes {PRIMITIVE_FORMAT_VERSION})"
                ),
            });
        }
        if self.format_version > PRIMITIVE_FORMAT_VERSION {
            return Err(PrimitiveError::UnsupportedVersion {
                source_name: self.name.clone(),
                found: self.format_version,
                supported: PRIMITIVE_FORMAT_VERSION,
            });
        }
        require_positive("duration", self.duration)?;
        self.formulation.validate()?;
        self.basis.validate()?;
        if self.dofs.is_empty() {
            return Err(PrimitiveError::InvalidParameter {
                field: "dofs".into(),
                reason: "a primitive needs at least one DOF".into(),
            });
        }
        for (j, d) in self.dofs.iter().enumerate() {
            let field = |f: &str| format!("dofs[{j}].{f}");
            if d.name.is_empty() {
                return Err(PrimitiveError::InvalidParameter {
                    field: field("name"),
                    reason: "empty".into(),
                });
            }
            if self.dofs[..j].iter().any(|o| o.name == d.name) {
                return Err(PrimitiveError::InvalidParameter {
                    field: field("name"),
                    reason: format!("`{}` appears twice", d.name),
                });
            }
            if d.weights.len() != self.basis.len() {
                return Err(PrimitiveError::InvalidParameter {
                    field: field("weights"),
                    reason: format!(
                        "{} weights for {} kernels",
                        d.weights.len(),
                        self.basis.len()
                    ),
                });
            }
            require_finite(&field("weights"), &d.weights)?;
            require_finite(&field("start"), &[d.start, d.goal, d.start_rate])?;
            if let SpatialScaling::GoalMinusStart { reference } = d.scaling
                && (reference == 0.0 || !reference.is_finite())
            {
                return Err(PrimitiveError::InvalidParameter {
                    field: field("scaling.reference"),
                    reason: format!("must be finite and non-zero, got {reference}"),
                });
            }
        }
        Ok(())
    }

    /// DOF names in order.
    pub fn names(&self) -> Vec<String> {
        self.dofs.iter().map(|d| d.name.clone()).collect()
    }

    /// Index of the DOF called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.dofs.iter().position(|d| d.name == name)
    }

    /// Goals g per DOF.
    pub fn goals(&self) -> Vec<f64> {
        self.dofs.iter().map(|d| d.goal).collect()
    }
}
