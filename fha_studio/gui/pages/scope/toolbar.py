"""The scope's toolbar: the LIVE / NOT LIVE indicator and the buttons that act on the whole view."""

from __future__ import annotations

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QFont, QFontMetrics
from PySide6.QtWidgets import QCheckBox, QComboBox, QLabel, QPushButton, QToolBar

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


class ScopeToolbar(QToolBar):
    """Says what the plot shows and carries the user's view-wide actions out as signals."""

    sigLiveToggled = Signal(bool)
    sigBackToLive = Signal()
    sigPaused = Signal(bool)
    sigAutoscale = Signal(bool)
    sigFit = Signal()
    sigCursors = Signal(bool)
    sigRecord = Signal(bool)  # the Record button clicked: True start (ask a file), False stop
    sigFile = Signal(str)  # "save", "png", "csv" or "open": ask for a path

    def __init__(self, parent=None):
        super().__init__("Scope", parent)
        self.indicator = QLabel()
        self.indicator.setObjectName("scopeIndicator")
        # a fixed width: the buttons do not shift when LIVE becomes NOT LIVE: ... (long texts are
        # elided, the whole text is in the tooltip)
        self.indicator.setFixedWidth(INDICATOR_WIDTH_PX)
        self.addWidget(self.indicator)
        self.addSeparator()
        self.live_button = QPushButton("Start live")
        self.live_button.setCheckable(True)
        self.live_button.toggled.connect(self.sigLiveToggled)
        self.addWidget(self.live_button)
        self.back_button = QPushButton("Back to live")
        self.back_button.setToolTip("Leave the capture or file on show and return to the live view")
        self.back_button.clicked.connect(self.sigBackToLive)
        self.addWidget(self.back_button)
        self.pause_button = QPushButton("Pause")
        self.pause_button.setCheckable(True)
        self.pause_button.toggled.connect(self.sigPaused)
        self.addWidget(self.pause_button)
        self.addWidget(QLabel(" Time base "))
        self.time_base = QComboBox()
        for tb in TIME_BASES_S:
            self.time_base.addItem(f"{tb:g} s", tb)
        self.time_base.setCurrentIndex(TIME_BASES_S.index(DEFAULT_TIME_BASE_S))
        self.addWidget(self.time_base)
        self.autoscale = QCheckBox("Autoscale Y")
        self.autoscale.setChecked(True)
        self.autoscale.toggled.connect(self.sigAutoscale)
        self.addWidget(self.autoscale)
        fit = QPushButton("Fit")
        fit.clicked.connect(self.sigFit)
        self.addWidget(fit)
        self.cursors_box = QCheckBox("Cursors")
        self.cursors_box.toggled.connect(self.sigCursors)
        self.addWidget(self.cursors_box)
        self.addSeparator()
        self.record_button = QPushButton("Record…")
        self.record_button.setCheckable(True)
        self.record_button.clicked.connect(self.sigRecord)
        self.addWidget(self.record_button)
        for text, what in (("Save capture…", "save"), ("PNG…", "png"), ("CSV…", "csv"), ("Open…", "open")):
            button = QPushButton(text)
            button.clicked.connect(lambda _=False, w=what: self.sigFile.emit(w))
            self.addWidget(button)
        self._indicator_text = ""

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
        self.indicator.setText(QFontMetrics(font).elidedText(text, Qt.TextElideMode.ElideRight,
                                                             INDICATOR_WIDTH_PX - _INDICATOR_PADDING_PX))
        self.indicator.setToolTip(text)
        self.indicator.setStyleSheet(INDICATOR_STYLE[kind])
        return True

    def indicator_text(self) -> str:
        return self._indicator_text
