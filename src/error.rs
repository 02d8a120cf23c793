//! The crate's one error type, [`Error`]: every module's error as a variant, so `?` carries any
//! of them to a caller that wants one type. Each variant shows its module error's message as is.

/// Any error of the crate; the variant says which module it came from.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Reading or writing BVH.
    #[error(transparent)]
    Bvh(#[from] crate::bvh::BvhError),
    /// Building or windowing a clip.
    #[error(transparent)]
    Clip(#[from] crate::skeleton::ClipError),
    /// A keyframed clip.
    #[error(transparent)]
    Keyframes(#[from] crate::clips::KeyframeError),
    /// Mapping a skeleton onto a model.
    #[error(transparent)]
    Mapping(#[from] crate::mapping::MappingError),
    /// An unknown model or a trajectory that does not fit one.
    #[error(transparent)]
    Figure(#[from] crate::humanoid::FigureError),
    /// A joint-range table.
    #[error(transparent)]
    Ranges(#[from] crate::humanoid::RangeError),
    /// Building the human body (height, mass, joints).
    #[error(transparent)]
    Body(#[from] crate::humanoid::HumanError),
    /// A DOF without a row in the strength table.
    #[error(transparent)]
    Strength(#[from] crate::humanoid::strength::NoStrength),
    /// An articulated-body model description.
    #[error(transparent)]
    Dynamics(#[from] crate::dynamics::ModelError),
    /// A joint-space inertia matrix that is not positive definite.
    #[error(transparent)]
    Inertia(#[from] crate::dynamics::NotPositiveDefinite),
    /// Balancing a body on the floor (its static equilibrium).
    #[error(transparent)]
    Equilibrium(#[from] crate::dynamics::EquilibriumError),
    /// Motor primitives: learning, playing, blending, connecting, files.
    #[error(transparent)]
    Primitive(#[from] crate::primitive::PrimitiveError),
    /// A pushed-fall simulation.
    #[error(transparent)]
    Fall(#[from] crate::experiments::fall::SimError),
    /// A simulation step: a non-finite or runaway state, with time, body and value.
    #[error(transparent)]
    Step(#[from] crate::dynamics::StepError),
    /// A motor-primitive experiment (high jump, jumping knee kick).
    #[error(transparent)]
    Experiment(#[from] crate::experiments::high_jump::PrimitiveExperimentError),
    /// Making a physical character (primitives, strength, tissue, settings).
    #[error(transparent)]
    Character(#[from] crate::ecs::character::CharacterError),
    /// An active character's run.
    #[error(transparent)]
    Active(#[from] crate::experiments::active::ActiveError),
    /// Gene bounds that are not a box.
    #[error(transparent)]
    Bounds(#[from] crate::evolve::genome::BoundsError),
    /// The GA: its settings, its evaluator or its checkpoints.
    #[error(transparent)]
    Evolve(#[from] crate::evolve::EvolveError),
    /// One evaluation of a genome.
    #[error(transparent)]
    Evaluation(#[from] crate::evolve::EvaluationError),
    /// A problem's own error behind a failed evaluation.
    #[error(transparent)]
    ProblemFailure(#[from] crate::evolve::ProblemFailure),
    /// Why an individual of a generation has no fitness (the GA's failure log).
    #[error(transparent)]
    Failure(#[from] crate::evolve::Failure),
    /// Why a GA run stopped before its last generation.
    #[error(transparent)]
    Stop(#[from] crate::evolve::StopCause),
    /// An evaluator that could not evaluate a generation.
    #[error(transparent)]
    Evaluator(#[from] crate::evolve::EvaluatorError),
    /// A JSON-lines worker that failed: which, how and what it last said.
    #[error(transparent)]
    Worker(#[from] Box<crate::evolve::WorkerFailure>),
    /// What a JSON-lines worker did wrong.
    #[error(transparent)]
    WorkerFault(#[from] Box<crate::evolve::WorkerFault>),
    /// A line of the worker protocol that does not parse.
    #[error(transparent)]
    ProtocolLine(#[from] Box<crate::evolve::LineError>),
    /// A GA checkpoint: reading, checking or writing it.
    #[error(transparent)]
    Checkpoint(#[from] crate::evolve::CheckpointError),
    /// The falling paper's GA problem (its ranges, bounds, gain bounds).
    #[error(transparent)]
    FallProblem(#[from] crate::experiments::evolve_fall::ProblemError),
    /// Evolving falls: the GA, its checkpoints, replaying the best falls.
    #[error(transparent)]
    EvolveFall(#[from] crate::experiments::evolve_fall::EvolveFallError),
    /// Decoding or analysing a song.
    #[error(transparent)]
    Music(#[from] crate::choreo::music::MusicError),
    /// Dance segments and their database.
    #[error(transparent)]
    Segment(#[from] crate::choreo::segments::SegmentError),
    /// A relevance-feedback search round.
    #[error(transparent)]
    Search(#[from] crate::choreo::search::SearchError),
    /// An action on a dance edit.
    #[error(transparent)]
    Edit(#[from] crate::choreo::edit::EditError),
    /// The dance-search experiment (the paper's Fig. 4).
    #[error(transparent)]
    DanceFeedback(#[from] crate::experiments::dance_feedback::FeedbackError),
    /// The transition table of a dance database (link weights, boundary data).
    #[error(transparent)]
    Transition(#[from] crate::choreo::transition::TransitionError),
    /// Filling the unpinned bars of a dance.
    #[error(transparent)]
    Fill(#[from] crate::choreo::fill::FillError),
    /// Assembling a dance from segments at a song's bars.
    #[error(transparent)]
    Dance(#[from] crate::choreo::dance::DanceError),
    /// Generating a dance (fill, then assembly).
    #[error(transparent)]
    Generate(#[from] crate::experiments::dance::GenerateError),
    /// The authored dance clips (their parameters).
    #[error(transparent)]
    Authored(#[from] crate::choreo::authored::AuthoredError),
    /// The dance-editing paper's Fig. 5 experiment.
    #[error(transparent)]
    DanceFill(#[from] crate::experiments::dance_fill::DanceFillError),
    /// The dance editor (its scene, server and actions).
    #[cfg(feature = "editor")]
    #[error(transparent)]
    Editor(#[from] crate::editor::EditorError),
    /// A data file (RON): reading, syntax, version.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// RON syntax or schema, located.
    #[error(transparent)]
    Ron(#[from] crate::io::RonError),
    /// Reading or writing a file.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A scene file: reading, checking, running.
    #[cfg(feature = "render")]
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    /// A checkpoint to resume that does not match the runs the scene asks for.
    #[cfg(feature = "render")]
    #[error(transparent)]
    ResumeMismatch(#[from] crate::scene::ResumeMismatch),
    /// One setting whose value in a checkpoint is not the scene's.
    #[cfg(feature = "render")]
    #[error(transparent)]
    SettingMismatch(#[from] crate::scene::SettingMismatch),
    /// Drawing a picture or plot.
    #[cfg(feature = "render")]
    #[error(transparent)]
    Render(#[from] crate::render::RenderError),
}

// The worker's errors are large (their lines and last words): boxed, as `EvaluatorError` holds
// them, so that every `Result<_, Error>` stays small; they convert unboxed too.
macro_rules! from_boxed {
    ($($ty:ty),*) => {$(
        impl From<$ty> for Error {
            fn from(e: $ty) -> Self {
                Box::new(e).into()
            }
        }
    )*};
}
from_boxed!(
    crate::evolve::WorkerFailure,
    crate::evolve::WorkerFault,
    crate::evolve::LineError
);

/// A result with the crate's [`Error`].
pub type Result<T> = std::result::Result<T, Error>;

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_missing_file() -> Result<()> {
        crate::clips::KeyframeClip::load(std::path::Path::new("/nonexistent/clip.ron"))?;
        Ok(())
    }

    #[test]
    fn module_errors_convert_and_keep_their_message() {
        let e = parse_missing_file().unwrap_err();
        assert!(matches!(e, Error::Keyframes(_)), "{e:?}");
        assert!(e.to_string().contains("/nonexistent/clip.ron"), "{e}");
        let m: Error = crate::humanoid::Figure::by_name("robot")
            .unwrap_err()
            .into();
        assert_eq!(
            m.to_string(),
            "unknown model 'robot': expected one of humanoid24, fall21"
        );
    }

    fn bounds_then_evaluation(lo: f64) -> Result<f64> {
        crate::evolve::Bounds::new(vec![lo], vec![1.0])?;
        let evaluation: crate::evolve::Evaluation =
            Err(crate::evolve::EvaluationError::NotEvaluated);
        let damage = evaluation?;
        Ok(damage)
    }

    #[test]
    fn the_worker_errors_convert_boxed_with_their_message() {
        let line = crate::evolve::LineError {
            side: "reply",
            line: 3,
            column: 1,
            field: None,
            expected: "a reply".into(),
            text: "junk".into(),
        };
        let message = line.to_string();
        let e: Error = line.into();
        assert!(matches!(e, Error::ProtocolLine(_)), "{e:?}");
        assert_eq!(e.to_string(), message);
    }

    #[test]
    fn the_ga_errors_convert_too() {
        let e = bounds_then_evaluation(2.0).unwrap_err();
        assert!(matches!(e, Error::Bounds(_)), "{e:?}");
        assert_eq!(
            e.to_string(),
            "gene 0: bounds [2, 1] are not a finite interval with lo ≤ hi"
        );
        let e = bounds_then_evaluation(0.0).unwrap_err();
        assert!(matches!(e, Error::Evaluation(_)), "{e:?}");
        assert_eq!(e.to_string(), "not evaluated");
    }
}
