"""The register's entries in words for people (command line and GUI alike): parameter names and
values as the parameter model states them, where a value is known from, what an entry is."""

from __future__ import annotations

from functools import cache
from typing import Any

from fha_studio.hardware.parameters import driver_family

#: Where a known value comes from.
SOURCE_WORDS = {
    "link": "read over the link",
    "front_panel": "front panel",
    "file": "from a file",
    "write": "verified write",
}

#: What a history entry is.
KIND_WORDS = {
    "axis": "axis",
    "snapshot": "parameters",
    "write": "write",
    "check": "check",
    "alarm": "alarm",
    "report": "report",
    "recording": "recording",
    "model_check": "model check",
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


def parameter_name(key: str, driver_model: str = "") -> str:
    """``"system 8 Rotary direction"``; the key itself for an item the driver does not have."""
    item = parameter_item(key, driver_model)
    return f"{item.mode.value} {item.number} {item.name}" if item is not None else key


def value_text(key: str, value: int | None, driver_model: str = "") -> str:
    """A wire value in the item's words (``"1: reversed: FWD command turns CCW"``, ``"20 pulse"``)."""
    if value is None:
        return "(not in it)"
    item = parameter_item(key, driver_model)
    return item.format(value) if item is not None else str(value)


def when_text(at_utc: str) -> str:
    """``2026-11-30 08:00:00`` (UTC) from the register's time stamp."""
    return at_utc[:19].replace("T", " ") if at_utc else ""
