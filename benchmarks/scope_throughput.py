"""Scope throughput: polled samples per second end to end against the line's limit, dropped
samples, and the live view's frames per second and CPU with 4 channels x 60 s at 1 kHz.

Run: QT_QPA_PLATFORM=offscreen python benchmarks/scope_throughput.py [--seconds S]
(prints figures; nothing is asserted).

1. Polling: the scope driver in its own thread with a DriveClient on the embedded simulated
   drive paced like the 19200 bit/s line (sim://...?paced=1); the view drains the ring on its
   GUI timer. Samples/s are counted where they arrive (the ring, drained by the view) and
   compared with the bound for the replies actually seen (``PollingAcquisition.limit_hz``).
2. View: a producer thread writes 4 channels at 1 kHz into the ring (as a fast acquisition
   would); the view shows a 60 s time base (240 000 points) from its pre-decimated min/max
   levels. Frames/s and the CPU of the whole process (producer included).
3. GUI: the main window on the paced simulated drive, the Scope page showing and plotting its
   default channels; samples/s against the line's limit, as a user sees it.

"% of the limit" counts every character on the line (a bus monitor on the client): the samples'
share of the line time the other exchanges (the held JOG, the window's status poll) leave free.
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

import numpy as np
from PySide6.QtCore import QEventLoop, QTimer

from fha_studio.gui.app import make_application
from fha_studio.gui.pages.scope.driver import LiveStarted, ScopeCmd, ScopeController
from fha_studio.gui.pages.scope.view import ScopeContext, ScopeView
from fha_studio.hardware import protocol as p
from fha_studio.hardware.client import DriveClient
from fha_studio.logic.scope.acquisition import LiveMode, estimated_rate_hz
from fha_studio.logic.scope.ring import RingBuffer

ACTUATOR = "FHA-25C-50-US250"


def run_for(seconds: float) -> None:
    loop = QEventLoop()
    QTimer.singleShot(int(seconds * 1000), loop.quit)
    loop.exec()


def cpu_s() -> float:
    t = os.times()
    return t.user + t.system


class LineCounter:
    """Counts the characters on the line (both ways) through the client's bus-monitor hook."""

    def __init__(self) -> None:
        self.chars = 0

    def __call__(self, sending: bool, data: bytes) -> None:
        self.chars += len(data)


def pct_of_limit(samples: int, seconds: float, limit_hz: float, line_chars: int) -> float:
    """Samples per second as a percentage of what the line could carry in the time the other
    exchanges left free: ``samples * sample_line_time / (seconds - other_line_time)``."""
    char_s = p.character_time_s()
    sample_line_s = samples / limit_hz
    other_line_s = max(0.0, line_chars * char_s - sample_line_s)
    return 100.0 * sample_line_s / max(1e-9, seconds - other_line_s)


def polling(keys: tuple[str, ...], seconds: float, jog_rpm: float) -> dict:
    client = DriveClient.open(f"sim://{ACTUATOR}")  # paced like the real line
    controller = ScopeController()
    view = ScopeView(controller, ScopeContext(ACTUATOR))
    view.resize(1200, 700)
    view.show()
    jog = QTimer()
    counter = LineCounter()
    client.trace_packet = counter
    try:
        controller.attach(client, 50)
        for c in view.all_channels:
            view._visible[c.key] = c.key in keys
        if jog_rpm:
            controller.send(ScopeCmd.CALL, lambda c: (c.servo(True), c.jog(jog_rpm)))
            jog.timeout.connect(lambda: controller.send(ScopeCmd.CALL, lambda c: c.jog(jog_rpm)))
            jog.start(40)  # the held jog button: JOG every 40 ms (it shares the line)
        view.start_live()
        run_for(1.0)  # settle: first replies, speed reached
        # samples counted where they arrive (the ring), at the same moments as the clock and the
        # line's characters (the status the driver sends every 0.2 s would blur the interval)
        ring = view._live.ring
        written0, chars0, t0 = ring.written, counter.chars, time.monotonic()
        run_for(seconds)
        samples, chars, elapsed = ring.written - written0, counter.chars - chars0, time.monotonic() - t0
        status = view._status
        jog.stop()
        items = len(controller.driver._poller.items)
        return {"items": items, "rate": samples / elapsed, "limit": status.limit_hz,
                "dropped": status.dropped, "estimate": estimated_rate_hz(items),
                "pct": pct_of_limit(samples, elapsed, status.limit_hz, chars)}
    finally:
        jog.stop()
        view.shutdown()
        controller.shutdown()
        client.close()
        view.close()


def view_load(seconds: float, rate_hz: float = 1000.0, channels: int = 4, span_s: float = 60.0) -> dict:
    controller = ScopeController()
    view = ScopeView(controller, ScopeContext(ACTUATOR))
    view.resize(1366, 768)
    view.show()
    shown = [c for c in view.all_channels if c.key in ("feedback_position", "command_position",
                                                        "output_speed", "motor_current")][:channels]
    ring = RingBuffer(1 + channels, int(span_s * rate_hz * 1.2))
    t0 = time.monotonic()
    # 60 s of history already there, then 1 kHz more while we measure
    n0 = int(span_s * rate_hz)
    t = np.arange(-n0, 0) / rate_hz
    ring.write(np.column_stack([t] + [np.sin(np.pi * (k + 1) * t) * (k + 1) for k in range(channels)]))
    stop = threading.Event()

    def produce() -> None:
        written = 0
        while not stop.is_set():
            now = time.monotonic() - t0
            due = int(now * rate_hz) - written
            if due > 0:
                tt = (written + np.arange(due)) / rate_hz
                ring.write(np.column_stack([tt] + [np.sin(2 * np.pi * (k + 1) * 0.5 * tt) * (k + 1)
                                                   for k in range(channels)]))
                written += due
            stop.wait(0.005)

    producer = threading.Thread(target=produce, name="bench producer")
    view.time_base.setCurrentIndex(view.time_base.findData(60.0))
    view._on_live_started(LiveStarted(LiveMode.MONITORS, tuple(shown), ring, t0))
    producer.start()
    try:
        run_for(1.0)
        f0, c0, w0 = view.frames, cpu_s(), time.monotonic()
        run_for(seconds)
        frames, cpu, wall = view.frames - f0, cpu_s() - c0, time.monotonic() - w0
    finally:
        stop.set()
        producer.join()
        view.shutdown()
        controller.shutdown()
        view.close()
    return {"fps": frames / wall, "cpu": 100.0 * cpu / wall, "points": len(ring) * channels,
            "cpu_per_frame_ms": 1000.0 * cpu / max(1, frames),
            "dropped": ring.dropped}


def gui_polling(seconds: float) -> dict:
    """The main window on the paced simulated drive, Scope page showing, live with its default
    channels: samples/s where the view gets them, against the line's limit."""
    from fha_studio.gui.link import Call
    from fha_studio.gui.main_window import MainWindow

    window = MainWindow()
    window.resize(1366, 768)
    window.show()
    counter = LineCounter()
    connected = []
    window.link.sigConnected.connect(connected.append)
    window.connect_to(f"sim://{ACTUATOR}")
    deadline = time.monotonic() + 30
    while not connected and time.monotonic() < deadline:
        run_for(0.05)
    if not connected:
        raise SystemExit("the GUI did not connect to the simulated drive within 30 s")
    window.link.send(Call(lambda client: setattr(client, "trace_packet", counter)))
    try:
        window.show_page("scope")
        view = window.scope_page.view
        view.start_live()
        run_for(1.5)  # settle: first replies, the window's own status poll slowed down
        ring = view._live.ring
        written0, chars0, frames0, t0 = ring.written, counter.chars, view.frames, time.monotonic()
        run_for(seconds)
        samples, chars, elapsed = ring.written - written0, counter.chars - chars0, time.monotonic() - t0
        status = view._status
        return {"items": len(view._live.channels), "rate": samples / elapsed, "limit": status.limit_hz,
                "dropped": status.dropped, "fps": (view.frames - frames0) / elapsed,
                "pct": pct_of_limit(samples, elapsed, status.limit_hz, chars)}
    finally:
        window._closing_confirmed = True
        window.close()
        window.shutdown()


def isolate_settings() -> None:
    """Keep the user's settings and data out of a benchmark (QSettings and XDG paths in a temp dir)."""
    import tempfile

    from PySide6.QtCore import QCoreApplication, QSettings

    tmp = tempfile.mkdtemp(prefix="fha-bench-")
    for fmt in (QSettings.Format.NativeFormat, QSettings.Format.IniFormat):
        QSettings.setPath(fmt, QSettings.Scope.UserScope, f"{tmp}/settings")
    QCoreApplication.setOrganizationName("FHA Studio Benchmark")
    QCoreApplication.setApplicationName("fha-studio-benchmark")
    os.environ["XDG_CONFIG_HOME"] = f"{tmp}/config"
    os.environ["XDG_DATA_HOME"] = f"{tmp}/data"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0], allow_abbrev=False)
    parser.add_argument("--seconds", type=float, default=10.0, help="measuring time per case [s]")
    parser.add_argument("--switch-interval", type=float, default=None,
                        help="sys.setswitchinterval for the run [s] (default: the GUI's, "
                             "fha_studio.gui.app.GIL_SWITCH_INTERVAL_S)")
    args = parser.parse_args()
    make_application()  # the QApplication as the GUI makes it (GIL switch interval included)
    if args.switch_interval:
        sys.setswitchinterval(args.switch_interval)
    load = os.getloadavg()[0]
    print(f"machine: {os.cpu_count()} cores, load average {load:.1f} (figures shrink with the load); "
          f"GIL switch interval {sys.getswitchinterval() * 1000:g} ms")
    print(f"Polling over the simulated drive paced at 19200 bit/s, {args.seconds:g} s per case")
    cases = (
        ("position", ("feedback_position",), 0.0),
        ("pos, cmd, speed, current (standstill)", ("feedback_position", "command_position", "output_speed",
                                                   "motor_current"), 0.0),
        ("pos, cmd, speed, current (jogging 20 r/min)", ("feedback_position", "command_position",
                                                         "output_speed", "motor_current"), 20.0),
    )
    for name, keys, jog in cases:
        r = polling(keys, args.seconds, jog)
        print(f"  {name}: {r['items']} items, {r['rate']:.1f} samples/s delivered, line limit "
              f"{r['limit']:.1f}/s for the replies seen ({r['pct']:.0f} % of the line time left by the "
              f"other exchanges), dropped {r['dropped']}")
    isolate_settings()
    g = gui_polling(args.seconds)
    print(f"  GUI, Scope page showing and plotting: {g['items']} channels, {g['rate']:.1f} samples/s, line "
          f"limit {g['limit']:.1f}/s ({g['pct']:.0f} %), {g['fps']:.1f} frames/s, dropped {g['dropped']}")
    print("Live view, 4 channels x 60 s at 1 kHz (offscreen, pre-decimated min/max levels)")
    v = view_load(args.seconds)
    print(f"  {v['points']} points on show: {v['fps']:.1f} frames/s (goal >= 30/s), "
          f"CPU {v['cpu']:.0f} % of one core (whole process, producer included), "
          f"{v['cpu_per_frame_ms']:.0f} ms CPU per frame, dropped {v['dropped']}")


if __name__ == "__main__":
    main()
