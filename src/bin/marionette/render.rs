//! `marionette render FILE --out OUT.png|OUT.gif`: a motion drawn as a filmstrip or an animation.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use marionette::humanoid::Model;
use marionette::render::{Track, animation_gif, filmstrip_png};
use marionette::scene::{ClipSource, load_motion};

// The command's arguments (its help text is on `Command::Render`).
#[derive(clap::Args)]
pub struct Args {
    /// The motion file.
    file: PathBuf,
    /// OUT.png (filmstrip) or OUT.gif (animation).
    #[arg(long)]
    out: PathBuf,
    /// Map onto this model first (humanoid24 or fall21).
    #[arg(long)]
    model: Option<String>,
    /// Frames in a filmstrip.
    #[arg(long, default_value_t = 8)]
    frames: usize,
}

/// Runs `render`: writes the picture and says so.
pub fn render(args: Args) -> Result<()> {
    let Args {
        file,
        out,
        model,
        frames,
    } = args;
    let (file, out) = (file.as_path(), out.as_path());
    let base = Path::new(".");
    let src = ClipSource {
        file: file.display().to_string(),
        start_s: None,
        end_s: None,
        unit_scale: None,
        mapping: None,
    };
    let motion = load_motion(&src, base)?;
    let clip = match &model {
        Some(name) => motion.on_model(&Model::by_name(name)?)?.to_clip(),
        None => motion.clip(),
    };
    let figure = clip.skeleton.figure();
    let points = clip.point_frames();
    let label = file
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    let track = Track {
        figure: &figure,
        frames: &points,
        label,
        frame_time: clip.frame_time,
    };
    match out
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .as_deref()
    {
        Some("png") => filmstrip_png(&[track], frames.max(1), out)?,
        Some("gif") => animation_gif(&[track], 25.0, out)?,
        _ => bail!(
            "--out {}: expected a .png (filmstrip) or .gif (animation) file",
            out.display()
        ),
    }
    println!("wrote {}", out.display());
    Ok(())
}
