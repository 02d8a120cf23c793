//! The active jumping knee kick: the jumping knee kick of [`JumpingKneeKickScene`] learned as
//! there, then played by a physical humanoid24 character ([`experiments::active`]) under PD
//! control with root assistance, pushed, and released so that it falls. Outputs: the
//! physical motion as BVH, a filmstrip and GIF of the animated and the physical motion side by
//! side, a plot of the pelvis height, and the report (tracking error, push, release and fall
//! times, peak torques against the strength limits, damage).
//!
//! [`experiments::active`]: crate::experiments::active

use std::collections::BTreeMap;
use std::path::Path;

use glam::DVec3;
use serde::{Deserialize, Serialize};
use serde_json::json;

use super::primitives::{JumpingKneeKickScene, PrimitiveRender, draw, knee_kick_config, write_bvh};
use super::{SceneError, page, write_output};
use crate::dynamics::forces::external::Push;
use crate::ecs::character::PhysicalSettings;
use crate::experiments::active::{ActiveConfig, ActiveOutcome, run_active};
use crate::experiments::knee_kick;
use crate::humanoid::AgeGroup;
use crate::render::{Page, Plot, Series, plot};

fn default_push() -> Push {
    Push {
        link: "chest".into(),
        point: DVec3::new(0.0, 0.25, 0.0),
        direction: DVec3::new(0.0, 0.0, -1.0),
        force_n: 600.0,
        start_s: 1.0,
        duration_s: 0.1,
    }
}

fn one() -> f64 {
    1.0
}

fn adult() -> Option<AgeGroup> {
    Some(AgeGroup::Adult)
}

/// The physical character of an active scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActiveCharacter {
    /// Standing height (m).
    pub height_m: f64,
    /// Body mass (kg).
    pub mass_kg: f64,
    /// Root assistance strength: 1 fully assisted, 0 not at all.
    #[serde(default = "one")]
    pub assist: f64,
    /// Joint PD bandwidth (rad/s).
    pub joint_omega: f64,
    /// Root assistance bandwidth (rad/s).
    pub assist_omega: f64,
    /// Whose strength bounds the joint torques (`None`: unbounded).
    #[serde(default = "adult")]
    pub strength: Option<AgeGroup>,
}

impl Default for ActiveCharacter {
    fn default() -> Self {
        let s = PhysicalSettings::default();
        Self {
            height_m: 1.70,
            mass_kg: 65.0,
            assist: s.assist,
            joint_omega: s.joint_omega,
            assist_omega: s.assist_omega,
            strength: s.strength,
        }
    }
}

impl ActiveCharacter {
    /// The engine's settings for this character: the scene's PD and assistance bandwidths,
    /// assistance strength and torque bounds, the rest at their defaults.
    pub fn settings(&self) -> PhysicalSettings {
        PhysicalSettings {
            joint_omega: self.joint_omega,
            assist: self.assist,
            assist_omega: self.assist_omega,
            strength: self.strength,
            ..PhysicalSettings::default()
        }
    }
}

/// The active jumping knee kick.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ActiveKneeKickScene {
    /// Scene format version.
    pub format_version: u32,
    /// Scene name.
    pub name: String,
    /// How the jumping knee kick is made (as the JumpingKneeKick scene).
    pub motion: JumpingKneeKickScene,
    /// The physical character.
    #[serde(default)]
    pub character: ActiveCharacter,
    /// The push (time on the motion's time line).
    #[serde(default = "default_push")]
    pub push: Push,
    /// Seconds after the push at which the assistance is released (`None`: kept).
    pub release_delay_s: Option<f64>,
    /// A key pose the PD switches to at the release (degrees per DOF name; others 0), as the
    /// falling paper's fall controller; `None` keeps following the primitives.
    #[serde(default)]
    #[serde(deserialize_with = "crate::io::unique_keys_opt")]
    pub key_pose_deg: Option<BTreeMap<String, f64>>,
    /// Simulated time (s).
    pub duration_s: f64,
    /// Physics step (s).
    pub dt_s: f64,
    /// Damage weight per link (links not named weigh 1).
    #[serde(default)]
    #[serde(deserialize_with = "crate::io::unique_keys")]
    pub damage_weights: BTreeMap<String, f64>,
    /// Pictures.
    #[serde(default)]
    pub render: PrimitiveRender,
}

/// Runs the scene into `out`; returns the report.
pub fn run_active_knee_kick(
    scene: &ActiveKneeKickScene,
    base: &Path,
    out: &Path,
) -> Result<serde_json::Value, SceneError> {
    let kk = knee_kick::run(&knee_kick_config(&scene.motion, base)?).map_err(SceneError::from)?;
    let c = &scene.character;
    let config = ActiveConfig {
        height_m: c.height_m,
        mass_kg: c.mass_kg,
        gravity: 9.81,
        settings: c.settings(),
        dt_s: scene.dt_s,
        duration_s: scene.duration_s,
        push: Some(scene.push.clone()),
        release_delay_s: scene.release_delay_s,
        key_pose_deg: scene.key_pose_deg.clone(),
        damage_weights: scene.damage_weights.clone(),
        record_hz: 60.0,
    };
    let o = run_active(&config, &kk.sequence())?;
    write_bvh(&out.join("active_knee_kick.bvh"), &o.motion)?;
    let motions = draw(
        &[
            ("animated (kinematic)", &kk.result_clip),
            (
                &format!("physical, pushed at {:.2} s", scene.push.start_s),
                &o.motion,
            ),
        ],
        &scene.render,
        out,
    )?;
    let pelvis = pelvis_plot(&o, out)?;
    let report = report(scene, &kk.events, &o);
    let at = |t: Option<f64>| t.map_or("never".to_string(), |t| format!("at {t:.2} s"));
    page::write(
        &Page {
            title: format!("{}: active jumping knee kick", scene.name),
            headline: vec![
                format!(
                    "Before the push the physical character tracks the animation to {:.1}° RMS \
                     over the joints.",
                    o.tracking_rms_deg
                ),
                format!(
                    "Pushed at the {} with {:.0} N {}; released {}; fallen {}.",
                    scene.push.link,
                    scene.push.force_n,
                    at(o.push_s),
                    at(o.release_s),
                    at(o.fall_s)
                ),
                format!(
                    "Pelvis height {:.2} m at the start, {:.2} m at the end; damage after the \
                     push {:.0} N.",
                    o.pelvis_height_m.0, o.pelvis_height_m.1, o.damage
                ),
            ],
            motions,
            plots: vec![page::timed(pelvis)],
            ..Page::default()
        },
        out,
    )?;
    Ok(report)
}

fn pelvis_plot(o: &ActiveOutcome, out: &Path) -> Result<Plot, SceneError> {
    let series = |label: &str, k: usize| Series {
        name: label.into(),
        points: o
            .pelvis_track
            .iter()
            .map(|s| (s.0, if k == 1 { s.1 } else { s.2 }))
            .collect(),
    };
    let mut markers = vec![];
    for (t, l) in [
        (o.push_s, "push"),
        (o.release_s, "release"),
        (o.fall_s, "fallen"),
    ] {
        if let Some(t) = t {
            markers.push((t, l.to_string()));
        }
    }
    let pelvis = Plot {
        title: "pelvis height: animated vs physical".into(),
        x_label: "time (s)".into(),
        y_label: "pelvis height (m)".into(),
        series: vec![series("animated", 2), series("physical", 1)],
        markers,
    };
    plot(&pelvis, &out.join("pelvis_height.png"))?;
    write_output(
        &out.join("pelvis_height.csv"),
        {
            let mut s = String::from("time_s,physical_m,animated_m\n");
            for (t, p, a) in &o.pelvis_track {
                s.push_str(&format!("{t},{p},{a}\n"));
            }
            s
        }
        .as_bytes(),
    )?;
    Ok(pelvis)
}

fn report(
    scene: &ActiveKneeKickScene,
    events: &crate::primitive::JumpEvents,
    o: &ActiveOutcome,
) -> serde_json::Value {
    let worst = o
        .dof_rms_deg
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .cloned();
    let saturated: Vec<_> = o
        .torques
        .iter()
        .filter(|t| t.limit_nm > 0.0 && t.peak_nm >= t.limit_nm - 1e-9)
        .map(|t| t.dof.clone())
        .collect();
    json!({
        "assist": scene.character.assist,
        "strength": scene.character.strength,
        "events_s": { "start": events.start, "bend": events.bend, "take_off": events.take_off, "leap": events.leap, "land": events.land },
        "tracking": {
            "joint_rms_deg": o.tracking_rms_deg,
            "worst_dof": worst,
            "per_dof_rms_deg": o.dof_rms_deg.iter().cloned().collect::<BTreeMap<_, _>>(),
            "max_pelvis_height_gap_m": o.max_pelvis_gap_m,
            "window": "ticks before the push",
            "worst_tick": { "time_s": o.worst_tick.0, "rms_deg": o.worst_tick.1 },
            "per_dof_demand": o.demands,
            "feet_on_floor": o.feet,
            "downward_pull": o.pull,
            "pull_rule": "before the push, the largest downward whole-body external force the animated motion needs (its inverse dynamics' root force, carried by the assistance), in body weights: a floor only pushes up, so anything above 0 is motion no body can make (e.g. a flight falling faster than gravity)",
            "feet_rule": format!("the animated foot is down within {} m of its floor; gap = the physical foot's lowest corner above the floor then", crate::ecs::character::ANIMATED_FOOT_DOWN_M),
        },
        "push": { "link": scene.push.link, "force_n": scene.push.force_n, "start_s": o.push_s, "duration_s": scene.push.duration_s },
        "release_s": o.release_s,
        "key_pose_deg": scene.key_pose_deg,
        "fall_s": o.fall_s,
        "fallen_below_fraction_of_start_pelvis_height": crate::experiments::active::FALLEN_FRACTION,
        "pelvis_height_m": { "start": o.pelvis_height_m.0, "end": o.pelvis_height_m.1 },
        "peak_torques": o.torques,
        "saturated_dofs": saturated,
        "damage": { "total_n": o.damage, "links": o.links, "window": "after the push" },
    })
}
