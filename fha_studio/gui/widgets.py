"""Small widgets shared by the pages: a lamp, the output-flange picture, the STOP button."""

from __future__ import annotations

import math
from collections.abc import Iterable

from PySide6.QtCore import QEvent, QObject, QPointF, QRectF, QSize, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QFont, QFontMetrics, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import (
    QAbstractButton,
    QLabel,
    QLineEdit,
    QPushButton,
    QScrollArea,
    QSizePolicy,
    QWidget,
)

GREEN = QColor("#2e9d3a")
RED = QColor("#d12c2c")
AMBER = QColor("#e0a000")
GREY = QColor("#9a9a9a")


class Lamp(QLabel):
    """A round indicator with a caption: on (colour), off (grey) or unknown (outline)."""

    def __init__(self, text: str, on_colour: QColor = GREEN, parent: QWidget | None = None):
        super().__init__(parent)
        self._caption = text
        self._on_colour = on_colour
        self._state: bool | None = None
        self.setMinimumHeight(22)
        self.setMinimumWidth(self.sizeHint().width())
        self.setAccessibleName(text)
        self.set_state(None)

    @property
    def state(self) -> bool | None:
        return self._state

    def set_state(self, state: bool | None, on_colour: QColor | None = None) -> None:
        if on_colour is not None:
            self._on_colour = on_colour
        self._state = state
        word = {True: "on", False: "off", None: "unknown"}[state]
        self.setToolTip(f"{self._caption}: {word}")
        self.setAccessibleDescription(word)
        self.update()

    def sizeHint(self) -> QSize:
        width = self.fontMetrics().horizontalAdvance(self._caption) + 30
        return QSize(width, max(22, self.fontMetrics().height() + 6))

    def paintEvent(self, event) -> None:
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        d = min(14, self.height() - 6)
        y = (self.height() - d) / 2
        if self._state is None:
            painter.setPen(QPen(GREY, 1.5, Qt.PenStyle.DashLine))
            painter.setBrush(Qt.BrushStyle.NoBrush)
        else:
            painter.setPen(QPen(QColor("#444"), 1))
            painter.setBrush(QBrush(self._on_colour if self._state else QColor("#d8d8d8")))
        painter.drawEllipse(QRectF(3, y, d, d))
        painter.setPen(self.palette().windowText().color())
        painter.drawText(
            QRectF(d + 9, 0, self.width() - d - 9, self.height()),
            Qt.AlignmentFlag.AlignVCenter | Qt.AlignmentFlag.AlignLeft,
            self._caption,
        )
        painter.end()


class HiddenWhileEmptyLabel(QLabel):
    """A word-wrapped label of a page's outcomes that takes no line while it has nothing to say
    (an empty line is height a plot below it needs)."""

    def __init__(self, text: str = "", parent: QWidget | None = None):
        super().__init__(text, parent)
        self.setWordWrap(True)
        self.setVisible(bool(text))

    def setText(self, text: str) -> None:
        super().setText(text)
        self.setVisible(bool(text))


class WrappingLabel(QLabel):
    """A word-wrapped label that asks its layout for the height its text needs, also in a layout
    that does not ask for height-for-width (the status bar): a long message takes another line
    instead of being cut. Its preferred width is that of the text on one line (up to its maximum
    width). It wraps at ``wrap_width_px`` when its owner sets it (a stretched label, whose room
    the owner knows), else at its preferred width: never at a width a layout gives it for a
    moment, since a window grows with its minimum height and does not shrink back."""

    #: Least width it asks for [px]; a layout may still give it more (a stretch).
    MINIMUM_WIDTH_PX = 120

    def __init__(self, text: str = "", parent: QWidget | None = None):
        super().__init__(text, parent)
        self.setWordWrap(True)
        self.wrap_width_px: int | None = None

    def setText(self, text: str) -> None:
        super().setText(text)
        self.updateGeometry()

    def set_wrap_width(self, width_px: int | None) -> None:
        """Wrap at ``width_px`` (None: at the preferred width)."""
        if width_px != self.wrap_width_px:
            self.wrap_width_px = width_px
            self.updateGeometry()

    def _one_line_width(self) -> int:
        margins = self.contentsMargins()
        room = margins.left() + margins.right() + 2 * self.margin() + 2
        return self.fontMetrics().horizontalAdvance(self.text()) + room

    def _height(self) -> int:
        width = self.wrap_width_px or min(self._one_line_width(), self.maximumWidth())
        height = self.heightForWidth(max(width, 1))
        return height if height > 0 else super().sizeHint().height()

    def sizeHint(self) -> QSize:
        return QSize(min(self._one_line_width(), self.maximumWidth()), self._height())

    def minimumSizeHint(self) -> QSize:
        return QSize(min(self._one_line_width(), self.MINIMUM_WIDTH_PX, self.maximumWidth()), self._height())


class StopButton(QPushButton):
    """The big red STOP. Always enabled: stopping is never refused.

    The window's toolbar has the STOP; a STOP shown elsewhere (the scope's Move panel) follows it
    (``follow``): it says what the toolbar's says and a click is a click on the toolbar's."""

    #: can_send changed (True: STOP goes to the drive; False: the drive has no stop command).
    sigCanSendChanged = Signal(bool)

    def __init__(self, parent: QWidget | None = None):
        super().__init__("STOP  (Esc)", parent)
        self.setObjectName("stopButton")
        self.setToolTip("Stop the axis now: decelerate and hold (the servo stays on). Key: Esc")
        self.setMinimumSize(150, 40)
        font = self.font()
        font.setBold(True)
        font.setPointSizeF(font.pointSizeF() * 1.3)
        self.setFont(font)
        self.can_send = True
        self._apply_style()

    #: What stops an axis whose drive has no stop command over CN3 (a real HA-655).
    NO_STOP_TEXT = (
        "This drive has no stop command over CN3: FHA Studio cannot stop this axis. Stop it with the "
        "emergency stop or the controller's servo-OFF (CN2)."
    )

    def set_can_send(self, can_send: bool) -> None:
        """True: STOP goes to the drive. False: the drive has no stop command, so the button says
        what stops the axis instead and looks like advice, not like a live control."""
        self.can_send = can_send
        if can_send:
            self.setText("STOP  (Esc)")
            self.setToolTip("Stop the axis now: decelerate and hold (the servo stays on). Key: Esc")
        else:
            self.setText("E-STOP / servo-OFF")
            self.setToolTip(self.NO_STOP_TEXT)
        self.setAccessibleDescription(self.toolTip())
        self._apply_style()
        self.sigCanSendChanged.emit(can_send)

    def follow(self, leader: StopButton) -> None:
        """Be a second view of ``leader`` (the toolbar's STOP): the same words and looks at every
        moment, and a click here is a click there (whatever that STOP is wired to do)."""
        self.set_can_send(leader.can_send)
        leader.sigCanSendChanged.connect(self.set_can_send)
        self.clicked.connect(leader.click)

    def _apply_style(self) -> None:
        if self.can_send:
            self.setStyleSheet(
                "QPushButton#stopButton { background: #c62828; color: white; border: 2px solid #7f0000;"
                " border-radius: 6px; padding: 4px 14px; }"
                "QPushButton#stopButton:pressed { background: #8e0000; }"
                "QPushButton#stopButton:focus { border: 3px solid #ffd54f; }"
            )
        else:
            self.setStyleSheet(
                "QPushButton#stopButton { background: #fff3e0; color: #7f0000; border: 2px dashed #c62828;"
                " border-radius: 6px; padding: 4px 10px; }"
                "QPushButton#stopButton:focus { border: 3px dashed #ffd54f; }"
            )


class FlangeWidget(QWidget):
    """The actuator seen from the output flange, with an arrow for the FWD command.

    `clockwise=True` draws FWD as a clockwise arrow (rotary direction 0, the manual's default,
    section 1-10); False draws it counter-clockwise (rotary direction 1).
    """

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self._clockwise: bool | None = True
        self._angle_deg = 0.0  # the output position, to show a mark turning with it
        self.setMinimumSize(220, 220)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setAccessibleName("Output flange, seen from the front")

    def set_clockwise(self, clockwise: bool | None) -> None:
        self._clockwise = clockwise
        word = {True: "clockwise", False: "counter-clockwise", None: "unknown"}[clockwise]
        self.setAccessibleDescription(f"FWD turns the output flange {word}")
        self.update()

    def set_angle_deg(self, angle_deg: float) -> None:
        self._angle_deg = angle_deg
        self.update()

    def sizeHint(self) -> QSize:
        return QSize(300, 300)

    def paintEvent(self, event) -> None:
        p = QPainter(self)
        p.setRenderHint(QPainter.RenderHint.Antialiasing)
        side = min(self.width(), self.height())
        p.translate(self.width() / 2, self.height() / 2)
        scale = side / 300.0
        p.scale(scale, scale)
        # housing (square body seen from the front), flange, hollow shaft, bolt circle
        p.setPen(QPen(QColor("#555"), 2))
        p.setBrush(QColor("#cfd4da"))
        p.drawRoundedRect(QRectF(-100, -100, 200, 200), 14, 14)
        p.setBrush(QColor("#aab3bd"))
        p.drawEllipse(QPointF(0, 0), 78, 78)
        p.setBrush(self.palette().window())
        p.drawEllipse(QPointF(0, 0), 26, 26)  # the hollow shaft
        p.setBrush(QColor("#6b7680"))
        for k in range(8):
            a = math.radians(k * 45 + self._angle_deg)
            p.drawEllipse(QPointF(52 * math.cos(a), 52 * math.sin(a)), 5, 5)
        # a mark on the flange that turns with the output
        a = math.radians(self._angle_deg - 90)
        p.setPen(QPen(QColor("#1565c0"), 5, Qt.PenStyle.SolidLine, Qt.PenCapStyle.RoundCap))
        p.drawLine(QPointF(32 * math.cos(a), 32 * math.sin(a)), QPointF(72 * math.cos(a), 72 * math.sin(a)))
        if self._clockwise is not None:
            self._draw_arrow(p, self._clockwise)
        p.setPen(self.palette().windowText().color())
        font = QFont(self.font())
        font.setPointSizeF(font.pointSizeF() * 1.05)
        p.setFont(font)
        p.drawText(QRectF(-150, 120, 300, 28), Qt.AlignmentFlag.AlignCenter, "seen from the output flange")
        p.end()

    def _draw_arrow(self, p: QPainter, clockwise: bool) -> None:
        colour = QColor("#2e7d32")
        r = 118
        # Qt angles: degrees counter-clockwise from 3 o'clock, y down on screen
        start, span = (150, -120) if clockwise else (30, 120)
        rect = QRectF(-r, -r, 2 * r, 2 * r)
        path = QPainterPath()
        path.arcMoveTo(rect, start)
        path.arcTo(rect, start, span)
        p.setPen(QPen(colour, 9, Qt.PenStyle.SolidLine, Qt.PenCapStyle.FlatCap))
        p.setBrush(Qt.BrushStyle.NoBrush)
        p.drawPath(path)
        end_deg = start + span
        end = QPointF(r * math.cos(math.radians(end_deg)), -r * math.sin(math.radians(end_deg)))
        # tangent direction of travel at the end of the arc (screen coordinates)
        sign = -1 if clockwise else 1
        tangent_deg = end_deg + 90 * sign
        t = QPointF(math.cos(math.radians(tangent_deg)), -math.sin(math.radians(tangent_deg)))
        n = QPointF(-t.y(), t.x())
        tip = end + t * 22
        head = QPolygonF([tip, end + n * 14 - t * 4, end - n * 14 - t * 4])
        p.setPen(Qt.PenStyle.NoPen)
        p.setBrush(colour)
        p.drawPolygon(head)
        p.setPen(colour)
        font = QFont(self.font())
        font.setBold(True)
        font.setPointSizeF(font.pointSizeF() * 1.4)
        p.setFont(font)
        label = "FWD = CW" if clockwise else "FWD = CCW"
        p.drawText(QRectF(-150, -150, 300, 30), Qt.AlignmentFlag.AlignCenter, label)


class _SpaceSwallower(QObject):
    """Eats the Space (and Select) key on the buttons it is installed on."""

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if event.type() not in (QEvent.Type.KeyPress, QEvent.Type.KeyRelease):
            return False
        return event.key() in (Qt.Key.Key_Space, Qt.Key.Key_Select)  # type: ignore[attr-defined]


def space_jogs_only(root: QWidget, jog_buttons: Iterable[QAbstractButton]) -> None:
    """Space holds a jog button; on every other button under ``root`` it does nothing. A
    technician holding Space to jog must not start a move or switch the servo because the
    keyboard focus happened to be on another button (those still take the mouse and Alt+letter)."""
    keep = set(jog_buttons)
    swallower = _SpaceSwallower(root)
    for button in root.findChildren(QAbstractButton):
        if button not in keep:
            button.installEventFilter(swallower)


def scrolling(panel: QWidget, minimum_width_px: int = 240) -> QScrollArea:
    """``panel`` in a scroll area: on a small screen (1024 x 600) a side panel scrolls instead of
    widening the window past the screen."""
    area = QScrollArea()
    area.setWidgetResizable(True)
    area.setFrameShape(QScrollArea.Shape.NoFrame)
    area.setWidget(panel)
    area.setMinimumWidth(minimum_width_px)
    return area


def hint_whole(edit: QLineEdit) -> QLineEdit:
    """``edit`` never narrower than its hint (placeholder): an empty field that says only "cha…"
    no longer says what it wants. The frame's and the text's own margins are added."""
    edit.setMinimumWidth(QFontMetrics(edit.font()).horizontalAdvance(edit.placeholderText()) + 14)
    return edit
