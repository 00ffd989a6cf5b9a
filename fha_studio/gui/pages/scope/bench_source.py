"""A bench instrument as a scope source: sigrok-cli streamed in a worker thread of its own.

``BenchWorker`` lives on a ``QThread`` and runs one :class:`sigrok.Acquisition` at a time in its
slot (the thread is the stream's: it blocks on sigrok-cli's pipe, never the GUI). Each block is
brought down to display rows (:mod:`fha_studio.logic.bench.display`) and written into a
``RingBuffer``; no signal per block. ``BenchSource`` (GUI thread) owns the thread, starts and
stops the stream, and one GUI-thread timer drains the ring and hands the rows on
(``sigRows``), as the scope's view drains the CN3 polling's ring. Every channel is named with
its source (``demo:D0``), so a plot beside CN3 channels says where each trace came from.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from dataclasses import dataclass
from functools import partial

import numpy as np
from PySide6.QtCore import QObject, QThread, QTimer, Signal, Slot

from fha_studio.hardware.bench import sigrok
from fha_studio.logic.bench import instruments
from fha_studio.logic.bench.decode import DecodeError
from fha_studio.logic.bench.display import (
    DISPLAY_RATE_HZ,
    Decimator,
    LiveCommandPulses,
    LiveQuadrature,
    display_factor,
)
from fha_studio.logic.bench.importer import DriveSettings
from fha_studio.logic.scope.ring import RingBuffer

#: Display rows the ring holds (10 s at the display rate).
RING_ROWS = int(10 * DISPLAY_RATE_HZ)
#: Period of the GUI timer that drains the ring [ms] (the scope's frame rate).
DRAIN_INTERVAL_MS = 25
#: How often the worker says how far it has come [s].
STATUS_INTERVAL_S = 0.2


@dataclass(frozen=True)
class BenchSettings:
    """What to stream: the instrument (``DRIVER[:OPTIONS]``), its channels, the rate (None: the
    instrument's own)."""

    device: str
    channels: tuple[str, ...]
    sample_rate_hz: float | None = None
    encoder: tuple[str, str] | None = None  # encoder A and B among the channels: counted x4 live
    # the command pulse lines (A, and B or None) among the channels, decoded live by ``drive``
    command: tuple[str, str | None] | None = None
    drive: DriveSettings | None = None  # parameters 1, 2, 3, 4 and 9 (the command's decoding)


@dataclass(frozen=True)
class BenchStarted:
    """A stream started: what each ring column is (after ``t_s``), its rates and the ring."""

    device: str
    channels: tuple[str, ...]  # as the instrument names them
    labels: tuple[str, ...]  # with the source: "demo:D0"; then "demo:D0/D1 counts", "... command counts"
    sample_rate_hz: float
    row_rate_hz: float
    ring: RingBuffer
    t0: float  # time.monotonic() of t_s = 0
    logic: tuple[str, ...] = ()  # the channels that are logic levels (the rest analog)
    extra: tuple[str, ...] = ()  # the decoded columns after the channels: "counts", "command"


@dataclass(frozen=True)
class BenchStatus:
    samples: int  # instrument samples so far
    rows: int  # display rows written
    dropped: int  # display rows overwritten before the GUI drained them


def source_label(device: str, channel: str) -> str:
    """A channel named with its source, as the scope shows it beside CN3's: ``demo:D0``."""
    return f"{device.split(':', 1)[0]}:{channel}"


class BenchWorker(QObject):
    """Streams in the thread it lives in; results go out through queued signals."""

    sigStarted = Signal(object)  # BenchStarted
    sigStatus = Signal(object)  # BenchStatus
    sigError = Signal(str)  # refused before any sample (one line)
    sigVanished = Signal(str, int)  # the instrument went away: one line, samples kept
    sigFinished = Signal(int)  # stopped as asked: samples
    sigDevices = Signal(object, str)  # the instruments sigrok-cli finds (list of Device), or why none

    def __init__(self) -> None:
        super().__init__()
        self._lock = threading.Lock()
        self._acquisition: instruments.Instrument | None = None
        self._stop = False

    def request_stop(self) -> None:
        """Any thread: end the running stream (sigrok-cli is asked through its stdin)."""
        with self._lock:
            self._stop = True
            if self._acquisition is not None:
                self._acquisition.stop()

    @Slot(str)
    def scan(self, driver: str) -> None:
        """List the instruments (every driver when ``driver`` is empty)."""
        try:
            found, why = instruments.scan(driver or None)
        except sigrok.SigrokError as exc:
            found, why = [], str(exc)
        self.sigDevices.emit(found, why if not found else "")

    @Slot(object)
    def run(self, settings: BenchSettings) -> None:
        if settings.encoder is not None and not set(settings.encoder) <= set(settings.channels):
            self.sigError.emit(f"encoder {'/'.join(settings.encoder)}: both must be among the channels "
                               f"({', '.join(settings.channels)})")
            return
        if settings.command is not None and not {c for c in settings.command if c} <= set(settings.channels):
            self.sigError.emit(f"command pulses {'/'.join(c for c in settings.command if c)}: the lines "
                               f"must be among the channels ({', '.join(settings.channels)})")
            return
        commands = None
        if settings.command is not None:
            drive = settings.drive or DriveSettings(0, 4, 1, 1, 3000.0)
            try:
                commands = LiveCommandPulses(drive.pulse_form, drive.multiplication, drive.gear_numerator,
                                             drive.gear_denominator)
            except DecodeError as exc:
                self.sigError.emit(str(exc))
                return
        acquisition = instruments.open_instrument(settings.device, settings.channels, settings.sample_rate_hz)
        try:
            acquisition.start()
        except sigrok.SigrokError as exc:
            self.sigError.emit(str(exc))
            return
        with self._lock:
            self._acquisition = acquisition
            if self._stop:
                acquisition.stop()
        factor = display_factor(acquisition.sample_rate_hz)
        encoder = settings.encoder
        quadrature = LiveQuadrature() if encoder is not None else None
        extra = (("counts",) if encoder is not None else ()) + (("command",) if commands is not None else ())
        decimator = Decimator(acquisition.sample_rate_hz, settings.channels, factor, extra)
        ring = RingBuffer(1 + len(settings.channels) + len(extra), RING_ROWS)
        labels = tuple(source_label(settings.device, c) for c in settings.channels)
        if encoder is not None:
            labels += (source_label(settings.device, f"{encoder[0]}/{encoder[1]} counts"),)
        if settings.command is not None:
            lines = "/".join(c for c in settings.command if c)
            labels += (source_label(settings.device, f"{lines} command counts"),)
        self.sigStarted.emit(BenchStarted(settings.device, settings.channels, labels,
                                          acquisition.sample_rate_hz, decimator.row_rate_hz, ring,
                                          time.monotonic(),
                                          instruments.logic_channels(acquisition, settings.channels), extra))
        last_status = 0.0
        try:
            for block in acquisition.blocks():
                # decoded on the packed words at each display row's last sample (all a row shows)
                counts: dict[str, Callable[[np.ndarray], np.ndarray]] = {}
                bit = block.logic_channels.index
                if quadrature is not None and encoder is not None:
                    counts["counts"] = partial(quadrature.feed_windows, block.logic, bit(encoder[0]),
                                               bit(encoder[1]))
                if commands is not None and settings.command is not None:
                    line_a, line_b = settings.command
                    counts["command"] = partial(commands.feed_windows, block.logic, bit(line_a),
                                                bit(line_b) if line_b else None)
                rows = decimator.feed(block, counts)
                if len(rows):
                    ring.write(rows)
                now = time.monotonic()
                if now - last_status >= STATUS_INTERVAL_S:
                    last_status = now
                    self.sigStatus.emit(BenchStatus(acquisition.samples, ring.written, ring.dropped))
        except sigrok.DeviceVanished as exc:
            self.sigVanished.emit(str(exc), exc.samples)
            return
        except sigrok.SigrokError as exc:
            self.sigError.emit(str(exc))
            return
        finally:
            acquisition.close()
            with self._lock:
                self._acquisition = None
                self._stop = False
        self.sigStatus.emit(BenchStatus(acquisition.samples, ring.written, ring.dropped))
        self.sigFinished.emit(acquisition.samples)


class BenchSource(QObject):
    """The GUI side: one worker thread, one drain timer. ``sigRows`` carries the rows
    ``[t_s, values...]`` each timer tick drained (none when nothing came)."""

    sigStart = Signal(object)  # BenchSettings, queued to the worker
    sigScan = Signal(str)  # a driver or "", queued to the worker
    sigRows = Signal(object)  # np.ndarray, in the GUI thread
    sigStarted = Signal(object)  # BenchStarted
    sigStopped = Signal(str)  # "" when stopped as asked, else the one line why

    def __init__(self, parent: QObject | None = None):
        super().__init__(parent)
        self.started: BenchStarted | None = None
        self.status: BenchStatus | None = None
        self.running = False
        self._thread = QThread()
        self._thread.setObjectName("bench-sigrok")
        self.worker = BenchWorker()
        self.worker.moveToThread(self._thread)
        self.sigStart.connect(self.worker.run)
        self.sigScan.connect(self.worker.scan)
        self.worker.sigStarted.connect(self._on_started)
        self.worker.sigStatus.connect(self._on_status)
        self.worker.sigError.connect(self._on_ended)
        # bound slots, not lambdas: a lambda would run in the worker's thread
        self.worker.sigVanished.connect(self._on_vanished)
        self.worker.sigFinished.connect(self._on_finished)
        self._timer = QTimer(self)
        self._timer.setInterval(DRAIN_INTERVAL_MS)
        self._timer.timeout.connect(self.drain)
        self._thread.start()

    def start(self, settings: BenchSettings) -> None:
        if self.running:
            raise RuntimeError("a bench stream is running already")
        self.running = True
        self.started = None
        self.sigStart.emit(settings)

    def stop(self) -> None:
        if self.running:
            self.worker.request_stop()

    def drain(self) -> None:
        """The GUI timer: the rows written since the last tick."""
        if self.started is None:
            return
        rows = self.started.ring.drain()
        if len(rows):
            self.sigRows.emit(rows)

    def shutdown(self) -> None:
        """Stop the stream and the thread (waits for both; call before the source goes)."""
        self.stop()
        self._thread.quit()
        self._thread.wait()
        self._timer.stop()

    @Slot(object)
    def _on_started(self, started: BenchStarted) -> None:
        self.started = started
        self._timer.start()
        self.sigStarted.emit(started)

    @Slot(object)
    def _on_status(self, status: BenchStatus) -> None:
        self.status = status

    @Slot(str, int)
    def _on_vanished(self, why: str, _samples: int) -> None:
        self._on_ended(why)

    @Slot(int)
    def _on_finished(self, _samples: int) -> None:
        self._on_ended("")

    @Slot(str)
    def _on_ended(self, why: str) -> None:
        self.drain()  # what came last
        self._timer.stop()
        self.running = False
        self.sigStopped.emit(why)


def rows_as_columns(started: BenchStarted, rows: np.ndarray) -> dict[str, np.ndarray]:
    """Drained rows as ``{label: values}`` plus ``t_s`` (for a plot or a recorder)."""
    columns = {"t_s": rows[:, 0]}
    for i, label in enumerate(started.labels):
        columns[label] = rows[:, 1 + i]
    return columns
