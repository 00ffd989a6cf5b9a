"""Training in the GUI: choose a scenario, work on its simulated drive with the ordinary pages,
say "done", read the score sheet (docs/training.md).

The hidden faults reach the drive only through a training registration: the address the link
opens is ``sim://ACTUATOR?training=TOKEN`` and every page sees ``sim://ACTUATOR (training)``.
Nothing here shows a fault before the score sheet.
"""

from __future__ import annotations

import html
import tempfile
from pathlib import Path
from typing import TYPE_CHECKING, Any

from PySide6.QtCore import QObject, Qt, QTimer, Signal, Slot
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QFileDialog,
    QFormLayout,
    QHBoxLayout,
    QLabel,
    QLineEdit,
    QListWidget,
    QListWidgetItem,
    QPlainTextEdit,
    QPushButton,
    QTextBrowser,
    QVBoxLayout,
    QWidget,
)

from fha_studio import clock
from fha_studio.gui.messages import Level
from fha_studio.gui.pages.base import PageId
from fha_studio.gui.pages.lookup import PageLookup
from fha_studio.hardware.sim.options import TrainingRegistration, forget_training, register_training
from fha_studio.logic.training.scenario import Scenario, ScenarioError, list_scenarios
from fha_studio.logic.training.score import ScoreSheet, TraineeRecord, score
from fha_studio.logic.training.sheet import render_sheet_html, sheet_title

if TYPE_CHECKING:
    from fha_studio.logic.modelcheck import ModelCheckResult

#: The main window (typed loosely: it imports this module, and the GUI's modules form no cycle;
#: its pages are typed through :class:`PageLookup`).
_Window = Any

#: How often the running dialog's clock is redrawn [ms].
CLOCK_MS = 1000


def briefing_html(scenario: Scenario) -> str:
    """What the trainee is told, as rich text: never the faults."""
    e = html.escape
    paragraphs = "".join(
        f"<p>{e(' '.join(p.split()))}</p>" for p in scenario.briefing.split("\n\n") if p.strip()
    )
    return (
        f"<h3>{e(scenario.title)}</h3>"
        f"<p><b>Actuator</b> {e(scenario.actuator)} &nbsp; <b>Driver</b> "
        f"{e(scenario.driver or 'as the combination table gives')}<br>"
        f"<b>Declared load inertia</b> {scenario.load_inertia_kgm2:g} kg·m² &nbsp; "
        f"<b>Time guide</b> {scenario.time_guide_min:g} min &nbsp; <b>Level</b> {e(scenario.level)}</p>"
        f"{paragraphs}"
    )


class TrainingController(QObject):
    """The window's training session: at most one at a time."""

    sigStarted = Signal(object)  # Scenario
    sigFinished = Signal(object)  # ScoreSheet

    def __init__(self, window: _Window):
        super().__init__(window)
        self.window = window
        self.scenario: Scenario | None = None
        self.trainee = ""
        self.started_s = 0.0
        self.last_sheet: ScoreSheet | None = None
        self._registration: TrainingRegistration | None = None
        self._effects: list[tuple[str, float]] = []
        self._folder: tempfile.TemporaryDirectory[str] | None = None
        self._modelcheck_hooked = False
        self.draft_findings = ""  # what the trainee wrote so far (kept between two looks)
        self._connecting = False  # "Connecting to the training drive …" is on show
        window.link.sigConnected.connect(self._on_connected)

    @property
    def pages(self) -> PageLookup:
        """The window's pages, each as its own class."""
        return self.window

    @property
    def running(self) -> bool:
        return self.scenario is not None

    def start(self, scenario: Scenario, trainee: str = "", *, paced: bool = True) -> None:
        """Open the scenario's drive (the axis's actuator and declared load become the
        scenario's), and a procedure session for the trainee's records."""
        window = self.window
        self._end_registration()
        self._registration = register_training(scenario.sim_options())
        self.scenario, self.trainee = scenario, trainee.strip()
        self.started_s = clock.now_s()
        self._effects = []
        self.last_sheet = None
        self.draft_findings = ""
        window.state.set_actuator(scenario.actuator, acknowledged=True)
        window.state.set_load_inertia(scenario.load_inertia_kgm2)
        url = f"sim://{scenario.actuator}?training={self._registration.token}" + ("" if paced else "&paced=0")
        self._connecting = True
        window.link.open(url)
        window.link_lamp.set_state(None)
        window.show_message(f"Training started: {scenario.title}. Connecting to the training drive …")
        self._folder = tempfile.TemporaryDirectory(prefix="fha-training-")
        procedures = window.procedures_page
        procedures.new_session(  # in a folder that goes with the training: not a path to show
            Path(self._folder.name) / "training-session.json", scenario.actuator, self.trainee,
            shown_as="of this training (not kept as a commissioning record)",
        )
        self._hook_modelcheck()
        self.sigStarted.emit(scenario)

    @Slot(object)
    def _on_connected(self, info: object) -> None:
        # the message line says what is true now: connected, not still connecting (and only for
        # the training's drive, not another one connected after its opening failed)
        training_drive = str(getattr(info, "url", "")).endswith("(training)")
        if self._connecting and training_drive and self.scenario is not None:
            self._connecting = False
            self.window.show_message(
                f"Training: {self.scenario.title}. Connected to the training drive: "
                "the axis is yours to commission.")

    def _hook_modelcheck(self) -> None:
        page = self.pages.built_page(PageId.MODELCHECK)
        if page is not None and not self._modelcheck_hooked:
            page.sigFinished.connect(self._on_model_check)
            self._modelcheck_hooked = True

    @Slot(object)
    def _on_model_check(self, result: ModelCheckResult) -> None:
        if self.running:
            now = clock.now_s()
            self._effects.extend((e.id, now) for e in result.effects)

    def record(self, findings: str = "") -> TraineeRecord:
        """What the trainee did so far."""
        assert self.scenario is not None and self._registration is not None
        effects = list(self._effects)
        page = self.pages.built_page(PageId.MODELCHECK)
        result = page.result if page is not None else None
        if result is not None and not effects:  # a check run before this controller could listen
            effects = [(e.id, clock.now_s()) for e in result.effects]
        procedures = self.pages.built_page(PageId.PROCEDURES)
        return TraineeRecord(
            started_s=self.started_s,
            ended_s=clock.now_s(),
            journal=self._registration.journal.entries(),
            session=procedures.session if procedures is not None else None,
            model_check_effects=effects,
            findings=findings,
            trainee=self.trainee,
        )

    def finish(self, findings: str = "") -> ScoreSheet:
        """The trainee says done: the score sheet (the faults are revealed from now on)."""
        assert self.scenario is not None
        sheet = score(self.scenario, self.record(findings))
        self.last_sheet = sheet
        self.scenario = None
        self.draft_findings = ""
        self._end_registration()
        self.window.show_message(
            f"Training done: {sheet.found_count} of {len(sheet.faults)} faults found. "
            "The score sheet is open."
        )
        self.sigFinished.emit(sheet)
        return sheet

    def _end_registration(self) -> None:
        # the drive already built keeps running; a new connection to it is no longer possible
        if self._registration is not None:
            forget_training(self._registration.token)
            self._registration = None

    def shutdown(self) -> None:
        self._end_registration()
        if self._folder is not None:
            self._folder.cleanup()
            self._folder = None


class ChooseScenarioDialog(QDialog):
    """Choose a scenario, read its briefing, give your name, start."""

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("Training: choose a scenario")
        self.resize(860, 520)
        self.scenarios: list[Scenario] = []
        layout = QVBoxLayout(self)
        self.problem = QLabel("")
        self.problem.setWordWrap(True)
        self.problem.setStyleSheet("color: #b00020;")
        self.problem.setVisible(False)
        row = QHBoxLayout()
        self.list = QListWidget()
        self.list.setObjectName("scenarioList")
        self.list.setSpacing(3)
        self.briefing = QTextBrowser()
        self.briefing.setObjectName("scenarioBriefing")
        row.addWidget(self.list, 2)
        row.addWidget(self.briefing, 3)
        form = QFormLayout()
        self.trainee = QLineEdit()
        self.trainee.setPlaceholderText("your name (on the score sheet)")
        form.addRow("Trainee", self.trainee)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Cancel)
        self.start_button = buttons.addButton("Start training", QDialogButtonBox.ButtonRole.AcceptRole)
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(
            QLabel(
                "Each scenario hides faults in the simulated drive. Find them with the "
                "ordinary pages and procedures, then say done for your score sheet."
            )
        )
        layout.addWidget(self.problem)
        layout.addLayout(row, 1)
        layout.addLayout(form)
        layout.addWidget(buttons)
        self.list.currentRowChanged.connect(self._show)
        try:
            self.scenarios = list_scenarios()
        except ScenarioError as exc:
            self.problem.setText(f"The scenarios cannot be read: {exc}")
            self.problem.setVisible(True)
        for s in self.scenarios:
            item = QListWidgetItem(f"{s.title}\n{s.level.capitalize()} · about {s.time_guide_min:g} min")
            self.list.addItem(item)
        self.start_button.setEnabled(bool(self.scenarios))
        if self.scenarios:
            self.list.setCurrentRow(0)

    @Slot(int)
    def _show(self, row: int) -> None:
        if 0 <= row < len(self.scenarios):
            self.briefing.setHtml(briefing_html(self.scenarios[row]))

    def chosen(self) -> Scenario | None:
        row = self.list.currentRow()
        return self.scenarios[row] if 0 <= row < len(self.scenarios) else None


class RunningDialog(QDialog):
    """While a scenario runs: the briefing, the time, the trainee's findings and Done."""

    def __init__(self, controller: TrainingController, parent: QWidget | None = None):
        super().__init__(parent)
        assert controller.scenario is not None
        self.controller = controller
        self.setWindowTitle("Training in progress")
        self.resize(640, 520)
        layout = QVBoxLayout(self)
        brief = QTextBrowser()
        brief.setObjectName("runningBriefing")
        brief.setHtml(briefing_html(controller.scenario))
        self.clock = QLabel("")
        self.clock.setObjectName("trainingClock")
        self.findings = QPlainTextEdit()
        self.findings.setObjectName("trainingFindings")
        self.findings.setPlaceholderText(
            "What did you find, and how do you know? (It goes on the score sheet.)"
        )
        self.findings.setPlainText(controller.draft_findings)
        buttons = QDialogButtonBox()
        self.done_button = buttons.addButton(
            "Done: show my score sheet", QDialogButtonBox.ButtonRole.AcceptRole
        )
        close = buttons.addButton("Back to work", QDialogButtonBox.ButtonRole.RejectRole)
        close.setToolTip("Keep working; your findings are kept")
        buttons.accepted.connect(self.accept)
        buttons.rejected.connect(self.reject)
        layout.addWidget(brief, 2)
        layout.addWidget(self.clock)
        layout.addWidget(QLabel("Your findings"))
        layout.addWidget(self.findings, 1)
        layout.addWidget(buttons)
        self._timer = QTimer(self)
        self._timer.timeout.connect(self._tick)
        self._timer.start(CLOCK_MS)
        self._tick()
        self.finished.connect(self._keep_draft)

    @Slot()
    def _tick(self) -> None:
        scenario = self.controller.scenario
        if scenario is None:
            return
        seconds = max(0, round(clock.now_s() - self.controller.started_s))
        self.clock.setText(
            f"Time so far: {seconds // 60} min {seconds % 60:02d} s (guide {scenario.time_guide_min:g} min)"
        )

    @Slot()
    def _keep_draft(self) -> None:
        self.controller.draft_findings = self.findings.toPlainText()


class ScoreSheetDialog(QDialog):
    """The score sheet, with Save PDF… and Save HTML…."""

    sigSaved = Signal(str)

    def __init__(self, sheet: ScoreSheet, parent: QWidget | None = None):
        super().__init__(parent)
        self.sheet = sheet
        self.html = render_sheet_html(sheet)
        self.setWindowTitle(sheet_title(sheet))
        self.resize(900, 640)
        layout = QVBoxLayout(self)
        self.view = QTextBrowser()
        self.view.setObjectName("scoreSheet")
        self.view.setHtml(self.html)
        layout.addWidget(self.view, 1)
        row = QHBoxLayout()
        pdf = QPushButton("Save PDF…")
        pdf.clicked.connect(self._save_pdf)
        page = QPushButton("Save HTML…")
        page.clicked.connect(self._save_html)
        close = QPushButton("Close")
        close.clicked.connect(self.accept)
        for b in (pdf, page):
            row.addWidget(b)
        row.addStretch(1)
        row.addWidget(close)
        layout.addLayout(row)

    def save_pdf(self, path: str | Path) -> Path:
        from fha_studio.gui.pages.procedures.report_pdf import write_pdf

        return write_pdf(self.html, path, sheet_title(self.sheet))

    def save_html(self, path: str | Path) -> Path:
        from fha_studio import fileio

        return fileio.write_text(path, self.html)

    def _ask(self, suffix: str, what: str) -> str:
        name = f"training-{self.sheet.scenario.id}.{suffix}"
        path, _ = QFileDialog.getSaveFileName(
            self, f"Save the score sheet as {what}", name, f"{what} (*.{suffix})"
        )
        return path

    @Slot()
    def _save_pdf(self) -> None:
        path = self._ask("pdf", "PDF")
        if path:
            self.sigSaved.emit(str(self.save_pdf(path)))

    @Slot()
    def _save_html(self) -> None:
        path = self._ask("html", "HTML")
        if path:
            self.sigSaved.emit(str(self.save_html(path)))


def open_training(window: _Window) -> None:
    """The toolbar's Training…: choose and start a scenario, or, while one runs, the briefing,
    the findings and Done."""
    controller = window.training
    if controller.running:
        running = RunningDialog(controller, window)
        if running.exec() == QDialog.DialogCode.Accepted:
            show_score_sheet(window, controller.finish(running.findings.toPlainText()))
        return
    chooser = ChooseScenarioDialog(window)
    if chooser.exec() != QDialog.DialogCode.Accepted or chooser.chosen() is None:
        return
    if window.link.connected and not window.confirm_axis_release("start a training drive"):
        return
    scenario = chooser.chosen()
    assert scenario is not None
    try:
        controller.start(scenario, chooser.trainee.text())
    except (ScenarioError, ValueError, OSError) as exc:
        window.show_message(f"Training could not start: {exc}", Level.ERROR)


def show_score_sheet(window: _Window, sheet: ScoreSheet) -> ScoreSheetDialog:
    dialog = ScoreSheetDialog(sheet, window)
    dialog.setAttribute(Qt.WidgetAttribute.WA_DeleteOnClose)
    dialog.sigSaved.connect(lambda path: window.show_message(f"Score sheet saved: {path}"))
    dialog.show()
    return dialog
