//! Search with relevance feedback on whole databases: a database built (through BVH files and
//! `Database::build`) from dance clips generated here, grown by mirror images and time offsets
//! (`augment`, checked against the clips themselves), the paper's Fig. 4 on it and on the
//! shared dance clips (a table, a plot, and the fall of eq. 9 over the first three re-searches),
//! and the edit a server holds, on a synthesized song. Whether the likes steer the search: on
//! the shared clips (the database `Database::build` makes of them, not augmented) the second
//! re-search is pulled toward the liked segments, measured against the same trials with the
//! likes withheld, at the paper's τ_0 = 1 (printed) and at the stated τ_0 = 0.5 (asserted); on
//! generated clips the likes change the second re-search's candidates.

use crate::common;
use crate::dance_clips;

use std::sync::Arc;

use dance_clips::{generated_database, scratch, tempo};
use marionette::choreo::Edit;
use marionette::choreo::FillParams;
use marionette::choreo::eros;
use marionette::choreo::{Beat, TempoSource, cut_segments};
use marionette::choreo::{BuildParams, Database, Manifest, OnRefusal, load_figure_clip};
use marionette::choreo::{SearchIndex, SearchParams};
use marionette::choreo::{augment, augment_with_variants};
use marionette::experiments::dance_feedback::{FeedbackConfig, FeedbackOutcome, run};

/// The τ_0 at which the likes must be felt in the second re-search: diversity and the likes
/// weigh the same in a bar's first round (the editor's slider at its middle).
const FOLLOW_TAU0: f64 = 0.5;

#[test]
fn augmented_segments_are_true_to_the_clips() {
    let (db, dir) = generated_database("augment", 6);
    assert_eq!(db.segments.len(), 48);
    let aug = augment_with_variants(&db, 300, 7);
    let a = &aug.database;
    assert_eq!(a.segments.len(), 300);
    assert_eq!(aug.variants.len(), 300);
    assert_eq!(
        a.sources.iter().map(|s| s.segments).sum::<usize>(),
        300,
        "the sources count their variants"
    );
    assert!((a.eros_weights.iter().sum::<f64>() - 1.0).abs() < 1e-12);
    // Deterministic from the seed; another seed, other variants.
    assert_eq!(augment(&db, 300, 7), *a);
    assert_ne!(augment(&db, 300, 8).segments, a.segments);
    // Fewer asked than there are: the first originals.
    assert_eq!(augment(&db, 10, 7).segments.len(), 10);

    let index = SearchIndex::new(a);
    let mut shifted = 0;
    let mut mirrored = 0;
    for (k, (v, s)) in aug.variants.iter().zip(&a.segments).enumerate() {
        let src = &db.segments[v.source];
        assert_eq!((s.clip, s.bar, s.frame_count()), (src.clip, src.bar, 32));
        if !v.mirrored && v.shift_frames == 0 {
            // An original keeps its motion and its intensity.
            assert_eq!(s.angles, src.angles);
            assert!((s.intensity - src.intensity).abs() <= 1e-9 * src.intensity);
            assert!(k < 48);
        }
        if v.shift_frames > 0 && !v.mirrored && shifted < 12 {
            // A time offset is the take re-cut at the shifted phase: cut the clip itself there.
            shifted += 1;
            let clip = load_figure_clip(&dir.join(format!("gen_{}.bvh", s.clip))).unwrap();
            let bar_s = 240.0 / tempo(s.clip);
            let beat = Beat {
                tempo_bpm: tempo(s.clip),
                first_beat_s: bar_s * v.shift_frames as f64 / 32.0,
                source: TempoSource::Manifest,
            };
            let cut = cut_segments(&clip, "gen", s.clip, &beat, &BuildParams::default()).unwrap();
            let want = &cut[s.bar];
            assert!((want.start_s - s.start_s).abs() < 1e-9);
            let dev = want
                .angles
                .iter()
                .zip(&s.angles)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(dev < 1e-9, "variant {k}: angles differ by {dev} rad");
            for (p, q) in want.root_translation.iter().zip(&s.root_translation) {
                assert!((*p - *q).length() < 1e-9);
            }
        }
        if v.mirrored && v.shift_frames == 0 {
            // A mirror image: the same intensity and Eros spectrum as its original, and less
            // similar to it than it is to itself (the moves are lopsided).
            mirrored += 1;
            let o = v.source;
            assert!((s.intensity - src.intensity).abs() <= 1e-9 * src.intensity);
            // Eigenvalues come with an absolute error of order ε·λ_max: compare on that scale.
            let scale = a.segments[o]
                .eros
                .values
                .iter()
                .fold(0.0f64, |m, &v| m.max(v.abs()));
            for (x, y) in s.eros.values.iter().zip(&a.segments[o].eros.values) {
                assert!(
                    (x - y).abs() <= 1e-9 * scale,
                    "{x} vs {y} (largest {scale})"
                );
            }
            let (own, other) = (index.sim(k, k), index.sim(k, o));
            assert!(other < own - 1e-3, "mirror {k}: {other} vs {own}");
        }
    }
    assert!(shifted > 0 && mirrored > 0, "{shifted} {mirrored}");
    // How far the recomputed Eros features of the originals (on the reference body) are from
    // those stored by the build (on the body the BVH's offsets gave): printed for the report.
    let worst = (0..48)
        .map(|k| {
            marionette::choreo::eros(&db.segments[k].eros, &a.segments[k].eros, &a.eros_weights)
        })
        .fold(1.0, f64::min);
    eprintln!("lowest Eros between an original's stored and recomputed features: {worst:.5}");
    assert!(worst > 0.95, "{worst}");
}

/// Draws the Fig. 4 curves of `o` into `dir`: eq. (9) per round, and how similar the shown
/// candidates are to the hidden target (PNG).
#[cfg(feature = "render")]
fn draw(name: &str, o: &FeedbackOutcome, dir: &std::path::Path) {
    use marionette::render::{Plot, Series, plot};
    let cfg = &o.config;
    let about = format!(
        "re-searches (0 = the first search); {} segments, {} trials, {} likes a round, rho {}",
        o.segments, cfg.trials, cfg.liked_per_round, cfg.search.rho
    );
    let curve =
        |label: &str, f: &dyn Fn(&marionette::experiments::dance_feedback::RoundOutcome) -> f64| {
            Series {
                name: label.to_string(),
                points: o.rounds.iter().map(|r| (r.round as f64, f(r))).collect(),
            }
        };
    let spread = dir.join(format!("fig4_{name}_spread.png"));
    plot(
        &Plot {
            title: format!("Fig. 4, {name}: spread of the six shown"),
            x_label: about.clone(),
            y_label: "mean pairwise Eros dissimilarity D (eq. 9)".into(),
            series: vec![curve("eq. 9, mean over the trials", &|r| {
                r.mean_dissimilarity
            })],
            markers: vec![],
        },
        &spread,
    )
    .unwrap();
    let target = dir.join(format!("fig4_{name}_target.png"));
    plot(
        &Plot {
            title: format!("Fig. 4, {name}: the six shown against the hidden target"),
            x_label: about,
            y_label: "Eros similarity to the target".into(),
            series: vec![
                curve("the most similar of the six", &|r| r.target_similarity),
                curve("mean of the six", &|r| r.mean_target_similarity),
            ],
            markers: vec![],
        },
        &target,
    )
    .unwrap();
    eprintln!("Fig. 4 plots: {} {}", spread.display(), target.display());
}

/// Checks the paper's claim on `o`: eq. (9) falls over the first three re-searches.
fn assert_spread_narrows(o: &FeedbackOutcome) {
    let d: Vec<f64> = o.rounds.iter().map(|r| r.mean_dissimilarity).collect();
    for k in 0..3 {
        assert!(d[k + 1] < d[k], "eq. 9 does not fall from round {k}: {d:?}");
    }
}

#[test]
fn fig4_on_a_generated_database() {
    let (db, _) = generated_database("fig4", 6);
    let db = augment(&db, 600, 1);
    let o = run(&db, &FeedbackConfig::default()).unwrap();
    eprintln!(
        "Fig. 4 on {} generated segments:\n{}",
        o.segments,
        o.table()
    );
    assert_spread_narrows(&o);
    #[cfg(feature = "render")]
    draw("generated", &o, &scratch("fig4-plot"));
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn fig4_on_the_shared_dance_clips() {
    let Some(dir) = common::data_path("dance") else {
        return;
    };
    let t = std::time::Instant::now();
    let db = Database::build(
        &Manifest::from_folder(&dir).unwrap(),
        &BuildParams::default(),
        OnRefusal::Fail,
        |_, _| {},
    )
    .unwrap();
    let built = t.elapsed().as_secs_f64();
    let real = db.segments.len();
    let t = std::time::Instant::now();
    let aug = augment_with_variants(&db, 2000, 1);
    eprintln!(
        "{real} real segments (built in {built:.1} s) augmented to {} in {:.1} s",
        aug.database.segments.len(),
        t.elapsed().as_secs_f64()
    );
    // The originals' Eros features recomputed on the reference body against those the build
    // stored (the clips' own bodies), and their intensities (kept exactly).
    let a = &aug.database;
    let worst = (0..real)
        .map(|k| eros(&db.segments[k].eros, &a.segments[k].eros, &a.eros_weights))
        .fold(1.0, f64::min);
    eprintln!("lowest Eros between an original's stored and recomputed features: {worst:.4}");
    for k in 0..real {
        let (x, y) = (a.segments[k].intensity, db.segments[k].intensity);
        assert!((x - y).abs() <= 1e-9 * y, "{x} vs {y}");
    }
    let db = aug.database;
    let o = run(&db, &FeedbackConfig::default()).unwrap();
    eprintln!("Fig. 4 on the shared dance clips:\n{}", o.table());
    assert_spread_narrows(&o);
    #[cfg(feature = "render")]
    draw("shared_clips", &o, &scratch("fig4-real"));
}

#[test]
fn an_edit_on_a_synthesized_song_prefers_intense_segments_for_loud_bars() {
    use marionette::choreo::music::{MusicParams, analyze};
    use marionette::choreo::music::{SynthSong, synthesize};
    let (db, _) = generated_database("edit", 6);
    let db = Arc::new(augment(&db, 200, 3));
    let song = synthesize(&SynthSong {
        bpm: 120.0,
        bars: 12,
        ..SynthSong::default()
    })
    .unwrap();
    let music = analyze(&song.samples, song.sample_rate, &MusicParams::default()).unwrap();
    let bars = music.bars.clone();
    assert!(bars.len() >= 8);
    let mut edit = Edit::new(
        db.clone(),
        bars.clone(),
        SearchParams::default(),
        FillParams::default(),
    )
    .unwrap();
    let q = edit.music_intensity().to_vec();
    let loud = (0..q.len()).max_by(|&a, &b| q[a].total_cmp(&q[b])).unwrap();
    let quiet = (0..q.len()).min_by(|&a, &b| q[a].total_cmp(&q[b])).unwrap();
    assert!(bars[loud].rms_db > bars[quiet].rms_db);
    let mean_w =
        |c: &[usize]| c.iter().map(|&s| db.segments[s].intensity).sum::<f64>() / c.len() as f64;
    let (l, s) = (edit.search(loud).unwrap(), edit.search(quiet).unwrap());
    eprintln!(
        "loudest bar {loud} ({:.1} dB): candidates' mean intensity {:.3} m/s; quietest bar \
         {quiet} ({:.1} dB): {:.3} m/s",
        bars[loud].rms_db,
        mean_w(&l),
        bars[quiet].rms_db,
        mean_w(&s)
    );
    assert!(db.segments[l[0]].intensity > db.segments[s[0]].intensity);
    assert!(mean_w(&l) > mean_w(&s));
    // The full loop of the editor: like two, search again, set, undo, redo; saved and restored.
    edit.like(loud, l[0], true).unwrap();
    edit.like(loud, l[1], true).unwrap();
    let again = edit.search(loud).unwrap();
    assert_eq!(again.len(), 6);
    assert!(again.iter().all(|c| !l.contains(c)));
    edit.set(loud, again[0]).unwrap();
    edit.undo().unwrap();
    assert!(edit.pins().is_empty());
    edit.redo().unwrap();
    assert_eq!(edit.pins().get(&loud), Some(&again[0]));
    // Generate: every other bar filled, the pin kept; the pins of the state, exactly.
    edit.set(0, l[2]).unwrap();
    let fill = edit.generate().unwrap();
    assert_eq!(fill.segments.len(), bars.len());
    assert_eq!(fill.segments[loud], again[0]);
    assert_eq!(fill.segments[0], l[2]);
    assert_eq!(fill.connections.len(), bars.len() - 1);
    assert!(
        fill.segments.windows(2).all(|w| w[0] != w[1]),
        "adjacent repeat"
    );
    assert_eq!(
        edit.generate().unwrap(),
        fill,
        "the same pins, the same dance"
    );
    let saved = serde_json::to_string(edit.state()).unwrap();
    let back = Edit::from_state(db, serde_json::from_str(&saved).unwrap()).unwrap();
    assert_eq!(back.state(), edit.state());
}

/// The likes' effect on round 2 (the second re-search, after likes in rounds 0 and 1) of the
/// Fig. 4 trials on `db` at τ_0 = `tau0` (decay 0.95): the outcome, printed.
fn likes_effect(db: &Database, tau0: f64) -> FeedbackOutcome {
    let cfg = FeedbackConfig {
        rounds: 3,
        search: SearchParams {
            tau0,
            ..SearchParams::default()
        },
        ..FeedbackConfig::default()
    };
    let o = run(db, &cfg).unwrap();
    let r = &o.rounds[2];
    let (gain, se) = r.liked_gain().unwrap();
    eprintln!(
        "tau0 {tau0}, decay {}: round 2 at tau {:.4}: mean Eros Sim of the six to the liked set \
         {:.4} with likes, {:.4} with the likes withheld: gain {gain:+.4} (se {se:.4}, {:.1} se); \
         candidates changed in {:.1} % of {} trials",
        cfg.search.tau_decay,
        r.tau,
        r.liked_similarity.unwrap(),
        r.liked_similarity_withheld.unwrap(),
        gain / se,
        100.0 * r.changed,
        cfg.trials
    );
    o
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn likes_pull_the_second_re_search_toward_them_on_the_shared_clips() {
    let Some(dir) = common::data_path("dance") else {
        return;
    };
    let db = Database::build(
        &Manifest::from_folder(&dir).unwrap(),
        &BuildParams::default(),
        OnRefusal::Fail,
        |_, _| {},
    )
    .unwrap();
    eprintln!(
        "{} segments built from the {} shared dance clips (not augmented)",
        db.segments.len(),
        db.sources.len()
    );
    let paper = likes_effect(&db, 1.0);
    for tau0 in [0.75, 0.25] {
        likes_effect(&db, tau0);
    }
    let follow = likes_effect(&db, FOLLOW_TAU0);
    eprintln!("at the stated tau0 {FOLLOW_TAU0}:\n{}", follow.table());
    // At the stated τ_0 the pull of the likes is measurable: more than three standard errors
    // of the paired difference, and larger than at the paper's τ_0.
    let (gain, se) = follow.rounds[2].liked_gain().unwrap();
    assert!(gain > 3.0 * se && gain > 0.0, "{}", follow.table());
    assert!(gain > paper.rounds[2].liked_gain().unwrap().0);
    assert!(follow.rounds[2].changed > 0.5, "{}", follow.table());
}

#[test]
fn likes_change_the_second_re_search_on_generated_clips() {
    let (db, _) = generated_database("likes", 6);
    let db = Arc::new(db);
    let bars: Vec<marionette::choreo::music::Bar> = (0..8)
        .map(|k| {
            let rms_db = -30.0 + 2.5 * k as f64;
            marionette::choreo::music::Bar {
                start_s: 2.0 * k as f64,
                end_s: 2.0 * (k + 1) as f64,
                rms: 10f64.powf(rms_db / 20.0),
                rms_db,
            }
        })
        .collect();
    let edit = |tau0: f64| {
        let search = SearchParams {
            tau0,
            ..SearchParams::default()
        };
        Edit::new(db.clone(), bars.clone(), search, FillParams::default()).unwrap()
    };
    // Per bar: round 0, like its first and fourth, round 1, like its first and fourth, round 2
    // (the user's likes); and the same three rounds with no like.
    let rounds = |e: &mut Edit, bar: usize, likes: bool| -> Vec<Vec<usize>> {
        (0..3)
            .map(|k| {
                let c = e.search(bar).unwrap();
                if likes && k < 2 {
                    e.like(bar, c[0], true).unwrap();
                    e.like(bar, c[3], true).unwrap();
                }
                c
            })
            .collect()
    };
    let same = |a: &[usize], b: &[usize]| a.iter().filter(|m| b.contains(m)).count();
    let (mut changed, mut kept, mut kept_paper) = (0, 0, 0);
    for bar in 0..bars.len() {
        let (mut with, mut without) = (edit(FOLLOW_TAU0), edit(FOLLOW_TAU0));
        let (a, b) = (
            rounds(&mut with, bar, true),
            rounds(&mut without, bar, false),
        );
        assert_eq!(a[0], b[0], "round 0 is the same: no like yet");
        assert_eq!(with.bar_search(bar).unwrap().liked.len(), 4);
        changed += usize::from(a[2] != b[2]);
        kept += same(&a[2], &b[2]);
        // At the paper's τ_0 = 1 the same likes weigh 5 % of Φ in round 1: for the record.
        let (mut paper, mut paper_without) = (edit(1.0), edit(1.0));
        let (p, q) = (
            rounds(&mut paper, bar, true),
            rounds(&mut paper_without, bar, false),
        );
        kept_paper += same(&p[2], &q[2]);
        eprintln!(
            "bar {bar}: round 2 at tau0 {FOLLOW_TAU0} with likes {:?}, without {:?}; at tau0 1 \
             with likes {:?}, without {:?}",
            a[2], b[2], p[2], q[2]
        );
    }
    eprintln!(
        "round 2 candidates also shown without the likes: {kept} of {} at tau0 {FOLLOW_TAU0}, \
         {kept_paper} at tau0 1",
        6 * bars.len()
    );
    assert_eq!(
        changed,
        bars.len(),
        "the likes changed round 2 of every bar"
    );
    // Not a reordering only: most of round 2 is other segments, far more than at τ_0 = 1.
    assert!(2 * kept <= 6 * bars.len(), "{kept} kept");
    assert!(kept < kept_paper, "{kept} vs {kept_paper}");
}
