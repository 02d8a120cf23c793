//! `marionette music` on a song the test synthesizes and writes as WAV: the text report, the
//! JSON object other tools read, the picture, and a clear error for a file that is not audio.

use std::path::Path;
use std::process::Command;

use marionette::choreo::music::wav_bytes;
use marionette::choreo::music::{SynthSong, synthesize};

#[test]
fn music_prints_tempo_beats_bars_as_text_and_json_and_draws_them() {
    let song = SynthSong {
        bpm: 104.5,
        bars: 8,
        ..SynthSong::default()
    };
    let t = synthesize(&song).unwrap();
    let dir = std::env::temp_dir().join(format!("marionette-music-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("song.wav");
    std::fs::write(&path, wav_bytes(&t.samples, 1, t.sample_rate).unwrap()).unwrap();
    let png = dir.join("song.png");
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", path.to_str().unwrap(), "--json", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let tempo = v["tempo_bpm"].as_f64().unwrap();
    assert!((tempo / 104.5 - 1.0).abs() < 0.01, "{tempo}");
    let beats = v["beats_s"].as_array().unwrap();
    assert!(beats.len() >= 30, "{}", beats.len());
    let bars = v["bars"].as_array().unwrap();
    assert!(bars.len() >= 7, "{}", bars.len());
    for key in ["start_s", "end_s", "rms", "rms_db"] {
        assert!(bars[0][key].is_f64(), "bars[0].{key}: {}", bars[0]);
    }
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let text = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", path.to_str().unwrap()])
        .output()
        .unwrap();
    let s = String::from_utf8_lossy(&text.stdout);
    assert!(
        s.contains("tempo") && s.contains("BPM") && s.contains("RMS (dB)"),
        "{s}"
    );
    let junk = dir.join("junk.mp3");
    std::fs::write(&junk, b"not audio at all").unwrap();
    let bad = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", junk.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(e.contains("junk.mp3") && e.contains("cannot decode"), "{e}");
    // A silent song: the error names the file and says why.
    let silent = dir.join("silent.wav");
    std::fs::write(&silent, wav_bytes(&vec![0.0; 44_100], 1, 22_050).unwrap()).unwrap();
    let bad = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", silent.to_str().unwrap()])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    let e = String::from_utf8_lossy(&bad.stderr);
    assert!(
        e.contains("silent.wav") && e.contains("the song is silent"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `marionette dance db` on a manifest of the project's four bars at 120 BPM: a progress line
/// per clip, a database with four segments that `dance info` reads back; an empty folder is one
/// clear error and writes nothing.
#[test]
fn dance_db_builds_from_a_manifest_and_refuses_an_empty_folder() {
    let dir = std::env::temp_dir().join(format!("marionette-dance-cli-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("empty")).unwrap();
    let clip = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/dance_bars.ron");
    let manifest = dir.join("manifest.ron");
    std::fs::write(
        &manifest,
        format!(
            "(format_version: 1, clips: [(file: {:?}, tempo_bpm: 120.0, first_beat_s: 0.0)])",
            clip.display().to_string()
        ),
    )
    .unwrap();
    let db = dir.join("db.json");
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["dance", "db"])
        .arg(&manifest)
        .arg("--out")
        .arg(&db)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("[1/1]")
            && err.contains("120.00 BPM (manifest)")
            && err.contains("4 segments"),
        "{err}"
    );
    let info = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["dance", "info"])
        .arg(&db)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    assert!(
        text.contains("4 segments of 32 frames") && text.contains("dance_bars.ron"),
        "{text}"
    );

    let none = dir.join("none.json");
    let out = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["dance", "db"])
        .arg(dir.join("empty"))
        .arg("--out")
        .arg(&none)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(err.contains("no dance clip in the folder"), "{err}");
    assert!(!none.exists());
}

/// `marionette dance db` on a folder with a file that is not BVH and a still clip beside two good
/// ones: one line each for the bad ones naming them and why, a database from the good ones,
/// exit 0, and `dance info` lists what was skipped; `--strict` fails on the first refusal; a
/// folder with nothing usable fails naming each clip; `--music-bpm` takes the tempo to the
/// song's octave level and says so.
#[test]
fn dance_db_skips_what_it_cannot_use_and_says_why() {
    use marionette::choreo::{AuthoredDance, generate, write_bvh_folder};
    use marionette::humanoid::FigureClip;

    let dir = std::env::temp_dir().join(format!("marionette-dance-skip-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let (mixed, bad) = (dir.join("mixed"), dir.join("bad"));
    let clips = generate(&AuthoredDance {
        bpm: 112.0,
        clips: 2,
        bars_per_clip: 4,
        ..AuthoredDance::default()
    })
    .unwrap();
    write_bvh_folder(&clips, &mixed).unwrap();
    for d in [&mixed, &bad] {
        std::fs::create_dir_all(d).unwrap();
        let like = &clips[0].motion;
        let n = (12.0 / like.frame_time) as usize;
        let still = FigureClip {
            model: like.model.clone(),
            frame_time: like.frame_time,
            root_translation: vec![like.root_translation[0]; n],
            root_rotation: vec![like.root_rotation[0]; n],
            angles: like.angles[..like.dof_count()].repeat(n),
        };
        marionette::bvh::write_file(&still.to_clip().to_bvh(), &d.join("still.bvh")).unwrap();
        std::fs::write(
            d.join("a_broken.bvh"),
            "HIERARCHY\nROOT hips\n{ OFFSET 0 0\n",
        )
        .unwrap();
    }
    let run = |args: &[&std::ffi::OsStr]| {
        Command::new(env!("CARGO_BIN_EXE_marionette"))
            .args(args)
            .output()
            .unwrap()
    };
    let db = dir.join("db.json");
    let out = run(&[
        "dance".as_ref(),
        "db".as_ref(),
        mixed.as_ref(),
        "--out".as_ref(),
        db.as_ref(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    eprintln!("{err}");
    assert!(out.status.success(), "{err}");
    let skipped: Vec<&str> = err.lines().filter(|l| l.contains("skipped")).collect();
    assert!(
        skipped
            .iter()
            .any(|l| l.contains("a_broken.bvh") && l.contains("line 4")),
        "{err}"
    );
    assert!(
        skipped
            .iter()
            .any(|l| l.contains("still.bvh") && l.contains("no kinematic tempo")),
        "{err}"
    );
    assert_eq!(err.matches("(kinematic)").count(), 2, "{err}");
    assert!(err.contains("from 2 clips (2 skipped)"), "{err}");
    let info = run(&["dance".as_ref(), "info".as_ref(), db.as_ref()]);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(
        info.status.success(),
        "{}",
        String::from_utf8_lossy(&info.stderr)
    );
    assert!(text.contains("from 2 clips (2 skipped)"), "{text}");
    assert!(
        text.lines().any(|l| l.contains("skipped")
            && l.contains("still.bvh")
            && l.contains("no kinematic tempo")),
        "{text}"
    );
    assert!(
        text.lines()
            .any(|l| l.contains("skipped") && l.contains("a_broken.bvh")),
        "{text}"
    );

    // --strict: the first refusal (the broken file, first by name) fails, nothing written.
    let strict = dir.join("strict.json");
    let out = run(&[
        "dance".as_ref(),
        "db".as_ref(),
        mixed.as_ref(),
        "--out".as_ref(),
        strict.as_ref(),
        "--strict".as_ref(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(
        err.contains("a_broken.bvh") && err.contains("line 4"),
        "{err}"
    );
    assert!(!strict.exists());

    // Nothing usable: an error naming each clip and why, nothing written.
    let none = dir.join("none.json");
    let out = run(&[
        "dance".as_ref(),
        "db".as_ref(),
        bad.as_ref(),
        "--out".as_ref(),
        none.as_ref(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("no clip could be used"), "{err}");
    let last = err.rsplit("no clip could be used").next().unwrap();
    assert!(
        last.contains("a_broken.bvh") && last.contains("still.bvh"),
        "{err}"
    );
    assert!(!none.exists());

    // For a song at 58 BPM the 112 BPM clips take two of their beats per song beat.
    let slow = dir.join("slow.json");
    let out = run(&[
        "dance".as_ref(),
        "db".as_ref(),
        mixed.as_ref(),
        "--out".as_ref(),
        slow.as_ref(),
        "--music-bpm".as_ref(),
        "58".as_ref(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let d = marionette::choreo::Database::load(&slow).unwrap();
    assert_eq!(d.params.music_bpm, Some(58.0));
    for s in &d.sources {
        assert!((s.beat.tempo_bpm / 56.0 - 1.0).abs() < 0.02, "{:?}", s.beat);
    }
    assert_eq!(err.matches("octave nearest the song").count(), 2, "{err}");
    let info = run(&["dance".as_ref(), "info".as_ref(), slow.as_ref()]);
    let text = String::from_utf8_lossy(&info.stdout);
    assert!(text.contains("for a song at 58.00 BPM"), "{text}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `marionette dance db INPUT --out DB EXTRA…`, killed after `secs` (see [`run_within`]).
fn dance_db(input: &Path, db: &Path, extra: &[&str], secs: u64) -> std::process::Output {
    let mut args: Vec<&std::ffi::OsStr> = vec![
        "dance".as_ref(),
        "db".as_ref(),
        input.as_os_str(),
        "--out".as_ref(),
        db.as_os_str(),
    ];
    args.extend(extra.iter().map(|a| std::ffi::OsStr::new(*a)));
    run_within(&args, secs)
}

/// `marionette` with `args`, killed and failed after `secs` seconds (a hang is a failure,
/// never a test left running).
fn run_within(args: &[&std::ffi::OsStr], secs: u64) -> std::process::Output {
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed().as_secs() >= secs {
            child.kill().unwrap();
            let _ = child.wait();
            panic!("marionette {args:?} still running after {secs} s");
        }
        std::thread::sleep(std::time::Duration::from_millis(50));
    }
    child.wait_with_output().unwrap()
}

/// A fresh temporary folder for one test.
fn fresh_dir(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("marionette-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A manifest in `dir` of the project's four bars with `fields` added to the clip.
fn bars_manifest(dir: &std::path::Path, fields: &str) -> std::path::PathBuf {
    let clip = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/dance_bars.ron");
    let manifest = dir.join("manifest.ron");
    std::fs::write(
        &manifest,
        format!(
            "(format_version: 1, clips: [(file: {:?}, {fields})])",
            clip.display().to_string()
        ),
    )
    .unwrap();
    manifest
}

/// Issue 38, point 3: a database whose segment names a missing source, whose counts disagree
/// or that was made on another model is refused by `dance info` and by `marionette run` alike
/// (exit 1, never a panic), naming the file, the segment and what is wrong.
#[test]
fn a_database_naming_a_missing_source_or_another_model_is_refused_by_info_and_run() {
    let dir = fresh_dir("dance-db-invalid");
    let manifest = bars_manifest(&dir, "tempo_bpm: 120.0, first_beat_s: 0.0");
    let good = dir.join("good.json");
    let out = dance_db(&manifest, &good, &[], 120);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let db: serde_json::Value = serde_json::from_slice(&std::fs::read(&good).unwrap()).unwrap();
    let edited = |name: &str, edit: &dyn Fn(&mut serde_json::Value)| {
        let mut v = db.clone();
        edit(&mut v);
        let p = dir.join(name);
        std::fs::write(&p, serde_json::to_vec(&v).unwrap()).unwrap();
        p
    };
    let cases = [
        (
            edited("missing_source.json", &|v| {
                v["segments"][2]["clip"] = 7.into()
            }),
            vec!["segment 2", "names source 7", "1 source"],
        ),
        (
            edited("other_model.json", &|v| v["model"] = "robot12".into()),
            vec!["made on model \"robot12\"", "humanoid24 only"],
        ),
        (
            edited("short_angles.json", &|v| {
                v["segments"][1]["angles"].as_array_mut().unwrap().pop();
            }),
            vec!["segment 1", "angles holds"],
        ),
        (
            edited("count.json", &|v| v["sources"][0]["segments"] = 9.into()),
            vec!["source 0", "says 9 segment(s), but 4"],
        ),
    ];
    for (path, expected) in &cases {
        let file = path.file_name().unwrap().to_str().unwrap();
        let info = run_within(&["dance".as_ref(), "info".as_ref(), path.as_os_str()], 60);
        let err = String::from_utf8_lossy(&info.stderr);
        assert_eq!(info.status.code(), Some(1), "dance info {file}: {err}");
        assert!(err.contains(file), "{err}");
        for e in expected {
            assert!(err.contains(e), "dance info {file}: {e:?} not in {err}");
        }
        let scene = dir.join(format!("{file}.scene.ron"));
        std::fs::write(
            &scene,
            format!(
                "Dance(format_version: 1, name: \"bad\", song: Synth(bpm: 120.0, bars: 4, \
                 bar_levels_db: [-20.0, -20.0, -20.0, -20.0], snr_db: None, lead_in_s: 0.5, \
                 tail_s: 0.5, seed: 1), database: File({:?}), pins: [], \
                 dance: (fps: 30.0, seam_frames: 5), render: (gif: false, gif_fps: 15.0))",
                path.display().to_string()
            ),
        )
        .unwrap();
        let outdir = dir.join(format!("{file}.out"));
        let run = run_within(
            &[
                "run".as_ref(),
                scene.as_os_str(),
                "--out".as_ref(),
                outdir.as_os_str(),
            ],
            120,
        );
        let err = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(1), "run on {file}: {err}");
        assert!(err.contains(file), "{err}");
        for e in expected {
            assert!(err.contains(e), "run on {file}: {e:?} not in {err}");
        }
        assert!(!outdir.exists());
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 38, point 4: tempi and bar sizes out of bounds are refused at once, naming the field
/// or option, its value and the accepted range (a manifest tempo of 1e9 BPM used to hang
/// `dance db`, 100,000 BPM wrote 97 MB, `--bar-frames 4000000000` aborted on a 32 GB
/// allocation, `music --prior-bpm 1e9` reported a tempo outside the documented range).
#[test]
fn sizes_and_tempi_out_of_bounds_are_refused_before_any_work() {
    let dir = fresh_dir("dance-bounds");
    let db = dir.join("db.json");
    for (tempo, shown) in [("1e9", "1000000000"), ("100000.0", "100000"), ("5.0", "5")] {
        let manifest = bars_manifest(&dir, &format!("tempo_bpm: {tempo}"));
        let out = dance_db(&manifest, &db, &[], 20);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "tempo {tempo}: {err}");
        assert!(
            err.contains("manifest.ron")
                && err.contains("tempo_bpm")
                && err.contains(&format!("{shown} BPM"))
                && err.contains("20 to 400 BPM"),
            "tempo {tempo}: {err}"
        );
        assert!(!db.exists());
    }
    let manifest = bars_manifest(&dir, "tempo_bpm: 120.0");
    for (option, value, range) in [
        ("--bar-frames", "4000000000", "2 to 1024"),
        ("--bar-frames", "1", "2 to 1024"),
        ("--music-bpm", "1e9", "20 to 400 BPM"),
    ] {
        let out = dance_db(&manifest, &db, &[option, value], 20);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{option} {value}: {err}");
        assert!(
            err.contains(option) && err.contains(range),
            "{option} {value}: {err}"
        );
        assert!(!db.exists());
    }
    let t = marionette::choreo::music::synthesize(&marionette::choreo::music::SynthSong {
        bars: 4,
        ..Default::default()
    })
    .unwrap();
    let song = dir.join("song.wav");
    std::fs::write(&song, wav_bytes(&t.samples, 1, t.sample_rate).unwrap()).unwrap();
    for value in ["1e9", "10"] {
        let out = run_within(
            &[
                "music".as_ref(),
                song.as_os_str(),
                "--prior-bpm".as_ref(),
                value.as_ref(),
            ],
            30,
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "--prior-bpm {value}: {err}");
        assert!(
            err.contains("--prior-bpm") && err.contains("40 to 240 BPM"),
            "--prior-bpm {value}: {err}"
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Issue 38, point 5a: a manifest window holding NaN is refused before anything is written
/// (it used to be written as `null`, and `dance info` then called the file "not a dance
/// database").
#[test]
fn a_window_that_is_not_finite_is_refused_before_writing() {
    let dir = fresh_dir("dance-nan-window");
    let db = dir.join("db.json");
    for window in ["(NaN, 10.0)", "(0.0, inf)", "(3.0, 1.0)"] {
        let manifest = bars_manifest(&dir, &format!("tempo_bpm: 120.0, window: {window}"));
        let out = dance_db(&manifest, &db, &[], 60);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "window {window}: {err}");
        assert!(
            err.contains("manifest.ron") && err.contains("window") && err.contains("clip 1"),
            "window {window}: {err}"
        );
        assert!(!db.exists(), "window {window}: a database was written");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Point 10 of issue 38: `marionette music … | head` panicked on the closed pipe.
#[test]
fn music_into_a_closed_pipe_ends_quietly() {
    let dir = fresh_dir("music-pipe");
    let t = synthesize(&SynthSong {
        bars: 8,
        ..SynthSong::default()
    })
    .unwrap();
    let path = dir.join("song.wav");
    std::fs::write(&path, wav_bytes(&t.samples, 1, t.sample_rate).unwrap()).unwrap();
    let mut child = Command::new(env!("CARGO_BIN_EXE_marionette"))
        .args(["music", path.to_str().unwrap()])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    // The reader goes away before the first line is printed (the analysis takes longer than
    // this), as `head` does once it has its lines: every line then meets a closed pipe.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        !err.contains("panicked") && !err.contains("Broken pipe"),
        "{err}"
    );
    assert!(out.status.success(), "{:?}: {err}", out.status);
    std::fs::remove_dir_all(&dir).ok();
}

/// Issue 38: a manifest clip may name its landmark mapping (`mapping: "FILE.ron"`, relative to
/// the manifest), which `dance db` uses instead of the one it finds: the mapping `marionette
/// mapping` writes gives the same database as finding it, a mapping with the legs' sides
/// swapped gives other segments, and a missing mapping file is an error naming it.
#[test]
fn dance_db_takes_a_clip_s_mapping_from_the_manifest() {
    let dir = std::env::temp_dir().join(format!("marionette-dance-map-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let clip = marionette::clips::KeyframeClip::load(&root.join("scenes/clips/dance_bars.ron"))
        .unwrap()
        .to_figure_clip();
    marionette::bvh::write_file(&clip.to_clip().to_bvh(), &dir.join("bars.bvh")).unwrap();
    let bin = || Command::new(env!("CARGO_BIN_EXE_marionette"));
    let out = bin()
        .arg("mapping")
        .arg(dir.join("bars.bvh"))
        .arg("--out")
        .arg(dir.join("map.ron"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // The same mapping with the legs' sides swapped.
    let text = std::fs::read_to_string(dir.join("map.ron")).unwrap();
    let mut swapped = String::new();
    for line in text.lines() {
        let line = match line.split_once(": ") {
            Some((key, value)) if key.contains("_hip") || key.contains("_knee") => {
                let value = if value.contains("left_") {
                    value.replacen("left_", "right_", 1)
                } else {
                    value.replacen("right_", "left_", 1)
                };
                format!("{key}: {value}")
            }
            _ => line.to_string(),
        };
        swapped.push_str(&line);
        swapped.push('\n');
    }
    assert_ne!(swapped, text);
    std::fs::write(dir.join("swapped.ron"), swapped).unwrap();
    // A database per manifest: the segments' JSON, or the error.
    let build = |mapping: Option<&str>| {
        let name = mapping.unwrap_or("found");
        let manifest = dir.join(format!("{name}.manifest.ron"));
        let field = mapping.map_or(String::new(), |m| format!(", mapping: {m:?}"));
        std::fs::write(
            &manifest,
            format!(
                "(format_version: 1, clips: [(file: \"bars.bvh\", tempo_bpm: 120.0, first_beat_s: 0.0{field})])"
            ),
        )
        .unwrap();
        let db = dir.join(format!("{name}.json"));
        let out = bin()
            .args(["dance", "db", "--strict"])
            .arg(&manifest)
            .arg("--out")
            .arg(&db)
            .output()
            .unwrap();
        if !out.status.success() {
            return Err(String::from_utf8_lossy(&out.stderr).into_owned());
        }
        let v: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&db).unwrap()).unwrap();
        Ok(v["segments"].clone())
    };
    let found = build(None).unwrap();
    assert_eq!(found.as_array().map(Vec::len), Some(4));
    assert_eq!(build(Some("map.ron")).unwrap(), found);
    assert_ne!(build(Some("swapped.ron")).unwrap(), found);
    let e = build(Some("nowhere.ron")).unwrap_err();
    assert!(e.contains("nowhere.ron"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}
