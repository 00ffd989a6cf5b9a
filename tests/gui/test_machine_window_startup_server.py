"""``fha-studio gui --machine NAME --register postgresql://...`` never waits for the server before
its window shows: a technician's laptop on a shop floor without the plant's network gets the
window at once, with the axes this computer's queue for the server knows (none for a machine never
opened here); the machine's axes are asked of the server from the questions' thread, and the
message line says that the plant's register is not reachable and that what the window records is
queued on this computer. Three servers: a closed port (refused at once), a listening socket that
never answers (a network that swallows the connection: the connection waits for its timeout), and
a real PostgreSQL server that has an axis this computer did not know; a wrong password.

The window's start is proved not to wait without a clock: it is built, shown and says it asks
while the question's connection still waits, unanswered, in the silent server's backlog (with a
connection timeout no test reaches: a start that waited for it would hang the test)."""

from __future__ import annotations

import contextlib
import select
import socket

import pytest

from fha_studio.gui import register_questions, register_worker
from fha_studio.gui.app import _machine_window, parse_arguments
from fha_studio.logic.machine import MachineProject
from fha_studio.logic.register import Register
from fha_studio.logic.register.facts_from_session import alarm_facts, axis_fact
from fha_studio.logic.register.sync import sync_registers
from tests.support.windows import torn_down

MACHINE = "Line 3"
ACTUATOR = "FHA-25C-50-US250"
#: the shortest connection timeout libpq keeps [s] (it takes a smaller one as 2)
SHORT_CONNECT_TIMEOUT_S = 2.0
#: a connection timeout no test reaches [s]: a connection to the silent server waits until the
#: test closes it (a start that waited for it would hang the test)
NEVER_S = 600.0


@pytest.fixture
def started(qtbot, monkeypatch):
    """``started(url, machine=MACHINE)``: the window ``fha-studio gui --machine MACHINE --register
    URL --no-connect`` builds (as the GUI's start does), shown; torn down afterwards."""
    monkeypatch.setattr(register_questions, "CONNECT_TIMEOUT_S", SHORT_CONNECT_TIMEOUT_S)
    monkeypatch.setattr(register_worker, "CONNECT_TIMEOUT_S", SHORT_CONNECT_TIMEOUT_S)
    monkeypatch.setattr(register_worker, "RETRY_MIN_S", 0.5)

    def start(url: str, machine: str = MACHINE):
        args = parse_arguments(["--machine", machine, "--register", url, "--no-connect"])
        window = _machine_window(args)
        windows.append(window)
        window.show()
        return window

    with torn_down(lambda window: [axis.link for axis in window.axis_windows]) as windows:
        yield start


def _known_here(url: str, *axes: str) -> None:
    """This computer's queue for the server knows the machine with ``axes`` (a window here recorded
    it before)."""
    project = MachineProject(MACHINE, site="Plant A")
    for number, axis in enumerate(axes):
        project.add_axis(axis, ACTUATOR, port_url=f"/dev/ttyUSB{number}")
    with Register(register_worker.queue_path(url)) as queue:
        project.save_to(queue, who="ana")


def _queued_axes(url: str) -> list[str]:
    with Register(register_worker.queue_path(url), read_only=True) as queue:
        try:
            return [a.name for a in queue.axes(MACHINE)]
        except ValueError:
            return []


def _messages(window) -> list[str]:
    return [m.text for w in window.axis_windows for m in w.message_area.messages]


def _in_the_pages_place(window, words: str) -> str:
    """The line holding ``words`` among those said in the pages' place (no axis yet)."""
    return next(line for line in window.no_axes_label.text().split("\n\n") if words in line)


def _free_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@contextlib.contextmanager
def _silent_server():
    """A server that takes connections and never answers (never accepts them): a connection waits
    in its backlog until its own timeout. Closed at the end (what waits is reset at once)."""
    listener = socket.socket()
    try:
        listener.bind(("127.0.0.1", 0))
        listener.listen(16)
        yield listener
    finally:
        listener.close()


def _waiting_in(listener: socket.socket) -> bool:
    """Whether a connection waits in the listener's backlog (never accepted, never answered)."""
    return bool(select.select([listener], [], [], 0)[0])


def test_a_closed_port_the_window_shows_the_axes_known_here_and_queues(started, qtbot):
    url = f"postgresql://fha:secret-word@127.0.0.1:{_free_port()}/plant"
    _known_here(url, "table", "tilt")
    window = started(url)
    # the axes this computer knew, at once; no register opened on this thread
    assert [axis.name for axis in window.project] == ["table", "tilt"]
    assert window.register is None and window.questions.on_server
    assert window.stack.isVisible() and not window.no_axes_label.isVisible()
    qtbot.waitUntil(lambda: any("not reachable" in text for text in _messages(window)), timeout=30000)
    said = next(text for text in _messages(window) if "not reachable" in text)
    assert said.startswith("Register: the plant's register is not reachable (")
    assert "the 2 axes shown are those this computer knew" in said
    assert "queued on this computer until the server answers" in said
    assert "secret-word" not in said and "\n" not in said
    # what the window records goes into the queue meanwhile
    window.add_axis("base", ACTUATOR)
    qtbot.waitUntil(lambda: _queued_axes(url) == ["table", "tilt", "base"], timeout=30000)
    assert window.server_writer.answers is False


def test_a_server_that_never_answers_the_window_is_there_before_its_timeout(started, qtbot, monkeypatch):
    monkeypatch.setattr(register_questions, "CONNECT_TIMEOUT_S", NEVER_S)
    monkeypatch.setattr(register_worker, "CONNECT_TIMEOUT_S", NEVER_S)
    with _silent_server() as listener:
        url = f"postgresql://fha:secret-word@127.0.0.1:{listener.getsockname()[1]}/plant"
        window = started(url)  # this machine was never opened here: no axis yet
        assert window.isVisible() and len(window.project) == 0
        assert window.no_axes_label.isVisible() and not window.stack.isVisible()
        asking = window.no_axes_label.text()
        assert "Register: asking the plant's register (postgresql://fha@127.0.0.1:" in asking
        assert "none is shown until it answers" in asking and "queued on this computer" in asking
        # the question's connection waits, unanswered, in the server's backlog while the window
        # is up: its start did not wait for the server
        qtbot.waitUntil(lambda: _waiting_in(listener), timeout=30000)
        assert window.questions.answers is None and window.axes_wanted
        # the network gives up on it (its own timeout is psycopg's: test_server.py says it is a
        # server away too): one line says it
        listener.close()
        qtbot.waitUntil(lambda: "not reachable" in window.no_axes_label.text(), timeout=30000)
        said = _in_the_pages_place(window, "not reachable")
        assert said.startswith("Register: the plant's register is not reachable (")
        assert "the machine's axes come when it answers" in said and "queued on this computer" in said
        assert "secret-word" not in said
        # an axis added meanwhile is shown and queued
        window.add_axis("table", ACTUATOR)
        assert window.stack.isVisible() and not window.no_axes_label.isVisible()
        assert window.banner.text().startswith("Axis table — FHA-25C-50-US250")
        qtbot.waitUntil(lambda: _queued_axes(url) == ["table"], timeout=30000)


def test_a_real_server_brings_the_axes_this_computer_did_not_know(started, qtbot, postgres_cluster):
    url = postgres_cluster.new_database()
    _known_here(url, "table")
    with Register(register_worker.queue_path(url)) as queue, Register(url) as server:
        sync_registers(queue, server, send_only=True)  # delivered before, by a window here
        server.add_axis(MACHINE, "tilt", ACTUATOR, port_url="/dev/ttyUSB7", who="ben")  # another laptop's
        history_before = len(server.history(f"{MACHINE}/table"))
    window = started(url)
    assert [axis.name for axis in window.project] == ["table"]
    qtbot.waitUntil(lambda: len(window.axis_windows) == 2, timeout=30000)
    assert [axis.name for axis in window.project] == ["table", "tilt"]
    assert window.project.axis("tilt").port_url == "/dev/ttyUSB7"
    assert any("this computer did not know: tilt" in text for text in _messages(window))
    assert not any("not reachable" in text for text in _messages(window))
    # the axes taken from the server are not written back to it
    window.shutdown()
    with Register(url) as server:
        assert len(server.history(f"{MACHINE}/table")) == history_before
        assert [a.name for a in server.axes(MACHINE)] == ["table", "tilt"]


def test_a_machine_the_server_does_not_have_is_said(started, qtbot, postgres_cluster):
    url = postgres_cluster.new_database()
    with Register(url) as server:
        server.add_machine("Line 4")
    window = started(url)
    qtbot.waitUntil(lambda: "no machine called" in window.no_axes_label.text(), timeout=30000)
    said = _in_the_pages_place(window, "no machine called")
    assert said == ("Register: no machine called 'Line 3' in the register (machines: Line 4). "
                    "Add axis… adds its first axis.")
    assert not window.axes_wanted
    with Register(url) as server:  # opening it by name did not make it
        assert [m.name for m in server.machines()] == ["Line 4"]


def test_a_wrong_password_is_said_as_such_and_the_next_start_delivers(started, qtbot, postgres_cluster):
    """A wrong password is no server away: the lines say the server refused the user name or
    password; what the window records waits in this computer's queue (one per server and database,
    whatever the password), and a start with the right password delivers it, each fact once."""
    from tests.support.postgres import PASSWORD

    url = postgres_cluster.new_database()
    with Register(url) as server:
        server.add_machine(MACHINE)
        server.add_axis(MACHINE, "table", ACTUATOR, port_url="/dev/ttyUSB0")
    wrong = url.replace(PASSWORD, "not-the-password")
    window = started(wrong)
    qtbot.waitUntil(lambda: "refused the user name or password" in window.no_axes_label.text(), timeout=30000)
    said = _in_the_pages_place(window, "refused the user name or password")
    assert "not reachable" not in window.no_axes_label.text()
    assert "does not answer" not in window.no_axes_label.text()
    assert "not reachable" not in said and "does not answer" not in said
    assert "not-the-password" not in said and "\n" not in said
    window.add_axis("tilt", ACTUATOR, port_url="/dev/ttyUSB1")  # queued
    qtbot.waitUntil(lambda: any("refused the user name or password" in text for text in _messages(window)),
                    timeout=30000)
    assert not any("does not answer" in text or "not reachable" in text for text in _messages(window))
    qtbot.waitUntil(lambda: _queued_axes(wrong) == ["tilt"], timeout=30000)
    window.shutdown()
    right = started(url)  # the same queue: its facts go to the server now
    qtbot.waitUntil(lambda: len(right.axis_windows) == 2, timeout=30000)
    with Register(url) as server:
        # the axis and its entry (the delivery's batches come one after another), each once
        qtbot.waitUntil(lambda: [a.name for a in server.axes(MACHINE)] == ["table", "tilt"]
                        and len(server.history(f"{MACHINE}/tilt")) == 1, timeout=30000)
        right.shutdown()  # every delivery ended: nothing more comes
        assert len(server.history(f"{MACHINE}/tilt")) == 1


def test_the_single_axis_window_on_a_server_that_never_answers_is_there_at_once(qtbot, monkeypatch):
    """``fha-studio gui --register URL`` (the single-axis window) neither: shown while the
    delivery's connection waits unanswered; then the line says the server does not answer, and
    the register line in the toolbar that the facts wait on this computer."""
    from fha_studio.gui.app import single_axis_window

    monkeypatch.setattr(register_worker, "CONNECT_TIMEOUT_S", NEVER_S)
    monkeypatch.setattr(register_questions, "CONNECT_TIMEOUT_S", NEVER_S)
    monkeypatch.setattr(register_worker, "RETRY_MIN_S", 0.5)
    # the listener closed before the window (the threads end at once)
    with torn_down(lambda window: [window.link]) as windows, _silent_server() as listener:
        url = f"postgresql://fha:secret-word@127.0.0.1:{listener.getsockname()[1]}/plant"
        window = single_axis_window(parse_arguments(["--register", url, "--machine", MACHINE,
                                                     "--axis", "table", "--no-connect"]))
        windows.append(window)
        window.show()
        server = window.window_register.server
        assert window.isVisible() and server is not None and server.answers is None
        # an alarm recorded: its delivery's connection waits, unanswered, while the window is up
        server.record(f"{MACHINE}/table", [axis_fact({"actuator_code": ACTUATOR}, "ana"),
                                            *alarm_facts(20, "HA-655", "ana")])
        qtbot.waitUntil(lambda: _waiting_in(listener), timeout=30000)
        assert server.answers is None
        listener.close()  # the network gives up on it
        qtbot.waitUntil(lambda: server.answers is False, timeout=30000)
        said = [m.text for m in window.message_area.messages if "does not answer" in m.text]
        assert said and said[0].startswith("Register: the server does not answer; what this window "
                                           "records waits on this computer")
        assert "server away, 1 fact waiting" in window.window_register.button.text()
        qtbot.waitUntil(lambda: _queued_axes(url) == ["table"], timeout=30000)
