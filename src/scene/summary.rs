//! A scene's headline: the few figures a person reads first, in words, taken from the scene's
//! report (`report.json`) so that they are the report's own numbers. `marionette run` prints
//! them; the report keeps them under `"headline"`.

use serde_json::Value;

use super::Scene;

/// Reads the report: numbers and strings by JSON pointer; a pointer the report lacks is named
/// in the line instead of a number, so a renamed field shows rather than vanishing.
struct Report<'a>(&'a Value);

impl Report<'_> {
    /// The value at `pointer` (RFC 6901, e.g. `/metrics/beat_alignment_score`).
    fn get(&self, pointer: &str) -> Option<&Value> {
        self.0.pointer(pointer)
    }

    /// The number at `pointer` with `decimals` digits, or `(no <pointer>)`.
    fn num(&self, pointer: &str, decimals: usize) -> String {
        match self.get(pointer).and_then(Value::as_f64) {
            Some(x) => format!("{x:.decimals$}"),
            None => missing(pointer),
        }
    }

    /// The number at `pointer` in scientific notation with `decimals` digits, or `(no <pointer>)`.
    fn sci(&self, pointer: &str, decimals: usize) -> String {
        match self.get(pointer).and_then(Value::as_f64) {
            Some(x) => format!("{x:.decimals$e}"),
            None => missing(pointer),
        }
    }

    /// The length at `pointer` (metres) in millimetres with one decimal, or `(no <pointer>)`.
    fn mm(&self, pointer: &str) -> String {
        match self.get(pointer).and_then(Value::as_f64) {
            Some(x) => format!("{:.1} mm", x * 1000.0),
            None => missing(pointer),
        }
    }

    /// The yes/no at `pointer`, or `(no <pointer>)`.
    fn yes(&self, pointer: &str) -> String {
        match self.get(pointer).and_then(Value::as_bool) {
            Some(true) => "yes".into(),
            Some(false) => "no".into(),
            None => missing(pointer),
        }
    }

    /// The string at `pointer`, or `(no <pointer>)`.
    fn text(&self, pointer: &str) -> String {
        match self.get(pointer) {
            Some(Value::String(s)) => s.clone(),
            Some(Value::Bool(b)) => b.to_string(),
            Some(Value::Number(n)) => n.to_string(),
            _ => missing(pointer),
        }
    }

    /// The array at `pointer` (empty when absent).
    fn list(&self, pointer: &str) -> &[Value] {
        self.get(pointer)
            .and_then(Value::as_array)
            .map(Vec::as_slice)
            .unwrap_or(&[])
    }
}

/// The marker for a field the report does not hold.
fn missing(pointer: &str) -> String {
    format!("(no {pointer} in the report)")
}

/// The headline of `scene`'s `report`: at most a dozen lines, each a sentence fragment with its
/// units.
pub fn headline(scene: &Scene, report: &Value) -> Vec<String> {
    let r = Report(report);
    match scene {
        Scene::Show(_) => show(&r),
        Scene::HighJump(_) => high_jump(&r),
        Scene::JumpingKneeKick(_) => jumping_knee_kick(&r),
        Scene::Fall(_) => fall(&r),
        Scene::ActiveKneeKick(_) => active_knee_kick(&r),
        Scene::EvolveFall(_) => evolve_fall(&r),
        Scene::Dance(_) => dance(&r),
    }
}

fn show(r: &Report) -> Vec<String> {
    let flights: Vec<String> = r
        .list("/flights")
        .iter()
        .map(|f| {
            let f = Report(f);
            format!("{}–{} s", f.num("/start_s", 2), f.num("/end_s", 2))
        })
        .collect();
    vec![
        format!(
            "{} on {}: {} frames at {} fps ({} s)",
            r.text("/clip"),
            r.text("/model"),
            r.text("/frames"),
            r.num("/fps", 1),
            r.num("/duration_s", 2)
        ),
        format!(
            "flights (both feet off the floor): {}",
            if flights.is_empty() {
                "none".to_string()
            } else {
                flights.join(", ")
            }
        ),
    ]
}

fn high_jump(r: &Report) -> Vec<String> {
    let jump = |name: &str| {
        format!(
            "{name} jump: apex {} m above standing, flight {} s, peak knee flexion {}°",
            r.num(&format!("/jumps/{name}/apex_above_standing_m"), 3),
            r.num(&format!("/jumps/{name}/flight_s"), 3),
            r.num(&format!("/peak_knee_flexion_deg/{name}"), 1)
        )
    };
    vec![
        jump("low"),
        jump("normal"),
        jump("high"),
        format!(
            "high jump against the paper's prediction ({}): apex {} m, flight {} s off; knee {}° off the expected {}°",
            r.text("/gamma"),
            r.num("/high_minus_predicted/apex_above_standing_m", 4),
            r.num("/high_minus_predicted/flight_s", 4),
            r.num("/high_minus_expected_deg", 2),
            r.num("/expected_high_deg", 1)
        ),
    ]
}

fn jumping_knee_kick(r: &Report) -> Vec<String> {
    let feet: Vec<String> = r
        .list("/at_leap/feet_above_floor_m")
        .iter()
        .map(|v| v.as_f64().map_or("?".into(), |x| format!("{x:.3}")))
        .collect();
    vec![
        format!(
            "jumping knee kick ({}, {}): apex {} m above standing, flight {} s (the jump alone: {} m, {} s)",
            r.text("/arrangement"),
            r.text("/gamma"),
            r.num("/jumping_knee_kick/apex_above_standing_m", 3),
            r.num("/jumping_knee_kick/flight_s", 3),
            r.num("/jump/apex_above_standing_m", 3),
            r.num("/jump/flight_s", 3)
        ),
        format!(
            "at the kick's leap ({} s): airborne: {}, feet {} m above the floor",
            r.num("/events_s/leap", 3),
            r.yes("/at_leap/airborne"),
            feet.join(" and ")
        ),
        format!(
            "played through the ECS: {} m from the kernel at most",
            r.sci("/ecs_vs_kernel_max_m", 1)
        ),
    ]
}

/// One fall's line: damage, the head's and pelvis's impact, rest.
fn fall_line(label: &str, f: &Report) -> String {
    let head = f
        .list("/impacts")
        .iter()
        .find(|i| i.get("link").and_then(Value::as_str) == Some("head"))
        // A head that never reached the floor has an impact entry without a touchdown.
        .filter(|i| i.get("touchdown_s").is_some_and(|t| !t.is_null()))
        .map(|i| {
            let i = Report(i);
            format!(
                "head peak force {} N at {} s",
                i.num("/peak_force_n", 0),
                i.num("/touchdown_s", 3)
            )
        })
        .unwrap_or_else(|| "the head never touched the floor".into());
    let rest = match f.get("/rest_time_s").and_then(Value::as_f64) {
        Some(_) => format!("at rest after {} s", f.num("/rest_time_s", 2)),
        None => "not at rest by the end".into(),
    };
    format!(
        "{label}: damage {} N, {head}, pelvis lands at {} m/s, {rest}",
        f.num("/damage", 0),
        f.num("/pelvis/impact_velocity_m_s", 2),
    )
}

fn fall(r: &Report) -> Vec<String> {
    let mut lines = vec![fall_line(&format!("{} fall", r.text("/age_group")), r)];
    if let Some(c) = r.get("/compared") {
        let c = Report(c);
        lines.push(fall_line(
            &format!("the same push, {} body", c.text("/age_group")),
            &c,
        ));
    }
    lines
}

fn active_knee_kick(r: &Report) -> Vec<String> {
    vec![
        format!(
            "tracking before the push: {}° RMS over the joints, pelvis height within {} m of the animation",
            r.num("/tracking/joint_rms_deg", 2),
            r.num("/tracking/max_pelvis_height_gap_m", 3)
        ),
        format!(
            "push {} N on the {} at {} s for {} s; fallen at {} s; damage {} N ({})",
            r.num("/push/force_n", 0),
            r.text("/push/link"),
            r.num("/push/start_s", 2),
            r.num("/push/duration_s", 2),
            r.num("/fall_s", 2),
            r.num("/damage/total_n", 0),
            r.text("/damage/window")
        ),
        format!(
            "joints at their torque limit: {}",
            r.list("/saturated_dofs").len()
        ),
    ]
}

fn evolve_fall(r: &Report) -> Vec<String> {
    let mut lines = vec![format!(
        "GA: population {}, {} generations, {} evaluations ({} failed); elite re-checks at half step: {} rejected",
        r.text("/population"),
        r.text("/generations"),
        r.text("/evaluations"),
        r.text("/failed_evaluations"),
        r.text("/elite_check/rejected")
    )];
    for g in r.list("/groups") {
        let g = Report(g);
        lines.push(format!(
            "{}: best damage {} N → {} N (mean over {} seeds; spread {} → {})",
            g.text("/age_group"),
            g.num("/initial/mean", 0),
            g.num("/final/mean", 0),
            g.list("/seeds").len(),
            g.num("/initial/std", 0),
            g.num("/final/std", 0)
        ));
    }
    lines.push(format!(
        "between the groups: {} N at the start, {} N at the end (more than the seeds' spread: {})",
        r.num("/comparison/initial_gap", 0),
        r.num("/comparison/final_gap", 0),
        r.yes("/comparison/final_gap_exceeds_seed_spread")
    ));
    for f in r.list("/best_falls") {
        let f = Report(f);
        lines.push(format!(
            "{}: damage {} N (at half step {} N)",
            f.text("/fall"),
            f.num("/honesty/damage", 0),
            f.num("/honesty/damage_at_half_step", 0)
        ));
    }
    lines
}

fn dance(r: &Report) -> Vec<String> {
    vec![
        format!(
            "{} bars at {} BPM ({} s) to the song {}",
            r.text("/bars"),
            r.num("/tempo_bpm", 1),
            r.num("/duration_s", 1),
            r.text("/song")
        ),
        format!("from {}", r.text("/database")),
        format!(
            "beat alignment {} (the segments alone: {}); music–motion intensity Spearman {}",
            r.num("/metrics/beat_alignment_score", 3),
            r.num("/metrics/sources/beat_alignment_score", 3),
            r.num("/metrics/intensity_spearman", 2)
        ),
        format!(
            "feet: lowest point {} from the floor, foot skating {} m/s; seams: mean jerk {} rad/s³",
            r.mm("/metrics/foot_penetration/deepest_m"),
            r.num("/metrics/foot_skating_m_s", 4),
            r.num("/metrics/seam_jerk_mean_rad_s3", 0)
        ),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn a_fall_line_says_what_did_not_happen_instead_of_a_missing_field() {
        let rolled = json!({
            "damage": 5471.2,
            "impacts": [{"link": "head", "touchdown_s": null, "peak_force_n": 0.0}],
            "pelvis": {"impact_velocity_m_s": 0.21},
            "came_to_rest": false,
            "rest_time_s": null,
        });
        let line = fall_line("elderly fall", &Report(&rolled));
        assert_eq!(
            line,
            "elderly fall: damage 5471 N, the head never touched the floor, pelvis lands at \
             0.21 m/s, not at rest by the end"
        );
        let hit = json!({
            "damage": 61320.0,
            "impacts": [{"link": "head", "touchdown_s": 0.74, "peak_force_n": 4486.0}],
            "pelvis": {"impact_velocity_m_s": 3.56},
            "came_to_rest": true,
            "rest_time_s": 1.11,
        });
        assert_eq!(
            fall_line("elderly fall", &Report(&hit)),
            "elderly fall: damage 61320 N, head peak force 4486 N at 0.740 s, pelvis lands at \
             3.56 m/s, at rest after 1.11 s"
        );
    }
}
