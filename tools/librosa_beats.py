"""librosa's beat tracker on a list of songs, the rival of marionette's music analysis.

Usage: python tools/librosa_beats.py SONG.wav [SONG.wav ...]

Prints one JSON object per song and line: {"song", "tempo_bpm", "beats_s", "seconds"}, where
seconds is the wall time of decoding (librosa.load at the file's own rate) and
librosa.beat.beat_track together, measured after one untimed warm-up run (librosa compiles parts
of itself with numba on first use). librosa's defaults throughout; it has no downbeats.
"""

import json
import sys
import time

import librosa
import numpy as np


def track(path):
    y, sr = librosa.load(path, sr=None, mono=True)
    tempo, beats = librosa.beat.beat_track(y=y, sr=sr, units="time")
    return float(np.atleast_1d(tempo)[0]), beats


def main(paths):
    if paths:
        sr = 22050
        t = np.arange(10 * sr) / sr
        clicks = librosa.clicks(times=np.arange(0.5, 10, 0.5), sr=sr, length=len(t))
        librosa.beat.beat_track(y=clicks, sr=sr)
    for p in paths:
        start = time.perf_counter()
        tempo, beats = track(p)
        seconds = time.perf_counter() - start
        print(
            json.dumps(
                {"song": p, "tempo_bpm": tempo, "beats_s": [float(b) for b in beats], "seconds": seconds}
            ),
            flush=True,
        )


if __name__ == "__main__":
    main(sys.argv[1:])
