"""A CSV capture's lines: the first ones split off to find its header, the rest left in place
and its rows read from there (no copy of a large file)."""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from typing import overload

import numpy as np

from fha_studio.hardware.bench._numbers import SEMICOLON, SEMICOLON_DECIMAL_COMMA, TAB, parse_rows
from fha_studio.hardware.bench.capture import CaptureError


class HeadLines(Sequence[bytes]):
    """``data.split(b"\\n", count)`` without copying the rest: the first ``count`` lines, then
    the rest of the file as one element, cut from ``data`` only when it is asked for.
    :meth:`offset` says where a line starts in ``data``, so the rows can be read in place."""

    def __init__(self, data: bytes, count: int):
        self.data = data
        ends: list[int] = []
        at = -1
        while len(ends) < count:
            at = data.find(b"\n", at + 1)
            if at < 0:
                break
            ends.append(at)
        self._starts = [0] + [end + 1 for end in ends]
        self._ends = ends
        self._rest: bytes | None = None

    def __len__(self) -> int:
        return len(self._ends) + 1

    @overload
    def __getitem__(self, i: int) -> bytes: ...

    @overload
    def __getitem__(self, i: slice) -> list[bytes]: ...

    def __getitem__(self, i: int | slice) -> bytes | list[bytes]:
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(len(self)))]
        if i < 0:
            i += len(self)
        if not 0 <= i < len(self):
            raise IndexError(i)
        if i < len(self._ends):
            return self.data[self._starts[i] : self._ends[i]]
        if self._rest is None:
            self._rest = self.data[self._starts[-1] :]
        return self._rest

    def __iter__(self) -> Iterator[bytes]:
        return (self[i] for i in range(len(self)))

    def offset(self, i: int) -> int:
        """Where line ``i`` (the rest, for the last one) starts in ``data``."""
        return self._starts[i]

    def first_of_rest(self) -> bytes:
        """The first line of the rest (what ``self[-1]`` begins with)."""
        start = self._starts[-1]
        end = self.data.find(b"\n", start)
        return self.data[start:] if end < 0 else self.data[start:end]


def all_lines(lines: Sequence[bytes]) -> list[bytes]:
    """Every line, the rest split too."""
    if isinstance(lines, HeadLines):
        return lines.data.split(b"\n") if len(lines) > 1 else list(lines)
    return list(lines)


def _rows(data: bytes, at: int, marks: tuple[bytes, ...], delimiter: bytes, decimal_comma: bool,
          clean: bool) -> tuple[bytes, int]:
    """The rows as parse_rows reads them: comment and empty lines out (``clean``), ``;`` or tab
    separators and decimal commas as ``,`` and points, one newline at the end."""
    if clean:
        data, at = b"\n".join(ln for ln in data[at:].split(b"\n")
                              if ln.strip() and not ln.lstrip().startswith(marks)), 0
    if delimiter == b";":
        data, at = data[at:].translate(SEMICOLON_DECIMAL_COMMA if decimal_comma else SEMICOLON), 0
    elif delimiter == b"\t":
        data, at = data[at:].translate(TAB), 0
    if data.startswith(b"\n", at) or data.endswith(b"\n\n") or (len(data) > at and not data.endswith(b"\n")):
        data, at = (data[at:].strip(b"\n") + b"\n").lstrip(b"\n"), 0
    return data, at


def table(lines: Sequence[bytes], start: int, width: int, name: str, delimiter: bytes,
          decimal_comma: bool = False, comment: str = ";", digits: bool = False) -> np.ndarray:
    """The numeric rows from line index ``start`` on, as ``(rows, width)`` float64 (uint8 for
    ``digits``), read in place where ``lines`` are a :class:`HeadLines`; CaptureError naming the
    first row that is not ``width`` numbers."""
    marks = tuple(c.encode() for c in comment)
    if isinstance(lines, HeadLines) and start < len(lines):
        data, at = lines.data, lines.offset(start)
    else:
        data, at = b"\n".join(lines[start:]), 0
    # comment and empty lines inside the rows are rare: the fast path reads the rows whole, and an
    # empty line (which fails it) is looked for only then
    clean = any(data.find(m, at) >= 0 for m in marks) or data.startswith(b"\n", at)
    body, body_at = _rows(data, at, marks, delimiter, decimal_comma, clean)
    rows = parse_rows(body, width, digits=digits, start=body_at)
    if rows is None and not clean and data.find(b"\n\n", at) >= 0:
        body, body_at = _rows(data, at, marks, delimiter, decimal_comma, True)
        rows = parse_rows(body, width, digits=digits, start=body_at)
    if rows is None:
        _find_bad_row(all_lines(lines), start, width, name, delimiter, decimal_comma, marks)
        raise CaptureError(f"{name}: line {start + 1}: the rows are not numbers in {width} columns")
    return rows


def _find_bad_row(lines: Sequence[bytes], start: int, width: int, name: str, delimiter: bytes,
                  decimal_comma: bool, marks: tuple[bytes, ...]) -> None:
    """Raises the CaptureError naming the first row that is not ``width`` numbers."""
    for i in range(start, len(lines)):
        raw = lines[i].strip()
        if not raw or raw.startswith(marks):
            continue
        text = raw.decode("utf-8", "replace")
        fields = text.split(delimiter.decode())
        if len(fields) != width:
            raise CaptureError(f"{name}: line {i + 1}: {len(fields)} fields, expected {width} (as the "
                               "header has)")
        for k, field in enumerate(fields, 1):
            cell = field.strip().replace(",", ".") if decimal_comma else field.strip()
            if cell and parse_rows(cell.encode() + b"\n", 1) is None:
                shown = field if len(field) <= 30 else field[:29] + "…"
                raise CaptureError(f"{name}: line {i + 1}: field {k} '{shown}' is not a number "
                                   "(a plain decimal like 12, -0.5 or 1.5e-3)")
