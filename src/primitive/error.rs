//! Errors of the motor-primitive kernel: every bad input is reported with what and where.

use thiserror::Error;

/// Everything that can go wrong when building, learning, playing, blending, saving or loading
/// primitives. Each variant names the offending field or quantity.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum PrimitiveError {
    /// A trajectory is malformed (`what` says which part: dt, names, values, frame count).
    #[error("invalid trajectory: {what}")]
    InvalidTrajectory {
        /// What is wrong.
        what: String,
    },
    /// A parameter is out of its valid range (`field` names it, `reason` says why).
    #[error("invalid parameter `{field}`: {reason}")]
    InvalidParameter {
        /// The parameter's name (e.g. `duration`, `dofs[3].weights`).
        field: String,
        /// Why it is invalid.
        reason: String,
    },
    /// A value is NaN or infinite.
    #[error("non-finite value in `{field}`")]
    NonFinite {
        /// Where the value was found.
        field: String,
    },
    /// Two primitives (or a primitive and a state) do not have the same DOF names in the same order.
    #[error("DOF sets differ: {what}")]
    DofMismatch {
        /// Which names differ.
        what: String,
    },
    /// A blend whose time placement is not one of the paper's six arrangements.
    #[error("invalid blend placement: {reason}")]
    InvalidPlacement {
        /// Why (no overlap, t_Be > t_Ae, non-positive duration…).
        reason: String,
    },
    /// A RON file could not be parsed; `line`/`column` locate the problem (1-based).
    #[error("{source_name}:{line}:{column}: {message}")]
    Parse {
        /// File name or `<string>`.
        source_name: String,
        /// 1-based line of the error.
        line: usize,
        /// 1-based column of the error.
        column: usize,
        /// The parser's message (names the field for missing/unknown fields).
        message: String,
    },
    /// The file was written by a newer version of the format than this build understands.
    #[error(
        "{source_name}: primitive format_version {found} is newer than the supported version {supported}"
    )]
    UnsupportedVersion {
        /// File name or `<string>`.
        source_name: String,
        /// Version found in the file.
        found: u32,
        /// Highest version this build reads.
        supported: u32,
    },
    /// Jump events could not be found in the data.
    #[error("jump events not found: {reason}")]
    EventsNotFound {
        /// What is missing (no crouch, no flight, no landing…).
        reason: String,
    },
    /// An I/O error (reading or writing a file), with the path.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The OS message.
        message: String,
    },
}

/// Shorthand for results of this module.
pub type Result<T> = std::result::Result<T, PrimitiveError>;

/// Returns `InvalidParameter` unless `value` is finite and > 0.
pub(crate) fn require_positive(field: &str, value: f64) -> Result<()> {
    if !value.is_finite() {
        return Err(PrimitiveError::NonFinite {
            field: field.to_string(),
        });
    }
    if value <= 0.0 {
        return Err(PrimitiveError::InvalidParameter {
            field: field.to_string(),
            reason: format!("must be > 0, got {value}"),
        });
    }
    Ok(())
}

/// Returns `NonFinite` if any value is NaN or infinite.
pub(crate) fn require_finite(field: &str, values: &[f64]) -> Result<()> {
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(PrimitiveError::NonFinite {
            field: format!("{field}[{i}]"),
        });
    }
    Ok(())
}
