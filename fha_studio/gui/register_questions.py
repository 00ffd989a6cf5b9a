"""The register's questions (and the writes a person waits for: a signature), answered without
the window ever waiting for a server.

A window asks through a :class:`RegisterQuestions`: ``ask(what, question, answered, failed)``
runs ``question(register)`` and hands its value to ``answered`` (or one line why not to
``failed``), always on the GUI thread.

- :class:`LocalQuestions`: a register file, answered at once on the GUI thread (a local file
  answers in milliseconds, and what the window wrote a moment ago is in it);
- :class:`ServerQuestions`: a register on a PostgreSQL server, asked by :class:`QuestionWorker` on
  a thread of its own with a connection of its own (typed queued signals: :class:`Question` in,
  :class:`Answer` out). While a question waits ``sigBusy`` says so (a dialog shows "asking the
  server…"); a server slow to answer (:data:`SLOW_S`) or that does not answer is said once in the
  message line (``sigSay``), naming it by its URL without password; a question not answered
  within :data:`GIVE_UP_S` is given up (its connection cut off, as a delivery that hangs is), and
  so are those asked behind it: each ``failed`` hears one line.

Nothing here blocks the GUI thread; closing waits a bounded time for the thread.
"""

from __future__ import annotations

import contextlib
import itertools
import logging
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from PySide6.QtCore import QObject, QThread, QTimer, Signal, Slot

from fha_studio.gui.link import end_worker_thread
from fha_studio.gui.messages import Level
from fha_studio.gui.register_connection import (
    CLOSE_WAIT_MS,
    CONNECT_TIMEOUT_S,
    server_socket,
    shut_socket,
    without_nothing_changed,
)
from fha_studio.gui.register_writer import HeldRegisterFile
from fha_studio.logic.register import Register, RegisterError, guard
from fha_studio.logic.register.guard import ServerAway
from fha_studio.logic.register.server import problem, shown_url

log = logging.getLogger(__name__)

#: A question not answered within this long [s] is said in the message line (the server is slow) ...
SLOW_S = 5.0
#: ... and one not answered within this long [s] is given up (its connection cut off).
GIVE_UP_S = 20.0

Answered = Callable[[Any], None]
Failed = Callable[[str], None]


def shown_location(location: Path | str) -> str:
    """The register as messages name it: the file's path, or the server's URL without password."""
    from fha_studio.logic.register.server import is_server_url

    return shown_url(str(location)) if is_server_url(location) else str(location)


@dataclass(frozen=True)
class Question:
    """What to ask (``ask(register)``, run on the asker's thread; Qt-free), in words (``what``)."""

    number: int
    what: str
    ask: Callable[[Register], Any]


@dataclass(frozen=True)
class Answer:
    """The value of question ``number``, or why there is none (``problem``, one line);
    ``server_problem``: the server itself did not answer (else the register refused the question)."""

    number: int
    value: Any = None
    problem: str = ""
    server_problem: bool = False


class RegisterQuestions(QObject):
    """Asks the register; each answer comes to a callable on the GUI thread."""

    sigSay = Signal(str, object)  # text, messages.Level: for the window's message line
    sigBusy = Signal(bool)  # a question waits for its answer (True) / none does (False)

    @property
    def location(self) -> Path | str:
        """The register: its file, or the server's URL."""
        raise NotImplementedError

    @property
    def on_server(self) -> bool:
        return False

    def ask(self, what: str, question: Callable[[Register], Any], answered: Answered,
            failed: Failed | None = None) -> None:
        """Runs ``question(register)``; its value to ``answered``, or one line to ``failed``
        (None: the line goes to the message line). ``what`` names it in words ("the history of
        Line 3/table")."""
        raise NotImplementedError

    def shutdown(self) -> None:
        """Answers nothing more (idempotent); the answers still owed are dropped."""

    def _say_refused(self, why: str) -> None:
        """A question the register refused, with no ``failed`` of its own: the message line."""
        self.sigSay.emit(f"Register: {why}", Level.WARNING)


class LocalQuestions(HeldRegisterFile, RegisterQuestions):
    """A register file: each question answered at once, on this thread."""

    def ask(self, what: str, question: Callable[[Register], Any], answered: Answered,
            failed: Failed | None = None) -> None:
        if self.register is None:
            return
        try:
            value = question(self.register)
        except (RegisterError, ValueError, OSError) as exc:
            (failed or self._say_refused)(str(exc))
            return
        answered(value)



class QuestionWorker(QObject):
    """Asks the server each question in turn (in its own thread), on a connection of its own
    (opened when the first question comes, again after one broke)."""

    sigStarted = Signal(int)  # the question's number: it is being asked now
    sigAnswer = Signal(object)  # Answer

    def __init__(self, url: str):
        super().__init__()
        self.url = url
        #: the numbers of questions the GUI gave up on: not asked any more (added from the GUI
        #: thread; a set's add and ``in`` need no lock)
        self.abandoned: set[int] = set()
        self._server: Register | None = None
        self._server_socket = -1
        self._was_cut_off = False

    @Slot(object)
    def answer(self, question: Question) -> None:
        if question.number in self.abandoned:
            self.abandoned.discard(question.number)
            return
        if self._was_cut_off:  # a connection cut off between two questions: a new one
            self._was_cut_off = False
            self._close()
        self.sigStarted.emit(question.number)
        try:
            if self._server is None:
                self._server = Register(self.url, busy_timeout_s=CONNECT_TIMEOUT_S)
                self._server_socket = server_socket(self._server)
            value = question.ask(self._server)
        except Exception as exc:
            # the server not reached, or its connection broken; a refusal is an answer (a wrong
            # password, a machine it does not have)
            gone = isinstance(exc, ServerAway | OSError) or (
                _broken(self._server) if self._server is not None else not isinstance(exc, RegisterError)
            )
            if isinstance(exc, RegisterError | ValueError | OSError):
                said = str(exc)
            elif guard.is_db_error(exc):
                reason = problem(self.url, exc)
                said, gone = str(reason), gone or isinstance(reason, ServerAway)
            else:
                log.exception("register: %s asked of %s", question.what, shown_url(self.url))
                said = f"the register {shown_url(self.url)}: {exc}"
            if gone:
                self._close()  # opened again for the next question
                said = without_nothing_changed(said)  # a question changes nothing anyway
            self.sigAnswer.emit(Answer(question.number, problem=said, server_problem=gone))
            return
        self.sigAnswer.emit(Answer(question.number, value))

    def cut_off(self) -> None:
        """From any thread: the question being asked gives up at once (its connection's socket
        is shut: a server that hangs cannot hold the thread); the next one connects anew."""
        self._was_cut_off = True
        shut_socket(self._server_socket)

    def _close(self) -> None:
        server, self._server, self._server_socket = self._server, None, -1
        if server is not None:
            with contextlib.suppress(Exception):  # a connection that broke closes all the same
                server.close()

    @Slot()
    def stop(self) -> None:
        self._close()
        end_worker_thread(self)


def _broken(register: Register) -> bool:
    """Whether a register's connection to its server is gone (closed, or broken by an error)."""
    connection = getattr(getattr(register, "_db", None), "_conn", None)
    return connection is None or bool(getattr(connection, "closed", True)) or bool(
        getattr(connection, "broken", False)
    )


@dataclass
class _Pending:
    what: str
    answered: Answered
    failed: Failed | None


class ServerQuestions(RegisterQuestions):
    """A register on a server: questions asked from a thread of their own, answers queued back."""

    _sigAsk = Signal(object)  # Question, queued into the asker's thread
    _sigStop = Signal()

    def __init__(self, url: str, parent: QObject | None = None):
        super().__init__(parent)
        self.url = url
        #: whether the server answered the last question (None: none asked yet)
        self.answers: bool | None = None
        self._numbers = itertools.count(1)
        self._pending: dict[int, _Pending] = {}
        self._shut_down = False
        self._said_slow = False
        self._thread = QThread()
        self._thread.setObjectName("fha-register-questions")
        self._worker = QuestionWorker(url)
        self._worker.moveToThread(self._thread)
        self._sigAsk.connect(self._worker.answer)
        self._sigStop.connect(self._worker.stop)
        self._worker.sigStarted.connect(self._on_started)
        self._worker.sigAnswer.connect(self._on_answer)
        self._slow_timer = QTimer(self)
        self._slow_timer.setSingleShot(True)
        self._slow_timer.timeout.connect(self._on_slow)
        self._give_up_timer = QTimer(self)
        self._give_up_timer.setSingleShot(True)
        self._give_up_timer.timeout.connect(self._give_up)
        self._thread.start()

    @property
    def location(self) -> Path | str:
        return self.url

    @property
    def on_server(self) -> bool:
        return True

    @property
    def busy(self) -> bool:
        """Whether a question waits for its answer."""
        return bool(self._pending)

    def ask(self, what: str, question: Callable[[Register], Any], answered: Answered,
            failed: Failed | None = None) -> None:
        if self._shut_down:
            return
        number = next(self._numbers)
        was_busy = self.busy
        self._pending[number] = _Pending(what, answered, failed)
        self._sigAsk.emit(Question(number, what, question))
        if not was_busy:
            self.sigBusy.emit(True)

    @Slot(int)
    def _on_started(self, number: int) -> None:
        """A question is being asked now: the timers run for it."""
        if number in self._pending:
            self._slow_timer.start(int(SLOW_S * 1000))
            self._give_up_timer.start(int(GIVE_UP_S * 1000))

    @Slot(object)
    def _on_answer(self, answer: Answer) -> None:
        pending = self._pending.pop(answer.number, None)
        if pending is None:  # given up on before
            return
        self._slow_timer.stop()
        self._give_up_timer.stop()
        where = shown_url(self.url)
        if answer.server_problem:
            self._server_away(pending.what, answer.problem)
        else:
            if self.answers is False or self._said_slow:
                self.sigSay.emit(f"Register: the server answers again ({where}).", Level.INFO)
            self.answers, self._said_slow = True, False
        if answer.problem:
            (pending.failed or self._say_refused)(answer.problem)
        else:
            pending.answered(answer.value)
        if not self.busy:
            self.sigBusy.emit(False)

    def _server_away(self, what: str, why: str) -> None:
        if self.answers is not False:
            self.sigSay.emit(
                f"Register: the server does not answer: no answer about {what} ({why}).", Level.WARNING
            )
        self.answers, self._said_slow = False, False

    @Slot()
    def _on_slow(self) -> None:
        if not self._pending or self._said_slow:
            return
        self._said_slow = True
        what = next(iter(self._pending.values())).what
        self.sigSay.emit(
            f"Register: the server is slow to answer ({shown_url(self.url)}); still waiting for {what}.",
            Level.WARNING
        )

    @Slot()
    def _give_up(self) -> None:
        """The question being asked did not come back in time: it and those behind it are given up
        (each ``failed`` hears why); the connection is cut off, the next question connects anew."""
        if not self._pending:
            return
        where = shown_url(self.url)
        why = (f"the register {where}: the server did not answer within {GIVE_UP_S:g} s; "
               "ask again when it answers")
        pending, self._pending = self._pending, {}
        self._worker.abandoned.update(pending)
        self._worker.cut_off()
        self._server_away(next(iter(pending.values())).what, why)
        for item in pending.values():
            (item.failed or (lambda _why: None))(why)
        self.sigBusy.emit(False)

    def shutdown(self) -> None:
        """Answers nothing more; the thread ends (within CLOSE_WAIT_MS: a question being asked is
        cut off)."""
        if self._shut_down:
            return
        self._shut_down = True
        self._slow_timer.stop()
        self._give_up_timer.stop()
        self._worker.abandoned.update(self._pending)
        self._pending.clear()
        self._worker.cut_off()
        self._sigStop.emit()
        if not self._thread.wait(CLOSE_WAIT_MS):
            self._thread.quit()
            if not self._thread.wait(500):
                log.error("the register thread %s did not end", self._thread.objectName())
