"""Checked command-line values: argparse ``type=`` functions that refuse a value with one line
saying what is allowed (argparse then exits with status 2, naming the option)."""

from __future__ import annotations

import argparse
import math
import re
import unicodedata
from collections.abc import Callable

from fha_studio import fileio
from fha_studio.plausible import TCP_PORT, Range

#: The longest free text (a name, a driver model) taken from the command line.
MAX_TEXT = 200
#: A number as the command line takes it: a plain decimal with an optional exponent, ASCII only.
NUMBER_SHAPE = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")


def number(text: str) -> float:
    """A finite decimal number (``1_0``, ``inf``, ``nan`` and non-ASCII digits are not numbers)."""
    stripped = text.strip()
    if not NUMBER_SHAPE.fullmatch(stripped):
        raise argparse.ArgumentTypeError(f"{_shown(text)} is not a number")
    value = float(stripped)
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"{_shown(text)} is too large")
    return value


def in_range(allowed: Range) -> Callable[[str], float]:
    """A number inside ``allowed`` (its reason is part of the message)."""

    def parse(text: str) -> float:
        value = number(text)
        if not allowed.contains(value):
            raise argparse.ArgumentTypeError(
                f"{_shown(text)} is outside {allowed.allowed()} ({allowed.reason})")
        return value

    parse.__name__ = allowed.name  # argparse names the type in some messages
    return parse


def tcp_port(text: str) -> int:
    """A TCP port number, 0 ... 65535 (0: any free port)."""
    stripped = text.strip()
    if not stripped.isascii() or not stripped.isdigit() or not TCP_PORT.contains(float(stripped)):
        raise argparse.ArgumentTypeError(f"{_shown(text)} is not a TCP port ({TCP_PORT.allowed()})")
    return int(stripped)


def whole(minimum: int, maximum: int) -> Callable[[str], int]:
    """A whole number ``minimum ... maximum``."""

    def parse(text: str) -> int:
        stripped = text.strip()
        body = stripped[1:] if stripped[:1] in "+-" else stripped
        if not body.isascii() or not body.isdigit() or not minimum <= int(stripped) <= maximum:
            raise argparse.ArgumentTypeError(f"{_shown(text)} is not a whole number {minimum} ... {maximum}")
        return int(stripped)

    parse.__name__ = "whole number"
    return parse


def text(value: str) -> str:
    """Free text for a person (a name): one line of printable characters, at most MAX_TEXT."""
    if len(value) > MAX_TEXT:
        raise argparse.ArgumentTypeError(f"is {len(value)} characters long; at most {MAX_TEXT}")
    if any(unicodedata.category(c) in ("Cc", "Cs") for c in value):
        raise argparse.ArgumentTypeError(f"{_shown(value)} holds control characters (line breaks, tabs)")
    return value


def output_path(value: str) -> str:
    """A file to write: refused now if it can never be a regular file (a device, a path under a
    file, a name too long), before any work is done."""
    try:
        fileio.check_output_path(value)
    except fileio.FileProblem as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return value


def _shown(value: str) -> str:
    shown = value if len(value) <= 40 else value[:39] + "…"
    if shown != shown.strip() or not shown or not shown.isprintable():
        return '"' + shown.encode("unicode_escape").decode("ascii") + '"'
    return shown
