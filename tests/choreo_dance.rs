//! The `Dance` scene: on the project's own data it runs with nothing from outside, honours its
//! pins, lasts exactly its bars and stays true under `--set`; every bad input of the issue is
//! one clear error that leaves the output folder as it was; the salsa scene runs on the shared
//! data when it is there.

mod common;

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
    let wav = marionette::choreo::music::wav::wav_bytes(&vec![0.0; 22_050 * 4], 1, 22_050);
    std::fs::write(&silent, wav.unwrap()).unwrap();
    let bar = marionette::choreo::music::synth::synthesize(
        &marionette::choreo::music::synth::SynthSong {
            bars: 1,
            lead_in_s: 0.0,
            tail_s: 0.0,
            ..Default::default()
        },
    )
    .unwrap();
    let part = d.join("part.wav");
    let three_quarters = &bar.samples[..bar.samples.len() * 3 / 4];
    let wav = marionette::choreo::music::wav::wav_bytes(three_quarters, 1, bar.sample_rate);
    std::fs::write(&part, wav.unwrap()).unwrap();
    let empty = d.join("empty");
    std::fs::create_dir(&empty).unwrap();
    let short = d.join("short");
    std::fs::create_dir(&short).unwrap();
    let clip = marionette::choreo::authored::generate(&Default::default()).unwrap();
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
    assert_eq!(r["per_bar"][8]["clip_bar"], 4);
    check_report(&r, &out, &[(0, seg(0)), (8, seg(8))]);
    std::fs::remove_dir_all(&d).unwrap();
}
