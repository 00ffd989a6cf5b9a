"""Units as the FHA-C manual prints them, for what a person reads in the GUI and the report.

The calculators and the command line keep plain ASCII units ("N m", "kg m^2": a terminal, a JSON
file and a script read them); a page shows "N·m" and "kg·m²" as the manual does.
"""

from __future__ import annotations

#: ASCII unit -> the manual's spelling.
UNIT_WORDS = {
    "N m": "N·m",
    "kg m^2": "kg·m²",
    "kg m2": "kg·m²",
    "m^2": "m²",
    "N m s/rad": "N·m·s/rad",
    "N m/rad": "N·m/rad",
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


__all__ = ["UNIT_WORDS", "unit_words", "with_unit"]
