"""The scope's numbers: its configuration (resources/scope/scope.toml) and the line's budget (how
long a polled sample, a DGR exchange or a trace read-out takes at the line's baud rate). No Qt."""

from __future__ import annotations

import math
import tomllib
from collections.abc import Sequence
from dataclasses import dataclass

from fha_studio.hardware import protocol as p
from fha_studio.paths import resource

# --- configuration (resources/scope/scope.toml) ----------------------------------------------------


@dataclass(frozen=True)
class ScopeConfig:
    """Numbers the scope needs that the protocol does not carry (see resources/scope/scope.toml)."""

    servo_rate_hz: float = 5000.0
    servo_rate_assumed: bool = True
    stale_after_s: float = 0.5
    stale_after_periods: float = 5.0


def load_scope_config() -> ScopeConfig:
    with open(resource("scope", "scope.toml"), "rb") as f:
        raw = tomllib.load(f)
    return ScopeConfig(
        servo_rate_hz=float(raw["trace"]["servo_rate_hz"]),
        servo_rate_assumed=bool(raw["trace"].get("servo_rate_assumed", True)),
        stale_after_s=float(raw["live"]["stale_after_s"]),
        stale_after_periods=float(raw["live"]["stale_after_periods"]),
    )


# --- the line's budget ------------------------------------------------------------------------------


def mmr_reply_chars(values: Sequence[int]) -> int:
    """Characters of an MMR reply carrying ``values``: the data line, its CR, then ``q`` CR."""
    return len(",".join(str(int(v)) for v in values)) + 1 + 2


def sample_line_time_s(values: Sequence[int], baudrate: int = p.BAUDRATE) -> float:
    """Line time of one polled sample: the 10-character request plus the reply (8N1: 10 bits)."""
    return (p.FRAME_LENGTH + mmr_reply_chars(values)) * p.character_time_s(baudrate)


def theoretical_rate_hz(values: Sequence[int], baudrate: int = p.BAUDRATE) -> float:
    """The most samples per second the line can carry for replies of these values."""
    return 1.0 / sample_line_time_s(values, baudrate)


def estimated_rate_hz(item_count: int, digits_per_value: int = 6, baudrate: int = p.BAUDRATE) -> float:
    """The bound before any reply is known: ``digits_per_value`` characters per value (sign incl.)."""
    return theoretical_rate_hz([10 ** (digits_per_value - 1)] * item_count, baudrate)


#: Characters per value of a trace block, for estimates before the read-out: text (TRB) about 7
#: digits and a separator; packed (TRP) about 2 (a moving position at 1 kHz, docs/protocol.md).
READOUT_CHARS_PER_VALUE = {"text": 8.0, "packed": 2.0}


def readout_time_s(samples: int, items: int, encoding: str = "text", baudrate: int = p.BAUDRATE) -> float:
    """Line time to read a trace out (64 samples a block) in ``encoding`` ("text": TRB,
    "packed": TRP): the values' characters, a CR per line, and the requests."""
    blocks = math.ceil(samples / p.TRACE_BLOCK_SAMPLES)
    chars = samples * items * READOUT_CHARS_PER_VALUE[encoding] + blocks * (p.FRAME_LENGTH + 2)
    return chars * p.character_time_s(baudrate)


def dgr_line_time_s(value: int, baudrate: int = p.BAUDRATE) -> float:
    """Line time of one DGR exchange."""
    return (p.FRAME_LENGTH + len(str(int(value))) + 1 + 2) * p.character_time_s(baudrate)
