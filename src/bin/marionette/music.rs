//! `marionette music SONG`: a song's tempo, beats, bars and per-bar intensity; `--out PNG` draws
//! them, `--json` prints one JSON object for other tools.

use std::path::{Path, PathBuf};

use anyhow::{Context, Result};
use serde::Serialize;

use marionette::choreo::music::{Audio, decode_file};
use marionette::choreo::music::{Bar, MusicAnalysis, MusicParams, analyze};
use marionette::render::music_png;

// The command's arguments (its help text is on `Command::Music`).
#[derive(clap::Args)]
pub struct Args {
    /// The song (WAV, OGG/Vorbis or MP3).
    song: PathBuf,
    /// Draw waveform, onset envelope, beats, bars and bar intensity to this PNG.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Print one JSON object (tempo_bpm, beats_s, bars) instead of the text report.
    #[arg(long)]
    json: bool,
    /// Which of the first beats is the first downbeat (0-based); chosen from the signal if absent.
    #[arg(long)]
    downbeat: Option<usize>,
    /// Centre of the tempo prior (BPM), within the tempi considered (40 to 240 BPM).
    #[arg(long)]
    prior_bpm: Option<f64>,
    /// Width of the tempo prior (octaves, one standard deviation).
    #[arg(long)]
    prior_octaves: Option<f64>,
    /// Beats per bar.
    #[arg(long, default_value_t = 4)]
    beats_per_bar: usize,
}

/// The JSON the command prints with `--json`.
#[derive(Serialize)]
struct Report<'a> {
    song: String,
    sample_rate: u32,
    duration_s: f64,
    tempo_bpm: f64,
    beats_per_bar: usize,
    downbeat: usize,
    downbeat_given: bool,
    beats_s: &'a [f64],
    downbeats_s: Vec<f64>,
    bars: &'a [Bar],
}

/// Runs `music`: analyses the song, prints the report (or JSON) and draws the picture.
pub fn music(args: Args) -> Result<()> {
    let params = music_params(&args)?;
    let audio = decode_file(&args.song)?;
    if let Some(w) = &audio.warning {
        eprintln!("warning: {}: {w}", args.song.display());
    }
    let a = analyze(&audio.samples, audio.sample_rate, &params)
        .with_context(|| args.song.display().to_string())?;
    if let Some(out) = &args.out {
        let name = args
            .song
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        music_png(&a, &audio.samples, &name, out)?;
    }
    if args.json {
        let r = Report {
            song: args.song.display().to_string(),
            sample_rate: a.sample_rate,
            duration_s: a.duration_s,
            tempo_bpm: a.tempo_bpm,
            beats_per_bar: a.beats_per_bar,
            downbeat: a.downbeat,
            downbeat_given: a.downbeat_given,
            beats_s: &a.beats_s,
            downbeats_s: a.downbeats.iter().map(|&i| a.beats_s[i]).collect(),
            bars: &a.bars,
        };
        println!("{}", serde_json::to_string(&r)?);
        return Ok(());
    }
    print_report(&args.song, &audio, &a, &params);
    if let Some(out) = &args.out {
        println!("picture     {}", out.display());
    }
    Ok(())
}

/// The analysis parameters the arguments ask for. Errors: a tempo prior outside the tempi the
/// analysis considers.
fn music_params(args: &Args) -> Result<MusicParams> {
    let mut params = MusicParams {
        downbeat: args.downbeat,
        beats_per_bar: args.beats_per_bar,
        ..MusicParams::default()
    };
    if let Some(c) = args.prior_bpm {
        let (lo, hi) = (params.prior.min_bpm, params.prior.max_bpm);
        if !(c.is_finite() && (lo..=hi).contains(&c)) {
            anyhow::bail!(
                "--prior-bpm is {c} BPM, outside the accepted range {lo} to {hi} BPM (the tempi \
                 the analysis considers)"
            );
        }
        params.prior.centre_bpm = c;
    }
    if let Some(o) = args.prior_octaves {
        params.prior.octaves = o;
    }
    Ok(params)
}

/// Prints the text report of the analysis `a` of `song` (decoded as `audio`, analysed with
/// `params`): the audio, tempo, beats and bars, and a line per bar.
fn print_report(song: &Path, audio: &Audio, a: &MusicAnalysis, params: &MusicParams) {
    println!("song        {}", song.display());
    println!(
        "audio       {:.3} s, {} Hz, {} channel(s) mixed to mono",
        a.duration_s, audio.sample_rate, audio.channels
    );
    println!(
        "tempo       {:.2} BPM (metrical comb {:.2} BPM, prior centred on {} BPM, {} octaves wide)",
        a.tempo_bpm, a.tempo_prior_bpm, params.prior.centre_bpm, params.prior.octaves
    );
    println!(
        "beats       {} from {:.3} s to {:.3} s",
        a.beats_s.len(),
        a.beats_s.first().copied().unwrap_or(0.0),
        a.beats_s.last().copied().unwrap_or(0.0)
    );
    println!(
        "bars        {}, first downbeat = beat {} ({})",
        a.bars_label(),
        a.downbeat + 1,
        if a.downbeat_given {
            "given"
        } else {
            "from the signal"
        }
    );
    println!("bar   start (s)   end (s)   beats   RMS       RMS (dB)");
    for ((k, b), beats) in a.bars.iter().enumerate().zip(a.bar_beats()) {
        println!(
            "{:>3}   {:>9.3} {:>9.3}   {:>5}   {:.5}   {:>7.2}",
            k + 1,
            b.start_s,
            b.end_s,
            beats,
            b.rms,
            b.rms_db
        );
    }
}
