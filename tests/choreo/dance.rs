//! The `Dance` scene: on the project's own data it runs with nothing from outside, honours its
//! pins, lasts exactly its bars and stays true under `--set`; every bad input of the issue is
//! one clear error that leaves the output folder as it was; the salsa scene runs on the shared
//! data when it is there.

use crate::common;

use std::path::{Path, PathBuf};

use marionette::scene::{self, Scene};

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-dance-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn load(rel: &str) -> Scene {
    Scene::load(&root().join(rel)).unwrap()
}

fn run(s: &Scene, out: &Path) -> Result<serde_json::Value, String> {
    scene::run(s, &root().join("scenes"), out).map_err(|e| e.to_string())
}

fn set(s: &Scene, a: &[&str]) -> Scene {
    let a: Vec<String> = a.iter().map(|x| x.to_string()).collect();
    scene::apply_overrides(s, &a).unwrap()
}

/// Checks the report against itself and the files beside it.
fn check_report(r: &serde_json::Value, out: &Path, pins: &[(usize, usize)]) {
    let bars = r["bars"].as_u64().unwrap() as usize;
    let per_bar = r["per_bar"].as_array().unwrap();
    assert_eq!(per_bar.len(), bars);
    assert_eq!(r["seams"].as_array().unwrap().len(), bars - 1);
    for &(bar, seg) in pins {
        assert_eq!(
            per_bar[bar]["segment"].as_u64().unwrap() as usize,
            seg,
            "pin on bar {bar}"
        );
        assert!(per_bar[bar]["pinned"].as_bool().unwrap());
    }
    let pinned = per_bar
        .iter()
        .filter(|b| b["pinned"].as_bool().unwrap())
        .count();
    assert_eq!(pinned, pins.len());
    // The dance lasts exactly its bars.
    let d = r["duration_s"].as_f64().unwrap();
    let b = r["bars_duration_s"].as_f64().unwrap();
    assert!((d - b).abs() < 1e-6, "dance {d} s, bars {b} s");
    let first = per_bar[0]["start_s"].as_f64().unwrap();
    let last = per_bar[bars - 1]["end_s"].as_f64().unwrap();
    assert!((last - first - d).abs() < 1e-6);
    for k in [
        "beat_alignment_score",
        "foot_skating_m_s",
        "transition_cost",
    ] {
        assert!(r["metrics"][k].as_f64().unwrap().is_finite(), "{k}");
    }
    let bas = r["metrics"]["beat_alignment_score"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&bas));
    // The BVH: humanoid24 from the song's t = 0 at the dance's frame rate.
    let (bvh, _) = marionette::bvh::parse_file(&out.join("motion.bvh")).unwrap();
    let fps = r["fps"].as_f64().unwrap();
    let lead = (r["dance_start_s"].as_f64().unwrap() * fps).round() as usize;
    assert_eq!(
        bvh.frame_count(),
        r["frames"].as_u64().unwrap() as usize + lead
    );
    for f in ["filmstrip.png", "intensity.png", "report.json"] {
        assert!(out.join(f).is_file(), "{f}");
    }
}

#[test]
fn the_own_scene_runs_honours_its_pins_and_lasts_its_bars() {
    let d = scratch("own");
    let out = d.join("dance");
    let s = load("scenes/dance.ron");
    let r = run(&s, &out).unwrap();
    assert_eq!(r["bars"], 16);
    // Pins: bar 0 → segment 0; bar 5 → authored_1 bar 5 (8 bars a clip: 13); bar 12 →
    // authored_3 bar 2 (26).
    check_report(&r, &out, &[(0, 0), (5, 13), (12, 26)]);
    assert_eq!(r["per_bar"][5]["clip"], "authored_1");
    assert_eq!(r["per_bar"][5]["clip_bar"], 5);
    assert!(out.join("song.wav").is_file() && out.join("motion.gif").is_file());
    let tempo = r["tempo_bpm"].as_f64().unwrap();
    assert!((tempo / 124.0 - 1.0).abs() < 0.01, "{tempo}");
    // No filled bar repeats its neighbour's segment.
    let segs: Vec<u64> = r["per_bar"]
        .as_array()
        .unwrap()
        .iter()
        .map(|b| b["segment"].as_u64().unwrap())
        .collect();
    assert!(segs.windows(2).all(|w| w[0] != w[1]), "{segs:?}");

    // --set: another tempo, fewer bars, no pins; the report follows.
    let s2 = set(
        &s,
        &[
            "song.Synth.bpm=100",
            "bars=6",
            "pins=[]",
            "render.gif=false",
        ],
    );
    let r2 = run(&s2, &out).unwrap();
    assert_eq!(r2["bars"], 6);
    assert_eq!(r2["song_known_tempo_bpm"], 100.0);
    let tempo = r2["tempo_bpm"].as_f64().unwrap();
    assert!((tempo / 100.0 - 1.0).abs() < 0.01, "{tempo}");
    check_report(&r2, &out, &[]);
    assert!(!out.join("motion.gif").exists());
    std::fs::remove_dir_all(&d).unwrap();
}

/// A small own-data scene with `song`, `database` and `pins` fields.
fn small(song: &str, database: &str, pins: &str) -> Scene {
    let text = format!(
        "Dance(format_version: 1, name: \"small\", song: {song}, database: {database}, \
         pins: {pins}, render: (gif: false))"
    );
    Scene::parse(&text, "small.ron").unwrap()
}

const SONG: &str = "Synth(bpm: 120.0, bars: 4)";
const DB: &str = "Authored(clips: 2, bars_per_clip: 4)";

fn files(dir: &Path) -> Vec<(String, Vec<u8>)> {
    let mut v: Vec<(String, Vec<u8>)> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| {
            let e = e.unwrap();
            (
                e.file_name().to_string_lossy().to_string(),
                std::fs::read(e.path()).unwrap(),
            )
        })
        .collect();
    v.sort();
    v
}

#[test]
fn every_bad_input_is_one_clear_error_and_leaves_the_outputs() {
    let d = scratch("bad");
    let out = d.join("small");
    let r = run(&small(SONG, DB, "[(bar: 1, segment: 2)]"), &out).unwrap();
    check_report(&r, &out, &[(1, 2)]);
    let before = files(&out);

    // A silent song, a song of less than a bar, a clip of less than a bar, an empty folder.
    let silent = d.join("silent.wav");
    let wav = marionette::choreo::music::wav_bytes(&vec![0.0; 22_050 * 4], 1, 22_050);
    std::fs::write(&silent, wav.unwrap()).unwrap();
    let bar = marionette::choreo::music::synthesize(&marionette::choreo::music::SynthSong {
        bars: 1,
        lead_in_s: 0.0,
        tail_s: 0.0,
        ..Default::default()
    })
    .unwrap();
    let part = d.join("part.wav");
    let three_quarters = &bar.samples[..bar.samples.len() * 3 / 4];
    let wav = marionette::choreo::music::wav_bytes(three_quarters, 1, bar.sample_rate);
    std::fs::write(&part, wav.unwrap()).unwrap();
    let empty = d.join("empty");
    std::fs::create_dir(&empty).unwrap();
    let short = d.join("short");
    std::fs::create_dir(&short).unwrap();
    let clip = marionette::choreo::generate(&Default::default()).unwrap();
    let one_s = clip[0].motion.window(0.0, 1.0).unwrap();
    std::fs::write(
        short.join("short.bvh"),
        marionette::bvh::to_string(&one_s.to_clip().to_bvh()),
    )
    .unwrap();
    std::fs::write(
        short.join("manifest.ron"),
        "(format_version: 1, clips: [(file: \"short.bvh\", tempo_bpm: 118.0, first_beat_s: 0.0)])",
    )
    .unwrap();
    let q = |p: &Path| format!("{:?}", p.display().to_string());
    let cases = [
        (
            small("File(\"/nonexistent/song.ogg\")", DB, "[]"),
            "/nonexistent/song.ogg: cannot read the song",
        ),
        (
            small(&format!("File({})", q(&silent)), DB, "[]"),
            "the song is silent",
        ),
        (
            small(&format!("File({})", q(&part)), DB, "[]"),
            "the song lasts",
        ),
        (
            small(
                SONG,
                &format!("Clips({})", q(&short.join("manifest.ron"))),
                "[]",
            ),
            "shorter than one bar",
        ),
        (
            small(SONG, &format!("Clips({})", q(&empty)), "[]"),
            "no dance clip in the folder",
        ),
        (
            small(SONG, DB, "[(bar: 9, segment: 0)]"),
            "pin on bar 9: the song has 4 bars",
        ),
        (
            small(SONG, DB, "[(bar: 0, segment: 99)]"),
            "segment 99 does not exist (the database has 8",
        ),
        (
            small(SONG, DB, "[(bar: 0, clip: \"authored_7\", clip_bar: 0)]"),
            "no clip 'authored_7' in the database",
        ),
        (
            small(SONG, DB, "[(bar: 0, clip: \"authored_1\", clip_bar: 4)]"),
            "clip 'authored_1' has 4 bars (0 to 3), not bar 4",
        ),
        (
            small(
                SONG,
                DB,
                "[(bar: 0, segment: 1, clip: \"authored_1\", clip_bar: 0)]",
            ),
            "give either segment",
        ),
    ];
    for (s, want) in cases {
        let e = run(&s, &out).unwrap_err();
        assert!(e.contains(want), "expected '{want}' in: {e}");
        assert_eq!(files(&out), before, "after: {e}");
    }
    let names: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(names.is_empty(), "temporary folders left: {names:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn the_salsa_scene_runs_on_the_shared_data() {
    let (Some(_), Some(_)) = (
        common::data_path("dance"),
        common::data_path("audio/supertux_chipdisko.ogg"),
    ) else {
        return;
    };
    let d = scratch("salsa");
    let out = d.join("dance_salsa");
    let s = set(
        &load("scenes/dance_salsa.ron"),
        &["bars=10", "render.gif=false"],
    );
    let r = run(&s, &out).unwrap();
    assert_eq!(r["bars"], 10);
    let seg = |bar: usize| r["per_bar"][bar]["segment"].as_u64().unwrap() as usize;
    assert_eq!(r["per_bar"][0]["clip"], "acrnn_salsa_01");
    assert_eq!(r["per_bar"][0]["clip_bar"], 2);
    assert_eq!(r["per_bar"][8]["clip"], "acrnn_salsa_03");
    assert_eq!(r["per_bar"][8]["clip_bar"], 2);
    check_report(&r, &out, &[(0, seg(0)), (8, seg(8))]);
    std::fs::remove_dir_all(&d).unwrap();
}

/// humanoid24 at 60 fps dancing `bars` bars at 120 BPM (beats of 0.5 s from t = 0), its arms,
/// legs and waist swinging one way per beat, θ = A (1 − cos πτ) / 2, so that every point stops
/// once per beat, where τ is a whole number: at the times t_j = (j + off[j mod 4]) × 0.5 s.
/// With `off` = 0 the speed minima sit on the counts; else count j mod 4 is late or early.
fn swinging(bars: usize, off: [f64; 4]) -> marionette::humanoid::FigureClip {
    let model = marionette::humanoid::humanoid24();
    let d = model.dofs.len();
    let beat = 0.5;
    let fps = 60.0;
    let frames = (bars as f64 * 4.0 * beat * fps) as usize + 30;
    let knots: Vec<f64> = (0..=bars * 4 + 2)
        .map(|j| (j as f64 + off[j % 4]) * beat)
        .collect();
    // τ(t): piecewise linear through (t_j, j).
    let tau = |t: f64| -> f64 {
        let j = knots.partition_point(|&k| k <= t).clamp(1, knots.len() - 1) - 1;
        j as f64 + (t - knots[j]) / (knots[j + 1] - knots[j])
    };
    let swings: Vec<(usize, f64)> = [
        ("left_shoulder_flexion", 0.9),
        ("right_shoulder_flexion", -0.7),
        ("left_elbow_flexion", 0.8),
        ("right_elbow_flexion", 0.6),
        ("left_knee", 0.5),
        ("right_knee", 0.4),
        ("waist_flexion", 0.2),
    ]
    .iter()
    .map(|&(n, a)| (model.dof_index(n).unwrap(), a))
    .collect();
    let mut angles = vec![0.0; frames * d];
    for f in 0..frames {
        let s = 0.5 * (1.0 - (std::f64::consts::PI * tau(f as f64 / fps)).cos());
        for &(j, a) in &swings {
            angles[f * d + j] = a * s;
        }
    }
    marionette::humanoid::FigureClip {
        model,
        frame_time: 1.0 / fps,
        root_translation: vec![glam::DVec3::new(0.0, 0.93, 0.0); frames],
        root_rotation: vec![glam::DQuat::IDENTITY; frames],
        angles,
    }
}

#[test]
fn beats_off_the_counts_are_warped_onto_the_music_and_the_seams_stay_smooth() {
    use marionette::choreo::Database;
    use marionette::choreo::music::Bar;
    use marionette::choreo::{
        BAS_SIGMA_S, beat_alignment_score, motion_beats, seam_jerk, source_beat_alignment,
    };
    use marionette::choreo::{Beat, BuildParams, TempoSource};
    use marionette::choreo::{DanceParams, assemble};

    // Counts 2, 3, 4 of every bar 0.07 s late, 0.06 s early, 0.06 s late.
    let off = [0.0, 0.14, -0.12, 0.12];
    let clip = swinging(4, off);
    let beat = Beat {
        tempo_bpm: 120.0,
        first_beat_s: 0.0,
        source: TempoSource::Manifest,
    };
    // The source on its own beat grid: lower than a clip whose minima sit on the counts.
    let own = source_beat_alignment(&clip, &beat);
    let on_counts = source_beat_alignment(&swinging(4, [0.0; 4]), &beat);
    eprintln!("source BAS: off the counts {own:.3}, on the counts {on_counts:.3}");
    assert!(on_counts > 0.95 && own < 0.75, "{on_counts} {own}");
    // A grid a quarter beat late misses every beat.
    let late = Beat {
        first_beat_s: 0.125,
        ..beat
    };
    assert!(source_beat_alignment(&swinging(4, [0.0; 4]), &late) < 0.1);

    let db = Database::from_clips(
        &[("off_counts".to_string(), clip, Some(beat))],
        &BuildParams::default(),
    )
    .unwrap();
    assert_eq!(db.segments.len(), 4);
    // A song of 6 bars of 2.1 s from 0.4 s, its beats not quite even (as tracked beats are).
    let bar_s = 2.1;
    let bars: Vec<Bar> = (0..6)
        .map(|k| Bar {
            start_s: 0.4 + k as f64 * bar_s,
            end_s: 0.4 + (k + 1) as f64 * bar_s,
            rms: 0.1,
            rms_db: -20.0,
        })
        .collect();
    let jitter = [0.0, 0.02, -0.015, 0.01];
    let beats: Vec<f64> = (0..24)
        .map(|j| 0.4 + (j as f64 * 0.25 + jitter[j % 4] / bar_s) * bar_s)
        .collect();
    let segs = [0, 1, 2, 3, 1, 2];
    let dance = |beat_warp: bool| {
        let p = DanceParams {
            beat_warp,
            ..DanceParams::default()
        };
        assemble(&db, &segs, &bars, &beats, &p).unwrap()
    };
    let (warped, uniform) = (dance(true), dance(false));
    assert_eq!(warped.warped_beats, vec![3; 6]);
    assert_eq!(uniform.warped_beats, vec![0; 6]);
    assert_eq!(warped.clip.frame_count(), uniform.clip.frame_count());
    let music: Vec<f64> = beats.iter().map(|t| t - 0.4).collect();
    let bas = |d: &marionette::choreo::Dance| {
        let m = motion_beats(&d.clip);
        (beat_alignment_score(&m, &music, BAS_SIGMA_S), m.len())
    };
    let ((w, wn), (u, un)) = (bas(&warped), bas(&uniform));
    let (sw, su) = (seam_jerk(&warped).0, seam_jerk(&uniform).0);
    let (iw, iu) = (seam_jerk(&warped).1, seam_jerk(&uniform).1);
    eprintln!(
        "BAS warped {w:.3} ({wn} motion beats), uniform {u:.3} ({un}); seam jerk peak / mean \
         warped {:.0} / {:.0}, uniform {:.0} / {:.0} rad/s³; inside {:.0} / {:.0} against {:.0} \
         / {:.0}",
        sw.peak_rad_s3,
        sw.mean_rad_s3,
        su.peak_rad_s3,
        su.mean_rad_s3,
        iw.peak_rad_s3,
        iw.mean_rad_s3,
        iu.peak_rad_s3,
        iu.mean_rad_s3
    );
    // The dance's beats land on the music only with the warp.
    assert!(w > 0.9, "warped BAS {w}");
    assert!(u < 0.75, "uniform BAS {u}");
    assert_eq!(wn, un, "the same motion beats, moved");
    // The seams no rougher than without the warp (within 1.25×).
    assert!(sw.peak_rad_s3 <= 1.25 * su.peak_rad_s3);
    assert!(sw.mean_rad_s3 <= 1.25 * su.mean_rad_s3);
}
