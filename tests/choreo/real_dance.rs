//! A dance from real motion capture that an animator would keep (issue 34), on the shared salsa
//! scene (the clips and song it was tuned on) and on a dance from clips kept out of all tuning
//! (`dance_more`) to another song: no foot in the floor, no more skating than its sources, its
//! intensity following the music's, seams (Σ C, the paper's measure) no costlier than the
//! paper's fill by more than 1.2×, every clip of the folder used or named as skipped, and beat
//! alignment at least its sources'. The seam jerk is printed beside the paper's fill's.

use crate::common;

use std::path::{Path, PathBuf};

use marionette::scene::{self, Scene};

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-real-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs `scene` (paths relative to `base`) with `overrides`, into `out`; the report.
fn run(scene: &Scene, base: &Path, overrides: &[&str], out: &Path) -> serde_json::Value {
    let a: Vec<String> = overrides.iter().map(|x| x.to_string()).collect();
    let s = scene::apply_overrides(scene, &a).unwrap();
    scene::run(&s, base, out).unwrap()
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The issue's checks on a dance's report, and the seams against the paper's fill (κ = 0).
fn check(what: &str, r: &serde_json::Value, paper: &serde_json::Value, folder: &Path) {
    let m = &r["metrics"];
    let pen = &m["foot_penetration"];
    let src = &m["sources"];
    let seam = f(&m["seam_jerk_mean_rad_s3"]);
    let seam_paper = f(&paper["metrics"]["seam_jerk_mean_rad_s3"]);
    eprintln!(
        "{what}: below 1 cm {:.4} of frames (deepest {:.4} m), skating {:.3} vs sources {:.3} \
         m/s, beat alignment {:.3} vs sources {:.3}, intensity Spearman {:.3} (paper's fill \
         {:.3}), seam jerk {seam:.0} vs paper's fill {seam_paper:.0} rad/s³, feet in contact \
         within ±1 cm {:.3} vs sources {:.3}, planted feet on the floor {:.3}",
        f(&pen["frames_below_1cm_fraction"]),
        f(&pen["deepest_m"]),
        f(&m["foot_skating_m_s"]),
        f(&src["foot_skating_m_s"]),
        f(&m["beat_alignment_score"]),
        f(&src["beat_alignment_score"]),
        f(&m["intensity_spearman"]),
        f(&paper["metrics"]["intensity_spearman"]),
        f(&pen["contact_within_1cm_fraction"]),
        f(&src["contact_within_1cm_fraction"]),
        f(&r["feet"]["planted_on_floor_fraction"]),
    );
    assert!(
        f(&pen["frames_below_1cm_fraction"]) <= 0.01,
        "{what}: feet in the floor"
    );
    assert!(
        f(&m["foot_skating_m_s"]) <= 1.1 * f(&src["foot_skating_m_s"]),
        "{what}: skates more than its sources"
    );
    assert!(
        f(&m["beat_alignment_score"]) >= f(&src["beat_alignment_score"]),
        "{what}: beats off the music"
    );
    assert!(f(&m["intensity_spearman"]) >= 0.6, "{what}: intensity");
    assert!(
        f(&pen["contact_within_1cm_fraction"]) >= f(&src["contact_within_1cm_fraction"]),
        "{what}: feet in contact hover more than their sources'"
    );
    // Planted feet on the floor: the frames a foot stands in (the analysis's contact on the
    // dance as assembled, not lifting off or landing), its sole within ±1 cm.
    assert!(
        f(&r["feet"]["planted_on_floor_fraction"]) >= 0.95,
        "{what}: planted feet off the floor"
    );
    let (cost, cost_paper) = (
        f(&m["transition_cost"]),
        f(&paper["metrics"]["transition_cost"]),
    );
    eprintln!("{what}: Σ C {cost:.4} vs paper's fill {cost_paper:.4}");
    assert!(
        cost <= 1.2 * cost_paper,
        "{what}: seams costlier than the paper's fill"
    );
    // Every clip of the folder used or named as skipped.
    let clips = std::fs::read_dir(folder)
        .unwrap()
        .filter(|e| {
            e.as_ref()
                .unwrap()
                .path()
                .extension()
                .is_some_and(|x| x == "bvh")
        })
        .count();
    let used = r["database_sources"].as_array().unwrap().len();
    let skipped = r["database_skipped"].as_array().unwrap().len();
    assert_eq!(
        used + skipped,
        clips,
        "{what}: {used} used, {skipped} skipped"
    );
    assert!(used > 0);
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn the_salsa_dance_stands_on_the_floor_lands_on_the_beat_and_follows_the_music() {
    let (Some(folder), Some(_)) = (
        common::data_path("dance"),
        common::data_path("audio/supertux_chipdisko.ogg"),
    ) else {
        return;
    };
    let d = scratch("salsa");
    let s = Scene::load(&root().join("scenes/dance_salsa.ron")).unwrap();
    let base = root().join("scenes");
    let r = run(&s, &base, &["render.gif=false"], &d.join("default"));
    let paper = run(
        &s,
        &base,
        &["render.gif=false", "fill.intensity_weight=0"],
        &d.join("paper"),
    );
    check("salsa", &r, &paper, &folder);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn a_dance_from_clips_kept_out_of_tuning_passes_the_same_checks() {
    let (Some(folder), Some(_)) = (
        common::data_path("dance_more"),
        common::data_path("audio/supertux_forest-sprint.ogg"),
    ) else {
        return;
    };
    let d = scratch("held-out");
    let path = d.join("held_out.ron");
    std::fs::write(
        &path,
        r#"Dance(
    format_version: 1,
    name: "held_out",
    song: File("${MARIONETTE_DATA}/audio/supertux_forest-sprint.ogg"),
    bars: Some(16),
    database: Clips("${MARIONETTE_DATA}/dance_more"),
    render: (gif: false),
)"#,
    )
    .unwrap();
    let s = Scene::load(&path).unwrap();
    let r = run(&s, &d, &[], &d.join("default"));
    let paper = run(&s, &d, &["fill.intensity_weight=0"], &d.join("paper"));
    check(
        "held out (dance_more to forest-sprint)",
        &r,
        &paper,
        &folder,
    );
    std::fs::remove_dir_all(&d).unwrap();
}
