//! Song decoding (feature `audio`): WAV, OGG/Vorbis and MP3 through symphonia to one mono
//! buffer (the channels averaged) at the file's sample rate.

use std::fs::File;
use std::path::Path;

use symphonia::core::codecs::audio::{AudioDecoder, AudioDecoderOptions};
use symphonia::core::errors::Error as SymphoniaError;
use symphonia::core::formats::probe::Hint;
use symphonia::core::formats::{FormatOptions, FormatReader, TrackType};
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
    /// Set when the file ended before its header said (a cut download): how much was read,
    /// e.g. "read 3.20 s of the 10.00 s its header states (32 %): the file is cut short". The
    /// part read is analysed; the caller shows the warning.
    pub warning: Option<String>,
}

impl Audio {
    /// Duration (s).
    pub fn duration_s(&self) -> f64 {
        self.samples.len() as f64 / self.sample_rate as f64
    }
}

/// Most mono samples [`decode_file`] keeps (two hours at 48 kHz, 1.4 GB of f32).
pub const MAX_SAMPLES: usize = 2 * 3600 * 48_000;

/// What the first bytes of a file say it is, for messages ("a WAV (RIFF) file"), if known.
fn container_of(head: &[u8]) -> Option<&'static str> {
    if head.starts_with(b"RIFF") || head.starts_with(b"RIFX") || head.starts_with(b"RF64") {
        Some("a WAV (RIFF) file")
    } else if head.starts_with(b"OggS") {
        Some("an OGG file")
    } else if head.starts_with(b"ID3")
        || (head.len() > 1 && head[0] == 0xFF && head[1] & 0xE0 == 0xE0)
    {
        Some("an MP3 file")
    } else if head.starts_with(b"fLaC") {
        Some("a FLAC file")
    } else if head.len() >= 8 && &head[4..8] == b"ftyp" {
        Some("an MP4/M4A file")
    } else {
        None
    }
}

/// Decodes the song at `path` (WAV, OGG/Vorbis or MP3, by content, the extension as a hint) and
/// mixes it to mono. Each error says which case it is: a directory, an empty or unreadable
/// file, a format this build does not read (naming the one the first bytes show), a corrupt
/// header, an unsupported codec, no audio track, a corrupt stream, a song longer than
/// [`MAX_SAMPLES`], no samples at all. A file cut short is decoded as far as it goes, with
/// [`Audio::warning`] saying how much was read.
pub fn decode_file(path: &Path) -> Result<Audio, MusicError> {
    let dec = |message: String| MusicError::Decode {
        path: path.to_path_buf(),
        message,
    };
    if path.is_dir() {
        return Err(dec("it is a directory, not a song file".into()));
    }
    let mut file = File::open(path).map_err(|reason| MusicError::Io {
        path: path.to_path_buf(),
        reason,
    })?;
    let (head, n) = read_head(path, &mut file)?;
    if n == 0 {
        return Err(dec("the file is empty (0 bytes)".into()));
    }
    let kind = container_of(&head[..n]);
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
        .map_err(|e| dec(probe_failure(kind, &e, &head[..n])))?;
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
        .map_err(|e| {
            dec(format!(
                "unsupported codec {:?} in {} ({e})",
                params.codec,
                kind.unwrap_or("the file")
            ))
        })?;
    let mixed = mix_packets(&mut *format, &mut *decoder, track_id, expected).map_err(dec)?;
    if mixed.samples.is_empty() {
        return Err(dec(if mixed.damaged > 0 {
            let damaged = mixed.damaged;
            format!("a corrupt stream: none of its {damaged} packets decodes")
        } else if mixed.cut {
            "cut short before its first sample".into()
        } else {
            "no audio samples in the file".into()
        }));
    }
    let warning = mixed.warning(expected);
    Ok(Audio {
        samples: mixed.samples,
        sample_rate: mixed.rate,
        channels: mixed.channels,
        warning,
    })
}

/// The first (up to 12) bytes of `file`, and how many there are; the file rewound after.
fn read_head(path: &Path, file: &mut File) -> Result<([u8; 12], usize), MusicError> {
    use std::io::{Read, Seek};
    let io = |reason| MusicError::Io {
        path: path.to_path_buf(),
        reason,
    };
    let mut head = [0u8; 12];
    let mut n = 0;
    while n < head.len() {
        match file.read(&mut head[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(reason) => return Err(io(reason)),
        }
    }
    file.rewind().map_err(io)?;
    Ok((head, n))
}

/// Why symphonia's probe failed, by what the first bytes `head` say the file is (`kind`): an
/// unsupported codec or a corrupt header of a format read, or a format not read.
fn probe_failure(kind: Option<&str>, e: &SymphoniaError, head: &[u8]) -> String {
    match (kind, e) {
        (
            Some(k @ ("a WAV (RIFF) file" | "an OGG file" | "an MP3 file")),
            SymphoniaError::Unsupported(what),
        ) => {
            format!("{k} in an unsupported codec or variant ({what})")
        }
        (kind, _) => match kind {
            Some(k @ ("a WAV (RIFF) file" | "an OGG file" | "an MP3 file")) => {
                format!("{k} by its first bytes, but its header is corrupt or cut ({e})")
            }
            Some(k) => format!(
                "{k} by its first bytes: an unsupported format (WAV, OGG/Vorbis and MP3 \
                     are read) ({e})"
            ),
            None => {
                format!("not a WAV, OGG/Vorbis or MP3 file: its first bytes are {head:02x?} ({e})")
            }
        },
    }
}

/// A track decoded and mixed to mono, and how its stream ended.
struct Mixed {
    /// Mono samples, the mean of the channels.
    samples: Vec<f32>,
    /// Sample rate (Hz), 0 before the first packet.
    rate: u32,
    /// Channels of the stream.
    channels: usize,
    /// The stream ended in the middle of a packet.
    cut: bool,
    /// Damaged packets skipped.
    damaged: usize,
}

impl Mixed {
    /// The warning for a stream read short of the `expected` samples its header states, cut in
    /// the middle of a packet, or with damaged packets skipped.
    fn warning(&self, expected: usize) -> Option<String> {
        let (rate, damaged) = (self.rate, self.damaged);
        let read_s = self.samples.len() as f64 / rate as f64;
        let short = expected > 0 && self.samples.len() < expected;
        let mut warning = (self.cut || short).then(|| {
            if expected > 0 {
                let total_s = expected as f64 / rate as f64;
                format!(
                    "read {read_s:.2} s of the {total_s:.2} s its header states ({:.0} %): the \
                     file is cut short; the part read is analysed",
                    100.0 * self.samples.len() as f64 / expected as f64
                )
            } else {
                format!("the file ends in the middle of a packet: read {read_s:.2} s, analysed")
            }
        });
        if damaged > 0 {
            let d = format!("{damaged} damaged packet(s) skipped");
            warning = Some(match warning {
                Some(w) => format!("{w}; {d}"),
                None => d,
            });
        }
        warning
    }
}

/// Every packet of track `track_id` decoded and mixed to mono (damaged ones skipped, a cut at
/// the end tolerated); errors: a corrupt stream, a change of rate or channels, more than
/// [`MAX_SAMPLES`].
fn mix_packets(
    format: &mut dyn FormatReader,
    decoder: &mut dyn AudioDecoder,
    track_id: u32,
    expected: usize,
) -> Result<Mixed, String> {
    let mut m = Mixed {
        samples: Vec::with_capacity(expected),
        rate: 0,
        channels: 0,
        cut: false,
        damaged: 0,
    };
    let mut interleaved: Vec<f32> = Vec::new();
    loop {
        let packet = match format.next_packet() {
            Ok(Some(p)) => p,
            Ok(None) => break,
            Err(SymphoniaError::IoError(e)) if e.kind() == std::io::ErrorKind::UnexpectedEof => {
                m.cut = true;
                break;
            }
            Err(e) => {
                return Err(format!(
                    "corrupt stream after {:.2} s ({e})",
                    m.samples.len() as f64 / m.rate.max(1) as f64
                ));
            }
        };
        if packet.track_id != track_id {
            continue;
        }
        let buf = match decoder.decode(&packet) {
            Ok(b) => b,
            // A damaged packet is skipped, as players do.
            Err(SymphoniaError::DecodeError(_)) => {
                m.damaged += 1;
                continue;
            }
            Err(e) => return Err(format!("decoding: {e}")),
        };
        let spec = buf.spec();
        let (r, c) = (spec.rate(), spec.channels().count());
        if c == 0 {
            continue;
        }
        let (rate, channels) = (m.rate, m.channels);
        if rate == 0 {
            (m.rate, m.channels) = (r, c);
        } else if r != rate || c != channels {
            return Err(format!(
                "the stream changes from {channels} channels at {rate} Hz to {c} at {r} Hz"
            ));
        }
        interleaved.resize(buf.samples_interleaved(), 0.0);
        buf.copy_to_slice_interleaved(&mut interleaved);
        if m.samples.len() + interleaved.len() / c > MAX_SAMPLES {
            return Err(format!(
                "longer than {} samples (two hours at 48 kHz)",
                MAX_SAMPLES
            ));
        }
        let inv = 1.0 / c as f32;
        match c {
            // Mono and stereo, the common cases, in passes the compiler vectorises.
            1 => m.samples.extend_from_slice(&interleaved),
            2 => m
                .samples
                .extend(interleaved.chunks_exact(2).map(|f| (f[0] + f[1]) * inv)),
            _ => m.samples.extend(
                interleaved
                    .chunks_exact(c)
                    .map(|f| f.iter().sum::<f32>() * inv),
            ),
        }
    }
    Ok(m)
}
