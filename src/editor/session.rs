//! What the editor's server holds: the [`Edit`] (pins, per-bar search, undo/redo), the song
//! (samples, beats, bars), the last fill, and the `Dance` scene file it opened and saves to.
//! The scene is loaded by [`crate::scene::load_dance`], the one path `marionette run` takes
//! too; the edit's transition table is built when the session opens (its first Generate), so
//! every Generate the page asks for is the path search only.
//!
//! Every method answers bad input with an [`EditorError`], never a panic; the server keeps one
//! `Session` behind a `Mutex`.

use std::path::Path;
use std::sync::Arc;

use glam::DVec3;

use super::EditorError;
use super::scene::DanceFile;
use crate::choreo::edit::Edit;
use crate::choreo::fill::Fill;
use crate::experiments::dance::{DanceFigures, figures, perform};
use crate::humanoid::{Figure, FigureClip, humanoid24};
use crate::scene::{load_dance, scene_pins, song_timed_bvh};

/// The song the edit dances to.
#[derive(Debug, Clone)]
pub struct Song {
    /// Mono samples (full scale ±1).
    pub samples: Vec<f32>,
    /// Sample rate (Hz).
    pub sample_rate: u32,
    /// Tempo found by the analysis (BPM).
    pub tempo_bpm: f64,
    /// Every beat time (s).
    pub beats_s: Vec<f64>,
}

/// The highest sample rate the page is sent the song at (Hz): mono 16-bit at 22.05 kHz is
/// 44.1 kB a second, a 2 s bar 88 kB.
pub const AUDIO_RATE: u32 = 22_050;

impl Song {
    /// The song's mono samples from `from_s` to `to_s` (clamped to the song) at
    /// `min(sample_rate, AUDIO_RATE)` Hz, and that rate. A higher rate is reduced by averaging
    /// the input samples around each output sample's time (a box filter one output sample
    /// wide, which also keeps the reduction from folding high frequencies back in). Sample i
    /// of the span is the song at `round(from_s · rate) + i` output samples: spans that meet
    /// (bar k's end, bar k + 1's start) tile the song without a gap or an overlap.
    pub fn span(&self, from_s: f64, to_s: f64) -> (Vec<f32>, u32) {
        let sr = self.sample_rate.max(1);
        let rate = sr.min(AUDIO_RATE);
        let n_in = self.samples.len();
        let song_s = n_in as f64 / sr as f64;
        let (a, b) = (from_s.clamp(0.0, song_s), to_s.clamp(0.0, song_s));
        let (i0, i1) = (
            (a * rate as f64).round() as usize,
            (b * rate as f64).round() as usize,
        );
        if rate == sr {
            let (i0, i1) = (i0.min(n_in), i1.min(n_in));
            return (self.samples[i0..i1.max(i0)].to_vec(), rate);
        }
        let ratio = sr as f64 / rate as f64;
        let out = (i0..i1.max(i0))
            .map(|i| {
                let centre = i as f64 * ratio;
                let lo = ((centre - ratio / 2.0).round().max(0.0) as usize).min(n_in);
                let hi = ((centre + ratio / 2.0).round() as usize).clamp(lo, n_in);
                if hi == lo {
                    0.0
                } else {
                    self.samples[lo..hi].iter().sum::<f32>() / (hi - lo) as f32
                }
            })
            .collect();
        (out, rate)
    }
}

/// The editor's state (module docs).
pub struct Session {
    edit: Edit,
    file: DanceFile,
    song: Arc<Song>,
    model: Figure,
    fill: Option<Fill>,
    /// The pins the last fill was made for: when they differ from the edit's, the unpinned
    /// bars' fills are stale until the next Generate.
    fill_pins: std::collections::BTreeMap<usize, usize>,
    /// Every segment's normalised motion intensity (percentile rank of W in the database).
    motion: Vec<f64>,
}

/// A seam of [`InContext`]: the connection of segment `from` into segment `to`.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SeamScore {
    /// The segment before the seam.
    pub from: usize,
    /// The segment after it.
    pub to: usize,
    /// The connection score S = S_pose + S_move (eq. 8; higher joins better).
    pub s: f64,
    /// The transition cost C = 1/S (eq. 9).
    pub cost: f64,
}

/// A candidate danced between its neighbours ([`Session::in_context`]).
#[derive(Debug, Clone, serde::Serialize)]
pub struct InContext {
    /// The bar.
    pub bar: usize,
    /// The segment tried in it.
    pub segment: usize,
    /// Frames per second of `frames`.
    pub fps: f64,
    /// Song time of frame 0 (the neighbour before's bar, or the bar), s.
    pub start_s: f64,
    /// Song time at which the bar starts, s.
    pub bar_start_s: f64,
    /// Song time at which the bar ends, s.
    pub bar_end_s: f64,
    /// Song time at which the last bar shown ends, s.
    pub end_s: f64,
    /// The seam from the bar before (none for the song's first bar).
    pub before: Option<SeamScore>,
    /// The seam into the bar after (none for the song's last bar).
    pub after: Option<SeamScore>,
    /// The stick-figure frames of the bars shown.
    pub frames: Frames,
}

/// Stick-figure frames: per frame, every drawable point (joints then end sites), metres rounded
/// to the millimetre (what a stick view draws; the answers stay short: "0.913", not
/// "0.91283154").
pub type Frames = Vec<Vec<[f32; 3]>>;

impl Session {
    /// Opens the `Dance` scene at `path`: loads its song, bars, database and pins as
    /// `marionette run` does ([`load_dance`]), starts an edit with the scene's search and fill
    /// parameters and pins, and generates once (building the transition table and filling the
    /// scene's dance, which the page shows from the start).
    pub fn open(path: &Path) -> Result<Session, EditorError> {
        let file = DanceFile::load(path)?;
        let scene = file.scene();
        let inputs = load_dance(scene, file.base())?;
        let mut edit = Edit::new(
            Arc::new(inputs.db),
            inputs.bars,
            scene.search.clone(),
            scene.fill.clone(),
        )?;
        for (&bar, &seg) in &inputs.pins {
            edit.set(bar, seg)?;
        }
        // The scene's pins are the starting point, not an undoable change.
        let mut state = edit.state().clone();
        state.undo.clear();
        let edit = Edit::with_index(edit.database().clone(), edit.index().clone(), state)?;
        let fill = edit.generate()?;
        let fill_pins = edit.pins().clone();
        let motion = crate::choreo::relevance::motion_intensity(edit.database());
        let song = Arc::new(Song {
            samples: inputs.samples,
            sample_rate: inputs.sample_rate,
            tempo_bpm: inputs.analysis.tempo_bpm,
            beats_s: inputs.analysis.beats_s,
        });
        Ok(Session {
            edit,
            file,
            song,
            model: humanoid24(),
            fill: Some(fill),
            fill_pins,
            motion,
        })
    }

    /// The edit.
    pub fn edit(&self) -> &Edit {
        &self.edit
    }

    /// The edit, to act on.
    pub fn edit_mut(&mut self) -> &mut Edit {
        &mut self.edit
    }

    /// The song.
    pub fn song(&self) -> &Song {
        &self.song
    }

    /// The song, shared: the server sends its pieces without holding the session.
    pub fn shared_song(&self) -> Arc<Song> {
        self.song.clone()
    }

    /// The last fill ([`Session::generate`]; the scene's own from the start).
    pub fn fill(&self) -> Option<&Fill> {
        self.fill.as_ref()
    }

    /// Whether the last fill was made for other pins than the edit's (a Set, Unpin, Undo or
    /// Redo since): its unpinned bars are then stale until the next Generate.
    pub fn fill_is_stale(&self) -> bool {
        &self.fill_pins != self.edit.pins()
    }

    /// Every segment's normalised motion intensity: the percentile rank of its W among the
    /// database's segments ([`crate::choreo::relevance::motion_intensity`]).
    pub fn motion_intensity(&self) -> &[f64] {
        &self.motion
    }

    /// The scene file the session saves to.
    pub fn scene_path(&self) -> &Path {
        self.file.path()
    }

    /// Frames per second of the dance ([`crate::choreo::dance::DanceParams::fps`] of the
    /// scene).
    pub fn fps(&self) -> f64 {
        self.file.scene().dance.fps
    }

    /// Parents of the stick figure's points (joints then end sites; `None` for the pelvis).
    pub fn point_parents(&self) -> Vec<Option<usize>> {
        self.model.skeleton().point_parents()
    }

    /// The side of every stick-figure point: `'l'`, `'r'` or `'c'` (centre), for colouring.
    pub fn point_sides(&self) -> Vec<char> {
        let side = |name: &str| {
            if name.starts_with("left_") {
                'l'
            } else if name.starts_with("right_") {
                'r'
            } else {
                'c'
            }
        };
        let joints = &self.model.joints;
        joints
            .iter()
            .map(|j| side(&j.name))
            .chain(
                joints
                    .iter()
                    .filter(|j| j.end_site.is_some())
                    .map(|j| side(&j.name)),
            )
            .collect()
    }

    /// The head of the stick figure: the neck joint's point and its end site's (the top of the
    /// head), when the model has them.
    pub fn head_points(&self) -> Option<(usize, usize)> {
        let joints = &self.model.joints;
        let neck = self.model.joint_index("neck")?;
        joints[neck].end_site?;
        let site = joints.len()
            + joints[..neck]
                .iter()
                .filter(|j| j.end_site.is_some())
                .count();
        Some((neck, site))
    }

    /// Generate: every unpinned bar filled by the minimum-cost path through the pins
    /// ([`Edit::generate`]: the exact DP on the edit's transition table, built when the
    /// session opened and kept).
    pub fn generate(&mut self) -> Result<&Fill, EditorError> {
        let f = self.edit.generate()?;
        self.fill_pins = self.edit.pins().clone();
        Ok(self.fill.insert(f))
    }

    /// The stick-figure frames of segment `segment` at its resampled frames, its pelvis moved
    /// so that the first frame stands over the origin (the heading kept).
    pub fn segment_frames(&self, segment: usize) -> Result<Frames, EditorError> {
        let db = self.edit.database();
        let s = db
            .segments
            .get(segment)
            .ok_or(crate::choreo::edit::EditError::NoSuchSegment {
                segment,
                segments: db.segments.len(),
            })?;
        let clip = s.clip(&self.model);
        let start = clip.root_translation.first().copied().unwrap_or_default();
        Ok(points(&clip, DVec3::new(start.x, 0.0, start.z)))
    }

    /// The whole dance of the current pins (generated now), assembled at the song's bars as
    /// the scene says ([`Session::fps`], seams): its stick-figure frames and the song time of
    /// frame 0 (s).
    pub fn dance_frames(&mut self) -> Result<(Frames, f64), EditorError> {
        let d = self.dance()?;
        Ok((points(&d.clip, DVec3::ZERO), d.start_s))
    }

    /// [`Session::dance_frames`] and the dance's figures ([`figures`]: feet in the floor,
    /// skating and beat alignment against its segments', intensity correlation, seam jerk).
    pub fn dance_with_figures(&mut self) -> Result<(Frames, f64, DanceFigures), EditorError> {
        let d = self.dance()?;
        let fill = self.fill.clone().expect("dance() generates first");
        let f = figures(
            &d,
            self.edit.database(),
            &fill,
            self.edit.bars(),
            &self.song.beats_s,
        );
        Ok((points(&d.clip, DVec3::ZERO), d.start_s, f))
    }

    fn dance(&mut self) -> Result<crate::choreo::dance::Dance, EditorError> {
        let segments = self.generate()?.segments.clone();
        let scene = self.file.scene();
        // An assembly error is reported as the scene's, as `marionette run` reports it.
        let (d, _) = perform(
            self.edit.database(),
            &segments,
            self.edit.bars(),
            &self.song.beats_s,
            &scene.dance,
            &scene.feet,
        )
        .map_err(|e| EditorError::DanceScene(e.into()))?;
        Ok(d)
    }

    /// Segment `segment` danced in bar `bar` between its current neighbours ([`InContext`]):
    /// the bars before and after take their pin, or else their segment in the last fill (made
    /// now if there is none, without keeping it), and the three bars (two at the song's ends)
    /// are performed as the whole dance is ([`perform`]: warped onto the song's beats, seams,
    /// feet on the floor), so the seams play as they would be danced.
    pub fn in_context(&self, bar: usize, segment: usize) -> Result<InContext, EditorError> {
        let e = &self.edit;
        e.bar_search(bar)?;
        let db = e.database();
        if segment >= db.segments.len() {
            return Err(crate::choreo::edit::EditError::NoSuchSegment {
                segment,
                segments: db.segments.len(),
            }
            .into());
        }
        let bars = e.bars();
        let (lo, hi) = (bar.saturating_sub(1), (bar + 1).min(bars.len() - 1));
        let made;
        let fill = match &self.fill {
            Some(f) => f,
            None => {
                made = e.generate()?;
                &made
            }
        };
        let segments: Vec<usize> = (lo..=hi)
            .map(|k| match k == bar {
                true => segment,
                false => e.pins().get(&k).copied().unwrap_or(fill.segments[k]),
            })
            .collect();
        let scene = self.file.scene();
        let (d, _) = perform(
            db,
            &segments,
            &bars[lo..=hi],
            &self.song.beats_s,
            &scene.dance,
            &scene.feet,
        )
        .map_err(|e| EditorError::DanceScene(e.into()))?;
        let link = |a: usize, b: usize| {
            let c = crate::choreo::transition::connection(
                &db.segments[a],
                &db.segments[b],
                &e.state().fill.transition,
            );
            SeamScore {
                from: a,
                to: b,
                s: c.s,
                cost: c.cost,
            }
        };
        Ok(InContext {
            bar,
            segment,
            fps: self.fps(),
            start_s: d.start_s,
            bar_start_s: bars[bar].start_s,
            bar_end_s: bars[bar].end_s,
            end_s: bars[hi].end_s,
            before: (lo < bar).then(|| link(segments[0], segment)),
            after: (hi > bar).then(|| link(segment, segments[segments.len() - 1])),
            frames: points(&d.clip, DVec3::ZERO),
        })
    }

    /// The whole dance of the current pins as the `motion.bvh` that `marionette run` writes
    /// for the saved scene ([`song_timed_bvh`]: humanoid24 at the scene's fps, frame 0 the
    /// song's t = 0).
    pub fn export_bvh(&mut self) -> Result<String, EditorError> {
        let d = self.dance()?;
        Ok(song_timed_bvh(&d).0)
    }

    /// Save: the scene written back to its file with the current pins (by clip and bar where
    /// the clip's name is unique), atomically, nothing else in the file changed.
    pub fn save(&mut self) -> Result<&Path, EditorError> {
        let pins = scene_pins(self.edit.pins(), self.edit.database());
        self.file.save(&pins)?;
        Ok(self.file.path())
    }
}

/// Every frame's drawable points of `clip`, less `origin`, in single precision.
fn points(clip: &FigureClip, origin: DVec3) -> Frames {
    clip.to_clip()
        .point_frames()
        .into_iter()
        .map(|f| {
            f.into_iter()
                .map(|p| {
                    let p = ((p - origin) * 1000.0).round() / 1000.0;
                    [p.x as f32, p.y as f32, p.z as f32]
                })
                .collect()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn song(rate: u32, f: impl Fn(f64) -> f32, seconds: f64) -> Song {
        let n = (seconds * rate as f64) as usize;
        Song {
            samples: (0..n).map(|i| f(i as f64 / rate as f64)).collect(),
            sample_rate: rate,
            tempo_bpm: 120.0,
            beats_s: vec![],
        }
    }

    /// A 44.1 kHz song is sent at 22.05 kHz: spans tile, a 440 Hz tone keeps its level, and a
    /// tone above the new Nyquist frequency (11.025 kHz) is damped, not folded back at full level.
    #[test]
    fn spans_are_reduced_to_22khz_and_tile() {
        let tone = song(
            44_100,
            |t| (2.0 * std::f64::consts::PI * 440.0 * t).sin() as f32,
            2.0,
        );
        let (whole, rate) = tone.span(0.0, f64::INFINITY);
        assert_eq!((rate, whole.len()), (22_050, 44_100));
        let (a, _) = tone.span(0.3, 0.7);
        let (b, _) = tone.span(0.7, 1.3);
        assert_eq!(a.len() + b.len(), 22_050);
        assert_eq!([a, b].concat(), whole[6_615..28_665]);
        let peak = whole.iter().fold(0f32, |m, s| m.max(s.abs()));
        assert!((peak - 1.0).abs() < 0.01, "{peak}");
        let high = song(
            44_100,
            |t| (2.0 * std::f64::consts::PI * 20_000.0 * t).sin() as f32,
            1.0,
        );
        let (h, _) = high.span(0.0, 1.0);
        let rms = (h.iter().map(|s| s * s).sum::<f32>() / h.len() as f32).sqrt();
        assert!(rms < 0.2, "20 kHz after the reduction: rms {rms}");
        // A 22.05 kHz song is sent as it is; a span past the end is cut at the end.
        let low = song(22_050, |t| t as f32, 1.0);
        assert_eq!(low.span(0.5, 9.0).0, low.samples[11_025..]);
        assert!(low.span(5.0, 9.0).0.is_empty());
    }
}
