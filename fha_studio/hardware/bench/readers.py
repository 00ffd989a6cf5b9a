"""Capture files of bench instruments, read into :class:`~.capture.Capture`.

- **sigrok session** (``.sr``, as ``sigrok-cli`` and PulseView write it): a zip holding
  ``version``, ``metadata`` (an ini file: ``samplerate``, ``probeN`` = the name of logic bit
  N-1, ``analogN`` = the name of an analog channel, ``unitsize``), the logic samples in chunks
  ``logic-1-1``, ``logic-1-2``... (``unitsize`` bytes per sample, little-endian) and each analog
  channel's float32 samples in ``analog-1-N-1``, ``analog-1-N-2``...
- **VCD** (IEEE 1364 value change dump): ``$timescale``, ``$var wire 1 ID NAME $end`` per
  channel, then ``#TIME`` and ``0ID`` / ``1ID`` changes (``x`` and ``z`` read as 0); an analog
  channel as a ``$var real 64 ID NAME $end`` with ``rVALUE ID`` changes (held until the next;
  its unit is not stated: V). The sample
  rate is the one sigrok states in its ``$comment`` ("at 1 MHz") or else the finest step between
  changes.
- **sigrok-cli's CSV** (``-O csv``): ``;`` comment lines naming the channels and the sample rate,
  an optional label row (units or channel names), an optional time column, one row per sample.
- **a generic CSV** (oscilloscopes, DAQs, controller traces): a header row of column names, one
  of them the time (``time``, ``t``, ``x-axis``...), in s unless its header or a units row says
  ``ms``, ``us`` or ``ns`` (``Time [ms]``, ``time (s)``, ``time_ms``); optionally a units row after
  the header; comment lines starting with ``#`` (or ``;`` when ``;`` is not the separator);
  ``,``, ``;`` (then decimal commas are read) or tab separated. Every other column is an analog
  channel named by its header; the samples must be at one rate. Oscilloscopes' variants of it:
  a preamble before the header (Tektronix MSO/MDO/DPO: ``Model,...``, ``Sample Interval,...``,
  ``Record Length,...`` rows, then ``TIME,CH1,CH2``; Siglent: ``Record Length,Analog:N``... then
  ``Second,Volt``, the channels named by its ``Source,CH1`` row or the ``CH1:`` of its settings);
  a units row in parentheses and an empty line (PicoScope: ``Time,Channel A`` over ``(ms),(V)``);
  Keysight's ``x-axis,1,2`` over ``second,Volt,Volt``.
- **a logic analyzer's export of changes** (Saleae Logic 2 and 1.x, File > Export Data > CSV of
  digital channels: ``Time [s],Channel 0,...`` or the channels' own names, ``Time[s], Channel 0``
  in Logic 1.x): every channel 0 or 1, one row per change, the first row the state at the start.
  It states no sample rate: the changes are put on a grid of the finest interval between them
  (the capture's ``form`` says the rate), or, where that grid would exceed
  :data:`CHANGES_GRID_MAX_SAMPLES` (a glitch of a few ns in a long capture), on a coarser one that
  drops pulses shorter than its step, counted;
  :func:`on_grid` samples it (or a VCD) at another file's rate. Saleae's analog export is one row
  per sample: a generic CSV.
- **Rigol** (DS1000Z, MSO5000, DS2000): ``X,CH1,CH2,Start,Increment,`` over
  ``Sequence,Volt,Volt,START,INCREMENT``, then rows ``index,value,...,``; a sample's time is
  Start + index x Increment.
- **older Tektronix** (TDS1000/2000, TPS2000, TBS1000; one file per channel): the settings in
  columns 1-3 (``Record Length``, ``Sample Interval``, ``Source,CH1``, ``Vertical Units``...),
  each row's sample in columns 4-5 (time, value); a file shorter than its Record Length is refused.

Where each layout comes from: the makers' exports as public files and readers of them on GitHub
show them (Rigol ``X,CH1,CH2,Start,Increment``; Saleae ``Time [s],Channel 0,...`` of changes;
Siglent SDS1000X-E ``Record Length,Analog:14000`` ... ``Second,Volt``; PicoScope ``(ms),(V)``;
Tektronix TDS files read from columns 4 and 5).

Everything is read through :mod:`fha_studio.fileio` (regular files only, at most
:data:`MAX_CAPTURE_BYTES`). A file of another shape raises :class:`~.capture.CaptureError`: one
line naming the file, the line (or the part of the zip) and what was expected.
"""

from __future__ import annotations

import configparser
import io
import math
import os
import re
import zipfile
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from fha_studio import fileio
from fha_studio.hardware.bench._lines import HeadLines, all_lines
from fha_studio.hardware.bench._lines import table as _table
from fha_studio.hardware.bench.capture import Capture, CaptureError, SampleBlock, logic_dtype, pack_logic

#: What a capture file may weigh (a minute of 8 channels at 24 MS/s is about 1.4 GB as .sr).
MAX_CAPTURE_BYTES = 4 * 1024**3
#: Samples a capture may expand to (VCD and CSV): a minute at 24 MS/s and more.
MAX_SAMPLES = 2_000_000_000
#: Samples a logic analyzer's export of changes is put on at most: finer than its finest interval
#: between changes would be, it takes a coarser grid (a glitch of a few ns in a long capture would
#: otherwise ask for billions of samples), as an analyzer sampling at that rate would see it.
CHANGES_GRID_MAX_SAMPLES = 50_000_000
#: A generic CSV's time column may stray this fraction of a sample interval from a steady rate.
TIME_JITTER = 0.5

_PREFIX = {"": 1.0, "k": 1e3, "m": 1e6, "g": 1e9, "K": 1e3, "M": 1e6, "G": 1e9}
_RATE_RE = re.compile(r"^\s*([0-9]+(?:\.[0-9]*)?)\s*([kKmMgG]?)\s*hz\s*$", re.IGNORECASE)
_TIME_UNITS = {"s": 1.0, "sec": 1.0, "second": 1.0, "seconds": 1.0, "ms": 1e-3, "msec": 1e-3,
               "millisecond": 1e-3, "milliseconds": 1e-3, "us": 1e-6, "µs": 1e-6, "μs": 1e-6,
               "microsecond": 1e-6, "microseconds": 1e-6, "ns": 1e-9, "nanosecond": 1e-9,
               "nanoseconds": 1e-9, "ps": 1e-12, "fs": 1e-15}
_TIME_NAMES = ("time", "t", "x-axis", "x_axis", "timestamp", "zeit", "temps")


def read_capture(path: str | os.PathLike[str]) -> Capture:
    """The capture in ``path``, its form found from its content (a zip is a sigrok session, a
    ``$`` keyword first is VCD, ``libsigrok`` in the first comment is sigrok's CSV, ``X,...,Start,
    Increment`` a Rigol CSV, ``Record Length`` beside samples an older Tektronix one, else CSV)."""
    name = os.fspath(path)
    data = fileio.read_bytes(name, limit_bytes=MAX_CAPTURE_BYTES)
    if data.startswith(b"PK\x03\x04"):
        return parse_sr(data, name)
    head = data[:4096].lstrip()
    if head.startswith(b"$"):
        return parse_vcd(data, name)
    if b"libsigrok" in head[:200] or head.startswith(b"; Channels"):
        return parse_sigrok_csv(data, name)
    if name.lower().endswith((".sr", ".vcd")):
        kind = "sigrok session (a zip)" if name.lower().endswith(".sr") else "VCD ($ keywords first)"
        raise CaptureError(f"{name}: line 1: not a {kind}")
    layout = instrument_layout(data[:4096])
    if layout == "Rigol CSV":
        return parse_rigol_csv(data, name)
    if layout == "Tektronix TDS/TBS CSV":
        return parse_tek_tds_csv(data, name)
    return parse_csv(data, name)


def instrument_layout(head: bytes) -> str | None:
    """The oscilloscope CSV layouts that are not a header row over columns of time and values
    (:func:`parse_csv` reads those, preamble or not), found from the file's first bytes: a Rigol
    DS1000Z/MSO5000 export (``X,CH1,...,Start,Increment``) or an older Tektronix TDS/TBS one
    (metadata beside the data, ``Record Length`` first); None for any other."""
    first = head.lstrip(b"\xef\xbb\xbf \t\r\n").split(b"\n", 1)[0].decode("utf-8", "replace")
    fields = [f.strip().strip('"') for f in first.split(",")]
    if fields[:1] == ["X"] and "Start" in fields and "Increment" in fields:
        return "Rigol CSV"
    if (fields[:1] == ["Record Length"] and len(fields) >= 5 and not fields[2]
            and _numbers_like(fields[3]) and _numbers_like(fields[4])):
        return "Tektronix TDS/TBS CSV"
    return None


def parse_rate(text: str) -> float | None:
    """sigrok's sample rate text (``200 kHz``, ``24 MHz``, ``1 Hz``) in Hz, None if it is not one."""
    match = _RATE_RE.match(text)
    if not match:
        return None
    rate = float(match.group(1)) * _PREFIX[match.group(2)]
    return rate if rate > 0 else None


# ------------------------------------------------------------------------------------- sigrok .sr


def parse_sr(data: bytes, name: str) -> Capture:
    """A sigrok session file (srzip, version 2)."""
    try:
        archive = zipfile.ZipFile(io.BytesIO(data))
        members = set(archive.namelist())
    except (zipfile.BadZipFile, ValueError) as exc:
        raise CaptureError(f"{name}: not a readable sigrok session (zip): {exc}") from None
    if "metadata" not in members:
        raise CaptureError(f"{name}: no 'metadata' in the zip: not a sigrok session")
    try:
        with archive:
            return _parse_sr(archive, members, name)
    except (zipfile.BadZipFile, OSError, EOFError) as exc:
        raise CaptureError(f"{name}: a part of the zip cannot be read: {exc}") from None


def _parse_sr(archive: zipfile.ZipFile, members: set[str], name: str) -> Capture:
    version = archive.read("version").decode("ascii", "replace").strip() if "version" in members else "?"
    if version != "2":
        raise CaptureError(f"{name}: version: sigrok session version '{version}', expected 2")
    text = archive.read("metadata").decode("utf-8", "replace")
    parser = configparser.ConfigParser(interpolation=None, strict=False)
    try:
        parser.read_string(text)
    except configparser.Error as exc:
        raise CaptureError(f"{name}: metadata: not an ini file ({str(exc).splitlines()[0]})") from None
    devices = [s for s in parser.sections() if s.startswith("device ")]
    if not devices:
        raise CaptureError(f"{name}: metadata: no [device 1] section")
    device = parser[devices[0]]
    rate = parse_rate(device.get("samplerate", ""))
    if rate is None:
        raise CaptureError(f"{name}: metadata: samplerate '{device.get('samplerate', '')}' is not a "
                           "rate like '1 MHz'")
    probes: dict[int, str] = {}
    analogs: dict[int, str] = {}
    for key, value in device.items():
        if key.startswith("probe") and key[5:].isdigit():
            probes[int(key[5:])] = value.strip()
        elif key.startswith("analog") and key[6:].isdigit():
            analogs[int(key[6:])] = value.strip()
    capturefile = device.get("capturefile", "logic-1").strip()
    logic_names: tuple[str, ...] = ()
    logic = np.zeros(0, np.uint8)
    n: int | None = None
    if probes:
        try:
            unitsize = int(device.get("unitsize", "1"))
        except ValueError:
            unitsize = 0
        if unitsize not in (1, 2, 4, 8):
            raise CaptureError(f"{name}: metadata: unitsize '{device.get('unitsize')}', "
                               "expected 1, 2, 4 or 8")
        raw = _chunks(archive, members, capturefile, name)
        if len(raw) % unitsize:
            raise CaptureError(f"{name}: {capturefile}: {len(raw)} bytes are not whole samples of "
                               f"{unitsize} bytes")
        words = np.frombuffer(raw, dtype=f"<u{unitsize}")
        # channels are named per bit: probeN is bit N-1; pack the named ones, in bit order
        order = sorted(probes)
        if max(order) > 8 * unitsize:
            raise CaptureError(f"{name}: metadata: probe{max(order)} beyond the {8 * unitsize} bits "
                               "of a sample")
        logic_names = tuple(probes[k] for k in order)
        if order == list(range(1, len(order) + 1)):
            logic = (words & np.array((1 << len(order)) - 1, words.dtype)).astype(logic_dtype(len(order)))
        else:
            logic = pack_logic([((words >> (k - 1)) & 1).astype(bool) for k in order])
        n = int(logic.shape[0])
    analog: dict[str, np.ndarray] = {}
    for index in sorted(analogs):
        raw = _chunks(archive, members, f"analog-1-{index}", name)
        if len(raw) % 4:
            raise CaptureError(f"{name}: analog-1-{index}: {len(raw)} bytes are not whole float32 samples")
        values = np.frombuffer(raw, dtype="<f4").astype(np.float32)
        if n is None:
            n = int(values.shape[0])
        elif values.shape[0] != n:
            # sigrok ends analog and logic at the same sample; cut to the shorter to stay aligned
            n = min(n, int(values.shape[0]))
        analog[analogs[index]] = values
    if n is None:
        raise CaptureError(f"{name}: metadata: no channels (probeN or analogN)")
    logic = logic[:n] if logic_names else logic
    analog = {k: v[:n] for k, v in analog.items()}
    block = SampleBlock(rate, logic_names, logic, analog)
    return Capture(name, block, {k: "V" for k in analog}, 0.0, "sigrok session")


def _chunks(archive: zipfile.ZipFile, members: set[str], base: str, name: str) -> bytes:
    numbered = sorted((int(m[len(base) + 1:]), m) for m in members
                      if m.startswith(base + "-") and m[len(base) + 1:].isdigit())
    names = [m for _, m in numbered]
    if not names and base in members:
        names = [base]
    if not names:
        raise CaptureError(f"{name}: no '{base}-1' in the zip for the channels its metadata names")
    return b"".join(archive.read(m) for m in names)


# -------------------------------------------------------------------------------------------- VCD


_VCD_UNITS = {"s": 1.0, "ms": 1e-3, "us": 1e-6, "ns": 1e-9, "ps": 1e-12, "fs": 1e-15}
_TIMESCALE_RE = re.compile(r"^\s*(1|10|100)\s*(s|ms|us|ns|ps|fs)\s*$")
_SIGROK_ANALOG_LINES = re.compile(rb"(?m)^[A-Za-z_][\w.-]*: [-+0-9.eE]+(?: [^\n]*)?\n?")
_SIGROK_ANALOG_LINE = re.compile(rb"(?m)^[A-Za-z_][\w.-]*: [-+0-9.eE]+(?: [^\n]*)?$")
_AT_RATE_RE = re.compile(r"\bat\s+([0-9.]+\s*[kKmMgG]?Hz)")


def parse_vcd(data: bytes, name: str) -> Capture:
    """A value change dump of 1-bit wires and real variables."""
    end = data.find(b"$enddefinitions")
    if end < 0:
        raise CaptureError(f"{name}: line 1: no '$enddefinitions $end': not a VCD file")
    header = data[:end].decode("utf-8", "replace")
    body_start = data.find(b"$end", end + 15)
    body_start = len(data) if body_start < 0 else body_start + 4
    header_lines = data[:body_start].count(b"\n")
    timescale = 1e-6
    rate: float | None = None
    ids: dict[str, str] = {}
    real_ids: dict[str, str] = {}
    for match in re.finditer(r"\$(\w+)(.*?)\$end", header, re.DOTALL):
        keyword, content = match.group(1), match.group(2)
        line = header.count("\n", 0, match.start()) + 1
        if keyword == "timescale":
            ts = _TIMESCALE_RE.match(content)
            if not ts:
                raise CaptureError(f"{name}: line {line}: $timescale '{content.strip()}', "
                                   "expected like '1 us'")
            timescale = int(ts.group(1)) * _VCD_UNITS[ts.group(2)]
        elif keyword == "comment":
            at = _AT_RATE_RE.search(content)
            if at:
                rate = parse_rate(at.group(1))
        elif keyword == "var":
            parts = content.split()
            if len(parts) < 4:
                raise CaptureError(f"{name}: line {line}: $var '{content.strip()}', expected "
                                   "'$var wire 1 ID NAME $end'")
            if parts[0] == "real":
                real_ids.setdefault(parts[2], parts[3])
                continue
            if parts[1] != "1":
                raise CaptureError(f"{name}: line {line}: $var {parts[3]} is {parts[1]} bits wide; only "
                                   "1-bit wires (logic channels) and real variables (analog) are read")
            ids.setdefault(parts[2], parts[3])
    if not ids and not real_ids:
        raise CaptureError(f"{name}: line {header_lines}: no $var: the file names no channels")
    names = list(dict.fromkeys(ids.values()))
    analog_names = [n for n in dict.fromkeys(real_ids.values()) if n not in names]
    if len(names) > 64:
        raise CaptureError(f"{name}: {len(names)} channels; at most 64 are read")
    # libsigrok 0.5.2 prints a session's analog samples ('A0: 10.00 V DC' lines) into its VCD too
    body = _SIGROK_ANALOG_LINES.sub(b"", data[body_start:])
    # $dumpvars / $end and other keywords in the body carry no samples of their own
    tokens = np.array(re.sub(rb"\$\w+|\$end", b" ", body).split(), dtype=object)
    if tokens.size == 0:
        raise CaptureError(f"{name}: line {header_lines + 1}: no samples after $enddefinitions")
    first = np.array([t[:1] for t in tokens], dtype="S1")
    # a real's change is two tokens, 'rVALUE' and its id (which may begin with any character)
    real_value = np.zeros(tokens.size, bool)
    real_id = np.zeros(tokens.size, bool)
    if real_ids:
        for k in np.flatnonzero((first == b"r") | (first == b"R")).tolist():
            if not real_id[k] and k + 1 < tokens.size:
                real_value[k] = real_id[k + 1] = True
    is_time = (first == b"#") & ~real_id
    if not is_time[0]:
        raise CaptureError(f"{name}: line {header_lines + 1}: '{_tok(tokens[0])}' before the first "
                           "'#time'")
    try:
        times = np.array([int(t[1:]) for t in tokens[is_time]], dtype=np.int64)
    except ValueError:
        bad = next(t for t in tokens[is_time] if not t[1:].isdigit())
        raise CaptureError(f"{name}: line {_line_of(data, body_start, bad)}: '{_tok(bad)}' is not a "
                           "time ('#' and a whole number)") from None
    if np.any(np.diff(times) < 0):
        i = int(np.flatnonzero(np.diff(times) < 0)[0]) + 1
        raise CaptureError(f"{name}: the time goes back at #{times[i]} (after #{times[i - 1]})")
    is_change = ~is_time & ~real_value & ~real_id
    changes = tokens[is_change]
    when = (np.cumsum(is_time) - 1)[is_change]
    value = np.array([t[:1] for t in changes], dtype="S1")
    ident = np.array([t[1:].decode("ascii", "replace") for t in changes], dtype=object)
    bad_value = ~np.isin(value, [b"0", b"1", b"x", b"z", b"X", b"Z"])
    if np.any(bad_value):
        bad = changes[int(np.flatnonzero(bad_value)[0])]
        raise CaptureError(f"{name}: line {_line_of(data, body_start, bad)}: '{_tok(bad)}' is not a "
                           "change of a 1-bit wire (0, 1, x or z and the wire's id)")
    unknown = [i for i in set(ident.tolist()) if i not in ids]
    if unknown:
        raise CaptureError(f"{name}: a change of '{unknown[0]}', which no $var declares")
    t0 = int(times[0])
    span = int(times[-1]) - t0
    if rate is not None:
        step_units = 1.0 / (rate * timescale)
    else:
        deltas = np.diff(np.unique(times))
        step_units = float(np.gcd.reduce(deltas)) if deltas.size else 1.0
        rate = 1.0 / (step_units * timescale)
    # a last '#time' with no change after it marks the end of the capture (sigrok writes one)
    ends_with_marker = bool(is_time[-1])
    n = round(span / step_units) + (0 if ends_with_marker else 1)
    if n > MAX_SAMPLES:
        raise CaptureError(f"{name}: {n} samples at {_rate_text(rate)}: more than the {MAX_SAMPLES} "
                           "a capture may hold")
    sample_of_time = np.rint((times - t0) / step_units).astype(np.int64)
    sample = np.minimum(sample_of_time[when], n - 1)
    high = (value == b"1")
    bits = []
    for channel in names:
        own = np.isin(ident, [i for i, nm in ids.items() if nm == channel])
        bits.append(_held(sample[own], high[own], n, bool))
    analog = _reals(data, body_start, tokens, real_value, real_ids, analog_names,
                    sample_of_time[(np.cumsum(is_time) - 1)[real_value]], n, name)
    logic = pack_logic(bits) if bits else np.zeros(0, np.uint8)
    block = SampleBlock(rate, tuple(names), logic, analog)
    return Capture(name, block, {a: "V" for a in analog}, t0 * timescale, "VCD", changes=True)


def _reals(data: bytes, body_start: int, tokens: np.ndarray, real_value: np.ndarray,
           real_ids: dict[str, str], analog_names: list[str], sample: np.ndarray, n: int,
           name: str) -> dict[str, np.ndarray]:
    """Each real variable's samples, its value held from one change to the next."""
    if not analog_names:
        return {}
    at = np.flatnonzero(real_value)
    ident = np.array([t.decode("ascii", "replace") for t in tokens[at + 1]], dtype=object)
    unknown = [i for i in set(ident.tolist()) if i not in real_ids]
    if unknown:
        raise CaptureError(f"{name}: a real change of '{unknown[0]}', which no '$var real' declares")
    bad = next((t for t in tokens[at] if not _REAL_RE.fullmatch(t[1:])), None)
    if bad is not None:
        raise CaptureError(f"{name}: line {_line_of(data, body_start, bad)}: '{_tok(bad)}' is not a "
                           "real value ('r' and a number)")
    values = np.array([float(t[1:]) for t in tokens[at]], dtype=np.float64)
    sample = np.minimum(sample, n - 1)
    out = {}
    for channel in analog_names:
        own = np.isin(ident, [i for i, nm in real_ids.items() if nm == channel])
        out[channel] = _held(sample[own], values[own], n)
    return out


#: A real's value: a finite number (an instrument never measured 'nan' or 'inf')
_REAL_RE = re.compile(rb"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")


def _held(at: np.ndarray, value: np.ndarray, n: int, dtype: type = np.float32) -> np.ndarray:
    """``n`` samples from (sample, value) changes in time order, each value held until the next;
    0 before the first; the last change at one sample wins."""
    out: np.ndarray = np.zeros(n, dtype)
    if at.size == 0:
        return out
    last_at_sample = np.ones(at.size, bool)
    last_at_sample[:-1] = at[1:] != at[:-1]
    at, value = at[last_at_sample], value[last_at_sample]
    out[at[0]:] = np.repeat(value.astype(dtype), np.diff(np.append(at, n)))
    return out


def _tok(token: bytes) -> str:
    text = token.decode("utf-8", "replace")
    return text if len(text) <= 30 else text[:29] + "…"


def _line_of(data: bytes, start: int, token: bytes) -> int:
    at = data.find(token, start)
    return data.count(b"\n", 0, max(at, 0)) + 1


def _rate_text(rate: float) -> str:
    for factor, unit in ((1e9, "GHz"), (1e6, "MHz"), (1e3, "kHz")):
        if rate >= factor:
            return f"{rate / factor:g} {unit}"
    return f"{rate:g} Hz"


# -------------------------------------------------------------------------------------------- CSV




def parse_sigrok_csv(data: bytes, name: str) -> Capture:
    """``sigrok-cli -O csv`` output (with or without the time column and the label row)."""
    # libsigrok 0.5.2 prints analog samples as 'A0: 10.00 V DC' lines as well (rows never hold ': ')
    comments_end = 0
    while data.startswith(b";", comments_end):
        comments_end = data.find(b"\n", comments_end) + 1 or len(data)
    if data.find(b": ", comments_end) >= 0:
        data = _SIGROK_ANALOG_LINE.sub(b"", data)
    lines: Sequence[bytes] = _head_lines(data)
    names: list[str] = []
    rate: float | None = None
    index = -1
    while True:
        index += 1
        if index == HEAD_LINES and len(lines) > HEAD_LINES:  # a long preamble: the file in lines after all
            lines = data.split(b"\n")
        if index >= len(lines):
            break
        line = lines[index].strip()
        if not line:
            continue
        if line.startswith(b";"):
            text = line[1:].decode("utf-8", "replace").strip()
            if text.startswith("Channels"):
                names = [c.strip() for c in text.partition(":")[2].split(",") if c.strip()]
            elif text.startswith("Samplerate:"):
                rate = parse_rate(text.partition(":")[2])
            continue
        if line.startswith(b"META samplerate:"):  # how 0.5.2 states the rate of a converted VCD
            rate = parse_rate(line.partition(b":")[2].decode("ascii", "replace").strip() + " Hz")
            continue
        if _SIGROK_ANALOG_LINE.match(line):
            continue  # libsigrok 0.5.2 prints live analog samples as 'A0: 1.0 V DC' lines too
        break
    if not names:
        raise CaptureError(f"{name}: line 1: no '; Channels (n/m): ...' comment naming the channels")
    if rate is None:
        raise CaptureError(f"{name}: line 1: no '; Samplerate: ...' comment (like '1 MHz')")
    first = _line(lines, index).decode("utf-8", "replace").strip() if index < len(lines) else ""
    labels = [c.strip() for c in first.split(",")]
    has_label_row = bool(first) and not all(_numbers_like(c) for c in labels)
    width = len(labels)
    has_time = width == len(names) + 1
    if width not in (len(names), len(names) + 1):
        raise CaptureError(f"{name}: line {index + 1}: {width} columns, expected {len(names)} (the "
                           f"channels {', '.join(names)}) or one more for the time")
    start = index + 1 if has_label_row else index
    table = _table(lines, start, width, name, b",", digits=True)
    values = table[:, 1:] if has_time else table
    units = labels[1:] if has_time and has_label_row else (labels if has_label_row else [""] * len(names))
    logic_names: list[str] = []
    bits: list[np.ndarray] = []
    analog: dict[str, np.ndarray] = {}
    unit_of: dict[str, str] = {}
    for column, (channel, unit) in enumerate(zip(names, units, strict=True)):
        col = values[:, column]
        is_logic = unit == "logic" or (unit in ("", channel) and _is_bits(col))
        if is_logic:
            if not _is_bits(col):
                row = int(np.flatnonzero((col != 0) & (col != 1))[0])
                raise CaptureError(f"{name}: line {_data_line(lines, start, row)}: logic channel {channel} "
                                   f"is {col[row]:g}, expected 0 or 1")
            logic_names.append(channel)
            bits.append(col == 1)
        else:
            analog[channel] = col.astype(np.float32)
            unit_of[channel] = _sigrok_unit(unit)
    block = SampleBlock(rate, tuple(logic_names), pack_logic(bits) if bits else np.zeros(0, np.uint8),
                        analog)
    start_s = 0.0
    if has_time and table.shape[0]:
        start_s = float(table[0, 0]) * _time_unit_of_label(labels[0] if has_label_row else "", rate)
    return Capture(name, block, unit_of, start_s, "sigrok CSV")


#: The lines split off a CSV's start to find its header; the rest stays one piece (the rows).
HEAD_LINES = 200


def _head_lines(data: bytes) -> HeadLines:
    """The first HEAD_LINES lines, then the rest of the file as one element (joined back with
    ``\n`` it is the file again, left in place); :func:`_all_lines` splits it when a line must be
    named."""
    return HeadLines(data, HEAD_LINES)


def _line(lines: Sequence[bytes], i: int) -> bytes:
    """Line ``i`` (of the rest of the file, its first line)."""
    if i < HEAD_LINES:
        return lines[i]
    if isinstance(lines, HeadLines):
        return lines.first_of_rest()
    text = lines[i]
    end = text.find(b"\n")
    return text if end < 0 else text[:end]


def _all_lines(lines: Sequence[bytes]) -> list[bytes]:
    return all_lines(lines)


def _sigrok_unit(label: str) -> str:
    # sigrok's unit labels: "V DC", "V AC", "A", ...: the unit is the first word
    return label.split()[0] if label.split() else "V"


def _time_unit_of_label(label: str, rate: float) -> float:
    if label.lower() in _TIME_UNITS:
        return _TIME_UNITS[label.lower()]
    # sigrok picks the time unit from the rate (ms at 20 Hz, us at 1 MHz): the time of one sample
    for unit in (1.0, 1e-3, 1e-6, 1e-9, 1e-12):
        if 1.0 / rate >= unit:
            return unit
    return 1e-15


def _is_bits(col: np.ndarray) -> bool:
    if col.dtype == np.uint8:
        return bool(col.size) and int(col.max()) <= 1
    return bool(col.size) and bool(np.all((col == 0) | (col == 1)))


def _numbers_like(text: str) -> bool:
    return bool(re.fullmatch(r"[+-]?(?:[0-9]+(?:[.,][0-9]*)?|[.,][0-9]+)(?:[eE][+-]?[0-9]+)?", text.strip()))


@dataclass(frozen=True)
class CsvLayout:
    """Where a generic CSV's parts are, from its first lines: what sigrok-cli's CSV input is told
    (``fha_studio.hardware.bench.sigrok_input``) and what :func:`parse_csv` reads by."""

    delimiter: str  # ",", ";" or "\t"
    decimal_comma: bool
    comment: str  # the characters a comment line starts with
    header_line: int  # index of the header row
    data_start: int  # index of the first line after the header (and its units row)
    names: tuple[str, ...]  # the columns' names, units taken off ("time", "CH1")
    units: tuple[str, ...]  # each column's unit as the header or a units row says ("" if none)
    time_column: int
    width: int  # fields per row (trailing empty columns included)


def csv_layout(data: bytes, name: str) -> CsvLayout:
    """The layout of a generic CSV from its start (the whole file or its first lines);
    :class:`CaptureError` naming the line for a file of another shape."""
    return _csv_layout(_head_lines(data), name)


def _csv_layout(lines: Sequence[bytes], name: str) -> CsvLayout:
    index = _first_content_line(lines, 0, None)
    if index is None:
        raise CaptureError(f"{name}: line 1: empty: expected a header row naming the columns "
                           "(one of them the time)")
    try:
        header_text = _line(lines, index).decode("utf-8").strip().lstrip("\ufeff")
    except UnicodeDecodeError:
        raise CaptureError(f"{name}: line {index + 1}: not UTF-8 text: is it a capture file?") from None
    delimiter = _delimiter(header_text)
    header = [c.strip().strip('"') for c in header_text.split(delimiter)]
    if all(_numbers_like(c) for c in header if c):
        raise CaptureError(f"{name}: line {index + 1}: numbers where the header row was expected "
                           "(names of the columns, one of them the time, like 'time [s],CH1 [V]')")
    preamble_end = index
    if not _names_time(header):
        # an oscilloscope's preamble (Tektronix: 'Model,...', 'Sample Interval,...'; Siglent:
        # 'Record Length,...', 'Source,CH1'): the header is the row over the first numbers
        found = _header_after_preamble(lines, index)
        if found is not None:
            index = preamble_end = found
            header_text = _line(lines, index).decode("utf-8", "replace").strip()
            delimiter = _delimiter(header_text)
            header = [c.strip().strip('"') for c in header_text.split(delimiter)]
    comment = "#" if delimiter == ";" else "#;"
    after = _first_content_line(lines, index + 1, comment)
    units: list[str] = [""] * len(header)
    data_start = index + 1
    if after is not None:
        row = [c.strip().strip('"') for c in _line(lines, after).decode("utf-8", "replace").split(delimiter)]
        if row and not any(_numbers_like(c) for c in row if c) and len(row) == len(header):
            # a units row under the header: "s,V,V", Keysight's "second,Volt,Volt", PicoScope's
            # "(ms),(V),(V)"
            units = [_unit_word(c.strip("()[]")) for c in row]
            data_start = after + 1
    names: list[str] = []
    column_units: list[str] = []
    for raw, unit_row in zip(header, units, strict=True):
        label, unit = _split_unit(raw)
        names.append(label)
        column_units.append(_unit_word(unit) or unit_row)
    # trailing empty columns (a separator at the end of each row) are not channels
    while names and not names[-1]:
        names.pop()
        column_units.pop()
    time_column = next((i for i, n in enumerate(names) if _is_time_name(n)), None)
    if time_column is not None and preamble_end > 0:
        _name_by_preamble(lines, preamble_end, names, column_units, time_column)
    if time_column is None:
        raise CaptureError(f"{name}: line {index + 1}: no time column (named time, t or x-axis, in s or "
                           f"ms); the header has {', '.join(n or '(empty)' for n in names)}")
    seen: set[str] = set()
    for label in names:
        if not label:
            raise CaptureError(f"{name}: line {index + 1}: a column without a name")
        if label in seen:
            raise CaptureError(f"{name}: line {index + 1}: column '{label}' given twice")
        seen.add(label)
    if _time_unit(names[time_column], column_units[time_column]) is None:
        raise CaptureError(f"{name}: line {index + 1}: the time column's unit '{column_units[time_column]}' "
                           "is not s, ms, us or ns")
    decimal_comma = delimiter == ";" and _has_decimal_comma(lines, data_start)
    return CsvLayout(delimiter, decimal_comma, comment, index, data_start, tuple(names),
                     tuple(column_units), time_column, len(header))


def _delimiter(header_text: str) -> str:
    return ";" if ";" in header_text else ("\t" if "\t" in header_text else ",")


def _names_time(header: Sequence[str]) -> bool:
    return any(_is_time_name(_split_unit(c)[0]) for c in header)


def _header_after_preamble(lines: Sequence[bytes], start: int) -> int | None:
    """The header row of a CSV with a preamble: the last row of names before the first row of
    numbers, or the one before that when it is a units row; None if neither names the time."""
    first_numbers = None
    for i in range(start, min(len(lines) - 1, HEAD_LINES)):
        text = lines[i].decode("utf-8", "replace").strip()
        fields = [f.strip().strip('"') for f in text.split(_delimiter(text)) if f.strip()]
        if fields and all(_numbers_like(f) for f in fields):
            first_numbers = i
            break
    if first_numbers is None:
        return None
    candidates = []
    for i in range(first_numbers - 1, start - 1, -1):
        text = lines[i].decode("utf-8", "replace").strip()
        fields = [f.strip().strip('"') for f in text.split(_delimiter(text))]
        if any(fields):  # a row of separators only (Tektronix writes ',,') is no row
            candidates.append((i, fields))
            if len(candidates) == 2:
                break
    for i, fields in candidates:
        if _names_time(fields):
            return i
    return None


#: Units as oscilloscopes spell them in a header or units row.
_UNIT_WORDS = {"volt": "V", "volts": "V", "v": "V", "value": "", "amp": "A", "ampere": "A",
               "amps": "A", "second": "s", "seconds": "s", "sec": "s"}
_SOURCE_RE = re.compile(r"^\s*(C\d+|CH\d+|Ch\d+|Channel\s*[A-H0-9]+|MATH\d*|M\d+|D\d+|REF\d*)\s*:")


def _unit_word(unit: str) -> str:
    return _UNIT_WORDS.get(unit.strip().lower(), unit.strip())


def _name_by_preamble(lines: Sequence[bytes], end: int, names: list[str], units: list[str],
                      time_column: int) -> None:
    """Siglent names its columns by their unit (``Second,Volt,Volt`` or ``Second,Value``) and the
    channels in its preamble (``Source,CH1,CH2``, or ``CH1:`` in ``Vertical Units,CH1:V``): the
    columns take the channels' names, the unit word becomes the unit."""
    value_columns = [i for i in range(len(names)) if i != time_column]
    unit_named = [i for i in value_columns if names[i].lower() in _UNIT_WORDS]
    if not unit_named:
        return
    sources: list[str] = []
    prefixed: list[str] = []
    for i in range(end):
        text = _line(lines, i).decode("utf-8", "replace").strip()
        fields = [f.strip().strip('"') for f in text.split(",")]
        if fields[0].lower() == "source":
            sources = [f for f in fields[1:] if f]
        for f in fields[1:]:
            match = _SOURCE_RE.match(f)
            if match and match.group(1) not in prefixed:
                prefixed.append(match.group(1))
    found = sources if len(sources) == len(value_columns) else prefixed
    for k, i in enumerate(value_columns):
        if i in unit_named:
            units[i] = units[i] or _unit_word(names[i])
            names[i] = found[k] if len(found) == len(value_columns) else f"CH{k + 1}"


def time_unit_s(layout: CsvLayout) -> float:
    """Seconds per unit of the layout's time column."""
    unit = _time_unit(layout.names[layout.time_column], layout.units[layout.time_column])
    assert unit is not None  # checked by csv_layout
    return unit


def parse_csv(data: bytes, name: str) -> Capture:
    """A generic CSV: header row, a time column, one analog channel per other column."""
    lines = _head_lines(data)
    layout = _csv_layout(lines, name)
    names, column_units, time_column = list(layout.names), list(layout.units), layout.time_column
    data_start, delimiter, comment = layout.data_start, layout.delimiter, layout.comment
    decimal_comma, width = layout.decimal_comma, layout.width
    table = _table(lines, data_start, width, name, delimiter.encode(), decimal_comma, comment)
    table = table[:, : len(names)]
    if table.shape[0] < 2:
        raise CaptureError(f"{name}: line {data_start + 1}: fewer than 2 rows of samples")
    t = table[:, time_column] * time_unit_s(layout)
    if _is_change_list(table, time_column):
        return _changes(table, t, names, time_column, name, lines, data_start, comment)
    _not_a_change(table, names, time_column, name, lines, data_start, comment)
    rate = _steady_rate(t, name, lines, data_start, comment)
    analog: dict[str, np.ndarray] = {}
    unit_of: dict[str, str] = {}
    for column, label in enumerate(names):
        if column == time_column:
            continue
        col = table[:, column]
        if not math.isfinite(col.sum()) and np.any(np.isnan(col)):
            bad_row = int(np.flatnonzero(np.isnan(col))[0])
            raise CaptureError(f"{name}: line {_data_line(lines, data_start, bad_row, comment)}: column "
                               f"'{label}' is empty, expected a number")
        analog[label] = col.astype(np.float32)
        unit_of[label] = column_units[column] or "V"
    block = SampleBlock(rate, (), np.zeros(0, np.uint8), analog)
    return Capture(name, block, unit_of, float(t[0]), "CSV")


def _is_time_name(label: str) -> bool:
    low = label.lower()
    if low in _TIME_NAMES or low in _TIME_UNITS:
        return True
    base, _, suffix = low.rpartition("_")
    return base in _TIME_NAMES and suffix in _TIME_UNITS


def _time_unit(label: str, unit: str) -> float | None:
    low = label.lower()
    if unit:
        return _TIME_UNITS.get(unit.strip().lower())
    if low in _TIME_UNITS:
        return _TIME_UNITS[low]
    base, _, suffix = low.rpartition("_")
    if base in _TIME_NAMES and suffix in _TIME_UNITS:
        return _TIME_UNITS[suffix]
    return 1.0  # a time without a unit is in seconds


_UNIT_RE = re.compile(r"^(.*?)\s*(?:\[([^\]]*)\]|\(([^)]*)\))\s*$")


def _split_unit(text: str) -> tuple[str, str]:
    """``Time [ms]`` / ``CH1 (V)`` -> (name, unit); a bare name has no unit."""
    match = _UNIT_RE.match(text)
    if match:
        return match.group(1).strip(), (match.group(2) or match.group(3) or "").strip()
    return text.strip(), ""


def _first_content_line(lines: Sequence[bytes], start: int, comment: str | None) -> int | None:
    marks = tuple(c.encode() for c in (comment if comment is not None else "#"))
    for i in range(start, len(lines)):
        line = _line(lines, i).strip()
        if line and not line.startswith(marks) and not line.startswith(b"//"):
            return i
    return None


def _has_decimal_comma(lines: Sequence[bytes], start: int) -> bool:
    for i in range(start, min(len(lines), start + 50)):
        line = _line(lines, i).strip()
        if line and not line.startswith(b"#"):
            return b"," in line
    return False


def _data_line(lines: Sequence[bytes], start: int, row: int, comment: str = ";") -> int:
    marks = tuple(c.encode() for c in comment)
    lines = _all_lines(lines)
    seen = -1
    for i in range(start, len(lines)):
        line = lines[i].strip()
        if line and not line.startswith(marks):
            seen += 1
            if seen == row:
                return i + 1
    return len(lines)


def _steady_rate(t: np.ndarray, name: str, lines: Sequence[bytes], start: int, comment: str) -> float:
    n = t.size
    steps = np.diff(t)
    mean = (t[-1] - t[0]) / (n - 1)  # all steps within 20 % of the mean: within half the median too
    if mean > 0 and math.isfinite(mean) and mean * 0.8 <= steps.min() and steps.max() <= 1.2 * mean:
        return float(f"{(n - 1) / (t[-1] - t[0]):.9g}")
    step = float(np.median(steps))
    if not (step > 0 and math.isfinite(step)):
        raise CaptureError(f"{name}: line {_data_line(lines, start, 1, comment)}: the time does not "
                           "increase")
    off = np.abs(steps - step) > TIME_JITTER * step
    if np.any(off):
        i = int(np.flatnonzero(off)[0]) + 1
        raise CaptureError(
            f"{name}: line {_data_line(lines, start, i, comment)}: time {t[i]:.9g} s after "
            f"{t[i - 1]:.9g} s: off the steady rate of {_rate_text(1.0 / step)} (a sample every "
            f"{step:.6g} s): a capture at one sample rate is expected")
    return float(f"{(n - 1) / (t[-1] - t[0]):.9g}")


# --------------------------------------------------------------------- a logic analyzer's changes


def _is_change_list(table: np.ndarray, time_column: int) -> bool:
    """A logic analyzer's export of changes (Saleae Logic 2's and Logic 1.x's digital CSV): every
    channel 0 or 1 and each row differs from the one before in some channel (the last may repeat
    the state: the capture's end). A file sampled at one rate repeats rows while nothing changes."""
    if table.shape[1] < 2 or table.shape[0] < 2 or not _mostly_bits(table, time_column, 0):
        return False
    columns = [c for c in range(table.shape[1]) if c != time_column]
    same = np.ones(table.shape[0] - 1, bool)
    for c in columns:
        if not np.all((table[:, c] == 0) | (table[:, c] == 1)):
            return False
        same &= table[1:, c] == table[:-1, c]
    return not np.any(same[:-1])


def _mostly_bits(table: np.ndarray, time_column: int, allowed: float) -> bool:
    """Whether the first rows' channels are 0 or 1 but for ``allowed`` of them (a quick look
    before the whole of a large table is looked at)."""
    head = np.delete(table[:1000], time_column, axis=1)
    bad = ~((head == 0) | (head == 1) | np.isnan(head))
    return bool(np.count_nonzero(bad) <= max(1.0, allowed * head.size) if allowed else not bad.any())


def _not_a_change(table: np.ndarray, names: list[str], time_column: int, name: str,
                  lines: Sequence[bytes], start: int, comment: str) -> None:
    """A file whose channels are 0 and 1 but for one value or a few: a logic analyzer's export
    of changes with a bad value, named (not read as analog channels, nor refused for its rate)."""
    if table.shape[1] < 2 or not _mostly_bits(table, time_column, 0.01):
        return
    columns = [c for c in range(table.shape[1]) if c != time_column]
    # an empty field is said by the caller
    bad = [~((table[:, c] == 0) | (table[:, c] == 1) | np.isnan(table[:, c])) for c in columns]
    count = sum(int(np.count_nonzero(b)) for b in bad)
    if 0 < count <= max(1.0, 0.01 * table.shape[0] * len(columns)):
        row, k = min((int(np.flatnonzero(b)[0]), k) for k, b in enumerate(bad) if b.any())
        label, value = names[columns[k]], table[row, columns[k]]
        raise CaptureError(f"{name}: line {_data_line(lines, start, row, comment)}: {label} is "
                           f"{value:g}, expected 0 or 1 (a logic analyzer's export of changes)")


def _changes(table: np.ndarray, t: np.ndarray, names: list[str], time_column: int, name: str,
             lines: Sequence[bytes], start: int, comment: str) -> Capture:
    """Changes put on a sample grid, each state held until the next change. Saleae's export states
    no sample rate: the grid is the finest interval between changes (6 significant digits: the
    file's times are printed to the ns), so no two changes share a sample. Where that grid would
    hold more than :data:`CHANGES_GRID_MAX_SAMPLES` (a glitch of a few ns in a long capture), it is
    the coarsest 1-2-5 step within them: changes closer than one step share a sample, the last one
    holding (a pulse that short is dropped, as an analyzer at that rate would not see it), counted
    in the capture's ``form``."""
    steps = np.diff(t)
    if not np.all(steps > 0):
        i = int(np.flatnonzero(~(steps > 0))[0]) + 1
        raise CaptureError(f"{name}: line {_data_line(lines, start, i, comment)}: time {t[i]:.9g} s after "
                           f"{t[i - 1]:.9g} s: the changes of a logic analyzer's export go forward in time")
    finest = float(f"{float(steps.min()):.6g}") if steps.size else 1.0
    span = float(t[-1] - t[0])
    step = finest
    if round(span / finest) + 1 > CHANGES_GRID_MAX_SAMPLES:
        step = max(finest, _step_up(span / (CHANGES_GRID_MAX_SAMPLES - 1)))
    rate = 1.0 / step
    at = np.rint((t - t[0]) / step).astype(np.int64)
    merged = int(np.count_nonzero(at[1:] == at[:-1]))
    n = int(at[-1]) + 1
    logic_names = [label for column, label in enumerate(names) if column != time_column]
    # each change's state packed first (one word per row), then held: n words, not n per channel
    words = pack_logic([table[:, column] == 1 for column in range(len(names)) if column != time_column])
    block = SampleBlock(rate, tuple(logic_names), _held(at, words, n, words.dtype.type), {})
    form = (f"logic analyzer CSV of changes, sampled at {_rate_text(float(f'{rate:.9g}'))} (the finest "
            "interval between them)")
    if step > finest:
        form = (f"logic analyzer CSV of changes, sampled at {_rate_text(float(f'{rate:.9g}'))}: its finest "
                f"interval, {_seconds_text(finest)}, would make {round(span / finest) + 1} samples; "
                f"{merged} {'change' if merged == 1 else 'changes'} within {_seconds_text(step)} of the "
                "next dropped (a pulse that short is a glitch)")
    return Capture(name, block, {}, float(t[0]), form, changes=True)


def _step_up(seconds: float) -> float:
    """The 1-2-5 step at or above ``seconds``: a grid a person reads as a rate."""
    decade = 10.0 ** math.floor(math.log10(seconds))
    return next(float(f"{m * decade:.3g}") for m in (1, 2, 5, 10) if m * decade >= seconds * (1 - 1e-9))


def _seconds_text(seconds: float) -> str:
    for unit, scale in (("s", 1.0), ("ms", 1e-3), ("µs", 1e-6)):
        if seconds >= scale:
            return f"{seconds / scale:.3g} {unit}"
    return f"{seconds / 1e-9:.3g} ns"


# ------------------------------------------------------------------------- oscilloscopes' layouts


def parse_rigol_csv(data: bytes, name: str) -> Capture:
    """A Rigol DS1000Z (and MSO5000, DS2000) CSV export. Its layout, as the scope writes it (and
    as readers of such files on GitHub take it, e.g. ``X,CH1,CH2,Start,Increment,`` over
    ``Sequence,Volt,Volt,-5.999998e-02,2.000000e-05``): a header naming the channels between
    ``X`` and ``Start,Increment``; a second row with each channel's unit, then the time of sample
    0 and the sample interval [s]; then one row per sample, its index first (each row ends in a
    separator). The time of a sample is Start + index x Increment."""
    lines = _head_lines(data)
    header = [f.strip().strip('"') for f in _line(lines, 0).decode("utf-8", "replace").strip()
              .lstrip("\ufeff").split(",")]
    at = header.index("Start") if "Start" in header else 0
    if header[at + 1 : at + 2] != ["Increment"] or at < 2 or header[0] != "X":
        raise CaptureError(f"{name}: line 1: expected 'X,CH1,...,Start,Increment' (Rigol), not "
                           f"'{','.join(header)}'")
    channels = header[1:at]
    if len(lines) < 3:
        raise CaptureError(f"{name}: line 2: expected the units, Start and Increment "
                           "('Sequence,Volt,...,-6.0e-03,2.0e-06'), then the samples")
    second = [f.strip() for f in _line(lines, 1).decode("utf-8", "replace").strip().split(",")]
    try:
        start_s, increment_s = float(second[at]), float(second[at + 1])
    except (IndexError, ValueError):
        raise CaptureError(f"{name}: line 2: expected the units, then Start and Increment as numbers "
                           f"('Sequence,Volt,...,-6.0e-03,2.0e-06'), not '{','.join(second)}'") from None
    if not (increment_s > 0 and math.isfinite(increment_s) and math.isfinite(start_s)):
        raise CaptureError(f"{name}: line 2: Increment {second[at + 1]}: a sample interval > 0 s "
                           "is expected")
    units = [_unit_word(u) or "V" for u in second[1:at]]
    first_row = _line(lines, 2).decode("utf-8", "replace").strip()
    width = len(first_row.split(","))
    if width not in (len(channels) + 1, len(channels) + 2):
        raise CaptureError(f"{name}: line 3: {width} fields, expected the index and "
                           f"{len(channels)} values ({', '.join(channels)})")
    table = _table(lines, 2, width, name, b",", comment="#")
    if table.shape[0] < 2:
        raise CaptureError(f"{name}: line 3: fewer than 2 rows of samples")
    index = table[:, 0]
    jump = np.flatnonzero(np.diff(index) != 1)
    if jump.size:
        i = int(jump[0]) + 1
        raise CaptureError(f"{name}: line {_data_line(lines, 2, i, '#')}: sample index {index[i]:g} "
                           f"after {index[i - 1]:g}: the samples of one acquisition, one after another, "
                           "are expected")
    analog: dict[str, np.ndarray] = {}
    for k, channel in enumerate(channels, 1):
        col = table[:, k]
        if np.any(np.isnan(col)):
            i = int(np.flatnonzero(np.isnan(col))[0])
            raise CaptureError(f"{name}: line {_data_line(lines, 2, i, '#')}: {channel} is empty, "
                               "expected a number")
        analog[channel] = col.astype(np.float32)
    rate = 1.0 / increment_s
    block = SampleBlock(rate, (), np.zeros(0, np.uint8), analog)
    return Capture(name, block, dict(zip(channels, units, strict=True)), start_s + index[0] * increment_s,
                   "Rigol CSV")


def parse_tek_tds_csv(data: bytes, name: str) -> Capture:
    """An older Tektronix scope's CSV (TDS1000/2000, TPS2000, TBS1000: one file per channel, as
    the scope saves it to its USB stick, and as readers of such files on GitHub take it): the
    settings in the first three columns (``Record Length,2.500000e+03,``, ``Sample
    Interval,4.000000e-06,``, ``Source,CH1,``, ``Vertical Units,V,``, ``Horizontal Units,s,``...),
    the samples beside them in columns 4 and 5 (time, value) on every row."""
    rows = data.decode("utf-8", "replace").lstrip("\ufeff").split("\n")
    settings: dict[str, str] = {}
    times: list[str] = []
    values: list[str] = []
    line_of: list[int] = []
    for i, raw in enumerate(rows):
        text = raw.strip()
        if not text:
            continue
        fields = [f.strip() for f in text.split(",")]
        if len(fields) < 5:
            raise CaptureError(f"{name}: line {i + 1}: {len(fields)} fields, expected 5 (a setting, its "
                               "value, an empty column, the time and the value)")
        if fields[0]:
            settings.setdefault(fields[0].lower(), fields[1])
        if not (_numbers_like(fields[3]) and _numbers_like(fields[4])):
            raise CaptureError(f"{name}: line {i + 1}: '{fields[3]}', '{fields[4]}' in columns 4 and 5, "
                               "expected the time and the value (numbers)")
        times.append(fields[3])
        values.append(fields[4])
        line_of.append(i + 1)
    channel = settings.get("source", "") or "CH1"
    unit_s = _TIME_UNITS.get(settings.get("horizontal units", "s").lower())
    if unit_s is None:
        raise CaptureError(f"{name}: Horizontal Units '{settings.get('horizontal units')}' is not s, ms, "
                           "us or ns")
    t = np.array([float(x) for x in times]) * unit_s
    v = np.array([float(x) for x in values], np.float32)
    stated = settings.get("record length", "")
    if _numbers_like(stated) and round(float(stated)) != t.size:
        raise CaptureError(f"{name}: line {line_of[-1] if line_of else 1}: {t.size} samples, but Record "
                           f"Length says {stated}: the file is cut short or has more than one record")
    if t.size < 2:
        raise CaptureError(f"{name}: line 1: fewer than 2 samples")
    steps = np.diff(t)
    step = float(np.median(steps))
    off = np.abs(steps - step) > TIME_JITTER * step if step > 0 else np.ones(steps.size, bool)
    if np.any(off):
        i = int(np.flatnonzero(off)[0]) + 1
        raise CaptureError(f"{name}: line {line_of[i]}: time {t[i]:.9g} s after {t[i - 1]:.9g} s: off "
                           "the steady rate of the record")
    interval = settings.get("sample interval", "")
    rate = 1.0 / (float(interval) * unit_s) if _numbers_like(interval) and float(interval) > 0 else \
        float(f"{(t.size - 1) / (t[-1] - t[0]):.9g}")
    unit = _unit_word(settings.get("vertical units", "V")) or "V"
    block = SampleBlock(rate, (), np.zeros(0, np.uint8), {channel: v})
    return Capture(name, block, {channel: unit}, float(t[0]), "Tektronix TDS/TBS CSV")


def on_grid(capture: Capture, rate_hz: float, start_s: float, samples: int) -> Capture:
    """A capture of changes (:attr:`~.capture.Capture.changes`) sampled at another rate: ``samples``
    samples from ``start_s`` (the file's own time) at ``rate_hz``, each the state held at that
    instant (the first state before the capture starts, the last after its last change), so
    that it lines up with a capture of another instrument's rate (Saleae's analog export beside
    its digital one)."""
    if not capture.changes:
        raise ValueError(f"{capture.source}: samples at one rate, not changes: it is not put on another grid")
    block = capture.block
    t = start_s + np.arange(samples) / rate_hz
    index = np.floor((t - capture.start_s) * block.sample_rate_hz + 1e-6).astype(np.int64)
    index = np.clip(index, 0, block.samples - 1)
    logic = block.logic[index] if block.logic_channels else block.logic
    analog = {k: v[index] for k, v in block.analog.items()}
    moved = SampleBlock(rate_hz, block.logic_channels, logic, analog)
    form = f"{capture.form}, resampled at {_rate_text(float(f'{rate_hz:.9g}'))}"
    return Capture(capture.source, moved, capture.units, start_s, form, changes=True)
