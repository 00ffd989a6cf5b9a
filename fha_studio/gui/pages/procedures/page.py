"""The Procedures page: the manual's procedures step by step (a stepper in the main window).

It drives :class:`fha_studio.logic.procedures.ProcedureRun`: one step at a time, each answer
recorded with the operator's name and the time in the session file (saved at every answer, so a
procedure can be left and resumed after a restart). Live checks run in the link thread through
the worker's CALL command; the page never touches the port. A failed check stops the procedure
with the manual's warning until someone says it was put right.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtWidgets import (
    QComboBox,
    QFileDialog,
    QGroupBox,
    QHBoxLayout,
    QInputDialog,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QMessageBox,
    QPushButton,
    QScrollArea,
    QSplitter,
    QStackedWidget,
    QVBoxLayout,
    QWidget,
)

from fha_studio.gui.link import LinkInfo
from fha_studio.gui.pages.absolute import AbsolutePage
from fha_studio.gui.pages.base import BasePage, PageHost, PageId
from fha_studio.gui.pages.direction import DirectionPage
from fha_studio.gui.pages.procedures.bench_watch import BenchWatch
from fha_studio.gui.pages.procedures.dog_panel import SensorDogPanel
from fha_studio.gui.pages.procedures.history import RecordHistory
from fha_studio.gui.pages.procedures.live_panel import LiveCheckPanel
from fha_studio.gui.pages.procedures.signer import ReportSigner
from fha_studio.logic.bench.checks import BenchCheck
from fha_studio.logic.procedures import (
    Observation,
    Procedure,
    ProcedureError,
    ProcedureRun,
    ProcedureSession,
    SessionError,
    Step,
    StepInputError,
    load_all,
)
from fha_studio.logic.procedures.report import build_report
from fha_studio.logic.procedures.report_inputs import ReportInputs, collect_for_report
from fha_studio.logic.register.report_signing import report_file_bytes
from fha_studio.logic.wording import NO_BREAK_SPACE

log = logging.getLogger(__name__)

_STATUS_WORDS = {
    "not_started": "not started",
    "running": "in progress",
    "paused": "paused",
    "stopped": "STOPPED",
    "completed": "done ✓",
}


class ProceduresPage(BasePage):
    """Receiving inspection, installation, wiring, sensor set, rotary direction; the report."""

    sigStepChanged = Signal()  # the current step or the run's state changed
    sigLiveDone = Signal(object)  # Observation of a live check (after it was recorded or shown)
    sigReportWritten = Signal(object, object)  # HTML path, PDF path (or None): a report was written
    sigSigned = Signal(bool)  # a signing asked of a register on a server ended: signed or not

    def __init__(self, gui_session, main_window: PageHost | None = None):
        super().__init__()
        self.gui_session = gui_session
        self.state = gui_session.state  # the axis: its actuator is the one on the Connection page
        self.link = gui_session.link
        self.main_window = main_window
        #: what the session line calls the session instead of its path ("" = its path)
        self._session_shown = ""
        self.session: ProcedureSession | None = None
        self.context: dict | None = None
        self.procedures: list[Procedure] = []
        self.run: ProcedureRun | None = None
        # the sign step's key: in the machine window's register (else the user's), its private
        # key in the user's keys folder
        self.signer = ReportSigner(
            lambda: getattr(self.main_window, "signing_register", None),
            lambda: getattr(self.main_window, "register_questions", None),
            self._message,
        )
        # a move on the Scope's Bench tab answers the steps that take it (CN2, servo on)
        self.bench_watch = BenchWatch(self)
        self._build()
        self.state.sigActuatorChanged.connect(self._axis_changed)
        self.live_panel.relay.sigSample.connect(
            lambda angle, bits: self.dog_panel.observe(angle, bits) if self.dog_panel.wizard else None
        )
        self._refresh()

    # -- layout -------------------------------------------------------------------------------
    def _build(self) -> None:
        layout = QVBoxLayout(self)
        top = QHBoxLayout()
        self.actuator_label = QLabel()
        self.actuator_label.setObjectName("procedureActuator")
        self.actuator_label.setToolTip("The actuator of the axis, given on the Connection page")
        self.operator_edit = QLineEdit()
        self.operator_edit.setPlaceholderText("your name (every check records it)")
        self.new_button = QPushButton("&New session…")
        self.open_button = QPushButton("&Open session…")
        self.new_button.clicked.connect(self._new_clicked)
        self.open_button.clicked.connect(self._open_clicked)
        for w in (
            QLabel("Actuator:"),
            self.actuator_label,
            QLabel("Operator:"),
            self.operator_edit,
            self.new_button,
            self.open_button,
        ):
            top.addWidget(w)
        layout.addLayout(top)
        self.session_label = QLabel("No session: start one with New session (actuator and your name first).")
        self.session_label.setWordWrap(True)
        layout.addWidget(self.session_label)

        split = QSplitter(self)
        layout.addWidget(split, 1)
        self.procedure_list = QListWidget()
        self.procedure_list.setObjectName("procedure_list")
        self.procedure_list.setWordWrap(True)
        self.procedure_list.currentItemChanged.connect(self._procedure_chosen)
        split.addWidget(self.procedure_list)

        middle = QWidget()
        m = QVBoxLayout(middle)
        self.step_box = QGroupBox("Step")
        s = QVBoxLayout(self.step_box)
        self.section_label = QLabel("")
        self.section_label.setObjectName("step_section")
        self.step_text = QLabel("")
        self.step_text.setObjectName("step_text")
        self.step_text.setWordWrap(True)
        self.step_text.setAlignment(Qt.AlignmentFlag.AlignTop | Qt.AlignmentFlag.AlignLeft)
        self.progress_label = QLabel("")
        s.addWidget(self.section_label)
        s.addWidget(self.step_text, 1)
        s.addWidget(self.progress_label)

        self.inputs = QStackedWidget()
        # confirm
        confirm = QWidget()
        c = QHBoxLayout(confirm)
        self.yes_button = QPushButton("&Yes, done / checked")
        self.no_button = QPushButton("N&o")
        self.yes_button.clicked.connect(lambda: self.answer(True))
        self.no_button.clicked.connect(lambda: self.answer(False))
        c.addWidget(self.yes_button)
        c.addWidget(self.no_button)
        # value (measure, text)
        value = QWidget()
        v = QHBoxLayout(value)
        self.value_edit = QLineEdit()
        self.value_edit.setObjectName("value_edit")
        self.unit_label = QLabel("")
        self.value_button = QPushButton("&Record")
        self.value_button.clicked.connect(lambda: self.answer(self.value_edit.text()))
        self.value_edit.returnPressed.connect(self.value_button.click)
        v.addWidget(self.value_edit, 1)
        v.addWidget(self.unit_label)
        v.addWidget(self.value_button)
        # choose
        choose = QWidget()
        ch = QHBoxLayout(choose)
        self.choice_combo = QComboBox()
        self.choice_button = QPushButton("&Record")
        self.choice_button.clicked.connect(lambda: self.answer(self.choice_combo.currentText()))
        ch.addWidget(self.choice_combo, 1)
        ch.addWidget(self.choice_button)
        # live: the drive's check, else what the technician saw (its widgets are the page's too)
        live = self.live_panel = LiveCheckPanel(self.link, self.answer, self._message)
        live.live_button.clicked.connect(self.run_live_check)
        live.sigDone.connect(self.sigLiveDone)
        self.live_button, self.live_label = live.live_button, live.live_label
        self.by_hand_box, self.by_hand_edit = live.by_hand_box, live.by_hand_edit
        self.sim_brake_check = live.sim_brake_check
        # sensor angle
        self.dog_panel = SensorDogPanel(self.link)
        self.dog_panel.sigRecord.connect(self.answer)
        self.dog_panel.sigMessage.connect(self._message)
        self._pages = {}
        for name, widget in (
            ("confirm", confirm),
            ("value", value),
            ("choose", choose),
            ("live", live),
            ("sensor_angle", self.dog_panel),
            ("none", QWidget()),
        ):
            self._pages[name] = self.inputs.addWidget(widget)
        s.addWidget(self.inputs)
        # a step a move seen on the bench answers (CN2 while the servo is on): what to do for it
        self.bench_note = QLabel("")
        self.bench_note.setObjectName("bench_note")
        self.bench_note.setWordWrap(True)
        s.addWidget(self.bench_note)
        m.addWidget(self.step_box, 1)

        self.stop_box = QGroupBox("Stopped")
        st = QVBoxLayout(self.stop_box)
        self.warning_label = QLabel("")
        self.warning_label.setObjectName("stop_warning")
        self.warning_label.setWordWrap(True)
        self.warning_label.setStyleSheet("color: #b00000; font-weight: bold;")
        self.note_edit = QLineEdit()
        self.note_edit.setPlaceholderText("what was put right (goes into the report)")
        self.retry_button = QPushButton("Put right — check a&gain")
        self.retry_button.clicked.connect(lambda: self.retry(self.note_edit.text()))
        st.addWidget(self.warning_label)
        st.addWidget(self.note_edit)
        st.addWidget(self.retry_button)
        m.addWidget(self.stop_box)

        buttons = QHBoxLayout()
        self.pause_button = QPushButton("&Pause (saved)")
        self.pause_button.clicked.connect(self.pause)
        self.report_button = QPushButton("Commissioning &report…")
        self.report_button.clicked.connect(self._report_clicked)
        self.capture_button = QPushButton("Capture the scope &plot")
        self.capture_button.setToolTip("Save what the Scope page shows as a PNG for the report")
        self.capture_button.clicked.connect(self._capture_clicked)
        self.sign_button = QPushButton("&Sign the report")
        self.sign_button.clicked.connect(self._sign_clicked)
        self.message_label = QLabel("")
        self.message_label.setObjectName("procedure_message")
        self.message_label.setWordWrap(True)
        buttons.addWidget(self.pause_button)
        buttons.addWidget(self.capture_button)
        buttons.addWidget(self.report_button)
        buttons.addWidget(self.sign_button)
        m.addLayout(buttons)
        m.addWidget(self.message_label)
        # the step scrolls rather than making the window taller than a 1024 x 600 screen
        middle_scroll = QScrollArea()
        middle_scroll.setWidgetResizable(True)
        middle_scroll.setFrameShape(QScrollArea.Shape.NoFrame)
        middle_scroll.setWidget(middle)
        split.addWidget(middle_scroll)

        self.record_history = RecordHistory()
        self.history = self.record_history.table
        split.addWidget(self.record_history)
        split.setSizes([260, 640, 360])

    # -- sessions -----------------------------------------------------------------------------
    def _identity(self) -> dict[str, str]:
        info = self.link.info
        if info is None:
            return {}
        return {
            "model": info.driver_model,
            "adjusted_for": info.adjusted_for,
            "version": info.firmware,
            "url": info.url,
        }

    def new_session(self, path: str | Path, actuator_code: str = "", operator: str = "",
                    shown_as: str = "") -> None:
        """Start a commissioning session for the axis's actuator saved at ``path``; an
        ``actuator_code`` given here becomes the axis's (ModelCodeError when it is not valid).
        ``shown_as``: what the page calls the session instead of its path (a training's, in a
        temporary folder that goes with the training)."""
        from fha_studio.logic.procedures.context import build_context

        if actuator_code:
            self.state.set_actuator(actuator_code)
        code = self.state.actuator_code
        operator = (operator or self.operator_edit.text()).strip()
        if not code:
            raise ProcedureError(
                "the actuator's model code is needed to start a session: give it on the Connection page"
            )
        context = build_context(code)  # ModelCodeError (a ValueError) says what is wrong with the code
        session = ProcedureSession(actuator_code=code, operator=operator, driver=self._identity())
        session.save(path)
        self._session_shown = shown_as
        self._use(session, context)

    def open_session(self, path: str | Path) -> None:
        """Open a saved session (resume where it was left)."""
        from fha_studio.logic.procedures.context import build_context

        session = ProcedureSession.load(path)
        context = build_context(session.actuator_code)
        # resuming the commissioning of that axis: its actuator is the axis's again
        self.state.set_actuator(session.actuator_code)
        self._session_shown = ""
        self._use(session, context)

    def _use(self, session: ProcedureSession, context: dict) -> None:
        self.signer.forget()
        self.session, self.context = session, context
        self.procedures = load_all(context)
        self.run = None
        if session.operator and not self.operator_edit.text():
            self.operator_edit.setText(session.operator)
        self.procedure_list.blockSignals(True)
        self.procedure_list.clear()
        for procedure in self.procedures:
            item = QListWidgetItem()
            item.setData(256, procedure.id)
            self.procedure_list.addItem(item)
        self.procedure_list.blockSignals(False)
        first = next((i for i, p in enumerate(self.procedures) if p.applies and not self._done(p)), 0)
        self.procedure_list.setCurrentRow(first)
        self._refresh()

    def _done(self, procedure: Procedure) -> bool:
        state = self.session.runs.get(procedure.id) if self.session else None
        return bool(state and state.status == "completed")

    # -- walking ------------------------------------------------------------------------------
    def select_procedure(self, procedure_id: str) -> None:
        for row, procedure in enumerate(self.procedures):
            if procedure.id == procedure_id:
                self.procedure_list.setCurrentRow(row)
                return
        raise ValueError(f"no procedure '{procedure_id}'")

    @Slot(object, object)
    def _procedure_chosen(self, current, _previous) -> None:
        self.dog_panel.release()
        self.run = None
        if current is None or self.session is None:
            self._refresh()
            return
        procedure = next(p for p in self.procedures if p.id == current.data(256))
        if procedure.applies:
            try:
                self.run = ProcedureRun(self.session, procedure)
            except ProcedureError as exc:
                self._message(str(exc))
        self._refresh()

    @property
    def who(self) -> str:
        return self.operator_edit.text().strip() or (self.session.operator if self.session else "")

    def current_step(self) -> Step | None:
        return self.run.current() if self.run else None

    def answer(self, value: Any, detail: str = "") -> bool:
        """Answer the current step (what the buttons do; ``detail``: where the answer came from).
        False with a message when not accepted."""
        if self.run is None:
            return False
        if self.axis_mismatch():
            self._message(self.axis_mismatch())
            return False
        step = self.run.current()
        if step is None:
            return False
        if step.kind == "live" and not isinstance(value, bool | Observation):
            return False
        try:
            record = self.run.submit(value, who=self.who, detail=detail)
        except StepInputError as exc:
            self._message(str(exc))
            return False
        self.live_panel.answered()  # what a live check kept belongs to the step just answered
        self._message("" if record.passed else "The check failed: the procedure stops here.")
        self.value_edit.clear()
        self._refresh()
        return True

    def answer_by_hand(self) -> bool:
        """Record the value the technician entered for a live step the drive cannot answer."""
        return self.live_panel.answer_by_hand()

    def run_live_check(self) -> None:
        """Ask the drive (in the link thread); the answer is recorded when it comes."""
        step = self.current_step()
        if step is None or step.kind != "live" or self.live_panel.asking or self.context is None:
            return
        if self.axis_mismatch():
            self._message(self.axis_mismatch())
            return
        self.live_panel.run(step, self.context, self.session.sensor_angles_deg)

    def bench_move(self, checks: Sequence[BenchCheck]) -> None:
        """A move's checks from the Scope's Bench tab: they answer the steps that take them."""
        self.bench_watch.answer_steps(checks)

    def bench_changed(self, *_args) -> None:
        """The step on show, or the Bench tab's stream, changed: say what the bench does for it."""
        self.bench_watch.attach()
        text = self.bench_watch.note()
        self.bench_note.setText(text)
        self.bench_note.setVisible(bool(text))

    def showEvent(self, event) -> None:
        super().showEvent(event)
        self.bench_changed()  # the Bench tab may have started meanwhile

    def retry(self, note: str = "") -> None:
        if self.run is not None and self.run.stopped:
            self.run.retry(self.who, note)
            self.note_edit.clear()
            self._message("")
            self._refresh()

    def pause(self) -> None:
        if self.run is not None:
            self.run.pause()
            self._message("Paused and saved: open the session again to go on.")
            self._refresh()

    # -- report -------------------------------------------------------------------------------
    def _collect_for_report(self) -> None:
        """Bring what the other pages know into the session before a report (what goes where:
        ``logic.procedures.report_inputs``)."""
        if self.session is None:
            return
        self._add_tuning_plots()
        if collect_for_report(self.session, self._report_inputs()):
            self._refresh()

    def _add_tuning_plots(self) -> None:
        """The Tuning page's measurements as plots beside the session, as a scope plot goes in
        (one file per tuning, its title updated once it has its after)."""
        window = self.main_window
        tuning = window.built_page(PageId.TUNING) if window is not None else None
        if tuning is None or self.session is None or self.session.path is None:
            return
        from fha_studio.gui.pages.tuning import TuningPage  # plots: imported once it is built

        if not isinstance(tuning, TuningPage):
            return
        try:
            plots = tuning.report_plots(self.session.path, self.who)
        except (OSError, ValueError) as exc:  # the report still goes out, with the notes
            self._message(f"The tuning plots were not saved: {exc}")
            return
        by_path = {p["path"]: p for p in self.session.plots}
        for shown, path in plots:
            title = shown.replace(NO_BREAK_SPACE, " ")  # the page's no-break spaces stay on the page
            if str(path) in by_path:
                by_path[str(path)]["title"] = title
            else:
                self.session.add_plot(title, path)

    def _report_inputs(self) -> ReportInputs:
        """The drive's identity, the known parameter values, the Rotary direction page's check and
        the DGR checks page's records, as plain data."""
        values = self.gui_session.known_values()
        window = self.main_window
        direction = window.built_page(PageId.DIRECTION) if window is not None else None
        checks = window.built_page(PageId.ABSOLUTE) if window is not None else None
        tuning = window.built_page(PageId.TUNING) if window is not None else None
        notes: list[tuple[str, str]] = []
        if tuning is not None:
            from fha_studio.gui.pages.tuning import TuningPage  # plots: imported once it is built

            if isinstance(tuning, TuningPage):
                notes = [(text, who or self.who) for text, who in tuning.report_notes()]
        # another page is a Page to this one: what it is, isinstance says
        return ReportInputs(
            who=self.who,
            parameter_model=self.gui_session.parameter_model,
            driver=self._identity(),
            values=values,
            read=set(self.state.drive_values),
            front_panel=dict(self.state.front_panel),
            parameter_file_text=self.gui_session.parameter_file_text(values) if values else "",
            direction_check=direction.last_check if isinstance(direction, DirectionPage) else None,
            dgr_checks=list(checks.records) if isinstance(checks, AbsolutePage) else [],
            tuning_notes=notes,
        )

    def add_plot(self, title: str, png_path: str | Path) -> None:
        if self.session is not None:
            self.session.add_plot(title, png_path)
            self.session.save()

    def capture_scope_plot(self, title: str = "") -> Path | None:
        """Save the Scope page's plot as a PNG beside the session and add it to the report."""
        if self.session is None or self.session.path is None or self.main_window is None:
            return None
        from fha_studio.gui.pages.scope.page import ScopePage

        scope = self.main_window.page(PageId.SCOPE)
        if not isinstance(scope, ScopePage):
            return None
        number = len(self.session.plots) + 1
        path = self.session.path.with_name(f"{self.session.path.stem}-plot{number}.png")
        scope.view.export_png(path)
        from fha_studio.gui.paper import save_for_paper

        save_for_paper(path)  # printed in the report: a light background, the legend readable
        # a bench stream drawn beside CN3's channels: the plot says where its traces came from
        self.add_plot(title or f"Scope plot {number}{scope.bench_source_text()}", path)
        self._message(f"Plot saved for the report: {path}")
        return path

    def write_report(self, html_path: str | Path, pdf_path: str | Path | None = None):
        """Write the commissioning report (HTML, and PDF when a path is given)."""
        from fha_studio.gui.pages.procedures.report_pdf import write_report

        if self.session is None:
            raise SessionError("no session: nothing to report")
        self._collect_for_report()
        html_file = report_file_bytes(self.session, self.context)  # with its signature line when signed
        html, pdf = write_report(build_report(self.session, self.context), html_path, pdf_path, html_file)
        if pdf is not None:
            self.signer.sign_pdf(self.session, pdf)
        self.sigReportWritten.emit(html, pdf)
        return html, pdf

    def sign(self, who: str = "", passphrase: str | None = None) -> bool:
        """Sign the report as ``who`` (else the operator), with their key when the register keeps
        one (``passphrase``: its passphrase; None asks for it when the key is encrypted). A
        register on a server is asked from another thread: False at once, "Signing: asking…" in
        the message line, and the answer there when it comes (``sigSigned`` then)."""
        if self.session is None:
            return False
        self._collect_for_report()
        ask = self._ask_passphrase if passphrase is None else (lambda _path: passphrase)
        session = self.session

        def done(said: str, signed: bool) -> None:
            if self.session is session:  # still the session on show
                self._message(said)
                self._refresh()
            self.sigSigned.emit(signed)

        try:
            said = self.signer.sign(session, who or self.who, self.context, ask, done)
        except ValueError as exc:  # open checks, a key that cannot be used, a wrong passphrase
            said = str(exc)
            self._message(said[:1].upper() + said[1:])  # a sentence in the message line
            return False
        if said is None:
            self._message("Signing: asking the register on the server for the signer's key…")
            return False
        self._message(said)
        self._refresh()
        return True

    def _ask_passphrase(self, key_file: Path) -> str | None:
        text, ok = QInputDialog.getText(self, "Sign the report", f"Passphrase of the key {key_file.name}:",
                                        QLineEdit.EchoMode.Password)
        return text if ok else None

    # -- dialogs ------------------------------------------------------------------------------
    def _new_clicked(self) -> None:
        path, _ = QFileDialog.getSaveFileName(
            self, "New commissioning session", "axis1.fha-session.json", "FHA sessions (*.json)"
        )
        if path:
            try:
                self.new_session(path)
            except (ValueError, OSError) as exc:
                QMessageBox.warning(self, "New session", str(exc))

    def _open_clicked(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open commissioning session", "", "FHA sessions (*.json)")
        if path:
            try:
                self.open_session(path)
            except (ValueError, OSError) as exc:
                QMessageBox.warning(self, "Open session", str(exc))

    def _report_clicked(self) -> None:
        if self.session is None:
            return
        base = self.session.path.with_suffix("") if self.session.path else Path("report")
        path, _ = QFileDialog.getSaveFileName(
            self, "Commissioning report (PDF)", str(base) + ".pdf", "PDF (*.pdf)"
        )
        if path:
            try:
                html, pdf = self.write_report(Path(path).with_suffix(".html"), path)
            except (OSError, ValueError) as exc:  # a folder without permission, a full disk
                self._message(f"The report was not written: {exc}")
                return
            self._message(f"Report written: {pdf} and {html}")

    def _capture_clicked(self) -> None:
        try:
            self.capture_scope_plot()
        except Exception as exc:  # an empty plot, a full disk: say so, the session goes on
            self._message(f"The plot could not be saved: {exc}")

    def _sign_clicked(self) -> None:
        self.sign()

    # -- view ---------------------------------------------------------------------------------
    def axis_mismatch(self) -> str:
        """Why the open session cannot go on with the axis's actuator ("" when it can)."""
        if self.session is None or self.session.actuator_code == self.state.actuator_code:
            return ""
        return (
            f"This session is for {self.session.actuator_code}, but the axis's actuator is now "
            f"{self.state.actuator_code or 'not given'} (Connection page): start a new session for it, "
            "or open its session."
        )

    def _axis_changed(self, _code: str) -> None:
        if self.run is not None and self.axis_mismatch():
            self.pause()  # the answers so far are saved; nothing is recorded against the other actuator
        self._message(self.axis_mismatch())
        self._refresh()

    def _message(self, text: str) -> None:
        self.message_label.setText(text)

    show_message = _message

    def _refresh(self) -> None:
        has_session = self.session is not None
        for row, procedure in enumerate(self.procedures):
            item = self.procedure_list.item(row)
            if not procedure.applies:
                status = "does not apply"
                item.setToolTip(f"Does not apply: {procedure.not_applicable_reason}.")
            else:
                state = self.session.runs.get(procedure.id)
                status = _STATUS_WORDS.get(state.status if state else "not_started", "")
            item.setText(f"{procedure.title} ({procedure.section}) — {status}")
        if has_session:
            signed = self.session.signature
            self.session_label.setText(
                f"Session {self._session_shown or self.session.path} — {self.session.actuator_code}"
                + (f" — signed by {signed['who']}" if signed else "")
                + (" — NOT the axis's actuator" if self.axis_mismatch() else "")
            )
        code = self.state.actuator_code
        self.actuator_label.setText(f"<b>{code}</b>" if code else "not given yet (Connection page)")
        step = self.current_step()
        run = self.run
        self.stop_box.setVisible(bool(run and run.stopped))
        if run and run.stopped:
            self.warning_label.setText(run.state.stop_warning)
        self.pause_button.setEnabled(bool(run))
        self.report_button.setEnabled(has_session)
        self.capture_button.setEnabled(has_session)
        info = self.link.info
        brake = bool(self.context and self.context["flags"].get("brake"))
        self.live_panel.reset(brake_switch=bool(info and info.is_simulated and brake))
        self.sign_button.setEnabled(has_session)
        self.step_box.setEnabled(True)
        if run is None:
            selected = self.procedure_list.currentItem()
            if has_session and selected is not None:
                self.step_text.setText("This procedure does not apply to this actuator.")
            self.section_label.setText("")
            self.progress_label.setText("")
            self.inputs.setCurrentIndex(self._pages["none"])
        elif step is None:
            self.section_label.setText(run.procedure.section)
            self.step_text.setText(f"{run.procedure.title}: done.")
            self.progress_label.setText("")
            self.inputs.setCurrentIndex(self._pages["none"])
        else:
            done, total = run.progress()
            self.section_label.setText(f"§ {step.section}")
            self.step_text.setText(step.text)
            self.progress_label.setText(f"Step {done + 1} of {total}")
            self._show_input(step)
            self.step_box.setEnabled(not run.stopped)
        self.bench_changed()
        self._fill_history()
        self.sigStepChanged.emit()

    def _show_input(self, step: Step) -> None:
        if step.kind == "confirm":
            self.inputs.setCurrentIndex(self._pages["confirm"])
        elif step.kind in ("measure", "text"):
            self.unit_label.setText(step.unit)
            self.value_edit.setPlaceholderText(step.expected_text() if step.kind == "measure" else "")
            self.inputs.setCurrentIndex(self._pages["value"])
        elif step.kind == "choose":
            self.choice_combo.clear()
            self.choice_combo.addItems(list(step.choices))
            self.inputs.setCurrentIndex(self._pages["choose"])
        elif step.kind == "live":
            self.inputs.setCurrentIndex(self._pages["live"])
        elif step.kind == "sensor_angle":
            if self.context is not None and (self.dog_panel.sensor != step.sensor
                                             or self.dog_panel.wizard is None):
                self.dog_panel.start(step.sensor, self.context)
            self.inputs.setCurrentIndex(self._pages["sensor_angle"])

    def _fill_history(self) -> None:
        self.record_history.show_records(self.run.state.records if self.run else [])

    # -- settings (called by the main window) --------------------------------------------------
    def save_settings(self, settings) -> None:
        settings.setValue("procedures/operator", self.operator_edit.text())
        if self.session is not None and self.session.path is not None:
            settings.setValue("procedures/session", str(self.session.path))

    def restore_settings(self, settings) -> None:
        """Reopen the last session, where it was left (a restart resumes the commissioning)."""
        operator = settings.value("procedures/operator", "")
        if operator and not self.operator_edit.text():
            self.operator_edit.setText(str(operator))
        path = settings.value("procedures/session", "")
        if path and self.session is None and Path(str(path)).is_file():
            try:
                self.open_session(str(path))
            except (ValueError, OSError) as exc:
                self._message(f"The last session could not be reopened: {exc}")

    def link_connected(self, info: LinkInfo) -> None:
        self._refresh()

    def shutdown(self) -> None:
        self.dog_panel.shutdown()
