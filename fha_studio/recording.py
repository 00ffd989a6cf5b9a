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
the output] and ``vel`` [r/min, output] are optional; further columns are extra channels (the
writer's own signals) and are kept by name in :attr:`Recording.channels`.

The file loads in plain numpy, e.g. ``np.genfromtxt(path, delimiter=",", comments="#")[1:]``
(the header row reads as NaN and is dropped) or ``np.loadtxt(path, delimiter=",", comments="#",
skiprows=...)``.

In the layers it sits beside :mod:`fha_studio.physics`, below the hardware layer (the simulated
drive records with it) and above the catalogue (which says whether an actuator exists). It
imports no Qt.
"""

from __future__ import annotations

import math
import os
import re
import time
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TextIO

import numpy as np

from fha_studio.catalog import get_actuator

FORMAT_ID = "fha-recording/1"

REQUIRED_COLUMNS = ("t", "pos", "current")
OPTIONAL_COLUMNS = ("cmd_pos", "load_pos", "vel")
CONTRACT_COLUMNS = REQUIRED_COLUMNS + OPTIONAL_COLUMNS
#: unit of each contract column, as the format defines it
COLUMN_UNITS = {"t": "s", "pos": "deg", "current": "A", "cmd_pos": "deg", "load_pos": "deg", "vel": "r/min"}

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
    load_inertia_kgm2: float
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

    def lines(self) -> list[str]:
        """The metadata as ``# key: value`` lines (without newline), in the format's order."""
        out = [f"# format: {FORMAT_ID}", f"# actuator: {self.actuator}"]
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

    @property
    def current_a(self) -> np.ndarray:
        """Motor current as the driver's monitor reports it [A]."""
        return self.channels["current"]

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
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as exc:
        raise RecordingError(f"not UTF-8 text ({exc.reason} at byte {exc.start})", source=str(path)) from None
    return parse_recording(text, source=str(path), check_actuator=check_actuator)


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
    if fmt != FORMAT_ID:
        raise RecordingError(f"format is '{fmt}', expected '{FORMAT_ID}'", source=source,
                             line=fmt_line, field="format")
    metadata = _parse_metadata(meta_raw, source, check_actuator)
    if header_index is None:
        raise RecordingError("no header row (column names) after the metadata", source=source,
                             line=len(lines) + 1, field="header")
    columns = _parse_header(lines[header_index], header_index + 1, source)
    data = _parse_rows(lines, header_index + 1, columns, source)
    channels = {name: data[:, i].copy() for i, name in enumerate(columns)}
    _check_time(channels["t"], data_line_numbers=_data_line_numbers(lines, header_index + 1), source=source)
    return Recording(metadata, channels, source)


def _parse_metadata(raw: dict[str, tuple[str, int]], source: str, check_actuator: bool) -> RecordingMetadata:
    for alias, proper in _UNITLESS_ALIASES.items():
        if alias in raw:
            raise RecordingError(f"metadata key has no unit: write '{proper}' ({_unit_of(proper)})",
                                 source=source, line=raw[alias][1], field=alias)
    missing_line = max((ln for _, ln in raw.values()), default=0) + 1
    if "actuator" not in raw:
        raise RecordingError("missing metadata '# actuator: <model code>' (or 'custom')", source=source,
                             line=missing_line, field="actuator")
    actuator, actuator_line = raw["actuator"]
    if "load_inertia_kgm2" not in raw:
        raise RecordingError("missing metadata '# load_inertia_kgm2: <declared load inertia>'",
                             source=source, line=missing_line, field="load_inertia_kgm2")
    values: dict[str, float] = {}
    for key in _NUMERIC_KEYS:
        if key in raw:
            text, line = raw[key]
            values[key] = _parse_number(key, text, line, source)
    if values["load_inertia_kgm2"] < 0:
        raise RecordingError("the load inertia cannot be negative", source=source,
                             line=raw["load_inertia_kgm2"][1], field="load_inertia_kgm2")
    supply = values.get("supply_voltage", 200.0)
    if supply not in (100.0, 200.0):
        raise RecordingError(f"supply_voltage is {_num(supply)}; the drivers run on 200 or 100 (V)",
                             source=source, line=raw["supply_voltage"][1], field="supply_voltage")
    if "sample_rate_hz" in values and values["sample_rate_hz"] <= 0:
        raise RecordingError("sample_rate_hz must be positive", source=source,
                             line=raw["sample_rate_hz"][1], field="sample_rate_hz")
    if actuator == "custom":
        for key in _CUSTOM_REQUIRED:
            if key not in values:
                raise RecordingError(f"'actuator: custom' requires '# {key}: <value>' ({_unit_of(key)})",
                                     source=source, line=actuator_line, field=key)
            if values[key] <= 0:
                raise RecordingError(f"{key} must be positive", source=source, line=raw[key][1], field=key)
        if "motor_turns_per_output_rev" in values and values["motor_turns_per_output_rev"] <= 0:
            key = "motor_turns_per_output_rev"
            raise RecordingError(f"{key} must be positive", source=source, line=raw[key][1], field=key)
    else:
        _check_model_code(actuator, actuator_line, source, check_actuator)
    known = set(_NUMERIC_KEYS) | {"format", "actuator"}
    extra = {k: v for k, (v, _) in raw.items() if k not in known}
    return RecordingMetadata(
        actuator=actuator,
        load_inertia_kgm2=values["load_inertia_kgm2"],
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
    try:
        value = float(number_text)
    except ValueError:
        raise RecordingError(f"value '{text}' is not a number", source=source, line=line, field=key) from None
    if not math.isfinite(value):
        raise RecordingError(f"value '{text}' is not finite", source=source, line=line, field=key)
    return value


def _parse_header(line: str, line_no: int, source: str) -> list[str]:
    names = [name.strip() for name in line.split(",")]
    seen: set[str] = set()
    for name in names:
        if not _COLUMN_RE.match(name):
            raise RecordingError(f"column name '{name}' is not a name (letters, digits, '_')",
                                 source=source, line=line_no, field=name or "header")
        if name in seen:
            raise RecordingError("column given twice", source=source, line=line_no, field=name)
        seen.add(name)
    for name in REQUIRED_COLUMNS:
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
    for index in range(start, len(lines)):
        line = lines[index].strip()
        if not line or line.startswith("#"):
            continue
        cells = line.split(",")
        if len(cells) != width:
            raise RecordingError(f"{len(cells)} values, the header has {width} columns",
                                 source=source, line=index + 1, field=None)
        try:
            row = [float(c) for c in cells]
        except ValueError:
            for name, cell in zip(columns, cells, strict=True):
                try:
                    float(cell)
                except ValueError:
                    raise RecordingError(f"'{cell.strip()}' is not a number", source=source,
                                         line=index + 1, field=name) from None
            raise  # pragma: no cover - one of the cells failed above
        for name, value in zip(columns, row, strict=True):
            if not math.isfinite(value):
                raise RecordingError(f"'{value}' is not a finite number (NaN or infinity)",
                                     source=source, line=index + 1, field=name)
        rows.append(row)
    if len(rows) < 2:
        raise RecordingError(f"{len(rows)} data rows; a recording needs at least 2", source=source,
                             line=len(lines) + 1, field=None)
    return np.asarray(rows, dtype=np.float64)


def _check_time(t: np.ndarray, *, data_line_numbers: list[int], source: str) -> None:
    steps = np.diff(t)
    bad = np.flatnonzero(steps <= 0)
    if bad.size:
        i = int(bad[0]) + 1
        raise RecordingError(f"time does not increase ({_num(t[i - 1])} then {_num(t[i])} s)",
                             source=source, line=data_line_numbers[i], field="t")


# ----------------------------------------------------------------------------------------- writing


def _num(value: float, digits: int = 12) -> str:
    return format(float(value), f".{digits}g")


class RecordingWriter:
    """Streaming writer: append rows as they come; the file is flushed at least once per second.

    ``columns`` are the column names in file order: the required ``t, pos, current`` first, then any
    of the optional contract columns and extra channels. Rows are checked as they are appended
    (finite, time increasing) so the writer never produces a file the reader refuses.
    Use as a context manager or call :meth:`close`.
    """

    FLUSH_INTERVAL_S = 1.0

    def __init__(self, path: str | os.PathLike, metadata: RecordingMetadata,
                 columns: Sequence[str] = REQUIRED_COLUMNS, *, digits: int = 12):
        columns = list(columns)
        _parse_header(",".join(columns), 0, "new recording")  # same rules as the reader
        for line in metadata.lines():
            if "\n" in line or "\r" in line:
                raise ValueError(f"metadata line contains a line break: {line!r}")
        self.path = Path(path)
        self.columns = tuple(columns)
        self._digits = digits
        self._format = ",".join([f"{{:.{digits}g}}"] * len(columns)) + "\n"
        self._t_index = self.columns.index("t")
        self._last_t = -math.inf
        self._rows = 0
        self._file: TextIO | None = self.path.open("w", encoding="utf-8", newline="\n")
        self._file.write("\n".join(metadata.lines()) + "\n" + ",".join(columns) + "\n")
        self._flush()

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
        if self._file is None:
            raise ValueError("recording writer is closed")
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
        self._file.write("".join(self._format.format(*r) for r in block.tolist()))
        self._last_t = float(t[-1])
        self._rows += len(block)
        if time.monotonic() - self._last_flush >= self.FLUSH_INTERVAL_S:
            self._flush()

    def _flush(self) -> None:
        assert self._file is not None
        self._file.flush()
        self._last_flush = time.monotonic()

    def flush(self) -> None:
        """Push everything appended so far to the file now."""
        if self._file is not None:
            self._flush()

    def close(self) -> None:
        """Flush and close (idempotent)."""
        if self._file is not None:
            self._file.flush()
            os.fsync(self._file.fileno())
            self._file.close()
            self._file = None

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def __del__(self):  # pragma: no cover - a writer dropped without close
        file = getattr(self, "_file", None)
        if file is not None:
            file.close()


def write_recording(path: str | os.PathLike, recording: Recording, *, digits: int = 12) -> None:
    """Write a whole recording at once (contract columns first, then the extra channels)."""
    columns = [c for c in CONTRACT_COLUMNS if c in recording.channels]
    columns += [c for c in recording.channels if c not in CONTRACT_COLUMNS]
    block = np.column_stack([recording.channels[c] for c in columns])
    with RecordingWriter(path, recording.metadata, columns, digits=digits) as writer:
        writer.append_rows(block)


def make_recording(metadata: RecordingMetadata, **channels: np.ndarray) -> Recording:
    """Build a recording in memory from arrays (t, pos, current required), checked like a read file."""
    for name in REQUIRED_COLUMNS:
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
