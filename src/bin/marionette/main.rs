//! The `marionette` command: inspect, export and render motion files, and run scene files.
//!
//! This file parses the arguments, dispatches to one module per command and prints errors.

/// `println!` for every command: when standard output is closed early (`marionette music
/// song.ogg | head`), the program ends quietly with success instead of panicking; another
/// write error ends it with that error.
macro_rules! println {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        if let Err(e) = writeln!(std::io::stdout().lock(), $($t)*) {
            crate::stdout_failed(e)
        }
    }};
}

mod body;
mod common;
mod dance;
mod edit;
mod eval;
mod export;
mod inspect;
mod mapping;
mod music;
mod render;
mod run;
mod view;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// marionette: human character motion — motor primitives and simulated falls.
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
    /// Find a BVH skeleton's landmark mapping automatically (names and structure) and write it
    /// as an editable mapping file for --mapping.
    Mapping(mapping::Args),
    /// Draw a motion (BVH or keyframed .ron clip) as a filmstrip PNG or an animated GIF.
    Render(render::Args),
    /// Analyse a song (WAV, OGG/Vorbis, MP3): tempo, beats, bars of 4 and each bar's intensity;
    /// draw them with --out, print JSON with --json.
    Music(music::Args),
    /// Dance segments: `dance db FOLDER|MANIFEST --out DB` builds the segment database.
    Dance(dance::Args),
    /// Open a dance edit scene (song, database, pins) in the browser editor on 127.0.0.1:
    /// prints its URL and serves until interrupted.
    Edit(edit::Args),
    /// Run scene files one after the other; each writes one folder (default out/<scene name>/)
    /// with report.json, and prints its headline figures and where its pictures are.
    Run(run::Args),
    /// Write the results page (one self-contained HTML file: the motions in 3-D on a shared
    /// timeline) for a BVH file or a scene's output folder, and print its path.
    View(view::Args),
    /// Evaluate fall genomes for a GA over the JSON-lines protocol (`--stdin`): the worker a
    /// cluster runs.
    Eval(eval::Args),
    /// Write the articulated fall21 body (links, joints, axes, ranges, masses, centres of mass,
    /// inertias, contact boxes) as URDF and/or MJCF for an age group, height and mass.
    Body(body::Args),
}

/// Ends the program after a failed write to standard output: quietly when the reader went
/// away (a broken pipe), else with the error.
fn stdout_failed(e: std::io::Error) -> ! {
    if e.kind() == std::io::ErrorKind::BrokenPipe {
        std::process::exit(0);
    }
    eprintln!("error: writing to standard output: {e}");
    std::process::exit(1)
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Inspect(a) => inspect::inspect(a),
        Command::Export(a) => export::export(a),
        Command::Mapping(a) => mapping::mapping(a),
        Command::Render(a) => render::render(a),
        Command::Music(a) => music::music(a),
        Command::Dance(a) => dance::dance(a),
        Command::Edit(a) => edit::edit(a),
        Command::Run(a) => run::run(a),
        Command::View(a) => view::view(a),
        Command::Eval(a) => eval::eval(a),
        Command::Body(a) => body::body(a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", format_chain(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, each said once: a cause whose text the message
/// already ends with (an error that prints its source, such as "file: reason") is not repeated.
fn format_chain(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for c in e.chain() {
        let text = c.to_string();
        if out.ends_with(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out
}
