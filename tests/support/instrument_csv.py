"""Captures written in the CSV layouts real instruments export, from a :class:`SampleBlock` of the
virtual bench instrument: what the bench import tests read back. Each layout as the instrument
writes it (where it comes from is said at each writer); logic lines on an oscilloscope's analog
channel are 0 V / 5 V traces, as a probe on a line receiver's output shows them."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from fha_studio.hardware.bench.capture import SampleBlock


def _volts(block: SampleBlock, channel: str) -> np.ndarray:
    if channel in block.logic_channels:
        return block.bit(channel).astype(np.float64) * 5.0
    return block.analog[channel].astype(np.float64)


def _formatted(fmt: str, col: np.ndarray) -> np.ndarray:
    levels = np.unique(col)
    if levels.size <= 2:  # a logic line: its two levels formatted once
        return np.array([fmt % v for v in levels])[np.searchsorted(levels, col)]
    return np.char.mod(fmt, col)


def _rows(columns: list[np.ndarray], formats: list[str], separator: str = ",", end: str = "") -> str:
    text = [_formatted(fmt, col) for fmt, col in zip(formats, columns, strict=True)]
    joined = text[0]
    for col in text[1:]:
        joined = np.char.add(np.char.add(joined, separator), col)
    return "\n".join((joined + end).tolist()) + "\n"


def write_saleae_digital(path: Path, block: SampleBlock, *, logic1: bool = False) -> Path:
    """Saleae Logic 2's digital export (File > Export Data > CSV): ``Time [s],NAME,...`` with the
    channels' own names, one row per change, the first row the state at the start, times printed
    to the ns. Logic 1.x: ``Time[s], Channel 0, Channel 1`` with ``, `` between the fields."""
    words = block.logic.astype(np.int64)
    at = np.concatenate(([0], np.flatnonzero(np.diff(words) != 0) + 1))
    t = at / block.sample_rate_hz
    bits = [(words[at] >> k) & 1 for k in range(len(block.logic_channels))]
    if logic1:
        header = "Time[s], " + ", ".join(f"Channel {k}" for k in range(len(bits)))
        body = _rows([t, *bits], ["%.15f"] + ["%d"] * len(bits), ", ")
    else:
        header = "Time [s]," + ",".join(block.logic_channels)
        body = _rows([t, *bits], ["%.9f"] + ["%d"] * len(bits))
    path.write_text(header + "\n" + body)
    return path


def write_saleae_analog(path: Path, block: SampleBlock, channels: Mapping[str, str]) -> Path:
    """Saleae Logic 2's analog export: ``Time [s],Channel 0,...`` at the analog rate, in volts."""
    t = np.arange(block.samples) / block.sample_rate_hz
    cols = [_volts(block, c) for c in channels.values()]
    path.write_text(
        "Time [s]," + ",".join(channels) + "\n" + _rows([t, *cols], ["%.9f"] + ["%.6f"] * len(cols))
    )
    return path


def write_rigol(path: Path, block: SampleBlock, channels: Mapping[str, str], start_s: float = -0.006) -> Path:
    """A Rigol DS1000Z CSV: ``X,CH1,...,Start,Increment,``, ``Sequence,Volt,...,START,INCREMENT``,
    then ``index,value,...,`` rows with three significant digits, as the scope writes them."""
    cols = [_volts(block, c) for c in channels.values()]
    head = (
        f"X,{','.join(channels)},Start,Increment,\n"
        f"Sequence,{','.join('Volt' for _ in channels)},{start_s:.6e},{1 / block.sample_rate_hz:.6e}\n"
    )
    path.write_text(head + _rows([np.arange(block.samples), *cols], ["%d"] + ["%.2e"] * len(cols), end=","))
    return path


def write_tek(path: Path, block: SampleBlock, channels: Mapping[str, str], start_s: float = -0.002) -> Path:
    """A Tektronix MSO/MDO/DPO 3000/4000 CSV: a preamble of settings (one value per channel),
    three rows of separators, ``Label``, then ``TIME,CH1,...``."""
    n, k = block.samples, len(channels)

    def row(key: str, value: str) -> str:
        return f"{key}," + ",".join([value] * k) + "\n"

    head = (
        f"Model,MDO3024{',' * k}\nFirmware Version,1.26{',' * k}\n"
        + row("Point Format", "Y")
        + row("Horizontal Units", "s")
        + row("Horizontal Scale", "0.04")
        + row("Sample Interval", f"{1 / block.sample_rate_hz:g}")
        + row("Record Length", str(n))
        + row("Gating", "0.0% to 100.0%")
        + row("Probe Attenuation", "10")
        + row("Vertical Units", "V")
        + row("Vertical Offset", "0")
        + row("Vertical Scale", "2")
        + row("Vertical Position", "0")
        + ("," * k + "\n") * 3
        + row("Label", "")
        + "TIME,"
        + ",".join(channels)
        + "\n"
    )
    t = start_s + np.arange(n) / block.sample_rate_hz
    cols = [_volts(block, c) for c in channels.values()]
    path.write_text(head + _rows([t, *cols], ["%.7e"] + ["%.5g"] * k))
    return path


def write_siglent(path: Path, block: SampleBlock, source: str, channel: str, start_s: float = -0.004) -> Path:
    """A Siglent SDS1000X-E CSV of one channel: ``Record Length,Analog:N``, ``Sample Rate``,
    ``Vertical Scale,CH1: 0.05``, ``Vertical Offset``, ``Horizontal Scale``, then ``Second,Volt``
    and the time and value of each sample."""
    n = block.samples
    head = (
        f"Record Length,Analog:{n}\nSample Rate,{block.sample_rate_hz:.1f}\n"
        f"Vertical Scale,{channel}: 2.00\nVertical Offset,{channel}:0.00000\n"
        "Horizontal Scale, 0.050000000\nSecond,Volt\n"
    )
    t = start_s + np.arange(n) / block.sample_rate_hz
    path.write_text(head + _rows([t, _volts(block, source)], ["%.11f", "%.5f"]))
    return path


def write_picoscope(
    path: Path, block: SampleBlock, channels: Mapping[str, str], start_s: float = -0.01
) -> Path:
    """PicoScope 6's CSV: ``Time,Channel A,...``, a units row ``(ms),(V),...``, an empty line,
    then the samples (time in ms)."""
    t_ms = (start_s + np.arange(block.samples) / block.sample_rate_hz) * 1e3
    cols = [_volts(block, c) for c in channels.values()]
    head = "Time," + ",".join(channels) + "\n(ms)," + ",".join("(V)" for _ in channels) + "\n\n"
    path.write_text(head + _rows([t_ms, *cols], ["%.8f"] + ["%.8f"] * len(cols)))
    return path
