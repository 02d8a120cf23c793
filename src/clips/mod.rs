//! Keyframed clips authored by the project (`scenes/clips/*.ron`): the default data that the
//! demos and tests use, so nothing from outside is needed.
//!
//! A keyframed clip gives, on one of the engine's models, DOF angles in degrees at key times;
//! each DOF is interpolated over the keys that name it (monotone cubic, [`pchip`]). The root's
//! horizontal path and turn are keyed too; its height is solved so that the lowest foot point
//! touches the floor, except during the listed flight spans, where it follows a ballistic arc
//! between take-off and landing heights (gravity 9.81 m/s²). [`ballistic`] takes the whole-body
//! centre of mass of a clip and can put it, instead of the root, on the arc.

pub mod ballistic;
mod pchip;

pub use pchip::pchip;

use std::collections::BTreeMap;
use std::path::Path;

use glam::{DQuat, DVec3};
use serde::{Deserialize, Serialize};

use crate::humanoid::{Figure, FigureClip};

/// The RON format version this build reads.
pub const FORMAT_VERSION: u32 = 1;

/// Most frames a keyframed clip may sample (`duration × fps`): a million, about 2.3 hours at
/// 120 fps (a clip of `duration: 1e7` is an error, not an allocation failure).
pub const MAX_FRAMES: usize = 1_000_000;

/// Largest keyed DOF angle or pelvis angle, degrees (ten turns).
pub const MAX_KEY_ANGLE_DEG: f64 = 3600.0;

/// Largest keyed root position, metres.
pub const MAX_KEY_POSITION_M: f64 = 10_000.0;

/// Gravity used for flight arcs, m/s².
pub const GRAVITY: f64 = 9.81;

/// One key: a time and what is keyed at it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Key {
    /// Time, seconds.
    pub t: f64,
    /// DOF angles at this key, degrees (anatomical sign).
    #[serde(default)]
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub dofs: BTreeMap<String, f64>,
    /// Root position along +Z (forward), metres.
    #[serde(default)]
    pub forward: Option<f64>,
    /// Root position along +X (the figure's left), metres.
    #[serde(default)]
    pub lateral: Option<f64>,
    /// Pelvis forward tilt (about +X), degrees.
    #[serde(default)]
    pub pitch: Option<f64>,
    /// Pelvis turn to the left (about +Y), degrees.
    #[serde(default)]
    pub turn: Option<f64>,
}

/// A keyframed clip as written in its RON file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KeyframeClip {
    /// Format version of the file.
    pub format_version: u32,
    /// Clip name.
    pub name: String,
    /// Model the DOF names belong to (`humanoid24` or `fall21`).
    pub model: String,
    /// Sampling rate of the generated clip, frames per second.
    pub fps: f64,
    /// Duration, seconds (frames cover `[0, duration)`).
    pub duration: f64,
    /// Standing height of the figure, metres (default: the model's 1.70 m).
    #[serde(default)]
    pub height: Option<f64>,
    /// Airborne spans `(take_off_s, landing_s)`.
    #[serde(default)]
    pub flights: Vec<(f64, f64)>,
    /// The keys, in increasing time.
    pub keys: Vec<Key>,
}

/// Errors of keyframed clips.
#[derive(Debug, thiserror::Error)]
pub enum KeyframeError {
    /// The file could not be read, parsed, or is of a newer version.
    #[error(transparent)]
    File(#[from] crate::io::FileError),
    /// Inconsistent content.
    #[error("{path}: {message}")]
    Content { path: String, message: String },
}

/// Key `i`'s root values within their bounds and its DOFs those of `model` (named
/// `model_name`), at finite angles within ±[`MAX_KEY_ANGLE_DEG`]; otherwise what is wrong.
fn check_key(i: usize, k: &Key, model: &Figure, model_name: &str) -> Result<(), String> {
    let root = [
        ("forward", k.forward, MAX_KEY_POSITION_M, "m"),
        ("lateral", k.lateral, MAX_KEY_POSITION_M, "m"),
        ("pitch", k.pitch, MAX_KEY_ANGLE_DEG, "°"),
        ("turn", k.turn, MAX_KEY_ANGLE_DEG, "°"),
    ];
    for (name, v, max, unit) in root {
        if let Some(v) = v
            && !(v.is_finite() && v.abs() <= max)
        {
            return Err(format!(
                "key {i} (t = {}): {name} {v} is beyond ±{max} {unit}",
                k.t
            ));
        }
    }
    for (name, v) in &k.dofs {
        if v.is_finite() && v.abs() > MAX_KEY_ANGLE_DEG {
            return Err(format!(
                "key {i} (t = {}): '{name}' is {v}°, beyond ±{MAX_KEY_ANGLE_DEG}°",
                k.t
            ));
        }
        if model.dof_index(name).is_none() {
            return Err(format!(
                "key {i} (t = {}): '{name}' is not a DOF of {}",
                k.t, model_name
            ));
        }
        if !v.is_finite() {
            return Err(format!(
                "key {i} (t = {}): '{name}' is not a finite angle",
                k.t
            ));
        }
    }
    Ok(())
}

impl KeyframeClip {
    /// Parses RON text and checks it; `origin` names the source in errors.
    pub fn parse(text: &str, origin: &str) -> Result<KeyframeClip, KeyframeError> {
        let c: KeyframeClip =
            crate::io::parse_ron(text, origin).map_err(crate::io::FileError::from)?;
        let bad = |message: String| {
            Err(KeyframeError::Content {
                path: origin.into(),
                message,
            })
        };
        crate::io::check_version(origin, c.format_version, FORMAT_VERSION)?;
        if !(c.fps.is_finite() && c.fps > 0.0 && c.duration.is_finite() && c.duration > 0.0) {
            return bad(format!(
                "fps and duration must be positive, found fps {} and duration {}",
                c.fps, c.duration
            ));
        }
        let frames = c.duration * c.fps;
        if frames > MAX_FRAMES as f64 {
            return bad(format!(
                "duration {} s at {} fps is {frames:.0} frames, more than the {MAX_FRAMES} a clip \
                 may have",
                c.duration, c.fps
            ));
        }
        if let Some(h) = c.height {
            let (lo, hi) = crate::skeleton::FIGURE_SIZE_M;
            if !(h.is_finite() && (lo..=hi).contains(&h)) {
                return bad(format!(
                    "height {h} m is outside the human range {lo}..{hi} m"
                ));
            }
        }
        let model = Figure::by_name(&c.model).map_err(|e| KeyframeError::Content {
            path: origin.into(),
            message: e.to_string(),
        })?;
        let mut last = f64::NEG_INFINITY;
        for (i, k) in c.keys.iter().enumerate() {
            if !(k.t.is_finite() && k.t > last) {
                return bad(format!(
                    "key {i}: time {} must be finite and after the previous key's {last}",
                    k.t
                ));
            }
            last = k.t;
            if let Err(message) = check_key(i, k, &model, &c.model) {
                return bad(message);
            }
        }
        for &(a, b) in &c.flights {
            if !(a < b && a >= 0.0 && b <= c.duration) {
                return bad(format!(
                    "flight ({a}, {b}) must satisfy 0 <= take-off < landing <= duration"
                ));
            }
        }
        Ok(c)
    }

    /// Reads and checks a keyframed clip file.
    pub fn load(path: &Path) -> Result<KeyframeClip, KeyframeError> {
        let text = crate::io::read_text(path)?;
        KeyframeClip::parse(&text, &path.display().to_string())
    }

    /// Samples the clip at its frame rate into a motion on its model.
    pub fn to_figure_clip(&self) -> FigureClip {
        let base = Figure::by_name(&self.model).expect("checked in parse");
        let model = match self.height {
            Some(h) => base.scaled_to_height(h),
            None => base,
        };
        let frames = (self.duration * self.fps).round().max(1.0) as usize;
        let dt = 1.0 / self.fps;
        // Per DOF (and root channel): the keys that name it.
        let series = |pick: &dyn Fn(&Key) -> Option<f64>| -> (Vec<f64>, Vec<f64>) {
            self.keys
                .iter()
                .filter_map(|k| pick(k).map(|v| (k.t, v)))
                .unzip()
        };
        let dof_keys: Vec<(Vec<f64>, Vec<f64>)> = model
            .dofs
            .iter()
            .map(|d| series(&|k: &Key| k.dofs.get(&d.name).map(|v| v.to_radians())))
            .collect();
        let fwd = series(&|k: &Key| k.forward);
        let lat = series(&|k: &Key| k.lateral);
        let pitch = series(&|k: &Key| k.pitch.map(f64::to_radians));
        let turn = series(&|k: &Key| k.turn.map(f64::to_radians));
        let at = |s: &(Vec<f64>, Vec<f64>), t: f64| pchip(&s.0, &s.1, t);

        let mut clip = FigureClip::with_capacity(model.clone(), dt, frames);
        for f in 0..frames {
            let t = f as f64 * dt;
            let angles: Vec<f64> = dof_keys.iter().map(|s| at(s, t)).collect();
            let root_q =
                DQuat::from_rotation_y(at(&turn, t)) * DQuat::from_rotation_x(at(&pitch, t));
            clip.root_translation
                .push(DVec3::new(at(&lat, t), 0.0, at(&fwd, t)));
            clip.root_rotation.push(root_q);
            clip.angles.extend(angles);
        }
        // On the ground the lowest foot point touches y = 0; in flight the root follows the
        // chord between take-off and landing heights plus a ballistic arc g(t − a)(b − t)/2.
        clip.keep_feet_on_floor(&self.flights, 0.0);
        for f in 0..frames {
            let t = f as f64 * dt;
            if let Some(&(a, b)) = self.flights.iter().find(|(a, b)| t > *a && t < *b) {
                clip.root_translation[f].y += 0.5 * GRAVITY * (t - a) * (b - t);
            }
        }
        clip
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const JUMP: &str = r#"(
        format_version: 1, name: "t", model: "humanoid24", fps: 100.0, duration: 1.0,
        flights: [(0.4, 0.7)],
        keys: [
            (t: 0.0, dofs: {"left_knee": 0.0, "right_knee": 0.0}, pitch: 0.0),
            (t: 0.3, dofs: {"left_knee": 90.0, "right_knee": 90.0}, pitch: 20.0),
            (t: 0.4, dofs: {"left_knee": 0.0, "right_knee": 0.0}, pitch: 0.0),
            (t: 1.0, dofs: {"left_knee": 0.0, "right_knee": 0.0}),
        ],
    )"#;

    #[test]
    fn knee_keys_are_met_and_feet_touch_the_floor_outside_flight() {
        let c = KeyframeClip::parse(JUMP, "jump").unwrap().to_figure_clip();
        let knee = c.model.dof_index("left_knee").unwrap();
        assert_eq!(c.frame_count(), 100);
        assert!((c.frame_angles(30)[knee].to_degrees() - 90.0).abs() < 1e-9);
        // Crouched: root lower than standing; flight apex ≈ g T²/8 above take-off height.
        let stand = c.root_translation[0].y;
        assert!((stand - 0.53 * 1.70).abs() < 0.02, "{stand}");
        assert!(c.root_translation[30].y < stand - 0.05);
        let apex = c.root_translation[55].y;
        assert!(
            (apex - stand - GRAVITY * 0.09 / 8.0).abs() < 0.01,
            "{apex} vs {stand}"
        );
    }

    #[test]
    fn sizes_and_magnitudes_beyond_the_limits_are_errors() {
        let cases = [
            (
                JUMP.replace("duration: 1.0", "duration: 1e7"),
                "more than the 1000000",
            ),
            (
                JUMP.replace("\"right_knee\": 90.0", "\"right_knee\": 1e300"),
                "beyond ±3600°",
            ),
            (
                JUMP.replace("pitch: 20.0", "pitch: 1e9"),
                "pitch 1000000000 is beyond",
            ),
            (
                JUMP.replace("duration: 1.0,", "duration: 1.0, height: 1000.0,"),
                "outside the human range",
            ),
            (
                JUMP.replace("format_version: 1", "format_version: 0"),
                "start at 1",
            ),
        ];
        for (text, want) in cases {
            let e = KeyframeClip::parse(&text, "t.ron").unwrap_err().to_string();
            assert!(e.contains(want), "{e}");
        }
    }

    #[test]
    fn bad_keys_are_named() {
        let e = KeyframeClip::parse(
            &JUMP.replace("\"right_knee\": 90.0", "\"right_kne\": 90.0"),
            "j.ron",
        )
        .unwrap_err();
        assert!(
            e.to_string()
                .contains("'right_kne' is not a DOF of humanoid24"),
            "{e}"
        );
        let e = KeyframeClip::parse(&JUMP.replace("t: 0.3", "t: 0.5"), "j.ron").unwrap_err();
        assert!(e.to_string().contains("key 2"), "{e}");
        let e = KeyframeClip::parse(&JUMP.replace("fps:", "fpz:"), "j.ron").unwrap_err();
        assert!(e.to_string().starts_with("j.ron:2:"), "{e}");
    }
}
