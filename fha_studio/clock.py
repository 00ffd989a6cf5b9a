"""The one clock every stamped fact takes its time from.

The register, the procedures, the session log, parameter files, reports, the training score and
the simulated drive's alarm history ask this module for "now" instead of reading the calendar in
passing, so a test (or a replay) sets the time in one place: ``use(FixedClock(...))``.
"""

from __future__ import annotations

import datetime as _dt
import os
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Protocol


class Clock(Protocol):
    def now_utc(self) -> _dt.datetime:
        """Now, as an aware datetime in UTC."""
        ...


class SystemClock:
    """The computer's calendar."""

    def now_utc(self) -> _dt.datetime:
        return _dt.datetime.now(_dt.UTC)


class FixedClock:
    """A clock that stands still until it is set or advanced (tests, replays)."""

    def __init__(self, at: _dt.datetime | str) -> None:
        self._lock = threading.Lock()
        self._at = _aware(at)

    def now_utc(self) -> _dt.datetime:
        with self._lock:
            return self._at

    def set(self, at: _dt.datetime | str) -> None:
        with self._lock:
            self._at = _aware(at)

    def advance(self, seconds: float) -> None:
        with self._lock:
            self._at += _dt.timedelta(seconds=seconds)


def _aware(at: _dt.datetime | str) -> _dt.datetime:
    moment = _dt.datetime.fromisoformat(at.replace("Z", "+00:00")) if isinstance(at, str) else at
    if moment.tzinfo is None:  # a naive time is taken as UTC, as the register does
        moment = moment.replace(tzinfo=_dt.UTC)
    return moment.astimezone(_dt.UTC)


_current: Clock = SystemClock()


def current() -> Clock:
    return _current


def set_clock(clock: Clock) -> Clock:
    """Makes ``clock`` the one every stamp reads; returns the one it replaces."""
    global _current
    previous, _current = _current, clock
    return previous


@contextmanager
def use(clock: Clock) -> Iterator[Clock]:
    previous = set_clock(clock)
    try:
        yield clock
    finally:
        set_clock(previous)


def now_utc() -> _dt.datetime:
    """Now, aware, in UTC."""
    return _current.now_utc()


def now_local() -> _dt.datetime:
    """Now, aware, in the computer's time zone (what a technician reads on a report)."""
    return _current.now_utc().astimezone()


def now_s() -> float:
    """Now as seconds since the epoch (what time.time() gives), from the same clock."""
    return _current.now_utc().timestamp()


def local_iso() -> str:
    """Now, local time with its offset, ISO 8601 to the second (session log, reports)."""
    return now_local().isoformat(timespec="seconds")


def utc_iso() -> str:
    """Now, UTC, ISO 8601 to the second."""
    return now_utc().replace(microsecond=0).isoformat()


def file_stamp() -> str:
    """Now as a file name's stamp, local time: 20261130-091500."""
    return now_local().strftime("%Y%m%d-%H%M%S")


# --- how long this process has run (a command's wall-time promise counts from its start) ----------

_IMPORTED_AT = time.monotonic()


def process_started_monotonic() -> float:
    """The moment this process started, on ``time.monotonic()``'s scale: a command that promises
    an answer within N s of being run counts Python's own start-up too. From the kernel's start
    time of the process (Linux ``/proc/self/stat``); elsewhere, or where that reads oddly, the
    moment this module was imported (a little later than the start)."""
    now = time.monotonic()
    try:
        with open("/proc/self/stat", "rb") as stat:
            fields = stat.read().rsplit(b")", 1)[1].split()
        started_s = int(fields[19]) / os.sysconf("SC_CLK_TCK")  # field 22, starttime in ticks
        age_s = time.clock_gettime(time.CLOCK_BOOTTIME) - started_s
    except (OSError, ValueError, IndexError, AttributeError):
        return _IMPORTED_AT
    # a kernel that counts the start time without a suspend gives an age too long: not ours
    if not 0.0 <= age_s <= now - _IMPORTED_AT + 30.0:
        return _IMPORTED_AT
    return min(now - age_s, _IMPORTED_AT)
