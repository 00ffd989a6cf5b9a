"""A simulation advanced in real time by a thread of its own (the simulated drive's ``start``)."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable

TICK_S = 0.002  # how often the thread advances the simulation
MOST_S = 0.05  # the most one tick advances: a stalled machine makes the simulation lag, not jump


class RealTime:
    """Calls ``advance(seconds)`` under ``lock`` about every ``TICK_S`` with the time that passed."""

    def __init__(self, lock: threading.RLock, advance: Callable[[float], None], name: str):
        self.lock = lock
        self.advance = advance
        self.name = name
        self._thread: threading.Thread | None = None
        self._stop = threading.Event()

    @property
    def running(self) -> bool:
        return self._thread is not None

    def elsewhere(self) -> bool:
        """True when it runs and the caller is another thread (stepping by hand is then wrong)."""
        return self._thread is not None and threading.current_thread() is not self._thread

    def start(self) -> None:
        if self._thread is not None:
            return
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)
        self._thread.start()

    def stop(self) -> None:
        """Ends the thread (waits up to 5 s for it)."""
        thread = self._thread
        if thread is not None:
            self._stop.set()
            thread.join(timeout=5.0)
            self._thread = None

    def _run(self) -> None:
        last = time.monotonic()
        while not self._stop.wait(TICK_S):
            now = time.monotonic()
            elapsed = min(now - last, MOST_S)
            last = now
            with self.lock:
                self.advance(elapsed)
