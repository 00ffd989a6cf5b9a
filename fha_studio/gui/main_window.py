"""The main window: a toolbar with servo and the always-visible STOP, the pages as tabs, and a
status bar with link, servo, alarm and what the drive supports."""

from __future__ import annotations

import logging
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, cast

from PySide6.QtCore import QObject, QSettings, Qt, Slot
from PySide6.QtGui import QAction, QKeySequence, QShortcut
from PySide6.QtWidgets import (
    QMainWindow,
    QMessageBox,
    QPushButton,
    QTabWidget,
    QToolBar,
    QVBoxLayout,
    QWidget,
)

from fha_studio.catalog import DEFAULT_ACTUATOR
from fha_studio.gui.link import (
    DriveStatus,
    JogLease,
    LinkController,
    LinkInfo,
    LinkReply,
    Open,
    Servo,
    SimPanelRequest,
    Stop,
)
from fha_studio.gui.messages import Level, MessageArea
from fha_studio.gui.mnemonics import mnemonic, resolve_mnemonics
from fha_studio.gui.pages.alarms import AlarmsPage
from fha_studio.gui.pages.base import Page, PageId
from fha_studio.gui.pages.connection import ConnectionPage
from fha_studio.gui.pages.direction import DirectionPage
from fha_studio.gui.pages.jog import JogPage
from fha_studio.gui.pages.lookup import PageLookup
from fha_studio.gui.pages.parameters import ParametersPage
from fha_studio.gui.pages.registry import PAGES, PageEntry
from fha_studio.gui.session import Session, new_axis_state
from fha_studio.gui.state import AxisState
from fha_studio.gui.widgets import AMBER, GREEN, RED, Lamp, StopButton, WrappingLabel
from fha_studio.hardware.protocol import BAUDRATE
from fha_studio.hardware.sim.options import drive_words
from fha_studio.logic.commissioning import CommissioningState

if TYPE_CHECKING:
    from fha_studio.gui.pages.modelcheck.page import ModelCheckPage
    from fha_studio.gui.pages.procedures.page import ProceduresPage
    from fha_studio.gui.pages.scope.page import ScopePage
    from fha_studio.gui.pages.sizing import SizingPage

log = logging.getLogger(__name__)

#: The key bound to STOP, everywhere in the main window (documented in the README and tooltip).
STOP_KEY = Qt.Key.Key_Escape
#: Room for the link summary in the status bar [px]; the messages get the rest.
CAPS_WIDTH_PX = 420
#: ... but never more than this share of the window's width, so that a narrow screen (1024 px)
#: still leaves room for the message line.
CAPS_WIDTH_SHARE = 0.25
#: What the status bar's margins, spacing and size grip take of its width [px] (more than they
#: take: a message wrapped a little early keeps its words whole).
STATUS_BAR_SPACING_PX = 72


class WindowPart(Protocol):
    """A part a window of its own has beside its pages (``gui/window_register.py``'s register
    line), ended with the window."""

    def shutdown(self) -> None: ...


class MainWindow(QMainWindow, PageLookup):
    """FHA Studio's main window (its pages by id: :class:`PageLookup`)."""

    def __init__(self, link: LinkController | None = None, parent: QWidget | None = None,
                 state: CommissioningState | None = None):
        """``state``: the axis's commissioning state when it lives elsewhere (an axis of a machine
        project); by default the window has its own, whose declared load is kept in the settings."""
        super().__init__(parent)
        self._caps_text = ""  # the link summary the status bar shows (elided again on a resize)
        self.setWindowTitle("FHA Studio")
        self.setObjectName("mainWindow")
        self.link = link or LinkController(self)
        # the axis being commissioned: every page reads and edits it through this one object
        self._own_state = state is None
        self.state = new_axis_state(self) if state is None else AxisState(state, self)
        if self._own_state:
            self.state.restore_settings(QSettings())
        self.session = Session(self.link, self.state, self)
        from fha_studio.gui.training import TrainingController

        self.training = TrainingController(self)
        #: the register where the Procedures page's sign step finds the signer's key (the
        #: machine window's; None: the user's register by the usual rule)
        self.signing_register: Path | str | None = None
        #: that register's questions when they are not asked on this thread (a server's
        #: ``RegisterQuestions``, gui/register_questions.py; None: the sign step asks the register)
        self.register_questions: QObject | None = None
        #: the register this window records into when it is a window of its own (a
        #: ``WindowRegister``; a machine window's axes are recorded by the machine window)
        self.window_register: WindowPart | None = None
        self._closing_confirmed = False
        self._shut_down = False
        self._status_note = ""
        self._build_toolbar()
        self._build_pages()
        self._build_status_bar()
        self.stop_shortcut = QShortcut(QKeySequence(STOP_KEY), self)
        self.stop_shortcut.setContext(Qt.ShortcutContext.WindowShortcut)
        self.stop_shortcut.activated.connect(self.stop_axis)
        self.link.sigConnected.connect(self._on_connected)
        self.link.sigDisconnected.connect(self._on_link_disconnected)
        self.link.sigStatus.connect(self._on_status)
        self.link.sigResult.connect(self._on_result)
        self.session.sigMessage.connect(self._on_session_message)
        self.resize(1280, 720)
        self._restore_layout()
        self._on_disconnected("not connected", False)

    # -- building -------------------------------------------------------------------------------
    def _build_toolbar(self) -> None:
        bar = QToolBar("Axis", self)
        bar.setObjectName("axisToolbar")
        bar.setMovable(False)
        bar.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
        self.addToolBar(Qt.ToolBarArea.TopToolBarArea, bar)
        self.connect_action = QAction("&Connect…", self)
        self.connect_action.setShortcut(QKeySequence("Ctrl+K"))
        self.connect_action.setToolTip("Choose a drive to connect to (Ctrl+K)")
        self.connect_action.triggered.connect(self.show_connect_dialog)
        bar.addAction(self.connect_action)
        self.disconnect_action = QAction("&Disconnect", self)
        self.disconnect_action.triggered.connect(self.disconnect_drive)
        bar.addAction(self.disconnect_action)
        self.training_action = QAction("Training…", self)
        self.training_action.setToolTip(
            "Training on the simulated drive: choose a scenario; while one runs, its briefing, "
            "your findings and Done"
        )
        self.training_action.triggered.connect(self.show_training)
        bar.addAction(self.training_action)
        bar.addSeparator()
        self.servo_action = QAction("Servo O&N", self)
        self.servo_action.setCheckable(True)
        self.servo_action.setToolTip("Switch the servo on or off (nothing moves without servo on)")
        self.servo_action.triggered.connect(self._servo_clicked)
        bar.addAction(self.servo_action)
        spacer = QWidget()
        spacer.setSizePolicy(
            spacer.sizePolicy().horizontalPolicy().Expanding, spacer.sizePolicy().verticalPolicy().Preferred
        )
        self._spacer_action = bar.addWidget(spacer)
        self.axis_toolbar = bar
        self.alarm_banner = QPushButton("")
        self.alarm_banner.setObjectName("alarmBanner")
        self.alarm_banner.setToolTip("Show the alarm, its cause and remedy on the Alarms page")
        self.alarm_banner.setCursor(Qt.CursorShape.PointingHandCursor)
        self.alarm_banner.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.alarm_banner.clicked.connect(lambda: self.show_page("alarms"))
        self.alarm_banner_action = bar.addWidget(
            self.alarm_banner
        )  # a toolbar widget shows through its action
        self.alarm_banner_action.setVisible(False)
        self.stop_button = StopButton()
        self.stop_button.clicked.connect(self.stop_axis)
        bar.addWidget(self.stop_button)
        from fha_studio.gui.sim_panel import SimPanelBar

        self.sim_panel = SimPanelBar(self.link, self)
        self.sim_panel.sigMessage.connect(self.show_message)
        self.addToolBarBreak(Qt.ToolBarArea.TopToolBarArea)
        self.addToolBar(Qt.ToolBarArea.TopToolBarArea, self.sim_panel)

    def add_axis_line(self, widget: QWidget) -> None:
        """A line about the axis in the toolbar, after the servo (a window of its own shows there
        where the register records it)."""
        self.axis_toolbar.insertSeparator(self._spacer_action)
        self.axis_toolbar.insertWidget(self._spacer_action, widget)

    def _build_pages(self) -> None:
        self.tabs = QTabWidget(self)
        self.tabs.setObjectName("pages")
        self.tabs.setDocumentMode(True)
        self._tabs: dict[PageId, QWidget] = {}
        for entry in PAGES:
            tab = LazyPage(self, entry) if entry.lazy else entry.build(self.session, self)
            assert isinstance(tab, QWidget)
            self._tabs[entry.id] = tab
            self.tabs.addTab(tab, entry.tab_text)
        self.setCentralWidget(self.tabs)
        for page in self._pages():  # the eager ones; a lazy page does it when it is built
            assert isinstance(page, QWidget)
            resolve_mnemonics(page, self.window_mnemonics())
        self.alarms_page.sigAlarmAttention.connect(self._on_alarm_attention)

    def window_mnemonics(self) -> set[str]:
        """The Alt letters of the page tabs and the toolbar: no page may use them."""
        letters = {mnemonic(self.tabs.tabText(i)) for i in range(self.tabs.count())}
        actions = (self.connect_action, self.disconnect_action, self.servo_action)
        letters |= {mnemonic(a.text()) for a in actions}
        letters |= {"f"}  # the servo action reads "Servo O&FF" while the servo is on
        letters.discard(None)
        return letters  # type: ignore[return-value]

    def _find_page(self, name: PageId | str, build: bool) -> Page | None:
        try:
            tab = self._tabs[PageId(name)]
        except ValueError:
            raise ValueError(f"no page {name!r}; pages: {', '.join(PageId)}") from None
        if isinstance(tab, LazyPage):
            return tab.page if build else tab.built
        return cast(Page, tab)

    @property
    def connection_page(self) -> ConnectionPage:
        return self.page(PageId.CONNECTION)

    @property
    def parameters_page(self) -> ParametersPage:
        return self.page(PageId.PARAMETERS)

    @property
    def direction_page(self) -> DirectionPage:
        return self.page(PageId.DIRECTION)

    @property
    def alarms_page(self) -> AlarmsPage:
        return self.page(PageId.ALARMS)

    @property
    def jog_page(self) -> JogPage:
        return self.page(PageId.JOG)

    @property
    def sizing_page(self) -> SizingPage:
        return self.page(PageId.SIZING)

    @property
    def scope_page(self) -> ScopePage:
        return self.page(PageId.SCOPE)

    @property
    def procedures_page(self) -> ProceduresPage:
        return self.page(PageId.PROCEDURES)

    @property
    def modelcheck_page(self) -> ModelCheckPage:
        return self.page(PageId.MODELCHECK)

    def _build_status_bar(self) -> None:
        bar = self.statusBar()
        self.link_lamp = Lamp("Link")
        self.servo_lamp = Lamp("Servo", AMBER)
        self.alarm_lamp = Lamp("Alarm", RED)
        # the link's state in a few words (whole, wrapped; what it means in the tooltip): it never
        # takes the room of the messages, which a person must see
        self.caps_label = WrappingLabel("")
        self.caps_label.setObjectName("capabilities")
        self.caps_label.setMaximumWidth(CAPS_WIDTH_PX)
        self.message_area = MessageArea(self)
        bar.addWidget(self.message_area, 1)
        for w in (self.link_lamp, self.servo_lamp, self.alarm_lamp):
            bar.addPermanentWidget(w)
        bar.addPermanentWidget(self.caps_label)

    def _set_caps(self, text: str) -> None:
        """The link summary at the right of the status bar, wrapped to its room (a word longer
        than the room, a long URL, shortened in its middle); whole in the tooltip."""
        self._caps_text = text
        width = self._caps_width()
        self.caps_label.setMaximumWidth(width)
        metrics = self.caps_label.fontMetrics()
        room = width - 8
        self.caps_label.setText(" ".join(
            metrics.elidedText(word, Qt.TextElideMode.ElideMiddle, room) for word in text.split(" ")
        ))
        self.caps_label.setToolTip(text)
        self._fit_message_line()

    def _fit_message_line(self) -> None:
        """The message line wraps at the room the status bar leaves it beside the lamps and the
        link's state (known from the window's width, not from a passing layout)."""
        text = self.message_area.text_label
        lamps = (self.link_lamp, self.servo_lamp, self.alarm_lamp)
        beside = (self.message_area.log_button, *lamps, self.caps_label)
        room = self.width() - sum(w.sizeHint().width() for w in beside) - STATUS_BAR_SPACING_PX
        text.set_wrap_width(max(text.minimumWidth(), room))

    def _caps_width(self) -> int:
        return max(120, min(CAPS_WIDTH_PX, int(self.width() * CAPS_WIDTH_SHARE)))

    def resizeEvent(self, event) -> None:
        super().resizeEvent(event)
        text = self._caps_text
        if text:
            tooltip = self.caps_label.toolTip()
            self._set_caps(text)
            self.caps_label.setToolTip(tooltip)  # a connected drive's tooltip says more than the text
        self._fit_message_line()

    # -- settings -------------------------------------------------------------------------------
    def _restore_layout(self) -> None:
        settings = QSettings()
        geometry = settings.value("window/geometry")
        if geometry is not None:
            self.restoreGeometry(geometry)
        state = settings.value("window/state")
        if state is not None:
            self.restoreState(state)
        remembered = str(settings.value("window/page", ""))
        if remembered in set(PageId):  # else none (or one of an older version): the first page
            self.tabs.setCurrentWidget(self._tabs[PageId(remembered)])
        for page in self._pages():
            page.restore_settings(settings)

    def save_layout(self) -> None:
        settings = QSettings()
        settings.setValue("window/geometry", self.saveGeometry())
        settings.setValue("window/state", self.saveState())
        current = self.tabs.currentWidget()
        settings.setValue("window/page", next(str(i) for i, tab in self._tabs.items() if tab is current))
        if self._own_state:
            self.state.save_settings(settings)
        for page in self._pages():
            page.save_settings(settings)

    def _pages(self) -> list[Page]:
        """The pages built so far, in tab order (a lazy page not yet shown has nothing to save,
        stop or tell)."""
        return [page for entry in PAGES if (page := self.built_page(entry.id)) is not None]

    def show_page(self, name: PageId | str) -> Page:
        """Shows the page ``name`` (a :class:`PageId` or its value) and returns it; ValueError
        naming the pages otherwise."""
        page = self.page(name)
        self.tabs.setCurrentWidget(self._tabs[PageId(name)])
        return page

    # -- actions --------------------------------------------------------------------------------
    @Slot()
    def stop_axis(self) -> None:
        """STOP: decelerate and hold. Sent even when the link looks idle."""
        self.release_held()
        if not self.link.connected:
            self.show_message("STOP: no drive is connected, nothing was sent.", Level.WARNING)
            return
        if not self.stop_button.can_send:
            self.show_message(f"STOP: nothing was sent. {StopButton.NO_STOP_TEXT}", Level.WARNING)
            return
        self.link.stop_now()
        self.show_message("STOP sent: the axis decelerates and holds (servo stays on) …")

    def release_held(self) -> None:
        """A jog held anywhere (the Jog page, the scope's panel) lets go."""
        for page in self._pages():
            page.release_held()

    def show_message(self, text: str, level: Level = Level.INFO) -> None:
        """Show an outcome the person caused in the message area (kept in its log with the time)."""
        self.message_area.show_message(text, level)

    @Slot(str)
    def _on_session_message(self, text: str) -> None:
        # the session says "Nothing written: ..." when a write it was asked for did not happen
        self.show_message(text, Level.WARNING if text.startswith("Nothing written") else Level.INFO)

    def connect_to(self, url: str | None = None, baud_rate: int = BAUDRATE) -> bool:
        """Connects (after asking, when the axis is live); False when the user said no. Without a
        URL: the embedded simulated drive, carrying the axis's declared load inertia and the
        catalogue's friction (a realistic axis, as the Connect dialog's default)."""
        if url is None:
            from fha_studio.gui.connect_dialog import sim_url

            url = sim_url(DEFAULT_ACTUATOR, self.state.load_inertia_kgm2)
        if self.link.connected and not self.confirm_axis_release("switch to another drive"):
            return False
        self.link.open(url, baud_rate)
        self.link_lamp.set_state(None)
        self._set_caps(f"Connecting to {url} …")
        return True

    @Slot()
    def show_connect_dialog(self) -> None:
        from fha_studio.gui.connect_dialog import ConnectDialog

        dialog = ConnectDialog(self, load_inertia_kgm2=self.state.load_inertia_kgm2)
        if dialog.exec():
            self.connect_to(dialog.url(), dialog.baud_rate())

    @Slot()
    def show_training(self) -> None:
        from fha_studio.gui.training import open_training

        open_training(self)

    @Slot()
    def disconnect_drive(self) -> None:
        if self.link.connected and self.confirm_axis_release("disconnect"):
            self.link.close_link()

    def confirm_axis_release(self, what: str) -> bool:
        """Asks before the link goes away while the servo is on or the axis moves."""
        if not (self.link.servo_on or self.link.moving):
            return True
        moving = self.link.moving
        text = (
            f"The servo is on{' and the axis is moving' if moving else ''}.\n\n"
            f"If you {what} now, FHA Studio first sends STOP: the axis decelerates to standstill "
            "and is held there by the servo, which stays ON. FHA Studio does not switch the servo "
            "off by itself, because an axis without a brake under a load (a vertical axis) would "
            "drop.\n\nSwitch the servo off yourself first if the axis should be free."
        )
        answer = QMessageBox.warning(
            self,
            f"{what.capitalize()} while the servo is on?",
            text,
            QMessageBox.StandardButton.Ok | QMessageBox.StandardButton.Cancel,
            QMessageBox.StandardButton.Cancel,
        )
        return answer == QMessageBox.StandardButton.Ok

    @Slot(bool)
    def _servo_clicked(self, checked: bool) -> None:
        self.link.send(Servo(checked))
        self.servo_action.setChecked(self.link.servo_on)  # the drive's state decides, not the click

    # -- from the link --------------------------------------------------------------------------
    @Slot(object)
    def _on_connected(self, info: LinkInfo) -> None:
        self.link_lamp.set_state(True, GREEN)
        # the embedded drive in words, also as a drive of the manual's commands: its address
        # carries its options (a file of the run among them), which say nothing in the status bar
        where = drive_words(info.url)
        model = info.driver_model or "driver model unknown"
        self.link_lamp.setToolTip(f"Link: connected to {where} ({model})")
        summary = info.capabilities_summary or "what it supports is unknown"
        # a drive that does not say its model (a real HA-655) is named by where it is
        self._set_caps(" · ".join(([info.driver_model] if info.driver_model else []) + [where, summary]))
        address = f" ({info.url})" if where != info.url else ""
        self.caps_label.setToolTip(f"{model} · {where}{address}\n{info.capabilities}")
        self.disconnect_action.setEnabled(True)
        self.servo_action.setEnabled(info.can_move)
        self.servo_action.setToolTip(
            "Switch the servo on or off (nothing moves without servo on)" if info.can_move else
            "This drive takes servo-ON only from the controller through CN2: switch it there"
        )
        self.stop_button.set_can_send(info.can_move)
        # the full profile has servo, jog and inputs over CN3; the panel is for the documented one
        self.sim_panel.set_available(info.embedded_sim and info.documented_only)
        self.setWindowTitle(f"FHA Studio — {model} — {where}")
        for page in self._pages():
            page.link_connected(info)

    @Slot(str, bool)
    def _on_link_disconnected(self, reason: str, lost: bool) -> None:
        self._on_disconnected(reason, lost)
        for page in self._pages():
            page.link_disconnected(reason, lost)

    @Slot(str, bool)
    def _on_disconnected(self, reason: str, lost: bool) -> None:
        self._status_note = ""
        self.link_lamp.set_state(False, GREEN)
        self.servo_lamp.set_state(None)
        self.alarm_lamp.set_state(None)
        self.disconnect_action.setEnabled(False)
        self.servo_action.setEnabled(False)
        self.stop_button.set_can_send(True)
        self.sim_panel.set_available(False)
        self.servo_action.setChecked(False)
        self.setWindowTitle("FHA Studio — not connected")
        if lost:
            why = _without_prefix(reason, "link lost: ")
            self.link_lamp.set_state(True, RED)
            self.link_lamp.setToolTip(f"Link: LOST — {why}")
            # the reason is the message line's (it can be long); here what to do
            self.caps_label.setStyleSheet("color: #b00020; font-weight: bold;")
            self._set_caps("LINK LOST. Check the cable and power, then Connect… (Ctrl+K)")
            self.caps_label.setToolTip(f"Link lost: {why}")
            self.show_message(f"Link lost: {why}. Check the cable and power, then Connect… (Ctrl+K).",
                              Level.ERROR)
        else:
            self.caps_label.setStyleSheet("")
            because = "" if reason == "not connected" else f" ({reason})"
            self._set_caps(f"Not connected{because}. Connect… (Ctrl+K)")

    @Slot(object)
    def _on_status(self, status: DriveStatus) -> None:
        self.caps_label.setStyleSheet("")
        if status.note != self._status_note:
            self._status_note = status.note
            info = self.link.info
            if status.note:
                self._set_caps(f"Link OK · {status.note}")
            elif info is not None:
                self._on_connected(info)
        if status.servo_on is not None:
            self.servo_lamp.set_state(status.servo_on)
            if status.refused:
                self.servo_lamp.setToolTip(f"Servo: {status.note}")
            self.servo_action.setChecked(status.servo_on)
            self.servo_action.setText("Servo O&N" if not status.servo_on else "Servo O&FF")
        if status.alarm_code is not None:
            self.alarm_lamp.set_state(status.alarm_code != 0)
            self.alarm_lamp.setToolTip(f"Alarm {status.alarm_code}" if status.alarm_code else "Alarm: none")

    @Slot(object)
    def _on_result(self, result: LinkReply) -> None:
        """Every reply, whoever asked: STOP's outcome and each failure, in the message area."""
        request = result.request
        if isinstance(request, Stop):
            if result.ok:
                self.show_message("STOP done: the drive decelerated the axis and holds it (servo stays on).")
            else:
                self.show_message(
                    f"STOP could not be sent: {result.error}. Stop the axis with the emergency stop "
                    "or the controller's servo-OFF.",
                    Level.ERROR,
                )
            return
        if result.ok:
            return
        if isinstance(request, Open):
            self.show_message(f"Could not connect: {result.error}", Level.ERROR)
            self.caps_label.setStyleSheet("color: #b00020; font-weight: bold;")
            self._set_caps("Could not connect: see the message at the left. Connect… (Ctrl+K)")
            self.caps_label.setToolTip(f"Could not connect: {result.error}")
            self.link_lamp.set_state(True, RED)
            self.connection_page.link_disconnected(str(result.error), False)
        elif not isinstance(request, JogLease | SimPanelRequest):  # the panel says its own
            self.show_message(f"{request.words} failed: {result.error}", Level.ERROR)

    @Slot(int, bool)
    def _on_alarm_attention(self, code: int, attention: bool) -> None:
        self.alarm_banner_action.setVisible(attention)
        if attention:
            self.alarm_banner.setText(f"NEW ALARM {code} — show it")
            self.alarm_banner.setStyleSheet(
                "background: #b00020; color: white; font-weight: bold; border-radius: 4px; padding: 4px;"
            )

    # -- closing --------------------------------------------------------------------------------
    def closeEvent(self, event) -> None:
        if self._shut_down:
            event.accept()
            return
        if not self._closing_confirmed and not self.confirm_axis_release("close FHA Studio"):
            event.ignore()
            return
        self._closing_confirmed = True
        self.save_layout()
        self.shutdown()
        event.accept()

    def shutdown(self) -> None:
        """Stops the axis, closes the port and ends the link thread (idempotent)."""
        if self._shut_down:
            return
        self._shut_down = True
        for page in self._pages():
            page.shutdown()
        self.link.shutdown()
        self.training.shutdown()
        if self.window_register is not None:
            self.window_register.shutdown()


def _without_prefix(text: str, prefix: str) -> str:
    """``text`` without ``prefix`` (any case) in front: the link says "link lost: ..." and the
    window puts its own words before it."""
    return text[len(prefix):] if text.lower().startswith(prefix) else text


class LazyPage(QWidget):
    """A tab whose page is built the first time it is shown (or asked for through `page`); the
    page then gets its saved settings and, if a drive is connected, the connection hook."""

    def __init__(self, window: MainWindow, entry: PageEntry):
        super().__init__()
        self._window = window
        self._entry = entry
        self.built: Page | None = None
        self._layout = QVBoxLayout(self)
        self._layout.setContentsMargins(0, 0, 0, 0)

    @property
    def page(self) -> Page:
        if self.built is None:
            window = self._window
            page = self._entry.build(window.session, window)
            assert isinstance(page, QWidget)
            self.built = page
            resolve_mnemonics(page, self._window.window_mnemonics())
            self._layout.addWidget(page)
            page.restore_settings(QSettings())
            if window.link.connected and window.link.info is not None:
                page.link_connected(window.link.info)
        return self.built

    def showEvent(self, event) -> None:
        _ = self.page
        super().showEvent(event)
