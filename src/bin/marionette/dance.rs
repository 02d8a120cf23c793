//! `marionette dance db FOLDER|MANIFEST --out DB [--music-bpm BPM] [--strict]`: builds the
//! dance-segment database (a line per clip on stderr as it goes: what it gave, or why it was
//! skipped); `marionette dance info DB`: what a database was built from, what it skipped, and
//! how long it took to load.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Result;

use marionette::choreo::{BAR_FRAMES_RANGE, TempoSource, check_tempo};
use marionette::choreo::{BuildParams, ClipOutcome, Database, Manifest, OnRefusal, Source};

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
        /// The tempo of the song the database is for (BPM): each kinematic tempo takes the
        /// octave level nearest it that the motion supports.
        #[arg(long)]
        music_bpm: Option<f64>,
        /// Fail on the first clip that cannot be used, instead of skipping it with a line
        /// that says why.
        #[arg(long)]
        strict: bool,
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
        TempoSource::KinematicMatched => "kinematic, octave nearest the song",
    }
}

/// A source clip of the database in words: its file, frames, rate, tempo, first beat and
/// segments.
fn source_line(s: &Source) -> String {
    format!(
        "{}: {} frames at {:.1} fps, {:.2} BPM ({}), first beat {:.3} s, {} segments",
        s.file,
        s.frames,
        s.fps,
        s.beat.tempo_bpm,
        how(s.beat.source),
        s.beat.first_beat_s,
        s.segments
    )
}

/// Runs `marionette dance`.
pub fn dance(a: Args) -> Result<()> {
    match a.command {
        DanceCommand::Db {
            input,
            out,
            bar_frames,
            music_bpm,
            strict,
        } => build_db(&input, &out, bar_frames, music_bpm, strict),
        DanceCommand::Info { db } => info(&db),
    }
}

/// `dance db`: builds the segment database from the clips of `input` (a folder or manifest)
/// and writes it to `out`, a line per clip on stderr.
fn build_db(
    input: &Path,
    out: &Path,
    bar_frames: usize,
    music_bpm: Option<f64>,
    strict: bool,
) -> Result<()> {
    let (lo, hi) = BAR_FRAMES_RANGE;
    if !(lo..=hi).contains(&bar_frames) {
        anyhow::bail!("--bar-frames is {bar_frames}, outside the accepted range {lo} to {hi}");
    }
    if let Some(m) = music_bpm {
        check_tempo("--music-bpm", m).map_err(anyhow::Error::msg)?;
    }
    let manifest = Manifest::from_path(input)?;
    let n = manifest.clips.len();
    let start = Instant::now();
    let params = BuildParams {
        bar_frames,
        music_bpm,
        ..BuildParams::default()
    };
    let policy = if strict {
        OnRefusal::Fail
    } else {
        OnRefusal::Skip
    };
    let db = Database::build(&manifest, &params, policy, |i, outcome| match outcome {
        ClipOutcome::Used(s) => eprintln!("[{}/{n}] {}", i + 1, source_line(s)),
        ClipOutcome::Skipped(s) => {
            eprintln!("[{}/{n}] skipped {}", i + 1, s.reason)
        }
    })?;
    db.save(out)?;
    eprintln!(
        "wrote {}: {} segments from {} clips ({} skipped) in {:.2} s",
        out.display(),
        db.segments.len(),
        db.sources.len(),
        db.skipped.len(),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}

/// `dance info`: prints what the database `db` holds: its segments, sources and skipped clips.
fn info(db: &Path) -> Result<()> {
    let start = Instant::now();
    let d = Database::load(db)?;
    let secs = start.elapsed().as_secs_f64();
    println!(
        "{}: {} segments of {} frames on {} from {} clips ({} skipped), loaded in {:.3} s",
        db.display(),
        d.segments.len(),
        d.params.bar_frames,
        d.model,
        d.sources.len(),
        d.skipped.len(),
        secs
    );
    for s in &d.sources {
        println!("  {}", source_line(s));
    }
    if let Some(m) = d.params.music_bpm {
        println!("  octave levels chosen for a song at {m:.2} BPM");
    }
    for s in &d.skipped {
        println!("  skipped {}", s.reason);
    }
    Ok(())
}
