//! The falling paper's controller: PD holds the standing pose until the reaction time, then
//! drives toward one key pose (θ̇_d = 0), the pose the genetic algorithm evolves.

use bevy_ecs::prelude::*;

use crate::dynamics::forces::pd::PdTargets;

/// Stance and key-pose PD settings and the time the reaction starts.
#[derive(Component, Clone, Debug, PartialEq)]
pub struct FallController {
    /// Targets and gains that hold the stance.
    pub stance: PdTargets,
    /// Targets (the key pose θ_d) and gains (k_p, k_v) of the reaction.
    pub key: PdTargets,
    /// Time the reaction starts (s).
    pub start_s: f64,
    /// True once the key pose is the active target.
    pub reacting: bool,
}

impl FallController {
    /// Writes the targets active at time `t` (s) into `pd`: the stance before `start_s`, the key
    /// pose from then on.
    pub fn apply(&mut self, t: f64, pd: &mut PdTargets) {
        let reacting = t >= self.start_s;
        if reacting != self.reacting {
            self.reacting = reacting;
            pd.clone_from(if reacting { &self.key } else { &self.stance });
        }
    }
}
