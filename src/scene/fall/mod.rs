//! The `Fall` scene: the falling paper's pushed figure (SPEC §3), simulated in an ECS world.

mod schema;

use std::path::Path;

use serde_json::json;

pub use schema::{Controller, FallScene, SceneFall};

use super::primitives::PrimitiveRender;
use super::{SceneError, draw_tracks, page, write_output};
use crate::experiments::fall::run_parallel;
use crate::experiments::fall::{FallConfig, FallResult, Ranges};
use crate::humanoid::AgeGroup;
use crate::humanoid::strength::torque_limits;
use crate::render::{Page, PageMotion, Plot, Series, StickFigure, Track, plot};

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
        .map(|(_, _, r)| r.to_figure_clip().to_clip())
        .collect();
    for ((file, _, _), clip) in falls.iter().zip(&clips) {
        write_output(
            &out.join(format!("{file}.bvh")),
            crate::bvh::to_string(&clip.to_bvh()).as_bytes(),
        )?;
    }
    let figures: Vec<_> = clips.iter().map(|c| StickFigure::of(&c.skeleton)).collect();
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
/// the other group's (its built-in ranges, unless the scene gives `fall.ranges`, and its
/// strength).
fn fall_groups(scene: &FallScene, config: &FallConfig) -> Vec<(AgeGroup, FallConfig)> {
    let mut groups = vec![(scene.age_group, config.clone())];
    if let Some(other) = scene.compare_with {
        let mut c = config.clone();
        if scene.fall.ranges.is_none() {
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
    let push = &groups[0].1.push;
    let push_end = push.start_s + push.duration_s;
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
            (push.start_s, "push".into()),
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
        config.push.link,
        config.push.force_n,
        config.push.start_s,
        config.push.duration_s,
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
