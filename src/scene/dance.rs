//! The `Dance` scene (SPEC §2, the dance-editing paper): a song, a segment database and pins
//! (bar → segment); the unpinned bars are filled by the minimum-cost path ([`fill::fill`]), the
//! segments assembled at the song's bar timing ([`dance::assemble`]) and the dance measured
//! ([`metrics::dance_metrics`]).
//!
//! Outputs: `motion.bvh` (the dance on humanoid24; frame 0 is the song's t = 0, the first frame
//! held until the first bar), `song.wav` beside it when the song is synthesized, `filmstrip.png`
//! (one tile per bar at its middle, bar numbers above, pinned bars marked), `motion.gif`,
//! `intensity.png` (music against motion intensity per bar, both as the search normalises them:
//! percentile ranks, [`relevance`]) and `report.json`.

use std::collections::BTreeMap;
use std::path::Path;

use serde::{Deserialize, Serialize};
use serde_json::json;

use super::source::resolve_path;
use super::{SceneError, write_output};
use crate::choreo::authored::{AuthoredDance, generate};
use crate::choreo::dance::{self, DanceParams};
use crate::choreo::database::{BuildParams, ClipOutcome, Database, Manifest, OnRefusal};
use crate::choreo::feet::{PlantParams, Planting, plant_feet};
use crate::choreo::fill::{self, FillParams, Pins};
use crate::choreo::metrics;
use crate::choreo::music::synth::{SynthSong, synthesize};
use crate::choreo::music::{Bar, MusicAnalysis, MusicParams, analyze};
use crate::choreo::relevance;
use crate::choreo::search::SearchParams;
use crate::choreo::segments::{Beat, TempoSource};
use crate::render::{Figure, Plot, Series, Track, View, animation_gif, filmstrip_at_png, plot};

/// Where the song comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SongSource {
    /// A drum track synthesized at a known tempo with a loudness per bar.
    Synth(SynthSong),
    /// A song file (WAV, OGG/Vorbis, MP3), relative to the scene, `${MARIONETTE_DATA}` allowed.
    File(String),
}

/// Where the segment database comes from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum DatabaseSource {
    /// The project's own dance ([`crate::choreo::authored`]), built in memory; each clip's tempo
    /// and first beat are the generator's (known, not estimated).
    Authored(AuthoredDance),
    /// Every clip of a folder, or a manifest's clips (path relative to the scene).
    Clips(String),
    /// A database file written by `marionette dance db`.
    File(String),
}

/// A pin: a bar of the song and the segment it takes, by index in the database or by the clip
/// (file name without extension) and the bar within it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Pin {
    /// The song's bar (0-based).
    pub bar: usize,
    /// The segment's index in the database.
    #[serde(default)]
    pub segment: Option<usize>,
    /// The clip the segment is cut from (its file name without extension).
    #[serde(default)]
    pub clip: Option<String>,
    /// The bar within that clip (0-based).
    #[serde(default)]
    pub clip_bar: Option<usize>,
}

/// What the scene draws.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DanceRender {
    /// Write the animated GIF.
    pub gif: bool,
    /// Its frame rate.
    pub gif_fps: f64,
}

impl Default for DanceRender {
    fn default() -> Self {
        DanceRender {
            gif: true,
            gif_fps: 15.0,
        }
    }
}

/// A dance to a song: pins given, the rest filled.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DanceScene {
    /// Scene format version.
    pub format_version: u32,
    /// Scene name.
    pub name: String,
    /// The song.
    pub song: SongSource,
    /// Music analysis parameters.
    #[serde(default)]
    pub music: MusicParams,
    /// Bars to dance, from the song's first bar (all the song's bars when absent).
    #[serde(default)]
    pub bars: Option<usize>,
    /// The segment database.
    pub database: DatabaseSource,
    /// How a database is built from clips (not used for a database file).
    #[serde(default)]
    pub build: BuildParams,
    /// The pins.
    #[serde(default)]
    pub pins: Vec<Pin>,
    /// How the other bars are filled.
    #[serde(default)]
    pub fill: FillParams,
    /// How the dance is assembled.
    #[serde(default)]
    pub dance: DanceParams,
    /// How the assembled dance's feet are put on the floor ([`crate::choreo::feet`]).
    #[serde(default)]
    pub feet: PlantParams,
    /// The relevance-feedback search of eqs. (1)–(4) that `marionette edit` runs on this scene
    /// (`marionette run` does not search: it fills the unpinned bars).
    #[serde(default)]
    pub search: SearchParams,
    /// Pictures.
    #[serde(default)]
    pub render: DanceRender,
}

/// Checks what can be checked before any work: each pin names its segment one way (an index,
/// or a clip and its bar), no bar is pinned twice, and the picture settings are in range.
pub fn validate_dance(s: &DanceScene) -> Result<(), SceneError> {
    let mut seen = BTreeMap::new();
    for (k, p) in s.pins.iter().enumerate() {
        let by_index = p.segment.is_some();
        let by_clip = p.clip.is_some() || p.clip_bar.is_some();
        if by_index == by_clip || (by_clip && (p.clip.is_none() || p.clip_bar.is_none())) {
            return Err(SceneError::Invalid(format!(
                "pins[{k}] (bar {}): give either segment: N, or clip: \"name\" with clip_bar: N",
                p.bar
            )));
        }
        if let Some(j) = seen.insert(p.bar, k) {
            return Err(SceneError::Invalid(format!(
                "pins[{k}]: bar {} is pinned already by pins[{j}]",
                p.bar
            )));
        }
    }
    if s.bars == Some(0) {
        return Err(SceneError::Invalid(
            "bars is 0: expected at least one bar to dance (or leave it out for the whole song)"
                .into(),
        ));
    }
    let fps = s.render.gif_fps;
    if s.render.gif && !(fps.is_finite() && fps > 0.0 && fps <= crate::render::MAX_GIF_FPS) {
        return Err(SceneError::Invalid(format!(
            "render.gif_fps is {fps}, expected more than 0 and at most {}",
            crate::render::MAX_GIF_FPS
        )));
    }
    Ok(())
}

/// The song: mono samples, rate, and the synthesized track's ground truth when there is one.
struct Song {
    samples: Vec<f32>,
    sample_rate: u32,
    known_bpm: Option<f64>,
    origin: String,
}

/// What a [`DanceScene`] stands on, loaded once by [`load_dance`] for `marionette run` and
/// `marionette edit` alike: the song and its analysis, the bars danced, the database and the
/// pins as bar → segment.
pub struct DanceInputs {
    /// Mono samples of the song (full scale ±1).
    pub samples: Vec<f32>,
    /// Their sample rate (Hz).
    pub sample_rate: u32,
    /// The synthesized song's tempo (BPM), `None` for a song file.
    pub known_bpm: Option<f64>,
    /// Where the song comes from, for reports.
    pub song_origin: String,
    /// The song's analysis (tempo, beats, every bar).
    pub analysis: MusicAnalysis,
    /// The bars danced: the song's first [`DanceScene::bars`] bars (all when absent).
    pub bars: Vec<Bar>,
    /// The segment database.
    pub db: Database,
    /// For the project's own dance, each clip's moves per bar (empty otherwise).
    pub moves: Vec<Vec<String>>,
    /// Where the database comes from, for reports.
    pub db_origin: String,
    /// The pins as bar → segment index, checked against the database.
    pub pins: Pins,
}

/// Loads what `scene` names (song, analysis, bars, database, pins), paths relative to `base`.
pub fn load_dance(scene: &DanceScene, base: &Path) -> Result<DanceInputs, SceneError> {
    let song = load_song(&scene.song, base)?;
    let analysis = analyze(&song.samples, song.sample_rate, &scene.music)?;
    analysis.require_bars(1)?;
    let bars_n = match scene.bars {
        Some(n) => {
            analysis.require_bars(n)?;
            n
        }
        None => analysis.bars.len(),
    };
    let bars = analysis.bars[..bars_n].to_vec();
    let (db, moves, db_origin) = load_database(scene, base, analysis.tempo_bpm)?;
    let pins = resolve_pins(&scene.pins, &db)?;
    Ok(DanceInputs {
        samples: song.samples,
        sample_rate: song.sample_rate,
        known_bpm: song.known_bpm,
        song_origin: song.origin,
        analysis,
        bars,
        db,
        moves,
        db_origin,
        pins,
    })
}

fn load_song(src: &SongSource, base: &Path) -> Result<Song, SceneError> {
    match src {
        SongSource::Synth(s) => {
            let t = synthesize(s)?;
            Ok(Song {
                samples: t.samples,
                sample_rate: t.sample_rate,
                known_bpm: Some(s.bpm),
                origin: format!("synthesized at {} BPM", s.bpm),
            })
        }
        SongSource::File(f) => {
            let path = resolve_path(f, base);
            #[cfg(feature = "audio")]
            {
                let a = crate::choreo::music::decode::decode_file(&path)?;
                if let Some(w) = &a.warning {
                    eprintln!("warning: {}: {w}", path.display());
                }
                Ok(Song {
                    samples: a.samples,
                    sample_rate: a.sample_rate,
                    known_bpm: None,
                    origin: path.display().to_string(),
                })
            }
            #[cfg(not(feature = "audio"))]
            Err(SceneError::Invalid(format!(
                "{}: decoding songs needs the `audio` feature",
                path.display()
            )))
        }
    }
}

/// The database and, for the project's own dance, each clip's moves; clips are built for the
/// song's tempo `music_bpm` (their kinematic tempo takes the octave level nearest it) unless
/// the scene's build parameters give one.
fn load_database(
    s: &DanceScene,
    base: &Path,
    music_bpm: f64,
) -> Result<(Database, Vec<Vec<String>>, String), SceneError> {
    match &s.database {
        DatabaseSource::Authored(a) => {
            let clips = generate(a)?;
            let beat = Beat {
                tempo_bpm: a.bpm,
                first_beat_s: 0.0,
                source: TempoSource::Manifest,
            };
            let named: Vec<_> = clips
                .iter()
                .map(|c| (c.name.clone(), c.motion.clone(), Some(beat)))
                .collect();
            let db = Database::from_clips(&named, &s.build)?;
            let moves = clips.iter().map(|c| c.moves.clone()).collect();
            Ok((
                db,
                moves,
                format!(
                    "the project's own dance: {} clips of {} bars at {} BPM, built in memory",
                    a.clips, a.bars_per_clip, a.bpm
                ),
            ))
        }
        DatabaseSource::Clips(p) => {
            let path = resolve_path(p, base);
            let manifest = Manifest::from_path(&path)?;
            let params = BuildParams {
                music_bpm: s.build.music_bpm.or(Some(music_bpm)),
                ..s.build.clone()
            };
            let db = Database::build(&manifest, &params, OnRefusal::Skip, |_, outcome| {
                if let ClipOutcome::Skipped(k) = outcome {
                    eprintln!("warning: skipped {}", k.reason);
                }
            })?;
            Ok((db, vec![], path.display().to_string()))
        }
        DatabaseSource::File(p) => {
            let path = resolve_path(p, base);
            Ok((Database::load(&path)?, vec![], path.display().to_string()))
        }
    }
}

/// A source clip's name: its file name without extension.
fn clip_name(file: &str) -> String {
    Path::new(file)
        .file_stem()
        .map_or_else(|| file.to_string(), |s| s.to_string_lossy().to_string())
}

/// The pins as scene entries: by clip and bar within it when the clip's name is unique in the
/// database and names this segment (stable however the database is rebuilt), else by segment
/// index.
pub fn scene_pins(pins: &Pins, db: &Database) -> Vec<Pin> {
    let names: Vec<String> = db.sources.iter().map(|s| clip_name(&s.file)).collect();
    pins.iter()
        .map(|(&bar, &seg)| {
            let s = &db.segments[seg];
            let name = &names[s.clip];
            let first = db
                .segments
                .iter()
                .position(|x| x.clip == s.clip && x.bar == s.bar);
            if names.iter().filter(|n| *n == name).count() == 1 && first == Some(seg) {
                Pin {
                    bar,
                    segment: None,
                    clip: Some(name.clone()),
                    clip_bar: Some(s.bar),
                }
            } else {
                Pin {
                    bar,
                    segment: Some(seg),
                    clip: None,
                    clip_bar: None,
                }
            }
        })
        .collect()
}

/// The dance as `motion.bvh` text at the song's timing: frame 0 is the song's t = 0, the
/// dance's first frame held until the first bar; also the number of frames held.
pub fn song_timed_bvh(d: &dance::Dance) -> (String, usize) {
    let lead = (d.start_s / d.clip.frame_time).round() as usize;
    let mut synced = d.clip.clone();
    let dofs = synced.dof_count();
    for _ in 0..lead {
        synced
            .root_translation
            .insert(0, d.clip.root_translation[0]);
        synced.root_rotation.insert(0, d.clip.root_rotation[0]);
        let first: Vec<f64> = d.clip.frame_angles(0).to_vec();
        synced.angles.splice(0..0, first);
    }
    debug_assert_eq!(synced.angles.len(), synced.frame_count() * dofs);
    (crate::bvh::to_string(&synced.to_clip().to_bvh()), lead)
}

/// The pins as bar → segment index.
fn resolve_pins(pins: &[Pin], db: &Database) -> Result<Pins, SceneError> {
    let mut out = Pins::new();
    for (k, p) in pins.iter().enumerate() {
        let seg = match (p.segment, &p.clip, p.clip_bar) {
            (Some(i), _, _) => i,
            (None, Some(clip), Some(bar)) => {
                let names: Vec<String> = db.sources.iter().map(|s| clip_name(&s.file)).collect();
                let c = names.iter().position(|n| n == clip).ok_or_else(|| {
                    SceneError::Invalid(format!(
                        "pins[{k}] (bar {}): no clip '{clip}' in the database; its clips: {}",
                        p.bar,
                        names.join(", ")
                    ))
                })?;
                db.segments
                    .iter()
                    .position(|s| s.clip == c && s.bar == bar)
                    .ok_or_else(|| {
                        SceneError::Invalid(format!(
                            "pins[{k}] (bar {}): clip '{clip}' has {} bars (0 to {}), not bar {bar}",
                            p.bar,
                            db.sources[c].segments,
                            db.sources[c].segments.saturating_sub(1)
                        ))
                    })?
            }
            _ => unreachable!("validate_dance checks each pin names its segment"),
        };
        out.insert(p.bar, seg);
    }
    Ok(out)
}

/// The dance of `segments` (one per bar of `bars`, the song's beats at `beats_s`) as `scene`
/// makes it, for `marionette run` and the editor alike: assembled at the bars' timing, each
/// bar's beats warped onto the song's ([`dance::assemble`]), then its feet put on the floor
/// ([`plant_feet`]).
pub fn perform(
    scene: &DanceScene,
    db: &Database,
    segments: &[usize],
    bars: &[Bar],
    beats_s: &[f64],
) -> Result<(dance::Dance, Planting), SceneError> {
    let mut d = dance::assemble(db, segments, bars, beats_s, &scene.dance)?;
    let planting = plant_feet(&mut d.clip, &scene.feet);
    Ok((d, planting))
}

/// What an animator looks at in a dance (the report's and the editor's figures): its metrics
/// ([`metrics::dance_metrics`]: beat alignment, seam jerk, skating, foot penetration), its
/// danced segments' own skating and beat alignment ([`metrics::source_metrics`]), and the
/// Spearman correlation of the bars' music and motion intensity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct DanceFigures {
    /// The dance's metrics.
    pub metrics: metrics::DanceMetrics,
    /// The danced segments, each alone at its own timing.
    pub sources: metrics::SourceMetrics,
    /// Spearman's ρ of music and motion intensity over the bars.
    pub intensity_spearman: f64,
    /// Every bar's music intensity as a percentile rank among the bars.
    #[serde(skip)]
    pub music_rank: Vec<f64>,
    /// Every bar's segment's motion intensity as a percentile rank in the database.
    #[serde(skip)]
    pub motion_rank: Vec<f64>,
}

/// The [`DanceFigures`] of dance `d` filled as `filled` to `bars` (song beats `beats_s`).
pub fn figures(
    d: &dance::Dance,
    db: &Database,
    filled: &fill::Fill,
    bars: &[Bar],
    beats_s: &[f64],
) -> DanceFigures {
    let music_rank = relevance::music_intensity(bars);
    let motion_rank_db = relevance::motion_intensity(db);
    let motion_rank: Vec<f64> = filled.segments.iter().map(|&s| motion_rank_db[s]).collect();
    DanceFigures {
        metrics: metrics::dance_metrics(d, beats_s, filled),
        sources: metrics::source_metrics(db, &filled.segments, 1.0 / d.clip.frame_time),
        intensity_spearman: metrics::spearman(&music_rank, &motion_rank),
        music_rank,
        motion_rank,
    }
}

/// Runs a [`DanceScene`] (module docs). Returns the report.
pub fn run_dance(
    scene: &DanceScene,
    base: &Path,
    out: &Path,
) -> Result<serde_json::Value, SceneError> {
    let DanceInputs {
        samples,
        sample_rate,
        known_bpm,
        song_origin,
        analysis,
        bars,
        db,
        moves,
        db_origin,
        pins,
    } = load_dance(scene, base)?;
    let bars = &bars[..];
    let bars_n = bars.len();
    let filled = fill::fill(&db, &relevance::music_intensity(bars), &pins, &scene.fill)?;
    let (d, planting) = perform(scene, &db, &filled.segments, bars, &analysis.beats_s)?;
    let DanceFigures {
        metrics: m,
        sources,
        intensity_spearman,
        music_rank,
        motion_rank,
    } = figures(&d, &db, &filled, bars, &analysis.beats_s);

    // motion.bvh at the song's timing: the first frame held from t = 0 to the first bar.
    let (bvh, lead) = song_timed_bvh(&d);
    write_output(&out.join("motion.bvh"), bvh.as_bytes())?;
    if matches!(scene.song, SongSource::Synth(_)) {
        let wav = crate::choreo::music::wav::wav_bytes(&samples, 1, sample_rate)
            .ok_or_else(|| SceneError::Invalid("the song is too long for a WAV file".into()))?;
        write_output(&out.join("song.wav"), &wav)?;
    }

    // Pictures of the dance itself (frame 0 at the first bar).
    let dclip = d.clip.to_clip();
    let frames = dclip.point_frames();
    let figure = Figure::of(&dclip.skeleton);
    let track = Track {
        figure: &figure,
        frames: &frames,
        label: format!("{}: {} bars on humanoid24", scene.name, bars_n),
        frame_time: dclip.frame_time,
    };
    let mid: Vec<f64> = d
        .bar_frames
        .iter()
        .map(|&(a, b)| 0.5 * (a + b) as f64 * dclip.frame_time)
        .collect();
    let labels: Vec<String> = (0..bars_n)
        .map(|b| {
            if pins.contains_key(&b) {
                format!("bar {b} (pinned)")
            } else {
                format!("bar {b}")
            }
        })
        .collect();
    filmstrip_at_png(
        std::slice::from_ref(&track),
        &mid,
        &labels,
        View::Front,
        &out.join("filmstrip.png"),
    )?;
    if scene.render.gif {
        animation_gif(
            std::slice::from_ref(&track),
            scene.render.gif_fps,
            &out.join("motion.gif"),
        )?;
    }
    plot(
        &Plot {
            title: format!("{}: music and motion intensity per bar", scene.name),
            x_label: "bar".into(),
            y_label: "percentile rank (RMS in song, W in database)".into(),
            series: vec![
                Series {
                    name: "music (bar RMS)".into(),
                    points: music_rank
                        .iter()
                        .enumerate()
                        .map(|(b, v)| (b as f64, *v))
                        .collect(),
                },
                Series {
                    name: "motion (chosen segment's W)".into(),
                    points: motion_rank
                        .iter()
                        .enumerate()
                        .map(|(b, v)| (b as f64, *v))
                        .collect(),
                },
            ],
            markers: pins
                .keys()
                .map(|&b| (b as f64, "pin".to_string()))
                .collect(),
        },
        &out.join("intensity.png"),
    )?;

    let per_bar: Vec<serde_json::Value> = (0..bars_n)
        .map(|b| {
            let seg = filled.segments[b];
            let s = &db.segments[seg];
            let mut v = json!({
                "bar": b,
                "start_s": bars[b].start_s,
                "end_s": bars[b].end_s,
                "segment": seg,
                "clip": clip_name(&db.sources[s.clip].file),
                "clip_bar": s.bar,
                "pinned": pins.contains_key(&b),
                "music_rms_db": bars[b].rms_db,
                "music_intensity_rank": music_rank[b],
                "motion_intensity_m_s": s.intensity,
                "motion_intensity_rank": motion_rank[b],
            });
            if let Some(mv) = moves.get(s.clip).and_then(|m| m.get(s.bar)) {
                v["move"] = json!(mv);
            }
            v
        })
        .collect();
    let seams: Vec<serde_json::Value> = filled
        .connections
        .iter()
        .enumerate()
        .map(|(k, c)| {
            json!({
                "from_bar": k, "to_bar": k + 1, "time_s": bars[k + 1].start_s,
                "s_pose": c.s_pose, "s_move": c.s_move, "s": c.s, "cost": c.cost,
            })
        })
        .collect();
    let dance_s = d.clip.frame_count() as f64 * d.clip.frame_time;
    let bars_s = bars[bars_n - 1].end_s - bars[0].start_s;
    Ok(json!({
        "song": song_origin,
        "song_known_tempo_bpm": known_bpm,
        "tempo_bpm": analysis.tempo_bpm,
        "song_duration_s": analysis.duration_s,
        "song_bars": analysis.bars.len(),
        "bars": bars_n,
        "database": db_origin,
        "database_segments": db.segments.len(),
        "database_sources": db.sources.iter().map(|s| json!({
            "clip": clip_name(&s.file), "segments": s.segments,
            "tempo_bpm": s.beat.tempo_bpm, "first_beat_s": s.beat.first_beat_s,
            "tempo_from": format!("{:?}", s.beat.source),
        })).collect::<Vec<_>>(),
        "database_skipped": db.skipped.iter().map(|s| json!({
            "clip": clip_name(&s.file), "reason": s.reason,
        })).collect::<Vec<_>>(),
        "pins": pins.iter().map(|(b, s)| json!({"bar": b, "segment": s})).collect::<Vec<_>>(),
        "no_adjacent_repeat": scene.fill.no_adjacent_repeat,
        "fill_intensity_weight": scene.fill.intensity_weight,
        "feet": {
            "planted": scene.feet.enabled,
            "locked": scene.feet.lock,
            "contact_spans": planting.spans,
            "contact_spans_locked": planting.locked,
            "leg_frames_moved": planting.leg_frames,
            "max_correction_m": planting.max_correction_m,
            "max_residual_m": planting.max_residual_m,
        },
        "per_bar": per_bar,
        "seams": seams,
        "metrics": {
            "beat_alignment_score": m.beat_alignment_score,
            "motion_beats": m.motion_beats,
            "music_beats": m.music_beats,
            "seam_jerk_peak_rad_s3": m.seam_jerk.peak_rad_s3,
            "seam_jerk_mean_rad_s3": m.seam_jerk.mean_rad_s3,
            "inside_jerk_peak_rad_s3": m.inside_jerk.peak_rad_s3,
            "inside_jerk_mean_rad_s3": m.inside_jerk.mean_rad_s3,
            "foot_skating_m_s": m.foot_skating_m_s,
            "foot_contact_fraction": m.foot_contact_fraction,
            "foot_penetration": {
                "deepest_m": m.foot_penetration.deepest_m,
                "frames_below_1cm_fraction": m.foot_penetration.frames_below_fraction,
                "contact_sole_max_m": m.foot_penetration.contact_sole_max_m,
            },
            "intensity_spearman": intensity_spearman,
            "intensity_mismatch": filled.intensity_mismatch,
            "sources": {
                "what": "the segments danced, each alone at its own timing in its clip, at the \
                    dance's frame rate, against its own counts",
                "segments": sources.segments,
                "foot_skating_m_s": sources.foot_skating_m_s,
                "beat_alignment_score": sources.beat_alignment_score,
            },
            "transition_cost": m.transition_cost,
            "mean_connection_s": m.mean_connection_s,
        },
        "dance_start_s": d.start_s,
        "duration_s": dance_s,
        "bars_duration_s": bars_s,
        "fps": 1.0 / d.clip.frame_time,
        "frames": d.clip.frame_count(),
        "motion_bvh": format!(
            "humanoid24, {} frames; frame 0 is the song's t = 0 (the dance's first frame held \
             for {lead} frames until the first bar at {:.3} s)",
            d.clip.frame_count() + lead,
            d.start_s
        ),
        "intensity_normalisation": "percentile rank: a bar's RMS (dB) among the song's bars \
            danced; a segment's mean W(f) among the database's segments",
        "source_skeleton": "not written: the mapping retargets onto humanoid24 only (no inverse \
            retarget onto a source skeleton exists)",
    }))
}
