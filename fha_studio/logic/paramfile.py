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
import re
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

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
    saved = saved or _dt.datetime.now(_dt.UTC)
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


def read_parameter_file(
    text: str, model: ParameterModel, name: str = "parameter file"
) -> LoadedParameterFile:
    """Parses `text` and maps it onto `model`. Raises ParameterFileError (with the line) for a
    file that is not a valid FHA Studio parameter file."""
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        line = _line_from_message(str(exc))
        where = f"line {line}" if line else "somewhere"
        raise ParameterFileError(f"{name}: {where}: not valid TOML ({exc})") from None
    if data.get("format") != FORMAT:
        found = data.get("format")
        line = _find_line(text, None, "format") or 1
        what = f"format is {found!r}" if found is not None else "there is no format line"
        raise ParameterFileError(
            f'{name}: line {line}: not an FHA Studio parameter file ({what}; expected format = "{FORMAT}")'
        )
    for key in ("actuator", "driver_model", "saved"):
        if key in data and not isinstance(data[key], str | _dt.datetime):
            raise ParameterFileError(f"{name}: line {_find_line(text, None, key)}: {key} must be text")
    unknown_top = [k for k, v in data.items() if isinstance(v, dict) and k not in MODES]
    if unknown_top:
        table = unknown_top[0]
        raise ParameterFileError(
            f"{name}: line {_find_table_line(text, table)}: unknown table [{table}] "
            "(expected [tune] or [system])"
        )
    values: dict[tuple[str, int], int] = {}
    not_mapped: list[str] = []
    for mode in MODES:
        table = data.get(mode, {})
        for key, wire in table.items():
            line = _find_line(text, mode, key)
            if not isinstance(wire, int) or isinstance(wire, bool):
                raise ParameterFileError(f"{name}: line {line}: {mode}.{key} = {wire!r} is not an integer")
            item = _item_by_key(model, mode, key)
            if item is None:
                not_mapped.append(
                    f"{mode}.{key} = {wire} (line {line}): {getattr(model, 'driver', 'this driver')} "
                    "has no such item"
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
    return LoadedParameterFile(
        actuator=str(data.get("actuator", "")),
        driver_model=str(data.get("driver_model", "")),
        driver=str(data.get("driver", "")),
        saved=str(data.get("saved", "")),
        values=values,
        not_mapped=not_mapped,
        source=str(data.get("source", "")),
    )


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


def _find_table_line(text: str, table: str) -> int:
    for number, line in enumerate(text.splitlines(), 1):
        if re.match(rf"\s*\[\s*{re.escape(table)}\s*\]", line):
            return number
    return 1


def _find_line(text: str, table: str | None, key: str) -> int | None:
    """The line where `key` is set inside [table] (None: before any table)."""
    current = None
    for number, line in enumerate(text.splitlines(), 1):
        header = re.match(r"\s*\[\s*([A-Za-z0-9_.-]+)\s*\]", line)
        if header:
            current = header.group(1)
            continue
        if current == table and re.match(rf"\s*{re.escape(key)}\s*=", line):
            return number
    return None
