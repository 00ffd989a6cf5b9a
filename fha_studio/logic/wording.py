"""Units as the FHA-C manual prints them, for what a person reads in the GUI and the report.

The calculators and the command line keep plain ASCII units ("N m", "kg m^2": a terminal, a JSON
file and a script read them); a page shows "N·m" and "kg·m²" as the manual does.
"""

from __future__ import annotations

import math

#: ASCII unit -> the manual's spelling.
UNIT_WORDS = {
    "N m": "N·m",
    "kg m^2": "kg·m²",
    "kg m2": "kg·m²",
    "m^2": "m²",
    "N m s/rad": "N·m·s/rad",
    "N m/rad": "N·m/rad",
    "rad/s^2": "rad/s²",
    "deg": "°",
    "arcsec": "arc-sec",
}


def unit_words(unit: str) -> str:
    """``unit`` as the manual prints it ("N m" -> "N·m"); any other unit unchanged."""
    return UNIT_WORDS.get(unit.strip(), unit)


def with_unit(text: str, unit: str) -> str:
    """``"28.3 N·m"``: a value and its unit in the manual's spelling ("°" follows the number)."""
    words = unit_words(unit)
    if not words:
        return text
    return f"{text}{words}" if words == "°" else f"{text} {words}"


def plain_number(value: float, significant: int = 4) -> str:
    """``value`` with ``significant`` digits as a person reads it, never in exponent notation
    ("7.933e-05" is "0.00007933", "1.2e+06" is "1200000"): a read-out, a cursor's value."""
    text = f"{value:.{significant}g}"
    if "e" not in text:
        return text
    if not math.isfinite(value):
        return text
    exponent = math.floor(math.log10(abs(value)))
    if exponent >= 0:  # large: whole units
        return f"{value:.0f}"
    return f"{value:.{significant - 1 - exponent}f}".rstrip("0").rstrip(".")


__all__ = ["UNIT_WORDS", "plain_number", "unit_words", "with_unit"]
