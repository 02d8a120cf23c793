//! `marionette edit SCENE.ron [--port P]`: opens a `Dance` scene (song, database, pins: the
//! file `marionette run` reads) in the dance editor, a page served on 127.0.0.1, and prints
//! its URL once the database's transition table is built. Serves until SIGINT, SIGTERM or
//! SIGHUP (Ctrl+C, `kill`): then it stops taking requests, lets those being answered finish (a
//! Save writes its file whole), says so on stderr and exits 0.

use std::io::Write;
use std::path::PathBuf;

use anyhow::Result;

use marionette::editor::server::{DEFAULT_PORT, Editor};
use marionette::editor::session::Session;

// The command's arguments (its help text is on `Command::Edit`).
#[derive(clap::Args)]
pub struct Args {
    /// The Dance scene (.ron): song, database, pins; Save writes its pins back.
    scene: PathBuf,
    /// The port on 127.0.0.1 (0: any free port).
    #[arg(long, default_value_t = DEFAULT_PORT)]
    port: u16,
}

/// Runs `marionette edit`.
pub fn edit(a: Args) -> Result<()> {
    let session = Session::open(&a.scene).map_err(marionette::Error::from)?;
    let editor = Editor::start(session, a.port).map_err(marionette::Error::from)?;
    let (tx, rx) = std::sync::mpsc::channel();
    ctrlc::set_handler(move || {
        let _ = tx.send(());
    })?;
    println!("dance editor: {}", editor.url());
    std::io::stdout().flush()?;
    // Only the handler sends; should it ever be dropped, stopping is still right.
    let _ = rx.recv();
    eprintln!("dance editor: stopping (finishing the requests in flight)");
    let stuck = editor.shutdown(std::time::Duration::from_secs(2));
    if stuck > 0 {
        eprintln!("dance editor: {stuck} requests still waiting for their clients were dropped");
    }
    eprintln!("dance editor: stopped");
    Ok(())
}
