"""A register on a server, written without the window ever waiting for the server.

The facts a window records for a register on a PostgreSQL server go first into a register file of
this computer's, one per server (:func:`queue_path`: ``server-queue/`` in the user data
directory), and from there to the server whenever it answers:

- :class:`QueueWorker`, in a thread of its own, writes each fact into that file as it comes (a
  local file takes it in milliseconds; once there a crash does not lose it);
- :class:`DeliveryWorker`, in another thread, brings what the file has and the server lacks to
  the server (``register sync`` one way, :func:`deliver_by_sync`: each fact by its stable id, so a
  fact is on the server once, however often a delivery is cut off and tried again; nothing of the
  server's comes back, so the file holds what this computer recorded, not a copy of the plant's
  register). A server that cannot be reached is tried again, at once after a new fact and at the
  latest every :data:`RETRY_MAX_S`;
- :class:`ServerWriter`, on the GUI thread, hands them the facts (typed queued signals) and says
  what the server does: ``sigState`` (a :class:`ServerState`), and ``sigSlow`` when a delivery
  takes longer than :data:`SLOW_S`.

Nothing here blocks the GUI thread; closing waits a bounded time for the facts to be in the file.
"""

from __future__ import annotations

import contextlib
import hashlib
import logging
import re
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from PySide6.QtCore import QObject, QThread, QTimer, Signal, Slot

from fha_studio.gui.axis_recorder import login_name
from fha_studio.gui.link import end_worker_thread
from fha_studio.gui.messages import Level
from fha_studio.gui.register_connection import (
    CLOSE_WAIT_MS,
    CONNECT_TIMEOUT_S,
    server_socket,
    shut_socket,
    without_nothing_changed,
)
from fha_studio.gui.register_writer import RegisterWriter, facts_text, write_fact
from fha_studio.logic.register import Register, RegisterError, guard
from fha_studio.logic.register.facts_from_session import (
    AxisFact,
    Fact,
    MachineLevelFact,
    record_machine_fact,
)
from fha_studio.logic.register.guard import ServerAway
from fha_studio.logic.register.server import problem, shown_url
from fha_studio.paths import user_data_dir

if TYPE_CHECKING:
    from fha_studio.logic.machine import MachineProject

log = logging.getLogger(__name__)

#: The folder of the user data directory that holds a register file per server.
QUEUE_FOLDER = "server-queue"
#: A server that did not answer is tried again after this long, then twice as long each time ...
RETRY_MIN_S = 2.0
#: ... up to this [s] (a new fact tries it at once).
RETRY_MAX_S = 30.0
#: A delivery that takes longer than this [s] is said (the server is slow, or hangs) ...
SLOW_S = 5.0
#: ... and one that takes longer than this [s] is cut off and tried again on a new connection (a
#: network gone without a word leaves a connection waiting for hours).
GIVE_UP_S = 60.0


def queue_path(url: str) -> Path:
    """The register file of this computer that holds the facts for the server at ``url``: one per
    server and database (its password is no part of the name: a new password keeps the queue)."""
    shown = shown_url(url)
    readable = re.sub(r"[^A-Za-z0-9._-]+", "-", shown.split("://", 1)[-1]).strip("-")[:60]
    digest = hashlib.sha256(shown.encode("utf-8")).hexdigest()[:12]
    return user_data_dir() / QUEUE_FOLDER / f"{readable}-{digest}.sqlite"


def machine_known_here(url: str, name: str) -> MachineProject | None:
    """The machine ``name`` as this computer's queue for the server at ``url`` holds it (what a
    window here recorded of it before), None when the queue does not know it or cannot be read:
    a window starts with it at once, never waiting for the server."""
    from fha_studio.logic.machine import MachineError, MachineProject

    path = queue_path(url)
    if not path.exists():
        return None
    try:
        with Register(path, read_only=True) as copy:
            return MachineProject.from_register(copy, name)
    except (RegisterError, MachineError, OSError, ValueError) as exc:
        log.info("machine %s is not in this computer's queue %s: %s", name, path, exc)
        return None


@dataclass(frozen=True)
class RecordRequest:
    """Facts of one axis (``MACHINE/AXIS``), in order, for the queue."""

    axis: str
    facts: tuple[Fact, ...]


@dataclass(frozen=True)
class MachineRequest:
    """A machine's own facts (the machine and its axes, its report), in order, for the queue."""

    machine: str
    facts: tuple[MachineLevelFact, ...]


@dataclass(frozen=True)
class ServerState:
    """What the last delivery found: the server answered (``reachable``) and took ``delivered``
    facts, or it did not (``problem``, one line naming it by its URL without password): it could
    not be reached, or it answered and ``refused`` them (a wrong password, a role's rule)."""

    reachable: bool
    problem: str = ""
    delivered: int = 0
    refused: bool = False


class QueueWorker(QObject):
    """Writes facts into this computer's register file for the server (in its own thread)."""

    sigNotRecorded = Signal(str, str, str)  # axis, what, why
    sigQueued = Signal(int)  # how many facts were written into the file
    sigReady = Signal()  # the file is open (or said not to be): a delivery may read it

    def __init__(self, path: Path):
        super().__init__()
        self.path = path
        self._queue: Register | None = None
        self._problem = ""

    @Slot()
    def start(self) -> None:
        try:
            self._queue = Register(self.path)
        except (RegisterError, OSError) as exc:
            self._problem = f"this computer's queue for the server cannot be opened: {exc}"
            log.warning("register queue %s: %s", self.path, exc)
        self.sigReady.emit()

    @Slot(object)
    def record(self, request: RecordRequest) -> None:
        queue = self._queue
        if queue is None:
            for fact in request.facts:
                self.sigNotRecorded.emit(request.axis, fact.what, self._problem)
            return
        facts = list(request.facts)
        if not facts or not isinstance(facts[0], AxisFact):
            facts.insert(0, AxisFact((), ""))  # the queue's file learns the axis with its first fact
        written = 0
        for fact in facts:
            problem = write_fact(queue, request.axis, fact)
            if problem:
                self.sigNotRecorded.emit(request.axis, fact.what, problem)
                if isinstance(fact, AxisFact):
                    break
            elif not isinstance(fact, AxisFact):
                written += 1
        if written:
            self.sigQueued.emit(written)

    @Slot(object)
    def record_machine(self, request: MachineRequest) -> None:
        written = 0
        for fact in request.facts:
            problem = self._problem if self._queue is None else _machine_fact_written(self._queue, fact)
            if problem:
                self.sigNotRecorded.emit(request.machine, fact.what, problem)
                break  # what comes after it (a report of an axis not added) waits for nothing
            written += 1
        if written:
            self.sigQueued.emit(written)

    @Slot()
    def stop(self) -> None:
        """Closes the file and ends the thread (after every fact queued before it)."""
        if self._queue is not None:
            self._queue.close()
            self._queue = None
        end_worker_thread(self)


def _machine_fact_written(queue: Register, fact: MachineLevelFact) -> str:
    """Writes a machine's fact into the queue; "" when it was, else why not (one line)."""
    try:
        record_machine_fact(queue, fact)
        return ""
    except (RegisterError, OSError, ValueError) as exc:
        log.warning("register: %s not recorded: %s", fact.what, exc)
        return str(exc)


#: Brings the facts the queue's register has and the server's lacks to the server; returns how
#: many. Raises RegisterError (one line) when the server does not take them. Calls its third
#: argument after each of its transactions (the server answers), which raises :class:`Closing`
#: once the window is closing (what was moved is kept).
Deliver = Callable[[Register, Register, Callable[[], None]], int]


class Closing(Exception):
    """The window closes: a delivery stops after the transaction it is in."""


def deliver_by_sync(queue: Register, server: Register, answered: Callable[[], None]) -> int:
    """The queue's facts to the server by ``register sync``, one way (each fact once, by its
    stable id; what the server has stays there: a plant's years of facts are not copied to this
    computer, and a delivery costs what the queue holds, not what the server holds)."""
    from fha_studio.logic.register.sync import SyncProgress, sync_registers

    def progress(_step: SyncProgress) -> None:
        answered()

    return int(sync_registers(queue, server, progress, who=login_name(), send_only=True).sent)


class DeliveryWorker(QObject):
    """Delivers the queue's facts to the server (in its own thread); tries again while it is away.
    Its connection to the server stays open between deliveries (opened again after a failure)."""

    sigState = Signal(object)  # ServerState
    sigBusy = Signal(bool)  # a delivery started (True) / ended (False)
    sigAnswered = Signal()  # the server took a transaction of the delivery under way

    def __init__(self, path: Path, url: str, deliver: Deliver | None = None):
        super().__init__()
        self.path, self.url = path, url
        self._deliver = deliver or deliver_by_sync
        self._stopping = threading.Event()
        #: set while a delivery is asked for and not begun: the requests of many facts queued
        #: during one long delivery are one delivery after it
        self.wanted = threading.Event()
        self._retry_s = RETRY_MIN_S
        self._timer: QTimer | None = None
        self._queue: Register | None = None
        self._server: Register | None = None
        self._server_socket = -1  # its file descriptor, for interrupt() from another thread

    @Slot()
    def start(self) -> None:
        self._timer = QTimer(self)
        self._timer.setSingleShot(True)
        self._timer.timeout.connect(self.deliver)
        self.deliver()  # what an earlier run left in the queue

    @Slot()
    def deliver(self) -> None:
        self.wanted.clear()  # a fact queued from now on asks for one more delivery
        if self._stopping.is_set() or self._timer is None or not self.path.exists():
            return  # (not started yet: its start delivers)
        self._timer.stop()
        self.sigBusy.emit(True)
        # a connection kept from before may have been cut meanwhile (the server restarted): once
        # more on a new one before the server is said to be away
        reused = self._server is not None
        state = self._deliver_once()
        if not state.reachable and reused and not self._stopping.is_set():
            state = self._deliver_once()
        self.sigBusy.emit(False)
        if self._stopping.is_set():
            return
        if state.reachable:
            self._retry_s = RETRY_MIN_S
        else:
            self._timer.start(int(self._retry_s * 1000))
            self._retry_s = min(RETRY_MAX_S, self._retry_s * 2)
        self.sigState.emit(state)

    def _deliver_once(self) -> ServerState:
        try:
            delivered = self._deliver(*self._registers(), self._answered)
        except Closing:
            return ServerState(True)
        except (ServerAway, OSError) as exc:
            state = ServerState(False, str(exc))
        except RegisterError as exc:  # the server answered: it refused them
            state = ServerState(False, str(exc), refused=True)
        except Exception as exc:  # the server's or the queue's errors, never the thread's end
            if guard.is_db_error(exc):
                said = problem(self.url, exc)
                state = ServerState(False, str(said), refused=not isinstance(said, ServerAway))
            else:
                log.exception("register: delivery to %s", shown_url(self.url))
                state = ServerState(False, f"the register {shown_url(self.url)}: {exc}")
        else:
            return ServerState(True, delivered=delivered)
        self._close_server()  # opened again at the next try
        return state

    def _answered(self) -> None:
        if self._stopping.is_set():
            raise Closing
        self.sigAnswered.emit()

    def _registers(self) -> tuple[Register, Register]:
        if self._queue is None:
            self._queue = Register(self.path, create=False)
        if self._server is None:
            self._server = Register(self.url, busy_timeout_s=CONNECT_TIMEOUT_S)
            self._server_socket = server_socket(self._server)
        return self._queue, self._server

    def _close_server(self) -> None:
        server, self._server, self._server_socket = self._server, None, -1
        if server is not None:
            with contextlib.suppress(Exception):  # a connection that broke closes all the same
                server.close()

    def interrupt(self) -> None:
        """From any thread: no more deliveries, and one under way gives up at once."""
        self._stopping.set()
        self.cut_off()

    def cut_off(self) -> None:
        """From any thread: a delivery under way gives up at once (its connection's socket is
        shut: a server that hangs, or a network that went away without a word, cannot hold the
        thread); the next delivery connects anew."""
        shut_socket(self._server_socket)

    @Slot()
    def stop(self) -> None:
        self._stopping.set()
        if self._timer is not None:
            self._timer.stop()
        self._close_server()
        if self._queue is not None:
            self._queue.close()
            self._queue = None
        end_worker_thread(self)


class ServerWriter(RegisterWriter):
    """The GUI thread's side of a register on a server: facts go to the queue's thread, the
    queue's facts to the server from the delivery's thread; what the server does comes back, and
    is said (``sigSay``: one line for the window's message area, naming the server by its URL
    without password) when it changes: the server does not answer, is slow, answers again."""

    sigState = Signal(object)  # ServerState, after each delivery
    sigSlow = Signal()  # a delivery has taken longer than SLOW_S
    sigQueued = Signal(int)  # facts written into the queue's file
    sigSay = Signal(str, object)  # text, messages.Level
    sigChanged = Signal()  # answers or waiting changed
    _sigRecord = Signal(object)  # RecordRequest, queued into the queue's thread
    _sigRecordMachine = Signal(object)  # MachineRequest, queued into the queue's thread
    _sigDeliver = Signal()  # queued into the delivery's thread
    _sigStop = Signal()  # queued into the queue's thread, after the facts
    _sigStopDelivery = Signal()  # queued into the delivery's thread

    def __init__(self, url: str, parent: QObject | None = None, deliver: Deliver | None = None,
                 queue: Path | None = None):
        super().__init__(parent)
        self.url = url
        self.queue = queue or queue_path(url)
        #: whether the server took the last delivery (None: none tried yet), and how many facts
        #: went into the queue since it last did
        self.answers: bool | None = None
        #: why the server refused the last delivery ("": it did not, or it was not reached)
        self.refusal = ""
        self.waiting = 0
        self._said_slow = False
        self._shut_down = False
        self._queue_thread, self._delivery_thread = QThread(), QThread()
        self._queue_thread.setObjectName("fha-register-queue")
        self._delivery_thread.setObjectName("fha-register-server")
        self._queue_worker = QueueWorker(self.queue)
        self._queue_worker.moveToThread(self._queue_thread)
        self._delivery = DeliveryWorker(self.queue, url, deliver)
        self._delivery.moveToThread(self._delivery_thread)
        self._queue_thread.started.connect(self._queue_worker.start)
        # the first delivery once the queue's file is made (half made, it is no register to read)
        self._queue_worker.sigReady.connect(self._delivery.start)
        self._sigRecord.connect(self._queue_worker.record)
        self._sigRecordMachine.connect(self._queue_worker.record_machine)
        self._sigStop.connect(self._queue_worker.stop)
        self._sigDeliver.connect(self._delivery.deliver)
        self._sigStopDelivery.connect(self._delivery.stop)
        self._queue_worker.sigNotRecorded.connect(self.sigNotRecorded)
        self._queue_worker.sigQueued.connect(self._on_queued)
        self._delivery.sigState.connect(self._on_state)
        self._delivery.sigBusy.connect(self._on_busy)
        self._delivery.sigAnswered.connect(self._on_answered)
        self._slow_timer = QTimer(self)
        self._slow_timer.setSingleShot(True)
        self._slow_timer.setInterval(int(SLOW_S * 1000))
        self._slow_timer.timeout.connect(self._on_slow)
        self._give_up_timer = QTimer(self)
        self._give_up_timer.setSingleShot(True)
        self._give_up_timer.setInterval(int(GIVE_UP_S * 1000))
        # in this thread (a lambda, not the worker's method: that would wait for its busy thread)
        self._give_up_timer.timeout.connect(lambda: self._delivery.cut_off())
        self._queue_thread.start()
        self._delivery_thread.start()

    @property
    def location(self) -> Path | str:
        return self.url

    def record(self, axis: str, facts: Sequence[Fact]) -> None:
        if not self._shut_down and facts:
            self._sigRecord.emit(RecordRequest(axis, tuple(facts)))

    def record_machine(self, machine: str, facts: Sequence[MachineLevelFact]) -> None:
        """Records a machine's own facts (the machine and its axes, its report) in order; one the
        queue cannot take is said (``sigNotRecorded``, naming the machine)."""
        if not self._shut_down and facts:
            self._sigRecordMachine.emit(MachineRequest(machine, tuple(facts)))

    def deliver_now(self) -> None:
        """Tries the server now (a person asked, or a fact is waiting)."""
        if not self._shut_down and not self._delivery.wanted.is_set():
            self._delivery.wanted.set()
            self._sigDeliver.emit()

    @Slot(int)
    def _on_queued(self, count: int) -> None:
        self.waiting += count
        self.sigQueued.emit(count)
        if self.answers is False:
            self.sigChanged.emit()
        self.deliver_now()

    @Slot(object)
    def _on_state(self, state: ServerState) -> None:
        where = shown_url(self.url)
        slow, self._said_slow = self._said_slow, False
        if state.reachable:
            if self.answers is False:
                self.sigSay.emit(
                    f"Register: the server answers again ({where}); what waited on this computer is "
                    f"on it now ({facts_text(state.delivered)} delivered).", Level.INFO
                )
            elif slow:
                self.sigSay.emit(
                    f"Register: the server answered ({where}); {facts_text(state.delivered)} delivered.",
                    Level.INFO,
                )
            self.waiting = 0
        elif state.refused:
            if state.problem != self.refusal:
                self.sigSay.emit(
                    f"Register: the server refused what this window records "
                    f"({without_nothing_changed(state.problem)}); it waits on this computer and goes "
                    "to the server once that is put right.", Level.WARNING
                )
        elif self.answers is not False or self.refusal:
            why = without_nothing_changed(state.problem)
            self.sigSay.emit(
                "Register: the server does not answer; what this window records waits on this "
                f"computer and goes to the server when it answers again ({why}).", Level.WARNING
            )
        self.refusal = state.problem if state.refused else ""
        self.answers = state.reachable
        self.sigState.emit(state)
        self.sigChanged.emit()

    @Slot()
    def _on_slow(self) -> None:
        self._said_slow = True
        self.sigSay.emit(
            f"Register: the server is slow to answer ({shown_url(self.url)}); what this window "
            "records waits on this computer meanwhile.", Level.WARNING
        )
        self.sigSlow.emit()

    @Slot()
    def _on_answered(self) -> None:
        """A long delivery goes on (the first sync of a large register): the server answers, so it
        neither is slow nor hangs."""
        if self._give_up_timer.isActive():
            self._give_up_timer.start()
        if self._slow_timer.isActive():
            self._slow_timer.start()

    @Slot(bool)
    def _on_busy(self, busy: bool) -> None:
        for timer in (self._slow_timer, self._give_up_timer):
            if busy:
                timer.start()
            else:
                timer.stop()

    def shutdown(self) -> None:
        """Every fact handed over is written into the queue's file, then both threads end (each
        within CLOSE_WAIT_MS: a delivery under way is cut off; what it did not bring to the server
        goes at the next start)."""
        if self._shut_down:
            return
        self._shut_down = True
        self._slow_timer.stop()
        self._give_up_timer.stop()
        self._delivery.interrupt()
        self._sigStop.emit()  # after the facts queued before it
        self._sigStopDelivery.emit()
        for thread in (self._queue_thread, self._delivery_thread):
            if not thread.wait(CLOSE_WAIT_MS):
                thread.quit()
                if not thread.wait(500):
                    log.error("the register thread %s did not end", thread.objectName())
