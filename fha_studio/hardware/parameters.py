"""The HA-655 / HA-675 driver's items (monitor, tune, parameter, test mode) and alarms, as typed data.

The data lives in ``resources/drive/`` (TOML, with the manual's section beside each item); this
module only reads and checks it. Values travel on the wire as integers (docs/protocol.md); an
item's ``scale`` converts: ``value_in_unit = wire * scale``.

What the public manual does not state is marked: ``item.assumed`` names the fields this project
chose, ``item.certain`` is False when there are any, ``item.note`` says why.
"""

from __future__ import annotations

import tomllib
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from enum import IntEnum, StrEnum
from types import MappingProxyType
from typing import Any

from fha_studio.paths import resource

#: Range of the five-digit signed value field of a CN3 command (docs/protocol.md, Framing).
WIRE_MINIMUM = -99999
WIRE_MAXIMUM = 99999


class Mode(StrEnum):
    """Front-panel mode of an item. ``SYSTEM`` is the manual's "parameter mode"."""

    MONITOR = "monitor"
    TUNE = "tune"
    SYSTEM = "system"
    TEST = "test"


#: The modes as the HA-655 manual and its front panel name them.
#: Keyed by the mode (a str: "system" finds it too).
MODE_WORDS: dict[str, str] = {
    Mode.MONITOR: "monitor", Mode.TUNE: "tune", Mode.SYSTEM: "parameter", Mode.TEST: "test"
}


class ParameterTableError(ValueError):
    """A parameter or alarm file is malformed; the message names the file and the item."""


class ParameterValueError(ValueError):
    """A value is outside an item's range or not one of its choices; the message names the item."""


_DRIVER_FILES = {"HA-655": "ha655-parameters.toml", "HA-675": "ha675-parameters.toml"}

_ITEM_FIELDS = {
    "mode", "number", "key", "name", "unit", "scale", "minimum", "maximum", "default",
    "restart_required", "writable", "choices", "part", "pair", "extension", "description",
    "source", "assumed", "note",
}
_REQUIRED_ITEM_FIELDS = {
    "mode", "number", "key", "name", "unit", "scale", "minimum", "maximum", "restart_required",
    "writable", "description", "source", "assumed",
}


@dataclass(frozen=True)
class ParameterItem:
    """One item of the driver. Ranges and the default are wire integers (see ``scale``)."""

    mode: Mode
    number: int
    key: str
    name: str
    unit: str
    scale: float
    minimum: int
    maximum: int
    default: int | None
    restart_required: bool
    writable: bool
    description: str
    source: str
    assumed: tuple[str, ...] = ()
    note: str = ""
    choices: Mapping[int, str] = field(default_factory=lambda: MappingProxyType({}))
    part: str | None = None
    pair: str | None = None
    extension: bool = False

    @property
    def certain(self) -> bool:
        """True when every field of the item comes from a source (nothing assumed)."""
        return not self.assumed

    def to_unit(self, wire: int) -> float:
        """The value in ``unit`` for a wire integer."""
        return wire * self.scale

    def to_wire(self, value: float) -> int:
        """The wire integer for a value in ``unit`` (rounded to the nearest step), range-checked."""
        wire = round(value / self.scale)
        self.check(wire)
        return wire

    def check(self, wire: int) -> None:
        """Raise ParameterValueError unless ``wire`` is a valid value of this item."""
        if not isinstance(wire, int) or isinstance(wire, bool):
            raise ParameterValueError(f"{self.label}: value must be an integer, got {wire!r}")
        if self.choices and wire not in self.choices:
            allowed = ", ".join(f"{k} ({v})" for k, v in self.choices.items())
            raise ParameterValueError(f"{self.label}: {wire} is not one of {allowed}")
        if not self.minimum <= wire <= self.maximum:
            # in the unit the front panel and the table show, not in the wire's steps
            raise ParameterValueError(
                f"{self.label}: {self.format(wire)} is outside {self.format(self.minimum)} … "
                f"{self.format(self.maximum)}"
            )

    def format(self, wire: int) -> str:
        """A value for people: the choice's meaning, or the scaled number with its unit."""
        if wire in self.choices:
            return f"{wire}: {self.choices[wire]}"
        value = self.to_unit(wire)
        text = f"{value:g}" if self.scale != 1 else str(wire)
        return f"{text} {self.unit}".rstrip()

    @property
    def label(self) -> str:
        """``"parameter 8, rotary direction"``: how messages name the item, in the words of the
        driver's front panel (its "parameter mode" is ``Mode.SYSTEM`` here)."""
        return f"{MODE_WORDS[self.mode]} {self.number}, {self.name[:1].lower()}{self.name[1:]}"


class MonitorItem(IntEnum):
    """The extension monitor items by name (numbers and keys as in the parameter model's
    ``monitor`` items, resources/drive/ha655-parameters.toml; a test keeps the two equal).
    Scale a wire value with ``model.item(Mode.MONITOR, item).to_unit``."""

    FEEDBACK_POSITION = 100  # output pulses
    COMMAND_POSITION = 101  # output pulses
    ERROR_PULSES = 102
    OUTPUT_SPEED = 103  # 0.01 r/min
    MOTOR_CURRENT = 104  # 0.001 A
    OVERLOAD_RATE = 105  # 0.1 %
    IO_STATE = 106  # the I/O bits (protocol.IoBit)
    LOAD_POSITION = 107  # external encoder pulses
    OUTPUT_TORQUE = 108  # 0.01 N m
    SPEED_COMMAND = 109  # 0.0001 r/min, the speed loop's reference
    OUTPUT_SPEED_FINE = 110  # 0.0001 r/min
    FLANGE_TORQUE = 111  # 0.01 N m, a torque sensor between the output flange and the load
    MOTOR_CURRENT_MEAN = 112  # 0.001 A, item 104's mean over the last 10 ms


class ParameterModel:
    """All items of one driver, looked up by (mode, number) or by key."""

    def __init__(self, driver: str, items: list[ParameterItem]):
        self.driver = driver
        self.items: tuple[ParameterItem, ...] = tuple(items)
        self._by_number = {(item.mode, item.number): item for item in self.items}
        self._by_key = {item.key: item for item in self.items}

    def item(self, mode: Mode | str, number: int) -> ParameterItem:
        """The item ``number`` of ``mode``; KeyError naming both when the driver has no such item."""
        mode = Mode(mode)
        try:
            return self._by_number[(mode, number)]
        except KeyError:
            numbers = ", ".join(str(i.number) for i in self.in_mode(mode))
            raise KeyError(f"{self.driver} has no {mode.value} item {number} (items: {numbers})") from None

    def by_key(self, key: str) -> ParameterItem:
        """The item called ``key`` (e.g. ``rotary_direction``)."""
        try:
            return self._by_key[key]
        except KeyError:
            raise KeyError(f"{self.driver} has no item '{key}'") from None

    def in_mode(self, mode: Mode | str) -> list[ParameterItem]:
        """The items of one mode, by number."""
        mode = Mode(mode)
        return sorted((i for i in self.items if i.mode is mode), key=lambda i: i.number)

    def defaults(self, mode: Mode | str) -> dict[int, int]:
        """Delivery values of the writable items of a mode: {number: wire value}."""
        return {i.number: i.default for i in self.in_mode(mode) if i.default is not None}

    def __iter__(self) -> Iterator[ParameterItem]:
        return iter(self.items)

    def __len__(self) -> int:
        return len(self.items)


def combine_low_high(low: int, high: int) -> int:
    """A count from its two 4-digit monitor halves: ``high * 10000 + low`` (HA-655 manual p.87).

    Both halves carry the sign of the count (an assumption: the manual's example is positive).
    """
    return high * 10000 + low


def split_low_high(count: int) -> tuple[int, int]:
    """The (low, high) monitor halves of a count; the inverse of combine_low_high."""
    sign = -1 if count < 0 else 1
    high, low = divmod(abs(count), 10000)
    return sign * low, sign * high


def _fail(path: str, where: str, what: str) -> ParameterTableError:
    return ParameterTableError(f"{path}: {where}: {what}")


def _item_from_table(path: str, index: int, raw: dict[str, Any], all_uncertain: bool) -> ParameterItem:
    where = f"item #{index + 1} ({raw.get('mode', '?')} {raw.get('number', '?')} {raw.get('key', '?')})"
    unknown = set(raw) - _ITEM_FIELDS
    if unknown:
        raise _fail(path, where, f"unknown fields {sorted(unknown)}")
    missing = _REQUIRED_ITEM_FIELDS - set(raw)
    if missing:
        raise _fail(path, where, f"missing fields {sorted(missing)}")
    try:
        mode = Mode(raw["mode"])
    except ValueError:
        raise _fail(path, where, f"mode must be one of {[m.value for m in Mode]}") from None
    for name in ("number", "minimum", "maximum"):
        if not isinstance(raw[name], int) or isinstance(raw[name], bool):
            raise _fail(path, where, f"{name} must be an integer")
    if not isinstance(raw["scale"], int | float) or raw["scale"] <= 0:
        raise _fail(path, where, "scale must be a positive number")
    if raw["minimum"] > raw["maximum"]:
        raise _fail(path, where, "minimum is above maximum")
    # written values travel in the five-digit request field; monitor values in reply lines
    if raw["writable"] and not WIRE_MINIMUM <= raw["minimum"] <= raw["maximum"] <= WIRE_MAXIMUM:
        raise _fail(
            path, where, f"a writable item needs {WIRE_MINIMUM} <= minimum <= maximum <= {WIRE_MAXIMUM}"
        )
    assumed = raw["assumed"]
    if not isinstance(assumed, list) or not set(assumed) <= _ITEM_FIELDS:
        raise _fail(path, where, f"assumed must list field names of {sorted(_ITEM_FIELDS)}")
    if assumed and not raw.get("note"):
        raise _fail(path, where, "an item with assumed fields needs a note saying why")
    choices = {}
    for wire, meaning in raw.get("choices", {}).items():
        try:
            choices[int(wire)] = str(meaning)
        except ValueError:
            raise _fail(path, where, f"choice key {wire!r} is not an integer") from None
    if all_uncertain and "all" not in assumed:
        assumed = [*assumed, "all"]
    item = ParameterItem(
        mode=mode,
        number=raw["number"],
        key=raw["key"],
        name=raw["name"],
        unit=raw["unit"],
        scale=float(raw["scale"]),
        minimum=raw["minimum"],
        maximum=raw["maximum"],
        default=raw.get("default"),
        restart_required=bool(raw["restart_required"]),
        writable=bool(raw["writable"]),
        description=raw["description"],
        source=raw["source"],
        assumed=tuple(assumed),
        note=raw.get("note", ""),
        choices=MappingProxyType(choices),
        part=raw.get("part"),
        pair=raw.get("pair"),
        extension=bool(raw.get("extension", False)),
    )
    if mode is Mode.MONITOR:
        if item.writable or item.default is not None:
            raise _fail(path, where, "monitor items are read-only and have no default")
    else:
        if item.default is None:
            raise _fail(path, where, "a tune/system/test item needs a default")
        try:
            item.check(item.default)
        except ParameterValueError as exc:
            raise _fail(path, where, f"default: {exc}") from None
    if item.part not in (None, "low", "high") or (item.part is None) != (item.pair is None):
        raise _fail(path, where, "part must be 'low' or 'high' and comes with pair")
    return item


def _read_toml(name: str) -> tuple[str, dict[str, Any]]:
    path = resource("drive", name)
    with path.open("rb") as fh:
        try:
            return str(path), tomllib.load(fh)
        except tomllib.TOMLDecodeError as exc:
            raise ParameterTableError(f"{path}: {exc}") from None


def _driver_file(driver: str) -> str:
    try:
        return _DRIVER_FILES[driver]
    except KeyError:
        raise ValueError(f"unknown driver {driver!r}; known: {', '.join(_DRIVER_FILES)}") from None


def driver_family(driver_model: str) -> str:
    """The parameter and alarm tables a driver model uses: "HA-675-4-200" -> "HA-675"; "HA-655"
    for anything else (also when the model is unknown)."""
    return "HA-675" if driver_model.strip().upper().startswith("HA-675") else "HA-655"


def load_parameter_model(driver: str = "HA-655") -> ParameterModel:
    """The items of ``driver`` ("HA-655" or "HA-675") from ``resources/drive/``.

    Raises ParameterTableError naming the file and item when the data is malformed.
    """
    path, data = _read_toml(_driver_file(driver))
    all_uncertain = bool(data.get("all_uncertain", False))
    if "based_on" in data:
        path, base = _read_toml(data["based_on"])
        raw_items = base.get("item", [])
    else:
        raw_items = data.get("item", [])
    items = [_item_from_table(path, i, raw, all_uncertain) for i, raw in enumerate(raw_items)]
    seen_numbers: set[tuple[Mode, int]] = set()
    seen_keys: set[str] = set()
    for item in items:
        if (item.mode, item.number) in seen_numbers:
            raise ParameterTableError(f"{path}: {item.mode.value} item {item.number} appears twice")
        if item.key in seen_keys:
            raise ParameterTableError(f"{path}: key '{item.key}' appears twice")
        seen_numbers.add((item.mode, item.number))
        seen_keys.add(item.key)
    return ParameterModel(driver, items)


@dataclass(frozen=True)
class Alarm:
    """One alarm of the driver. ``alm_code`` is the 4-bit output written D C B A (ON = 1)."""

    code: int
    name: str
    alm_code: str
    clearable: bool
    absolute_only: bool
    cause: str
    remedy: str
    source: str
    assumed: tuple[str, ...] = ()

    @property
    def alm_bits(self) -> int:
        """The 4-bit code as an integer: bit 0 = ALM-A ... bit 3 = ALM-D."""
        return int(self.alm_code, 2)

    @property
    def certain(self) -> bool:
        return not self.assumed


class AlarmTable:
    """The alarms of one driver by code."""

    def __init__(self, driver: str, alarms: list[Alarm]):
        self.driver = driver
        self.alarms: tuple[Alarm, ...] = tuple(sorted(alarms, key=lambda a: a.code))
        self._by_code = {a.code: a for a in self.alarms}

    def get(self, code: int) -> Alarm | None:
        """The alarm with ``code``, or None (0 = no alarm, or a code the table does not know)."""
        return self._by_code.get(code)

    def describe(self, code: int) -> str:
        """``"20 Overload"``, ``"no alarm"`` for 0, or ``"alarm 99 (unknown code)"``."""
        if code == 0:
            return "no alarm"
        alarm = self.get(code)
        return f"{code} {alarm.name}" if alarm else f"alarm {code} (unknown code)"

    def __iter__(self) -> Iterator[Alarm]:
        return iter(self.alarms)

    def __len__(self) -> int:
        return len(self.alarms)


def load_alarm_table(driver: str = "HA-655") -> AlarmTable:
    """The alarm table of ``driver`` from ``resources/drive/``."""
    _, data = _read_toml(_driver_file(driver))
    path, table = _read_toml(data.get("alarms", "ha655-alarms.toml"))
    alarms = []
    for index, raw in enumerate(table.get("alarm", [])):
        where = f"alarm #{index + 1} ({raw.get('code', '?')})"
        try:
            alarm = Alarm(
                code=int(raw["code"]),
                name=str(raw["name"]),
                alm_code=str(raw["alm_code"]),
                clearable=bool(raw["clearable"]),
                absolute_only=bool(raw["absolute_only"]),
                cause=str(raw.get("cause", "")),
                remedy=str(raw.get("remedy", "")),
                source=str(raw["source"]),
                assumed=tuple(raw.get("assumed", ())),
            )
        except KeyError as exc:
            raise _fail(path, where, f"missing field {exc}") from None
        if len(alarm.alm_code) != 4 or set(alarm.alm_code) - {"0", "1"}:
            raise _fail(path, where, "alm_code must be 4 binary digits (D C B A)")
        if not 1 <= alarm.code <= 99:
            raise _fail(path, where, "code must be 1 ... 99")
        alarms.append(alarm)
    if len({a.code for a in alarms}) != len(alarms):
        raise ParameterTableError(f"{path}: an alarm code appears twice")
    return AlarmTable(driver, alarms)


#: The ways the encoder outputs on CN2 may count up (``[encoder_outputs] counts_up_on``).
ENCODER_SENSES = ("FWD command", "CW")


@dataclass(frozen=True)
class Cn2Signal:
    """One signal of the driver's CN2 connector (``pins`` "" where our sources give none)."""

    name: str
    pins: str
    direction: str  # "out": the drive drives it; "in": the controller does
    kind: str  # "analog", "logic", "line driver"
    role: str  # the bench role(s) that read it, "" if none
    description: str
    source: str
    common: str = ""  # the pin of its common, where stated


@dataclass(frozen=True)
class Cn2Table:
    """The driver's CN2 as our sources give it, and which way its encoder outputs count up."""

    driver: str
    pin_table: str  # where the pins our sources lack are (the manual's table)
    signals: tuple[Cn2Signal, ...]
    encoder_counts_up_on: str  # one of ENCODER_SENSES
    encoder_sense_assumed: bool
    encoder_sense_note: str

    def signal(self, role: str) -> Cn2Signal:
        """The signal a bench role reads (KeyError when none does)."""
        for signal in self.signals:
            if role in (r.strip() for r in signal.role.split(",")):
                return signal
        raise KeyError(role)

    def pins_text(self, role: str) -> str:
        """``CN2-33``, or where to look when our sources give no pin."""
        pins = self.signal(role).pins
        return f"CN2-{pins}" if pins else f"CN2 pin: see {self.pin_table}"


def load_cn2(driver: str = "HA-655") -> Cn2Table:
    """The CN2 connector of ``driver`` from ``resources/drive/``."""
    _, data = _read_toml(_driver_file(driver))
    path, table = _read_toml(data.get("cn2", "ha655-cn2.toml"))
    signals = []
    for index, raw in enumerate(table.get("signal", [])):
        try:
            signals.append(Cn2Signal(str(raw["name"]), str(raw["pins"]), str(raw["direction"]),
                                     str(raw["kind"]), str(raw["role"]), str(raw["description"]),
                                     str(raw["source"]), str(raw.get("common", ""))))
        except KeyError as exc:
            raise _fail(path, f"signal #{index + 1}", f"missing field {exc}") from None
    encoder = table.get("encoder_outputs", {})
    sense = encoder.get("counts_up_on")
    if sense not in ENCODER_SENSES:
        raise _fail(path, "[encoder_outputs]", f"counts_up_on must be one of {', '.join(ENCODER_SENSES)}")
    return Cn2Table(driver, str(table.get("pin_table", "the manual's CN2 pin table")), tuple(signals), sense,
                    "counts_up_on" in encoder.get("assumed", ()), str(encoder.get("note", "")))
