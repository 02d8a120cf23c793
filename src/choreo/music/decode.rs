//! Song decoding (feature `audio`): WAV, OGG/Vorbis and MP3 through symphonia to one mono
//! buffer (the channels averaged) at the file's sample rate.

use std::fs::File;
use std::path::Path;

use symphonia::core::codecs::audio::AudioDecoderOptions;
use symphonia::core::errors::Error as SymphoniaError;
use symphonia::core::formats::probe::Hint;
use symphonia::core::formats::{FormatOptions, TrackType};
use symphonia::core::io::MediaSourceStream;
use symphonia::core::meta::MetadataOptions;

use super::MusicError;

/// A decoded song: mono samples (full scale ±1) and their rate.
#[derive(Debug, Clone, PartialEq)]
pub struct Audio {
    /// Mono samples, the mean of the channels.
    pub samples: Vec<f32>,
    /// Sample rate (Hz).
    pub sample_rate: u32,
    /// Channels in the file.
    pub channels: usize,
}

impl Audio {
    /// Duration (s).
    pub fn duration_s(&self) -> f64 {
        self.samples.len() as f64 / self.sample_rate as f64
    }
}

/// Most mono samples [`decode_file`] keeps (two hours at 48 kHz, 1.4 GB of f32).
pub const MAX_SAMPLES: usize = 2 * 3600 * 48_000;

/// Decodes the song at `path` (WAV, OGG/Vorbis or MP3, by content, the extension as a hint) and
/// mixes it to mono. Errors: an unreadable file, a format or codec symphonia does not read, no
/// audio track, a corrupt stream, a song longer than [`MAX_SAMPLES`], no samples at all.
pub fn decode_file(path: &Path) -> Result<Audio, MusicError> {
    let dec = |message: String| MusicError::Decode {
        path: path.to_path_buf(),
        message,
    };
    let file = File::open(path).map_err(|reason| MusicError::Io {
        path: path.to_path_buf(),
        reason,
    })?;
    let mss = MediaSourceStream::new(Box::new(file), Default::default());
    let mut hint = Hint::new();
    if let Some(ext) = path.extension().and_then(|e| e.to_str()) {
        hint.with_extension(ext);
    }
    let mut format = symphonia::default::get_probe()
        .probe(
            &hint,
            mss,
            FormatOptions::default(),
            MetadataOptions::default(),
        )
        .map_err(|e| dec(format!("not a WAV, OGG/Vorbis or MP3 file ({e})")))?;
    let track = format
        .default_track(TrackType::Audio)
        .ok_or_else(|| dec("no audio track".into()))?;
    let track_id = track.id;
    // The container's frame count, when it states one, sizes the buffer once.
    let expected = track.num_frames.unwrap_or(0).min(MAX_SAMPLES as u64) as usize;
    let params = track
        .codec_params
        .as_ref()
        .and_then(|p| p.audio())
        .ok_or_else(|| dec("the audio track has no codec parameters".into()))?;
    let mut decoder = symphonia::default::get_codecs()
        .make_audio_decoder(params, &AudioDecoderOptions::default())
        .map_err(|e| dec(format!("no decoder for its codec ({e})")))?;
    let mut samples: Vec<f32> = Vec::with_capacity(expected);
    let mut interleaved: Vec<f32> = Vec::new();
    let mut rate = 0u32;
    let mut channels = 0usize;
    loop {
        let packet = match format.next_packet() {
            Ok(Some(p)) => p,
            Ok(None) => break,
            Err(SymphoniaError::IoError(e)) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                break;
            }
            Err(e) => return Err(dec(format!("reading packets: {e}"))),
        };
        if packet.track_id != track_id {
            continue;
        }
        let buf = match decoder.decode(&packet) {
            Ok(b) => b,
            // A damaged packet is skipped, as players do.
            Err(SymphoniaError::DecodeError(_)) => continue,
            Err(e) => return Err(dec(format!("decoding: {e}"))),
        };
        let spec = buf.spec();
        let (r, c) = (spec.rate(), spec.channels().count());
        if c == 0 {
            continue;
        }
        if rate == 0 {
            (rate, channels) = (r, c);
        } else if r != rate || c != channels {
            return Err(dec(format!(
                "the stream changes from {channels} channels at {rate} Hz to {c} at {r} Hz"
            )));
        }
        interleaved.resize(buf.samples_interleaved(), 0.0);
        buf.copy_to_slice_interleaved(&mut interleaved);
        if samples.len() + interleaved.len() / c > MAX_SAMPLES {
            return Err(dec(format!(
                "longer than {} samples (two hours at 48 kHz)",
                MAX_SAMPLES
            )));
        }
        let inv = 1.0 / c as f32;
        samples.extend(
            interleaved
                .chunks_exact(c)
                .map(|f| f.iter().sum::<f32>() * inv),
        );
    }
    if samples.is_empty() {
        return Err(dec("no audio samples in the file".into()));
    }
    Ok(Audio {
        samples,
        sample_rate: rate,
        channels,
    })
}
