"""FakeClock: the one injected clock of the tests.

It is two clocks that stand still until the test moves them, and move together: the calendar
(``now_utc``, what ``fha_studio.clock.use`` takes and every stamp reads: the ``fixed_clock``
fixture) and a count of seconds (call it, or read and set ``now``: what a ``clock=`` argument
takes in place of ``time.monotonic``).
"""

from __future__ import annotations

import datetime as _dt

from fha_studio.clock import FixedClock

#: Where a FakeClock's calendar stands unless told: a Monday morning of the project's time.
START = "2026-11-30T07:00:00Z"


class FakeClock(FixedClock):
    def __init__(self, at: _dt.datetime | str = START, now: float = 100.0) -> None:
        super().__init__(at)
        self._now = now

    def __call__(self) -> float:
        """Seconds, as ``time.monotonic()`` gives them."""
        return self.now

    @property
    def now(self) -> float:
        return self._now

    @now.setter
    def now(self, seconds: float) -> None:
        self.advance(seconds - self.now)

    def advance(self, seconds: float) -> None:
        """Both clocks, ``seconds`` on."""
        super().advance(seconds)
        self._now += seconds
