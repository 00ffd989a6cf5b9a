"""Figures on a page keep their unit on their line."""

from __future__ import annotations

import re

from fha_studio.logic.wording import NO_BREAK_SPACE, UNIT_DECIMALS, UNIT_WORDS

_UNITS = {*UNIT_DECIMALS, *UNIT_WORDS.values(), "kHz", "°/s", "r/min"}
_UNITS |= {f"{unit}/s" for unit in set(_UNITS) if not unit.endswith("/s")}
#: the space between a number and a unit the manual uses (longest first, so "ms" is not "m" and
#: "s"); the unit ends where no letter, digit, "²", "·" or "/" goes on ("5 samples" is no "5 s")
_UNIT_ALTERNATIVES = "|".join(re.escape(unit) for unit in sorted(_UNITS, key=len, reverse=True))
_NUMBER_SPACE_UNIT = re.compile(rf"(?<=\d) (?=(?:{_UNIT_ALTERNATIVES})(?![\w²·/]))")


def units_kept(text: str) -> str:
    """``text`` as a wrapping label shows it: each number joined to its unit by a no-break space
    ("at 30 r/min" never leaves "30" at a line's end and "r/min" on the next). Only for display:
    the logic, files, the command line and the session keep the plain space."""
    return _NUMBER_SPACE_UNIT.sub(NO_BREAK_SPACE, text)
