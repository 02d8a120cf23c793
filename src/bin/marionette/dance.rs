//! `marionette dance db FOLDER|MANIFEST --out DB`: builds the dance-segment database (a line
//! per clip on stderr as it goes).

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Result;

use marionette::choreo::database::{BuildParams, Database, Manifest};
use marionette::choreo::segments::TempoSource;

// The command's arguments (its help text is on `Command::Dance`).
#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: DanceCommand,
}

#[derive(clap::Subcommand)]
enum DanceCommand {
    /// Build a segment database from a folder of clips (.bvh, keyframed .ron) or a manifest.
    Db {
        /// A folder of clips or a manifest (.ron).
        input: PathBuf,
        /// The database file to write (compact JSON).
        #[arg(long)]
        out: PathBuf,
        /// Frames every bar is resampled to.
        #[arg(long, default_value_t = 32)]
        bar_frames: usize,
    },
}

/// Runs `marionette dance`.
pub fn dance(a: Args) -> Result<()> {
    match a.command {
        DanceCommand::Db {
            input,
            out,
            bar_frames,
        } => {
            let manifest = Manifest::from_path(&input)?;
            let n = manifest.clips.len();
            let start = Instant::now();
            let params = BuildParams {
                bar_frames,
                ..BuildParams::default()
            };
            let db = Database::build(&manifest, &params, |i, s| {
                let how = match s.beat.source {
                    TempoSource::Manifest => "manifest",
                    TempoSource::Kinematic => "kinematic",
                };
                eprintln!(
                    "[{}/{n}] {}: {} frames at {:.1} fps, {:.2} BPM ({how}), first beat {:.3} s, \
                     {} segments",
                    i + 1,
                    s.file,
                    s.frames,
                    s.fps,
                    s.beat.tempo_bpm,
                    s.beat.first_beat_s,
                    s.segments
                );
            })?;
            db.save(&out)?;
            eprintln!(
                "wrote {}: {} segments from {} clips in {:.2} s",
                out.display(),
                db.segments.len(),
                db.sources.len(),
                start.elapsed().as_secs_f64()
            );
            Ok(())
        }
    }
}
