//! Mapping real skeletons onto the engine's models.
//!
//! A [`Mapping`] (a RON file a user can copy and edit, see `src/mapping/builtin/`) names, for each
//! anatomical landmark (pelvis, waist, neck, head, and per side clavicle, shoulder, elbow, wrist,
//! hand, hip, knee, ankle, toe), the source joint or End Site that marks it. [`retarget`] turns a
//! clip into the model's DOF angle trajectories plus root motion
//! ([`FigureClip`](crate::humanoid::FigureClip)).
//!
//! A skeleton none of the built-in files fits is mapped automatically ([`detect_automatic`]):
//! the five chains by structure ([`structure`]), the landmarks along them by names
//! ([`names`], synonyms in `builtin/synonyms.ron`) and bone lengths, left and right by
//! geometry, each landmark with a confidence and a reason.

mod automatic;
mod fidelity;
pub mod names;
mod retarget;
mod structure;

pub use automatic::{AutoMapping, Finding, detect_automatic};
pub use fidelity::{EffectorError, effector_errors};
pub use names::{NormalName, Synonyms};
pub use retarget::{leg_length, onto_figure, retarget};

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

use crate::skeleton::{Clip, Skeleton, Transform, forward_kinematics};

/// The RON format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

/// Landmarks every mapping must name.
pub const LANDMARKS: [&str; 22] = [
    "pelvis",
    "waist",
    "neck",
    "head",
    "left_clavicle",
    "left_shoulder",
    "left_elbow",
    "left_wrist",
    "left_hand",
    "left_hip",
    "left_knee",
    "left_ankle",
    "left_toe",
    "right_clavicle",
    "right_shoulder",
    "right_elbow",
    "right_wrist",
    "right_hand",
    "right_hip",
    "right_knee",
    "right_ankle",
    "right_toe",
];

/// A skeleton mapping as written in its RON file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Mapping {
    /// Format version of the file.
    pub format_version: u32,
    /// Name of the source skeleton family.
    pub name: String,
    /// Joint names whose presence identifies this skeleton (all must be present).
    pub detect: Vec<String>,
    /// Landmark → source joint name, or `"<joint>:end"` for its End Site.
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub landmarks: BTreeMap<String, String>,
}

/// Errors of mappings.
#[derive(Debug, thiserror::Error)]
pub enum MappingError {
    /// The file could not be read, parsed, or is of a newer version.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// A landmark missing from the file, or an unknown one.
    #[error("mapping '{mapping}': {message}")]
    Landmarks {
        /// The mapping's name.
        mapping: String,
        /// What is missing or unknown.
        message: String,
    },
    /// A landmark names a joint the skeleton does not have.
    #[error(
        "mapping '{mapping}': landmark '{landmark}' names '{joint}', which the skeleton does not have{hint}"
    )]
    MissingJoint {
        /// The mapping's name.
        mapping: String,
        /// The landmark.
        landmark: String,
        /// The joint it names.
        joint: String,
        /// Similar joint names of the skeleton, if any.
        hint: String,
    },
    /// Neither a built-in mapping nor the automatic detection fits: not a humanoid (or not
    /// standing in the frame looked at).
    #[error(
        "no mapping for this skeleton (root '{root}'): no built-in mapping fits and it was not recognised as a humanoid: {reason}. Write a mapping (marionette mapping FILE.bvh --out my.ron gives a start when the figure is a humanoid) and give it to the command: --mapping FILE, or `mapping: \"FILE\"` beside the clip in a dance manifest"
    )]
    NotHumanoid {
        /// The skeleton's root joint.
        root: String,
        /// What could not be found.
        reason: String,
    },
}

/// A landmark resolved on a skeleton: a joint, or a joint's End Site.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Landmark {
    /// Joint index in the skeleton.
    pub joint: usize,
    /// True for the joint's End Site.
    pub end_site: bool,
}

const BUILTIN: [(&str, &str); 5] = [
    (
        "marionette_humanoid24.ron",
        include_str!("builtin/marionette_humanoid24.ron"),
    ),
    (
        "marionette_fall21.ron",
        include_str!("builtin/marionette_fall21.ron"),
    ),
    ("cmu_cgspeed.ron", include_str!("builtin/cmu_cgspeed.ron")),
    ("cmu_acrnn.ron", include_str!("builtin/cmu_acrnn.ron")),
    ("bandai.ron", include_str!("builtin/bandai.ron")),
];

impl Mapping {
    /// Parses RON text; `origin` names the source in errors.
    pub fn parse(text: &str, origin: &str) -> Result<Mapping, MappingError> {
        let m: Mapping = crate::io::parse_ron(text, origin).map_err(crate::io::FileError::from)?;
        crate::io::check_version(origin, m.format_version, FORMAT_VERSION)?;
        for l in LANDMARKS {
            if !m.landmarks.contains_key(l) {
                return Err(MappingError::Landmarks {
                    mapping: m.name.clone(),
                    message: format!("landmark '{l}' is missing"),
                });
            }
        }
        if let Some(k) = m
            .landmarks
            .keys()
            .find(|k| !LANDMARKS.contains(&k.as_str()))
        {
            return Err(MappingError::Landmarks {
                mapping: m.name.clone(),
                message: format!(
                    "'{k}' is not a landmark; expected one of {}",
                    LANDMARKS.join(", ")
                ),
            });
        }
        Ok(m)
    }

    /// Reads a mapping from a RON file.
    pub fn load(path: &Path) -> Result<Mapping, MappingError> {
        let text = crate::io::read_text(path)?;
        Mapping::parse(&text, &path.display().to_string())
    }

    /// The built-in mappings (`src/mapping/builtin/*.ron`, embedded in the program), parsed
    /// once on first use.
    pub fn builtins() -> &'static [Mapping] {
        static PARSED: OnceLock<Vec<Mapping>> = OnceLock::new();
        PARSED.get_or_init(|| {
            BUILTIN
                .iter()
                .map(|(name, text)| {
                    Mapping::parse(text, name).expect("built-in mappings are valid")
                })
                .collect()
        })
    }

    /// The built-in mapping whose `detect` joints are all in `skeleton`, if any.
    pub fn builtin_for(skeleton: &Skeleton) -> Option<&'static Mapping> {
        Mapping::builtins()
            .iter()
            .find(|m| m.detect.iter().all(|d| skeleton.index(d).is_some()))
    }

    /// The mapping of a skeleton: the built-in one whose `detect` joints it has, else the
    /// automatic one ([`detect_automatic`]) found on its rest pose. With a clip at hand prefer
    /// [`Mapping::detect_clip`], which looks at the first frame (rest poses are often not
    /// standing figures).
    pub fn detect(skeleton: &Skeleton) -> Result<Mapping, MappingError> {
        if let Some(m) = Mapping::builtin_for(skeleton) {
            return Ok(m.clone());
        }
        let rest = rest_globals(skeleton);
        Ok(detect_automatic(skeleton, &rest, Synonyms::builtin())?.mapping)
    }

    /// The mapping of a clip's skeleton: the built-in one whose `detect` joints it has, else the
    /// automatic one found on the clip's first frame.
    pub fn detect_clip(clip: &Clip) -> Result<Mapping, MappingError> {
        if let Some(m) = Mapping::builtin_for(&clip.skeleton) {
            return Ok(m.clone());
        }
        Ok(Mapping::automatic(clip, Synonyms::builtin())?.mapping)
    }

    /// The automatic mapping of a clip's skeleton (built-in files not consulted), found on its
    /// first frame with these synonyms.
    pub fn automatic(clip: &Clip, synonyms: &Synonyms) -> Result<AutoMapping, MappingError> {
        let mut g = vec![];
        if clip.frame_count() > 0 {
            clip.globals(0, &mut g);
        } else {
            g = rest_globals(&clip.skeleton);
        }
        detect_automatic(&clip.skeleton, &g, synonyms)
    }

    /// Resolves a landmark's source name on `skeleton`.
    pub fn resolve(&self, skeleton: &Skeleton, landmark: &str) -> Result<Landmark, MappingError> {
        let source = &self.landmarks[landmark];
        let (joint_name, end_site) = match source.strip_suffix(":end") {
            Some(j) => (j, true),
            None => (source.as_str(), false),
        };
        let missing = |hint: String| MappingError::MissingJoint {
            mapping: self.name.clone(),
            landmark: landmark.into(),
            joint: source.clone(),
            hint,
        };
        let joint = skeleton.index(joint_name).ok_or_else(|| {
            let close: Vec<&str> = skeleton
                .joints
                .iter()
                .map(|j| j.name.as_str())
                .filter(|n| {
                    n.to_lowercase()
                        .contains(&joint_name.to_lowercase()[..joint_name.len().min(4)])
                })
                .take(5)
                .collect();
            missing(if close.is_empty() {
                String::new()
            } else {
                format!(" (similar: {})", close.join(", "))
            })
        })?;
        if end_site && skeleton.joints[joint].end_site.is_none() {
            return Err(missing(" End Site (the joint has none)".into()));
        }
        Ok(Landmark { joint, end_site })
    }
}

/// Global transforms of the rest pose (every rotation identity, the root at its offset).
fn rest_globals(skeleton: &Skeleton) -> Vec<Transform> {
    let n = skeleton.joints.len();
    let t: Vec<glam::DVec3> = skeleton.joints.iter().map(|j| j.offset).collect();
    let mut g = vec![Transform::IDENTITY; n];
    forward_kinematics(skeleton, &t, &vec![glam::DQuat::IDENTITY; n], &mut g);
    g
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Point 9 of issue 38: a landmark given twice kept its last joint without a word.
    #[test]
    fn a_landmark_given_twice_is_refused() {
        let text = include_str!("builtin/bandai.ron").replace(
            "\"waist\": \"Spine\",",
            "\"waist\": \"Spine\", \"pelvis\": \"Spine\",",
        );
        let e = Mapping::parse(&text, "bandai2.ron")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("bandai2.ron:") && e.contains("\"pelvis\" is given twice"),
            "{e}"
        );
    }

    #[test]
    fn builtins_are_parsed_once() {
        assert!(std::ptr::eq(Mapping::builtins(), Mapping::builtins()));
    }

    #[test]
    fn builtins_parse_and_name_every_landmark() {
        let b = Mapping::builtins();
        assert_eq!(b.len(), 5);
        for m in b {
            assert_eq!(m.landmarks.len(), LANDMARKS.len(), "{}", m.name);
            // Left landmarks name left joints (a swapped mapping would be caught here).
            for side in ["left", "right"] {
                for part in ["shoulder", "hip", "ankle"] {
                    let src = m.landmarks[&format!("{side}_{part}")].to_lowercase();
                    let is_left =
                        src.contains("left") || src.starts_with('l') || src.ends_with("_l");
                    assert_eq!(
                        is_left,
                        side == "left",
                        "{}: {side}_{part} -> {src}",
                        m.name
                    );
                }
            }
        }
    }

    #[test]
    fn errors_are_clear() {
        let e = Mapping::parse(
            "(format_version: 1, name: \"x\", detect: [], landmarks: {})",
            "m.ron",
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("landmark 'pelvis' is missing"),
            "{e}"
        );
        let e = Mapping::parse(
            "(format_version: 1,\n name: \"x\",\n detect: [],\n landmarkz: {})",
            "m.ron",
        )
        .unwrap_err();
        assert!(e.to_string().starts_with("m.ron:4:"), "{e}");
    }
}
