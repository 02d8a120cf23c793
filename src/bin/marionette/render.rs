//! `marionette render FILE --out OUT.png|OUT.gif`: a motion drawn as a filmstrip or an animation.

use std::path::{Path, PathBuf};

use anyhow::{Result, bail};

use marionette::humanoid::Figure;
use marionette::render::{StickFigure, Track, animation_gif, filmstrip_png};
use marionette::scene::{ClipSource, MAX_FILMSTRIP_FRAMES, load_motion};

// The command's arguments (its help text is on `Command::Render`).
#[derive(clap::Args)]
pub struct Args {
    /// The motion file (.bvh, or .ron for a keyframed clip).
    file: PathBuf,
    /// OUT.png (filmstrip) or OUT.gif (animation).
    #[arg(long)]
    out: PathBuf,
    /// Map onto this model first (humanoid24 or fall21); without it the skeleton is drawn as it
    /// is, whatever its joints.
    #[arg(long)]
    model: Option<String>,
    /// With --model: a mapping file for the skeleton (default: detected among the built-ins).
    #[arg(long, requires = "model")]
    mapping: Option<PathBuf>,
    /// Start of the time window, seconds (default: the clip's start).
    #[arg(long)]
    start: Option<f64>,
    /// End of the time window, seconds (default: the clip's end).
    #[arg(long)]
    end: Option<f64>,
    /// Metres per file unit of a BVH (estimated from the standing height when absent).
    #[arg(long)]
    unit_scale: Option<f64>,
    /// Frames in a filmstrip (1 to 64).
    #[arg(long, default_value_t = 8)]
    frames: usize,
}

/// Runs `render`: writes the picture and says so.
pub fn render(args: Args) -> Result<()> {
    let Args {
        file,
        out,
        model,
        mapping,
        start,
        end,
        unit_scale,
        frames,
    } = args;
    if !(1..=MAX_FILMSTRIP_FRAMES).contains(&frames) {
        bail!("--frames {frames}: expected 1 to {MAX_FILMSTRIP_FRAMES}");
    }
    let (file, out) = (file.as_path(), out.as_path());
    let kind = out
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    if !matches!(kind.as_deref(), Some("png" | "gif")) {
        bail!(
            "--out {}: expected a .png (filmstrip) or .gif (animation) file",
            out.display()
        );
    }
    let base = Path::new(".");
    let src = ClipSource {
        file: file.display().to_string(),
        start_s: start,
        end_s: end,
        unit_scale,
        mapping: mapping.map(|m| m.display().to_string()),
    };
    let motion = load_motion(&src, base)?;
    let clip = match &model {
        Some(name) => motion.on_figure(&Figure::by_name(name)?)?.to_clip(),
        None => motion.clip(),
    };
    let figure = StickFigure::of(&clip.skeleton);
    let points = clip.point_frames();
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    // The tiles' times count from the window's start: say where that is in the clip.
    let label = match start {
        Some(s) if s > 0.0 => format!("{stem}: t from {s:.2} s of the clip"),
        _ => stem,
    };
    let track = Track {
        figure: &figure,
        frames: &points,
        label,
        frame_time: clip.frame_time,
    };
    if kind.as_deref() == Some("png") {
        filmstrip_png(&[track], frames, out)?;
    } else {
        animation_gif(&[track], 25.0, out)?;
    }
    println!("wrote {}", out.display());
    Ok(())
}
