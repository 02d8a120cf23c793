//! The dance-segment database: the project's keyframed dance (`scenes/clips/dance_bars.ron`,
//! four bars at 120 BPM) cut into its four bars, the kinematic tempo of a clip generated with a
//! known tempo, the shared dance clips (segments and tempo per clip), and one clear error per
//! bad input.

use crate::common;

use std::path::{Path, PathBuf};

use marionette::choreo::{
    Beat, LEVEL_BPM, MAX_BPM, MIN_BPM, SegmentError, TempoSource, cut_segments, kinematic_beat,
};
use marionette::choreo::{BuildParams, ClipOutcome, Database, Manifest, ManifestClip, OnRefusal};
use marionette::humanoid::{FigureClip, humanoid24};

use glam::{DQuat, DVec3};

fn dance_bars() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/clips/dance_bars.ron")
}

/// A fresh scratch folder for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("marionette-segments-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn one_clip(file: PathBuf, tempo_bpm: Option<f64>, window: Option<(f64, f64)>) -> Manifest {
    Manifest {
        format_version: 1,
        clips: vec![ManifestClip {
            file,
            tempo_bpm,
            first_beat_s: tempo_bpm.map(|_| 0.0),
            window,
            mapping: None,
        }],
    }
}

#[test]
fn dance_bars_at_120_bpm_give_its_four_bars() {
    let dir = scratch("bars");
    let manifest = dir.join("manifest.ron");
    std::fs::write(
        &manifest,
        format!(
            "(format_version: 1, clips: [(file: {:?}, tempo_bpm: 120.0, first_beat_s: 0.0)])",
            dance_bars().display().to_string()
        ),
    )
    .unwrap();
    let m = Manifest::load(&manifest).unwrap();
    let db = Database::build(&m, &BuildParams::default(), OnRefusal::Fail, |_, _| {}).unwrap();
    assert_eq!(db.segments.len(), 4);
    assert_eq!(db.sources[0].segments, 4);
    assert_eq!(db.sources[0].beat.source, TempoSource::Manifest);
    for (k, s) in db.segments.iter().enumerate() {
        assert_eq!(s.bar, k);
        assert!((s.start_s - 2.0 * k as f64).abs() < 1e-12, "{}", s.start_s);
        assert!(
            (s.end_s - 2.0 * (k + 1) as f64).abs() < 1e-12,
            "{}",
            s.end_s
        );
        assert_eq!(s.frame_count(), 32);
        assert_eq!(s.angles.len(), 32 * humanoid24().dofs.len());
        assert!(s.intensity > 0.0);
        assert_eq!(s.first_directions.len(), s.last_directions.len());
        for d in &s.first_directions {
            assert!((d.length() - 1.0).abs() < 1e-9 || d.length() == 0.0);
        }
    }
    // Consecutive bars of one take connect: the last links of a bar point where the next bar's
    // first links do (one resampled frame, 1/16 s, apart).
    let mean_dot = |a: &[DVec3], b: &[DVec3]| -> f64 {
        a.iter().zip(b).map(|(x, y)| x.dot(*y)).sum::<f64>() / a.len() as f64
    };
    for k in 0..3 {
        let (a, b) = (&db.segments[k], &db.segments[k + 1]);
        let seam = mean_dot(&a.last_directions, &b.first_directions);
        eprintln!("bar {k}→{}: mean cosine of boundary links {seam:.4}", k + 1);
        assert!(seam > 0.98, "{seam}");
    }
    // Frame 0 of bar 2 is the clip at 4 s: bar 3's quarter turn starts there (turn 0 at 4 s).
    let clip = marionette::clips::KeyframeClip::load(&dance_bars())
        .unwrap()
        .to_figure_clip();
    let f = (4.0 / clip.frame_time).round() as usize;
    assert!(db.segments[2].root_rotation[0].angle_between(clip.root_rotation[f]) < 1e-9);
    // The motion intensity of each bar, printed for the report.
    let w: Vec<f64> = db.segments.iter().map(|s| s.intensity).collect();
    eprintln!("dance_bars intensity per bar (m/s, unit weights): {w:?}");

    // Saved and loaded, the same database.
    let out = dir.join("db.json");
    db.save(&out).unwrap();
    let back = Database::load(&out).unwrap();
    assert_eq!(back, db);

    // Without the manifest (a folder of that one clip), the kinematic beat.
    let folder = scratch("bars-folder");
    std::fs::copy(dance_bars(), folder.join("dance_bars.ron")).unwrap();
    let k = Database::build(
        &Manifest::from_folder(&folder).unwrap(),
        &BuildParams::default(),
        OnRefusal::Fail,
        |_, _| {},
    )
    .unwrap();
    eprintln!(
        "dance_bars kinematic beat: {:.2} BPM, first beat {:.3} s, {} segments",
        k.sources[0].beat.tempo_bpm, k.sources[0].beat.first_beat_s, k.sources[0].segments
    );
    assert_eq!(k.sources[0].beat.source, TempoSource::Kinematic);
}

/// A humanoid24 clip whose arms and legs swing from one extreme to the other on every beat
/// (a smooth step per beat, at rest on the beat) at `bpm`, its first beat at `phase_s`.
fn generated(bpm: f64, phase_s: f64, fps: f64, seconds: f64) -> FigureClip {
    let model = humanoid24();
    let d = model.dofs.len();
    let period = 60.0 / bpm;
    let n = (seconds * fps) as usize;
    let dofs: Vec<(usize, f64)> = [
        ("left_knee", 40.0),
        ("right_knee", 40.0),
        ("left_shoulder_abduction", 60.0),
        ("right_shoulder_abduction", -30.0),
        ("left_elbow_flexion", 50.0),
    ]
    .iter()
    .map(|(name, amp)| (model.dof_index(name).unwrap(), f64::to_radians(*amp)))
    .collect();
    let mut angles = vec![0.0; n * d];
    for f in 0..n {
        let t = f as f64 / fps - phase_s + 10.0 * period;
        let k = (t / period).floor() as i64;
        let u = t / period - k as f64;
        let s = u - (2.0 * std::f64::consts::PI * u).sin() / (2.0 * std::f64::consts::PI);
        let x = if k % 2 == 0 { s } else { 1.0 - s };
        for &(i, amp) in &dofs {
            angles[f * d + i] = amp * x + 0.1;
        }
    }
    FigureClip {
        model,
        frame_time: 1.0 / fps,
        root_translation: vec![DVec3::new(0.0, 0.95, 0.0); n],
        root_rotation: vec![DQuat::IDENTITY; n],
        angles,
    }
}

#[test]
fn kinematic_tempo_of_a_generated_clip_is_within_2_percent() {
    let dir = scratch("kinematic");
    for (bpm, phase) in [(96.0, 0.15), (113.7, 0.31), (131.4, 0.05)] {
        let clip = generated(bpm, phase, 120.0, 24.0);
        // Through the whole path: written as BVH, read, mapped onto humanoid24 again.
        let file = dir.join(format!("gen_{bpm}.bvh"));
        marionette::bvh::write_file(&clip.to_clip().to_bvh(), &file).unwrap();
        let db = Database::build(
            &one_clip(file, None, None),
            &BuildParams::default(),
            OnRefusal::Fail,
            |_, _| {},
        )
        .unwrap();
        let beat = db.sources[0].beat;
        eprintln!(
            "generated {bpm} BPM, first beat {phase} s: kinematic {:.3} BPM, first beat {:.3} s",
            beat.tempo_bpm, beat.first_beat_s
        );
        assert_eq!(beat.source, TempoSource::Kinematic);
        assert!((beat.tempo_bpm / bpm - 1.0).abs() < 0.02, "{bpm}: {beat:?}");
        let p = 60.0 / bpm;
        let off = (beat.first_beat_s - phase).rem_euclid(p);
        assert!(off.min(p - off) < 0.03, "{bpm}: first beat {beat:?}");
        let bars = ((24.0 - beat.first_beat_s) / beat.bar_s()).floor() as usize;
        assert_eq!(db.segments.len(), bars);
    }
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn shared_dance_clips_segments_and_tempo() {
    let Some(dir) = common::data_path("dance") else {
        return;
    };
    let m = Manifest::from_folder(&dir).unwrap();
    let db = Database::build(&m, &BuildParams::default(), OnRefusal::Fail, |_, s| {
        let ClipOutcome::Used(s) = s else { return };
        eprintln!(
            "{}: {} frames at {:.0} fps, {:.2} BPM ({:?}), first beat {:.3} s, {} segments",
            Path::new(&s.file).file_name().unwrap().to_string_lossy(),
            s.frames,
            s.fps,
            s.beat.tempo_bpm,
            s.beat.source,
            s.beat.first_beat_s,
            s.segments
        )
    })
    .unwrap();
    eprintln!(
        "{} segments from {} clips; database {} bytes",
        db.segments.len(),
        db.sources.len(),
        db.to_json().len()
    );
    assert_eq!(db.sources.len(), m.clips.len());
    for s in &db.sources {
        assert!(s.segments >= 1);
        assert!((MIN_BPM..=MAX_BPM).contains(&s.beat.tempo_bpm));
        let dur = s.frames as f64 / s.fps;
        assert_eq!(
            s.segments,
            ((dur - s.beat.first_beat_s) / s.beat.bar_s() + 1e-9).floor() as usize
        );
    }
    // A consistency check (no music exists for these takes): the kinematic tempo of each half.
    for c in &m.clips {
        let clip = marionette::choreo::load_figure_clip(&c.file).unwrap();
        let half = clip.frame_count() as f64 * clip.frame_time / 2.0;
        let name = c.file.file_name().unwrap().to_string_lossy().to_string();
        let t: Vec<String> = [(0.0, half), (half, 2.0 * half)]
            .iter()
            .map(|&(a, b)| {
                let w = clip.window(a, b).unwrap();
                kinematic_beat(&w, &name, None)
                    .map(|b| format!("{:.2}", b.tempo_bpm))
                    .unwrap_or_else(|e| e.to_string())
            })
            .collect();
        eprintln!("{name}: kinematic tempo of the first and second half {t:?} BPM");
    }
    let out = scratch("shared").join("db.json");
    db.save(&out).unwrap();
    assert_eq!(
        Database::load(&out).unwrap().segments.len(),
        db.segments.len()
    );
}

#[test]
fn boundary_links_do_not_depend_on_where_the_dancer_faces() {
    let clip = marionette::clips::KeyframeClip::load(&dance_bars())
        .unwrap()
        .to_figure_clip();
    let yaw = DQuat::from_rotation_y(1.1);
    let mut turned = clip.clone();
    for (t, r) in turned
        .root_translation
        .iter_mut()
        .zip(turned.root_rotation.iter_mut())
    {
        *t = yaw * *t + DVec3::new(3.0, 0.0, -2.0);
        *r = yaw * *r;
    }
    let beat = Beat {
        tempo_bpm: 120.0,
        first_beat_s: 0.0,
        source: TempoSource::Manifest,
    };
    let p = BuildParams::default();
    let a = cut_segments(&clip, "a", 0, &beat, &p).unwrap();
    let b = cut_segments(&turned, "b", 0, &beat, &p).unwrap();
    for (x, y) in a.iter().zip(&b) {
        for (u, v) in x.first_directions.iter().zip(&y.first_directions) {
            assert!((*u - *v).length() < 1e-9, "{u} {v}");
        }
        for (u, v) in x.last_velocities.iter().zip(&y.last_velocities) {
            assert!((*u - *v).length() < 1e-9, "{u} {v}");
        }
        assert!((x.intensity - y.intensity).abs() < 1e-9);
    }
}

#[test]
fn bad_input_gives_one_clear_error_each() {
    // A clip shorter than a bar: one second of the 120 BPM dance.
    let e = Database::build(
        &one_clip(dance_bars(), Some(120.0), Some((0.0, 1.0))),
        &BuildParams::default(),
        OnRefusal::Fail,
        |_, _| {},
    )
    .unwrap_err();
    assert!(matches!(e, SegmentError::TooShort { .. }), "{e}");
    let msg = e.to_string();
    assert!(
        msg.contains("dance_bars.ron") && msg.contains("shorter than one bar"),
        "{msg}"
    );

    // An empty folder.
    let empty = scratch("empty");
    let e = Manifest::from_folder(&empty).unwrap_err();
    assert!(matches!(e, SegmentError::EmptyFolder { .. }), "{e}");
    assert!(e.to_string().contains("no dance clip"), "{e}");

    // An unreadable file: a BVH that is not one.
    let bad = scratch("bad");
    std::fs::write(
        bad.join("broken.bvh"),
        "HIERARCHY\nROOT hips\n{ OFFSET 0 0\n",
    )
    .unwrap();
    let e = Database::build(
        &Manifest::from_folder(&bad).unwrap(),
        &BuildParams::default(),
        OnRefusal::Fail,
        |_, _| {},
    )
    .unwrap_err();
    assert!(matches!(e, SegmentError::Load { .. }), "{e}");
    let msg = e.to_string();
    assert_eq!(msg.matches("broken.bvh").count(), 1, "{msg}");
    assert!(msg.contains("line 4"), "{msg}");

    // A file that does not exist, and a database that is not one.
    let e = Manifest::load(&bad.join("missing.ron")).unwrap_err();
    assert!(e.to_string().contains("missing.ron"), "{e}");
    std::fs::write(bad.join("db.json"), "{\"format_version\": 1}").unwrap();
    let e = Database::load(&bad.join("db.json")).unwrap_err();
    assert!(matches!(e, SegmentError::Database { .. }), "{e}");

    // A manifest tempo that is not a tempo.
    let e = Database::build(
        &one_clip(dance_bars(), Some(0.0), None),
        &BuildParams::default(),
        OnRefusal::Fail,
        |_, _| {},
    )
    .unwrap_err();
    assert!(matches!(e, SegmentError::Tempo { .. }), "{e}");
}

/// A folder of two good clips (the project's own dance at 112 BPM, written as BVH), a still
/// clip (the first pose held for 12 s: no tempo) and a file that is not BVH, named so that
/// the broken one comes first.
fn folder_with_bad_clips(name: &str) -> PathBuf {
    let dir = scratch(name);
    let p = marionette::choreo::AuthoredDance {
        bpm: 112.0,
        clips: 2,
        bars_per_clip: 4,
        ..Default::default()
    };
    let clips = marionette::choreo::generate(&p).unwrap();
    marionette::choreo::write_bvh_folder(&clips, &dir).unwrap();
    write_still_and_broken(&dir, &clips[0].motion);
    dir
}

/// `still.bvh` (the first pose of `like` held for 12 s) and `a_broken.bvh` (not BVH) in `dir`.
fn write_still_and_broken(dir: &Path, like: &FigureClip) {
    let n = (12.0 / like.frame_time) as usize;
    let d = like.dof_count();
    let still = FigureClip {
        model: like.model.clone(),
        frame_time: like.frame_time,
        root_translation: vec![like.root_translation[0]; n],
        root_rotation: vec![like.root_rotation[0]; n],
        angles: like.angles[..d].repeat(n),
    };
    marionette::bvh::write_file(&still.to_clip().to_bvh(), &dir.join("still.bvh")).unwrap();
    std::fs::write(
        dir.join("a_broken.bvh"),
        "HIERARCHY\nROOT hips\n{ OFFSET 0 0\n",
    )
    .unwrap();
}

#[test]
fn a_clip_that_cannot_be_used_is_skipped_named_and_recorded() {
    let dir = folder_with_bad_clips("skip");
    let m = Manifest::from_folder(&dir).unwrap();
    assert_eq!(m.clips.len(), 4);
    let mut lines = vec![];
    let db = Database::build(&m, &BuildParams::default(), OnRefusal::Skip, |i, o| {
        lines.push(match o {
            ClipOutcome::Used(s) => format!("{i} used {}", s.file),
            ClipOutcome::Skipped(s) => format!("{i} skipped {}", s.reason),
        })
    })
    .unwrap();
    eprintln!("{lines:#?}");
    assert_eq!(lines.len(), 4, "one line per clip: {lines:?}");
    // The two good clips give their bars, indexed 0 and 1 in the database.
    assert_eq!(db.sources.len(), 2);
    for (k, s) in db.sources.iter().enumerate() {
        assert!(s.file.contains("authored_"), "{}", s.file);
        assert!(
            (s.beat.tempo_bpm / 112.0 - 1.0).abs() < 0.02,
            "{:?}",
            s.beat
        );
        assert_eq!(db.segments_of(k).count(), s.segments);
        assert!(s.segments >= 3);
    }
    assert_eq!(
        db.segments.len(),
        db.sources.iter().map(|s| s.segments).sum::<usize>()
    );
    // The broken file and the still clip are named, each with why.
    assert_eq!(db.skipped.len(), 2, "{:?}", db.skipped);
    let broken = &db.skipped[0];
    assert!(broken.file.ends_with("a_broken.bvh"), "{broken:?}");
    assert!(
        broken.reason.contains("a_broken.bvh") && broken.reason.contains("line 4"),
        "{broken:?}"
    );
    let still = &db.skipped[1];
    assert!(still.file.ends_with("still.bvh"), "{still:?}");
    assert!(
        still.reason.contains("still.bvh") && still.reason.contains("no kinematic tempo"),
        "{still:?}"
    );
    // Saved and loaded, the skipped clips are still there; a database written before they
    // were recorded (no `skipped` field) still loads, with none.
    let out = dir.join("db.json");
    db.save(&out).unwrap();
    assert_eq!(Database::load(&out).unwrap().skipped, db.skipped);
    let mut old: serde_json::Value = serde_json::from_slice(&db.to_json()).unwrap();
    old.as_object_mut().unwrap().remove("skipped");
    std::fs::write(&out, serde_json::to_vec(&old).unwrap()).unwrap();
    let back = Database::load(&out).unwrap();
    assert!(back.skipped.is_empty());
    assert_eq!(back.segments.len(), db.segments.len());

    // Strict: the first refusal fails the build, with that clip's own error.
    let e = Database::build(&m, &BuildParams::default(), OnRefusal::Fail, |_, _| {}).unwrap_err();
    assert!(matches!(e, SegmentError::Load { .. }), "{e}");
    assert!(e.to_string().contains("a_broken.bvh"), "{e}");

    // Nothing usable: one error that names every clip and says why.
    let bad = scratch("skip-all-bad");
    let one = marionette::choreo::generate(&Default::default()).unwrap();
    write_still_and_broken(&bad, &one[0].motion);
    let e = Database::build(
        &Manifest::from_folder(&bad).unwrap(),
        &BuildParams::default(),
        OnRefusal::Skip,
        |_, _| {},
    )
    .unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, SegmentError::NoUsableClip { .. }), "{msg}");
    assert!(
        msg.contains("a_broken.bvh") && msg.contains("line 4"),
        "{msg}"
    );
    assert!(
        msg.contains("still.bvh") && msg.contains("no kinematic tempo"),
        "{msg}"
    );
}

#[test]
fn the_song_tempo_takes_a_generated_clip_to_its_octave_level() {
    // A clip that swings on every beat at 113.7 BPM (it repeats every two beats too): for a
    // song at 60 BPM its bars are two of its beats long, for a song at 110 its own beat.
    let dir = scratch("octave");
    let file = dir.join("gen.bvh");
    let clip = generated(113.7, 0.31, 120.0, 24.0);
    marionette::bvh::write_file(&clip.to_clip().to_bvh(), &file).unwrap();
    for (music, want) in [(None, 113.7), (Some(110.0), 113.7), (Some(60.0), 56.85)] {
        let params = BuildParams {
            music_bpm: music,
            ..BuildParams::default()
        };
        let db = Database::build(
            &one_clip(file.clone(), None, None),
            &params,
            OnRefusal::Fail,
            |_, _| {},
        )
        .unwrap();
        let beat = db.sources[0].beat;
        eprintln!(
            "song {music:?}: {:.3} BPM ({:?})",
            beat.tempo_bpm, beat.source
        );
        assert!(
            (beat.tempo_bpm / want - 1.0).abs() < 0.02,
            "{music:?}: {beat:?}"
        );
        let how = match music {
            None => TempoSource::Kinematic,
            Some(_) => TempoSource::KinematicMatched,
        };
        assert_eq!(beat.source, how);
    }
}

/// The kinematic tempo of every shared clip: `dance` (the scenes') and `dance_more` (held out of
/// tuning), alone and for the shared song of `scenes/dance_salsa.ron` (its tempo measured here).
#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn every_shared_clip_gets_a_tempo_in_range_alone_and_for_the_song() {
    let (Some(dance), Some(more), Some(song)) = (
        common::data_path("dance"),
        common::data_path("dance_more"),
        common::data_path("audio/supertux_chipdisko.ogg"),
    ) else {
        return;
    };
    let audio = marionette::choreo::music::decode_file(&song).unwrap();
    let music =
        marionette::choreo::music::analyze(&audio.samples, audio.sample_rate, &Default::default())
            .unwrap()
            .tempo_bpm;
    eprintln!("supertux_chipdisko.ogg: {music:.2} BPM");
    for dir in [dance, more] {
        let m = Manifest::from_folder(&dir).unwrap();
        for c in &m.clips {
            let clip = marionette::choreo::load_figure_clip(&c.file).unwrap();
            let name = c.file.file_name().unwrap().to_string_lossy().to_string();
            let alone = kinematic_beat(&clip, &name, None).unwrap();
            let matched = kinematic_beat(&clip, &name, Some(music)).unwrap();
            eprintln!(
                "{}/{name}: {:.2} BPM alone, {:.2} BPM for the song at {music:.2}",
                dir.file_name().unwrap().to_string_lossy(),
                alone.tempo_bpm,
                matched.tempo_bpm
            );
            // Alone, the beat search's range; for the song, its octave levels' range.
            assert!(
                (MIN_BPM..=MAX_BPM).contains(&alone.tempo_bpm),
                "{name}: {alone:?}"
            );
            assert!(
                (LEVEL_BPM.0..=LEVEL_BPM.1).contains(&matched.tempo_bpm),
                "{name}: {matched:?}"
            );
            // For the song, the clip's level nearest it: within half an octave of its tempo.
            assert!(
                (matched.tempo_bpm / music).log2().abs() <= 0.5 + 1e-9,
                "{name}: {} for a song at {music}",
                matched.tempo_bpm
            );
        }
    }
}

/// The kinematic tempo holds on slower and faster dances: every shared clip (`dance` and the
/// held-out `dance_more`), played 0.7 and 1.4 times as fast (its speed curve v resampled as
/// s · v(s t)), gets s times its tempo when built for a song s times as fast: to 3 % for nine
/// in ten, to 10 % for all.
#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn a_clip_danced_slower_or_faster_keeps_its_beat() {
    use marionette::choreo::{kinematic_tempo, speed_curve};
    let (Some(dance), Some(more)) = (common::data_path("dance"), common::data_path("dance_more"))
    else {
        return;
    };
    let song = 100.0;
    let mut worst: f64 = 0.0;
    let mut errors = vec![];
    for dir in [dance, more] {
        for c in &Manifest::from_folder(&dir).unwrap().clips {
            let clip = marionette::choreo::load_figure_clip(&c.file).unwrap();
            let fps = 1.0 / clip.frame_time;
            let v = speed_curve(&clip.to_clip().point_frames(), fps);
            let own = kinematic_tempo(&v, fps, Some(song)).unwrap();
            for s in [0.7, 1.4] {
                let n = ((v.len() - 1) as f64 / s).floor() as usize + 1;
                let played: Vec<f64> = (0..n)
                    .map(|f| {
                        let x = f as f64 * s;
                        let i = (x.floor() as usize).min(v.len() - 2);
                        let t = x - i as f64;
                        s * (v[i] * (1.0 - t) + v[i + 1] * t)
                    })
                    .collect();
                let got = kinematic_tempo(&played, fps, Some(song * s)).unwrap();
                let err = (got / (own * s) - 1.0).abs();
                worst = worst.max(err);
                eprintln!(
                    "{}: {own:.2} BPM; played at {s}: {got:.2} (want {:.2})",
                    c.file.file_name().unwrap().to_string_lossy(),
                    own * s
                );
                errors.push(err);
            }
        }
    }
    let within = errors.iter().filter(|e| **e < 0.03).count();
    eprintln!(
        "played slower or faster: {within} of {} within 3 %, worst error {:.2} %",
        errors.len(),
        100.0 * worst
    );
    // A clip with two periodicities that are not octaves of each other (a salsa take's steps
    // at 84 and 90 BPM) may take the other one at another speed; no more than one in ten.
    assert!(
        10 * within >= 9 * errors.len(),
        "{within} of {}",
        errors.len()
    );
    assert!(worst < 0.1, "worst {worst}");
}
