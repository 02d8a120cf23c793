//! A primitive M = {T, D_j | j = 1..N_DOF} (the paper's eq. 6): one DMP per DOF — joint angles
//! plus the six root DOFs [`ROOT_DOF_NAMES`] — sharing one canonical phase and one kernel basis.
//! Learning, adjusting (goal, duration), playing, fit reports and versioned RON files. The data
//! itself ([`Primitive`], [`DofPrimitive`]) is defined in [`definition`](super::definition) and
//! re-exported here.

use std::path::Path;

use serde::Deserialize;

use super::basis::Basis;
pub use super::definition::{DofPrimitive, PRIMITIVE_FORMAT_VERSION, Primitive, ROOT_DOF_NAMES};
use super::error::{PrimitiveError, Result, require_finite, require_positive};
use super::learn::{LearnConfig, learn_dofs};
use super::rollout::{DofState, Rollout, Samples};
use super::trajectory::{DofUnit, Trajectory};

/// A learned primitive with its fit against the demonstration.
#[derive(Clone, Debug, PartialEq)]
pub struct Learned {
    /// The primitive.
    pub primitive: Primitive,
    /// Per-DOF RMSE of its rollout against the demonstration.
    pub fit: FitReport,
}

/// Fit of one DOF: rollout at the demonstration's frame times vs the demonstration.
#[derive(Clone, Debug, PartialEq)]
pub struct DofFit {
    /// DOF name.
    pub name: String,
    /// Unit of `rmse` and `max_error`: degrees for angles, millimetres for root translation.
    pub unit: DofUnit,
    /// Root-mean-square error, in the report unit.
    pub rmse: f64,
    /// Largest absolute error, in the report unit.
    pub max_error: f64,
}

/// Fit of every DOF of a primitive.
#[derive(Clone, Debug, PartialEq)]
pub struct FitReport {
    /// One entry per DOF, in the primitive's order.
    pub dofs: Vec<DofFit>,
}

impl FitReport {
    /// Median RMSE over the angle DOFs, degrees (`None` if there are none).
    pub fn median_angle_rmse_deg(&self) -> Option<f64> {
        let mut v: Vec<f64> = self
            .dofs
            .iter()
            .filter(|d| d.unit == DofUnit::Radian)
            .map(|d| d.rmse)
            .collect();
        if v.is_empty() {
            return None;
        }
        v.sort_by(f64::total_cmp);
        let m = v.len() / 2;
        Some(if v.len() % 2 == 1 {
            v[m]
        } else {
            0.5 * (v[m - 1] + v[m])
        })
    }

    /// Largest RMSE over the angle DOFs, degrees (`None` if there are none).
    pub fn max_angle_rmse_deg(&self) -> Option<f64> {
        self.dofs
            .iter()
            .filter(|d| d.unit == DofUnit::Radian)
            .map(|d| d.rmse)
            .reduce(f64::max)
    }
}

impl Primitive {
    /// Learns a primitive from a demonstration: τ = the clip's duration, kernels even in time
    /// ([`Basis::even_in_time`]), weights by [`learn_dofs`]; then rolls it out at the clip's frame
    /// times to report the fit.
    pub fn learn(name: &str, demo: &Trajectory, config: &LearnConfig) -> Result<Learned> {
        demo.validate()?;
        let duration = demo.duration();
        let n = config.kernels.count(duration)?;
        let basis = Basis::even_in_time(&config.formulation.canonical(), n, config.overlap)?;
        let dofs = learn_dofs(demo, &basis, config)?;
        let primitive = Primitive {
            format_version: PRIMITIVE_FORMAT_VERSION,
            name: name.to_string(),
            formulation: config.formulation,
            duration,
            basis,
            dofs,
        };
        primitive.validate()?;
        let fit = primitive.fit_report(demo)?;
        Ok(Learned { primitive, fit })
    }

    /// Time scaling: the same primitive with duration τ′ seconds (same path, τ′/τ times slower).
    pub fn with_duration(&self, duration: f64) -> Result<Primitive> {
        require_positive("duration", duration)?;
        let mut p = self.clone();
        p.duration = duration;
        Ok(p)
    }

    /// Spatial scaling: the same primitive with new goals (one per DOF, in order). Under 2002/2013
    /// a DOF's forcing scales by (g′ − s)/(g_d − s_d) — a goal whose g′ − s has the opposite sign
    /// mirrors that DOF's motion (see [`Primitive::goal_sign_flips`]); under Hoffmann 2009 and
    /// for unscaled DOFs the forcing is unchanged and the attractor brings the DOF to g′.
    pub fn with_goals(&self, goals: &[f64]) -> Result<Primitive> {
        if goals.len() != self.dofs.len() {
            return Err(PrimitiveError::DofMismatch {
                what: format!("{} goals for {} DOFs", goals.len(), self.dofs.len()),
            });
        }
        require_finite("goals", goals)?;
        let mut p = self.clone();
        for (d, g) in p.dofs.iter_mut().zip(goals) {
            d.goal = *g;
        }
        Ok(p)
    }

    /// Spatial scaling of one DOF by name.
    pub fn with_goal(&self, name: &str, goal: f64) -> Result<Primitive> {
        let j = self
            .index_of(name)
            .ok_or_else(|| PrimitiveError::DofMismatch {
                what: format!("no DOF `{name}` in primitive `{}`", self.name),
            })?;
        let mut g = self.goals();
        g[j] = goal;
        self.with_goals(&g)
    }

    /// Indices of the DOFs that `goals` would mirror: goal-scaled DOFs whose g − s changes sign.
    pub fn goal_sign_flips(&self, goals: &[f64]) -> Vec<usize> {
        self.dofs
            .iter()
            .zip(goals)
            .enumerate()
            .filter(|(_, (d, g))| d.scaling.factor(**g, d.start) < 0.0)
            .map(|(j, _)| j)
            .collect()
    }

    /// Plays the primitive from its demonstrated start (or from `start`) and samples θ and θ̇ at
    /// `times` (seconds, non-decreasing, ≥ 0; they may run past τ, where the DMP settles on g).
    pub fn sample(&self, times: &[f64], start: Option<&DofState>) -> Result<Samples> {
        require_finite("times", times)?;
        if let Some(k) = (1..times.len()).find(|&k| times[k] < times[k - 1]) {
            return Err(PrimitiveError::InvalidParameter {
                field: format!("times[{k}]"),
                reason: "sample times must be non-decreasing".into(),
            });
        }
        if times.first().is_some_and(|t| *t < 0.0) {
            return Err(PrimitiveError::InvalidParameter {
                field: "times[0]".into(),
                reason: "sample times must be ≥ 0".into(),
            });
        }
        let mut r = Rollout::new(self, start)?;
        let d = self.dofs.len();
        let mut values = Vec::with_capacity(times.len() * d);
        let mut velocities = vec![0.0; times.len() * d];
        for (k, t) in times.iter().enumerate() {
            r.advance_to(*t);
            values.extend_from_slice(r.theta());
            r.theta_dot_into(&mut velocities[k * d..(k + 1) * d]);
        }
        Ok(Samples {
            times: times.to_vec(),
            names: self.names(),
            values,
            velocities,
        })
    }

    /// Plays the primitive over [0, τ] on a grid of step `dt`: frames at k·dt for
    /// k = 0..=⌊τ/dt⌋ (rounded when τ/dt is within 1e−6 of an integer).
    pub fn rollout(&self, dt: f64, start: Option<&DofState>) -> Result<Trajectory> {
        require_positive("dt", dt)?;
        let n = (self.duration / dt + 1e-6).floor() as usize + 1;
        let times: Vec<f64> = (0..n).map(|k| k as f64 * dt).collect();
        let s = self.sample(&times, start)?;
        Trajectory::new(dt, s.names, s.values)
    }

    /// Rolls the primitive out at `demo`'s frame times (after time-scaling it to the demo's
    /// duration) and reports the per-DOF RMSE and max error (degrees, or mm for root translation).
    pub fn fit_report(&self, demo: &Trajectory) -> Result<FitReport> {
        demo.validate()?;
        if demo.names != self.names() {
            return Err(PrimitiveError::DofMismatch {
                what: format!(
                    "demonstration DOFs {:?} vs primitive DOFs {:?}",
                    demo.names,
                    self.names()
                ),
            });
        }
        let p = self.with_duration(demo.duration())?;
        let roll = p.rollout(demo.dt, None)?;
        let n = roll.frames().min(demo.frames());
        let d = demo.dofs();
        let dofs = (0..d)
            .map(|j| {
                let unit = DofUnit::of(&demo.names[j]);
                let (mut se, mut mx) = (0.0, 0.0f64);
                for k in 0..n {
                    let e = roll.value(k, j) - demo.value(k, j);
                    se += e * e;
                    mx = mx.max(e.abs());
                }
                DofFit {
                    name: demo.names[j].clone(),
                    unit,
                    rmse: (se / n as f64).sqrt() * unit.report_factor(),
                    max_error: mx * unit.report_factor(),
                }
            })
            .collect();
        Ok(FitReport { dofs })
    }

    /// The primitive as pretty RON text (struct and field names spelled out).
    pub fn to_ron(&self) -> Result<String> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::new().struct_names(true)).map_err(
            |e| PrimitiveError::InvalidParameter {
                field: "primitive".into(),
                reason: format!("cannot serialise: {e}"),
            },
        )
    }

    /// Parses RON text written by [`Primitive::to_ron`]. A file of a newer `format_version` is
    /// refused with [`PrimitiveError::UnsupportedVersion`]; a syntax error, missing or unknown
    /// field gives [`PrimitiveError::Parse`] with line, column and the field's name; a well-formed
    /// but inconsistent primitive gives the field from [`Primitive::validate`].
    /// `source_name` (file name) is used in messages.
    pub fn from_ron(text: &str, source_name: &str) -> Result<Primitive> {
        /// Reads only the version, ignoring every other field, so a newer file is reported as
        /// such rather than as an unknown-field error.
        #[derive(Deserialize)]
        #[serde(rename = "Primitive")]
        struct VersionProbe {
            format_version: u32,
        }
        let parse_err = |e: ron::error::SpannedError| PrimitiveError::Parse {
            source_name: source_name.to_string(),
            line: e.span.start.line,
            column: e.span.start.col,
            message: e.code.to_string(),
        };
        if let Ok(probe) = ron::from_str::<VersionProbe>(text)
            && probe.format_version > PRIMITIVE_FORMAT_VERSION
        {
            return Err(PrimitiveError::UnsupportedVersion {
                source_name: source_name.to_string(),
                found: probe.format_version,
                supported: PRIMITIVE_FORMAT_VERSION,
            });
        }
        let p: Primitive = ron::from_str(text).map_err(parse_err)?;
        p.validate().map_err(|e| match e {
            PrimitiveError::UnsupportedVersion {
                found, supported, ..
            } => PrimitiveError::UnsupportedVersion {
                source_name: source_name.to_string(),
                found,
                supported,
            },
            other => other,
        })?;
        Ok(p)
    }

    /// Writes the primitive as RON to `path` atomically.
    pub fn save(&self, path: &Path) -> Result<()> {
        let text = self.to_ron()?;
        crate::io::write_atomic(path, text.as_bytes()).map_err(|e| PrimitiveError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })
    }

    /// Reads a primitive from a RON file (see [`Primitive::from_ron`]).
    pub fn load(path: &Path) -> Result<Primitive> {
        let text = std::fs::read_to_string(path).map_err(|e| PrimitiveError::Io {
            path: path.display().to_string(),
            message: e.to_string(),
        })?;
        Primitive::from_ron(&text, &path.display().to_string())
    }
}
