"""Names and ports a person gives FHA Studio, and how a refusal quotes what it was given (any layer).

- :func:`check_name`: a machine or axis name, a site, an operator, a serial number, a port: one
  line of printable text (no line breaks, tabs or terminal escape sequences), within its length.
  A 10 kB name or one with an escape sequence is a mistake (a pasted file, a stray key), and
  stored as given it would make every later listing of the names unreadable or drive the
  terminal.
- :func:`quoted`: what a refusal shows of a value: at most 80 characters, anything unprintable
  escaped (``\\n``, ``\\x1b``), so a refusal is always one readable line.
"""

from __future__ import annotations

import unicodedata

#: The longest machine or axis name (the register's tables, the GUI's lists and the reports'
#: headings show it in full).
NAME_MAX = 80
#: The longest port: a device path (Linux allows 4096, but no serial device is named so) or a
#: socket://host:port URL with a 253-character host name.
PORT_MAX = 300
#: The longest other line of text (a site, an operator, a serial number, a driver model).
TEXT_MAX = 200
#: The most of a value a refusal shows.
QUOTE_MAX = 80

#: Character categories that are not text a person reads: controls, format characters (the
#: invisible bidirectional overrides among them), surrogates, private use, unassigned, line and
#: paragraph separators.
_NOT_TEXT = frozenset(("Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"))


class NameProblem(ValueError):
    """A name or port that cannot be taken; ``str()`` is one line saying why."""


def printable(text: str) -> bool:
    """True when every character of ``text`` is one a person reads (spaces included)."""
    return not any(unicodedata.category(c) in _NOT_TEXT for c in text)


def quoted(text: str, limit: int = QUOTE_MAX, always: bool = True) -> str:
    """``'text'`` as a refusal shows it: unprintable characters escaped, at most ``limit``
    characters of it (then "…" and how long it was). ``always=False``: quotes only where the text
    needs them (it was escaped or cut, or has spaces at its ends)."""
    cut = len(text) > limit
    head = text[: limit - 1] if cut else text
    escaped = "".join(c if unicodedata.category(c) not in _NOT_TEXT else _escape(c) for c in head)
    changed = escaped != head or cut or head != head.strip() or not head
    shown = f"'{escaped}'" if always or changed else escaped
    return f"{shown}… ({len(text)} characters)" if cut else shown


def _escape(c: str) -> str:
    return c.encode("unicode_escape").decode("ascii")


def check_name(value: str, what: str, limit: int = NAME_MAX, empty_ok: bool = False) -> str:
    """``value`` without spaces at its ends, or :class:`NameProblem` saying why ``what`` (e.g.
    "machine name") cannot be it: empty (unless ``empty_ok``), longer than ``limit`` characters,
    or holding characters that are not text (line breaks, tabs, escape sequences)."""
    if not isinstance(value, str):
        raise NameProblem(f"{what} must be text")
    stripped = value.strip()
    if not stripped and not empty_ok:
        raise NameProblem(f"{what} is empty")
    if len(stripped) > limit:
        raise NameProblem(f"{what} {quoted(stripped)} is {len(stripped)} characters long; at most {limit}")
    if not printable(stripped):
        raise NameProblem(f"{what} {quoted(stripped)} holds characters that are not text "
                          "(line breaks, tabs, terminal escape sequences)")
    return stripped


def kind_of(value: object) -> str:
    """What a JSON value is, as a refusal says it ("got the text 'x'"): the text quoted and
    escaped like every refusal, so a line break or escape sequence in a file stays one line."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return f"the number {value:g}"
    if isinstance(value, str):
        return f"the text {quoted(value, 30)}"
    return "a list" if isinstance(value, list) else "a table"
