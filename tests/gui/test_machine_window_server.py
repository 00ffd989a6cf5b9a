"""A machine window on a register on a real PostgreSQL server never asks or writes the server on
its own thread: the machine and an axis added go through this computer's queue, the Register
dialog's questions and the machine report's part from the register through a thread of their
own. With the server hung (SIGSTOP) and stopped, the window stays responsive (the GUI thread's
longest block is measured), the dialog says "Asking the server…" and then one line, the message
line says the server does not answer, and once it answers everything is on it once."""

from __future__ import annotations

import time
from urllib.parse import urlsplit

import pytest

from fha_studio.gui import register_questions, register_worker
from fha_studio.logic.machine import MachineProject
from fha_studio.logic.register import Register
from tests.gui.test_window_register_server import GuiThreadWatch, _hung, _said_since
from tests.support.windows import torn_down

MACHINE = "Line 3"
ACTUATOR = "FHA-25C-50-US250"


@pytest.fixture
def machine_window(qtbot, postgres_cluster, monkeypatch):
    """The machine window of Line 3 (one axis) on a new database of the tests' server, and its URL."""
    from fha_studio.gui.machine_window import MachineWindow

    monkeypatch.setattr(register_questions, "SLOW_S", 0.3)
    monkeypatch.setattr(register_questions, "GIVE_UP_S", 1.0)
    monkeypatch.setattr(register_worker, "RETRY_MIN_S", 0.5)
    url = postgres_cluster.new_database()
    project = MachineProject(MACHINE)
    project.add_axis("table", ACTUATOR, port_url=f"sim://{ACTUATOR}?paced=0")
    register = Register(url)
    with torn_down(lambda window: [axis.link for axis in window.axis_windows]) as windows:
        window = MachineWindow(project, register)
        windows.append(window)
        window.show()
        yield window, url
    register.close()


def _axes(url: str) -> list[str]:
    with Register(url) as register:
        try:
            return [a.name for a in register.axes(MACHINE)]
        except ValueError:  # the machine is not there yet
            return []


def _entries(url: str, axis: str) -> int:
    """The lines of the axis's history on the server (0 while it is not there)."""
    with Register(url) as register:
        try:
            return len(register.history(f"{MACHINE}/{axis}"))
        except ValueError:
            return 0


def _machine_reports(url: str) -> int:
    with Register(url) as register:
        return int(register._db.execute("SELECT COUNT(*) FROM report WHERE axis_id IS NULL").fetchone()[0])


def _messages(window) -> list[str]:
    return [m.text for w in window.axis_windows for m in w.message_area.messages]


def test_a_machine_window_on_a_server_that_hangs_and_stops(
    machine_window, qtbot, postgres_cluster, tmp_path, time_ceiling
):
    window, url = machine_window
    assert window.questions.on_server
    # the machine and its axis reach the server through this computer's queue
    qtbot.waitUntil(lambda: _entries(url, "table") == 1, timeout=30000)
    dialog = window.show_register()
    assert dialog.status_label.text() == "Asking the server…"  # the answer comes later, never now
    qtbot.waitUntil(lambda: dialog.history_axis.count() == 1 and dialog.status_label.text() == "",
                    timeout=30000)
    assert dialog.history_table.rowCount() >= 1
    assert dialog.where_label.text().startswith("Register on the server: postgresql://fha@/")

    watch = GuiThreadWatch()
    reports: list[tuple] = []
    try:
        with _hung(postgres_cluster, urlsplit(url).path.lstrip("/"), postmaster=True):
            started = time.monotonic()
            window.add_axis("tilt", ACTUATOR)  # into the queue: the server hears of it later
            written = window.write_machine_report(tmp_path / "line3.html", None,
                                                  lambda *done: reports.append(done))
            dialog.refresh()
            time_ceiling("an axis added, a report and the questions asked while the server hangs",
                         time.monotonic() - started, 2.0)
            assert written is None and dialog.status_label.text() == "Asking the server…"
            # not answered within GIVE_UP_S: one line in the dialog, one in the message line
            qtbot.waitUntil(lambda: dialog.status_label.text().startswith("Not answered: "), timeout=30000)
            said = dialog.status_label.text()
            assert "did not answer within 1 s" in said and "\n" not in said
            assert "fha-test-password" not in said
            qtbot.waitUntil(lambda: bool(reports), timeout=30000)
            html, pdf, why = reports[0]
            assert pdf is None and "did not answer" in why
            assert "is not in this report" in html.read_text(encoding="utf-8")
            # said on the axis on show (the new one: adding an axis shows it)
            said = _said_since(window.current_window, 0, "does not answer")
            assert said.startswith("Register: the server does not answer: no answer about ")
        # answering again: the axis added and the machine report are on the server, once
        qtbot.waitUntil(lambda: _axes(url) == ["table", "tilt"] and _machine_reports(url) == 1, timeout=30000)
        dialog.refresh()
        qtbot.waitUntil(lambda: dialog.history_axis.count() == 2 and dialog.status_label.text() == "",
                        timeout=30000)

        # the server stops: the dialog's questions are answered by one line at once
        with watch.paused():
            postgres_cluster.stop()
        try:
            dialog.refresh()
            qtbot.waitUntil(lambda: dialog.status_label.text().startswith("Not answered: "), timeout=30000)
            assert "the server" in dialog.status_label.text()
            assert dialog.history_axis.count() == 2  # what it showed stays
        finally:
            with watch.paused():
                postgres_cluster.start()
        dialog.refresh()
        qtbot.waitUntil(lambda: dialog.status_label.text() == "", timeout=30000)
    finally:
        watch.stop()
    time_ceiling("the GUI thread blocked", watch.longest_s, 3.0)
    assert any("answers again" in text for text in _messages(window))
