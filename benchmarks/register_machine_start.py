"""How long ``fha-studio gui --machine NAME --register postgresql://...`` takes to show its window
when the plant's register does not answer (prints figures).

Run from the checkout: PYTHONPATH=. python benchmarks/register_machine_start.py [RUNS] (offscreen)

Three servers: a closed port (refused at once), a listening socket that never answers (a network
that swallows the connection: the connection waits for its timeout, 5 s in the windows' threads),
and, where Debian's PostgreSQL is installed, a real throw-away server (as the tests start one).
For each: the time from the start of the machine window (``gui.app``'s own path, the machine known
to this computer's queue with two axes) to the window shown, the longest the GUI thread then went
without its event loop until the window has said what the register did (its axes, or that it is
not reachable), and that time. Beside it, what opening the register on the GUI thread (as the
start did before) costs against the same server. Settings and data in a temporary directory.
"""

from __future__ import annotations

import contextlib
import os
import socket
import statistics
import sys
import tempfile
import time

TMP = tempfile.mkdtemp(prefix="fha-bench-")
os.environ["XDG_CONFIG_HOME"] = f"{TMP}/config"
os.environ["XDG_DATA_HOME"] = f"{TMP}/data"
os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from PySide6.QtCore import QCoreApplication, QEvent, QTimer  # noqa: E402

from fha_studio.gui import register_worker  # noqa: E402
from fha_studio.gui.app import _machine_window, make_application, parse_arguments  # noqa: E402
from fha_studio.logic.machine import MachineProject  # noqa: E402
from fha_studio.logic.register import Register, RegisterError  # noqa: E402

MACHINE = "Line 3"
#: The longest the benchmark waits for the window to say what the register did [s].
SAID_WITHIN_S = 30.0


def known_here(url: str) -> None:
    project = MachineProject(MACHINE)
    project.add_axis("table", "FHA-25C-50-US250", port_url="/dev/ttyUSB0")
    project.add_axis("tilt", "FHA-32C-100-US250", port_url="/dev/ttyUSB1")
    with Register(register_worker.queue_path(url)) as queue:
        project.save_to(queue)


def said(window) -> bool:
    texts = [m.text for w in window.axis_windows for m in w.message_area.messages]
    return any("not reachable" in t or "did not know" in t or "refused" in t for t in texts) or (
        window.questions is not None and window.questions.answers is True and not window.axes_wanted
    )


def one_start(app, url: str) -> tuple[float, float, float]:
    """(shown after [s], the GUI thread's longest block until said [s], said after [s])."""
    started = time.perf_counter()
    window = _machine_window(parse_arguments(["--machine", MACHINE, "--register", url, "--no-connect"]))
    window.show()
    app.processEvents()
    shown = time.perf_counter() - started
    longest, last = 0.0, time.perf_counter()
    while not said(window) and time.perf_counter() - started < SAID_WITHIN_S:
        app.processEvents()
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
        time.sleep(0.002)
    said_s = time.perf_counter() - started
    window.shutdown()
    window.close()
    window.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete.value)
    return shown, longest, said_s


def opened_on_this_thread(url: str) -> float:
    started = time.perf_counter()
    with contextlib.suppress(RegisterError):
        Register(url).close()
    return time.perf_counter() - started


def report(name: str, app, url: str, runs: int) -> None:
    known_here(url)
    figures = [one_start(app, url) for _ in range(runs)]
    shown = [f[0] for f in figures]
    longest = [f[1] for f in figures]
    said_s = [f[2] for f in figures]
    before = opened_on_this_thread(url)
    print(f"{name}:")
    print(f"  window shown after        median {statistics.median(shown) * 1000:7.0f} ms, "
          f"max {max(shown) * 1000:6.0f} ms")
    print(f"  GUI thread's longest block median {statistics.median(longest) * 1000:7.0f} ms, "
          f"max {max(longest) * 1000:6.0f} ms")
    print(f"  the register's state said median {statistics.median(said_s):8.2f} s")
    print(f"  (opening the register on the GUI thread, as the start did: {before:.2f} s)")


def main() -> int:
    runs = int(sys.argv[1]) if len(sys.argv) > 1 else 5
    app = make_application()
    QTimer()  # the event loop's timers run in processEvents
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores, {runs} starts each")
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    report("closed port", app, f"postgresql://fha:pw@127.0.0.1:{port}/plant", runs)
    with socket.socket() as listener:
        listener.bind(("127.0.0.1", 0))
        listener.listen(64)
        report("a server that never answers", app,
               f"postgresql://fha:pw@127.0.0.1:{listener.getsockname()[1]}/plant", runs)
    try:
        from tests.support.postgres import throwaway_cluster
    except ImportError:
        return 0
    try:
        with throwaway_cluster() as cluster:
            url = cluster.new_database()
            with Register(url) as server:
                server.add_machine(MACHINE)
                server.add_axis(MACHINE, "base", "FHA-40C-160-US250", port_url="/dev/ttyUSB2")
            report("a real server with one axis more", app, url, runs)
    except BaseException as exc:  # pytest.skip without PostgreSQL's binaries
        print(f"(no real server: {exc})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
