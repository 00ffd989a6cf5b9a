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


def parse_rows(data: bytes, columns: int, *, digits: bool = False) -> np.ndarray | None:
    """The rows of ``data`` (each ending in ``\\n``) as a ``(rows, columns)`` float64 array, or
    None when a field is not a number or a row has another number of fields. ``digits``: rows of
    single digits (a logic analyzer's) come as uint8 instead."""
    if not data:
        return np.zeros((0, columns))
    if not data.endswith(b"\n"):
        data += b"\n"
    if any(bytes([ch]) in data for ch in _SPACES):
        if _INNER_SPACE.search(data):
            return None
        data = data.translate(None, _SPACES)
    fixed = _fixed_width_digits(data, columns)
    if fixed is not None and not digits:
        fixed = fixed.astype(np.float64)
    if fixed is None:
        fixed = _fixed_width_fields(data, columns)
    if fixed is not None:
        return fixed
    parts: list[np.ndarray] = []
    start = 0
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


def _fixed_width_digits(data: bytes, columns: int) -> np.ndarray | None:
    """Rows of single digits (a logic analyzer's ``1,0,1``): the bytes as a 2-D array."""
    width = 2 * columns
    if len(data) % width or data[width - 1 : width] != b"\n":
        return None
    grid = np.frombuffer(data, np.uint8).reshape(-1, width)
    values = grid[:, 0::2]
    seps = grid[:, 1::2]
    if not (np.all(seps[:, :-1] == ord(",")) and np.all(seps[:, -1] == ord("\n"))):
        return None
    digits = values - np.uint8(ord("0"))
    if np.any(digits > 9):
        return None
    return digits


def _fixed_width_fields(data: bytes, columns: int) -> np.ndarray | None:
    """Rows of one length whose fields keep their places (most instruments' exports): the
    character kinds of the first row hold in every row, so every digit of every field is checked
    in one pass and weighted by its place in one matrix product per field."""
    width = data.find(b"\n") + 1
    if width <= 1 or len(data) % width:
        return None
    first = np.frombuffer(data, np.uint8, width)
    seps = np.flatnonzero(first == ord(","))
    if seps.size != columns - 1:
        return None
    grid = np.frombuffer(data, np.uint8).reshape(-1, width)
    rows = grid.shape[0]
    marks = np.concatenate((seps, [width - 1]))
    expected = first[marks]
    if np.any(np.bitwise_or.reduce(np.take(grid, marks, axis=1) ^ expected, axis=0)):
        return None
    bounds = np.concatenate(([-1], seps, [width - 1]))
    plans = []
    for k in range(columns):
        plan = _field_plan(first, int(bounds[k]) + 1, int(bounds[k + 1]))
        if plan is None:
            return None
        plans.append(plan)
    # every place that must hold a digit, in every row, checked at once
    digit_at = np.array([j for plan in plans for j in plan["mantissa"] + plan["exponent"]], np.int64)
    digits = np.take(grid, digit_at, axis=1)
    digits -= np.uint8(ord("0"))
    if digits.size and int(digits.max()) > 9:
        return None
    # the other places: the same character as in the first row (points, exponent marks)
    fixed_at = np.array([j for plan in plans for j in plan["same"]], np.int64)
    if fixed_at.size and np.any(
        np.bitwise_or.reduce(np.take(grid, fixed_at, axis=1) ^ first[fixed_at], axis=0)
    ):
        return None
    out = np.empty((rows, columns))
    used = 0
    for k, plan in enumerate(plans):
        m, e = len(plan["mantissa"]), len(plan["exponent"])
        block = digits[:, used : used + m + e]
        used += m + e
        values = np.zeros(rows)
        for j in range(m):  # Horner over the places, one column at a time
            if j:
                values *= 10.0
            values += block[:, j]
        head_at = plan["head"]
        negative = None
        if head_at is not None:  # a digit here, or a sign in some rows
            head = grid[:, head_at]
            head_digit = head - np.uint8(ord("0"))
            if int(head_digit.max()) > 9:
                if m == 0:
                    return None  # a sign without digits
                negative = head == ord("-")
                signed = negative | (head == ord("+"))
                if not np.all(signed | (head_digit <= 9)):
                    return None
                head_digit[signed] = 0
            values += head_digit * 10.0**m
        if plan["exp_sign"] is not None or e:
            scale = np.full(rows, -plan["frac"], np.int64)
            exponent = (block[:, m:] @ (10 ** np.arange(e - 1, -1, -1))).astype(np.int64)
            if plan["exp_sign"] is not None:
                sign = grid[:, plan["exp_sign"]]
                if not np.all((sign == ord("-")) | (sign == ord("+"))):
                    return None
                exponent[sign == ord("-")] *= -1
            scale += exponent
            if np.any(np.abs(scale) > 300):
                return None
            up = scale > 0
            values[up] *= np.power(10.0, scale[up])
            values[~up] /= np.power(10.0, -scale[~up])
        elif plan["frac"]:
            values /= 10.0 ** plan["frac"]
        if negative is not None:
            np.negative(values, out=values, where=negative)
        elif plan["negative"]:
            values *= -1.0
        out[:, k] = values
    return out


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
