"""A machine of several axes in one window.

The axes are listed at the left, beside the pages; choosing one shows every page for that axis
(the same page stays on show). Each axis has its own link (one link worker and thread per port),
its own pages and its own commissioning session, so several axes are connected at once. The
banner above the pages always says which axis they act on. STOP (the button, or Esc on any page)
stops every connected axis that can be stopped, not only the one on show.

What happens on each axis goes into the register as it happens (``gui/axis_recorder.py``):
parameter reads and verified writes, alarms, procedure checks, reports, recordings and model-check
results. An axis is added through ``gui/axis_dialog.py``.

A register file is written and asked on this thread. A register on a server never is: what the
window records (the machine and its axes at the start, an axis added, the machine report, each
axis's facts) goes through this computer's queue for the server (``gui/register_worker.py``), and
what it asks (the Register dialog, the machine report's part from the register, a signature)
through ``gui/register_questions.py``; a slow or absent server is said in the message line.
Nor does the window wait for the server to start: opened by the machine's name
(``server_url``, ``ask_for_axes``) it shows at once the axes this computer's queue for the server
knows (none for a machine never opened here), asks the server for the machine's axes from the
questions' thread and adds those it lacks when the answer comes; while the server is not reachable
it says so, and that what it records is queued on this computer.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path

from PySide6.QtCore import QSettings, Qt, QTimer, Slot
from PySide6.QtGui import QAction, QColor
from PySide6.QtWidgets import (
    QFileDialog,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QMainWindow,
    QMessageBox,
    QStackedWidget,
    QToolBar,
    QVBoxLayout,
    QWidget,
)

from fha_studio import fileio
from fha_studio.gui.axis_dialog import AxisDialog
from fha_studio.gui.axis_recorder import OPERATOR_KEY, AxisRecorder, login_name
from fha_studio.gui.link import LinkController, OpenClient
from fha_studio.gui.main_window import MainWindow
from fha_studio.gui.messages import Level
from fha_studio.gui.pages.base import PageId
from fha_studio.gui.register_connection import without_nothing_changed
from fha_studio.gui.register_dialog import RegisterDialog
from fha_studio.gui.register_questions import (
    LocalQuestions,
    RegisterQuestions,
    ServerQuestions,
    shown_location,
)
from fha_studio.gui.register_worker import ServerWriter
from fha_studio.gui.widgets import StopButton, hint_whole
from fha_studio.hardware.sim.options import drive_words
from fha_studio.logic.machine import MachineAxis, MachineProject
from fha_studio.logic.procedures import ProcedureSession
from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register.facts_from_session import MachineFact, MachineReportFact
from fha_studio.logic.register.server import is_server_url

log = logging.getLogger(__name__)

#: Width of the axis list [px].
AXIS_LIST_WIDTH_PX = 230
#: The machine's axes are asked of a server that did not answer again after this long [s] (at
#: once when a delivery finds it answering).
AXES_RETRY_S = 30.0
#: Lines about the register shown in the pages' place while the machine has no axis.
LINES_WITHOUT_AXES = 3


class MachineWindow(QMainWindow):
    """FHA Studio for a machine: the axis list, the banner, one set of pages per axis."""

    def __init__(
        self,
        project: MachineProject,
        register: Register | None = None,
        open_client: OpenClient | None = None,
        parent: QWidget | None = None,
        server_url: str | None = None,
        ask_for_axes: bool = False,
    ):
        """``register``: an open register file (or one on a server, whose location only is used
        here). ``server_url``: instead, a register on a server that this window never opens on its
        own thread. ``ask_for_axes``: the machine's axes are asked of the server (the project
        holds those this computer knew, perhaps none) and those it lacks are added when the answer
        comes."""
        super().__init__(parent)
        self.setObjectName("machineWindow")
        self.project = project
        self.register = register
        #: the register: its file or its server's URL (None: the window records nothing)
        self.location: Path | str | None = register.location if register is not None else server_url
        self.axis_windows: list[MainWindow] = []
        self.recorders: list[AxisRecorder] = []
        #: a register on a server is written and asked from threads of their own, never this one's
        self.server_writer: ServerWriter | None = None
        #: the register's questions (a file's answered on this thread, a server's from another)
        self.questions: RegisterQuestions | None = None
        if self.location is not None and is_server_url(self.location):
            self.server_writer = ServerWriter(str(self.location), self)
            self.server_writer.sigSay.connect(self._say)
            self.server_writer.sigNotRecorded.connect(self._machine_not_recorded)
            self.server_writer.sigState.connect(self._on_server_state)
            self.questions = ServerQuestions(str(self.location), self)
        elif register is not None:
            self.questions = LocalQuestions(register, self)
        if self.questions is not None:
            self.questions.sigSay.connect(self._say)
        self._shut_down = False
        self._closing_confirmed = False
        self._register_dialog: RegisterDialog | None = None
        #: the last lines about the register said while there was no axis, shown in the pages'
        #: place (the first axis's message line says them again)
        self._lines_without_axes: list[tuple[str, Level]] = []
        #: the machine's axes are still to be had from the server (asked, or to be asked again)
        self.axes_wanted = ask_for_axes and self.questions is not None and self.questions.on_server
        self._asking_axes = False
        self._axes_retry = QTimer(self)
        self._axes_retry.setSingleShot(True)
        self._axes_retry.timeout.connect(self.ask_for_axes)
        self._build_toolbar()
        self._build_body(open_client)
        not_recorded = None
        if self.server_writer is not None:
            if len(project):  # a machine not known here is not made on the server by opening it
                self._record_machine()  # a line says it if the queue cannot take it
        elif register is not None:
            try:
                project.save_to(register, who=self.operator)
            except (RegisterError, OSError) as exc:  # read-only, locked, damaged: said, not raised
                log.warning("register: machine %s not recorded: %s", project.name, exc)
                not_recorded = exc
        self.axis_list.setCurrentRow(0)
        if not_recorded is not None:
            self.current_window.show_message(
                f"Register: the machine was not recorded ({not_recorded}).", Level.WARNING
            )
        self.resize(1366, 740)
        if self.axes_wanted:
            self.ask_for_axes()

    # -- the machine's axes from a server ---------------------------------------------------------
    @Slot()
    def ask_for_axes(self) -> None:
        """Asks the server for the machine's axes (from the questions' thread); the window goes on."""
        if not self.axes_wanted or self._asking_axes or self.questions is None or self._shut_down:
            return
        self._axes_retry.stop()
        self._asking_axes = True
        name = self.project.name
        if self._server_answers() is None:
            known = (f"the {_axes_text(len(self.project))} this computer knew are shown meanwhile"
                     if len(self.project) else "none is shown until it answers")
            self._say(f"Register: asking the plant's register ({shown_location(self.location or '')}) "
                      f"for the axes of {name} ({known}); what this window records is queued on this "
                      "computer and goes to the server when it answers.", Level.INFO)
        self.questions.ask(
            f"the axes of {name}",
            lambda register: (register.machine(name), register.axes(name)),
            self._axes_answered,
            self._axes_not_answered,
        )

    def _axes_answered(self, answer) -> None:
        self._asking_axes, self.axes_wanted = False, False
        _machine, rows = answer
        known = {axis.name for axis in self.project}
        added = []
        for row in rows:
            if row.name in known:
                continue
            try:
                axis = self.project.add_axis(
                    row.name, row.actuator_code, row.driver_model, row.port_url,
                    row.load_inertia_kgm2 or 0.0, row.notes, row.serial_number,
                )
            except ValueError as exc:  # a port another axis here has: said, the others still come
                self._say(f"Register: the server's axis {row.name} is not shown: {exc}", Level.WARNING)
                continue
            self._add_axis_window(axis)
            added.append(axis.name)
        if added:
            self._say(f"Register: the plant's register has {_axes_text(len(added))} of {self.project.name} "
                      f"this computer did not know: {', '.join(added)}.", Level.INFO)
        elif not len(self.project):
            self._say(f"Register: the machine {self.project.name} has no axes in the register: "
                      "Add axis… to add its first.", Level.WARNING)

    def _axes_not_answered(self, why: str) -> None:
        self._asking_axes = False
        if self._shut_down or self.questions is None:
            return
        if self._server_answers() is False:  # the server is away: asked again later
            shown = (f"the {_axes_text(len(self.project))} shown are those this computer knew"
                     if len(self.project) else "the machine's axes come when it answers")
            self._say(f"Register: the plant's register is not reachable ({why}); {shown}, and what "
                      "this window records is queued on this computer until the server answers.",
                      Level.WARNING)
            self._axes_retry.start(int(AXES_RETRY_S * 1000))
            return
        # the server answered, and refused: it does not have the machine, or not this login
        self.axes_wanted = False
        more = "" if len(self.project) else " Add axis… adds its first axis."
        self._say(f"Register: {without_nothing_changed(why)}.{more}", Level.WARNING)

    def _server_answers(self) -> bool | None:
        """Whether the server answered the last question (None: none asked yet, or no server)."""
        return self.questions.answers if isinstance(self.questions, ServerQuestions) else None

    @Slot(object)
    def _on_server_state(self, state) -> None:
        """A delivery found the server answering: the axes still wanted are asked at once."""
        if state.reachable and self.axes_wanted and not self._asking_axes:
            self.ask_for_axes()

    def _record_machine(self) -> None:
        """The machine and its axes into the queue for the server (from its thread)."""
        assert self.server_writer is not None
        fact = MachineFact(self.project.to_json(), self.operator)
        self.server_writer.record_machine(self.project.name, [fact])

    @Slot(str, str, str)
    def _machine_not_recorded(self, machine: str, what: str, why: str) -> None:
        if machine == self.project.name:
            self._say(f"Register: the {what} was not recorded ({why}).", Level.WARNING)

    @Slot(str, object)
    def _say(self, text: str, level: Level) -> None:
        """A line about the register, in the message line of the axis on show (in the place of
        the pages while there is no axis)."""
        if self.axis_windows:
            self.current_window.show_message(text, level)
        else:
            # the last few (the questions' and the deliveries' lines come in any order)
            self._lines_without_axes = [*self._lines_without_axes, (text, level)][-LINES_WITHOUT_AXES:]
            lines = "\n\n".join(line for line, _level in self._lines_without_axes)
            self.no_axes_label.setText(f"{self._no_axes_text()}\n\n{lines}")
            self.no_axes_label.setStyleSheet(
                "color: #8a5a00; font-size: 11pt;" if level == Level.WARNING else "font-size: 11pt;"
            )

    def _no_axes_text(self) -> str:
        return (f"Machine {self.project.name}: no axis yet. Its axes come from the register, or "
                "Add axis… adds one.")

    # -- building -------------------------------------------------------------------------------------
    def _build_toolbar(self) -> None:
        bar = QToolBar("Machine", self)
        bar.setObjectName("machineToolbar")
        bar.setMovable(False)
        self.addToolBar(Qt.ToolBarArea.TopToolBarArea, bar)
        title = QLabel(f"  {self.project.name}  ")
        title.setObjectName("machineName")
        title.setStyleSheet("font-weight: bold; font-size: 12pt;")
        bar.addWidget(title)
        self.connect_all_action = QAction("Connect &all axes", self)
        self.connect_all_action.setToolTip("Connect every axis to its port (one link per port)")
        self.connect_all_action.triggered.connect(self.connect_all)
        bar.addAction(self.connect_all_action)
        self.add_axis_action = QAction("Add a&xis…", self)
        self.add_axis_action.setToolTip("Add an axis to the machine: its name, actuator, driver, port, load")
        self.add_axis_action.triggered.connect(self._add_axis_clicked)
        bar.addAction(self.add_axis_action)
        self.report_action = QAction("&Machine report…", self)
        self.report_action.setToolTip(
            "A summary of every axis, then each axis's commissioning report (PDF, HTML)"
        )
        self.report_action.triggered.connect(self._report_clicked)
        bar.addAction(self.report_action)
        self.register_action = QAction("&Register…", self)
        self.register_action.setToolTip(
            "The register: an axis's history, compare axes or snapshots, find a value, open items"
        )
        self.register_action.triggered.connect(self.show_register)
        self.register_action.setEnabled(self.location is not None)
        bar.addAction(self.register_action)
        bar.addSeparator()
        bar.addWidget(QLabel("Operator: "))
        self.operator_edit = QLineEdit(str(QSettings().value(OPERATOR_KEY, "")))
        self.operator_edit.setObjectName("operator")
        login = login_name()
        # the hint short enough to be whole in the toolbar; the tooltip says why the name is asked
        self.operator_edit.setPlaceholderText(f"your name, else {login}" if login else "your name")
        self.operator_edit.setToolTip(
            "Your name: the register records it with what you do"
            + (f"; left empty, the login name {login}" if login else "")
        )
        self.operator_edit.setMaximumWidth(200)
        hint_whole(self.operator_edit)
        self.operator_edit.setMaximumWidth(max(200, self.operator_edit.minimumWidth()))
        self.operator_edit.editingFinished.connect(
            lambda: QSettings().setValue(OPERATOR_KEY, self.operator_edit.text().strip())
        )
        bar.addWidget(self.operator_edit)
        spacer = QWidget()
        spacer.setSizePolicy(
            spacer.sizePolicy().horizontalPolicy().Expanding, spacer.sizePolicy().verticalPolicy().Preferred
        )
        bar.addWidget(spacer)
        self.stop_all_button = StopButton()
        self.stop_all_button.setText("STOP ALL")
        self.stop_all_button.setToolTip("STOP every connected axis: each decelerates and holds (Esc)")
        self.stop_all_button.clicked.connect(self.stop_all)
        bar.addWidget(self.stop_all_button)

    def _build_body(self, open_client: OpenClient | None) -> None:
        body = QWidget(self)
        row = QHBoxLayout(body)
        row.setContentsMargins(4, 4, 4, 4)
        self.axis_list = QListWidget()
        self.axis_list.setObjectName("axisList")
        self.axis_list.setFixedWidth(AXIS_LIST_WIDTH_PX)
        self.axis_list.setWordWrap(True)
        self.axis_list.setSpacing(2)
        self.axis_list.setToolTip("The axes of the machine: choose one, every page acts on it")
        row.addWidget(self.axis_list)
        right = QVBoxLayout()
        self.banner = QLabel("")
        self.banner.setObjectName("axisBanner")
        self.banner.setWordWrap(True)  # a long port (a socket:// or sim:// URL) takes a second line
        self.banner.setStyleSheet(
            "background: #1d3f6e; color: white; font-size: 12pt; font-weight: bold;"
            " padding: 6px; border-radius: 4px;"
        )
        right.addWidget(self.banner)
        self.stack = QStackedWidget()
        right.addWidget(self.stack, 1)
        #: in the place of the pages while the machine has no axis (one from the server to come)
        self.no_axes_label = QLabel(self._no_axes_text())
        self.no_axes_label.setObjectName("noAxes")
        self.no_axes_label.setWordWrap(True)
        self.no_axes_label.setAlignment(Qt.AlignmentFlag.AlignCenter)
        self.no_axes_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        right.addWidget(self.no_axes_label, 1)
        row.addLayout(right, 1)
        self.setCentralWidget(body)
        self._open_client = open_client
        for axis in self.project:
            self._add_axis_window(axis)
        self.axis_list.currentRowChanged.connect(self._axis_chosen)
        self._show_pages_or_none()

    def _show_pages_or_none(self) -> None:
        """The pages of the axis on show, or the line in their place while there is no axis."""
        has_axes = bool(self.axis_windows)
        self.stack.setVisible(has_axes)
        self.no_axes_label.setVisible(not has_axes)
        self.banner.setVisible(has_axes)
        self.report_action.setEnabled(has_axes)
        if not has_axes:
            self.setWindowTitle(f"FHA Studio — {self.project.name}")

    def _add_axis_window(self, axis: MachineAxis) -> MainWindow:
        """The pages of one axis: its own link (worker and thread), its own commissioning state."""
        link = LinkController(open_client=self._open_client)
        window = MainWindow(link, state=axis.state)  # the axis's own commissioning state
        link.setParent(window)
        window.setWindowFlags(Qt.WindowType.Widget)  # a page set inside this window
        window.setObjectName(f"axis:{axis.name}")
        # STOP on any axis's pages (its button, Esc) stops every connected axis
        window.stop_button.clicked.disconnect()
        window.stop_button.clicked.connect(self.stop_all)
        window.stop_shortcut.activated.disconnect()
        window.stop_shortcut.activated.connect(self.stop_all)
        self.stack.addWidget(window)
        self.axis_windows.append(window)
        self.axis_list.addItem(QListWidgetItem())
        index = len(self.axis_windows) - 1
        for signal in (link.sigConnected, link.sigDisconnected, link.sigStatus):
            signal.connect(lambda *_args, i=index: self._refresh_axis(i))
        link.sigStopped.connect(lambda _reply, i=index: self._refresh_axis(i))
        window.state.sigActuatorChanged.connect(lambda code, i=index: self._on_actuator(i, code))
        if self.location is not None:
            window.signing_register = self.location  # the sign step finds the keys there
            window.register_questions = self.questions  # and asks a server from another thread
            writer = self.server_writer or self.register
            assert writer is not None  # a location is a register file open here, or a server's
            self.recorders.append(
                AxisRecorder(
                    writer,
                    f"{self.project.name}/{axis.name}",
                    window,
                    lambda: self.operator,
                    self.project.site,
                )
            )
        self._refresh_axis(index)
        if index == 0:  # the first axis (after none, the pages take the place of the line)
            self.axis_list.setCurrentRow(0)
            self._show_pages_or_none()
            for line in self._lines_without_axes:
                window.show_message(*line)
            self._lines_without_axes = []
        return window

    def add_axis(
        self,
        name: str,
        actuator_code: str = "",
        driver_model: str = "",
        port_url: str = "",
        load_inertia_kgm2: float = 0.0,
        notes: str = "",
        serial_number: str = "",
    ) -> MainWindow:
        """A new axis of the machine, with its pages, in the register too; shown. Raises
        MachineError or the catalogue's ModelCodeError (ValueErrors) and adds nothing then (a
        register file that refuses it too; a register on a server hears of it through this
        computer's queue, and a server that refuses it is said in the message line)."""
        axis = self.project.add_axis(
            name, actuator_code, driver_model, port_url, load_inertia_kgm2, notes, serial_number
        )
        if self.server_writer is not None:
            self._record_machine()
        elif self.register is not None:
            try:
                self.project.save_to(self.register, who=self.operator)
            except (RegisterError, OSError):
                self.project.remove_axis(axis.name)
                raise
        window = self._add_axis_window(axis)
        self.select_axis(axis.name)
        return window

    @Slot()
    def _add_axis_clicked(self) -> None:
        dialog = AxisDialog(self)
        while dialog.exec():
            try:
                self.add_axis(**dialog.values())
            except (ValueError, OSError) as exc:
                dialog.error_label.setText(str(exc))
                continue
            return

    # -- which axis ----------------------------------------------------------------------------------
    @property
    def operator(self) -> str:
        """Who the register records: the name typed, else the computer's login name."""
        return self.operator_edit.text().strip() or login_name()

    @property
    def current_index(self) -> int:
        return self.stack.currentIndex()

    @property
    def current_axis(self) -> MachineAxis:
        return self.project.axes[self.current_index]

    @property
    def current_window(self) -> MainWindow:
        return self.axis_windows[self.current_index]

    def axis_window(self, name: str) -> MainWindow:
        return self.axis_windows[self.project.axes.index(self.project.axis(name))]

    def select_axis(self, name: str) -> MainWindow:
        """Shows the pages of axis ``name`` (MachineError naming the axes when there is none)."""
        index = self.project.axes.index(self.project.axis(name))
        self.axis_list.setCurrentRow(index)
        return self.axis_windows[index]

    @Slot(int)
    def _axis_chosen(self, index: int) -> None:
        if index < 0:
            return
        page = self.stack.currentWidget().tabs.currentIndex() if self.stack.currentWidget() else 0
        self.stack.setCurrentIndex(index)
        self.axis_windows[index].tabs.setCurrentIndex(page)  # the same page, now for this axis
        self._refresh_banner()

    def _axis_state(self, index: int) -> tuple[str, QColor]:
        link = self.axis_windows[index].link
        if link.connected:
            if link.status is not None and link.status.alarm_code:
                return f"ALARM {link.status.alarm_code}", QColor("#b00020")
            if link.servo_on:
                return "servo ON", QColor("#b36b00")
            if link.info is not None and not link.info.can_move:
                return "connected (the manual's commands only)", QColor("#176b1d")
            return "connected", QColor("#176b1d")
        if link.last_disconnect_reason and "lost" in link.last_disconnect_reason.lower():
            return "LINK LOST", QColor("#b00020")
        return "not connected", QColor("#555555")

    def _refresh_axis(self, index: int) -> None:
        axis = self.project.axes[index]
        state, colour = self._axis_state(index)
        item = self.axis_list.item(index)
        item.setText(f"{axis.name}\n{axis.actuator_code or 'actuator not given'}\n{state}")
        item.setForeground(colour)
        item.setToolTip(f"{axis.name}: {axis.actuator_code} at {axis.port_url or 'no port given'} — {state}")
        if index == self.current_index:
            self._refresh_banner()

    def _refresh_banner(self) -> None:
        index = self.current_index
        if index < 0:
            return
        axis = self.project.axes[index]
        window = self.axis_windows[index]
        state, _ = self._axis_state(index)
        driver = window.link.info.driver_model if window.link.info else axis.driver_model
        # an embedded drive in words: its address carries options (a file's path among them)
        port = axis.port_url
        where = drive_words(port) if port else "no port given"
        self.banner.setToolTip(f"Port: {port}" if port else "")
        self.banner.setText(
            f"Axis {axis.name} — {axis.actuator_code or 'actuator not given'}"
            f"{' on ' + driver if driver else ''} — {where} — {state}"
        )
        self.setWindowTitle(f"FHA Studio — {self.project.name} — axis {axis.name}")

    def _on_actuator(self, index: int, code: str) -> None:
        if self.recorders:
            self.recorders[index].record_actuator(code)
        self._refresh_axis(index)

    # -- actions --------------------------------------------------------------------------------------
    def connect_axis(self, name: str) -> bool:
        axis = self.project.axis(name)
        if not axis.port_url:
            self.axis_window(name).show_message(
                f"Axis {name} has no port: Connect… (Ctrl+K) to choose one.", Level.WARNING
            )
            return False
        return self.axis_window(name).connect_to(axis.port_url)

    @Slot()
    def connect_all(self) -> list[str]:
        """Connects every axis that has a port and is not connected; returns their names."""
        started = []
        for axis, window in zip(self.project, self.axis_windows, strict=True):
            if axis.port_url and not window.link.connected and window.connect_to(axis.port_url):
                started.append(axis.name)
        return started

    @Slot()
    def stop_all(self) -> list[str]:
        """STOP to every connected axis; returns the names of the axes it was sent to."""
        sent, idle, elsewhere = [], [], []
        for axis, window in zip(self.project, self.axis_windows, strict=True):
            window.release_held()
            info = window.link.info
            if info is None:
                idle.append(axis.name)
            elif not info.can_move:
                # a drive of the manual's commands only has no STOP over CN3: the controller
                # (servo-ON, command pulses on CN2) moves and stops that axis
                elsewhere.append(axis.name)
            else:
                window.link.stop_now()
                sent.append(axis.name)
        parts = []
        if sent:
            parts.append(f"STOP sent to {', '.join(sent)}: each decelerates and holds (servo stays on)")
        if elsewhere:
            parts.append(f"{', '.join(elsewhere)}: no STOP over the link, the controller stops it")
        if idle:
            parts.append(f"not connected: {', '.join(idle)}")
        text = ("; ".join(parts) if sent else "STOP: nothing was sent; " + "; ".join(parts)) + "."
        level = Level.INFO if sent else Level.WARNING
        for window in self.axis_windows:
            window.show_message(text, level)
        return sent

    def sessions(self) -> dict[str, ProcedureSession]:
        """Each axis's procedure session as its pages hold it (axes without one are left out)."""
        out: dict[str, ProcedureSession] = {}
        for axis, window in zip(self.project, self.axis_windows, strict=True):
            procedures = window.built_page(PageId.PROCEDURES)
            session = procedures.session if procedures is not None else None
            if session is not None:
                out[axis.name] = session
                axis.session_file = session.path
        return out

    def write_machine_report(
        self,
        html_path: str | Path,
        pdf_path: str | Path | None = None,
        done: Callable[[Path, Path | None, str], None] | None = None,
    ):
        """Writes the machine report (HTML, and PDF when a path is given); records it. With a
        register file (or none) at once: returns (html, pdf). With a register on a server its part
        is asked from the server first (the window does not wait): returns None, and ``done``
        hears (html, pdf, why the register's part is missing: "" when it is there) once they are
        written; OSError or ValueError from writing them are said in the message line then."""
        html_path = Path(html_path)
        html_path.parent.mkdir(parents=True, exist_ok=True)
        for target in (html_path, pdf_path):
            if target is not None:
                fileio.check_output_path(target)  # before the work: a target that cannot be written
        sessions = self.sessions()
        if self.questions is None or not self.questions.on_server:
            html, pdf = self._machine_report_files(html_path, pdf_path, sessions, self.register)
            if done is not None:
                done(html, pdf, "")
            return html, pdf
        from fha_studio.logic.machine_report import RegisterExcerpt

        refs = [f"{self.project.name}/{axis.name}" for axis in self.project]

        def written(excerpt: RegisterExcerpt | None, why: str = "") -> None:
            try:
                html, pdf = self._machine_report_files(html_path, pdf_path, sessions, excerpt, why)
            except (OSError, ValueError) as exc:
                self._say(f"The machine report was not written: {exc}", Level.WARNING)
                return
            if done is not None:
                done(html, pdf, why)

        self.questions.ask(
            "what the register knows of the machine's axes",
            lambda register: RegisterExcerpt.of(register, refs),
            written,
            lambda why: written(None, why),
        )
        return None

    def _machine_report_files(self, html_path: Path, pdf_path: str | Path | None, sessions, register,
                              register_problem: str = "") -> tuple[Path, Path | None]:
        from fha_studio.gui.pages.procedures.report_pdf import write_pdf
        from fha_studio.logic.machine_report import build_machine_report, render_machine_html

        report = build_machine_report(self.project, sessions, register, register_problem)
        html = render_machine_html(report)
        fileio.write_text(html_path, html)  # whole or not at all
        pdf = write_pdf(html, pdf_path, report.title, html_path.parent) if pdf_path is not None else None
        # a machine report is not signed itself: each axis's report is
        warnings = sum(s.open_warnings for s in report.summaries)
        if self.server_writer is not None:
            fact = MachineReportFact(self.project.name, pdf or html_path, warnings, self.operator)
            self.server_writer.record_machine(self.project.name, [fact])
        elif self.register is not None:
            self.register.record_report(
                pdf or html_path, machine=self.project.name, open_warnings=warnings, who=self.operator
            )
        return html_path, pdf

    @Slot()
    def show_register(self):
        """Opens the register's questions for this machine, on the axis on show (not modal: the
        pages stay usable); returns the dialog."""

        if self.questions is None:
            return None
        if self._register_dialog is None:
            self._register_dialog = RegisterDialog(
                self.questions,
                self.project.name,
                self.current_axis.name if self.axis_windows else None,
                self,
                writer=self.server_writer,  # a settlement on a server goes through this computer's queue
                operator=lambda: self.operator,
            )
        else:
            self._register_dialog.refresh(self.current_axis.name if self.axis_windows else None)
        self._register_dialog.show()
        self._register_dialog.raise_()
        return self._register_dialog

    def _report_clicked(self) -> None:
        folder = Path(str(QSettings().value("machine/report_dir", str(Path.home()))))
        base = folder / f"{self.project.name}.pdf"
        path, _ = QFileDialog.getSaveFileName(self, "Machine report (PDF)", str(base), "PDF (*.pdf)")
        if not path:
            return
        def written(html: Path, pdf: Path | None, why: str) -> None:
            missing = f" (without what the register knows: {why})" if why else ""
            self._say(f"Machine report written: {pdf} and {html}{missing}",
                      Level.WARNING if why else Level.INFO)

        try:
            self.write_machine_report(Path(path).with_suffix(".html"), path, written)
        except (OSError, ValueError) as exc:
            QMessageBox.warning(self, "Machine report", f"The machine report was not written: {exc}")
            return
        QSettings().setValue("machine/report_dir", str(Path(path).parent))
        if self.questions is not None and self.questions.on_server:
            self._say("Machine report: asking the register on the server what it knows of the axes…",
                      Level.INFO)

    # -- closing --------------------------------------------------------------------------------------
    def closeEvent(self, event) -> None:
        if self._shut_down:
            event.accept()
            return
        live = [
            a.name
            for a, w in zip(self.project, self.axis_windows, strict=True)
            if w.link.servo_on or w.link.moving
        ]
        if live and not self._closing_confirmed:
            answer = QMessageBox.warning(
                self,
                "Close while the servo is on?",
                f"The servo is on at {', '.join(live)}. FHA Studio sends STOP to every axis; each is "
                "held by its servo, which stays ON. Switch the servos off yourself first if the axes "
                "should be free.",
                QMessageBox.StandardButton.Ok | QMessageBox.StandardButton.Cancel,
                QMessageBox.StandardButton.Cancel,
            )
            if answer != QMessageBox.StandardButton.Ok:
                event.ignore()
                return
        self._closing_confirmed = True
        self.shutdown()
        event.accept()

    def shutdown(self) -> None:
        """Stops every axis, closes every port and ends every link thread (idempotent)."""
        if self._shut_down:
            return
        self._shut_down = True
        self._axes_retry.stop()
        if self._register_dialog is not None:
            self._register_dialog.close()
        for window in self.axis_windows:
            window._closing_confirmed = True
            window.shutdown()
        if self.questions is not None:
            self.questions.shutdown()  # a question the server did not answer yet is dropped
        if self.server_writer is not None:
            self.server_writer.shutdown()  # the facts handed over are in this computer's queue


def _axes_text(count: int) -> str:
    """``1 axis``, ``3 axes``."""
    return f"{count} axis" if count == 1 else f"{count} axes"
