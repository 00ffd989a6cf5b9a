"""Scope throughput: polled samples per second end to end against the line's limit, dropped
samples, and the live view's frames per second and CPU with 4 channels x 60 s at 1 kHz.

Run: QT_QPA_PLATFORM=offscreen python benchmarks/scope_throughput.py [--seconds S]
(prints figures; nothing is asserted).

1. Polling: the scope driver in its own thread with a DriveClient on the embedded simulated
   drive paced like the 19200 bit/s line (sim://...?paced=1); the view drains the ring on its
   GUI timer. Samples/s are counted where they arrive (the ring, drained by the view) and
   compared with the bound for the replies actually seen (``PollingAcquisition.limit_hz``).
2. View: a producer thread writes 4 channels at 1 kHz into the ring (as a fast acquisition
   would); the view shows a 60 s time base (240 000 points), peak downsampling, clip to view.
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
from PySide6.QtWidgets import QApplication

from fha_studio.gui.pages.scope.driver import LiveStarted, ScopeCmd, ScopeController
from fha_studio.gui.pages.scope.view import ScopeContext, ScopeView
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


def polling(keys: tuple[str, ...], seconds: float, jog_rpm: float) -> dict:
    client = DriveClient.open(f"sim://{ACTUATOR}")  # paced like the real line
    controller = ScopeController()
    view = ScopeView(controller, ScopeContext(ACTUATOR))
    view.resize(1200, 700)
    view.show()
    jog = QTimer()
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
        status0 = view._status
        run_for(seconds)
        status = view._status
        jog.stop()
        rate = (status.samples - status0.samples) / seconds
        items = len(controller.driver._poller.items)
        return {"items": items, "rate": rate, "limit": status.limit_hz, "dropped": status.dropped,
                "estimate": estimated_rate_hz(items)}
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="measuring time per case [s]")
    parser.add_argument("--switch-interval", type=float, default=None,
                        help="sys.setswitchinterval for the run [s] (Python's default: 0.005)")
    args = parser.parse_args()
    if args.switch_interval:
        sys.setswitchinterval(args.switch_interval)
    load = os.getloadavg()[0]
    print(f"machine: {os.cpu_count()} cores, load average {load:.1f} (figures shrink with the load); "
          f"GIL switch interval {sys.getswitchinterval() * 1000:g} ms")
    QApplication.instance() or QApplication([])
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
              f"{r['limit']:.1f}/s for the replies seen ({100 * r['rate'] / r['limit']:.0f} %), "
              f"dropped {r['dropped']}")
    print("Live view, 4 channels x 60 s at 1 kHz (offscreen, peak downsampling, clip to view)")
    v = view_load(args.seconds)
    print(f"  {v['points']} points on show: {v['fps']:.1f} frames/s (wanted: ~16/s, a pixel per frame), "
          f"CPU {v['cpu']:.0f} % of one core (whole process, producer included), "
          f"{v['cpu_per_frame_ms']:.0f} ms CPU per frame, dropped {v['dropped']}")


if __name__ == "__main__":
    main()
