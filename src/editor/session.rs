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
use crate::humanoid::{Model, ModelClip, humanoid24};
use crate::scene::{DanceFigures, figures, load_dance, perform, scene_pins, song_timed_bvh};

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

/// The editor's state (module docs).
pub struct Session {
    edit: Edit,
    file: DanceFile,
    song: Song,
    model: Model,
    fill: Option<Fill>,
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
        let song = Song {
            samples: inputs.samples,
            sample_rate: inputs.sample_rate,
            tempo_bpm: inputs.analysis.tempo_bpm,
            beats_s: inputs.analysis.beats_s,
        };
        Ok(Session {
            edit,
            file,
            song,
            model: humanoid24(),
            fill: Some(fill),
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

    /// The last fill ([`Session::generate`]; the scene's own from the start).
    pub fn fill(&self) -> Option<&Fill> {
        self.fill.as_ref()
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
        let (d, _) = perform(
            self.file.scene(),
            self.edit.database(),
            &segments,
            self.edit.bars(),
            &self.song.beats_s,
        )?;
        Ok(d)
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
fn points(clip: &ModelClip, origin: DVec3) -> Frames {
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
