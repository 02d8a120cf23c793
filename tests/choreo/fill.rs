//! Connection-aware fill (the dance-editing paper §3.2, Fig. 5): on a database generated in code
//! and on the shared dance clips, over many random pin sets, the minimum-cost fill has lower
//! seam jerk and a higher connection score S than connection-blind fills (random, intensity
//! only); the fill honours every pin and assembles into a dance that lasts exactly its bars
//! with the pinned frames unchanged outside the seams.

use crate::common;

use marionette::choreo::dance_metrics;
use marionette::choreo::generated_database;
use marionette::choreo::music::Bar;
use marionette::choreo::{BuildParams, Database, Manifest, OnRefusal};
use marionette::choreo::{DanceParams, assemble};
use marionette::choreo::{FillParams, Pins, fill, fill_dijkstra};
use marionette::experiments::dance_fill::{DanceFillConfig, DanceFillOutcome, Strategy, run};

/// The claims of Fig. 5 on an outcome.
fn check_fig5(o: &DanceFillOutcome, what: &str) {
    eprintln!("{what}:\n{}", o.table());
    let aware = o.row(Strategy::ConnectionAware);
    for other in [Strategy::Random, Strategy::IntensityOnly] {
        let r = o.row(other);
        assert!(
            aware.seam_jerk_mean.mean < r.seam_jerk_mean.mean,
            "{what}: seam jerk, aware {} vs {other:?} {}",
            aware.seam_jerk_mean.mean,
            r.seam_jerk_mean.mean
        );
        assert!(
            aware.mean_s.mean > r.mean_s.mean,
            "{what}: S, aware {} vs {other:?} {}",
            aware.mean_s.mean,
            r.mean_s.mean
        );
        // The minimum-cost path costs no more than any other fill of the same pins.
        for (a, b) in aware.trials.iter().zip(&r.trials) {
            assert!(a.total_cost <= b.total_cost + 1e-9, "{what}");
        }
    }
    assert!(o.aware_beats_random_jerk > 0.6, "{what}");
    assert!(o.aware_beats_intensity_jerk > 0.6, "{what}");
}

#[test]
fn fig5_on_a_generated_database() {
    let db = generated_database(21, 6, 8).unwrap();
    let cfg = DanceFillConfig {
        pin_sets: 60,
        ..DanceFillConfig::default()
    };
    let o = run(&db, &cfg).unwrap();
    check_fig5(&o, "generated database");
}

/// Bars of `bar_s` seconds from `start_s`.
fn bars(n: usize, bar_s: f64, start_s: f64) -> Vec<Bar> {
    (0..n)
        .map(|k| Bar {
            start_s: start_s + k as f64 * bar_s,
            end_s: start_s + (k + 1) as f64 * bar_s,
            rms: 0.1,
            rms_db: -20.0,
        })
        .collect()
}

#[test]
fn a_fill_keeps_its_pins_and_assembles_into_a_dance_as_long_as_its_bars() {
    let db = generated_database(4, 5, 6).unwrap();
    let n = db.segments.len();
    let p = FillParams::default();
    let pins = Pins::from([(2, 7), (3, 8), (9, n - 1), (13, 0)]);
    let music: Vec<f64> = (0..16).map(|k| (k % 4) as f64 / 3.0).collect();
    let f = fill(&db, &music, &pins, &p).unwrap();
    assert_eq!(f, fill_dijkstra(&db, &music, &pins, &p).unwrap());
    assert_eq!(f.segments.len(), 16);
    assert_eq!(f.connections.len(), 15);
    for (&bar, &s) in &pins {
        assert_eq!(f.segments[bar], s);
    }
    for w in f.segments.windows(2) {
        assert_ne!(w[0], w[1], "no adjacent repeat");
    }
    // A song's bars of 1.93 s from 0.71 s, 30 fps: 16 bars last 30.88 s, 926 frames.
    let b = bars(16, 1.93, 0.71);
    let beats: Vec<f64> = (0..64).map(|k| 0.71 + k as f64 * 1.93 / 4.0).collect();
    let d = assemble(&db, &f.segments, &b, &beats, &DanceParams::default()).unwrap();
    let duration = d.clip.frame_count() as f64 * d.clip.frame_time;
    assert!((duration - 16.0 * 1.93).abs() < 1e-9, "{duration}");
    assert_eq!(d.clip.frame_count(), 926);
    assert_eq!(d.bar_frames.last().unwrap().1, 926);
    let m = dance_metrics(&d, &beats, &f);
    eprintln!("generated dance metrics: {m:?}");
    assert!((m.transition_cost - f.total_cost).abs() < 1e-12);
    assert_eq!(m.music_beats, 64);
    assert!(m.motion_beats > 0);
    assert!((0.0..=1.0).contains(&m.beat_alignment_score));
    assert!(m.seam_jerk.samples > 0 && m.inside_jerk.samples > 0);
    assert!(m.foot_skating_m_s.is_finite());
}

#[test]
fn pins_past_the_end_or_to_missing_segments_are_refused() {
    let db = generated_database(4, 2, 4).unwrap();
    let n = db.segments.len();
    let p = FillParams::default();
    let music = [0.5; 8];
    let e = fill(&db, &music, &Pins::from([(8, 0)]), &p).unwrap_err();
    assert_eq!(e.to_string(), "pin on bar 8: the song has 8 bars (0 to 7)");
    let e = fill(&db, &music, &Pins::from([(1, n)]), &p).unwrap_err();
    assert!(
        e.to_string()
            .contains(&format!("segment {n} does not exist")),
        "{e}"
    );
    let empty = Database {
        segments: vec![],
        ..db.clone()
    };
    assert_eq!(
        fill(&empty, &music, &Pins::new(), &p)
            .unwrap_err()
            .to_string(),
        "the dance database has no segments to fill bars with"
    );
}

/// The shared dance clips as a database (kinematic tempo per clip).
fn shared_database() -> Option<Database> {
    let dir = common::data_path("dance")?;
    let m = Manifest::from_folder(&dir).unwrap();
    Some(Database::build(&m, &BuildParams::default(), OnRefusal::Skip, |_, _| {}).unwrap())
}

#[test]
#[cfg_attr(
    not(shared_data),
    ignore = "needs the shared data: set MARIONETTE_DATA (default ../shared/data)"
)]
fn fig5_on_the_shared_dance_database() {
    let Some(db) = shared_database() else {
        return;
    };
    let o = run(&db, &DanceFillConfig::default()).unwrap();
    check_fig5(&o, "shared dance database");
}

/// The music term (issue 34): at κ = 0 the fill is the paper's; at the default κ the filled
/// bars' motion intensity follows the music (Spearman ≥ 0.6 on a song whose loudness rises and
/// falls), the music term's mismatch falls, and the DP still agrees with Dijkstra.
#[test]
fn the_music_term_makes_the_fill_follow_the_music_and_zero_is_the_paper_s_fill() {
    use marionette::choreo::spearman;
    use marionette::choreo::{motion_intensity, percentile_ranks};
    let db = generated_database(21, 6, 8).unwrap();
    let n = db.segments.len();
    let bars = 24;
    // A song louder and quieter in turn, every bar's level distinct.
    let loudness: Vec<f64> = (0..bars)
        .map(|k| (k as f64 * 0.7).sin() + 0.01 * k as f64)
        .collect();
    let music = percentile_ranks(&loudness);
    let pins = Pins::from([(3, 5 % n), (17, 11 % n)]);
    let paper = fill(&db, &music, &pins, &FillParams::paper()).unwrap();
    let zero = FillParams {
        intensity_weight: 0.0,
        ..FillParams::default()
    };
    assert_eq!(paper, fill(&db, &music, &pins, &zero).unwrap());
    // The paper's fill does not look at the music: any music gives the same path.
    let flat = vec![0.5; bars];
    assert_eq!(
        paper.segments,
        fill(&db, &flat, &pins, &FillParams::paper())
            .unwrap()
            .segments
    );
    let p = FillParams::default();
    let follow = fill(&db, &music, &pins, &p).unwrap();
    assert_eq!(follow, fill_dijkstra(&db, &music, &pins, &p).unwrap());
    let motion = motion_intensity(&db);
    let rho = |f: &[usize]| spearman(&music, &f.iter().map(|&s| motion[s]).collect::<Vec<_>>());
    let (r0, r1) = (rho(&paper.segments), rho(&follow.segments));
    eprintln!(
        "Spearman {r0:.3} -> {r1:.3}; mismatch {:.3} -> {:.3}; seam cost {:.4} -> {:.4}",
        paper.intensity_mismatch, follow.intensity_mismatch, paper.total_cost, follow.total_cost
    );
    assert!(r1 >= 0.6 && r1 > r0, "Spearman {r0} -> {r1}");
    assert!(follow.intensity_mismatch < paper.intensity_mismatch);
    // The paper's fill is the cheapest in seam cost; following the music costs some of it.
    assert!(paper.total_cost <= follow.total_cost);
    for (&bar, &s) in &pins {
        assert_eq!(follow.segments[bar], s);
    }
    // Bad music ranks and κ are refused, naming the bar.
    let mut bad = music.clone();
    bad[4] = 1.5;
    let e = fill(&db, &bad, &pins, &p).unwrap_err().to_string();
    assert!(e.contains("bar 4") && e.contains("1.5"), "{e}");
    let neg = FillParams {
        intensity_weight: -1.0,
        ..FillParams::default()
    };
    let e = fill(&db, &music, &pins, &neg).unwrap_err().to_string();
    assert!(e.contains("intensity_weight"), "{e}");
    let tight = FillParams {
        seam_budget: Some(0.9),
        ..FillParams::default()
    };
    let e = fill(&db, &music, &pins, &tight).unwrap_err().to_string();
    assert!(e.contains("seam_budget is 0.9"), "{e}");
}

/// The seam budget: the default fill takes the largest κ of the halving ladder whose Σ C stays
/// within 1.2× the paper's fill's, and the next κ up would break it; without a budget κ is
/// taken as given, and a budget of 1 keeps the paper's seam cost.
#[test]
fn the_seam_budget_takes_the_largest_kappa_whose_seams_stay_within_it() {
    use marionette::choreo::percentile_ranks;
    use marionette::choreo::{BUDGET_HALVINGS, DEFAULT_SEAM_BUDGET};
    let db = generated_database(21, 6, 8).unwrap();
    let bars = 24;
    let loudness: Vec<f64> = (0..bars)
        .map(|k| (k as f64 * 0.7).sin() + 0.01 * k as f64)
        .collect();
    let music = percentile_ranks(&loudness);
    let pins = Pins::from([(3, 5)]);
    let paper = fill(&db, &music, &pins, &FillParams::paper()).unwrap();
    let p = FillParams::default();
    let f = fill(&db, &music, &pins, &p).unwrap();
    assert_eq!(f, fill_dijkstra(&db, &music, &pins, &p).unwrap());
    let kappa = f.intensity_weight;
    eprintln!(
        "κ taken {kappa} of {}; Σ C {:.4} against the paper's {:.4}",
        p.intensity_weight, f.total_cost, paper.total_cost
    );
    assert!(f.total_cost <= DEFAULT_SEAM_BUDGET * paper.total_cost);
    let fixed = |kappa: f64| FillParams {
        intensity_weight: kappa,
        seam_budget: None,
        ..FillParams::default()
    };
    // The κ taken is on the ladder, its fill the fixed-κ fill, and the rung above breaks the
    // budget.
    let rung = (p.intensity_weight / kappa).log2();
    assert!(kappa > 0.0 && rung.fract() == 0.0 && rung <= BUDGET_HALVINGS as f64);
    assert_eq!(f, fill(&db, &music, &pins, &fixed(kappa)).unwrap());
    if kappa < p.intensity_weight {
        let above = fill(&db, &music, &pins, &fixed(2.0 * kappa)).unwrap();
        assert!(above.total_cost > DEFAULT_SEAM_BUDGET * paper.total_cost);
    }
    // A budget of 1: the seams cost what the paper's do.
    let strict = FillParams {
        seam_budget: Some(1.0),
        ..FillParams::default()
    };
    let s = fill(&db, &music, &pins, &strict).unwrap();
    assert!(s.total_cost <= paper.total_cost);
}
