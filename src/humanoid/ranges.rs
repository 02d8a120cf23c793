use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};

use super::Figure;

/// The RON format version this build reads and writes.
pub const FORMAT_VERSION: u32 = 1;

/// A range table as written in its RON file: degrees, anatomical sign; keys are DOF names
/// without the side prefix (`knee` serves `left_knee` and `right_knee`), or full DOF names to
/// give one side its own range.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RangeTable {
    /// Format version of the file.
    pub format_version: u32,
    /// The group's name, e.g. `elderly`.
    pub name: String,
    /// `(lower, upper)` in degrees per DOF name.
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub ranges: BTreeMap<String, (f64, f64)>,
}

/// A built-in age group.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AgeGroup {
    /// 65–85 years (the paper's Table 1).
    Elderly,
    /// Healthy adults (normative tables).
    Adult,
}

impl AgeGroup {
    /// The group's name as scenes and files write it (`elderly`, `adult`).
    pub fn name(self) -> &'static str {
        match self {
            AgeGroup::Elderly => "elderly",
            AgeGroup::Adult => "adult",
        }
    }
}

/// Errors reading a range table.
#[derive(Debug, thiserror::Error)]
pub enum RangeError {
    /// The file could not be read, parsed, or is of a newer version.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// A DOF without a range, an unknown DOF name or an empty range.
    #[error("{path}: {message}")]
    Content { path: String, message: String },
}

impl RangeTable {
    /// The built-in table of an age group.
    pub fn builtin(group: AgeGroup) -> RangeTable {
        let (name, text) = match group {
            AgeGroup::Elderly => (
                "fall21_elderly.ron",
                include_str!("data/fall21_elderly.ron"),
            ),
            AgeGroup::Adult => ("fall21_adult.ron", include_str!("data/fall21_adult.ron")),
        };
        RangeTable::parse(text, name).expect("built-in range tables are valid")
    }

    /// The built-in table of `group` for the model named `model` (`fall21` or `humanoid24`), or
    /// `None` when there is none: humanoid24 has an adult table only (the elderly table is the
    /// falling paper's, published for fall21's DOFs).
    pub fn builtin_for(model: &str, group: AgeGroup) -> Option<RangeTable> {
        match (model, group) {
            ("fall21", g) => Some(RangeTable::builtin(g)),
            ("humanoid24", AgeGroup::Adult) => Some(
                RangeTable::parse(
                    include_str!("data/humanoid24_adult.ron"),
                    "humanoid24_adult.ron",
                )
                .expect("built-in range tables are valid"),
            ),
            _ => None,
        }
    }

    /// Reads a table from a RON file.
    pub fn load(path: &Path) -> Result<RangeTable, RangeError> {
        let text = crate::io::read_text(path)?;
        RangeTable::parse(&text, &path.display().to_string())
    }

    /// Parses RON text; `origin` names the source in errors.
    pub fn parse(text: &str, origin: &str) -> Result<RangeTable, RangeError> {
        let t: RangeTable =
            crate::io::parse_ron(text, origin).map_err(crate::io::FileError::from)?;
        crate::io::check_version(origin, t.format_version, FORMAT_VERSION)?;
        for (k, (lo, hi)) in &t.ranges {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return Err(RangeError::Content {
                    path: origin.into(),
                    message: format!(
                        "range of '{k}' must be finite with lower <= upper, found ({lo}, {hi})"
                    ),
                });
            }
        }
        Ok(t)
    }

    /// `(lower, upper)` in radians for every DOF of `model`, in model order. The full DOF name is
    /// looked up first, then the name without its `left_`/`right_` prefix.
    pub fn for_figure(&self, model: &Figure) -> Result<Vec<(f64, f64)>, RangeError> {
        let known: Vec<String> = model.dofs.iter().map(|d| d.name.clone()).collect();
        for k in self.ranges.keys() {
            let matches = known.iter().any(|n| n == k || strip_side(n) == k);
            if !matches {
                return Err(RangeError::Content {
                    path: self.name.clone(),
                    message: format!("'{k}' is not a DOF of model {}", model.name),
                });
            }
        }
        known
            .iter()
            .map(|n| {
                self.ranges
                    .get(n)
                    .or_else(|| self.ranges.get(strip_side(n)))
                    .map(|&(lo, hi)| (lo.to_radians(), hi.to_radians()))
                    .ok_or_else(|| RangeError::Content {
                        path: self.name.clone(),
                        message: format!("no range for DOF '{n}'"),
                    })
            })
            .collect()
    }
}

fn strip_side(name: &str) -> &str {
    name.strip_prefix("left_")
        .or_else(|| name.strip_prefix("right_"))
        .unwrap_or(name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::humanoid::fall21;

    #[test]
    fn builtin_tables_cover_every_fall21_dof() {
        let m = fall21();
        for g in [AgeGroup::Elderly, AgeGroup::Adult] {
            let r = RangeTable::builtin(g).for_figure(&m).unwrap();
            assert_eq!(r.len(), 21);
        }
        let e = RangeTable::builtin(AgeGroup::Elderly)
            .for_figure(&m)
            .unwrap();
        let knee = m.dof_index("left_knee").unwrap();
        assert!(
            (e[knee].0.to_degrees() - 32.0).abs() < 1e-9
                && (e[knee].1.to_degrees() - 127.0).abs() < 1e-9
        );
    }

    #[test]
    fn humanoid24_has_adult_ranges_for_every_dof() {
        let m = crate::humanoid::humanoid24();
        let t = RangeTable::builtin_for("humanoid24", AgeGroup::Adult).unwrap();
        let r = t.for_figure(&m).unwrap();
        assert_eq!(r.len(), 24);
        for (d, (lo, hi)) in m.dofs.iter().zip(&r) {
            assert!(
                *lo <= 0.0 && 0.0 <= *hi && lo < hi,
                "{}: ({lo}, {hi})",
                d.name
            );
        }
        // Where the two models share a DOF, the same normative rows as fall21's adult table.
        let f = RangeTable::builtin(AgeGroup::Adult);
        for k in [
            "waist_flexion",
            "shoulder_flexion",
            "shoulder_rotation",
            "hip_flexion",
            "hip_abduction",
            "knee",
        ] {
            assert_eq!(t.ranges[k], f.ranges[k], "{k}");
        }
        assert_eq!(t.ranges["elbow_flexion"], f.ranges["elbow"]);
        assert!(RangeTable::builtin_for("humanoid24", AgeGroup::Elderly).is_none());
        assert_eq!(
            RangeTable::builtin_for("fall21", AgeGroup::Elderly),
            Some(RangeTable::builtin(AgeGroup::Elderly))
        );
    }

    #[test]
    fn elderly_ranges_are_narrower_than_adult_ones() {
        let m = fall21();
        let e = RangeTable::builtin(AgeGroup::Elderly)
            .for_figure(&m)
            .unwrap();
        let a = RangeTable::builtin(AgeGroup::Adult).for_figure(&m).unwrap();
        for (i, d) in m.dofs.iter().enumerate() {
            assert!(e[i].1 - e[i].0 < a[i].1 - a[i].0, "{}", d.name);
        }
    }

    #[test]
    fn errors_name_line_column_and_field() {
        let bad = "(\n format_version: 1,\n name: \"x\",\n rangez: {},\n)";
        let err = RangeTable::parse(bad, "t.ron").unwrap_err().to_string();
        assert!(err.starts_with("t.ron:4:"), "{err}");
        assert!(err.contains("rangez"), "{err}");
        let newer = "(format_version: 9, name: \"x\", ranges: {})";
        assert!(
            RangeTable::parse(newer, "n.ron")
                .unwrap_err()
                .to_string()
                .contains("newer")
        );
        let unknown = "(format_version: 1, name: \"x\", ranges: {\"tail\": (0.0, 1.0)})";
        let t = RangeTable::parse(unknown, "u.ron").unwrap();
        assert!(
            t.for_figure(&fall21())
                .unwrap_err()
                .to_string()
                .contains("tail")
        );
    }
}
