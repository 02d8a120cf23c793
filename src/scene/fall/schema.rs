//! The `Fall` scene's schema: a [`FallConfig`] (the one schema of a fall) with the scene's own
//! fields beside it, and its translation into the configuration the experiment runs.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use serde::de::{self, DeserializeSeed, Deserializer, IntoDeserializer, MapAccess, Visitor};
use serde::{Deserialize, Serialize, Serializer};

use super::super::SceneError;
use super::super::primitives::PrimitiveRender;
use super::super::source::resolve_path;
use crate::experiments::fall::{FallConfig, Ranges};
use crate::humanoid::fall21;
use crate::humanoid::{AgeGroup, RangeTable};

/// PD settings per DOF, by full DOF name (`left_knee`) or side-less name (`knee`, both sides);
/// DOFs not named keep the fall's. The schema of a controller file (an evolution writes
/// `best_<group>.controller.ron`) and of a `Fall` scene's `controller` block.
#[derive(Clone, Debug, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Controller {
    /// Key pose θ_d, degrees.
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub key_pose_deg: BTreeMap<String, f64>,
    /// Proportional gains k_p, N·m/rad.
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub kp: BTreeMap<String, f64>,
    /// Derivative gains k_v, N·m·s/rad.
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub kv: BTreeMap<String, f64>,
    /// Time the reaction toward the key pose starts, seconds.
    pub start_s: Option<f64>,
    /// The time step this controller was evolved at, seconds: the step its damage holds at,
    /// which the fall takes when `fall.dt_s` is left out. A scene's own `controller.dt_s`
    /// overrides the file's (e.g. half of it, to check the fall at half the step).
    pub dt_s: Option<f64>,
    /// Whether the floor's normal damping was taken implicitly when this controller was
    /// evolved ([`crate::dynamics::forces::contact::ContactParams::implicit_damping`]): the
    /// fall replays with the same contact. A scene's own `controller` block overrides the
    /// file's; left out everywhere, the fall's `contact` decides.
    pub contact_implicit_damping: Option<bool>,
    /// The integration scheme this controller was evolved with (written when it is not the
    /// paper fall's): the fall replays with it. Overridden and left out as
    /// `contact_implicit_damping`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub integrator: Option<crate::dynamics::Integrator>,
    /// The finer reaction it was evolved with ([`FallConfig::reaction_window_s`], seconds;
    /// written when above 0): the fall replays with it, as `integrator`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reaction_window_s: Option<f64>,
    /// Sub-steps per step in that window ([`FallConfig::reaction_substeps`]; written when above
    /// 1), as `integrator`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reaction_substeps: Option<u32>,
    /// The age group whose fall this controller was evolved on (an evolution writes it): that
    /// group's fall replays its evolved damage. The report names it
    /// (`controller_evolved_for`), and a fall of other groups only is noted on standard error.
    pub evolved_for: Option<AgeGroup>,
}

/// A `Fall` scene's `fall` block: a [`FallConfig`], each field left out keeping the paper's
/// value ([`FallConfig::paper`]), but for the three the scene decides:
/// - `dt_s` left out: the controller's step (its `dt_s`), else the paper's 0.5 ms; given and
///   different from the controller's step, the scene is refused;
/// - `ranges` left out: the scene's age group's built-in table; a `File` is relative to the
///   scene file;
/// - `torque_limits_nm` is always the age group's strength (a scene that gives it is refused).
///
/// Written back (for `--set`) as the full configuration, `dt_s` and `ranges` `null` when left
/// out.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct SceneFall {
    /// The configuration read; its `dt_s`, `ranges` and `torque_limits_nm` are the paper's for
    /// the elderly group (the scene decides them: [`FallScene::config`]).
    pub config: FallConfig,
    /// `dt_s` as given.
    pub dt_s: Option<f64>,
    /// `ranges` as given.
    pub ranges: Option<Ranges>,
}

/// The name of a struct field, as text.
struct FieldName;

impl<'de> DeserializeSeed<'de> for FieldName {
    type Value = String;
    fn deserialize<D: Deserializer<'de>>(self, d: D) -> Result<String, D::Error> {
        d.deserialize_identifier(self)
    }
}

impl Visitor<'_> for FieldName {
    type Value = String;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a field name")
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<String, E> {
        Ok(v.to_string())
    }
}

/// The fields of a `fall` block as [`FallConfig`] reads them, the three the scene decides taken
/// out on the way.
struct Intercept<'a, A> {
    map: A,
    fall: &'a mut SceneFall,
    seen: Vec<&'static str>,
}

impl<'de, A: MapAccess<'de>> MapAccess<'de> for Intercept<'_, A> {
    type Error = A::Error;

    fn next_key_seed<K: DeserializeSeed<'de>>(
        &mut self,
        seed: K,
    ) -> Result<Option<K::Value>, A::Error> {
        loop {
            let Some(key) = self.map.next_key_seed(FieldName)? else {
                return Ok(None);
            };
            let name = match key.as_str() {
                "dt_s" => "dt_s",
                "ranges" => "ranges",
                "torque_limits_nm" => {
                    return Err(de::Error::custom(
                        "torque_limits_nm: a Fall scene's figure has its age group's strength \
                         (age_group); leave torque_limits_nm out",
                    ));
                }
                _ => return seed.deserialize(key.into_deserializer()).map(Some),
            };
            if self.seen.contains(&name) {
                return Err(de::Error::duplicate_field(name));
            }
            self.seen.push(name);
            if name == "dt_s" {
                self.fall.dt_s = self.map.next_value()?;
            } else {
                self.fall.ranges = self.map.next_value()?;
            }
        }
    }

    fn next_value_seed<V: DeserializeSeed<'de>>(&mut self, seed: V) -> Result<V::Value, A::Error> {
        self.map.next_value_seed(seed)
    }
}

/// Reads a `fall` block.
struct SceneFallVisitor;

impl<'de> Visitor<'de> for SceneFallVisitor {
    type Value = SceneFall;
    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a fall configuration (FallConfig)")
    }
    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<SceneFall, A::Error> {
        let mut fall = SceneFall::default();
        let config = FallConfig::deserialize(de::value::MapAccessDeserializer::new(Intercept {
            map,
            fall: &mut fall,
            seen: Vec::new(),
        }))?;
        fall.config = config;
        Ok(fall)
    }
}

impl<'de> Deserialize<'de> for SceneFall {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_struct("FallConfig", &[], SceneFallVisitor)
    }
}

impl Serialize for SceneFall {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::Error;
        if let Some(dt) = self.dt_s.filter(|dt| !dt.is_finite()) {
            // It would read back as null, that is left out.
            return Err(S::Error::custom(format!(
                "fall.dt_s is {dt}: write a finite number"
            )));
        }
        let mut v = serde_json::to_value(&self.config).map_err(S::Error::custom)?;
        if let Some(o) = v.as_object_mut() {
            o.remove("torque_limits_nm");
            o.insert("dt_s".into(), serde_json::json!(self.dt_s));
            o.insert("ranges".into(), serde_json::json!(self.ranges));
        }
        v.serialize(s)
    }
}

/// A pushed fall: an elderly or adult figure with given PD settings, pushed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FallScene {
    /// Scene format version.
    pub format_version: u32,
    /// Scene name.
    pub name: String,
    /// Age group of the figure: its joint ranges (unless `fall.ranges` gives others) and its
    /// strength (`Elderly` or `Adult`).
    pub age_group: AgeGroup,
    /// The fall: push, step, integrator, duration, subject, contact, damage weights, gains…
    /// (see [`SceneFall`] for the fields the scene decides).
    #[serde(default)]
    pub fall: SceneFall,
    /// PD control toward a key pose, by DOF name, applied over `fall` and the controller file.
    #[serde(default)]
    pub controller: Controller,
    /// A controller file (RON, a `controller` block such as the `best_<group>.controller.ron`
    /// an evolution writes), applied before `controller`; relative to the scene file.
    #[serde(default)]
    pub controller_file: Option<String>,
    /// Also simulate this age group (same push and controller), beside the first.
    #[serde(default)]
    pub compare_with: Option<AgeGroup>,
    /// Pictures.
    #[serde(default)]
    pub render: PrimitiveRender,
}

fn strip_side(name: &str) -> &str {
    name.strip_prefix("left_")
        .or_else(|| name.strip_prefix("right_"))
        .unwrap_or(name)
}

/// Applies per-DOF overrides by full or side-less name; an unknown name is an error.
fn override_per_dof(
    field: &str,
    values: &mut [f64],
    names: &[String],
    by_name: &BTreeMap<String, f64>,
) -> Result<(), SceneError> {
    for (key, v) in by_name {
        let mut hit = false;
        for (i, n) in names.iter().enumerate() {
            if n == key || strip_side(n) == key {
                values[i] = *v;
                hit = true;
            }
        }
        if !hit {
            return Err(SceneError::UnknownName {
                field: format!("controller.{field}"),
                name: key.clone(),
                expected: "a fall21 DOF (e.g. knee, left_knee, neck_flexion)".into(),
            });
        }
    }
    Ok(())
}

impl FallScene {
    /// The time step (s): `fall.dt_s`, else the controller's `dt_s` (the scene's
    /// `controller` block before the file's), else the paper's; a `fall.dt_s` that
    /// differs from the controller's step is an error naming both.
    fn step(&self, from_file: Option<&Controller>) -> Result<f64, SceneError> {
        let controller = match (self.controller.dt_s, from_file.and_then(|c| c.dt_s)) {
            (Some(dt), _) => Some((dt, "controller.dt_s".to_string())),
            (None, Some(dt)) => Some((
                dt,
                format!(
                    "the controller file '{}'",
                    self.controller_file.as_deref().unwrap_or_default()
                ),
            )),
            (None, None) => None,
        };
        match (self.fall.dt_s, controller) {
            (Some(dt), Some((evolved, from))) if dt != evolved => {
                Err(SceneError::StepMismatch { dt, evolved, from })
            }
            (Some(dt), _) => Ok(dt),
            (None, Some((evolved, _))) => Ok(evolved),
            (None, None) => Ok(FallConfig::default().dt_s),
        }
    }

    /// The controller file, read, if the scene names one.
    fn controller_from_file(&self, base: &Path) -> Result<Option<Controller>, SceneError> {
        let Some(f) = &self.controller_file else {
            return Ok(None);
        };
        let path = resolve_path(f, base);
        let text = crate::io::read_text(&path)?;
        Ok(Some(crate::io::parse_ron::<Controller>(
            &text,
            &path.display().to_string(),
        )?))
    }

    /// The simulation configuration: the scene's `fall` with the age group's ranges and
    /// strength, the controllers applied and the step decided.
    pub fn config(&self, base: &Path) -> Result<FallConfig, SceneError> {
        Ok(self.configure(base)?.0)
    }

    /// [`Self::config`] and the age group the controller was evolved for (the scene's
    /// `controller` block's, else the file's), the file read once.
    pub(super) fn configure(
        &self,
        base: &Path,
    ) -> Result<(FallConfig, Option<AgeGroup>), SceneError> {
        let mut c = self.fall.config.clone();
        let paper = FallConfig::paper(self.age_group);
        c.torque_limits_nm = paper.torque_limits_nm;
        c.ranges = match &self.fall.ranges {
            None => paper.ranges,
            Some(Ranges::File(f)) => {
                Ranges::Table(RangeTable::load(&resolve_path(&f.to_string_lossy(), base))?)
            }
            Some(r) => r.clone(),
        };
        let names = fall21().dof_names();
        let from_file = self.controller_from_file(base)?;
        for ctrl in from_file.iter().chain(std::iter::once(&self.controller)) {
            override_per_dof(
                "key_pose_deg",
                &mut c.key_pose_deg,
                &names,
                &ctrl.key_pose_deg,
            )?;
            override_per_dof("kp", &mut c.kp, &names, &ctrl.kp)?;
            override_per_dof("kv", &mut c.kv, &names, &ctrl.kv)?;
            if let Some(s) = ctrl.start_s {
                c.control_start_s = s;
            }
            // How it was stepped: the file's, then the scene's own block over it; left out
            // everywhere, the fall's.
            if let Some(b) = ctrl.contact_implicit_damping {
                c.contact.implicit_damping = b;
            }
            if let Some(i) = ctrl.integrator {
                c.integrator = i;
            }
            if let Some(w) = ctrl.reaction_window_s {
                c.reaction_window_s = w;
            }
            if let Some(k) = ctrl.reaction_substeps {
                c.reaction_substeps = k;
            }
        }
        c.dt_s = self.step(from_file.as_ref())?;
        let evolved_for = self
            .controller
            .evolved_for
            .or(from_file.and_then(|f| f.evolved_for));
        Ok((c, evolved_for))
    }
}

#[cfg(test)]
mod tests {
    use super::super::super::{Scene, apply_overrides};
    use super::*;

    fn fall(text: &str) -> Result<FallScene, String> {
        let scene = format!("Fall(format_version: 1, name: \"f\", age_group: adult, {text})");
        match Scene::parse(&scene, "f.ron").map_err(|e| e.to_string())? {
            Scene::Fall(f) => Ok(*f),
            s => panic!("{s:?}"),
        }
    }

    #[test]
    fn a_fall_block_is_a_fall_config_with_the_step_and_ranges_left_to_the_scene() {
        // Left out: the paper's values, the step and the ranges undecided.
        let f = fall("").unwrap();
        assert_eq!(f.fall, SceneFall::default());
        assert_eq!((f.fall.dt_s, &f.fall.ranges), (None, &None));
        let c = f.config(Path::new(".")).unwrap();
        assert_eq!(c, FallConfig::paper(AgeGroup::Adult));
        // Given: the FallConfig's fields, the step and the ranges.
        let f = fall("fall: (dt_s: 0.0004, mass_kg: 70.0, ranges: Builtin(elderly))").unwrap();
        assert_eq!(f.fall.dt_s, Some(0.0004));
        assert_eq!(f.fall.config.mass_kg, 70.0);
        let c = f.config(Path::new(".")).unwrap();
        assert_eq!(c.dt_s, 0.0004);
        assert_eq!(c.ranges, Ranges::Builtin(AgeGroup::Elderly));
        assert_eq!(
            c.torque_limits_nm,
            FallConfig::paper(AgeGroup::Adult).torque_limits_nm
        );
    }

    #[test]
    fn a_controller_replays_with_the_scheme_it_was_evolved_with() {
        use crate::dynamics::Integrator;
        let f = fall(
            "controller: (dt_s: Some(0.002), integrator: Some(LinearlyImplicitEuler), \
             reaction_window_s: Some(0.1), reaction_substeps: Some(4))",
        )
        .unwrap();
        let c = f.config(Path::new(".")).unwrap();
        assert_eq!(
            (
                c.integrator,
                c.dt_s,
                c.reaction_window_s,
                c.reaction_substeps
            ),
            (Integrator::LinearlyImplicitEuler, 0.002, 0.1, 4)
        );
        // Left out: the fall's own.
        let c = fall("").unwrap().config(Path::new(".")).unwrap();
        let paper = FallConfig::paper(AgeGroup::Adult);
        assert_eq!(
            (c.integrator, c.reaction_window_s, c.reaction_substeps),
            (
                paper.integrator,
                paper.reaction_window_s,
                paper.reaction_substeps
            )
        );
    }

    #[test]
    fn set_keeps_a_step_left_out_undecided_and_reaches_it() {
        let s = Scene::Fall(Box::new(fall("fall: (mass_kg: 70.0)").unwrap()));
        let Scene::Fall(f) = apply_overrides(&s, &["name=g".into()]).unwrap() else {
            panic!()
        };
        assert_eq!((f.fall.dt_s, &f.fall.ranges), (None, &None));
        assert_eq!(f.fall.config.mass_kg, 70.0);
        let Scene::Fall(f) = apply_overrides(
            &s,
            &["fall.dt_s=0.00025".into(), "fall.push.force_n=600".into()],
        )
        .unwrap() else {
            panic!()
        };
        assert_eq!(f.fall.dt_s, Some(0.00025));
        assert_eq!(f.fall.config.push.force_n, 600.0);
    }

    #[test]
    fn a_fall_block_refuses_strength_repeats_and_unknown_fields() {
        let e = fall("fall: (torque_limits_nm: None)").unwrap_err();
        assert!(e.contains("age group's strength"), "{e}");
        let e = fall("fall: (dt_s: 0.0004, dt_s: 0.0005)").unwrap_err();
        assert!(e.contains("dt_s"), "{e}");
        let e = fall("fall: (dt: 0.0004)").unwrap_err();
        assert!(e.contains("f.ron:1:") && e.contains("dt_s"), "{e}");
        let s = Scene::Fall(Box::new(fall("fall: (dt_s: 0.0004)").unwrap()));
        let Scene::Fall(mut f) = s else { panic!() };
        f.fall.dt_s = Some(f64::NAN);
        let e = apply_overrides(&Scene::Fall(f), &["name=g".into()])
            .unwrap_err()
            .to_string();
        assert!(e.contains("finite"), "{e}");
    }
}
