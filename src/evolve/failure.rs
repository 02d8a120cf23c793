//! Why an individual has no fitness: [`EvaluationError`], why one evaluation failed, and
//! [`Failure`], an entry of the GA's failure log (a failed evaluation or a rejected elite
//! check). Each shows the message the log, the reports and the worker protocol have always
//! carried. The checkpoint and the worker protocol carry only that message, so what they bring
//! back is parsed into its kind at that boundary ([`Failure::from_message`],
//! [`EvaluationError::from_message`]); a message no kind gives back as is stays
//! [`EvaluationError::Reported`].

use std::sync::Arc;

use serde::{Deserialize, Serialize};

/// How the failure log's entries of the elite check begin.
pub const ELITE_CHECK: &str = "elite check";

/// The refinement at which elites are checked (`GaConfig::elite_check_tolerance`): twice
/// the resolution, a fall at half its time step.
pub const ELITE_CHECK_REFINE: u32 = 2;

/// The error a problem's own evaluation gave (for a fall: why it could not be simulated),
/// shared and type-erased so that the GA kernel knows no problem; [`Self::downcast_ref`] gives
/// the problem's error back.
#[derive(Clone, Debug)]
pub struct ProblemFailure(pub Arc<dyn std::error::Error + Send + Sync>);

impl ProblemFailure {
    /// The problem's error as a `T`, if it is one.
    pub fn downcast_ref<T: std::error::Error + 'static>(&self) -> Option<&T> {
        self.0.downcast_ref::<T>()
    }
}

impl<E: std::error::Error + Send + Sync + 'static> From<Arc<E>> for ProblemFailure {
    fn from(e: Arc<E>) -> Self {
        Self(e)
    }
}

impl std::fmt::Display for ProblemFailure {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        self.0.fmt(f)
    }
}

impl std::error::Error for ProblemFailure {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        self.0.source()
    }
}

/// Why one evaluation gave no damage. Two are equal when their messages are: only the message
/// crosses the worker protocol and the checkpoint, and what comes back equals what was sent.
#[derive(Clone, Debug, thiserror::Error)]
pub enum EvaluationError {
    /// The problem's evaluation failed (for a fall: its simulation), with the problem's error.
    #[error(transparent)]
    Problem(ProblemFailure),
    /// A genome of the wrong length, answered without being run.
    #[error("a genome has {expected} genes, found {found}")]
    GenomeLength {
        /// Genes the problem has.
        expected: usize,
        /// Genes the genome has.
        found: usize,
    },
    /// The evaluator gave no result for the genome.
    #[error("not evaluated")]
    NotEvaluated,
    /// A damage below zero.
    #[error("damage {0} is negative")]
    NegativeDamage(f64),
    /// A damage that is not finite.
    #[error("damage {0} is not finite")]
    NonFiniteDamage(f64),
    /// A damage a worker would not send, negative or not finite (the worker protocol's words).
    #[error("damage {0} is negative or not finite")]
    InvalidDamage(f64),
    /// A failure known only by its message: as a worker sent it, a checkpoint stored it or an
    /// evaluator that has no error type of its own words it.
    #[error("{0}")]
    Reported(String),
}

impl PartialEq for EvaluationError {
    fn eq(&self, other: &Self) -> bool {
        self.to_string() == other.to_string()
    }
}

impl EvaluationError {
    /// Why `damage` is no damage ([`Self::NegativeDamage`], [`Self::NonFiniteDamage`]);
    /// `None` for a finite damage ≥ 0.
    pub fn of_damage(damage: f64) -> Option<Self> {
        if !damage.is_finite() {
            Some(Self::NonFiniteDamage(damage))
        } else if damage < 0.0 {
            Some(Self::NegativeDamage(damage))
        } else {
            None
        }
    }

    /// The error whose message `message` is (one read back from a worker or a checkpoint):
    /// the kind that shows it as is, else [`Self::Reported`]. A problem's error comes back as
    /// [`Self::Reported`]: only its message crossed.
    pub fn from_message(message: &str) -> Self {
        Self::kind_of(message)
            .filter(|e| e.to_string() == message)
            .unwrap_or_else(|| Self::Reported(message.to_string()))
    }

    /// The kind `message` reads as, unchecked.
    fn kind_of(message: &str) -> Option<Self> {
        if message == "not evaluated" {
            return Some(Self::NotEvaluated);
        }
        if let Some(rest) = message.strip_prefix("a genome has ") {
            let (expected, found) = rest.split_once(" genes, found ")?;
            return Some(Self::GenomeLength {
                expected: expected.parse().ok()?,
                found: found.parse().ok()?,
            });
        }
        let (value, why) = message.strip_prefix("damage ")?.split_once(" is ")?;
        let value: f64 = value.parse().ok()?;
        match why {
            "negative" => Some(Self::NegativeDamage(value)),
            "not finite" => Some(Self::NonFiniteDamage(value)),
            "negative or not finite" => Some(Self::InvalidDamage(value)),
            _ => None,
        }
    }
}

/// An entry of the GA's failure log: why an individual of a generation has no fitness. In a
/// checkpoint it is its message.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum Failure {
    /// Its evaluation failed.
    #[error(transparent)]
    Evaluation(#[from] EvaluationError),
    /// An elite whose damage moved by more than the tolerance at [`ELITE_CHECK_REFINE`] times
    /// the problem's resolution.
    #[error(
        "{}: damage {damage} at the problem's resolution, {fine} at {}× it ({:+.1} %, \
         tolerance {:.1} %)",
        ELITE_CHECK,
        ELITE_CHECK_REFINE,
        100.0 * (.fine - .damage) / .damage,
        100.0 * .tolerance
    )]
    EliteCheckMoved {
        /// Damage at the problem's resolution.
        damage: f64,
        /// Damage at [`ELITE_CHECK_REFINE`] times it.
        fine: f64,
        /// The tolerance, a fraction of the damage (read back from a checkpoint: as shown, to
        /// 0.1 %).
        tolerance: f64,
    },
    /// An elite whose re-evaluation at [`ELITE_CHECK_REFINE`] times the resolution failed.
    #[error("{}: at {}× the resolution: {}", ELITE_CHECK, ELITE_CHECK_REFINE, .0)]
    EliteCheckFailed(EvaluationError),
}

impl Failure {
    /// True for a rejected elite check, false for a failed evaluation.
    pub fn is_elite_check(&self) -> bool {
        matches!(
            self,
            Self::EliteCheckMoved { .. } | Self::EliteCheckFailed(_)
        )
    }

    /// The failure whose message `message` is (one read back from a checkpoint): the kind that
    /// shows it as is, else a failed evaluation ([`EvaluationError::from_message`]).
    pub fn from_message(message: &str) -> Self {
        Self::elite_check_of(message)
            .filter(|f| f.to_string() == message)
            .unwrap_or_else(|| Self::Evaluation(EvaluationError::from_message(message)))
    }

    /// The elite check `message` reads as, unchecked.
    fn elite_check_of(message: &str) -> Option<Self> {
        let rest = message.strip_prefix(ELITE_CHECK)?.strip_prefix(": ")?;
        let failed = format!("at {ELITE_CHECK_REFINE}× the resolution: ");
        if let Some(e) = rest.strip_prefix(&failed) {
            return Some(Self::EliteCheckFailed(EvaluationError::from_message(e)));
        }
        let (damage, rest) = rest
            .strip_prefix("damage ")?
            .split_once(" at the problem's resolution, ")?;
        let (fine, rest) = rest.split_once(&format!(" at {ELITE_CHECK_REFINE}× it ("))?;
        let (_, tolerance) = rest.strip_suffix(" %)")?.rsplit_once("tolerance ")?;
        Some(Self::EliteCheckMoved {
            damage: damage.parse().ok()?,
            fine: fine.parse().ok()?,
            tolerance: tolerance.parse::<f64>().ok()? / 100.0,
        })
    }
}

impl Serialize for Failure {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(self)
    }
}

impl<'de> Deserialize<'de> for Failure {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Ok(Self::from_message(&String::deserialize(d)?))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::mem::discriminant;

    /// The kind of a failure and of the evaluation error in it (equality alone compares
    /// messages).
    fn kind(
        f: &Failure,
    ) -> (
        std::mem::Discriminant<Failure>,
        Option<std::mem::Discriminant<EvaluationError>>,
    ) {
        let inner = match f {
            Failure::Evaluation(e) | Failure::EliteCheckFailed(e) => Some(discriminant(e)),
            Failure::EliteCheckMoved { .. } => None,
        };
        (discriminant(f), inner)
    }

    #[test]
    fn each_kind_shows_its_message_and_comes_back_from_it() {
        let sim = std::io::Error::other("non-finite velocity of 'pelvis' at t = 0.1000 s");
        let cases = [
            (
                Failure::EliteCheckMoved {
                    damage: 120.5,
                    fine: 150.0,
                    tolerance: 0.1,
                },
                "elite check: damage 120.5 at the problem's resolution, 150 at 2× it (+24.5 %, \
                 tolerance 10.0 %)",
            ),
            (
                Failure::EliteCheckFailed(EvaluationError::NotEvaluated),
                "elite check: at 2× the resolution: not evaluated",
            ),
            (
                EvaluationError::GenomeLength {
                    expected: 42,
                    found: 3,
                }
                .into(),
                "a genome has 42 genes, found 3",
            ),
            (
                EvaluationError::NegativeDamage(-5.0).into(),
                "damage -5 is negative",
            ),
            (
                EvaluationError::NonFiniteDamage(f64::NEG_INFINITY).into(),
                "damage -inf is not finite",
            ),
            (
                EvaluationError::InvalidDamage(-0.25).into(),
                "damage -0.25 is negative or not finite",
            ),
            (
                EvaluationError::Reported("the worker's own words".into()).into(),
                "the worker's own words",
            ),
        ];
        for (failure, message) in cases {
            assert_eq!(failure.to_string(), message);
            let back = Failure::from_message(message);
            assert_eq!(back, failure, "{message}");
            assert_eq!(kind(&back), kind(&failure), "{message}");
            let json = serde_json::to_string(&failure).unwrap();
            assert_eq!(json, serde_json::to_string(message).unwrap());
            let back: Failure = serde_json::from_str(&json).unwrap();
            assert_eq!(kind(&back), kind(&failure), "{message}");
        }
        // A problem's error shows its own message; only that message comes back.
        let p = Failure::Evaluation(EvaluationError::Problem(Arc::new(sim).into()));
        assert_eq!(
            p.to_string(),
            "non-finite velocity of 'pelvis' at t = 0.1000 s"
        );
        let back = Failure::from_message(&p.to_string());
        assert_eq!(back, p);
        assert_eq!(
            kind(&back),
            kind(&EvaluationError::Reported(String::new()).into())
        );
        let Failure::Evaluation(EvaluationError::Problem(e)) = &p else {
            unreachable!()
        };
        assert!(e.downcast_ref::<std::io::Error>().is_some());
    }

    #[test]
    fn the_elite_check_is_told_by_kind_and_a_look_alike_stays_reported() {
        let moved = Failure::EliteCheckMoved {
            damage: 1.0,
            fine: 3.0,
            tolerance: 0.123,
        };
        assert!(moved.is_elite_check());
        // Read back, the tolerance is the one shown; the message is the same.
        let back = Failure::from_message(&moved.to_string());
        assert!(back.is_elite_check());
        assert_eq!(back.to_string(), moved.to_string());
        assert!(!Failure::from(EvaluationError::NotEvaluated).is_elite_check());
        // A message that begins like one but is not one this build writes.
        let odd = "elite check: the worker said so";
        let back = Failure::from_message(odd);
        assert!(!back.is_elite_check());
        assert!(matches!(back, Failure::Evaluation(EvaluationError::Reported(m)) if m == odd));
        let big = "damage 1e400 is negative";
        assert!(matches!(
            EvaluationError::from_message(big),
            EvaluationError::Reported(m) if m == big
        ));
        assert!(EvaluationError::of_damage(0.0).is_none());
        assert!(matches!(
            EvaluationError::of_damage(-1.0),
            Some(EvaluationError::NegativeDamage(_))
        ));
        assert_eq!(
            EvaluationError::of_damage(f64::NAN).map(|e| e.to_string()),
            Some("damage NaN is not finite".into())
        );
    }
}
