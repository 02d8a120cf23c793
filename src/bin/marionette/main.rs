//! The `marionette` command: inspect, export and render motion files, and run scene files.
//!
//! This file parses the arguments, dispatches to one module per command and prints errors.

mod common;
mod export;
mod inspect;
mod music;
mod render;
mod run;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// marionette: human character motion — motor primitives, choreography, evolved falls.
#[derive(Parser)]
#[command(version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print a BVH file's skeleton, channels, frames, rate, duration, size, ground contact and
    /// flight phases.
    Inspect(inspect::Args),
    /// Export a BVH file's motion: global joint positions, joint angles on a model, or BVH.
    Export(export::Args),
    /// Draw a motion (BVH or keyframed .ron clip) as a filmstrip PNG or an animated GIF.
    Render(render::Args),
    /// Analyse a song (WAV, OGG/Vorbis, MP3): tempo, beats, bars of 4 and each bar's intensity;
    /// draw them with --out, print JSON with --json.
    Music(music::Args),
    /// Run a scene file; outputs go to one folder (default out/<scene name>/) with report.json.
    Run(run::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Inspect(a) => inspect::inspect(a),
        Command::Export(a) => export::export(a),
        Command::Render(a) => render::render(a),
        Command::Music(a) => music::music(a),
        Command::Run(a) => run::run(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", format_chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line.
fn format_chain(e: &anyhow::Error) -> String {
    e.chain()
        .map(|c| c.to_string())
        .collect::<Vec<_>>()
        .join(": ")
}
