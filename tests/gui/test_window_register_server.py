"""The single-axis window on a register on a real PostgreSQL server never waits for the server:
facts go into this computer's queue (a register file per server) from a thread of their own and
on to the server from another. A server that hangs or stops while the window records is said in
the message line (one line, by its URL without the password), the window stays responsive (how
long its thread is ever blocked is measured), and once the server answers again every fact is on
it once; closing the window while the server hangs ends at once and loses nothing."""

from __future__ import annotations

import contextlib
import os
import signal
import threading
import time
from urllib.parse import urlsplit

import pytest
from PySide6.QtCore import QTimer

from fha_studio.gui import register_worker
from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register.identity import UID_TABLES
from fha_studio.logic.register.server import shown_url
from tests.support.postgres import SUPER_PASSWORD
from tests.support.windows import torn_down

AXIS = "Line 3/table"
#: A server made to hang answers again after this long whatever happens [s].
HUNG_AT_MOST_S = 60.0


@pytest.fixture
def make_window(monkeypatch, make_cli_window):
    """Factory: make_window(*options) -> the window ``fha-studio OPTIONS`` makes (conftest); a
    slow server is said after 0.5 s here (5 s in use)."""
    monkeypatch.setattr(register_worker, "SLOW_S", 0.5)
    monkeypatch.setattr(register_worker, "RETRY_MIN_S", 0.5)
    return make_cli_window


class GuiThreadWatch:
    """The longest the GUI thread went without running its event loop while the watch ran: a
    timer that should fire every 10 ms notes the longest gap between its firings. Meanwhile the
    test waits only on what the window shows (no question to the server from this thread)."""

    def __init__(self) -> None:
        self.longest_s = 0.0
        self._last = time.monotonic()
        self._timer = QTimer()
        self._timer.setInterval(10)
        self._timer.timeout.connect(self._tick)
        self._timer.start()

    def _tick(self) -> None:
        now = time.monotonic()
        self.longest_s = max(self.longest_s, now - self._last)
        self._last = now

    @contextlib.contextmanager
    def paused(self):
        """The test's own blocking work (the server stopped and started) is not the window's."""
        self._timer.stop()
        try:
            yield
        finally:
            self._last = time.monotonic()
            self._timer.start()

    def stop(self) -> None:
        self._timer.stop()


def _facts(target) -> dict[str, set[str]]:
    """Every fact's stable id, by table, and how many rows each table has (a fact twice would
    have two rows)."""
    with Register(target) as register:
        out = {}
        for table in UID_TABLES:
            rows = register._db.execute(f"SELECT uid FROM {table}").fetchall()
            uids = [str(r[0]) for r in rows]
            assert len(uids) == len(set(uids)), f"{table}: a fact twice"
            out[table] = set(uids)
        return out


def _snapshot_count(url: str) -> int:
    """The axis's snapshots on the server (0 while the axis is not there yet)."""
    with Register(url) as register:
        try:
            return len(register.snapshots(AXIS))
        except RegisterError:
            return 0


def _said_since(window, mark: int, words: str) -> str:
    """The first message from the ``mark``-th on that holds ``words`` ("" while there is none):
    a delivery before the mark may have been slow, and said so, too."""
    return next((m.text for m in window.message_area.messages[mark:] if words in m.text), "")


@contextlib.contextmanager
def _hung(cluster, database: str, postmaster: bool = False):
    """The server's processes serving ``database`` stop answering (SIGSTOP) until the block ends;
    with ``postmaster`` the server itself too (a new connection waits for it, as for a server
    whose network went away)."""
    import psycopg

    with psycopg.connect(cluster.url("postgres", "postgres", SUPER_PASSWORD), autocommit=True) as db:
        pids = [int(r[0]) for r in db.execute(
            "SELECT pid FROM pg_stat_activity WHERE datname = %s AND pid <> pg_backend_pid()", (database,)
        )]
    assert pids, "no connection of the window's to the server"
    if postmaster:
        pids.append(int((cluster.data / "postmaster.pid").read_text().split()[0]))

    def answer_again() -> None:
        for pid in pids:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGCONT)

    for pid in pids:
        os.kill(pid, signal.SIGSTOP)
    # should the window's own thread wait for the server (the fault this file is about), the
    # server answers again after a while, so that the test fails on its ceilings instead of hanging
    rescue = threading.Timer(HUNG_AT_MOST_S, answer_again)
    rescue.start()
    try:
        yield
    finally:
        rescue.cancel()
        rescue.join()
        answer_again()


def test_a_server_that_hangs_then_stops_while_the_window_records(
    make_window, qtbot, postgres_cluster, time_ceiling
):
    url = postgres_cluster.new_database()
    database = urlsplit(url).path.lstrip("/")
    window = make_window("--register", url, "--machine", "Line 3", "--axis", "table")
    recording = window.window_register
    assert recording.register is None  # the GUI thread holds no connection to the server
    window.state.enter_front_panel("system", 8, 0, "ana")
    qtbot.waitUntil(lambda: _snapshot_count(url) == 1, timeout=30000)
    qtbot.waitUntil(lambda: recording.server.answers is True, timeout=30000)
    where = shown_url(url)
    watch = GuiThreadWatch()
    try:
        # the server hangs: said as slow; the facts wait on this computer
        mark = len(window.message_area.messages)
        with _hung(postgres_cluster, database):
            started = time.monotonic()
            window.state.enter_front_panel("system", 8, 1, "ben")
            window.state.enter_front_panel("tune", 4, 20, "cy")
            time_ceiling("two facts handed over while the server hangs", time.monotonic() - started, 2.0)
            qtbot.waitUntil(lambda: bool(_said_since(window, mark, "slow to answer")), timeout=30000)
            said = _said_since(window, mark, "slow to answer")
            assert said == (f"Register: the server is slow to answer ({where}); what this window records "
                            "waits on this computer meanwhile.")
            assert "fha-test-password" not in said
        qtbot.waitUntil(lambda: bool(_said_since(window, mark, "the server answered")), timeout=30000)
        said = _said_since(window, mark, "the server answered")
        assert said.startswith(f"Register: the server answered ({where}); ") and said.endswith(" delivered.")
        with watch.paused():  # the test's own questions to the server
            qtbot.waitUntil(lambda: _snapshot_count(url) == 3, timeout=30000)

        # the server stops: said once, the line says how many wait
        with watch.paused():
            postgres_cluster.stop()
        try:
            mark = len(window.message_area.messages)
            window.state.enter_front_panel("tune", 4, 30, "dee")
            qtbot.waitUntil(lambda: recording.server.answers is False, timeout=30000)
            said = _said_since(window, mark, "does not answer")
            assert said.startswith("Register: the server does not answer; what this window records waits on "
                                   "this computer and goes to the server when it answers again (the register "
                                   f"{where}: the server ")
            assert said.endswith(").") and "nothing was changed" not in said
            assert "\n" not in said and "fha-test-password" not in said
            window.state.enter_front_panel("tune", 4, 40, "eve")
            qtbot.waitUntil(lambda: recording.server.waiting == 2, timeout=30000)
            assert recording.button.text().endswith("· server away, 2 facts waiting")
        finally:
            with watch.paused():
                postgres_cluster.start()
        mark = len(window.message_area.messages)
        recording.deliver_now()
        qtbot.waitUntil(lambda: recording.server.answers is True, timeout=30000)
        assert _said_since(window, mark, "answers again").startswith(
            f"Register: the server answers again ({where}); what waited on this computer is on it now ("
        )
    finally:
        watch.stop()
    time_ceiling("the GUI thread blocked", watch.longest_s, 3.0)
    # every fact once: what the queue has, the server has, and no fact is there twice
    queue = _facts(register_worker.queue_path(url))
    server = _facts(url)
    for table in UID_TABLES:
        assert queue[table] <= server[table], table
    assert _snapshot_count(url) == 5


def test_closing_while_the_server_hangs_ends_at_once_and_the_next_start_delivers(
    make_window, qtbot, postgres_cluster, time_ceiling
):
    url = postgres_cluster.new_database()
    database = urlsplit(url).path.lstrip("/")
    window = make_window("--register", url, "--machine", "Line 3", "--axis", "table")
    window.state.enter_front_panel("system", 8, 1, "ana")
    qtbot.waitUntil(lambda: _snapshot_count(url) == 1, timeout=30000)
    mark = len(window.message_area.messages)
    with _hung(postgres_cluster, database):
        window.state.enter_front_panel("tune", 4, 20, "ben")
        qtbot.waitUntil(lambda: bool(_said_since(window, mark, "slow to answer")), timeout=30000)
        started = time.monotonic()
        window.shutdown()  # the window closes: the delivery under way is cut off
        time_ceiling("closing while the server hangs", time.monotonic() - started, 8.0)
    # the fact is in this computer's queue; the next window on that server delivers it, once
    window = make_window("--register", url, "--machine", "Line 3", "--axis", "table")
    qtbot.waitUntil(lambda: window.window_register.server.answers is True, timeout=30000)
    qtbot.waitUntil(lambda: _snapshot_count(url) == 2, timeout=30000)
    assert _facts(register_worker.queue_path(url))["snapshot"] <= _facts(url)["snapshot"]


def test_a_machine_window_on_a_server_records_through_this_computers_queue(qtbot, postgres_cluster):
    from fha_studio.gui.machine_window import MachineWindow
    from fha_studio.logic.machine import MachineProject

    url = postgres_cluster.new_database()
    project = MachineProject("Line 3")
    project.add_axis("table", "FHA-25C-50-US250", port_url="sim://FHA-25C-50-US250?paced=0")
    register = Register(url)
    with torn_down(lambda window: [axis.link for axis in window.axis_windows]) as windows:
        window = MachineWindow(project, register)
        windows.append(window)
        window.show()
        assert window.server_writer is not None and window.recorders[0].writer is window.server_writer
        window.axis_windows[0].state.enter_front_panel("system", 8, 1, "ana")
        qtbot.waitUntil(lambda: _snapshot_count(url) == 1, timeout=30000)
        assert register_worker.queue_path(url).exists()
    register.close()


def test_a_delivery_that_hangs_is_cut_off_and_made_again_on_a_new_connection(
    make_window, qtbot, postgres_cluster, monkeypatch
):
    """A connection the network left waiting (here: its server process stopped) is given up after
    GIVE_UP_S and the delivery made again on a new one, while the old one still hangs."""
    monkeypatch.setattr(register_worker, "GIVE_UP_S", 1.0)
    url = postgres_cluster.new_database()
    window = make_window("--register", url, "--machine", "Line 3", "--axis", "table")
    window.state.enter_front_panel("system", 8, 1, "ana")
    qtbot.waitUntil(lambda: window.window_register.server.answers is True, timeout=30000)
    mark = len(window.message_area.messages)
    with _hung(postgres_cluster, urlsplit(url).path.lstrip("/")):
        window.state.enter_front_panel("tune", 4, 20, "ben")
        qtbot.waitUntil(lambda: bool(_said_since(window, mark, "the server answered")), timeout=30000)
        qtbot.waitUntil(lambda: _snapshot_count(url) == 2, timeout=30000)  # the old one still hangs


def test_the_queue_delivers_one_way_and_holds_only_what_this_computer_recorded(
    make_window, qtbot, postgres_cluster, fixed_clock
):
    """A window on a plant's register does not copy the plant's history to this computer: its
    queue holds the axis it records and its facts, nothing of the server's other facts."""
    from tests.register.test_sync import fill_offline

    url = postgres_cluster.new_database()
    fill_offline(url, "ben", fixed_clock, 0, "gripper", facts_per_axis=3)  # the plant's history
    before = _facts(url)
    window = make_window("--register", url, "--machine", "Line 3 positioner", "--axis", "table")
    window.state.enter_front_panel("system", 8, 1, "ana")
    qtbot.waitUntil(lambda: len(_facts(url)["snapshot"]) == len(before["snapshot"]) + 1, timeout=30000)
    queue = _facts(register_worker.queue_path(url))
    server = _facts(url)
    assert sum(map(len, queue.values())) == 2  # the axis's entry (its actuator) and the snapshot
    for table in UID_TABLES:
        assert queue[table] <= server[table] and not queue[table] & before[table], table
    with Register(register_worker.queue_path(url)) as copy:
        assert [a.ref for a in copy.axes()] == ["Line 3 positioner/table"]
    # the naming dialog offers the server's axes all the same, asked from another thread
    from fha_studio.gui.window_register import WindowAxisDialog

    dialog = WindowAxisDialog(window.window_register, window)
    qtbot.waitUntil(lambda: "gripper" in dialog._known.get("Line 3 positioner", []), timeout=30000)
    dialog.machine_combo.setCurrentText("Line 3 positioner")
    assert [dialog.axis_combo.itemText(i) for i in range(dialog.axis_combo.count())] == ["table", "gripper"]
    dialog.reject()
