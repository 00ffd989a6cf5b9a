"""Captures written in the forms :mod:`.readers` reads: sigrok session, VCD, sigrok's CSV, a
generic CSV (the virtual bench instrument of the simulated drive writes them).

They are written as the instruments' software writes them (``sigrok-cli`` reads the ``.sr`` and
VCD files back), through :func:`fha_studio.fileio.write_bytes` (whole or not at all).
"""

from __future__ import annotations

import io
import os
import zipfile
from pathlib import Path

import numpy as np

from fha_studio import fileio
from fha_studio.hardware.bench.capture import SampleBlock

#: Bytes per logic or analog chunk in a session file (sigrok writes chunks of a few MB too).
SR_CHUNK_BYTES = 4 << 20
_VCD_IDS = [chr(c) for c in range(33, 127)]


def rate_text(rate_hz: float) -> str:
    """A sample rate as sigrok writes it: ``200 kHz``, ``24 MHz``, ``1 Hz``."""
    for factor, unit in ((1e9, "GHz"), (1e6, "MHz"), (1e3, "kHz")):
        if rate_hz >= factor:
            return f"{rate_hz / factor:g} {unit}"
    return f"{rate_hz:g} Hz"


def sr_bytes(block: SampleBlock) -> bytes:
    """A sigrok session (srzip version 2) of the block."""
    lines = ["[global]", "sigrok version=0.5.2", "", "[device 1]"]
    unitsize = 1
    if block.logic_channels:
        unitsize = block.logic.dtype.itemsize
        lines += ["capturefile=logic-1", f"total probes={8 * unitsize}"]
    lines.append(f"samplerate={rate_text(block.sample_rate_hz)}")
    if block.analog:
        lines.append(f"total analog={len(block.analog)}")
    for i, name in enumerate(block.logic_channels, 1):
        lines.append(f"probe{i}={name}")
    first_analog = 8 * unitsize + 1 if block.logic_channels else 1
    for i, name in enumerate(block.analog):
        lines.append(f"analog{first_analog + i}={name}")
    lines.append(f"unitsize={unitsize}")
    out = io.BytesIO()
    with zipfile.ZipFile(out, "w", zipfile.ZIP_DEFLATED, compresslevel=1) as archive:
        archive.writestr("version", "2")
        archive.writestr("metadata", "\n".join(lines) + "\n")
        if block.logic_channels:
            _write_chunks(archive, "logic-1", block.logic.astype(f"<u{unitsize}").tobytes())
        for i, values in enumerate(block.analog.values()):
            _write_chunks(archive, f"analog-1-{first_analog + i}", values.astype("<f4").tobytes())
    return out.getvalue()


def _write_chunks(archive: zipfile.ZipFile, base: str, data: bytes) -> None:
    for k, start in enumerate(range(0, max(len(data), 1), SR_CHUNK_BYTES), 1):
        archive.writestr(f"{base}-{k}", data[start:start + SR_CHUNK_BYTES])


def write_sr(path: str | os.PathLike[str], block: SampleBlock) -> Path:
    """Write the block as a sigrok session file."""
    return fileio.write_bytes(path, sr_bytes(block))


def vcd_bytes(block: SampleBlock) -> bytes:
    """The block as a VCD, as sigrok writes it (time in the unit of one sample where the rate
    allows, a comment stating the rate): logic channels as 1-bit wires, analog channels as IEEE
    1364 ``real`` variables (``r<value> ID``, written where the value changes; sigrok-cli's VCD
    input skips them, a mixed-signal viewer such as GTKWave draws them)."""
    analog = list(block.analog)
    width = len(block.logic_channels)
    if not width and not analog:
        raise ValueError("a VCD holds channels; the block has none")
    if width + len(analog) > len(_VCD_IDS):
        raise ValueError(f"at most {len(_VCD_IDS)} channels in one VCD")
    unit_s, unit = _vcd_timescale(block.sample_rate_hz)
    head = [
        "$version FHA Studio virtual bench instrument $end",
        "$comment",
        f"  Acquisition with {width}/{width} channels at {rate_text(block.sample_rate_hz)}",
        "$end",
        f"$timescale {unit} $end",
        "$scope module fha_studio $end",
    ]
    for i, name in enumerate(block.logic_channels):
        head.append(f"$var wire 1 {_VCD_IDS[i]} {name} $end")
    for k, name in enumerate(analog):
        head.append(f"$var real 64 {_VCD_IDS[width + k]} {name} $end")
    head += ["$upscope $end", "$enddefinitions $end"]
    n = block.samples
    words = block.logic if width else np.zeros(n, np.uint8)
    values = [np.asarray(block.analog[name], np.float32) for name in analog]
    changed_at = [words[1:] != words[:-1]] + [v[1:] != v[:-1] for v in values]
    change = np.flatnonzero(np.logical_or.reduce(changed_at)) + 1 if n > 1 else np.zeros(0, np.int64)
    at = np.concatenate(([0], change)) if n else np.zeros(0, np.int64)
    times = np.rint(at / block.sample_rate_hz / unit_s).astype(np.int64).tolist()
    words_at = words[at].tolist()
    # 9 significant digits give a float32 back exactly
    reals = [[f"r{x:.9g} {_VCD_IDS[width + k]}" for x in v[at].tolist()] for k, v in enumerate(values)]
    parts = ["\n".join(head), "\n"]
    previous_word: int | None = None
    previous_real: list[str | None] = [None] * len(analog)
    for j, (t, word) in enumerate(zip(times, words_at, strict=True)):
        changed = (1 << width) - 1 if previous_word is None else word ^ previous_word
        items = [f"{(word >> i) & 1}{_VCD_IDS[i]}" for i in range(width) if (changed >> i) & 1]
        for k, column in enumerate(reals):
            if column[j] != previous_real[k]:
                items.append(column[j])
                previous_real[k] = column[j]
        parts.append(f"#{t} {' '.join(items)}\n")
        previous_word = word
    parts.append(f"#{round(n / block.sample_rate_hz / unit_s)}\n")
    return "".join(parts).encode("ascii")


def _vcd_timescale(rate_hz: float) -> tuple[float, str]:
    """The coarsest VCD unit in which a sample interval is a whole number (else 1 ps)."""
    period = 1.0 / rate_hz
    for unit_s, unit in ((1.0, "1 s"), (1e-3, "1 ms"), (1e-6, "1 us"), (1e-9, "1 ns"), (1e-12, "1 ps")):
        steps = period / unit_s
        if steps >= 1 and abs(steps - round(steps)) < 1e-9 * steps:
            return unit_s, unit
    return 1e-12, "1 ps"


def write_vcd(path: str | os.PathLike[str], block: SampleBlock) -> Path:
    """Write the block's logic channels as a VCD file."""
    return fileio.write_bytes(path, vcd_bytes(block))


def sigrok_csv_bytes(block: SampleBlock, *, time: bool = False,
                     source: str = "FHA Studio virtual bench instrument") -> bytes:
    """``sigrok-cli -O csv`` of the block: comments (``source``: where the samples came from), the
    units label row, one row per sample."""
    names = list(block.channels)
    head = [
        "; CSV generated by libsigrok 0.5.2",
        f"; from {source}",
        f"; Channels ({len(names)}/{len(names)}): {', '.join(names)}",
        f"; Samplerate: {rate_text(block.sample_rate_hz)}",
    ]
    labels = ["logic"] * len(block.logic_channels) + ["V DC"] * len(block.analog)
    times = None
    if time:
        unit, factor = _sigrok_time_unit(block.sample_rate_hz)
        labels.insert(0, unit)
        times = np.arange(1, block.samples + 1) / block.sample_rate_hz / factor
    return ("\n".join(head) + "\n" + ",".join(labels) + "\n").encode() + _rows(block, times)


def _sigrok_time_unit(rate_hz: float) -> tuple[str, float]:
    for factor, unit in ((1.0, "seconds"), (1e-3, "milliseconds"), (1e-6, "microseconds"),
                         (1e-9, "nanoseconds")):
        if 1.0 / rate_hz >= factor:
            return unit, factor
    return "picoseconds", 1e-12


def write_sigrok_csv(path: str | os.PathLike[str], block: SampleBlock, *, time: bool = False,
                     source: str = "FHA Studio virtual bench instrument") -> Path:
    """Write the block as ``sigrok-cli -O csv`` writes it."""
    return fileio.write_bytes(path, sigrok_csv_bytes(block, time=time, source=source))


def csv_bytes(block: SampleBlock, *, semicolon: bool = False, time_unit: str = "s",
              comments: tuple[str, ...] = ()) -> bytes:
    """A generic CSV as an oscilloscope or DAQ exports it: comment lines, a header with units
    (``time [s]``, ``CH [V]``), logic channels as 0/1 columns and analog channels in volts.
    ``semicolon``: ``;`` separated with decimal commas, as European-locale instruments write."""
    factor = {"s": 1.0, "ms": 1e-3}[time_unit]
    names = [f"time [{time_unit}]"] + [f"{n} [V]" for n in block.channels]
    head = "".join(f"# {c}\n" for c in comments)
    times = np.arange(block.samples) / block.sample_rate_hz / factor
    text = (head + ",".join(names) + "\n").encode() + _rows(block, times)
    if semicolon:
        text = text.translate(bytes.maketrans(b",.", b";,"))
    return text


def write_csv(path: str | os.PathLike[str], block: SampleBlock, *, semicolon: bool = False,
              time_unit: str = "s") -> Path:
    """Write the block as a generic CSV (see :func:`csv_bytes`)."""
    return fileio.write_bytes(path, csv_bytes(block, semicolon=semicolon, time_unit=time_unit))


def _rows(block: SampleBlock, times: np.ndarray | None) -> bytes:
    """A text row per sample: its time (when given), each logic channel 0/1, each analog one."""
    columns: list[np.ndarray] = [] if times is None else [times]
    formats: list[str] = [] if times is None else ["%.10g"]
    for name in block.logic_channels:
        columns.append(block.bit(name).astype(np.uint8))
        formats.append("%d")
    for values in block.analog.values():
        columns.append(values)
        formats.append("%.6g")
    out = io.BytesIO()
    if columns and columns[0].size:
        np.savetxt(out, np.column_stack([c.astype(np.float64) for c in columns]), fmt=formats, delimiter=",")
    return out.getvalue()
