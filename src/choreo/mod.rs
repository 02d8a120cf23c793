//! Choreography (SPEC §2, the dance-editing paper): music analysis of a song (beats, bars, each
//! bar's intensity) that a dance is cut to.
//!
//! - [`music`]: the music kernel over a plain sample buffer (onset envelope, tempo, beats, bars,
//!   bar intensity), song decoding behind the `audio` feature, and a drum-track synthesizer with
//!   exact ground truth.

pub mod music;
