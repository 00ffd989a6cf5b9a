"""Whatever the line does, opening a drive and every call end within their stated wall time, and
the error says what the line did: nothing arrives, bytes arrive but no reply, or the drive refuses.

A "line" here is a thread writing into the drive end of an in-process pipe: silent, a trickle
of 4 bytes per second, a flood of printable characters, random garbage, a flood of NUL bytes.
The bounds asserted are the client's own (``LinkSettings.transaction_limit_s``) with a margin
for a loaded machine, far below the minute a hostile line used to cost.
"""

from __future__ import annotations

import random
import threading
import time
from collections.abc import Callable, Iterator

import pytest

from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import (
    CommandRejected,
    LinkGarbled,
    LinkSilent,
    LinkTimeout,
    ReadAborted,
    ServoOnRefused,
)
from fha_studio.hardware.client import DriveClient, LinkSettings
from fha_studio.hardware.protocol import Command
from fha_studio.hardware.transport import PipeEnd, pipe_pair
from tests.support.documented import DocumentedDrive
from tests.support.scripted import ScriptedDrive

#: The link worker's settings (gui/link.py): a dead line must show within a few seconds.
GUI = LinkSettings(response_timeout_s=0.25, retries=1)
#: What a loaded 2-core machine may add to a bound.
MARGIN_S = 3.0


def _chunks(kind: str) -> Callable[[], tuple[bytes, float]]:
    """(bytes to write, pause after) for each kind of hostile line."""
    rng = random.Random(12)
    return {
        "trickle": lambda: (b"A", 0.25),  # 4 bytes/s: every byte restarts a naive timeout
        "flood": lambda: (b"A" * 200, 0.002),
        "garbage": lambda: (bytes(rng.randrange(256) for _ in range(200)), 0.002),
        "nul": lambda: (b"\0" * 200, 0.002),
    }[kind]


class HostileLine:
    """Writes ``kind`` into ``end`` from a thread until stopped (``start_after`` lets a real
    drive answer first)."""

    def __init__(self, end: PipeEnd, kind: str):
        self.end, self.next = end, _chunks(kind)
        self.go = threading.Event()
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, name=f"hostile line {kind}", daemon=True)
        self.thread.start()

    def _run(self) -> None:
        self.go.wait()
        while not self.stop.is_set():
            data, pause = self.next()
            try:
                self.end.write(data)
            except Exception:
                return
            self.stop.wait(pause)

    def close(self) -> None:
        self.stop.set()
        self.go.set()
        self.thread.join(5)


@pytest.fixture
def pipes() -> Iterator[tuple[PipeEnd, PipeEnd]]:
    host, drive = pipe_pair("hostile")
    yield host, drive
    host.close()
    drive.close()


def _timed(call: Callable[[], object]) -> tuple[BaseException, float]:
    t0 = time.monotonic()
    with pytest.raises(LinkTimeout) as raised:
        call()
    return raised.value, time.monotonic() - t0


def test_a_silent_line_says_nothing_arrives(pipes):
    error, elapsed = _timed(lambda: DriveClient.attach(pipes[0], GUI))
    assert isinstance(error, LinkSilent)
    assert "no drive answers on hostile" in str(error) and "nothing arrives" in str(error)
    assert "cable" in str(error)
    assert elapsed < DriveClient.open_limit_s(GUI) + MARGIN_S


@pytest.mark.parametrize("kind", ["trickle", "flood", "garbage", "nul"])
def test_a_babbling_line_says_bytes_arrive_but_no_reply_within_the_bound(pipes, kind):
    line = HostileLine(pipes[1], kind)
    line.go.set()
    try:
        error, elapsed = _timed(lambda: DriveClient.attach(pipes[0], GUI))
    finally:
        line.close()
    assert isinstance(error, LinkGarbled), error
    assert "bytes arrive" in str(error) and "baud rate" in str(error)
    assert elapsed < GUI.transaction_limit_s(Command.CAP) + MARGIN_S


@pytest.mark.parametrize("kind", ["trickle", "flood", "nul"])
def test_every_call_is_bounded_when_the_line_turns_hostile_after_connecting(pipes, kind):
    line = HostileLine(pipes[1], kind)
    drive = ScriptedDrive(pipes[1], DocumentedDrive())
    try:
        client = DriveClient.attach(pipes[0], GUI)
        assert client.absolute_position() == 123456
        drive.close()  # the drive goes; the line babbles
        line.go.set()
        error, elapsed = _timed(client.absolute_position)
    finally:
        line.close()
        drive.close()
    assert isinstance(error, LinkGarbled), error
    assert elapsed < GUI.transaction_limit_s(Command.DGR) + MARGIN_S


def test_the_drive_refusing_is_neither_silence_nor_garbage(pipes):
    documented = DocumentedDrive()
    drive = ScriptedDrive(pipes[1], documented)
    try:
        client = DriveClient.attach(pipes[0], GUI)
        with pytest.raises(CommandRejected):
            client.transaction.transact(Command.IOS, parse=lambda r: None)
        documented.servo_on = True
        with pytest.raises(ServoOnRefused):
            client.absolute_position()
        assert not client.link_lost
    finally:
        drive.close()


def test_an_exchange_gives_up_at_once_when_asked_to(pipes):
    closing = threading.Event()
    line = HostileLine(pipes[1], "trickle")
    line.go.set()
    timer = threading.Timer(0.3, closing.set)
    timer.start()
    t0 = time.monotonic()
    try:
        with pytest.raises(ReadAborted):
            DriveClient.attach(pipes[0], LinkSettings(), should_abort=closing.is_set)
    finally:
        timer.cancel()
        line.close()
    assert time.monotonic() - t0 < 0.3 + MARGIN_S


def test_the_stated_bound_covers_the_slow_commands_and_the_longest_replies():
    s = LinkSettings()
    # a trace block of 64 x 4 values may take its line time; a babbling line no more than twice it
    block_s = s.transfer_time_s(p.TRACE_BLOCK_SAMPLES * (p.TRACE_MAX_CHANNELS * 12 + 1))
    assert block_s < s.reply_time_limit_s(Command.TRB) <= s.max_reply_s
    assert s.reply_time_limit_s(Command.IOS) < 1.0
    assert s.transaction_limit_s(Command.OWW) > s.oww_timeout_s  # OWW's q comes about 5 s later
    assert DriveClient.open_limit_s(GUI) < 10.0


def test_replies_that_come_late_are_a_timeout_not_garbage(pipes):
    slow = LinkSettings(response_timeout_s=0.3, retries=1)

    documented = DocumentedDrive()

    def late(request):
        if isinstance(request, p.Request) and request.command is Command.IOS:
            # after the attempt gave up (0.3 s), inside the quiet-line wait before the retry
            return [0.45, p.Reply(("0",))]
        return documented(request)

    drive = ScriptedDrive(pipes[1], late)
    try:
        client = DriveClient.attach(pipes[0], slow)
        error, _ = _timed(lambda: client.transaction.transact(Command.IOS, parse=lambda r: r))
    finally:
        drive.close()
    assert type(error) is LinkTimeout and "IOS on hostile" in str(error)
