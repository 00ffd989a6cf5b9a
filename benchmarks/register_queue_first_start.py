"""A window's first start on a large plant register on a PostgreSQL server (prints figures): how
long until the first fact it records is on the server, how long until its first delivery ends, and
how big this computer's queue for the server gets.

Run from the checkout: PYTHONPATH=. python benchmarks/register_queue_first_start.py [URL] [AXES] [PER_DAY]

Without URL it starts a throw-away cluster of its own (as the tests do: tests/support/postgres.py).
The server's register is filled as ``register_server_speed.py`` fills it: AXES axes (1000) with 10
years of facts each (PER_DAY verified writes a day, 1; a snapshot of 14 values a month). Then the
single-axis window as ``fha-studio --register URL --machine park --axis "axis 7"`` makes it, with
settings and data in a new temporary directory (no queue yet: the first start on this computer),
records a value entered from the front panel, and later a second one (a delivery once the first
start is over). The GUI thread's longest time without its event loop is measured from the window
shown to the second fact on the server.
"""

from __future__ import annotations

import contextlib
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

TMP = tempfile.mkdtemp(prefix="fha-bench-")
os.environ["XDG_CONFIG_HOME"] = f"{TMP}/config"
os.environ["XDG_DATA_HOME"] = f"{TMP}/data"
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")
sys.path.insert(0, str(Path(__file__).resolve().parent))

from PySide6.QtCore import QCoreApplication, QTimer  # noqa: E402
from register_server_speed import YEARS, fill  # noqa: E402

#: The longest a delivery may take here before the benchmark gives up [s].
WAIT_S = 1800.0


def on_server(url: str, who: str) -> int:
    """The snapshots the server holds that ``who`` recorded."""
    import psycopg

    with psycopg.connect(url) as db:
        row = db.execute("SELECT COUNT(*) FROM snapshot WHERE who = %s", (who,)).fetchone()
        return int(row[0]) if row else 0


def megabytes(path: Path) -> float:
    return sum(p.stat().st_size for p in path.parent.glob(path.name + "*")) / 1e6


def measure(url: str, axes: int, per_day: int) -> None:
    from fha_studio.gui.app import make_application, parse_arguments, single_axis_window

    _, rows, filled = fill(url, axes, per_day)
    print(f"register on the server: {axes} axes x {YEARS} years: {rows:,} rows (filled in {filled:.0f} s)")
    QCoreApplication.setOrganizationName("FHA Studio Benchmarks")
    app = make_application()
    longest = [0.0, time.perf_counter()]

    def tick() -> None:
        now = time.perf_counter()
        longest[0] = max(longest[0], now - longest[1])
        longest[1] = now

    def wait_until(condition, timeout_s: float = WAIT_S) -> float:
        started = time.perf_counter()
        while not condition():
            if time.perf_counter() - started > timeout_s:
                raise TimeoutError("no answer")
            app.processEvents()
            time.sleep(0.01)
        return time.perf_counter() - started

    watch = QTimer()
    watch.setInterval(5)
    watch.timeout.connect(tick)
    t0 = time.perf_counter()
    window = single_axis_window(parse_arguments(["--no-connect", "--register", url,
                                                 "--machine", "park", "--axis", "axis 7"]))
    window.show()
    app.processEvents()
    longest[:] = [0.0, time.perf_counter()]
    watch.start()
    server = window.window_register.server
    assert server is not None
    busy: list[bool] = []
    server._delivery.sigBusy.connect(busy.append)
    made_s = time.perf_counter() - t0
    window.state.enter_front_panel("tune", 4, 21, "first")
    t1 = time.perf_counter()
    try:
        first_s = wait_until(lambda: on_server(url, "first") == 1)
    except TimeoutError:
        print(f"the first fact was not on the server after {WAIT_S:.0f} s; the queue holds "
              f"{megabytes(server.queue):.0f} MB; the window said:")
        for message in window.message_area.messages:
            print(f"  {message.text}")
        raise
    ended_s = wait_until(lambda: server.answers is True and busy[-1:] == [False]) + first_s
    size_mb = megabytes(server.queue)
    window.state.enter_front_panel("tune", 4, 22, "second")
    second_s = wait_until(lambda: on_server(url, "second") == 1)
    watch.stop()
    window._closing_confirmed = True
    t2 = time.perf_counter()
    window.shutdown()
    closed_s = time.perf_counter() - t2
    window.deleteLater()
    print(f"window made in {made_s:.2f} s; first fact on the server {first_s:.2f} s after it was "
          f"recorded; the first delivery ended after {ended_s:.2f} s "
          f"({time.perf_counter() - t1:.0f} s in all)")
    print(f"this computer's queue for the server: {size_mb:.2f} MB after the first delivery")
    print(f"a second fact on the server after {second_s:.2f} s; the GUI thread's longest time "
          f"without its event loop {longest[0] * 1000:.0f} ms; closing {closed_s:.2f} s")


def main() -> None:
    url = sys.argv[1] if len(sys.argv) > 1 and "://" in sys.argv[1] else ""
    numbers = [int(a) for a in sys.argv[1:] if a.isdigit()]
    axes = numbers[0] if numbers else 1000
    per_day = numbers[1] if len(numbers) > 1 else 1
    with contextlib.ExitStack() as stack:
        stack.callback(shutil.rmtree, TMP, ignore_errors=True)  # this computer's queue with it
        from tests.support.postgres import given_or_throwaway

        measure(stack.enter_context(given_or_throwaway(url)), axes, per_day)


if __name__ == "__main__":
    main()
