"""Programs the tests run in processes of their own, each ended the one way: ``Child.stop``.

``Child.sim(eeprom, *options)`` is ``fha-studio sim OPTIONS --unpaced --eeprom EEPROM`` with the
address it printed (``socket://...`` for ``--tcp 0``, a pty path for ``--pty``); ``Child.fha`` and
``Child.python`` run anything else. ``stop()`` sends SIGTERM, SIGKILL after a grace time if it is
still there, waits for it and closes its pipes, whatever happened before (a test that killed it,
a process that ended by itself); ``with`` and the ``children`` fixture stop it too.
"""

from __future__ import annotations

import contextlib
import os
import select
import signal
import subprocess
import sys
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path
from typing import Any

import pytest

#: The checkout: every child runs there, with the checkout's package first on its path.
ROOT = Path(__file__).resolve().parents[2]
#: How long a child may take to print its first line (an address) on a loaded machine.
FIRST_LINE_S = 30.0


class Child:
    def __init__(self, *args: str | os.PathLike[str], stdin: bool = False, text: bool = False,
                 cwd: Path = ROOT, env: Mapping[str, str] | None = None):
        """Start ``args`` in ``cwd`` (the checkout) with the environment and ``env`` on top."""
        self.args = [str(a) for a in args]
        self.proc = subprocess.Popen(
            self.args, cwd=cwd, env={**os.environ, "PYTHONPATH": str(ROOT), **(env or {})},
            stdin=subprocess.PIPE if stdin else None, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
            text=text,
        )
        #: What it printed first (``first_line``): for ``Child.sim`` its address.
        self.address = ""

    @classmethod
    def fha(cls, *args: str | os.PathLike[str], **how: Any) -> Child:
        """``fha-studio ARGS`` (``python -m fha_studio``); ``how``: as for ``Child``."""
        return cls(sys.executable, "-m", "fha_studio", *args, **how)

    @classmethod
    def python(cls, *args: str | os.PathLike[str], **how: Any) -> Child:
        """``python ARGS``: a script, or ``-c`` and its program; ``how``: as for ``Child``."""
        return cls(sys.executable, *args, **how)

    @classmethod
    def sim(cls, eeprom: Path, *options: str, stdin: bool = False) -> Child:
        """``fha-studio sim OPTIONS --unpaced --eeprom EEPROM``, once it printed its address
        (``address``; a pty path begins with /dev/, a TCP one with socket://)."""
        child = cls.fha("sim", *options, "--unpaced", "--eeprom", eeprom, stdin=stdin)
        expect = "/dev/" if "--pty" in options else "socket://"
        child.address = child.first_line("fha-studio sim " + " ".join(options), expect=expect)
        return child

    @property
    def stdin(self):
        return self.proc.stdin

    @property
    def stdout(self):
        return self.proc.stdout

    @property
    def stderr(self):
        return self.proc.stderr

    @property
    def pid(self) -> int:
        return self.proc.pid

    @property
    def returncode(self) -> int | None:
        return self.proc.returncode

    def first_line(self, what: str, *, expect: str = "", within_s: float = FIRST_LINE_S) -> str:
        """The first line it prints, stripped, within ``within_s``; one that does not begin with
        ``expect``, or none, stops it and fails the test naming ``what`` and what it said on
        stderr."""
        assert self.proc.stdout is not None
        ready, _, _ = select.select([self.proc.stdout], [], [], within_s)
        line = self.proc.stdout.readline() if ready else ""
        line = (line.decode() if isinstance(line, bytes) else line).strip()
        if line and line.startswith(expect):
            return line
        ended = bool(ready)  # stdout readable and no line: it closed its stdout (ended)
        self.proc.kill()
        self.proc.wait(10)
        said = self._said_on_stderr()
        self.stop()
        if line:
            printed = f"printed {line!r}"
        else:
            printed = "ended without a line" if ended else f"printed nothing within {within_s:g} s"
        pytest.fail(f"{what} {printed} (exit code {self.proc.returncode}); on stderr: {said!r}")

    def communicate(
        self, timeout: float, stdin: str | bytes | None = None
    ) -> tuple[str | bytes, str | bytes]:
        """Everything it prints until it ends by itself (within ``timeout``; ``stdin`` given to it
        first, its stdin then closed), stdout and stderr."""
        return self.proc.communicate(stdin, timeout=timeout)

    def kill(self) -> int:
        """SIGKILL (as a crash, a pulled plug) and wait; its pipes stay open until ``stop``."""
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGKILL)
        return self.proc.wait(30)

    def stop(self, grace_s: float = 10.0) -> int:
        """End it (SIGTERM, then SIGKILL after ``grace_s``), wait, close its pipes; its exit code
        (0 for a program that ends cleanly on SIGTERM). Idempotent."""
        if self.proc.poll() is None:
            self.proc.terminate()
            try:
                self.proc.wait(grace_s)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait(grace_s)
        for stream in (self.proc.stdin, self.proc.stdout, self.proc.stderr):
            if stream is not None:
                with contextlib.suppress(OSError):  # a stdin whose reader has gone
                    stream.close()
        return self.proc.returncode

    def _said_on_stderr(self) -> str:
        """What is waiting on its stderr now, without blocking (a grandchild may hold it open)."""
        if self.proc.stderr is None or self.proc.stderr.closed:
            return ""
        fd = self.proc.stderr.fileno()
        os.set_blocking(fd, False)
        chunks = []
        with contextlib.suppress(BlockingIOError, OSError):
            while chunk := os.read(fd, 65536):
                chunks.append(chunk)
        return b"".join(chunks).decode(errors="replace")

    def __enter__(self) -> Child:
        return self

    def __exit__(self, *exc: object) -> None:
        self.stop()


@pytest.fixture
def children() -> Iterator[Callable[..., Child]]:
    """Factory: children(start, *args, **options) -> start(*args, **options), a ``Child`` (e.g.
    ``children(Child.sim, tmp_path / "e.json", "--pty")``), stopped after the test."""
    started: list[Child] = []

    def start(how: Callable[..., Child], *args: object, **options: object) -> Child:
        started.append(how(*args, **options))
        return started[-1]

    yield start
    for child in started:
        child.stop()
