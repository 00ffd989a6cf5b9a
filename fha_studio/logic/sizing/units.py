"""Unit conversion of the FHA-C manual's Appendix 1 (data: resources/sizing/units.toml).

    >>> convert(1.0, "kgf.cm.s2", "kg.m2")   # doctest: +ELLIPSIS
    0.0980665...

Units are named by ASCII ids (``"lbf.in"``, ``"r/min"``, ``"kgf.cm.s2"``); the SI unit of each
quantity is one of them too. The factors used are the units' definitions; the manual's printed
factors are kept beside them (``Unit.printed_to_si``) with a note where they slip.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

from fha_studio.logic.sizing._data import load


class UnitError(ValueError):
    """An unknown unit, or two units of different quantities."""


@dataclass(frozen=True)
class Unit:
    """One unit: ``value_si = value * to_si``."""

    id: str
    quantity: str
    label: str
    to_si: float
    printed_to_si: float | None = None
    printed_from_si: float | None = None
    note: str = ""


@cache
def units() -> dict[str, Unit]:
    """Every unit by id, SI units included (factor 1)."""
    table = load("units")
    out: dict[str, Unit] = {}
    for quantity, entry in table.items():
        if not isinstance(entry, dict):
            continue
        out[entry["si"]] = Unit(entry["si"], quantity, entry["si"], 1.0)
        for uid, u in entry["units"].items():
            out[uid] = Unit(
                uid,
                quantity,
                u.get("label", uid),
                float(u["to_si"]),
                u.get("printed_to_si"),
                u.get("printed_from_si"),
                u.get("note", ""),
            )
    return out


def quantities() -> dict[str, list[str]]:
    """Unit ids by quantity (``{"torque": ["N.m", "kgf.m", ...], ...}``), SI unit first."""
    out: dict[str, list[str]] = {}
    for unit in units().values():
        out.setdefault(unit.quantity, []).append(unit.id)
    return out


def _unit(uid: str) -> Unit:
    try:
        return units()[uid]
    except KeyError:
        known = ", ".join(sorted(units()))
        raise UnitError(f"unknown unit {uid!r}; known units: {known}") from None


def to_si(value: float, unit: str) -> float:
    """``value`` in ``unit`` expressed in the quantity's SI unit."""
    return value * _unit(unit).to_si


def from_si(value: float, unit: str) -> float:
    """``value`` in SI expressed in ``unit``."""
    return value / _unit(unit).to_si


def convert(value: float, from_unit: str, to_unit: str) -> float:
    """``value`` in ``from_unit`` expressed in ``to_unit`` (same quantity, else UnitError)."""
    a, b = _unit(from_unit), _unit(to_unit)
    if a.quantity != b.quantity:
        raise UnitError(f"cannot convert {a.quantity} ({from_unit}) to {b.quantity} ({to_unit})")
    return value * a.to_si / b.to_si
