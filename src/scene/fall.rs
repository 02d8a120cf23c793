//! The `Fall` scene: the falling paper's pushed figure (SPEC §3), simulated in an ECS world.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use serde_json::json;

use super::primitives::PrimitiveRender;
use super::source::resolve_path;
use super::{SceneError, draw_tracks, page, write_output};
use crate::dynamics::forces::contact::ContactParams;
use crate::dynamics::forces::external::Push;
use crate::dynamics::integrator::Integrator;
use crate::experiments::fall::ecs::run_parallel;
use crate::experiments::fall::{FallConfig, FallResult, Ranges};
use crate::humanoid::fall21;
use crate::humanoid::ranges::{AgeGroup, RangeTable};
use crate::humanoid::strength::torque_limits;
use crate::render::{Figure, Page, PageMotion, Plot, Series, Track, plot};

/// Time stepping of a simulation (a field left out keeps the paper's value).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Simulation {
    /// Step, seconds. Left out: the step the controller was evolved at (its `dt_s`, e.g. from
    /// a `controller_file`), else the paper's 0.5 ms. Given and different from the
    /// controller's step, the scene is refused (the controller's damage holds at its step).
    pub dt: Option<f64>,
    /// Integration scheme.
    pub integrator: Integrator,
    /// Simulated time, seconds.
    pub duration: f64,
}

impl Default for Simulation {
    fn default() -> Self {
        let c = FallConfig::default();
        Self {
            dt: None,
            integrator: c.integrator,
            duration: c.duration_s,
        }
    }
}

/// The subject (default 1.70 m, 65 kg).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Body {
    /// Standing height, metres.
    pub height_m: f64,
    /// Mass, kilograms.
    pub mass_kg: f64,
}

impl Default for Body {
    fn default() -> Self {
        let c = FallConfig::default();
        Self {
            height_m: c.height_m,
            mass_kg: c.mass_kg,
        }
    }
}

/// PD settings per DOF, by full DOF name (`left_knee`) or side-less name (`knee`, both sides);
/// DOFs not named keep the paper defaults.
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
    /// which the fall takes when `simulation.dt` is left out. A scene's own `controller.dt_s`
    /// overrides the file's (e.g. half of it, to check the fall at half the step).
    pub dt_s: Option<f64>,
    /// Whether the floor's normal damping was taken implicitly when this controller was
    /// evolved ([`ContactParams::implicit_damping`]): the fall replays with the same contact.
    /// A scene's own `controller` block overrides the file's; left out everywhere, the scene's
    /// `contact` decides.
    pub contact_implicit_damping: Option<bool>,
    /// The age group whose fall this controller was evolved on (an evolution writes it): that
    /// group's fall replays its evolved damage. The report names it
    /// (`controller_evolved_for`), and a fall of other groups only is noted on standard error.
    pub evolved_for: Option<AgeGroup>,
}

/// A pushed fall: an elderly or adult figure with given PD settings, pushed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FallScene {
    /// Scene format version.
    pub format_version: u32,
    /// Scene name.
    pub name: String,
    /// Age group whose joint ranges are used (`Elderly` or `Adult`).
    pub age_group: AgeGroup,
    /// A range table (RON) to use instead of the age group's built-in one.
    #[serde(default)]
    pub ranges_file: Option<String>,
    /// Time stepping.
    #[serde(default)]
    pub simulation: Simulation,
    /// The push.
    #[serde(default)]
    pub push: Push,
    /// The subject (default 1.70 m, 65 kg).
    #[serde(default)]
    pub body: Body,
    /// PD control toward a key pose.
    #[serde(default)]
    pub controller: Controller,
    /// A controller file (RON, a `controller` block such as the `best_<group>.controller.ron`
    /// an evolution writes), applied before `controller`; relative to the scene file.
    #[serde(default)]
    pub controller_file: Option<String>,
    /// Damage weight w_i per link (links not named keep the default; the head is protected most).
    #[serde(default)]
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub damage_weights: BTreeMap<String, f64>,
    /// Floor contact parameters (scales on the published tissue gains, friction, floor).
    #[serde(default)]
    pub contact: ContactParams,
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
    /// The time step (s): `simulation.dt`, else the controller's `dt_s` (the scene's
    /// `controller` block before the file's), else the paper's; a `simulation.dt` that
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
        match (self.simulation.dt, controller) {
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

    /// The simulation configuration: the paper's experiment for the age group, with this
    /// scene's settings.
    pub fn config(&self, base: &Path) -> Result<FallConfig, SceneError> {
        Ok(self.configure(base)?.0)
    }

    /// [`Self::config`] and the age group the controller was evolved for (the scene's
    /// `controller` block's, else the file's), the file read once.
    fn configure(&self, base: &Path) -> Result<(FallConfig, Option<AgeGroup>), SceneError> {
        let mut c = FallConfig::paper(self.age_group);
        if let Some(f) = &self.ranges_file {
            c.ranges = Ranges::Table(RangeTable::load(&resolve_path(f, base))?);
        }
        c.integrator = self.simulation.integrator;
        c.duration_s = self.simulation.duration;
        c.push = self.push.clone();
        c.height_m = self.body.height_m;
        c.mass_kg = self.body.mass_kg;
        c.contact = self.contact;
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
        }
        c.dt_s = self.step(from_file.as_ref())?;
        if let Some(b) = self
            .controller
            .contact_implicit_damping
            .or(from_file.as_ref().and_then(|f| f.contact_implicit_damping))
        {
            c.contact.implicit_damping = b;
        }
        for (link, w) in &self.damage_weights {
            if !c.damage_weights.contains_key(link) {
                return Err(SceneError::UnknownName {
                    field: "damage_weights".into(),
                    name: link.clone(),
                    expected: format!(
                        "a fall21 link ({})",
                        c.damage_weights
                            .keys()
                            .cloned()
                            .collect::<Vec<_>>()
                            .join(", ")
                    ),
                });
            }
            c.damage_weights.insert(link.clone(), *w);
        }
        let evolved_for = self
            .controller
            .evolved_for
            .or(from_file.and_then(|f| f.evolved_for));
        Ok((c, evolved_for))
    }
}

/// Per-link values as a JSON object keyed by link name.
fn per_link(names: &[String], values: &[f64]) -> serde_json::Value {
    serde_json::Value::Object(
        names
            .iter()
            .zip(values)
            .map(|(n, v)| (n.clone(), json!(v)))
            .collect(),
    )
}

/// The report of one fall.
pub fn fall_report(r: &FallResult, sim_wall_s: f64) -> serde_json::Value {
    let head: Vec<f64> = r.frames.iter().map(|f| f.head_height_m).collect();
    json!({
        "damage": r.damage,
        "peak_vertical_force_n": per_link(&r.link_names, &r.peak_vertical_force_n),
        "impulse_n_s": per_link(&r.link_names, &r.impulse_n_s),
        "max_penetration_m": r.max_penetration_m,
        "max_penetration_by_link_m": per_link(&r.link_names, &r.max_penetration_by_link_m),
        "impacts": r.impacts,
        "pelvis": {
            "impact_velocity_m_s": r.pelvis.impact_velocity_m_s,
            "descent_start_s": r.pelvis.descent_start_s,
            "touchdown_s": r.pelvis.touchdown_s,
            "descent_time_s": r.pelvis.descent_time_s,
            "rebound_m": r.pelvis.rebound_m,
            "published_older_adults": {
                "source": "video-captured falls of older adults in long-term care (Choi, Wakeling & Robinovitch 2015, J. Biomech. 48:911-920), as quoted in issue 9",
                "impact_velocity_m_s": {"mean": 2.1, "sd": 0.6},
                "descent_time_s": {"mean": 0.58, "sd": 0.26},
            },
            "published_hip_impact_force_n": {
                "range": [2600.0, 5600.0],
                "note": "standing-height falls onto the hip",
            },
        },
        "standing_start": r.standing,
        "torque_saturation": r.torque_saturation,
        "came_to_rest": r.came_to_rest,
        "rest_time_s": r.rest_time_s,
        "steps": r.steps,
        "dt_s": r.dt_s,
        "simulation_wall_time_s": sim_wall_s,
        "final_head_height_m": head.last(),
        "final_pelvis_position_m": r.frames.last().map(|f| f.root_position.to_array()),
    })
}

/// Writes each fall as `<file>.bvh` (fall21 skeleton) and draws them together as
/// `filmstrip.png` (and `motion.gif`), one track per fall with its label; returns the falls as
/// motions of the results page.
pub(super) fn write_falls(
    falls: &[(String, String, &FallResult)],
    render: &PrimitiveRender,
    out: &Path,
) -> Result<Vec<PageMotion>, SceneError> {
    let clips: Vec<_> = falls
        .iter()
        .map(|(_, _, r)| r.to_model_clip().to_clip())
        .collect();
    for ((file, _, _), clip) in falls.iter().zip(&clips) {
        write_output(
            &out.join(format!("{file}.bvh")),
            crate::bvh::to_string(&clip.to_bvh()).as_bytes(),
        )?;
    }
    let figures: Vec<_> = clips.iter().map(|c| Figure::of(&c.skeleton)).collect();
    let frames: Vec<_> = clips.iter().map(|c| c.point_frames()).collect();
    let tracks: Vec<Track> = (0..clips.len())
        .map(|k| Track {
            figure: &figures[k],
            frames: &frames[k],
            label: falls[k].1.clone(),
            frame_time: clips[k].frame_time,
        })
        .collect();
    draw_tracks(
        &tracks,
        render.filmstrip_frames,
        render.gif.then_some(render.gif_fps),
        out,
    )?;
    falls
        .iter()
        .map(|(_, label, r)| page::fall_motion(label, r))
        .collect()
}

/// A fall's head height (m) over time (s) as a plot series.
pub(super) fn head_height_series(name: String, r: &FallResult) -> Series {
    Series {
        name,
        points: r
            .frames
            .iter()
            .map(|f| (f.time_s, f.head_height_m))
            .collect(),
    }
}

/// One fall's headline figures in words, from its report ([`fall_report`]).
pub(super) fn fall_headline(who: &str, report: &serde_json::Value) -> String {
    let num = |v: &serde_json::Value| v.as_f64().unwrap_or(f64::NAN);
    format!(
        "{who}: damage {:.0} N; the head ends {:.2} m above the floor; the pelvis meets the \
         floor at {:.2} m/s{}.",
        num(&report["damage"]),
        num(&report["final_head_height_m"]),
        num(&report["pelvis"]["impact_velocity_m_s"]),
        match report["rest_time_s"].as_f64() {
            Some(t) if report["came_to_rest"] == true => format!(" and is at rest from {t:.2} s"),
            _ => " and has not come to rest by the end".to_string(),
        }
    )
}

/// The age groups to simulate and their configurations: the scene's, and with `compare_with`
/// the other group's (its ranges, unless the scene reads them from a file, and its torques).
fn fall_groups(scene: &FallScene, config: &FallConfig) -> Vec<(AgeGroup, FallConfig)> {
    let mut groups = vec![(scene.age_group, config.clone())];
    if let Some(other) = scene.compare_with {
        let mut c = config.clone();
        if scene.ranges_file.is_none() {
            c.ranges = Ranges::Builtin(other);
        }
        c.torque_limits_nm = Some(torque_limits(other));
        groups.push((other, c));
    }
    groups
}

/// Each fall's output file stem (`fall`, then `fall_<group>`) and label.
fn named_falls<'r>(
    scene: &FallScene,
    results: &'r [FallResult],
    groups: &[(AgeGroup, FallConfig)],
) -> Vec<(String, String, &'r FallResult)> {
    results
        .iter()
        .zip(groups)
        .enumerate()
        .map(|(k, (r, (g, _)))| {
            let file = if k == 0 {
                "fall".to_string()
            } else {
                format!("fall_{}", g.name())
            };
            (file, format!("{} ({})", scene.name, g.name()), r)
        })
        .collect()
}

/// The head height of every fall over time, the push marked (the paper's Fig. 3).
fn head_plot(scene: &FallScene, results: &[FallResult], groups: &[(AgeGroup, FallConfig)]) -> Plot {
    let push_end = scene.push.start_s + scene.push.duration_s;
    Plot {
        title: format!("Head height: {}", scene.name),
        x_label: "time (s)".into(),
        y_label: "head height (m)".into(),
        series: results
            .iter()
            .zip(groups)
            .map(|(r, (g, _))| head_height_series(g.name().into(), r))
            .collect(),
        markers: vec![
            (scene.push.start_s, "push".into()),
            (push_end, "push ends".into()),
        ],
    }
}

/// Runs a [`FallScene`]: writes `fall.bvh` (fall21 skeleton), `filmstrip.png`, `motion.gif`,
/// `head_height.png` (the paper's Fig. 3) and returns the report. With `compare_with`, the same
/// fall is also simulated for the other age group in a second World, in parallel, and drawn and
/// plotted beside the first (`fall_<group>.bvh` for it; its report under `compared`).
pub fn run_fall(
    scene: &FallScene,
    base: &Path,
    out: &Path,
) -> Result<serde_json::Value, SceneError> {
    let (config, evolved_for) = scene.configure(base)?;
    let groups = fall_groups(scene, &config);
    let configs: Vec<FallConfig> = groups.iter().map(|(_, c)| c.clone()).collect();
    let started = std::time::Instant::now();
    let results: Vec<FallResult> = run_parallel(&configs)
        .into_iter()
        .map(|r| r.map_err(SceneError::from))
        .collect::<Result<_, _>>()?;
    let sim_wall = started.elapsed().as_secs_f64();

    let named = named_falls(scene, &results, &groups);
    let motions = write_falls(&named, &scene.render, out)?;
    let head = head_plot(scene, &results, &groups);
    plot(&head, &out.join("head_height.png"))?;
    if let Some(e) = evolved_for
        && groups.iter().all(|(g, _)| *g != e)
    {
        eprintln!(
            "note: the controller was evolved for the {} figure; this fall runs it on the {} \
             figure (--set age_group={} replays its evolved damage)",
            e.name(),
            scene.age_group.name(),
            e.name()
        );
    }
    let mut report = fall_report(&results[0], sim_wall);
    report["age_group"] = json!(scene.age_group);
    if let Some(e) = evolved_for {
        report["controller_evolved_for"] = json!(e);
    }
    report["damage_weights"] = json!(config.damage_weights);
    let mut headline = vec![fall_headline(&named[0].1, &report)];
    if let (Some(r), Some((g, _))) = (results.get(1), groups.get(1)) {
        let mut other = fall_report(r, sim_wall);
        other["age_group"] = json!(g);
        headline.push(fall_headline(&named[1].1, &other));
        report["compared"] = other;
    }
    headline.push(format!(
        "Pushed at the {} with {:.0} N from {:.2} s for {:.2} s; {:.1} s simulated at a step of \
         {} s.",
        scene.push.link,
        scene.push.force_n,
        scene.push.start_s,
        scene.push.duration_s,
        config.duration_s,
        config.dt_s
    ));
    page::write(
        &Page {
            title: format!("{}: pushed fall", scene.name),
            headline,
            motions,
            plots: vec![page::timed(head)],
            ..Page::default()
        },
        out,
    )?;
    Ok(report)
}
