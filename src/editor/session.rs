//! What the editor's server holds: the [`Edit`] (pins, per-bar search, undo/redo), the song
//! (samples, beats, bars), the last fill, and the scene file it saves to. The edit keeps the
//! database's transition table from the first Generate on, so later ones are a path search only.
//!
//! Every method answers bad input with an [`EditorError`], never a panic; the server keeps one
//! `Session` behind a `Mutex`.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::DVec3;

use super::EditorError;
use super::scene::{EditScene, SongSource, resolve};
use crate::choreo::dance::{DanceParams, assemble};
use crate::choreo::database::Database;
use crate::choreo::edit::Edit;
use crate::choreo::fill::Fill;
use crate::choreo::music::{MusicParams, analyze, synth::synthesize};
use crate::humanoid::{Model, ModelClip, humanoid24};

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
    scene: EditScene,
    scene_path: PathBuf,
    song: Song,
    model: Model,
    fill: Option<Fill>,
}

/// Stick-figure frames: per frame, every drawable point (joints then end sites), metres.
pub type Frames = Vec<Vec<[f32; 3]>>;

impl Session {
    /// Opens the edit scene at `path`: loads the database, synthesizes or decodes the song,
    /// finds its beats and bars, applies the scene's pins (checked against song and database).
    pub fn open(path: &Path) -> Result<Session, EditorError> {
        let scene = EditScene::load(path)?;
        let db = Database::load(&resolve(path, &scene.database))?;
        let (samples, sample_rate) = match &scene.song {
            SongSource::Synth(s) => {
                let t = synthesize(s)?;
                (t.samples, t.sample_rate)
            }
            SongSource::File(f) => decode(&resolve(path, f))?,
        };
        let music = analyze(&samples, sample_rate, &MusicParams::default())?;
        let song = Song {
            samples,
            sample_rate,
            tempo_bpm: music.tempo_bpm,
            beats_s: music.beats_s,
        };
        Session::new(Arc::new(db), music.bars, song, scene, path.to_path_buf())
    }

    /// A session over a database and an analysed song; `scene` gives the pins and parameters
    /// and is saved to `scene_path`.
    pub fn new(
        db: Arc<Database>,
        bars: Vec<crate::choreo::music::Bar>,
        song: Song,
        scene: EditScene,
        scene_path: PathBuf,
    ) -> Result<Session, EditorError> {
        let mut edit = Edit::new(db, bars, scene.search.clone(), scene.fill.clone())?;
        for (&bar, &seg) in &scene.pins {
            edit.set(bar, seg)?;
        }
        // The scene's pins are the starting point, not an undoable change.
        let mut state = edit.state().clone();
        state.undo.clear();
        let edit = Edit::with_index(edit.database().clone(), edit.index().clone(), state)?;
        Ok(Session {
            edit,
            scene,
            scene_path,
            song,
            model: humanoid24(),
            fill: None,
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

    /// The last fill ([`Session::generate`]), if any.
    pub fn fill(&self) -> Option<&Fill> {
        self.fill.as_ref()
    }

    /// The scene file the session saves to.
    pub fn scene_path(&self) -> &Path {
        &self.scene_path
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
    /// ([`Edit::generate`]: the exact DP on the edit's transition table, built at the first
    /// Generate and kept).
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

    /// The whole dance of the current pins (generated now), assembled at the song's bars at
    /// `fps`: its stick-figure frames and the song time of frame 0 (s).
    pub fn dance_frames(&mut self, fps: f64) -> Result<(Frames, f64), EditorError> {
        let d = self.dance(fps)?;
        Ok((points(&d.clip, DVec3::ZERO), d.start_s))
    }

    fn dance(&mut self, fps: f64) -> Result<crate::choreo::dance::Dance, EditorError> {
        let segments = self.generate()?.segments.clone();
        let p = DanceParams {
            fps,
            ..DanceParams::default()
        };
        Ok(assemble(
            self.edit.database(),
            &segments,
            self.edit.bars(),
            &p,
        )?)
    }

    /// The whole dance of the current pins as BVH text on humanoid24 at 30 fps.
    pub fn export_bvh(&mut self) -> Result<String, EditorError> {
        let d = self.dance(30.0)?;
        Ok(crate::bvh::to_string(&d.clip.to_clip().to_bvh()))
    }

    /// Save: the scene written back to its file with the current pins, atomically.
    pub fn save(&mut self) -> Result<&Path, EditorError> {
        self.scene.pins = self.edit.pins().clone();
        self.scene.save(&self.scene_path)?;
        Ok(&self.scene_path)
    }
}

#[cfg(feature = "audio")]
fn decode(path: &Path) -> Result<(Vec<f32>, u32), EditorError> {
    let a = crate::choreo::music::decode::decode_file(path)?;
    Ok((a.samples, a.sample_rate))
}

#[cfg(not(feature = "audio"))]
fn decode(path: &Path) -> Result<(Vec<f32>, u32), EditorError> {
    Err(EditorError::Scene {
        path: path.display().to_string(),
        message: "song files need the `audio` feature; use a Synth song".into(),
    })
}

/// Every frame's drawable points of `clip`, less `origin`, in single precision.
fn points(clip: &ModelClip, origin: DVec3) -> Frames {
    clip.to_clip()
        .point_frames()
        .into_iter()
        .map(|f| {
            f.into_iter()
                .map(|p| {
                    let p = p - origin;
                    [p.x as f32, p.y as f32, p.z as f32]
                })
                .collect()
        })
        .collect()
}
