//! The names most programs need: `use marionette::prelude::*;`.
//!
//! Only re-exports. The crate's [`Result`](crate::Result) alias is left out so that it does not
//! shadow `std`'s; write `marionette::Result<T>`.

pub use crate::Error;

// Motion data: BVH files (read with `bvh::parse_file`), skeletons, clips, keyframed clips.
pub use crate::bvh::{self, Bvh};
pub use crate::clips::KeyframeClip;
pub use crate::skeleton::{Clip, Skeleton, Transform, forward_kinematics};

// The engine's models and mapping real skeletons onto them.
pub use crate::humanoid::AgeGroup;
pub use crate::humanoid::{Figure, FigureClip, fall21, humanoid24};
pub use crate::mapping::{Mapping, effector_errors, retarget};

// Ground contact and flight phases.
pub use crate::analysis::{Contacts, Span, clip_contacts};

// Motor primitives: learn, adjust, connect, blend.
pub use crate::primitive::{
    BlendPlacement, Gamma, LearnConfig, Primitive, Relearn, Trajectory, blend, connect,
    find_jump_events,
};

// The pushed fall.
pub use crate::experiments::fall::{FallConfig, FallResult, simulate_fall};

// The ECS wiring: the clock, the sets, each domain's systems, characters and the World pool.
pub use crate::ecs::human::{HumanFigure, add_human_physics_systems, human_physics};
pub use crate::ecs::physics::{
    BodyState, ExternalForces, FloorContact, JointLimits, PdController, PhysicsBundle,
    add_physics_systems,
};
pub use crate::ecs::primitive::{BlendPlayer, PrimitivePlayer, add_primitive_systems};
pub use crate::ecs::{
    Clock, DofPose, MotionSet, Recorder, WorldPool, add_core_systems, add_motion_systems,
    spawn_clip_character, spawn_primitive_character,
};
pub use crate::experiments::fall::{add_fall_systems, build_fall_world, run_fall_world};

// Pictures and scenes.
#[cfg(feature = "render")]
pub use crate::render::{Track, animation_gif, filmstrip_png};
#[cfg(feature = "render")]
pub use crate::scene::Scene;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_readme_pipeline_compiles_from_the_prelude() -> Result<(), Error> {
        let clip = KeyframeClip::parse(
            include_str!("../scenes/clips/normal_jump.ron"),
            "normal_jump.ron",
        )?
        .to_figure_clip();
        let skeleton: Skeleton = clip.to_clip().skeleton;
        let mapping = Mapping::detect(&skeleton)?;
        let on24 = retarget(&clip.to_clip(), &mapping, &humanoid24())?;
        assert_eq!(on24.frame_count(), clip.frame_count());
        let learned = Primitive::learn("jump", &on24.to_trajectory(), &LearnConfig::default())?;
        assert!(!learned.primitive.dofs.is_empty());
        Ok(())
    }
}
