"""The packed trace block of TRP (docs/protocol.md, "Packed trace blocks"): trace samples as
printable lines of the base-64 alphabet, deltas zigzag-mapped in 5-bit groups, a 12-bit check.
protocol.py offers these names too."""

from __future__ import annotations

from collections.abc import Iterable

#: The 64 characters of a packed block, in value order 0 ... 63 (the base-64 alphabet).
PACKED_ALPHABET = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/"
_PACKED_VALUE = {c: i for i, c in enumerate(PACKED_ALPHABET)}
#: Longest line of a packed block (characters, without CR).
PACKED_LINE_CHARS = 128
#: A packed character carries 5 bits of a number; value 32 and above says "more follow".
_PACKED_MORE = 32
#: The check at the end of a block: two characters, 12 bits.
PACKED_CHECK_MODULUS = 4096


def _zigzag(v: int) -> int:
    return 2 * v if v >= 0 else -2 * v - 1


def _unzigzag(z: int) -> int:
    return z >> 1 if not z & 1 else -((z + 1) >> 1)


def packed_check(body: str) -> int:
    """The block check: sum over the characters of (position, from 1) x (character value 0-63),
    modulo 4096."""
    return sum((k + 1) * _PACKED_VALUE[c] for k, c in enumerate(body)) % PACKED_CHECK_MODULUS


def encode_packed_block(rows: Iterable[Iterable[int]]) -> list[str]:
    """Trace samples (one row of channel values per sample) -> the data lines of a TRP reply.

    Channel by channel: the first sample's value, then each sample's difference from the one
    before, every number zigzag-mapped (0, -1, 1, -2 ... -> 0, 1, 2, 3 ...) and written as
    5-bit groups, least significant first, one character each, ``+32`` on every group but the
    last. Two check characters end the block; it is cut into lines of at most
    ``PACKED_LINE_CHARS``, as even as possible, so no line is one character (a lone q, s or x).
    """
    table = list(zip(*[tuple(int(v) for v in row) for row in rows], strict=True))
    out: list[str] = []
    for column in table:
        previous = 0
        for v in column:
            z = _zigzag(v - previous)
            previous = v
            while z >= _PACKED_MORE:
                out.append(PACKED_ALPHABET[_PACKED_MORE | (z & 31)])
                z >>= 5
            out.append(PACKED_ALPHABET[z])
    body = "".join(out)
    check = packed_check(body)
    text = body + PACKED_ALPHABET[check >> 6] + PACKED_ALPHABET[check & 63]
    lines = -(-len(text) // PACKED_LINE_CHARS)
    size, extra = divmod(len(text), lines)
    cuts, start = [], 0
    for k in range(lines):
        end = start + size + (1 if k < extra else 0)
        cuts.append(text[start:end])
        start = end
    return cuts


def decode_packed_block(lines: Iterable[str], samples: int, channels: int) -> list[tuple[int, ...]]:
    """The data lines of a TRP reply -> ``samples`` rows of ``channels`` values.

    ValueError (naming what is wrong) when a character is outside the alphabet, the numbers do
    not make exactly ``samples x channels`` values, or the check does not match.
    """
    text = "".join(lines)
    if len(text) < 3:
        raise ValueError(f"packed block too short ({len(text)} characters)")
    body, check = text[:-2], text[-2:]
    try:
        digits = [_PACKED_VALUE[c] for c in body]
        expected = _PACKED_VALUE[check[0]] << 6 | _PACKED_VALUE[check[1]]
    except KeyError as exc:
        raise ValueError(f"packed block: character {exc.args[0]!r} is not in the alphabet") from None
    if packed_check(body) != expected:
        raise ValueError("packed block: the check does not match (a character changed on the line)")
    values: list[int] = []
    z = shift = 0
    for d in digits:
        z |= (d & 31) << shift
        if d & _PACKED_MORE:
            shift += 5
            continue
        values.append(_unzigzag(z))
        z = shift = 0
    if shift:
        raise ValueError("packed block: it ends inside a number")
    if len(values) != samples * channels:
        raise ValueError(f"packed block: {len(values)} values, expected {samples} samples x "
                         f"{channels} channels")
    columns = []
    for j in range(channels):
        deltas = values[j * samples : (j + 1) * samples]
        column, v = [], 0
        for d in deltas:
            v += d
            column.append(v)
        columns.append(column)
    return list(zip(*columns, strict=True))
