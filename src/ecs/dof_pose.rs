//! A character's pose as DOF values ([`DofPose`]: θ and θ̇ per DOF and root channel, written by
//! the primitive players or any other source) and its binding to a figure ([`FigureBinding`]):
//! [`pose_from_dofs`] turns it into the joint state, which then goes through forward kinematics
//! and recording like any other character's.

use std::sync::Arc;

use bevy_ecs::prelude::*;
use glam::{DQuat, DVec3};

use super::motion::JointState;
use super::physics::PhysicsBody;
use crate::humanoid::{Figure, ROOT_CHANNELS};
use crate::primitive::{Primitive, PrimitiveError};

/// A character's current DOF state, written by its motion source (e.g. a primitive player).
#[derive(Component, Clone, Debug, PartialEq, Default)]
pub struct DofPose {
    /// DOF names (shared).
    pub names: Arc<[String]>,
    /// θ per DOF (rad, or m).
    pub theta: Vec<f64>,
    /// θ̇ per DOF (rad/s, or m/s).
    pub theta_dot: Vec<f64>,
}

impl DofPose {
    /// A pose for the DOFs of `p`, at its demonstrated start, at rest.
    pub fn for_primitive(p: &Primitive) -> DofPose {
        DofPose {
            names: p.names().into(),
            theta: p.dofs.iter().map(|d| d.start).collect(),
            theta_dot: vec![0.0; p.dofs.len()],
        }
    }
}

/// Which entries of a character's [`DofPose`] are its model's DOFs and its six root channels
/// (`root_tx, root_ty, root_tz` in metres, `root_rx, root_ry, root_rz` a rotation vector).
#[derive(Component, Clone, Debug)]
pub struct FigureBinding {
    /// The model the pose drives.
    pub model: Arc<Figure>,
    dof_cols: Vec<usize>,
    root_cols: [usize; 6],
}

impl FigureBinding {
    /// Binds pose entries named `names` to `model`; every model DOF and root channel must be
    /// among them.
    pub fn new(model: Arc<Figure>, names: &[String]) -> Result<FigureBinding, PrimitiveError> {
        let col = |n: &str| {
            names
                .iter()
                .position(|x| x == n)
                .ok_or_else(|| PrimitiveError::DofMismatch {
                    what: format!("the pose has no channel '{n}'"),
                })
        };
        let dof_cols = model
            .dofs
            .iter()
            .map(|d| col(&d.name))
            .collect::<Result<_, _>>()?;
        let mut root_cols = [0; 6];
        for (k, n) in ROOT_CHANNELS.iter().enumerate() {
            root_cols[k] = col(n)?;
        }
        Ok(FigureBinding {
            model,
            dof_cols,
            root_cols,
        })
    }

    /// For each model DOF (model order), its entry in the pose.
    pub fn dof_columns(&self) -> &[usize] {
        &self.dof_cols
    }

    /// The pose entries of the six root channels (`root_tx … root_rz`).
    pub fn root_columns(&self) -> [usize; 6] {
        self.root_cols
    }
}

/// Sets every bound kinematic character's joint state from its DOF pose: the root from the
/// root channels, every other joint's rotation from its DOF angles (see
/// [`Figure::local_rotations`]). A simulated character's joint state comes from its body instead
/// ([`publish_body_pose`](super::human::publish_body_pose)); its DOF pose is the PD target.
pub fn pose_from_dofs(
    mut q: Query<(&FigureBinding, &DofPose, &mut JointState), Without<PhysicsBody>>,
) {
    for (b, pose, mut state) in &mut q {
        let angles: Vec<f64> = b.dof_cols.iter().map(|&c| pose.theta[c]).collect();
        let st = &mut *state;
        b.model.local_rotations(&angles, &mut st.rotations);
        for (t, j) in st.translations.iter_mut().zip(&b.model.joints) {
            *t = j.offset;
        }
        let r = |k: usize| pose.theta[b.root_cols[k]];
        st.translations[0] = DVec3::new(r(0), r(1), r(2));
        st.rotations[0] = DQuat::from_scaled_axis(DVec3::new(r(3), r(4), r(5)));
    }
}
