"""ScriptedDrive: a tiny stand-in drive on a pipe end, answering from a script (tests, demos).

It decodes requests with the codec's drive side and writes whatever its handler returns: a
``Reply`` (encoded by the codec), raw ``bytes`` (garbage, half frames: anything), a list of those
and ``float`` pauses in seconds, or None (silence). It is not a simulation of anything; the
simulated drive is ``fha_studio.hardware.sim``, and a drive of the manual's DGR and OWW is the
handler ``tests.support.documented.DocumentedDrive``.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable, Iterable
from typing import Union

import serial

from fha_studio.hardware import protocol as p
from fha_studio.hardware.transport import PipeEnd

log = logging.getLogger(__name__)

Answer = Union[p.Reply, bytes, float, None, Iterable["Answer"]]  # noqa: UP007 - recursive alias
Handler = Callable[[p.Request | p.UnknownRequest], Answer]


class ScriptedDrive:
    """Answers requests arriving on ``end`` in a thread; ``close()`` (or ``with``) stops it."""

    def __init__(self, end: PipeEnd, handler: Handler):
        self.end = end
        self.handler = handler
        self.requests: list[p.Request | p.UnknownRequest] = []
        self.garbage: list[p.Garbage] = []
        self.errors: list[Exception] = []  # exceptions of the handler (answered with silence)
        self._stop = threading.Event()
        self._decoder: p.StreamDecoder[p.Request | p.UnknownRequest | p.Garbage] = p.StreamDecoder(
            p.decode_request
        )
        self.end.timeout = 0.01
        self._thread = threading.Thread(target=self._run, name=f"scripted drive {end.port}", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.is_set():
            try:
                data = self.end.read(max(1, self.end.in_waiting))
            except (serial.SerialException, OSError):
                return  # unplugged or closed
            for message in self._decoder.feed(data):
                if isinstance(message, p.Garbage):
                    self.garbage.append(message)
                    continue
                self.requests.append(message)
                try:
                    answer = self.handler(message)
                    self._send(answer)
                except (serial.SerialException, OSError):
                    return
                except Exception as exc:  # a broken script must not kill the drive silently
                    log.exception("scripted drive: handler failed on %r", message)
                    self.errors.append(exc)

    def _send(self, answer: Answer) -> None:
        if answer is None:
            return
        if isinstance(answer, p.Reply):
            self.end.write(answer.encode())
        elif isinstance(answer, bytes | bytearray):
            self.end.write(bytes(answer))
        elif isinstance(answer, float):
            self._stop.wait(answer)
        else:
            for part in answer:
                self._send(part)

    def commands(self) -> list[str]:
        """Names of the requests received so far, in order."""
        return [m.command.value if isinstance(m, p.Request) else m.name for m in self.requests]

    def close(self) -> None:
        self._stop.set()
        self.end.cancel_read()
        self._thread.join(timeout=2)

    def __enter__(self) -> ScriptedDrive:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
