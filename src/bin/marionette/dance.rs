//! `marionette dance db FOLDER|MANIFEST --out DB`: builds the dance-segment database (a line
//! per clip on stderr as it goes); `marionette dance info DB`: what a database was built from
//! and how long it took to load.

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
    /// Print what a database was built from (sources, tempo per clip and how it was found,
    /// segments per clip) and the time it took to load.
    Info {
        /// The database file.
        db: PathBuf,
    },
}

/// How a tempo was found, in words.
fn how(source: TempoSource) -> &'static str {
    match source {
        TempoSource::Manifest => "manifest",
        TempoSource::Kinematic => "kinematic",
    }
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
                let how = how(s.beat.source);
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
        DanceCommand::Info { db } => {
            let start = Instant::now();
            let d = Database::load(&db)?;
            let secs = start.elapsed().as_secs_f64();
            println!(
                "{}: {} segments of {} frames on {} from {} clips, loaded in {:.3} s",
                db.display(),
                d.segments.len(),
                d.params.bar_frames,
                d.model,
                d.sources.len(),
                secs
            );
            for s in &d.sources {
                println!(
                    "  {}: {} frames at {:.1} fps, {:.2} BPM ({}), first beat {:.3} s, {} segments",
                    s.file,
                    s.frames,
                    s.fps,
                    s.beat.tempo_bpm,
                    how(s.beat.source),
                    s.beat.first_beat_s,
                    s.segments
                );
            }
            Ok(())
        }
    }
}
