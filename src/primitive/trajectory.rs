//! The plain-data exchange type of the primitive kernel: per-DOF trajectories on a uniform grid.

use serde::{Deserialize, Serialize};

use super::error::{PrimitiveError, Result, require_finite, require_positive};

/// Per-DOF trajectories sampled every `dt` seconds.
///
/// `values` is `frames × dofs`, row-major: frame `k`, DOF `j` is `values[k * dofs + j]`, at time
/// `k · dt`. Values are radians for joint angles and for the root rotation vector, metres for the
/// root translation DOFs `root_tx, root_ty, root_tz` (see [`DofUnit::of`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Trajectory {
    /// Time step between frames, seconds (> 0).
    pub dt: f64,
    /// DOF names, one per column.
    pub names: Vec<String>,
    /// `frames × names.len()` values, row-major (radians or metres).
    pub values: Vec<f64>,
}

/// The unit a DOF's values are in, decided by its name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DofUnit {
    /// Joint angle or rotation-vector component, radians (reported in degrees).
    Radian,
    /// Root translation (`root_tx`, `root_ty`, `root_tz`), metres (reported in millimetres).
    Metre,
}

impl DofUnit {
    /// The unit of the DOF called `name`: metres for `root_tx`, `root_ty`, `root_tz`, else radians.
    pub fn of(name: &str) -> DofUnit {
        match name {
            "root_tx" | "root_ty" | "root_tz" => DofUnit::Metre,
            _ => DofUnit::Radian,
        }
    }

    /// Factor from the internal unit to the report unit (180/π for radians → degrees,
    /// 1000 for metres → millimetres).
    pub fn report_factor(self) -> f64 {
        match self {
            DofUnit::Radian => 180.0 / std::f64::consts::PI,
            DofUnit::Metre => 1000.0,
        }
    }

    /// Name of the report unit ("deg" or "mm").
    pub fn report_name(self) -> &'static str {
        match self {
            DofUnit::Radian => "deg",
            DofUnit::Metre => "mm",
        }
    }
}

impl Trajectory {
    /// Builds a trajectory, checking that `dt > 0`, names are non-empty and unique, `values.len()`
    /// is a multiple of the DOF count, and every value is finite.
    pub fn new(dt: f64, names: Vec<String>, values: Vec<f64>) -> Result<Trajectory> {
        let t = Trajectory { dt, names, values };
        t.validate()?;
        Ok(t)
    }

    /// Builds a trajectory from one column (time series) per DOF; all columns must have the
    /// same length.
    pub fn from_columns(dt: f64, names: Vec<String>, columns: &[Vec<f64>]) -> Result<Trajectory> {
        if columns.len() != names.len() {
            return Err(PrimitiveError::InvalidTrajectory {
                what: format!("{} columns for {} names", columns.len(), names.len()),
            });
        }
        let frames = columns.first().map_or(0, |c| c.len());
        if let Some((j, c)) = columns.iter().enumerate().find(|(_, c)| c.len() != frames) {
            return Err(PrimitiveError::InvalidTrajectory {
                what: format!(
                    "column {j} (`{}`) has {} frames, column 0 has {frames}",
                    names[j],
                    c.len()
                ),
            });
        }
        let dofs = names.len();
        let mut values = vec![0.0; frames * dofs];
        for (j, c) in columns.iter().enumerate() {
            for (k, v) in c.iter().enumerate() {
                values[k * dofs + j] = *v;
            }
        }
        Trajectory::new(dt, names, values)
    }

    /// Checks the invariants listed at [`Trajectory::new`].
    pub fn validate(&self) -> Result<()> {
        require_positive("dt", self.dt)?;
        if self.names.is_empty() {
            return Err(PrimitiveError::InvalidTrajectory {
                what: "no DOF names".into(),
            });
        }
        for (i, n) in self.names.iter().enumerate() {
            if n.is_empty() {
                return Err(PrimitiveError::InvalidTrajectory {
                    what: format!("names[{i}] is empty"),
                });
            }
            if self.names[..i].contains(n) {
                return Err(PrimitiveError::InvalidTrajectory {
                    what: format!("DOF name `{n}` appears twice"),
                });
            }
        }
        if !self.values.len().is_multiple_of(self.names.len()) {
            return Err(PrimitiveError::InvalidTrajectory {
                what: format!(
                    "{} values is not a multiple of {} DOFs",
                    self.values.len(),
                    self.names.len()
                ),
            });
        }
        require_finite("values", &self.values)
    }

    /// Number of DOFs (columns).
    pub fn dofs(&self) -> usize {
        self.names.len()
    }

    /// Number of frames (rows).
    pub fn frames(&self) -> usize {
        self.values.len().checked_div(self.names.len()).unwrap_or(0)
    }

    /// Duration in seconds from the first to the last frame: `(frames − 1)·dt`.
    pub fn duration(&self) -> f64 {
        self.frames().saturating_sub(1) as f64 * self.dt
    }

    /// Values of frame `k` (one per DOF).
    pub fn frame(&self, k: usize) -> &[f64] {
        let d = self.dofs();
        &self.values[k * d..(k + 1) * d]
    }

    /// Value of DOF `j` at frame `k`.
    pub fn value(&self, k: usize, j: usize) -> f64 {
        self.values[k * self.dofs() + j]
    }

    /// The time series of DOF `j`.
    pub fn column(&self, j: usize) -> Vec<f64> {
        (0..self.frames()).map(|k| self.value(k, j)).collect()
    }

    /// Index of the DOF called `name`.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// Frames `first..=last` as a new trajectory (same dt and names).
    pub fn slice_frames(&self, first: usize, last: usize) -> Result<Trajectory> {
        if first > last || last >= self.frames() {
            return Err(PrimitiveError::InvalidTrajectory {
                what: format!("frame range {first}..={last} outside 0..{}", self.frames()),
            });
        }
        let d = self.dofs();
        Trajectory::new(
            self.dt,
            self.names.clone(),
            self.values[first * d..(last + 1) * d].to_vec(),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_round_trip_and_layout_is_row_major() {
        let t = Trajectory::from_columns(
            0.1,
            vec!["a".into(), "b".into()],
            &[vec![1.0, 2.0, 3.0], vec![10.0, 20.0, 30.0]],
        )
        .unwrap();
        assert_eq!(t.values, vec![1.0, 10.0, 2.0, 20.0, 3.0, 30.0]);
        assert_eq!(t.frames(), 3);
        assert!((t.duration() - 0.2).abs() < 1e-12);
        assert_eq!(t.column(1), vec![10.0, 20.0, 30.0]);
    }

    #[test]
    fn rejects_bad_shapes_and_values() {
        assert!(Trajectory::new(0.0, vec!["a".into()], vec![1.0]).is_err());
        assert!(Trajectory::new(0.1, vec!["a".into(), "b".into()], vec![1.0]).is_err());
        assert!(Trajectory::new(0.1, vec!["a".into(), "a".into()], vec![1.0, 2.0]).is_err());
        assert!(matches!(
            Trajectory::new(0.1, vec!["a".into()], vec![f64::NAN]),
            Err(PrimitiveError::NonFinite { .. })
        ));
    }
}
