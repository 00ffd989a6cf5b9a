"""Numeric CSV rows to a float64 array, vectorised (numpy, no Python loop over values).

:func:`parse_rows` takes the data part of a CSV file (bytes, rows ending in ``\\n``, fields
separated by ``,``; a ``;`` file with decimal commas is translated to that first) and returns the
``(rows, columns)`` array, or ``None`` when anything in it is not a plain decimal number in the
expected shape: the caller then reads line by line to say which line and field is wrong. A
number is what :data:`fha_studio.recording.NUMBER_SHAPE` says (``12``, ``-0.5``, ``1.5e-3``);
an empty field is NaN, and the caller decides whether that is allowed.

The digits of each field are weighted by their place and summed per field (an integer
mantissa), then scaled by the power of ten of the exponent less the digits after the point,
so a number of up to 15 significant digits reads exactly as ``float()`` reads it. Large inputs
go through in chunks of whole rows so the intermediate arrays stay small.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

CHUNK_BYTES = 1 << 22

_DIGIT, _DOT, _COMMA, _NEWLINE, _MINUS, _PLUS, _EXP, _OTHER = range(8)
_CLASS = np.full(256, _OTHER, np.uint8)
_CLASS[ord("0") : ord("9") + 1] = _DIGIT
_CLASS[ord(".")] = _DOT
_CLASS[ord(",")] = _COMMA
_CLASS[ord("\n")] = _NEWLINE
_CLASS[ord("-")] = _MINUS
_CLASS[ord("+")] = _PLUS
_CLASS[ord("e")] = _EXP
_CLASS[ord("E")] = _EXP
_POW10_INT = np.array([10**k for k in range(19)], np.int64)
# a space between two parts of one number ("1 2", "1. 5") is not a number
_INNER_SPACE = re.compile(rb"[0-9.eE+-][ \t\r]+[0-9.eE+-]")
_SPACES = b" \t\r"
# a ';' file with decimal commas, as a ',' file with decimal points
SEMICOLON_DECIMAL_COMMA = bytes.maketrans(b",;", b".,")
SEMICOLON = bytes.maketrans(b";", b",")
TAB = bytes.maketrans(b"\t", b",")


def parse_rows(data: bytes, columns: int, *, digits: bool = False, start: int = 0) -> np.ndarray | None:
    """The rows of ``data`` from byte ``start`` on (each ending in ``\\n``) as a ``(rows, columns)``
    float64 array, or None when a field is not a number or a row has another number of fields.
    ``digits``: rows of single digits (a logic analyzer's) come as uint8 instead."""
    if len(data) <= start:
        return np.zeros((0, columns))
    if not data.endswith(b"\n"):
        data, start = data[start:] + b"\n", 0
    if any(data.find(bytes([ch]), start) >= 0 for ch in _SPACES):
        if _INNER_SPACE.search(data, start):
            return None
        data, start = data[start:].translate(None, _SPACES), 0
    fixed = _fixed_width_digits(data, columns, start)
    if fixed is not None and not digits:
        fixed = fixed.astype(np.float64)
    if fixed is None:
        fixed = _fixed_width_fields(data, columns, start)
    if fixed is not None:
        return fixed
    parts: list[np.ndarray] = []
    while start < len(data):
        end = data.rfind(b"\n", start, start + CHUNK_BYTES) + 1
        if end <= start:  # one row longer than a chunk
            end = data.index(b"\n", start) + 1
        block = _parse_chunk(np.frombuffer(data, np.uint8, end - start, start), columns)
        if block is None:
            return None
        parts.append(block)
        start = end
    return np.concatenate(parts) if len(parts) > 1 else parts[0]


def _fixed_width_digits(data: bytes, columns: int, start: int = 0) -> np.ndarray | None:
    """Rows of single digits (a logic analyzer's ``1,0,1``): the bytes as a 2-D array."""
    width, size = 2 * columns, len(data) - start
    if size % width or data[start + width - 1 : start + width] != b"\n":
        return None
    grid = np.frombuffer(data, np.uint8, size, start).reshape(-1, width)
    out = np.empty((grid.shape[0], columns), np.uint8, order="F")
    expected = np.full(columns, ord(","), np.uint8)
    expected[-1] = ord("\n")
    for row in range(0, grid.shape[0], CHUNK_ROWS):  # rows the caches hold: each pass stays there
        rows = grid[row : row + CHUNK_ROWS]
        if np.any(rows[:, 1::2] != expected):
            return None
        digits = rows[:, 0::2] - np.uint8(ord("0"))
        if digits.size and int(digits.max()) > 9:
            return None
        out[row : row + rows.shape[0]] = digits
    return out


#: Rows of a fixed-width CSV worked on at once: a block the caches hold (a pass per field's
#: place over the whole file would read it from memory once per place).
CHUNK_ROWS = 1 << 15


def _fixed_width_fields(data: bytes, columns: int, start: int = 0) -> np.ndarray | None:
    """Rows of one length whose fields keep their places (most instruments' exports): the
    character kinds of the first row hold in every row, so a block of rows at a time (one the
    caches hold) is checked place by place and the digits summed by their places
    (:class:`_FixedLayout`). Columns come out in column order."""
    width, size = data.find(b"\n", start) + 1 - start, len(data) - start
    if width <= 1 or size % width:
        return None
    first = np.frombuffer(data, np.uint8, width, start)
    seps = np.flatnonzero(first == ord(","))
    if seps.size != columns - 1:
        return None
    grid = np.frombuffer(data, np.uint8, size, start).reshape(-1, width)
    bounds = np.concatenate(([-1], seps, [width - 1]))
    plans = []
    for k in range(columns):
        plan = _field_plan(first, int(bounds[k]) + 1, int(bounds[k + 1]))
        if plan is None:
            return None
        plans.append(plan)
    layout = _FixedLayout(first, plans)
    out = np.empty((grid.shape[0], columns), order="F")
    for row in range(0, grid.shape[0], CHUNK_ROWS):
        rows = grid[row : row + CHUNK_ROWS]
        if not layout.read(rows, out[row : row + rows.shape[0]]):
            return None
    return out


class _FixedLayout:
    """What :func:`_fixed_width_fields` checks and weighs in every row, from the first row.

    Every place of a row is checked in two passes over a block: the byte less a base (``'0'`` at a
    digit's place, the first row's character at a separator's, a point's or an exponent mark's)
    must be at most a limit (9 at a digit's place, 0 at the others; a field's head, a digit or a
    sign, and an exponent's sign are checked on their own). What is left at the digits' places
    are the digits, summed place by place in integers (exact to 18 digits)."""

    def __init__(self, first: np.ndarray, plans: list[dict[str, Any]]):
        self.plans = plans
        base = first.copy()
        limit = np.zeros(first.size, np.uint8)
        for plan in plans:
            for at in plan["mantissa"] + plan["exponent"]:
                base[at], limit[at] = ord("0"), 9
            for at in (plan["head"], plan["exp_sign"]):
                if at is not None:
                    base[at], limit[at] = 0, 255
        self.base, self.limit = base, limit
        self._buffers: dict[int, tuple[np.ndarray, np.ndarray]] = {}

    def read(self, grid: np.ndarray, out: np.ndarray) -> bool:
        """The block's values into ``out`` ``(rows, columns)``; False when a row is not of the
        first's shape."""
        rows = grid.shape[0]
        if rows not in self._buffers:
            self._buffers[rows] = (np.empty(grid.shape, np.uint8), np.empty(grid.shape, bool))
        digits, wrong = self._buffers[rows]
        np.subtract(grid, self.base, out=digits)
        np.greater(digits, self.limit, out=wrong)
        if wrong.any():
            return False
        for k, plan in enumerate(self.plans):
            values = self._field(grid, digits, plan)
            if values is None:
                return False
            out[:, k] = values
        return True

    @staticmethod
    def _field(grid: np.ndarray, digits: np.ndarray, plan: dict[str, Any]) -> np.ndarray | None:
        rows = grid.shape[0]
        m = len(plan["mantissa"])
        whole: np.ndarray = np.zeros(rows, np.int32 if m < 9 else np.int64)
        for j, at in enumerate(plan["mantissa"]):
            if j:
                whole *= 10
            whole += digits[:, at]
        sign = None
        head_at = plan["head"]
        if head_at is not None:  # a digit here, or a sign in some rows (not without digits)
            head = grid[:, head_at]
            head_digit = (_HEAD_DIGIT_OF if m else _DIGIT_OF)[head]
            if int(head_digit.max()) > 9:
                return None
            if m:
                sign = _HEAD_SIGN[head]
            whole = whole + head_digit.astype(whole.dtype) * whole.dtype.type(10**m)
        values = whole.astype(np.float64)
        e = len(plan["exponent"])
        if plan["exp_sign"] is not None or e:
            exponent = np.zeros(rows, np.int64)
            for at in plan["exponent"]:
                exponent *= 10
                exponent += digits[:, at]
            if plan["exp_sign"] is not None:
                exp_sign = grid[:, plan["exp_sign"]]
                if not np.all((exp_sign == ord("-")) | (exp_sign == ord("+"))):
                    return None
                exponent[exp_sign == ord("-")] *= -1
            scale = exponent - plan["frac"]
            if np.any(np.abs(scale) > 300):
                return None
            up = scale > 0
            values[up] *= np.power(10.0, scale[up])
            values[~up] /= np.power(10.0, -scale[~up])
        elif plan["frac"]:
            values /= 10.0 ** plan["frac"]
        if sign is not None:
            values *= sign
        elif plan["negative"]:
            values *= -1.0
        return values


# a field's first character: its digit (a sign counts 0 and gives the sign), 255 for anything else
_DIGIT_OF = np.full(256, 255, np.uint8)
_DIGIT_OF[ord("0") : ord("9") + 1] = np.arange(10)
_HEAD_DIGIT_OF = _DIGIT_OF.copy()
_HEAD_DIGIT_OF[[ord("-"), ord("+")]] = 0
_HEAD_SIGN = np.ones(256)
_HEAD_SIGN[ord("-")] = -1.0


def _field_plan(first: np.ndarray, start: int, stop: int) -> dict[str, Any] | None:
    """Where a fixed-width field's digits, point, exponent and sign are, from the first row."""
    kinds = _CLASS[first[start:stop]].tolist()
    width = len(kinds)
    if width == 0 or width > 24:
        return None
    exp_at = kinds.index(_EXP) if _EXP in kinds else width
    plan: dict[str, Any] = {
        "mantissa": [],
        "exponent": [],
        "same": [],
        "head": None,
        "exp_sign": None,
        "frac": 0,
        "negative": False,
    }
    seen_dot = False
    for j in range(exp_at):
        kind = kinds[j]
        if kind == _DIGIT:
            if j == 0:
                plan["head"] = start  # a digit here, a sign in other rows maybe
            else:
                plan["mantissa"].append(start + j)
                plan["frac"] += seen_dot
        elif kind == _DOT and not seen_dot:
            seen_dot = True
            plan["same"].append(start + j)
        elif kind in (_MINUS, _PLUS) and j == 0:
            plan["head"] = start
        else:
            return None
    if exp_at < width:
        plan["same"].append(start + exp_at)
        j = exp_at + 1
        if j < width and kinds[j] in (_MINUS, _PLUS):
            plan["exp_sign"] = start + j
            j += 1
        rest = list(range(j, width))
        if not 0 < len(rest) <= 3 or any(kinds[r] != _DIGIT for r in rest):
            return None
        plan["exponent"] = [start + r for r in rest]
    if not plan["mantissa"] and plan["head"] is None:
        return None
    if len(plan["mantissa"]) > 16:
        return None
    return plan


def _parse_chunk(a: np.ndarray, columns: int) -> np.ndarray | None:
    cls = _CLASS[a]
    if np.any(cls == _OTHER):
        return None
    is_sep = (cls == _COMMA) | (cls == _NEWLINE)
    seps = np.flatnonzero(is_sep)
    fields = seps.size
    newlines = cls[seps] == _NEWLINE
    rows = int(np.count_nonzero(newlines))
    if fields != rows * columns or not np.all(newlines[columns - 1 :: columns]):
        return None
    field_of = np.cumsum(is_sep, dtype=np.int64)  # the field a byte belongs to (a separator ends it)
    starts = np.empty(fields, np.int64)
    starts[0] = 0
    starts[1:] = seps[:-1] + 1
    lengths = seps - starts
    # signs: at a field's start, or right after an exponent mark
    sign_pos = np.flatnonzero((cls == _MINUS) | (cls == _PLUS))
    negative = np.zeros(fields, bool)
    exp_negative = np.zeros(fields, bool)
    if sign_pos.size:
        sign_field = field_of[sign_pos]
        at_start = sign_pos == starts[sign_field]
        after_exp = np.zeros(sign_pos.size, bool)
        inner = sign_pos > 0
        after_exp[inner] = cls[sign_pos[inner] - 1] == _EXP
        if not np.all(at_start | after_exp):
            return None
        minus = a[sign_pos] == ord("-")
        negative[sign_field[at_start & minus]] = True
        exp_negative[sign_field[after_exp & minus]] = True
    # exponent marks: at most one per field
    exp_at = np.full(fields, np.iinfo(np.int64).max, np.int64)
    exp_pos = np.flatnonzero(cls == _EXP)
    if exp_pos.size:
        exp_field = field_of[exp_pos]
        if np.any(np.diff(exp_field) == 0):
            return None
        exp_at[exp_field] = exp_pos
    # decimal points: at most one per field, before the exponent
    dot_at = seps.copy()  # no point: every mantissa digit is before it
    dot_pos = np.flatnonzero(cls == _DOT)
    if dot_pos.size:
        dot_field = field_of[dot_pos]
        if np.any(np.diff(dot_field) == 0) or np.any(dot_pos > exp_at[dot_field]):
            return None
        dot_at[dot_field] = dot_pos
    digit_pos = np.flatnonzero(cls == _DIGIT)
    digit_field = field_of[digit_pos]
    digit = (a[digit_pos] - np.uint8(ord("0"))).astype(np.int64)
    in_exp = digit_pos > exp_at[digit_field]
    mant = ~in_exp
    m_pos, m_field, m_digit = digit_pos[mant], digit_field[mant], digit[mant]
    m_count = np.bincount(m_field, minlength=fields)
    empty = lengths == 0
    if np.any((m_count == 0) & ~empty) or np.any(m_count > 18):
        return None
    # place of each mantissa digit: how many mantissa digits of its field follow it
    last = np.cumsum(m_count) - 1
    place = last[m_field] - np.arange(m_field.size)
    mantissa = _sum_by_field(m_digit * _POW10_INT[place], m_field, m_count, fields)
    frac = np.bincount(m_field[m_pos > dot_at[m_field]], minlength=fields)
    exponent = np.zeros(fields, np.int64)
    if exp_pos.size:
        e_field, e_digit = digit_field[in_exp], digit[in_exp]
        e_count = np.bincount(e_field, minlength=fields)
        has_exp = exp_at < np.iinfo(np.int64).max
        if np.any(has_exp & (e_count == 0)) or np.any(e_count > 4):
            return None
        e_last = np.cumsum(e_count) - 1
        e_place = e_last[e_field] - np.arange(e_field.size)
        exponent = _sum_by_field(e_digit * _POW10_INT[e_place], e_field, e_count, fields)
        exponent[exp_negative] *= -1
    scale = exponent - frac
    if np.any(np.abs(scale) > 330):
        return None  # beyond float64 (or a denormal): read one by one, which says so
    values = mantissa.astype(np.float64)
    up = scale > 0
    values[up] *= np.power(10.0, scale[up])
    down = ~up
    values[down] /= np.power(10.0, -scale[down])
    values[negative] *= -1.0
    if not np.all(np.isfinite(values)):
        return None  # a number too large for float64
    values[empty] = np.nan
    return values.reshape(rows, columns)


def _sum_by_field(terms: np.ndarray, field_of: np.ndarray, counts: np.ndarray, fields: int) -> np.ndarray:
    """Sum of ``terms`` per field (``field_of`` sorted), 0 for fields without terms."""
    out = np.zeros(fields, np.int64)
    if terms.size == 0:
        return out
    has = counts > 0
    firsts = (np.cumsum(counts) - counts)[has]
    out[has] = np.add.reduceat(terms, firsts)
    return out
