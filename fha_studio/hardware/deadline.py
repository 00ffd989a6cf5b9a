"""A port with a wall-clock deadline: whatever the line does, reading stops when the time is up.

The client's own timeouts restart at every byte received (a reply may be long), so a line that
trickles or floods bytes without ever forming a usable reply keeps an attempt alive for up to
``LinkSettings.max_reply_s``, and every retry again. A caller that has promised an answer within a
fixed time (a command-line probe that must exit within 5 s) wraps the port in a
``DeadlineTransport``: once ``deadline`` (a ``time.monotonic()`` value) has passed, every read,
write and ``in_waiting`` raises ``DeadlinePassed`` (a ``LinkLost``), which the client passes on
without retrying. ``received_bytes`` counts what arrived, so the caller can tell "nothing arrived"
(cable, port, power) from "bytes arrived, but no reply" (wrong device or baud rate).
"""

from __future__ import annotations

import time
from typing import Any

from fha_studio.hardware.errors import LinkLost


class DeadlinePassed(LinkLost):
    """The caller's time for the whole exchange ran out (``seconds`` after ``started``)."""


class DeadlineTransport:
    """Wraps a pyserial-like port; ``deadline`` (monotonic seconds, None = none) can be moved
    between phases (``allow(seconds)``)."""

    def __init__(self, inner: Any, seconds: float | None = None):
        self.inner = inner
        self.name = str(getattr(inner, "name", None) or getattr(inner, "port", None) or "port")
        self.received_bytes = 0
        self.deadline: float | None = None
        self.allowed_s = 0.0
        if seconds is not None:
            self.allow(seconds)

    def allow(self, seconds: float) -> None:
        """From now on, ``seconds`` more for everything until the next ``allow``."""
        self.allowed_s = seconds
        self.deadline = time.monotonic() + seconds

    def allow_until(self, deadline: float, allowed_s: float) -> None:
        """Everything until ``deadline`` (monotonic seconds), fixed before the port was opened: one
        deadline for the whole exchange, opening included; ``allowed_s`` is what messages call the
        budget."""
        self.allowed_s = allowed_s
        self.deadline = deadline

    def remaining_s(self) -> float | None:
        return None if self.deadline is None else self.deadline - time.monotonic()

    def _check(self) -> None:
        left = self.remaining_s()
        if left is not None and left <= 0:
            heard = (
                f"{self.received_bytes} bytes arrived, but no usable reply"
                if self.received_bytes
                else "nothing arrived"
            )
            raise DeadlinePassed(
                f"no usable answer on {self.name} within {self.allowed_s:g} s ({heard})", port=self.name
            )

    def read(self, size: int = 1) -> bytes:
        self._check()
        data: bytes = self.inner.read(size)
        self.received_bytes += len(data)
        return data

    def write(self, data: bytes) -> int | None:
        self._check()
        written: int | None = self.inner.write(data)
        return written

    @property
    def in_waiting(self) -> int:
        self._check()
        waiting: int = self.inner.in_waiting
        return waiting

    def reset_input_buffer(self) -> None:
        self.inner.reset_input_buffer()

    @property
    def timeout(self) -> float | None:
        timeout: float | None = self.inner.timeout
        return timeout

    @timeout.setter
    def timeout(self, value: float | None) -> None:
        self.inner.timeout = value

    @property
    def port(self) -> str:
        return self.name

    @property
    def is_open(self) -> bool:
        return bool(self.inner.is_open)

    def close(self) -> None:
        self.inner.close()

    def __getattr__(self, name: str) -> Any:
        return getattr(self.inner, name)
