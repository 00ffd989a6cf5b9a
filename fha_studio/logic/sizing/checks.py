"""One verdict of the selection calculator: a value against a limit, with the manual's section."""

from __future__ import annotations

from dataclasses import asdict, dataclass
from typing import Any


@dataclass(frozen=True)
class Check:
    """One check of Chapter 2.

    ``value`` and ``limit`` are in ``unit``; ``comparison`` says how they are compared
    (``"<="``: the value must not exceed the limit, ``">="``: it must reach it). ``ok`` is the
    verdict; ``section`` the manual's section (e.g. ``"2-4-6"``); ``note`` says what the check
    assumed, where the manual's printed formula differs, or what to do when it fails.
    """

    name: str
    value: float
    limit: float
    ok: bool
    section: str
    unit: str = ""
    note: str = ""
    comparison: str = "<="

    def as_dict(self) -> dict[str, Any]:
        """Plain dict (JSON-ready)."""
        return asdict(self)


def at_most(name: str, value: float, limit: float, section: str, unit: str = "", note: str = "") -> Check:
    """A check that passes when ``value <= limit``."""
    return Check(name, float(value), float(limit), bool(value <= limit), section, unit, note, "<=")


def at_least(name: str, value: float, limit: float, section: str, unit: str = "", note: str = "") -> Check:
    """A check that passes when ``value >= limit``."""
    return Check(name, float(value), float(limit), bool(value >= limit), section, unit, note, ">=")
