//! Writing a song as a WAV file (16-bit PCM, interleaved channels), e.g. the synthesized song a
//! dance scene plays, so that any player or tool can read it.

/// The bytes of a 16-bit PCM WAV file of interleaved `samples` (full scale ±1, clipped beyond)
/// with `channels` channels at `sample_rate` Hz. `samples.len()` should be a multiple of
/// `channels`; a last partial frame is dropped. Returns `None` when the data would not fit a
/// WAV file (4 GiB) or `channels` is 0.
pub fn wav_bytes(samples: &[f32], channels: u16, sample_rate: u32) -> Option<Vec<u8>> {
    if channels == 0 {
        return None;
    }
    let frames = samples.len() / channels as usize;
    let data_len = u32::try_from(frames * channels as usize * 2).ok()?;
    let riff_len = data_len.checked_add(36)?;
    let block = channels.checked_mul(2)?;
    let byte_rate = sample_rate.checked_mul(block as u32)?;
    let mut b = Vec::with_capacity(44 + data_len as usize);
    b.extend(b"RIFF");
    b.extend(riff_len.to_le_bytes());
    b.extend(b"WAVEfmt ");
    b.extend(16u32.to_le_bytes());
    b.extend(1u16.to_le_bytes());
    b.extend(channels.to_le_bytes());
    b.extend(sample_rate.to_le_bytes());
    b.extend(byte_rate.to_le_bytes());
    b.extend(block.to_le_bytes());
    b.extend(16u16.to_le_bytes());
    b.extend(b"data");
    b.extend(data_len.to_le_bytes());
    for s in &samples[..frames * channels as usize] {
        b.extend(((s.clamp(-1.0, 1.0) * 32767.0).round() as i16).to_le_bytes());
    }
    Some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_and_samples() {
        let b = wav_bytes(&[0.0, 1.0, -1.0, 2.0], 2, 8000).unwrap();
        assert_eq!(b.len(), 44 + 8);
        assert_eq!(&b[0..4], b"RIFF");
        assert_eq!(u32::from_le_bytes(b[24..28].try_into().unwrap()), 8000);
        assert_eq!(i16::from_le_bytes([b[46], b[47]]), 32767);
        assert_eq!(i16::from_le_bytes([b[50], b[51]]), 32767); // 2.0 clipped
        assert!(wav_bytes(&[0.0], 0, 8000).is_none());
    }
}
