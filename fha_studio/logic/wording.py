"""Units as the FHA-C manual prints them, for what a person reads in the GUI and the report.

The calculators and the command line keep plain ASCII units ("N m", "kg m^2": a terminal, a JSON
file and a script read them); a page shows "N·m" and "kg·m²" as the manual does.
"""

from __future__ import annotations

import math
import re

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
    """``unit`` as the manual prints it ("N m" -> "N·m", a rate "deg/s" -> "°/s"); any other unit
    unchanged."""
    unit = unit.strip()
    if unit in UNIT_WORDS:
        return UNIT_WORDS[unit]
    if unit.endswith("/s") and unit[:-2] in UNIT_WORDS:
        return f"{UNIT_WORDS[unit[:-2]]}/s"
    return unit


#: Units written in plain ASCII inside a sentence (a finding, a note) -> the manual's spelling: the
#: longer first, each only where it stands as a unit (not inside a word)
_TEXT_UNITS = (
    (re.compile(r"(?<![\w·])kg m\^2(?![\w^])"), "kg·m²"),
    (re.compile(r"(?<![\w·])N m s/rad(?![\w^])"), "N·m·s/rad"),
    (re.compile(r"(?<![\w·])N m/rad(?![\w^])"), "N·m/rad"),
    (re.compile(r"(?<![\w·])N m(?![\w^/·])"), "N·m"),
    (re.compile(r"(?<![\w·])rad/s\^2(?![\w^])"), "rad/s²"),
    (re.compile(r"(?<=\d) deg(?![\w^])"), "°"),
    (re.compile(r"(?<![\w-])arcsec(?![\w^])"), "arc-sec"),
)


def manual_units_in_text(text: str) -> str:
    """A sentence's ASCII units ("0.67 kg m^2", "2.5 N m", "30 deg") as the manual prints them, for
    a page: the command line and the files keep the sentence as it is."""
    for pattern, words in _TEXT_UNITS:
        text = pattern.sub(words, text)
    return text


#: The space that joins a number to its unit on a page: a label that wraps never leaves the
#: number at a line's end and its unit on the next ("crossover 22" / "Hz"). Only for what a
#: page shows: a file, a terminal and the register keep the plain space.
NO_BREAK_SPACE = "\u00a0"


def with_unit(text: str, unit: str, *, on_page: bool = False) -> str:
    """``"28.3 N·m"``: a value and its unit in the manual's spelling ("°" follows the number).
    ``on_page``: joined by :data:`NO_BREAK_SPACE`, for a label that may wrap."""
    words = unit_words(unit)
    if not words:
        return text
    return f"{text}{words}" if words == "°" else f"{text}{NO_BREAK_SPACE if on_page else ' '}{words}"


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


#: Decimals a read-out of a quantity in this unit shows, whatever its size: a column of cursor
#: values lines up and no figure claims more than the signal resolves (an output angle to about
#: 0.4 arc-sec, the speed monitor to 0.01 r/min, the current monitor to 1 mA; a trace's time to its
#: 0.2 ms servo period).
UNIT_DECIMALS = {
    "s": 4, "ms": 1, "Hz": 2,
    "deg": 4, "°": 4, "arcsec": 1, "arc-sec": 1, "rad": 5, "pulse": 0, "bit": 0,
    "r/min": 2, "rad/s": 3,
    "A": 3, "mA": 1, "V": 3, "mV": 1,
    "N m": 2, "N·m": 2, "%": 1,
}


def fixed_number(value: float, unit: str) -> str:
    """``value`` with the fixed decimals of ``unit`` (a rate ``X/s`` as ``X``), its unit after it:
    "0.32 r/min" whatever the value's size. A unit without its decimals gets four significant
    digits (:func:`plain_number`)."""
    return f"{_fixed_digits(value, unit)} {unit.strip()}".strip()


def fixed_words(value: float, unit: str) -> str:
    """:func:`fixed_number` with the unit as the manual prints it ("90.0000°", "0.32 r/min")."""
    return with_unit(_fixed_digits(value, unit), unit)


def _fixed_digits(value: float, unit: str) -> str:
    unit = unit.strip()
    decimals = UNIT_DECIMALS.get(unit)
    if decimals is None and unit.endswith("/s"):
        decimals = UNIT_DECIMALS.get(unit[:-2])
    if decimals is None or not math.isfinite(value):
        text = plain_number(value, 4)
    else:
        text = f"{value:.{decimals}f}"
        if float(text) == 0.0:
            text = text.lstrip("-")  # "-0.00" reads as a sign the signal does not have
    return text


__all__ = ["NO_BREAK_SPACE", "UNIT_DECIMALS", "UNIT_WORDS", "fixed_number", "fixed_words", "plain_number",
           "unit_words", "with_unit"]
