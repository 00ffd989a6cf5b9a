"""The message area: a line at the bottom of the main window (more when the message is long: it
is never cut) for every outcome a person caused (STOP sent or not, a write failed, a backup
saved), and the log of all of them with their time. QStatusBar's temporary messages are covered
by permanent widgets and vanish after a few seconds; a technician who presses STOP must see what
happened, so nothing here is temporary.
"""

from __future__ import annotations

import enum
import time
from dataclasses import dataclass

from PySide6.QtCore import Qt, Signal, Slot
from PySide6.QtWidgets import (
    QDialog,
    QDialogButtonBox,
    QFrame,
    QHBoxLayout,
    QPushButton,
    QTableWidget,
    QTableWidgetItem,
    QVBoxLayout,
    QWidget,
)

from fha_studio import clock
from fha_studio.gui.widgets import WrappingLabel

#: Most messages kept in the log (oldest dropped first).
MESSAGE_LOG_LENGTH = 500


class Level(enum.Enum):
    """How a message is shown: info in the window's text colour, warning amber, error red."""

    INFO = "info"
    WARNING = "warning"
    ERROR = "error"


_STYLE = {
    Level.INFO: "",
    Level.WARNING: "color: #8a5a00; font-weight: bold;",
    Level.ERROR: "color: #b00020; font-weight: bold;",
}


@dataclass(frozen=True)
class Message:
    """One message: wall-clock time (s since the epoch), level and text."""

    time_s: float
    level: Level
    text: str

    @property
    def clock(self) -> str:
        return time.strftime("%H:%M:%S", time.localtime(self.time_s))


class MessageArea(QFrame):
    """The latest message with its time, and a button that opens the log of all messages."""

    sigMessage = Signal(object)  # Message

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.setObjectName("messageArea")
        self.messages: list[Message] = []
        layout = QHBoxLayout(self)
        layout.setContentsMargins(4, 0, 4, 0)
        self.text_label = WrappingLabel("")  # a long message takes a second line, never cut
        self.text_label.setObjectName("messageText")
        self.text_label.setTextInteractionFlags(Qt.TextInteractionFlag.TextSelectableByMouse)
        self.text_label.setMinimumWidth(200)
        self.log_button = QPushButton("Messages")
        self.log_button.setToolTip("Every message of this session with its time")
        self.log_button.setFocusPolicy(Qt.FocusPolicy.NoFocus)
        self.log_button.clicked.connect(self.show_log)
        layout.addWidget(self.text_label, 1)
        layout.addWidget(self.log_button)

    @Slot(str)
    def show_message(self, text: str, level: Level = Level.INFO) -> Message:
        """Show ``text`` whole (wrapped when it is longer than the line; also in the tooltip and the
        log) and keep it."""
        message = Message(clock.now_s(), level, " ".join(str(text).split()))
        self.messages.append(message)
        del self.messages[:-MESSAGE_LOG_LENGTH]
        self.text_label.setText(f"{message.clock}  {message.text}")
        self.text_label.setToolTip(message.text)
        self.text_label.setStyleSheet(_STYLE[level])
        self.log_button.setText(f"Messages ({len(self.messages)})")
        self.sigMessage.emit(message)
        return message

    def latest(self) -> Message | None:
        return self.messages[-1] if self.messages else None

    @Slot()
    def show_log(self) -> None:
        MessageLogDialog(self.messages, self.window()).exec()


class MessageLogDialog(QDialog):
    """All messages of this session, newest first."""

    def __init__(self, messages: list[Message], parent: QWidget | None = None):
        super().__init__(parent)
        self.setWindowTitle("Messages")
        self.resize(760, 420)
        layout = QVBoxLayout(self)
        self.table = QTableWidget(len(messages), 3)
        self.table.setHorizontalHeaderLabels(["Time", "Kind", "Message"])
        self.table.verticalHeader().setVisible(False)
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        self.table.setWordWrap(True)
        for row, message in enumerate(reversed(messages)):
            self.table.setItem(row, 0, QTableWidgetItem(message.clock))
            self.table.setItem(row, 1, QTableWidgetItem(message.level.value))
            self.table.setItem(row, 2, QTableWidgetItem(message.text))
        self.table.horizontalHeader().setStretchLastSection(True)
        self.table.resizeColumnToContents(0)
        self.table.resizeColumnToContents(1)
        self.table.resizeRowsToContents()
        layout.addWidget(self.table)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        buttons.rejected.connect(self.reject)
        layout.addWidget(buttons)


__all__ = ["Level", "Message", "MessageArea", "MessageLogDialog"]
