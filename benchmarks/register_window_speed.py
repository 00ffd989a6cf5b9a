"""What recording into a register on a PostgreSQL server costs the window (prints figures).

Run from the checkout: PYTHONPATH=. python benchmarks/register_window_speed.py [FACTS] (offscreen)

The single-axis window as ``fha-studio --register URL`` makes it, on a throw-away cluster (as the
tests start one: tests/support/postgres.py, Debian's postgresql) and settings and data in a
temporary directory. FACTS front-panel values (200) are entered one after another, as a
technician's fast typing would: the GUI thread's time for each (what the window spends before it
can draw again), the longest the GUI thread went without its event loop, and how long until the
last of them is on the server. The same again with the server stopped (the facts wait in this
computer's queue), then how long until the server has them once it is back; beside it, the GUI
thread's time per fact for a register file (written on that thread).
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time

TMP = tempfile.mkdtemp(prefix="fha-bench-")
os.environ["XDG_CONFIG_HOME"] = f"{TMP}/config"
os.environ["XDG_DATA_HOME"] = f"{TMP}/data"
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QCoreApplication, QTimer  # noqa: E402

from fha_studio.logic.register import Register, RegisterError  # noqa: E402

AXIS = "Bench/table"


def snapshots(url: str) -> int:
    with Register(url) as register:
        try:
            return len(register.snapshots(AXIS))
        except RegisterError:
            return 0


def main() -> int:
    facts = int(sys.argv[1]) if len(sys.argv) > 1 else 200
    from fha_studio.gui.app import make_application, parse_arguments, single_axis_window
    from tests.support.postgres import throwaway_cluster

    QCoreApplication.setOrganizationName("FHA Studio Benchmarks")
    app = make_application()  # as fha-studio: its GIL switch interval too

    def wait_until(condition, timeout_s: float = 300.0) -> float:
        started = time.perf_counter()
        while not condition():
            if time.perf_counter() - started > timeout_s:
                raise TimeoutError("no answer")
            app.processEvents()
            time.sleep(0.005)
        return time.perf_counter() - started

    longest = [0.0, time.perf_counter()]

    def tick() -> None:
        now = time.perf_counter()
        longest[0] = max(longest[0], now - longest[1])
        longest[1] = now

    with throwaway_cluster() as cluster:
        url = cluster.new_database()
        window = single_axis_window(parse_arguments(["--no-connect", "--register", url,
                                                     "--machine", "Bench", "--axis", "table"]))
        window.show()
        server = window.window_register.server
        watch = QTimer()
        watch.setInterval(5)
        watch.timeout.connect(tick)

        def enter(count: int, first: int) -> list[float]:
            times = []
            for n in range(count):
                t0 = time.perf_counter()
                window.state.enter_front_panel("tune", 4, (first + n) % 9000, f"person {first + n}")
                times.append(time.perf_counter() - t0)
                app.processEvents()
            return times

        window.state.enter_front_panel("tune", 4, 1, "warm-up")
        wait_until(lambda: server.answers is True and snapshots(url) == 1)
        longest[:] = [0.0, time.perf_counter()]
        watch.start()
        t0 = time.perf_counter()
        online = enter(facts, 2)
        wait_until(lambda: snapshots(url) == facts + 1)
        delivered_s = time.perf_counter() - t0
        watch.stop()
        online_longest = longest[0]

        cluster.stop()
        try:
            longest[:] = [0.0, time.perf_counter()]
            watch.start()
            offline = enter(facts, 10000)
            wait_until(lambda: server.answers is False and server.waiting == facts)
            watch.stop()
            offline_longest = longest[0]
        finally:
            cluster.start()
        t0 = time.perf_counter()
        window.window_register.deliver_now()
        wait_until(lambda: server.answers is True)
        back_s = time.perf_counter() - t0
        total = snapshots(url)
        window._closing_confirmed = True
        window.shutdown()
        window.deleteLater()

    # beside it: a register file, written on the GUI thread
    window = single_axis_window(parse_arguments(["--no-connect", "--register", f"{TMP}/file.sqlite",
                                                 "--machine", "Bench", "--axis", "table"]))
    window.show()
    enter(1, 1)
    in_file = enter(facts, 2)
    window._closing_confirmed = True
    window.shutdown()
    window.deleteLater()

    def ms(values: list[float]) -> str:
        return (f"median {statistics.median(values) * 1000:.2f} ms, "
                f"max {max(values) * 1000:.2f} ms")

    print(f"{facts} facts, server answering: GUI thread per fact {ms(online)}; longest without "
          f"its event loop {online_longest * 1000:.0f} ms; all on the server after {delivered_s:.2f} s")
    print(f"{facts} facts, server stopped:   GUI thread per fact {ms(offline)}; longest without "
          f"its event loop {offline_longest * 1000:.0f} ms")
    print(f"{facts} facts, a register file:  GUI thread per fact {ms(in_file)} (written on it)")
    print(f"server back: the {facts} waiting facts on it after {back_s:.2f} s; "
          f"the server holds {total} snapshots (expected {2 * facts + 1})")
    return 0 if total == 2 * facts + 1 else 1


if __name__ == "__main__":
    raise SystemExit(main())
