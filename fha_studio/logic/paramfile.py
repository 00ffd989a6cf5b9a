"""The parameter file: a drive's tune and parameter (system) values as human-readable TOML.

    # FHA Studio parameter file
    format = "fha-parameters/1"
    actuator = "FHA-25C-50-US250"
    driver_model = "HA-655-2-200"
    driver = "HA-655"
    saved = "2026-11-25T17:05:00+00:00"

    [system]
    rotary_direction = 0   # system 8: Rotary direction = FWD command turns CW ...

Values are the drive's wire integers (the parameter model's `scale` converts them). Items are
named by key inside the table of their mode, so a file made on another driver model maps by
name. Reading refuses a corrupt or foreign file whole, naming the line at fault; a file for
another actuator or driver loads what fits and lists what it could not map.
"""

from __future__ import annotations

import datetime as _dt
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from fha_studio import clock, fileio
from fha_studio.hardware.parameters import ParameterItem, ParameterModel

FORMAT = "fha-parameters/1"
MODES = ("tune", "system")


class ParameterFileError(ValueError):
    """The file cannot be used at all; the message names the file and the line."""


@dataclass(frozen=True)
class LoadedParameterFile:
    """What a parameter file holds, mapped onto a driver's parameter model."""

    actuator: str
    driver_model: str
    driver: str
    saved: str
    values: dict[tuple[str, int], int]  # (mode, number) -> wire value, only items that fit
    not_mapped: list[str] = field(default_factory=list)  # one line each: what and why
    missing: list[str] = field(default_factory=list)  # items of the driver the file does not set
    source: str = ""  # FRONT_PANEL_SOURCE when the values were entered from the front panel


#: The ``source`` line of a file whose values were (all or partly) entered from the front panel.
FRONT_PANEL_SOURCE = "entered from the drive's front panel"


def dump_parameter_file(
    model: ParameterModel,
    values: Mapping[tuple[str, int], int],
    actuator: str,
    driver_model: str,
    saved: _dt.datetime | None = None,
    front_panel: Mapping[tuple[str, int], Any] | None = None,
) -> str:
    """The TOML text of `values` ({(mode, number): wire int}) for the items of `model`.

    ``front_panel`` ({(mode, number): entry with ``who`` and ``time``}) marks the values that were
    entered from the drive's front panel (a drive without parameter access over CN3): the file
    says so in its ``source`` line and beside each such value."""
    saved = saved or clock.now_utc()
    front_panel = front_panel or {}
    lines = [
        "# FHA Studio parameter file: the tune and parameter (system) values of a HA-655/HA-675 driver.",
        "# Values are the drive's wire integers; the comment gives the item and its meaning.",
        f"format = {_quote(FORMAT)}",
        f"actuator = {_quote(actuator)}",
        f"driver_model = {_quote(driver_model)}",
        f"driver = {_quote(getattr(model, 'driver', ''))}",
        f"saved = {_quote(saved.isoformat(timespec='seconds'))}",
    ]
    if any(key in values for key in front_panel):
        lines.append(f"source = {_quote(FRONT_PANEL_SOURCE)}")
    for mode in MODES:
        items = [i for i in model if i.mode == mode and (i.mode, i.number) in values]
        if not items:
            continue
        lines += ["", f"[{mode}]"]
        width = max(len(i.key) for i in items)
        for item in sorted(items, key=lambda i: i.number):
            wire = int(values[(item.mode, item.number)])
            meaning = item.format(wire)
            entry = front_panel.get((item.mode, item.number))
            by = f" (front panel: {entry.who}, {entry.time})" if entry is not None else ""
            lines.append(
                f"{item.key.ljust(width)} = {wire:<6d} # {mode} {item.number}: {item.name} = {meaning}{by}"
            )
    return "\n".join(lines) + "\n"


#: The keys a parameter file may have outside its [tune] and [system] tables (all text).
HEADER_KEYS = ("format", "actuator", "driver_model", "driver", "saved", "source")
#: Bound on a parameter file's size: a full HA-655 file is about 3 kB.
MAX_FILE_BYTES = 1024 * 1024


def load_parameter_file(path: str | os.PathLike[str], model: ParameterModel) -> LoadedParameterFile:
    """Reads the file at ``path`` (a regular file, at most ``MAX_FILE_BYTES``) and maps it onto
    ``model``; ParameterFileError names the file and what is wrong with it."""
    from fha_studio import fileio

    try:
        text = fileio.read_text(path, limit_bytes=MAX_FILE_BYTES)
    except fileio.FileProblem as exc:
        raise ParameterFileError(str(exc)) from None
    return read_parameter_file(text, model, name=str(path))


def read_parameter_file(
    text: str, model: ParameterModel, name: str = "parameter file"
) -> LoadedParameterFile:
    """Parses `text` and maps it onto `model`. Raises ParameterFileError (with the line) for a
    file that is not a valid FHA Studio parameter file.

    A value of the right shape that this driver cannot take is listed in ``not_mapped``; an item
    of the driver that the file does not set (a file cut short, or made on another driver) is
    listed in ``missing``.
    """
    if text.startswith("\ufeff"):  # a byte-order mark some editors put first
        text = text[1:]
    try:
        data = fileio.parse_toml(text)  # bounded in depth
    except tomllib.TOMLDecodeError as exc:
        line = _line_from_message(str(exc))
        where = f"line {line}" if line else "somewhere"
        raise ParameterFileError(f"{name}: {where}: not valid TOML ({exc})") from None
    lines = _key_lines(text)
    if data.get("format") != FORMAT:
        found = data.get("format")
        line = lines.get(("format",), 1)
        what = f"format is {_shown(found)}" if found is not None else "there is no format line"
        raise ParameterFileError(
            f'{name}: line {line}: not an FHA Studio parameter file ({what}; expected format = "{FORMAT}")'
        )
    allowed = f"allowed: {', '.join(HEADER_KEYS)} and the tables [tune] and [system]"
    for key, value in data.items():
        line = lines.get((key,), 1)
        if key in MODES:
            if not isinstance(value, dict):
                raise ParameterFileError(
                    f"{name}: line {line}: {key} = {_shown(value)}: {key} must be the table [{key}] "
                    "of items, each key = integer"
                )
        elif isinstance(value, dict):
            raise ParameterFileError(
                f"{name}: line {line}: unknown table [{key}] (expected [tune] or [system])"
            )
        elif key not in HEADER_KEYS:
            raise ParameterFileError(f"{name}: line {line}: unknown key {_shown(key)} ({allowed})")
        elif not isinstance(value, str | _dt.datetime):
            raise ParameterFileError(f"{name}: line {line}: {key} must be text, got {_shown(value)}")
    values: dict[tuple[str, int], int] = {}
    not_mapped: list[str] = []
    mentioned: set[tuple[str, str]] = set()
    for mode in MODES:
        table = data.get(mode, {})
        for key, wire in table.items():
            line = lines.get((mode, key), lines.get((mode,), 1))
            if not isinstance(wire, int) or isinstance(wire, bool):
                raise ParameterFileError(
                    f"{name}: line {line}: {mode}.{_shown(key, quote=False)} = {_shown(wire)} "
                    "is not an integer"
                )
            mentioned.add((mode, key))
            item = _item_by_key(model, mode, key)
            if item is None:
                not_mapped.append(
                    f"{mode}.{_shown(key, quote=False)} = {wire} (line {line}): "
                    f"{getattr(model, 'driver', 'this driver')} has no such item"
                )
                continue
            try:
                item.check(wire)
            except ValueError as exc:
                not_mapped.append(f"{mode}.{key} = {wire} (line {line}): {exc}")
                continue
            if not getattr(item, "writable", True):
                not_mapped.append(f"{mode}.{key} (line {line}): read-only on this driver")
                continue
            values[(item.mode, item.number)] = wire
    missing = [
        f"{item.mode}.{item.key} ({item.mode} {item.number}: {item.name}): not in the file, "
        "the drive keeps its value"
        for item in model
        if item.mode in MODES and getattr(item, "writable", True)
        and (str(item.mode), item.key) not in mentioned
    ]
    return LoadedParameterFile(
        actuator=str(data.get("actuator", "")),
        driver_model=str(data.get("driver_model", "")),
        driver=str(data.get("driver", "")),
        saved=str(data.get("saved", "")),
        values=values,
        not_mapped=not_mapped,
        source=str(data.get("source", "")),
        missing=missing,
    )


def _shown(value: object, quote: bool = True) -> str:
    """A value from the file as a message shows it: TOML-like, one line, not too long."""
    if isinstance(value, str):
        text = _quote(value) if quote else value
    elif isinstance(value, bool):
        text = "true" if value else "false"
    elif isinstance(value, dict):
        text = "a table"
    elif isinstance(value, list):
        text = "a list [" + ", ".join(_shown(v) for v in value[:4]) + (", …" if len(value) > 4 else "") + "]"
    else:
        text = str(value)
    text = text.replace("\n", " ")
    return text if len(text) <= 60 else text[:59] + "…"


def _item_by_key(model: ParameterModel, mode: str, key: str) -> ParameterItem | None:
    for item in model:
        if item.mode == mode and item.key == key:
            return item
    return None


def _quote(text: str) -> str:
    return '"' + str(text).replace("\\", "\\\\").replace('"', '\\"') + '"'


def _line_from_message(message: str) -> int | None:
    match = re.search(r"line (\d+)", message)
    return int(match.group(1)) if match else None


_BARE_KEY = r"[A-Za-z0-9_-]+"
_KEY_PART = rf'(?:{_BARE_KEY}|"(?:[^"\\]|\\.)*"|\'[^\']*\')'
_DOTTED = rf"{_KEY_PART}(?:\s*\.\s*{_KEY_PART})*"
_TABLE_RE = re.compile(rf"\s*\[\s*({_DOTTED})\s*\]")
_ASSIGN_RE = re.compile(rf"\s*({_DOTTED})\s*=")


def _split_key(dotted: str) -> tuple[str, ...]:
    parts = re.findall(_KEY_PART, dotted)
    return tuple(p[1:-1] if p[:1] in "\"'" else p for p in parts)


def _key_lines(text: str) -> dict[tuple[str, ...], int]:
    """Where each key path is first set or opened: ("tune",) for [tune] or tune.x = ...,
    ("tune", "x") for x = ... under [tune] or tune.x = ... at the top (dotted keys included).

    The file has already parsed as TOML, so a line-by-line reading finds the keys; values that
    span lines (multi-line strings or arrays) cannot hide a key here because TOML refuses them
    in this file's shape before this runs, or they are reported at their first line."""
    lines: dict[tuple[str, ...], int] = {}
    table: tuple[str, ...] = ()
    for number, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("#"):
            continue
        header = _TABLE_RE.match(line)
        if header and not line.lstrip().startswith("[["):
            table = _split_key(header.group(1))
            for depth in range(1, len(table) + 1):
                lines.setdefault(table[:depth], number)
            continue
        assign = _ASSIGN_RE.match(line)
        if assign:
            path = table + _split_key(assign.group(1))
            for depth in range(1, len(path) + 1):
                lines.setdefault(path[:depth], number)
    return lines
