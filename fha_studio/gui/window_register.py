"""The single-axis window records into the register too, as each axis of a machine window does.

:class:`WindowRegister` opens the register (``--register``, ``$FHA_STUDIO_REGISTER``, else the
user's ``register.sqlite``) for a :class:`~fha_studio.gui.main_window.MainWindow` of its own,
and hangs the machine window's :class:`~fha_studio.gui.axis_recorder.AxisRecorder` on it. Its
axis is the one a person names (the *Register* line of the status bar opens
:class:`WindowAxisDialog`; ``fha-studio --machine NAME --axis NAME``), else this computer's bench
and an axis named after the actuator or the connection
(:mod:`fha_studio.logic.register.window_axis`). The status bar always says where the facts go.
"""

from __future__ import annotations

import logging
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QEvent, QObject, QSettings, Qt, Slot
from PySide6.QtGui import QFontMetrics
from PySide6.QtWidgets import (
    QComboBox,
    QDialog,
    QDialogButtonBox,
    QFormLayout,
    QLabel,
    QLineEdit,
    QPushButton,
    QToolButton,
    QVBoxLayout,
    QWidget,
)

from fha_studio import names
from fha_studio.gui.axis_recorder import OPERATOR_KEY, AxisRecorder, login_name
from fha_studio.gui.link import LinkInfo
from fha_studio.gui.messages import Level
from fha_studio.gui.register_questions import ServerQuestions, shown_location
from fha_studio.gui.register_writer import DirectWriter, RegisterWriter, facts_text
from fha_studio.logic.register import Register, RegisterError, register_location
from fha_studio.logic.register.server import is_server_url
from fha_studio.logic.register.window_axis import (
    DefaultAxis,
    WindowAxis,
    check_names,
    default_machine_name,
)

if TYPE_CHECKING:
    from fha_studio.gui.main_window import MainWindow
    from fha_studio.gui.register_worker import ServerWriter

log = logging.getLogger(__name__)

#: QSettings key of the machines and axes named before (the dialog offers them again).
RECENT_KEY = "register/recent_axes"
#: How many named axes the dialog remembers.
RECENT_MAX = 12
#: The toolbar's register line takes at most this share of the window's width ...
LINE_WIDTH_SHARE = 0.3
#: ... and never more than this [px].
LINE_WIDTH_MAX_PX = 460


class WindowRegister(QObject):
    """The register one single-axis window records into, and the machine and axis it records under."""

    def __init__(
        self,
        window: MainWindow,
        register: str | Path | None = None,
        machine: str = "",
        axis: str = "",
        computer: str | None = None,
    ):
        """``register``: the ``--register`` value (None: the one rule). ``machine`` / ``axis``:
        the names given on the command line ("": the default). ``computer``: this computer's
        name for the default machine (None: the host name)."""
        super().__init__(window)
        self.window = window
        self.location = register_location(register)
        self._machine, self._axis = check_names(machine, axis)
        self.default_machine = default_machine_name(computer)
        self._default_axis = DefaultAxis()
        self._url, self._simulated = "", False
        self.problem = ""
        #: the register file, open on the GUI thread (None for a server's, or one that failed)
        self.register: Register | None = None
        self.writer: RegisterWriter | None = None
        #: a server's questions (the signer's key, the axes it has), asked from their own thread
        self.questions: ServerQuestions | None = None
        if is_server_url(self.location):
            self.writer = self._server_writer(str(self.location))
            self.questions = ServerQuestions(str(self.location), self)
            self.questions.sigSay.connect(window.show_message)
            window.register_questions = self.questions
        else:
            try:
                self.register = Register(self.location)
                self.writer = DirectWriter(self.register, self)
            except (RegisterError, OSError) as exc:  # read-only, damaged, locked: said, not raised
                log.warning("register %s not opened: %s", shown_location(self.location), exc)
                self.problem = str(exc)
        # before the recorder's: the connection's URL is known when the recorder asks for the axis
        window.link.sigConnected.connect(self._on_connected)
        window.state.sigActuatorChanged.connect(self._on_actuator)
        self.recorder: AxisRecorder | None = None
        if self.writer is not None:
            self.recorder = AxisRecorder(
                self.writer, self._axis_for_fact, window, self.operator, axis_fields=self._axis_fields
            )
        self.button = QToolButton()
        self.button.setObjectName("registerLine")
        self.button.setAutoRaise(True)
        self.button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        self.button.clicked.connect(self.show_dialog)
        window.add_axis_line(self.button)
        window.installEventFilter(self)  # the line is elided again to a new width
        window.window_register = self
        window.signing_register = self.location  # the sign step finds the signer's key there
        self._show()
        if self.problem:
            window.show_message(f"Register: nothing is recorded: {self.problem}.", Level.WARNING)

    # -- a register on a server ------------------------------------------------------------------------
    def _server_writer(self, url: str) -> RegisterWriter:
        from fha_studio.gui.register_worker import ServerWriter

        writer = ServerWriter(url, self)
        writer.sigSay.connect(self.window.show_message)
        writer.sigChanged.connect(self._show)
        return writer

    @property
    def server(self) -> ServerWriter | None:
        """The writer of a register on a server (its state: ``answers``, ``waiting``), else None."""
        from fha_studio.gui.register_worker import ServerWriter

        return self.writer if isinstance(self.writer, ServerWriter) else None

    def deliver_now(self) -> None:
        """Tries the server now with what waits on this computer (a register on a server only)."""
        if self.server is not None:
            self.server.deliver_now()

    # -- where the facts go ---------------------------------------------------------------------------
    @property
    def axis(self) -> WindowAxis:
        """The machine and axis the next fact goes to (the default axis as it would be now)."""
        name = self._axis or self.default_axis_name()
        return WindowAxis(self._machine or self.default_machine, name, bool(self._machine), bool(self._axis))

    def default_axis_name(self) -> str:
        """The axis's default name as it would be now (kept for a connection once a fact went there)."""
        state = self.window.state
        return self._default_axis.current(state.actuator_code, self._url, self._simulated)

    def _axis_for_fact(self) -> str:
        """The axis a fact goes to now: a default one is kept from here to the end of the connection."""
        if not self._axis:
            state = self.window.state
            self._default_axis.take(state.actuator_code, self._url, self._simulated)
        return self.axis.ref

    def _axis_fields(self, _axis_ref: str) -> dict[str, Any]:
        """What a new axis is given: its actuator and declared load."""
        state = self.window.state
        fields: dict[str, Any] = {"actuator_code": state.actuator_code}
        if state.load_inertia_kgm2 > 0:
            fields["load_inertia_kgm2"] = state.load_inertia_kgm2
        return fields

    def operator(self) -> str:
        """Who the register records: the name given (here or in a machine window), else the login name."""
        return str(QSettings().value(OPERATOR_KEY, "") or "").strip() or login_name()

    def name_axis(self, machine: str, axis: str) -> WindowAxis:
        """Facts from now on go under ``machine``/``axis`` ("" for the default of either);
        ``names.NameProblem`` (a ValueError, one line) for a name the register would refuse."""
        self._machine, self._axis = check_names(machine, axis)
        if not self._axis:
            self._default_axis.forget()  # back to the default: it is chosen again at the next fact
        if self._machine and self._axis:
            _remember(self._machine, self._axis)
        self._show()
        return self.axis

    def known_axes(self) -> dict[str, list[str]]:
        """Machines and their axes to offer: those named before here, and the register's."""
        known: dict[str, list[str]] = {}
        for machine, axis in _recent():
            known.setdefault(machine, []).append(axis)
        try:
            if self.register is not None:
                rows = self.register.axes()
            elif self.server is not None and self.server.queue.exists():
                # a server's: the axes this computer recorded for it (the server is never asked on
                # this thread)
                with Register(self.server.queue, read_only=True) as copy:
                    rows = copy.axes()
            else:
                rows = []
        except (RegisterError, OSError) as exc:
            log.warning("register's axes not listed: %s", exc)
            rows = []
        for axis_row in rows:
            names_there = known.setdefault(axis_row.machine, [])
            if axis_row.name not in names_there:
                names_there.append(axis_row.name)
        return known

    # -- what the window hears ------------------------------------------------------------------------
    @Slot(object)
    def _on_connected(self, info: LinkInfo) -> None:
        self._url, self._simulated = info.url, info.is_simulated
        self._show()

    @Slot(str)
    def _on_actuator(self, code: str) -> None:
        """The actuator declared: the axis's record says it (once its axis is in the register)."""
        self._show()
        if self.recorder is not None and code and self.axis.ref in self.recorder.recorded_axes():
            self.recorder.record_actuator(code)

    # -- showing it -----------------------------------------------------------------------------------
    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if watched is self.window and event.type() == QEvent.Type.Resize:
            self._show()
        return False

    def _show(self) -> None:
        where = shown_location(self.location)
        if self.writer is None:
            self.button.setText("Register: not recording")
            self.button.setStyleSheet("color: #b00020; font-weight: bold;")
            self.button.setToolTip(f"Nothing is recorded: {self.problem}")
        else:
            axis = self.axis
            width = max(160, min(LINE_WIDTH_MAX_PX, int(self.window.width() * LINE_WIDTH_SHARE)))
            server = self.server
            away = server is not None and server.answers is False
            state_now = "server refuses them" if server and server.refusal else "server away"
            tail = f" · {state_now}, {facts_text(server.waiting)} waiting" if server and away else ""
            self.button.setText(_line(self.button.fontMetrics(), axis, width - 16, tail))
            self.button.setStyleSheet("color: #8a5a00; font-weight: bold;" if away else "")
            how = "" if axis.named else (
                "\n(a default name: this computer's bench, the axis after its actuator or connection)"
            )
            queue = ""
            if server is not None:
                state = {None: "not reached yet", True: "answers", False: "does not answer"}
                queue = (f"\nThe server {state[server.answers]}; what is recorded goes first into "
                         f"this computer's {server.queue}, then to the server.")
            self.button.setToolTip(
                f"What this window learns is recorded in the register {where}\n"
                f"as machine {axis.machine}, axis {axis.axis}{how}.{queue}\n"
                "Click to name the machine and axis."
            )

    @Slot()
    def show_dialog(self) -> WindowAxisDialog:
        """Opens the dialog that names the machine and axis (modal); returns it once closed."""
        dialog = WindowAxisDialog(self, self.window)
        dialog.exec()
        return dialog

    def shutdown(self) -> None:
        """Closes the register (idempotent)."""
        if self.recorder is not None:
            self.recorder.stop()  # a reply the link sent before it ended is not recorded any more
            self.recorder = None
        if self.questions is not None:
            self.questions.shutdown()  # a question the server did not answer yet is dropped
            self.questions = None
        if self.writer is not None:
            self.writer.shutdown()  # a server's: the facts handed over are in this computer's queue
            self.writer = None
        if self.register is not None:
            self.register.close()
            self.register = None


def _line(metrics: QFontMetrics, axis: WindowAxis, width: int, state: str = "") -> str:
    """``Register: MACHINE › AXIS`` (and the server's ``state``) within ``width`` pixels: the
    machine shortened first (the axis is what a person checks), then the axis in its middle."""
    head = "Register: "
    text = f"{head}{axis.machine} › {axis.axis}{state}"
    if metrics.horizontalAdvance(text) <= width:
        return text
    tail = f" › {axis.axis}{state}"
    room = width - metrics.horizontalAdvance(head + tail)
    if room >= metrics.horizontalAdvance("M…"):
        return head + metrics.elidedText(axis.machine, Qt.TextElideMode.ElideRight, room) + tail
    room = width - metrics.horizontalAdvance(f"{head}… › {state}")
    return f"{head}… › {metrics.elidedText(axis.axis, Qt.TextElideMode.ElideMiddle, max(room, 40))}{state}"


def _recent() -> list[tuple[str, str]]:
    raw = QSettings().value(RECENT_KEY, [])
    items = raw if isinstance(raw, list) else [raw] if isinstance(raw, str) else []
    out = []
    for item in items:
        machine, sep, axis = str(item).partition("/")
        if sep and machine and axis:
            out.append((machine, axis))
    return out


def _remember(machine: str, axis: str) -> None:
    entries = [f"{m}/{a}" for m, a in _recent() if (m, a) != (machine, axis)]
    QSettings().setValue(RECENT_KEY, [f"{machine}/{axis}", *entries][:RECENT_MAX])


class WindowAxisDialog(QDialog):
    """Names the machine and axis the window records under (empty: the default), and the operator."""

    def __init__(self, recording: WindowRegister, parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("Record in the register as")
        self.recording = recording
        self._known = recording.known_axes()
        current = recording.axis
        layout = QVBoxLayout(self)
        intro = QLabel(
            f"What this window learns (parameters read and written, alarms, checks, reports, "
            f"recordings, model checks) goes into the register "
            f"<b>{_html(shown_location(recording.location))}</b> under this machine and axis. "
            "Facts recorded before stay where they are."
        )
        if recording.server is not None:
            intro.setText(
                intro.text() + " They go to the server through this computer's queue for it, "
                f"{_html(str(recording.server.queue))}, which keeps them while the server does not answer."
            )
        intro.setWordWrap(True)
        layout.addWidget(intro)
        form = QFormLayout()
        self.machine_combo = _name_combo(
            sorted(self._known), current.machine if current.machine_named else ""
        )
        self.machine_combo.lineEdit().setPlaceholderText(f"{recording.default_machine} (this computer's)")
        self.axis_combo = _name_combo([], current.axis if current.axis_named else "")
        self.axis_combo.lineEdit().setPlaceholderText(
            f"{recording.default_axis_name()} (after the actuator or the connection)"
        )
        self.operator_edit = QLineEdit(str(QSettings().value(OPERATOR_KEY, "") or ""))
        login = login_name()
        self.operator_edit.setPlaceholderText(
            f"your name (else the login name {login})" if login else "your name"
        )
        form.addRow("&Machine:", self.machine_combo)
        form.addRow("A&xis:", self.axis_combo)
        form.addRow("&Operator:", self.operator_edit)
        layout.addLayout(form)
        self.error_label = QLabel("")
        self.error_label.setObjectName("error")
        self.error_label.setWordWrap(True)
        self.error_label.setStyleSheet("color: #b00020;")
        layout.addWidget(self.error_label)
        buttons = QDialogButtonBox(
            QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel
        )
        self.default_button = QPushButton("&Default names")
        self.default_button.setToolTip(
            "This computer's bench, the axis named after its actuator or connection"
        )
        buttons.addButton(self.default_button, QDialogButtonBox.ButtonRole.ResetRole)
        self.default_button.clicked.connect(self._defaults)
        self.deliver_button: QPushButton | None = None
        if recording.server is not None:
            self.deliver_button = QPushButton("&Try the server now")
            self.deliver_button.setToolTip(
                "Send what waits on this computer to the server now (it is tried again by itself too)"
            )
            buttons.addButton(self.deliver_button, QDialogButtonBox.ButtonRole.ActionRole)
            self.deliver_button.clicked.connect(recording.deliver_now)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)
        self.machine_combo.currentTextChanged.connect(self._offer_axes)
        self._offer_axes(self.machine_combo.currentText())
        self.resize(560, self.sizeHint().height())
        if recording.questions is not None:  # the server's axes too, when it answers
            recording.questions.ask(
                "the machines and axes of the register",
                lambda reg: [(a.machine, a.name) for a in reg.axes()],
                self._offer_known,
                lambda _why: None,  # the message line says a server that does not answer
            )

    def _offer_known(self, axes: list[tuple[str, str]]) -> None:
        """The server's machines and axes beside those offered already."""
        for machine, axis in axes:
            names_there = self._known.setdefault(machine, [])
            if axis not in names_there:
                names_there.append(axis)
        text = self.machine_combo.currentText()
        self.machine_combo.blockSignals(True)
        self.machine_combo.clear()
        self.machine_combo.addItems(sorted(self._known))
        self.machine_combo.setCurrentText(text)
        self.machine_combo.blockSignals(False)
        self._offer_axes(text)

    @Slot(str)
    def _offer_axes(self, machine: str) -> None:
        text = self.axis_combo.currentText()
        self.axis_combo.blockSignals(True)
        self.axis_combo.clear()
        self.axis_combo.addItems(self._known.get(machine.strip(), []))
        self.axis_combo.setCurrentText(text)
        self.axis_combo.blockSignals(False)

    @Slot()
    def _defaults(self) -> None:
        self.machine_combo.setCurrentText("")
        self.axis_combo.setCurrentText("")

    def accept(self) -> None:
        try:
            self.recording.name_axis(self.machine_combo.currentText(), self.axis_combo.currentText())
        except names.NameProblem as exc:
            self.error_label.setText(str(exc))
            return
        QSettings().setValue(OPERATOR_KEY, self.operator_edit.text().strip())
        axis = self.recording.axis
        self.recording.window.show_message(
            f"Register: from now on recorded as machine {axis.machine}, axis {axis.axis}."
        )
        super().accept()


def _name_combo(items: list[str], text: str) -> QComboBox:
    combo = QComboBox()
    combo.setEditable(True)
    combo.setInsertPolicy(QComboBox.InsertPolicy.NoInsert)
    combo.addItems(items)
    combo.setCurrentText(text)
    combo.setMinimumWidth(320)
    return combo


def _html(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;")
