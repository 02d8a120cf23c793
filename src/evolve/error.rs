//! Why a run could not go on: [`EvolveError`] and the kinds it carries, for the evaluator
//! ([`EvaluatorError`], a worker's fault [`WorkerFailure`]), the checkpoint
//! ([`CheckpointError`]) and a GA stopped by its failures ([`StopCause`]). Each shows the
//! message the engine has always shown.

use std::path::PathBuf;
use std::process::ExitStatus;

use super::failure::Failure;
use super::formats::{FORMAT_VERSION, MAX_LINE, MAX_REFINE, PROTOCOL};

/// Why a run could not go on.
#[derive(Debug, thiserror::Error)]
pub enum EvolveError {
    /// A setting is invalid.
    #[error("ga.{field}: {message}")]
    Config {
        /// Field.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The evaluator broke (worker died, protocol violated, an answer of the wrong length).
    #[error("evaluator: {0}")]
    Evaluator(#[from] EvaluatorError),
    /// A checkpoint could not be read or written.
    #[error("checkpoint {}: {why}", .path.display())]
    Checkpoint {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        #[source]
        why: CheckpointError,
    },
    /// Too many evaluations of a generation failed ([`super::GaConfig::max_failed_share`]).
    #[error("the GA stopped: {run}, {cause}")]
    Stopped {
        /// The run, e.g. `seed 3` or `adult seed 3`.
        run: String,
        /// The generation, its failures and the limit.
        cause: StopCause,
    },
}

/// How an evaluator broke.
#[derive(Debug, thiserror::Error)]
pub enum EvaluatorError {
    /// The worker process could not be started.
    #[error("cannot start the worker `{worker}`: {source}")]
    Start {
        /// The worker's command line.
        worker: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The worker process started without its pipes.
    #[error("the worker `{worker}` has no pipes")]
    NoPipes {
        /// The worker's command line.
        worker: String,
    },
    /// A protocol line could not be written as JSON.
    #[error("{0}")]
    Encode(#[source] serde_json::Error),
    /// The worker failed: it was stopped and is not asked again.
    #[error(transparent)]
    Worker(Box<WorkerFailure>),
    /// The worker failed on an earlier batch.
    #[error("failed before: {0}")]
    FailedBefore(Box<WorkerFailure>),
    /// An evaluator gave a number of results other than the number of genomes.
    #[error("{found} results for {expected} genomes")]
    ResultCount {
        /// Genomes asked for.
        expected: usize,
        /// Results given.
        found: usize,
    },
    /// Worker side: the input ended before the header line.
    #[error("no header line")]
    NoHeader,
    /// Worker side: a request line could not be read.
    #[error("request line {line}: {source}")]
    Read {
        /// The line (1 for the header).
        line: usize,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Worker side: a request line longer than [`MAX_LINE`].
    #[error("request line {0} longer than {MAX_LINE} bytes")]
    LineTooLong(usize),
    /// Worker side: a request line it does not understand.
    #[error(transparent)]
    BadRequest(Box<LineError>),
    /// Worker side: a header of another protocol than [`PROTOCOL`].
    #[error("protocol '{0}' is not '{PROTOCOL}'")]
    Protocol(String),
    /// Worker side: the header's problem could not be read or posed.
    #[error("problem: {0}")]
    Problem(String),
    /// Worker side: a refinement out of 1..=[`MAX_REFINE`].
    #[error("request line {line}, field `genome.refine`: must be 1..={MAX_REFINE}, found {refine}")]
    Refine {
        /// The request line.
        line: usize,
        /// The refinement asked for.
        refine: u32,
    },
    /// Worker side: a genome index given twice in a batch.
    #[error("request line {line}, field `genome.index`: genome {index} given twice in a batch")]
    RepeatedIndex {
        /// The request line.
        line: usize,
        /// The index.
        index: usize,
    },
    /// Worker side: a batch end whose count is not the number of genomes of the batch.
    #[error(
        "request line {line}, field `evaluate.count`: the batch holds {held} genomes, found {count}"
    )]
    BatchCount {
        /// The request line.
        line: usize,
        /// Genomes the batch holds.
        held: usize,
        /// The count the line gives.
        count: usize,
    },
    /// Worker side: the input ended inside a batch.
    #[error("the input ended inside a batch of {0} genomes (no {{\"evaluate\": …}} line)")]
    UnendedBatch(usize),
    /// Worker side: the replies could not be written.
    #[error("{0}")]
    Write(#[source] std::io::Error),
}

/// A protocol line that does not parse as what was expected.
#[derive(Clone, Debug, thiserror::Error)]
#[error("{side} line {line}, column {column}{}: {expected} (in {text})", field_of(.field))]
pub struct LineError {
    /// `request` or `reply`.
    pub side: &'static str,
    /// The line, from 1.
    pub line: usize,
    /// The column, from 1.
    pub column: usize,
    /// The field, if the line parsed that far.
    pub field: Option<String>,
    /// What was wrong, or expected, as the parser says.
    pub expected: String,
    /// The line, cut to 120 characters.
    pub text: String,
}

/// `, field `f`` or nothing.
fn field_of(field: &Option<String>) -> String {
    field
        .as_ref()
        .map(|f| format!(", field `{f}`"))
        .unwrap_or_default()
}

/// A worker that failed: which, how and what it last said.
#[derive(Clone, Debug, thiserror::Error)]
#[error("the worker `{worker}` {fault}; {said}")]
pub struct WorkerFailure {
    /// The worker's command line.
    pub worker: String,
    /// What it did wrong.
    pub fault: WorkerFault,
    /// The last it said.
    pub said: LastWords,
}

/// What a worker did wrong.
#[derive(Clone, Debug, thiserror::Error)]
pub enum WorkerFault {
    /// A reply line that is not a reply.
    #[error("sent a bad {0}")]
    BadReply(LineError),
    /// A batch end before all replies.
    #[error(
        "ended generation {generation} with {{\"done\": {{\"count\": {count}}}}} after {got} of \
         its {n} replies"
    )]
    EarlyDone {
        /// The generation.
        generation: u64,
        /// The count it gave.
        count: usize,
        /// Replies received.
        got: usize,
        /// Genomes sent.
        n: usize,
    },
    /// Two replies for one genome.
    #[error("replied twice for genome {index} of generation {generation}")]
    RepliedTwice {
        /// The genome.
        index: usize,
        /// The generation.
        generation: u64,
    },
    /// A reply for a genome not sent.
    #[error("replied for genome {index}, past the {n} of generation {generation}")]
    IndexPastBatch {
        /// The genome.
        index: usize,
        /// Genomes sent.
        n: usize,
        /// The generation.
        generation: u64,
    },
    /// The batch was not answered within the timeout.
    #[error(
        "answered {got} of the {n} genomes of generation {generation} in {seconds:.1} s, the \
         batch timeout, and was stopped"
    )]
    Timeout {
        /// Replies received.
        got: usize,
        /// Genomes sent.
        n: usize,
        /// The generation.
        generation: u64,
        /// The timeout, seconds.
        seconds: f64,
    },
    /// The worker closed its output (most often: it died).
    #[error(
        "closed its output after {got} of the {n} replies of generation {generation} ({})",
        match .status { Some(s) => format!("it ended with {s}"), None => "it is still running".into() }
    )]
    Closed {
        /// Replies received.
        got: usize,
        /// Genomes sent.
        n: usize,
        /// The generation.
        generation: u64,
        /// Its exit status, if it ended.
        status: Option<ExitStatus>,
    },
}

/// The last line a worker wrote on each of its outputs, and why its input broke.
#[derive(Clone, Debug, Default)]
pub struct LastWords {
    /// The last line on standard output, cut to 120 characters.
    pub stdout: Option<String>,
    /// The last non-blank line on standard error, cut to 120 characters.
    pub stderr: Option<String>,
    /// Why writing to its input failed.
    pub stdin_error: Option<String>,
}

impl std::fmt::Display for LastWords {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut parts = Vec::new();
        if let Some(s) = &self.stdout {
            parts.push(format!("on stdout {s:?}"));
        }
        if let Some(s) = &self.stderr {
            parts.push(format!("on stderr {s:?}"));
        }
        if parts.is_empty() {
            f.write_str("it said nothing")?;
        } else {
            write!(f, "it last said {}", parts.join(" and "))?;
        }
        match &self.stdin_error {
            Some(e) => write!(f, "; its input broke: {e}"),
            None => Ok(()),
        }
    }
}

/// Why a checkpoint could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// Reading or writing the file failed.
    #[error("{0}")]
    Io(#[source] std::io::Error),
    /// A file of format version 1 (the bare state).
    #[error(
        "a checkpoint of format version 1 (no version, no checksum); this marionette reads \
         version {FORMAT_VERSION}: run the scene again without --resume"
    )]
    Version1,
    /// Not a checkpoint's envelope (its line and column: [`serde_json::Error::line`]).
    #[error("not a checkpoint: {0}")]
    NotACheckpoint(#[source] serde_json::Error),
    /// Another format version.
    #[error("format version {0}, this marionette reads version {FORMAT_VERSION}")]
    FormatVersion(u32),
    /// The content does not have the checksum the file states.
    #[error(
        "the checksum of the content is {computed}, the file says {stated}: the file was changed \
         or cut after it was written"
    )]
    Checksum {
        /// The content's checksum.
        computed: String,
        /// The file's.
        stated: String,
    },
    /// The content is not the state (its line and column: [`serde_json::Error::line`]).
    #[error("content: {0}")]
    Content(#[source] serde_json::Error),
    /// The state read is inconsistent: what disagrees.
    #[error("{0}")]
    Inconsistent(String),
    /// The state could not be written as JSON.
    #[error("{0}")]
    Encode(String),
    /// Not written: the state to write is inconsistent (what disagrees).
    #[error("not written, the state is inconsistent: {0}")]
    InconsistentState(String),
    /// Not written: the text would not read back.
    #[error("not written: {0}")]
    Unreadable(Box<CheckpointError>),
    /// Not written: a number would not read back bit for bit.
    #[error("not written: a number in it would not read back bit for bit")]
    NotBitExact,
}

/// Why a GA stopped ([`super::GaState::stopped`] holds its message).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum StopCause {
    /// More than the limit of a generation's evaluations failed.
    #[error(
        "generation {generation}: {failed} of {evaluations} evaluations failed, more than \
         ga.max_failed_share = {limit} of them; the first: {}",
        .first.iter().map(|(i, why)| format!("individual {i}: {why}")).collect::<Vec<_>>().join("; ")
    )]
    TooManyFailed {
        /// The generation.
        generation: u64,
        /// Its failed evaluations.
        failed: usize,
        /// Its evaluations.
        evaluations: usize,
        /// [`super::GaConfig::max_failed_share`].
        limit: f64,
        /// The first (up to three) failures: individual and why.
        first: Vec<(usize, Failure)>,
    },
    /// A cause known only by its message, as a checkpoint stored it.
    #[error("{0}")]
    Reported(String),
}

impl StopCause {
    /// The cause whose message `message` is (one read back from a checkpoint): the kind that
    /// shows it as is, else [`Self::Reported`].
    pub fn from_message(message: &str) -> Self {
        Self::too_many_failed_of(message)
            .filter(|c| c.to_string() == message)
            .unwrap_or_else(|| Self::Reported(message.to_string()))
    }

    /// The [`Self::TooManyFailed`] `message` reads as, unchecked.
    fn too_many_failed_of(message: &str) -> Option<Self> {
        let (generation, rest) = message.strip_prefix("generation ")?.split_once(": ")?;
        let (failed, rest) = rest.split_once(" of ")?;
        let (evaluations, rest) = rest.split_once(" evaluations failed, more than ")?;
        let (limit, rest) = rest
            .strip_prefix("ga.max_failed_share = ")?
            .split_once(" of them; the first: ")?;
        let first = rest
            .strip_prefix("individual ")?
            .split("; individual ")
            .map(|f| {
                let (i, why) = f.split_once(": ")?;
                Some((i.parse().ok()?, Failure::from_message(why)))
            })
            .collect::<Option<Vec<_>>>()?;
        Some(Self::TooManyFailed {
            generation: generation.parse().ok()?,
            failed: failed.parse().ok()?,
            evaluations: evaluations.parse().ok()?,
            limit: limit.parse().ok()?,
            first,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::evolve::EvaluationError;

    #[test]
    fn a_stop_cause_comes_back_from_its_message_and_a_look_alike_stays_reported() {
        let cause = StopCause::TooManyFailed {
            generation: 4,
            failed: 3,
            evaluations: 5,
            limit: 0.5,
            first: vec![
                (1, Failure::Evaluation(EvaluationError::NotEvaluated)),
                (
                    2,
                    Failure::Evaluation(EvaluationError::NegativeDamage(-1.5)),
                ),
                (4, EvaluationError::Reported("no: a; b".into()).into()),
            ],
        };
        let message = cause.to_string();
        assert_eq!(
            message,
            "generation 4: 3 of 5 evaluations failed, more than ga.max_failed_share = 0.5 of \
             them; the first: individual 1: not evaluated; individual 2: damage -1.5 is \
             negative; individual 4: no: a; b"
        );
        assert_eq!(StopCause::from_message(&message), cause);
        let other = "generation 4: everything failed";
        assert_eq!(
            StopCause::from_message(other),
            StopCause::Reported(other.into())
        );
    }

    #[test]
    fn a_dead_worker_is_named_with_its_fault_and_last_words() {
        let failure = WorkerFailure {
            worker: "w".into(),
            fault: WorkerFault::RepliedTwice {
                index: 2,
                generation: 7,
            },
            said: LastWords {
                stderr: Some("oops".into()),
                stdin_error: Some("broken pipe".into()),
                ..LastWords::default()
            },
        };
        assert_eq!(
            EvolveError::from(EvaluatorError::FailedBefore(Box::new(failure))).to_string(),
            "evaluator: failed before: the worker `w` replied twice for genome 2 of generation \
             7; it last said on stderr \"oops\"; its input broke: broken pipe"
        );
    }
}
