//! Pictures of poses and motions, and plots, independent of any skeleton type.
//!
//! A motion is given as a [`Track`]: a [`StickFigure`] (point names and parents) and the global
//! position of every point in every frame (metres, Y up, the figure faces +Z, its left is +X).
//! From tracks this module draws
//!
//! - [`pose_png`]: one frame, front, side and three-quarter views side by side;
//! - [`filmstrip_png`] / [`filmstrip_view_png`]: N instants chosen by motion in one PNG, one row
//!   per track, time labels above the columns (like the figures in the papers), in the
//!   three-quarter view chosen from the motion ([`three_quarter`]) or a named one;
//! - [`animation_gif`]: all tracks side by side in the three-quarter view, looping, subsampled
//!   to a chosen frame rate;
//!
//! - [`write_page`]: the results page, one self-contained `index.html` with every motion in 3-D,
//!   a shared timeline, the plots and the headline figures;
//!
//! and from numbers [`plot`]: line plots with title, axis labels, legend and labelled event
//! markers, as PNG or SVG; from a song's analysis [`music_png`]: waveform, onsets, beats, bars
//! and bar intensity in one PNG.
//!
//! Conventions of every picture: orthographic views ([`View`]) of the figure turned to face +Z
//! (its facing found from its left and right points, so "front" is its front); the body drawn
//! as volumes ([`Volumes`]: the contact boxes of the project's models, capsules along the bones
//! of any other skeleton), shaded against one light and sorted back to front, over its shadow
//! on the floor; the figure's left limbs blue, its right limbs vermillion, mid-line grey
//! (decided from point names by [`side_from_name`]); the floor y = 0 as a line over a light
//! ground seen edge-on, as a patch with a 0.5 m grid seen from above; one scale (metres per pixel)
//! for every view of a picture, framed on the whole motion (all frames, all tracks) so figures
//! do not jump; a 1 m scale bar, and in filmstrips and GIFs the view's name beside it. Text
//! uses the bundled DejaVu Sans, so nothing depends on system fonts. Every file is rendered in
//! memory and written atomically ([`crate::io::write_atomic`]).

mod animation;
mod camera;
mod canvas;
mod facing;
mod figure;
mod filmstrip;
mod music;
mod page;
mod plot;
mod pose;
mod text;
mod volume;

use std::path::{Path, PathBuf};

pub use animation::{MAX_GIF_FPS, MAX_GIF_FRAMES, animation_gif};
pub use camera::{ELEVATION, Eye, View, three_quarter};
pub use figure::{Side, StickFigure, Track, side_from_name};
pub use filmstrip::{filmstrip_at_png, filmstrip_png, filmstrip_view_png};
pub use music::music_png;
pub use page::{
    MAX_PAGE_VALUES, ORBIT_JS, Page, PageBox, PageEvent, PageMotion, PagePlot, PageSong, SONG_RATE,
    page_html, stand_upright, write_page,
};
pub use plot::{Plot, Series, plot};
pub use pose::pose_png;
pub use text::FONT_TTF;
pub use volume::{Shape, Solid, Volumes};

/// Why a picture or plot could not be made.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// Nothing to draw: no tracks, a track without frames, a figure without points, a plot
    /// without data.
    #[error("nothing to draw: {0}")]
    Empty(String),
    /// The figure's topology is inconsistent.
    #[error("bad figure: {0}")]
    BadFigure(String),
    /// A frame has a different number of points than the figure.
    #[error("track '{track}': frame {frame} has {got} points, the figure has {expected}")]
    PointCount {
        /// Label of the track.
        track: String,
        /// Index of the frame.
        frame: usize,
        /// Points in that frame.
        got: usize,
        /// Points of the figure.
        expected: usize,
    },
    /// A position is NaN or infinite.
    #[error("track '{track}': frame {frame}, point {point} ('{name}') is not finite: {value:?}")]
    NonFinite {
        /// Label of the track.
        track: String,
        /// Index of the frame.
        frame: usize,
        /// Index of the point.
        point: usize,
        /// Name of the point.
        name: String,
        /// The offending position (x, y, z), metres.
        value: [f64; 3],
    },
    /// A plot value is NaN or infinite.
    #[error("plot '{plot}': series '{series}', point {index} is not finite: ({x}, {y})")]
    NonFinitePlot {
        /// Plot title.
        plot: String,
        /// Series name (or "markers").
        series: String,
        /// Index of the point in the series.
        index: usize,
        /// Its x.
        x: f64,
        /// Its y.
        y: f64,
    },
    /// A frame index past the end of a track.
    #[error("track '{track}' has {len} frames, there is no frame {frame}")]
    FrameOutOfRange {
        /// Label of the track.
        track: String,
        /// The requested frame.
        frame: usize,
        /// Number of frames.
        len: usize,
    },
    /// An argument out of its range (frame count, frame rate, frame time, image size).
    #[error("invalid argument: {0}")]
    InvalidArgument(String),
    /// The output path's extension names no supported format.
    #[error("{path}: unsupported extension {extension:?}, expected {expected}")]
    UnsupportedExtension {
        /// The output path.
        path: PathBuf,
        /// Its extension (empty if none).
        extension: String,
        /// What is supported there.
        expected: &'static str,
    },
    /// The bundled font could not be loaded.
    #[error("font: {0}")]
    Font(String),
    /// PNG, GIF or plot encoding failed.
    #[error("encoding failed: {0}")]
    Encode(String),
    /// Writing the output file failed.
    #[error("writing {path}: {source}")]
    Io {
        /// The output path.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
}

/// Lower-case extension of `path`, or "" if it has none.
fn extension(path: &Path) -> String {
    path.extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase()
}

/// Requires `path` to end in `.{ext}` (case-insensitive).
fn require_extension(path: &Path, ext: &'static str) -> Result<(), RenderError> {
    let e = extension(path);
    if e == ext {
        Ok(())
    } else {
        Err(RenderError::UnsupportedExtension {
            path: path.to_path_buf(),
            extension: e,
            expected: match ext {
                "png" => ".png",
                "gif" => ".gif",
                _ => "a known image type",
            },
        })
    }
}

/// Writes `bytes` to `path` atomically.
fn write(path: &Path, bytes: &[u8]) -> Result<(), RenderError> {
    crate::io::write_atomic(path, bytes).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}
