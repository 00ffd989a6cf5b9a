"""The register's entries in words for people (command line and GUI alike): parameter names and
values as the parameter model states them, where a value is known from, what an entry is."""

from __future__ import annotations

from functools import cache
from typing import Any

from fha_studio.hardware.parameters import MODE_WORDS, driver_family
from fha_studio.logic.register.records import EventKind

#: Where a known value comes from.
SOURCE_WORDS = {
    "link": "read over the link",
    "front_panel": "front panel",
    "file": "from a file",
    "write": "verified write",
    "settled": "settled by a person (a conflict)",
}

#: What a history entry is.
KIND_WORDS: dict[EventKind, str] = {
    EventKind.AXIS: "axis",
    EventKind.SNAPSHOT: "parameters",
    EventKind.WRITE: "write",
    EventKind.CHECK: "check",
    EventKind.ALARM: "alarm",
    EventKind.REPORT: "report",
    EventKind.RECORDING: "recording",
    EventKind.MODEL_CHECK: "model check",
    EventKind.CONFLICT: "conflict",
    EventKind.SETTLED: "settled",
}


@cache
def _model(family: str) -> Any:
    from fha_studio.hardware.parameters import load_parameter_model

    return load_parameter_model(family)


def parameter_item(key: str, driver_model: str = "") -> Any:
    """The parameter model's item called ``key`` (None when the driver has no such item)."""
    try:
        return _model(driver_family(driver_model)).by_key(key)
    except KeyError:
        return None


def parameter_items(driver_model: str = "") -> list[Any]:
    """The writable tune and parameter-mode items, in the front panel's order."""
    model = _model(driver_family(driver_model))
    return [i for i in model if i.mode.value in ("tune", "system") and i.writable]


def parameter_name(key: str, driver_model: str = "", where: tuple[str, int] | None = None) -> str:
    """``"parameter 8 Rotary direction"``, in the front panel's words (its "parameter mode" is
    ``Mode.SYSTEM``); for an item the driver does not have, its mode and number when ``where``
    gives them, else the key itself."""
    item = parameter_item(key, driver_model)
    if item is not None:
        return f"{MODE_WORDS[item.mode]} {item.number} {item.name}"
    if where is not None:
        mode, number = where
        return f"{MODE_WORDS.get(mode, mode)} {number}"
    return key


def change_text(key: str, old: int | None, new: int, driver_model: str = "") -> str:
    """``"10 → 25 pulse"``, ``"0 → 1: FWD turns CCW (reversed)"``: a
    change of a parameter's value in the item's words ("unknown" for a value nobody read)."""
    item = parameter_item(key, driver_model)
    after = value_text(key, new, driver_model)
    if old is None:
        return f"unknown → {after}"
    if item is not None and (item.choices or item.unit):
        before = str(old) if item.choices else item.format(old).removesuffix(f" {item.unit}")
    else:
        before = value_text(key, old, driver_model)
    return f"{before} → {after}"  # the meaning or the unit once, after the new value


#: How a reading's name ends -> its unit (a check's readings: ``{"position_deg": 0.01}``).
_READING_UNITS = {"_deg": "°", "_counts": " counts", "_s": " s"}


def readings_text(values: dict[str, Any]) -> str:
    """``"position 0.01°, oww 0.5 s"``: a check's readings for people, when no sentence says them."""
    out = []
    for key, value in values.items():
        name, unit = key, ""
        for ending, words in _READING_UNITS.items():
            if key.endswith(ending):
                name, unit = key[: -len(ending)], words
                break
        out.append(f"{name.replace('_', ' ')} {value}{unit}")
    return ", ".join(out)


def value_text(key: str, value: int | None, driver_model: str = "") -> str:
    """A wire value in the item's words (``"1: FWD turns CCW (reversed)"``, ``"20 pulse"``)."""
    if value is None:
        return "(not in it)"
    item = parameter_item(key, driver_model)
    return item.format(value) if item is not None else str(value)


def when_text(at_utc: str) -> str:
    """``2026-11-30 08:00:00`` (UTC) from the register's time stamp."""
    return at_utc[:19].replace("T", " ") if at_utc else ""
