//! `marionette edit SCENE.ron [--port P]`: opens an edit scene (song, database, pins; see
//! `marionette::editor::scene`) in the dance editor, a page served on 127.0.0.1, and prints
//! its URL. Serves until interrupted.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;

use marionette::editor::server::{DEFAULT_PORT, Editor};
use marionette::editor::session::Session;

// The command's arguments (its help text is on `Command::Edit`).
#[derive(clap::Args)]
pub struct Args {
    /// The edit scene (.ron): song, database, pins.
    scene: PathBuf,
    /// The port on 127.0.0.1 (0: any free port).
    #[arg(long, default_value_t = DEFAULT_PORT)]
    port: u16,
}

/// Runs `marionette edit`.
pub fn edit(a: Args) -> Result<()> {
    let session = Session::open(&a.scene).map_err(marionette::Error::from)?;
    let editor = Editor::start(session, a.port).map_err(marionette::Error::from)?;
    println!("dance editor: {}", editor.url());
    std::io::stdout().flush()?;
    editor.wait();
    Ok(())
}
