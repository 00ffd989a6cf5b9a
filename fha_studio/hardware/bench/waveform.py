"""Waveform files an instrument's output plays: the excitation of a frequency response on SPD-CMD.

A :class:`Waveform` is volts at one rate. It is written in the forms instruments take:

- ``csv``: ``time (s),SPD-CMD (V)``, one row per sample of the whole run (as DAQ software and the
  waveform players that take time and volts read it; FHA Studio's generic CSV reader reads it
  back as a capture with the analog channel ``SPD-CMD``);
- ``wav``: 16-bit PCM, mono, the whole run; full scale (32767) is the waveform's peak, stated in
  the file's ``LIST``/``INFO`` comment (``ICMT``: ``full scale = 0.75 V``), which is how FHA
  Studio reads the volts back;
- ``cycle``: one period, normalised to -1 ... +1, one value per line, no header (the form of
  arbitrary-waveform generators that repeat one cycle at a set frequency and amplitude, e.g.
  PicoScope's AWG: 10 ... 8192 values). It has no volts in it: the generator's amplitude gives
  them, so record SPD-CMD beside SPD-MON when it plays.

Everything is written whole or not at all (:func:`fha_studio.fileio.write_bytes`); a file of
another shape is refused with one line naming the file and what was expected.
"""

from __future__ import annotations

import io
import os
import re
import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from fha_studio import fileio
from fha_studio.hardware.bench.capture import CaptureError
from fha_studio.hardware.bench.readers import read_capture

FORMS = ("csv", "wav", "cycle")
#: the channel name of the CSV form (and of the waveform read back)
CHANNEL = "SPD-CMD"
#: what a waveform file may weigh (an hour at 48 kHz as CSV is about 5 GB: far beyond any excitation)
MAX_WAVEFORM_BYTES = 512 * 1024**2
#: PicoScope's AWG takes 10 ... 8192 values for one cycle
CYCLE_MAX_VALUES = 8192
_SCALE_RE = re.compile(r"full scale\s*=\s*([0-9.eE+-]+)\s*V")


@dataclass(frozen=True)
class Waveform:
    """Volts at ``rate_hz``; ``period_samples`` (0: not periodic) and ``start_sample`` (where the
    periodic part begins) when the file's maker knew them."""

    rate_hz: float
    volts: np.ndarray
    comment: str = ""
    period_samples: int = 0
    start_sample: int = 0

    @property
    def duration_s(self) -> float:
        return len(self.volts) / self.rate_hz

    @property
    def peak_v(self) -> float:
        return float(np.max(np.abs(self.volts))) if len(self.volts) else 0.0

    def cycle(self) -> np.ndarray:
        """One period of the periodic part."""
        if self.period_samples <= 0:
            raise ValueError("the waveform has no period")
        return self.volts[self.start_sample:self.start_sample + self.period_samples]


def _csv_bytes(wave: Waveform) -> bytes:
    out = io.BytesIO()
    t = np.arange(len(wave.volts)) / wave.rate_hz
    np.savetxt(out, np.column_stack([t, wave.volts]), fmt=["%.7f", "%.6f"], delimiter=",")
    return f"time (s),{CHANNEL} (V)\n".encode() + out.getvalue()


def _wav_bytes(wave: Waveform) -> bytes:
    rate = round(wave.rate_hz)
    if abs(rate - wave.rate_hz) > 1e-6 * wave.rate_hz:
        raise ValueError(f"a WAV file's rate is a whole number of Hz: {wave.rate_hz:g} Hz is not")
    peak = wave.peak_v
    if peak <= 0.0:
        raise ValueError("a silent waveform: nothing to write")
    pcm = np.round(np.asarray(wave.volts, float) / peak * 32767.0).astype("<i2").tobytes()
    fmt = struct.pack("<HHIIHH", 1, 1, rate, rate * 2, 2, 16)
    text = f"FHA Studio excitation for SPD-CMD (CN2-31/32): full scale = {peak:.6g} V. {wave.comment}"
    icmt = text.encode("ascii", "replace") + b"\0"
    if len(icmt) % 2:
        icmt += b"\0"
    info = b"INFO" + b"ICMT" + struct.pack("<I", len(icmt)) + icmt
    chunks = (b"fmt " + struct.pack("<I", len(fmt)) + fmt
              + b"data" + struct.pack("<I", len(pcm)) + pcm + (b"\0" if len(pcm) % 2 else b"")
              + b"LIST" + struct.pack("<I", len(info)) + info)
    return b"RIFF" + struct.pack("<I", 4 + len(chunks)) + b"WAVE" + chunks


def _cycle_bytes(wave: Waveform) -> bytes:
    cycle = wave.cycle()
    if not 10 <= len(cycle) <= CYCLE_MAX_VALUES:
        raise ValueError(f"one cycle of {len(cycle)} samples: a cycle file holds 10 ... {CYCLE_MAX_VALUES} "
                         "values (choose a lower rate)")
    peak = float(np.max(np.abs(cycle)))
    out = io.BytesIO()
    np.savetxt(out, cycle / peak, fmt="%.6f")
    return out.getvalue()


def write_waveform(path: str | os.PathLike[str], wave: Waveform, form: str) -> Path:
    """Write ``wave`` in one of :data:`FORMS`; ValueError for a form or waveform it cannot take."""
    if form == "csv":
        data = _csv_bytes(wave)
    elif form == "wav":
        data = _wav_bytes(wave)
    elif form == "cycle":
        data = _cycle_bytes(wave)
    else:
        raise ValueError(f"waveform form '{form}': one of {', '.join(FORMS)}")
    return fileio.write_bytes(path, data)


def form_of(path: str | os.PathLike[str]) -> str:
    """The form a file name asks for: ``.wav`` -> wav, ``.txt`` -> cycle, else csv."""
    name = os.fspath(path).lower()
    return "wav" if name.endswith(".wav") else "cycle" if name.endswith(".txt") else "csv"


def read_waveform(path: str | os.PathLike[str]) -> Waveform:
    """A waveform file in volts: the ``csv`` form (any generic CSV of one analog column and a
    time column) or a ``wav`` stating its full scale. CaptureError (one line) otherwise; a cycle
    file has no volts and is refused so."""
    name = os.fspath(path)
    head = fileio.read_head(name, 12)
    if head.startswith(b"RIFF") and head[8:12] == b"WAVE":
        return _read_wav(fileio.read_bytes(name, limit_bytes=MAX_WAVEFORM_BYTES), name)
    try:
        capture = read_capture(name)
    except CaptureError as exc:
        if name.lower().endswith(".txt"):
            raise CaptureError(f"{name}: a cycle file holds no volts (the generator's amplitude sets "
                               "them): record SPD-CMD beside SPD-MON instead") from None
        raise CaptureError(str(exc)) from None
    analog = list(capture.block.analog)
    if len(analog) != 1:
        raise CaptureError(f"{name}: {len(analog)} analog columns ({', '.join(analog) or 'none'}), "
                           "expected one: the volts on SPD-CMD")
    volts = np.asarray(capture.block.analog[analog[0]], float)
    return Waveform(capture.sample_rate_hz, volts, f"{capture.form} column {analog[0]}")


def _read_wav(data: bytes, name: str) -> Waveform:
    def bad(what: str) -> CaptureError:
        return CaptureError(f"{name}: {what}")

    if len(data) < 12 or data[:4] != b"RIFF" or data[8:12] != b"WAVE":
        raise bad("not a WAV file (RIFF/WAVE expected)")
    pos, fmt, samples, comment = 12, None, None, ""
    while pos + 8 <= len(data):
        chunk, size = data[pos:pos + 4], struct.unpack("<I", data[pos + 4:pos + 8])[0]
        body = data[pos + 8:pos + 8 + size]
        if len(body) < size:
            raise bad(f"byte {pos}: chunk '{chunk.decode('latin-1')}' cut short "
                      f"({len(body)} of {size} bytes)")
        if chunk == b"fmt ":
            if size < 16:
                raise bad(f"byte {pos}: a fmt chunk of {size} bytes, expected 16 or more")
            fmt = struct.unpack("<HHIIHH", body[:16])
        elif chunk == b"data":
            samples = body
        elif chunk == b"LIST" and body[:4] == b"INFO":
            sub = 4
            while sub + 8 <= len(body):
                key, n = body[sub:sub + 4], struct.unpack("<I", body[sub + 4:sub + 8])[0]
                if key == b"ICMT":
                    comment = body[sub + 8:sub + 8 + n].rstrip(b"\0").decode("ascii", "replace")
                sub += 8 + n + (n % 2)
        pos += 8 + size + (size % 2)
    if fmt is None or samples is None:
        raise bad("no 'fmt ' or no 'data' chunk")
    tag, channels, rate, _byte_rate, _align, bits = fmt
    if channels != 1:
        raise bad(f"{channels} channels, expected one (mono)")
    if tag == 1 and bits in (16, 32):
        values = np.frombuffer(samples, dtype=f"<i{bits // 8}").astype(float) / float(2 ** (bits - 1) - 1)
    elif tag == 3 and bits == 32:
        values = np.frombuffer(samples, dtype="<f4").astype(float)
    else:
        raise bad(f"sample format {tag} of {bits} bits: 16- or 32-bit PCM or 32-bit float expected")
    match = _SCALE_RE.search(comment)
    if match is None:
        raise bad("no full-scale voltage stated (its comment has no 'full scale = ... V'): the volts are "
                  "unknown; record SPD-CMD beside SPD-MON instead")
    return Waveform(float(rate), values * float(match.group(1)), comment)
