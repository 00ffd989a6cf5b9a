"""What happens on one axis goes into the register as it happens: an axis of a machine (the
machine window) or the single-axis window's (``gui/window_register.py`` names its axis).

:class:`AxisRecorder` hears the axis's link (parameter reads, verified writes, alarms, the driver
it names) and its pages (procedure checks and reports, recordings, model checks, the DGR checks,
values entered from the front panel); what each becomes in the register is decided below the GUI,
in :mod:`fha_studio.logic.register.facts_from_session`.
"""

from __future__ import annotations

import getpass
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, TypeGuard, TypeVar

from PySide6.QtCore import QObject, Slot

from fha_studio.gui.link import DriveStatus, LinkInfo, LinkReply, ParameterReadout
from fha_studio.gui.main_window import MainWindow
from fha_studio.gui.messages import Level
from fha_studio.gui.pages.base import PageId
from fha_studio.gui.register_writer import DirectWriter, RegisterWriter
from fha_studio.logic.absolute import DgrCheckRecord
from fha_studio.logic.register import Register
from fha_studio.logic.register.facts_from_session import (
    ActuatorFact,
    DriverFact,
    Fact,
    RecordingFact,
    alarm_facts,
    axis_fact,
    facts_from_dgr_check,
    front_panel_facts,
    model_check_facts,
    read_facts,
    report_facts,
    session_fact,
    write_fact,
)

if TYPE_CHECKING:
    from fha_studio.gui.pages.modelcheck.page import ModelCheckPage
    from fha_studio.gui.pages.procedures.page import ProceduresPage
    from fha_studio.logic.modelcheck import ModelCheckResult

_P = TypeVar("_P")

#: QSettings key of the operator's name (the machine window's *Operator* field, the single-axis
#: window's register line): who the register records.
OPERATOR_KEY = "machine/operator"


def login_name() -> str:
    """The computer's login name ("" when the environment and the password database have none)."""
    try:
        return getpass.getuser()
    except (KeyError, OSError):
        return ""


class AxisRecorder(QObject):
    """Writes one axis's commissioning facts into the register as they happen.

    A fact the register cannot take (the file locked for longer than its busy timeout, a full
    disk) is said in the axis's message area; the commissioning goes on."""

    def __init__(
        self,
        register: Register | RegisterWriter,
        axis_ref: str | Callable[[], str],
        window: MainWindow,
        who: Callable[[], str],
        site: str = "",
        axis_fields: Callable[[str], Mapping[str, Any]] | None = None,
    ):
        """``register``: an open register (written on the GUI thread) or a writer (a server's, in
        its own thread). ``axis_ref``: the axis (``MACHINE/AXIS``), or a function saying it at each
        fact (the single-axis window's, which a person may rename). ``axis_fields``: for an axis
        that may not be in the register yet, what a new one is given (actuator, load); the axis
        is added before its facts."""
        super().__init__(window)
        self.writer = register if isinstance(register, RegisterWriter) else DirectWriter(register, self)
        self.writer.sigNotRecorded.connect(self._on_not_recorded)
        self._axis_ref = axis_ref
        self._axis_fields = axis_fields
        self._axes_sent: set[str] = set()
        self._stopped = False
        self.site = site
        self.window = window
        self._who = who
        self._alarm_code = 0
        self._hooked: set[int] = set()
        link = window.link
        window.session.sigParametersRead.connect(self._on_read)
        link.sigWrite.connect(self._on_write)
        link.sigStatus.connect(self._on_status)
        link.sigConnected.connect(self._on_connected)
        window.state.sigFrontPanelChanged.connect(self._on_front_panel)
        self._front_panel_seen: set[tuple[str, int, int, str]] = set()
        window.tabs.currentChanged.connect(lambda _index: self.hook_pages())
        self.hook_pages()

    # -- pages built later (plots, procedures) ------------------------------------------------------
    def hook_pages(self) -> None:
        """Connects to the pages built so far (a page with plots is built when first shown)."""
        window = self.window
        if self._first_time(procedures := window.built_page(PageId.PROCEDURES)):
            procedures.sigStepChanged.connect(lambda: self._on_procedures(procedures))
            procedures.sigReportWritten.connect(lambda html, pdf: self._on_report(procedures, html, pdf))
        if self._first_time(scope := window.built_page(PageId.SCOPE)):
            scope.view.sigRecordingSaved.connect(self._on_recording)
        if self._first_time(modelcheck := window.built_page(PageId.MODELCHECK)):
            modelcheck.sigFinished.connect(lambda result: self._on_model_check(modelcheck, result))
        if self._first_time(absolute := window.built_page(PageId.ABSOLUTE)):
            absolute.sigRecorded.connect(self._on_dgr_check)

    def _first_time(self, page: _P | None) -> TypeGuard[_P]:
        """A page built and not hooked yet (it is hooked now)."""
        if page is None or id(page) in self._hooked:
            return False
        self._hooked.add(id(page))
        return True

    @property
    def axis_ref(self) -> str:
        """The axis the next fact goes to (``MACHINE/AXIS``)."""
        return self._axis_ref() if callable(self._axis_ref) else self._axis_ref

    def stop(self) -> None:
        """Records nothing more (the window is closing and its register is closed)."""
        self._stopped = True

    def recorded_axes(self) -> set[str]:
        """The axes facts were sent to (``MACHINE/AXIS``)."""
        return set(self._axes_sent)

    # -- writing, never failing the GUI ---------------------------------------------------------------
    def record(self, facts: Iterable[Fact]) -> None:
        """Hands ``facts`` of the axis to the register (after the axis itself, when the recorder
        may add it: ``axis_fields``)."""
        facts = list(facts)
        if not facts or self._stopped:
            return
        axis = self.axis_ref
        if self._axis_fields is not None:
            facts.insert(0, axis_fact(self._axis_fields(axis), self.who))
        self._axes_sent.add(axis)
        self.writer.record(axis, facts)

    @Slot(str, str, str)
    def _on_not_recorded(self, axis: str, what: str, why: str) -> None:
        if axis in self._axes_sent:  # one writer may serve several axes (a machine's, on a server)
            self.window.show_message(f"Register: the {what} was not recorded ({why}).", Level.WARNING)

    @property
    def who(self) -> str:
        return self._who()

    def record_actuator(self, code: str) -> None:
        """The actuator declared on the axis (its register record says it)."""
        self.record([ActuatorFact(code, self.who)])

    # -- from the link --------------------------------------------------------------------------------
    @Slot(object)
    def _on_connected(self, info: LinkInfo) -> None:
        self._alarm_code = 0
        if info.driver_model:
            self.record([DriverFact(info.driver_model, self.who)])

    @Slot(object)
    def _on_read(self, result: LinkReply[ParameterReadout]) -> None:
        if not result.ok or not result.answer.values:
            return
        info = self.window.link.info
        self.record(
            read_facts(
                self.window.session.parameter_model,
                {(str(mode), number): value for (mode, number), value in result.answer.values.items()},
                self.who,
                driver_model=info.driver_model if info else "",
            )
        )

    @Slot(object)
    def _on_write(self, entry: dict) -> None:
        self.record([write_fact(self.window.session.parameter_model, entry, self.who)])

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        code = status.alarm_code
        if code is None or code == self._alarm_code:
            return
        self._alarm_code = code
        self.record(alarm_facts(code, self.window.session.driver, self.who))

    @Slot()
    def _on_front_panel(self) -> None:
        """Values read off the drive's front panel by a person: a front-panel snapshot per
        entry time and person (an entry already recorded is not recorded again)."""
        self.record(
            front_panel_facts(
                self.window.session.parameter_model,
                self.window.state.front_panel.values(),
                self._front_panel_seen,
            )
        )

    # -- from the pages -------------------------------------------------------------------------------
    def _on_procedures(self, page: ProceduresPage) -> None:
        session = page.session
        if session is None or self._stopped:
            return
        axis_name = self.axis_ref.split("/", 1)[1]
        if session.axis != axis_name and not any(s.records for s in session.runs.values()):
            # a session started on this axis's pages is this axis's, on this machine's site
            session.axis = axis_name
            session.site = session.site or self.site
            if session.path is not None:
                try:
                    session.save()
                except (OSError, ValueError) as exc:
                    self.window.show_message(
                        f"Register: the session file was not recorded ({exc}).", Level.WARNING
                    )
        self.record([session_fact(session)])

    def _on_report(self, page: ProceduresPage, html: Path, pdf: Path | None) -> None:
        self.record(report_facts(page.session, page.context, html, pdf, self.who))

    @Slot(object, str)
    def _on_recording(self, path: Path, what: str) -> None:
        self.record([RecordingFact(path, what, self.who)])

    @Slot(object)
    def _on_dgr_check(self, record: DgrCheckRecord) -> None:
        """A check of the DGR checks page (what it becomes: ``facts_from_dgr_check``)."""
        self.record(facts_from_dgr_check(record))

    def _on_model_check(self, page: ModelCheckPage, result: ModelCheckResult) -> None:
        self.record(
            model_check_facts(result.summary_lines(manual_units=True), page.recording_path or "", self.who)
        )
