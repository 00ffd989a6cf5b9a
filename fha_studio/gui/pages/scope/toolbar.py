"""The scope's toolbar: the LIVE / NOT LIVE indicator and the buttons that act on the whole view."""

from __future__ import annotations

from enum import StrEnum

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QFont, QFontMetrics
from PySide6.QtWidgets import QCheckBox, QComboBox, QGridLayout, QLabel, QToolBar, QToolButton, QWidget

TIME_BASES_S = (0.5, 1.0, 2.0, 5.0, 10.0, 30.0, 60.0)
DEFAULT_TIME_BASE_S = 10.0
#: Indicator colours: live, not live, paused.
INDICATOR_STYLE = {
    "live": "background:#1b5e20; color:white; font-weight:bold; padding:3px 8px; border-radius:3px;",
    "not": "background:#b71c1c; color:white; font-weight:bold; padding:3px 8px; border-radius:3px;",
    "paused": "background:#e65100; color:white; font-weight:bold; padding:3px 8px; border-radius:3px;",
}


#: The indicator's width [px]: room for "NOT LIVE: waiting for the first sample".
INDICATOR_WIDTH_PX = 270
#: The indicator's padding and border, left and right together [px] (INDICATOR_STYLE).
_INDICATOR_PADDING_PX = 20


def indicator_words(text: str, metrics: QFontMetrics, room_px: int) -> str:
    """``text`` as the indicator shows it in ``room_px`` (the whole text is the tooltip's): whole;
    else up to a colon that still gives a reason ("NOT LIVE: servo on (controller)" of "NOT LIVE:
    servo on (controller): the drive does not answer ..."); else as many whole words as fit, with
    an ellipsis; never a word cut in two."""
    if metrics.horizontalAdvance(text) <= room_px:
        return text
    at = text.rfind(": ")
    while at > 0:
        head = text[:at]
        if ": " in head and metrics.horizontalAdvance(head) <= room_px:
            return head
        at = text.rfind(": ", 0, at)
    words = text.split(" ")
    for count in range(len(words) - 1, 0, -1):
        head = " ".join(words[:count]).rstrip(",;:·") + "…"
        if metrics.horizontalAdvance(head) <= room_px:
            return head
    return metrics.elidedText(text, Qt.TextElideMode.ElideRight, room_px)


def _button(text: str, checkable: bool = False) -> QToolButton:
    """A toolbar button as wide as its text (a push button is at least 80 px): the whole row
    fits a 1280 px window, as the main window's toolbar buttons do."""
    button = QToolButton()
    button.setText(text)
    button.setCheckable(checkable)
    button.setToolButtonStyle(Qt.ToolButtonStyle.ToolButtonTextOnly)
    button.setAutoRaise(True)
    return button


class FileAction(StrEnum):
    """What a file the scope asks for is for."""

    SAVE = "save"  # the capture on show, as an fha-recording
    PNG = "png"  # the plot as an image
    CSV = "csv"  # the data on show as a plain table
    OPEN = "open"  # a recording (or capture) to show
    RECORD = "record"  # a recording streamed from now on

    @property
    def opens(self) -> bool:
        """The file is read (an open dialog), not written."""
        return self is FileAction.OPEN

    @property
    def file_filter(self) -> str:
        return _FILE_FILTERS[self]


_FILE_FILTERS = {
    FileAction.SAVE: "FHA recording (*.csv)",
    FileAction.PNG: "PNG image (*.png)",
    FileAction.CSV: "CSV (*.csv)",
    FileAction.OPEN: "FHA recording (*.csv);;All files (*)",
    FileAction.RECORD: "FHA recording (*.csv)",
}


class ScopeToolbar(QWidget):
    """Says what the plot shows and carries the user's view-wide actions out as signals.

    Two toolbars: the view's (indicator, live, pause, time base, scale, cursors) and the files'
    (record, save, PNG, CSV, open). They share a row when it holds both (1280 px and wider) and
    the files' goes under the view's when it does not: no button is ever behind a chevron."""

    sigLiveToggled = Signal(bool)
    sigBackToLive = Signal()
    sigPaused = Signal(bool)
    sigAutoscale = Signal(bool)
    sigFit = Signal()
    sigCursors = Signal(bool)
    sigRecord = Signal(bool)  # the Record button clicked: True start (ask a file), False stop
    sigFile = Signal(object)  # FileAction (save, png, csv, open): ask for a path

    def __init__(self, parent=None):
        super().__init__(parent)
        self.view_bar = QToolBar("Scope")
        self.file_bar = QToolBar("Scope files")
        self._grid = QGridLayout(self)
        self._grid.setContentsMargins(0, 0, 0, 0)
        self._grid.setSpacing(0)
        self._grid.addWidget(self.view_bar, 0, 0)
        self._grid.addWidget(self.file_bar, 0, 1)
        self._grid.setColumnStretch(1, 1)
        self._one_row = True
        view = self.view_bar
        self.indicator = QLabel()
        self.indicator.setObjectName("scopeIndicator")
        # a fixed width: the buttons do not shift when LIVE becomes NOT LIVE: ... (long texts are
        # elided, the whole text is in the tooltip)
        self.indicator.setFixedWidth(INDICATOR_WIDTH_PX)
        view.addWidget(self.indicator)
        view.addSeparator()
        self.live_button = _button("Start live", checkable=True)
        self.live_button.toggled.connect(self.sigLiveToggled)
        view.addWidget(self.live_button)
        self.back_button = _button("Back to live")
        self.back_button.setToolTip("Leave the capture or file on show and return to the live view")
        self.back_button.clicked.connect(self.sigBackToLive)
        view.addWidget(self.back_button)
        self.pause_button = _button("Pause", checkable=True)
        self.pause_button.toggled.connect(self.sigPaused)
        view.addWidget(self.pause_button)
        view.addWidget(QLabel(" Time base "))
        self.time_base = QComboBox()
        for tb in TIME_BASES_S:
            self.time_base.addItem(f"{tb:g} s", tb)
        self.time_base.setCurrentIndex(TIME_BASES_S.index(DEFAULT_TIME_BASE_S))
        view.addWidget(self.time_base)
        self.autoscale = QCheckBox("Autoscale Y")
        self.autoscale.setChecked(True)
        self.autoscale.toggled.connect(self.sigAutoscale)
        view.addWidget(self.autoscale)
        fit = _button("Fit")
        fit.clicked.connect(self.sigFit)
        view.addWidget(fit)
        self.cursors_box = QCheckBox("Cursors")
        self.cursors_box.toggled.connect(self.sigCursors)
        view.addWidget(self.cursors_box)
        files = self.file_bar
        files.setContentsMargins(8, 0, 0, 0)  # apart from the view's buttons, in one row or two
        self.record_button = _button("Record…", checkable=True)
        self.record_button.clicked.connect(self.sigRecord)
        files.addWidget(self.record_button)
        for text, what in (("Save capture…", FileAction.SAVE), ("PNG…", FileAction.PNG),
                           ("CSV…", FileAction.CSV), ("Open…", FileAction.OPEN)):
            button = _button(text)
            button.clicked.connect(lambda _=False, w=what: self.sigFile.emit(w))
            files.addWidget(button)
        self._indicator_text = ""

    def resizeEvent(self, event) -> None:
        """The files' toolbar beside the view's when the row holds both, else under it."""
        super().resizeEvent(event)
        one_row = self.view_bar.sizeHint().width() + self.file_bar.sizeHint().width() <= event.size().width()
        if one_row != self._one_row:
            self._one_row = one_row
            self._grid.removeWidget(self.file_bar)
            if one_row:
                self._grid.addWidget(self.file_bar, 0, 1)
            else:
                self._grid.addWidget(self.file_bar, 1, 0, 1, 2)

    def one_row(self) -> bool:
        """True when both toolbars share one row."""
        return self._one_row

    def time_base_s(self) -> float:
        return float(self.time_base.currentData())

    def set_live(self, on: bool) -> None:
        """Show the live acquisition as on or off, without asking for it again."""
        self.live_button.blockSignals(True)
        self.live_button.setChecked(on)
        self.live_button.blockSignals(False)
        self.live_button.setText("Stop live" if on else "Start live")

    def set_paused(self, paused: bool) -> None:
        if self.pause_button.isChecked() != paused:
            self.pause_button.setChecked(paused)

    def set_recording(self, on: bool) -> None:
        self.record_button.setChecked(on)
        self.record_button.setText("■ Stop recording" if on else "Record…")

    def set_indicator(self, kind: str, text: str) -> bool:
        """Show ``text`` in the ``kind`` colour ("live", "not", "paused"); True when it changed."""
        if text == self._indicator_text:
            return False
        self._indicator_text = text
        font = QFont(self.indicator.font())
        font.setBold(True)
        room = INDICATOR_WIDTH_PX - _INDICATOR_PADDING_PX
        self.indicator.setText(indicator_words(text, QFontMetrics(font), room))
        self.indicator.setToolTip(text)
        self.indicator.setStyleSheet(INDICATOR_STYLE[kind])
        return True

    def indicator_text(self) -> str:
        return self._indicator_text
