//! The dance editor (the paper's editing interface, §3.3 and Fig. 3) as a local web server: a
//! page in the browser over one [`crate::choreo::edit::Edit`], no second copy of the
//! algorithms.
//!
//! - [`scene`]: the `Dance` scene file (song, database, pins) that `marionette edit` opens and
//!   saves — the same file `marionette run` reads;
//! - [`session`]: what the server holds — the edit, the song, the transition table, the fill;
//! - [`api`]: the JSON API, one route per action, as a pure function over the session;
//! - `http`: HTTP/1.1 connections — request heads (httparse), bodies, deadlines, refusals;
//! - [`server`]: the HTTP server on 127.0.0.1 — Host check against DNS
//!   rebinding, embedded files only, body limit, the session behind a `Mutex`.

pub mod api;
mod http;
pub mod scene;
pub mod server;
pub mod session;

use crate::choreo::dance::DanceError;
use crate::choreo::edit::EditError;
use crate::choreo::fill::FillError;
use crate::choreo::music::MusicError;
use crate::choreo::segments::SegmentError;
use crate::choreo::transition::TransitionError;

/// Why the editor could not open, act or save.
#[derive(Debug, thiserror::Error)]
pub enum EditorError {
    /// A file could not be read or written.
    #[error("{path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's reason.
        message: String,
    },
    /// A dance scene: its syntax, fields, song, database or pins.
    #[error(transparent)]
    DanceScene(#[from] crate::scene::SceneError),
    /// A scene the editor cannot open or save.
    #[error("{path}: {message}")]
    Scene {
        /// The scene file.
        path: String,
        /// What is wrong (with line and column when the syntax is).
        message: String,
    },
    /// The server could not listen.
    #[error("cannot listen on {addr}: {message}")]
    Bind {
        /// The address.
        addr: String,
        /// Why.
        message: String,
    },
    /// An edit action.
    #[error(transparent)]
    Edit(#[from] EditError),
    /// Filling the bars.
    #[error(transparent)]
    Fill(#[from] FillError),
    /// Assembling the dance.
    #[error(transparent)]
    Dance(#[from] DanceError),
    /// The database's transition table.
    #[error(transparent)]
    Transition(#[from] TransitionError),
    /// The song.
    #[error(transparent)]
    Music(#[from] MusicError),
    /// The database file.
    #[error(transparent)]
    Segment(#[from] SegmentError),
}
