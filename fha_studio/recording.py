"""The ``fha-recording/1`` file format: a recorded motion of one axis (reader and streaming writer).

A CSV file in UTF-8. First metadata lines ``# key: value``, then one header row of column names,
then numeric rows::

    # format: fha-recording/1
    # actuator: FHA-25C-50-US250
    # load_inertia_kgm2: 1.5
    # supply_voltage: 200
    # sample_rate_hz: 1000
    t,pos,current,cmd_pos
    0,0,0.012,0
    0.001,0.0002,0.35,0.0003

Metadata (units are in the key names; values are plain numbers):

- ``format`` (required): ``fha-recording/1``.
- ``actuator`` (required): a catalogue model code (e.g. ``FHA-25C-50-US250``) or ``custom``.
- ``load_inertia_kgm2`` (required): the load inertia the user declared [kg m^2].
- ``supply_voltage`` (optional, 200 or 100 [V], default 200).
- ``sample_rate_hz`` (optional) [Hz].
- with ``actuator: custom``: ``torque_constant_nm_per_a`` [N m/A] and ``actuator_inertia_kgm2``
  [kg m^2] are required, ``motor_turns_per_output_rev`` (the reduction ratio) is optional.
- any other key is kept as text in :attr:`RecordingMetadata.extra`.

Columns: ``t`` [s], ``pos`` [deg, output side from the motor encoder] and ``current`` [A, the
driver's current monitor] are required; ``cmd_pos`` [deg], ``load_pos`` [deg, external encoder on
the output], ``vel`` [r/min, output] and ``torque`` [N m, a torque sensor on the output flange,
positive = the flange driving the load CW] are optional; further columns are extra channels (the
writer's own signals) and are kept by name in :attr:`Recording.channels`.

**fha-recording/2** is the same file with ``# format: fha-recording/2``, in which ``current`` and
``load_inertia_kgm2`` are optional (a bench capture through CN2: the HA-655 has no current monitor
output). It also knows the column ``in_pos`` (the drive's IN-POS output, 1 = on). A writer writes
/2 only when one of the two is missing; ``fha-recording/1`` files read as before.

The file loads in plain numpy, e.g. ``np.genfromtxt(path, delimiter=",", comments="#")[1:]``
(the header row reads as NaN and is dropped) or ``np.loadtxt(path, delimiter=",", comments="#",
skiprows=...)``.

In the layers it sits beside :mod:`fha_studio.physics`, below the hardware layer (the simulated
drive records with it) and above the catalogue (which says whether an actuator exists). It
imports no Qt.
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import os
import re
import threading
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from fha_studio import fileio, plausible
from fha_studio.catalog import get_actuator
from fha_studio.fileio import FileProblem

FORMAT_ID = "fha-recording/1"
#: The second version: ``current`` and ``load_inertia_kgm2`` are optional (a bench capture of a
#: drive without a current monitor, of an axis whose load nobody declared). Written only when one
#: of them is absent, so a recording that has both stays an ``fha-recording/1`` file.
FORMAT_V2 = "fha-recording/2"
FORMATS = (FORMAT_ID, FORMAT_V2)

REQUIRED_COLUMNS = ("t", "pos", "current")
#: what a ``fha-recording/2`` file must have
REQUIRED_COLUMNS_V2 = ("t", "pos")
OPTIONAL_COLUMNS = ("cmd_pos", "load_pos", "vel", "in_pos", "torque")
CONTRACT_COLUMNS = ("t", "pos", "current", *OPTIONAL_COLUMNS)
#: unit of each contract column, as the format defines it (in_pos: 1 = the drive's IN-POS output on)
COLUMN_UNITS = {"t": "s", "pos": "deg", "current": "A", "cmd_pos": "deg", "load_pos": "deg", "vel": "r/min",
                "in_pos": "1 = on, 0 = off", "torque": "N m"}

# Numeric metadata keys (unit in the name) and the unit text a writer may append to the value.
_NUMERIC_KEYS = {
    "load_inertia_kgm2": ("kg m^2", "kgm2", "kg m2", "kg·m²", "kg·m^2", "kg*m^2"),
    "supply_voltage": ("v",),
    "sample_rate_hz": ("hz",),
    "torque_constant_nm_per_a": ("n m/a", "nm/a", "n·m/a"),
    "actuator_inertia_kgm2": ("kg m^2", "kgm2", "kg m2", "kg·m²", "kg·m^2", "kg*m^2"),
    "motor_turns_per_output_rev": (),
}
# Keys written without their unit: refused, telling the writer the key the format wants.
_UNITLESS_ALIASES = {
    "load_inertia": "load_inertia_kgm2",
    "inertia": "load_inertia_kgm2",
    "load_inertia_kg_m2": "load_inertia_kgm2",
    "sample_rate": "sample_rate_hz",
    "rate": "sample_rate_hz",
    "torque_constant": "torque_constant_nm_per_a",
    "kt": "torque_constant_nm_per_a",
    "actuator_inertia": "actuator_inertia_kgm2",
    "voltage": "supply_voltage",
}
_CUSTOM_REQUIRED = ("torque_constant_nm_per_a", "actuator_inertia_kgm2")
_KEY_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_COLUMN_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
# FHA-<frame>C-<ratio>-<encoder>[-options]: the shape of a model code (the catalogue decides if it exists).
_MODEL_CODE_RE = re.compile(r"^FHA-(17|25|32|40)C-(50|100|160)-(US250|S248)(-[A-Z0-9]+)*$")
# A number in a recording: a plain decimal with an optional exponent, ASCII only. What Python's
# float() accepts beyond that ("1_0", "inf", "nan", " ١ ") is not a number in a CSV file.
_NUMBER = r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?"
_NUMBER_RE = re.compile(_NUMBER)
NUMBER_SHAPE = "a number (a plain decimal like 12, -0.5 or 1.5e-3)"
#: What a recording file may weigh: about an hour at 1 kHz with six columns. Reading is bounded by
#: it, and the parsed arrays take about a quarter of it in memory.
MAX_RECORDING_BYTES = 256 * 1024 * 1024
#: A declared sample_rate_hz and the time column must agree to this fraction (median step).
SAMPLE_RATE_TOLERANCE = 0.1
# plausible range of each numeric metadata key (fha_studio.plausible states why)
_RANGES = {
    "load_inertia_kgm2": plausible.LOAD_INERTIA_KGM2,
    "sample_rate_hz": plausible.SAMPLE_RATE_HZ,
    "torque_constant_nm_per_a": plausible.TORQUE_CONSTANT_NM_PER_A,
    "actuator_inertia_kgm2": plausible.ACTUATOR_INERTIA_KGM2,
    "motor_turns_per_output_rev": plausible.MOTOR_TURNS_PER_OUTPUT_REV,
}


class RecordingError(ValueError):
    """A malformed recording. ``line`` (1-based, or None) and ``field`` name where and what."""

    def __init__(self, message: str, *, source: str = "", line: int | None = None, field: str | None = None):
        self.source = source
        self.line = line
        self.field = field
        self.reason = message
        where = source or "recording"
        if line is not None:
            where += f" line {line}"
        if field is not None:
            where += f", field '{field}'"
        super().__init__(f"{where}: {message}")


@dataclass(frozen=True)
class RecordingMetadata:
    """The ``# key: value`` lines of a recording, typed. Units are in the names."""

    actuator: str
    load_inertia_kgm2: float | None  # None: not declared (fha-recording/2 only)
    supply_voltage: int = 200
    sample_rate_hz: float | None = None
    torque_constant_nm_per_a: float | None = None
    actuator_inertia_kgm2: float | None = None
    motor_turns_per_output_rev: float | None = None
    extra: Mapping[str, str] = field(default_factory=dict)

    @property
    def is_custom(self) -> bool:
        """True for ``actuator: custom`` (constants given in the file, not from the catalogue)."""
        return self.actuator == "custom"

    def format_for(self, columns: Sequence[str] = REQUIRED_COLUMNS) -> str:
        """The version a file of these columns is written in: ``fha-recording/1`` unless the
        current or the load inertia is missing."""
        if self.load_inertia_kgm2 is None or "current" not in columns:
            return FORMAT_V2
        return FORMAT_ID

    def lines(self, columns: Sequence[str] = REQUIRED_COLUMNS) -> list[str]:
        """The metadata as ``# key: value`` lines (without newline), in the format's order, for a
        file of ``columns``."""
        out = [f"# format: {self.format_for(columns)}", f"# actuator: {self.actuator}"]
        if self.load_inertia_kgm2 is not None:
            out.append(f"# load_inertia_kgm2: {_num(self.load_inertia_kgm2)}")
        out.append(f"# supply_voltage: {int(self.supply_voltage)}")
        for key in ("sample_rate_hz", "torque_constant_nm_per_a", "actuator_inertia_kgm2",
                    "motor_turns_per_output_rev"):
            value = getattr(self, key)
            if value is not None:
                out.append(f"# {key}: {_num(value)}")
        for key, value in self.extra.items():
            out.append(f"# {key}: {value}")
        return out


@dataclass(frozen=True)
class Recording:
    """A parsed recording: typed metadata and one float64 array per column (same length)."""

    metadata: RecordingMetadata
    channels: Mapping[str, np.ndarray]
    source: str = ""

    @property
    def t_s(self) -> np.ndarray:
        """Time [s], strictly increasing."""
        return self.channels["t"]

    @property
    def pos_deg(self) -> np.ndarray:
        """Output position from the motor encoder [deg]."""
        return self.channels["pos"]

    def with_declared_load(self, load_inertia_kgm2: float) -> Recording:
        """The same recording with the axis's declared load inertia (a bench capture declares none:
        the technician knows it)."""
        metadata = dataclasses.replace(self.metadata, load_inertia_kgm2=float(load_inertia_kgm2))
        return dataclasses.replace(self, metadata=metadata)

    @property
    def has_current(self) -> bool:
        """True when the recording measured the motor current (always in fha-recording/1)."""
        return "current" in self.channels

    @property
    def current_a(self) -> np.ndarray:
        """Motor current as the driver's monitor reports it [A]; RecordingError when the
        recording has none (see :attr:`has_current`)."""
        if "current" not in self.channels:
            raise RecordingError("no current column: this recording did not measure the motor current",
                                 source=self.source, field="current")
        return self.channels["current"]

    @property
    def in_pos(self) -> np.ndarray | None:
        """The drive's IN-POS output (1 = on), or None when not recorded."""
        return self.channels.get("in_pos")

    @property
    def cmd_pos_deg(self) -> np.ndarray | None:
        """Commanded output position [deg], or None when not recorded."""
        return self.channels.get("cmd_pos")

    @property
    def load_pos_deg(self) -> np.ndarray | None:
        """Output position from an external encoder [deg], or None when not recorded."""
        return self.channels.get("load_pos")

    @property
    def vel_rpm(self) -> np.ndarray | None:
        """Output speed [r/min], or None when not recorded."""
        return self.channels.get("vel")

    @property
    def extra_channels(self) -> dict[str, np.ndarray]:
        """The columns beyond the format's contract, by name."""
        return {k: v for k, v in self.channels.items() if k not in CONTRACT_COLUMNS}

    def __len__(self) -> int:
        return len(self.channels["t"])

    @property
    def duration_s(self) -> float:
        """Time from the first to the last sample [s]."""
        t = self.t_s
        return float(t[-1] - t[0]) if len(t) else 0.0

    def slice(self, start: int, stop: int) -> Recording:
        """The rows ``start:stop`` as a new recording (same metadata)."""
        return Recording(self.metadata, {k: v[start:stop] for k, v in self.channels.items()}, self.source)


# ----------------------------------------------------------------------------------------- reading


def read_recording(path: str | os.PathLike, *, check_actuator: bool = True) -> Recording:
    """Read and check an ``fha-recording/1`` file. Raises :class:`RecordingError` naming line and field.

    ``check_actuator`` looks the model code up in the catalogue (unknown codes are refused).
    """
    try:
        text = fileio.read_text(path, limit_bytes=MAX_RECORDING_BYTES)
    except FileProblem as exc:
        raise RecordingError(exc.reason, source=exc.path) from None
    return parse_recording(text, source=os.fspath(path), check_actuator=check_actuator)


def parse_recording(text: str, *, source: str = "", check_actuator: bool = True) -> Recording:
    """Parse the text of a recording; see :func:`read_recording`."""
    lines = text.splitlines()
    meta_raw: dict[str, tuple[str, int]] = {}
    header_index = None
    for index, raw in enumerate(lines):
        line = raw.strip()
        if index == 0 and line.startswith("\ufeff"):
            line = line[1:]
        if not line:
            continue
        if line.startswith("#"):
            body = line[1:].strip()
            if ":" not in body:
                continue  # a plain comment
            key, _, value = body.partition(":")
            key, value = key.strip(), value.strip()
            if not _KEY_RE.match(key):
                continue  # free text that happens to contain a colon
            if key in meta_raw:
                raise RecordingError(
                    f"metadata key given twice (first on line {meta_raw[key][1]})",
                    source=source, line=index + 1, field=key)
            meta_raw[key] = (value, index + 1)
            continue
        header_index = index
        break
    if "format" not in meta_raw:
        raise RecordingError(f"missing metadata line '# format: {FORMAT_ID}'", source=source,
                             line=1, field="format")
    fmt, fmt_line = meta_raw["format"]
    if fmt not in FORMATS:
        raise RecordingError(f"format is '{fmt}', expected '{FORMAT_ID}' or '{FORMAT_V2}'", source=source,
                             line=fmt_line, field="format")
    metadata = _parse_metadata(meta_raw, source, check_actuator)
    if header_index is None:
        raise RecordingError("no header row (column names) after the metadata", source=source,
                             line=len(lines) + 1, field="header")
    columns = _parse_header(lines[header_index], header_index + 1, source, fmt)
    data = _parse_rows(lines, header_index + 1, columns, source)
    channels = {name: data[:, i].copy() for i, name in enumerate(columns)}
    _check_time(channels["t"], lines=lines, start=header_index + 1, source=source)
    if "sample_rate_hz" in meta_raw:
        _check_rate(channels["t"], metadata.sample_rate_hz, meta_raw["sample_rate_hz"][1], source)
    return Recording(metadata, channels, source)


def _parse_metadata(raw: dict[str, tuple[str, int]], source: str, check_actuator: bool) -> RecordingMetadata:
    version = raw.get("format", (FORMAT_ID, 0))[0]
    for alias, proper in _UNITLESS_ALIASES.items():
        if alias in raw:
            raise RecordingError(f"metadata key has no unit: write '{proper}' ({_unit_of(proper)})",
                                 source=source, line=raw[alias][1], field=alias)
    missing_line = max((ln for _, ln in raw.values()), default=0) + 1
    if "actuator" not in raw:
        raise RecordingError("missing metadata '# actuator: <model code>' (or 'custom')", source=source,
                             line=missing_line, field="actuator")
    actuator, actuator_line = raw["actuator"]
    if "load_inertia_kgm2" not in raw and version != FORMAT_V2:
        raise RecordingError("missing metadata '# load_inertia_kgm2: <declared load inertia>'",
                             source=source, line=missing_line, field="load_inertia_kgm2")
    values: dict[str, float] = {}
    for key in _NUMERIC_KEYS:
        if key in raw:
            text, line = raw[key]
            values[key] = _parse_number(key, text, line, source)
    for key, value in values.items():
        if key in _RANGES and not _RANGES[key].contains(value):
            raise RecordingError(f"{_num(value)} is outside the plausible range {_RANGES[key].allowed()} "
                                 f"({_RANGES[key].reason})", source=source, line=raw[key][1], field=key)
    supply = values.get("supply_voltage", 200.0)
    if supply not in (100.0, 200.0):
        raise RecordingError(f"supply_voltage is {_num(supply)}; the drivers run on 200 or 100 (V)",
                             source=source, line=raw["supply_voltage"][1], field="supply_voltage")
    if actuator == "custom":
        for key in _CUSTOM_REQUIRED:
            if key not in values:
                raise RecordingError(f"'actuator: custom' requires '# {key}: <value>' ({_unit_of(key)})",
                                     source=source, line=actuator_line, field=key)
    else:
        _check_model_code(actuator, actuator_line, source, check_actuator)
    known = set(_NUMERIC_KEYS) | {"format", "actuator"}
    extra = {k: v for k, (v, _) in raw.items() if k not in known}
    return RecordingMetadata(
        actuator=actuator,
        load_inertia_kgm2=values.get("load_inertia_kgm2"),
        supply_voltage=int(supply),
        sample_rate_hz=values.get("sample_rate_hz"),
        torque_constant_nm_per_a=values.get("torque_constant_nm_per_a"),
        actuator_inertia_kgm2=values.get("actuator_inertia_kgm2"),
        motor_turns_per_output_rev=values.get("motor_turns_per_output_rev"),
        extra=extra,
    )


def _check_model_code(code: str, line: int, source: str, check_actuator: bool) -> None:
    if not _MODEL_CODE_RE.match(code):
        raise RecordingError(
            f"'{code}' is not an FHA-C model code (like FHA-25C-50-US250) nor 'custom'",
            source=source, line=line, field="actuator")
    if not check_actuator:
        return
    try:
        get_actuator(code)  # the catalogue decides whether it exists
    except (ValueError, KeyError, LookupError) as exc:
        raise RecordingError(f"unknown actuator '{code}': {exc}", source=source, line=line,
                             field="actuator") from None


def _unit_of(key: str) -> str:
    return {"load_inertia_kgm2": "kg m^2", "actuator_inertia_kgm2": "kg m^2", "sample_rate_hz": "Hz",
            "torque_constant_nm_per_a": "N m/A", "supply_voltage": "V",
            "motor_turns_per_output_rev": "motor turns per output turn"}.get(key, "")


def _parse_number(key: str, text: str, line: int, source: str) -> float:
    if not text:
        raise RecordingError("no value", source=source, line=line, field=key)
    number_text, _, unit = text.partition(" ")
    unit = unit.strip().lower()
    if unit and unit not in _NUMERIC_KEYS[key]:
        raise RecordingError(
            f"value '{text}' is not a number in {_unit_of(key)} (the unit is in the key name; "
            "write the number only)", source=source, line=line, field=key)
    if not _NUMBER_RE.fullmatch(number_text):
        raise RecordingError(f"value '{_clip(text)}' is not {NUMBER_SHAPE}", source=source, line=line,
                             field=key)
    value = float(number_text)
    if not math.isfinite(value):
        raise RecordingError(f"value '{_clip(text)}' is too large to be a number", source=source,
                             line=line, field=key)
    return value


def _clip(text: str, width: int = 40) -> str:
    """A cell or value as shown in a message: one line, not too long."""
    text = text.replace("\n", " ").replace("\r", " ")
    return text if len(text) <= width else text[: width - 1] + "…"


def _parse_header(line: str, line_no: int, source: str, version: str = FORMAT_ID) -> list[str]:
    names = [name.strip() for name in line.split(",")]
    seen: set[str] = set()
    for name in names:
        if not _COLUMN_RE.fullmatch(name) or len(name) > 64:
            raise RecordingError(f"column name '{_clip(name)}' is not a name (letters, digits, '_', "
                                 "at most 64)", source=source, line=line_no,
                                 field=_clip(name, 20) if name else "header")
        if name in seen:
            raise RecordingError("column given twice", source=source, line=line_no, field=name)
        seen.add(name)
    for name in REQUIRED_COLUMNS_V2 if version == FORMAT_V2 else REQUIRED_COLUMNS:
        if name not in seen:
            raise RecordingError(
                f"required column '{name}' ({COLUMN_UNITS[name]}) is missing; "
                f"the header has {', '.join(names)}",
                source=source, line=line_no, field=name)
    return names


def _data_line_numbers(lines: Sequence[str], start: int) -> list[int]:
    return [i + 1 for i in range(start, len(lines))
            if lines[i].strip() and not lines[i].lstrip().startswith("#")]


def _parse_rows(lines: Sequence[str], start: int, columns: list[str], source: str) -> np.ndarray:
    rows: list[list[float]] = []
    width = len(columns)
    cell = rf"[ \t]*{_NUMBER}[ \t]*"
    row_re = re.compile(cell + rf"(?:,{cell}){{{width - 1}}}")
    # the usual file, every data line a row of finite numbers, in whole-list passes (no Python loop
    # per line; a 20 s recording at 1 kHz is 20 000 lines); any other goes line by line below, which
    # names the line and field of the first fault
    data = [line for line in map(str.strip, lines[start:]) if line and not line.startswith("#")]
    if len(data) >= 2 and all(map(row_re.fullmatch, data)):
        values = np.array(list(map(float, ",".join(data).split(","))), dtype=np.float64).reshape(-1, width)
        if np.isfinite(values).all():
            return values
    for index in range(start, len(lines)):
        line = lines[index].strip()
        if not line or line.startswith("#"):
            continue
        cells = line.split(",")
        if len(cells) != width:
            raise RecordingError(f"{len(cells)} values, the header has {width} columns",
                                 source=source, line=index + 1, field=None)
        if not row_re.fullmatch(line):
            for name, text in zip(columns, cells, strict=True):
                if not _NUMBER_RE.fullmatch(text.strip(" \t")):
                    raise RecordingError(f"'{_clip(text.strip())}' is not {NUMBER_SHAPE}", source=source,
                                         line=index + 1, field=name)
        row = [float(c) for c in cells]
        for name, value in zip(columns, row, strict=True):
            if not math.isfinite(value):
                raise RecordingError("the number is too large", source=source, line=index + 1,
                                     field=name)
        rows.append(row)
    if len(rows) < 2:
        raise RecordingError(f"{len(rows)} data rows; a recording needs at least 2", source=source,
                             line=len(lines) + 1, field=None)
    return np.asarray(rows, dtype=np.float64)


def _check_time(t: np.ndarray, *, lines: Sequence[str], start: int, source: str) -> None:
    # the data rows' line numbers are counted only for a message (a pass over every line)
    steps = np.diff(t)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise RecordingError(f"time does not increase ({_num(t[i - 1])} then {_num(t[i])} s)",
                             source=source, line=_data_line_numbers(lines, start)[i], field="t")
    if not math.isfinite(float(t[-1] - t[0])):
        raise RecordingError("the time span is too large to compute with", source=source,
                             line=_data_line_numbers(lines, start)[-1], field="t")


def _check_rate(t: np.ndarray, rate_hz: float | None, line: int, source: str) -> None:
    """The declared sample rate and the time column must agree (a time column in milliseconds
    with ``sample_rate_hz: 1000`` would make every rate, inertia and delay wrong by 1000)."""
    if rate_hz is None:
        return
    step_s = float(np.median(np.diff(t)))
    expected_s = 1.0 / rate_hz
    if abs(step_s / expected_s - 1.0) > SAMPLE_RATE_TOLERANCE:
        raise RecordingError(
            f"sample_rate_hz is {_num(rate_hz)} (a sample every {_num(expected_s, 6)} s), but the time "
            f"column 't' steps by {_num(step_s, 6)} s (median): they contradict each other; 't' must "
            "be in seconds, and sample_rate_hz must match it (or be left out)",
            source=source, line=line, field="sample_rate_hz")


# ----------------------------------------------------------------------------------------- writing


def _num(value: float, digits: int = 12) -> str:
    return format(float(value), f".{digits}g")


class RecordingWriter:
    """Streaming writer: append rows as they come; they reach the disk within a second.

    ``columns`` are the column names in file order: the required ``t, pos, current`` first, then any
    of the optional contract columns and extra channels. Rows are checked as they are appended
    (finite, time increasing) and the metadata as the writer starts, so the writer never produces
    a file the reader refuses.

    While recording the file is ``PATH.partial`` (:class:`fha_studio.fileio.PartialFile`);
    :meth:`close` renames it to ``PATH``. A thread writes what was appended every
    ``FLUSH_INTERVAL_S`` whether or not more rows come, in whole rows: a process killed while
    recording leaves ``PATH.partial``, readable, missing at most the last ``FLUSH_INTERVAL_S`` of
    rows. A failed write (disk full) is raised by the next :meth:`append` or by :meth:`close`,
    and the file never ends in half a row. Use as a context manager or call :meth:`close`.
    """

    FLUSH_INTERVAL_S = 1.0

    def __init__(self, path: str | os.PathLike, metadata: RecordingMetadata,
                 columns: Sequence[str] = REQUIRED_COLUMNS, *, digits: int = 12):
        columns = list(columns)
        lines = metadata.lines(columns)
        _parse_header(",".join(columns), 0, "new recording", metadata.format_for(columns))  # as the reader
        for line in lines:
            if "\n" in line or "\r" in line:
                raise ValueError(f"metadata line contains a line break: {line!r}")
        _check_metadata_lines(lines)
        self.columns = tuple(columns)
        self._digits = digits
        self._format = ",".join([f"{{:.{digits}g}}"] * len(columns)) + "\n"
        self._t_index = self.columns.index("t")
        self._last_t = -math.inf
        self._rows = 0
        self._lock = threading.Lock()
        self._pending: list[str] = []
        self._error: FileProblem | None = None
        self._out: fileio.PartialFile | None = fileio.PartialFile(path)
        self.path = self._out.path
        self.partial_path = self._out.partial_path
        self._pending.append("\n".join(lines) + "\n" + ",".join(columns) + "\n")
        try:
            self._write_pending()  # a file that cannot be written is known now, not later
        except FileProblem:
            self._out.abandon()
            _remove_quietly(self.partial_path)
            raise
        self._last_flush = time.monotonic()
        self._stop = threading.Event()
        self._flusher = threading.Thread(target=self._flush_on_time, name="recording-flush", daemon=True)
        self._flusher.start()

    @property
    def rows_written(self) -> int:
        """Number of data rows appended so far."""
        return self._rows

    def append(self, row: Sequence[float] | Mapping[str, float]) -> None:
        """Append one row (a sequence in column order, or a mapping by column name)."""
        if isinstance(row, Mapping):
            missing = [c for c in self.columns if c not in row]
            if missing:
                raise ValueError(f"row lacks column(s) {', '.join(missing)}")
            row = [row[c] for c in self.columns]
        self.append_rows(np.asarray(row, dtype=np.float64).reshape(1, -1))

    def append_rows(self, rows: np.ndarray | Iterable[Sequence[float]]) -> None:
        """Append a block of rows (shape ``(n, len(columns))``)."""
        if self._out is None:
            raise ValueError("recording writer is closed")
        if self._error is not None:
            raise self._error
        block = np.asarray(rows, dtype=np.float64)
        if block.ndim != 2 or block.shape[1] != len(self.columns):
            raise ValueError(f"rows must have {len(self.columns)} values ({', '.join(self.columns)}), "
                             f"got shape {block.shape}")
        if block.size == 0:
            return
        if not np.all(np.isfinite(block)):
            r, c = np.argwhere(~np.isfinite(block))[0]
            raise ValueError(f"row {self._rows + int(r)}: column '{self.columns[c]}' is not finite")
        t = block[:, self._t_index]
        if t[0] <= self._last_t or np.any(np.diff(t) <= 0):
            raise ValueError(f"time must increase (last written {self._last_t} s)")
        text = "".join(self._format.format(*r) for r in block.tolist())
        with self._lock:
            self._pending.append(text)
        self._last_t = float(t[-1])
        self._rows += len(block)
        if time.monotonic() - self._last_flush >= self.FLUSH_INTERVAL_S:
            self.flush()

    def _write_pending(self) -> None:
        # whole rows in one unbuffered write: the file on disk always ends with a whole row
        with self._lock:
            if not self._pending or self._out is None:
                return
            data = "".join(self._pending).encode("utf-8")
            self._pending = []
            self._out.write(data)

    def _flush_on_time(self) -> None:
        while not self._stop.wait(self.FLUSH_INTERVAL_S):
            try:
                self._write_pending()
            except FileProblem as exc:
                self._error = exc
                return
            self._last_flush = time.monotonic()

    def flush(self) -> None:
        """Push everything appended so far to the file now."""
        if self._error is not None:
            raise self._error
        try:
            self._write_pending()
        except FileProblem as exc:
            self._error = exc
            raise
        self._last_flush = time.monotonic()

    def close(self) -> None:
        """Write what is left, and rename the ``.partial`` file to the final name (idempotent).
        A write that failed is raised here; the rows written before it stay in ``PATH.partial``."""
        if self._out is None:
            return
        self._stop.set()
        if self._flusher is not threading.current_thread():
            self._flusher.join()
        try:
            if self._error is not None:
                raise self._error
            self._write_pending()
            self._out.commit()
        finally:
            if self._out is not None:
                self._out.abandon()
            self._out = None

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):  # pragma: no cover - a writer dropped without close keeps its .partial file
        stop = getattr(self, "_stop", None)
        if stop is not None:
            stop.set()
        out = getattr(self, "_out", None)
        if out is not None:
            out.abandon()


def _remove_quietly(path: Path) -> None:
    with contextlib.suppress(OSError):
        path.unlink()


def _check_metadata_lines(lines: Sequence[str]) -> None:
    """The reader's metadata checks on what a writer is about to write (ValueError if refused)."""
    raw: dict[str, tuple[str, int]] = {}
    for number, line in enumerate(lines, 1):
        key, _, value = line[1:].strip().partition(":")
        raw[key.strip()] = (value.strip(), number)
    _parse_metadata(raw, "new recording", check_actuator=False)


def write_recording(path: str | os.PathLike, recording: Recording, *, digits: int = 12) -> None:
    """Write a whole recording at once (contract columns first, then the extra channels)."""
    columns = [c for c in CONTRACT_COLUMNS if c in recording.channels]
    columns += [c for c in recording.channels if c not in CONTRACT_COLUMNS]
    block = np.column_stack([recording.channels[c] for c in columns])
    with RecordingWriter(path, recording.metadata, columns, digits=digits) as writer:
        writer.append_rows(block)


def make_recording(metadata: RecordingMetadata, **channels: np.ndarray) -> Recording:
    """Build a recording in memory from arrays (t, pos required; current too unless the recording
    is an fha-recording/2 one), checked like a read file."""
    for name in REQUIRED_COLUMNS_V2:
        if name not in channels:
            raise RecordingError(f"required column '{name}' is missing", field=name)
    arrays = {k: np.asarray(v, dtype=np.float64).ravel() for k, v in channels.items()}
    n = len(arrays["t"])
    for name, values in arrays.items():
        if not _COLUMN_RE.match(name):
            raise RecordingError("not a column name", field=name)
        if len(values) != n:
            raise RecordingError(f"{len(values)} values, 't' has {n}", field=name)
        if not np.all(np.isfinite(values)):
            row = int(np.flatnonzero(~np.isfinite(values))[0])
            raise RecordingError(f"not finite at row {row}", field=name)
    if n < 2:
        raise RecordingError("a recording needs at least 2 rows", field="t")
    bad = np.flatnonzero(np.diff(arrays["t"]) <= 0)
    if bad.size:
        raise RecordingError(f"time does not increase at row {int(bad[0]) + 1}", field="t")
    return Recording(metadata, arrays)
