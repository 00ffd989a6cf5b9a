"""A figure of each load shape of the FHA-C manual's Appendix 2: the part seen from the side
(its length along x) and its cross-section (y across, z up), with the letters of the dimensions
the sizing page asks for. Without it a technician cannot tell which side is A, B or C."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import ClassVar

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QBrush, QColor, QPainter, QPainterPath, QPen, QPolygonF
from PySide6.QtWidgets import QSizePolicy, QWidget

#: Each shape's dimensions (parameter names of fha_studio.logic.sizing.inertia) -> the letter the
#: figure and the form use.
LETTERS: dict[str, dict[str, str]] = {
    "cylinder": {"radius_m": "R", "length_m": "L"},
    "slanted_cylinder": {"radius_m": "R", "length_m": "L", "angle_deg": "θ"},
    "elliptic_cylinder": {"b_m": "B", "c_m": "C", "length_m": "L"},
    "rectangular_pillar": {"a_m": "A", "b_m": "B", "c_m": "C"},
    "circular_pipe": {"outer_radius_m": "R1", "inner_radius_m": "R2", "length_m": "L"},
    "ball": {"radius_m": "R"},
    "cone": {"radius_m": "R", "length_m": "L"},
    "square_pipe": {"length_m": "A", "side_m": "B", "wall_m": "D"},
    "rhombus_pillar": {"length_m": "A", "diagonal_b_m": "B", "diagonal_c_m": "C"},
    "hexagonal_pillar": {"length_m": "A", "side_m": "B"},
    "isosceles_triangle_pillar": {"length_m": "A", "base_m": "B", "height_m": "C"},
    "right_triangle_pillar": {"length_m": "A", "leg_b_m": "B", "leg_c_m": "C"},
}

_FILL = QColor("#cfd8dc")
_EDGE = QColor("#37474f")
_AXIS = QColor("#1565c0")
_DIM = QColor("#b71c1c")


class ShapeFigure(QWidget):
    """Side view and cross-section of one Appendix 2 shape, dimensions lettered."""

    def __init__(self, parent: QWidget | None = None):
        super().__init__(parent)
        self.shape = "cylinder"
        self._focus = QPointF()  # the part drawn last: dimension letters go outside it
        self.setMinimumHeight(120)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Fixed)
        self.setToolTip("Which dimension is which: the side view (length along x) and the cross-section")

    def set_shape(self, shape: str) -> None:
        self.shape = shape
        self.update()

    # -- drawing ---------------------------------------------------------------------------------------
    def paintEvent(self, event) -> None:
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        w, h = self.width(), self.height()
        side = QRectF(8, 8, w * 0.55 - 16, h - 16)
        section = QRectF(w * 0.55 + 8, 8, w * 0.45 - 16, h - 16)
        letters = LETTERS.get(self.shape, {})
        draw = self._DRAWERS.get(self.shape)
        if draw is not None:
            draw(self, painter, side, section, letters)
        painter.end()

    def _pen(self, color: QColor, width: float = 1.5) -> QPen:
        return QPen(color, width)

    def _body(self, painter: QPainter, path: QPainterPath) -> None:
        painter.setPen(self._pen(_EDGE))
        painter.setBrush(QBrush(_FILL))
        painter.drawPath(path)
        painter.setBrush(Qt.BrushStyle.NoBrush)

    def _label(self, painter: QPainter, at: QPointF, text: str, color: QColor = _DIM) -> None:
        painter.setPen(color)
        metrics = painter.fontMetrics()
        width = metrics.horizontalAdvance(text) + 6
        rect = QRectF(at.x() - width / 2, at.y() - metrics.height() / 2, width, metrics.height())
        painter.drawText(rect, Qt.AlignmentFlag.AlignCenter, text)

    def _dimension(self, painter: QPainter, a: QPointF, b: QPointF, text: str) -> None:
        """A dimension line from a to b with its letter beside the middle, on the side away from
        the middle of the widget (outside the part, not on its edge)."""
        painter.setPen(self._pen(_DIM, 1.0))
        painter.drawLine(a, b)
        for end, other in ((a, b), (b, a)):
            angle = math.atan2(other.y() - end.y(), other.x() - end.x())
            for turn in (0.45, -0.45):
                painter.drawLine(end, end + QPointF(6 * math.cos(angle + turn), 6 * math.sin(angle + turn)))
        middle = (a + b) / 2
        normal = QPointF(-(b.y() - a.y()), b.x() - a.x())
        length = math.hypot(normal.x(), normal.y()) or 1.0
        normal = normal / length * 10
        centre = self._focus
        if math.dist((middle + normal).toTuple(), centre.toTuple()) < math.dist(
            (middle - normal).toTuple(), centre.toTuple()
        ):
            normal = -normal
        self._label(painter, middle + normal, text)

    def _axis(self, painter: QPainter, start: QPointF, end: QPointF, name: str) -> None:
        painter.setPen(QPen(_AXIS, 1.0, Qt.PenStyle.DashLine))
        painter.drawLine(start, end)
        self._label(painter, end + QPointF(8 if end.x() >= start.x() else -8, -8), name, _AXIS)

    def _side_box(self, side: QRectF, thickness: float) -> QRectF:
        """The side view of a prism: its length along x, ``thickness`` (0..1) of the height."""
        height = side.height() * 0.62 * thickness
        return QRectF(side.left() + 14, side.center().y() - height / 2, side.width() - 40, height)

    def _side_view(self, painter, box: QRectF, body: QPainterPath, length: str) -> None:
        """A side view in ``box``: the body, the x axis through it, its length under it."""
        self._body(painter, body)
        self._focus = box.center()
        self._axis(
            painter,
            QPointF(box.left() - 8, box.center().y()),
            QPointF(box.right() + 22, box.center().y()),
            "x",
        )
        self._dimension(
            painter, QPointF(box.left(), box.bottom() + 8), QPointF(box.right(), box.bottom() + 8), length
        )

    def _prism(self, painter, side, section, letters, outline: QPainterPath, length: str, dims) -> None:
        box = self._side_box(side, 1.0)
        path = QPainterPath()
        path.addRect(box)
        self._side_view(painter, box, path, length)
        self._body(painter, outline)
        centre = section.center()
        self._focus = outline.boundingRect().center()
        self._axis(
            painter, QPointF(section.left() + 4, centre.y()), QPointF(section.right() - 4, centre.y()), "y"
        )
        self._axis(
            painter, QPointF(centre.x(), section.bottom() - 2), QPointF(centre.x(), section.top() + 10), "z"
        )
        for a, b, text in dims:
            self._dimension(painter, a, b, text)

    @staticmethod
    def _across(rect: QRectF, width: str, height: str) -> list[tuple[QPointF, QPointF, str]]:
        """The two dimensions of a cross-section's bounding ``rect``: its width under it (along y),
        its height at its right (along z)."""
        return [
            (QPointF(rect.left(), rect.bottom() + 8), QPointF(rect.right(), rect.bottom() + 8), width),
            (QPointF(rect.right() + 8, rect.top()), QPointF(rect.right() + 8, rect.bottom()), height),
        ]

    def _square(self, section: QRectF, fraction: float = 0.7) -> QRectF:
        size = min(section.width(), section.height()) * fraction
        return QRectF(section.center().x() - size / 2, section.center().y() - size / 2, size, size)

    # one method per shape: the side view and the cross-section
    def _draw_cylinder(self, painter, side, section, letters) -> None:
        circle = self._square(section)
        path = QPainterPath()
        path.addEllipse(circle)
        c = circle.center()
        self._prism(
            painter,
            side,
            section,
            letters,
            path,
            letters["length_m"],
            [(c, QPointF(circle.right(), c.y()) + QPointF(0, 0), letters["radius_m"])],
        )

    def _draw_slanted_cylinder(self, painter, side, section, letters) -> None:
        self._draw_cylinder(painter, side, section, letters)
        box = self._side_box(side, 1.0)
        self._label(
            painter, QPointF(box.center().x(), box.top() - 10), f"axis tilted {letters['angle_deg']} from z"
        )

    def _draw_elliptic_cylinder(self, painter, side, section, letters) -> None:
        square = self._square(section)
        ellipse = QRectF(
            square.left() - square.width() * 0.15,
            square.top() + square.height() * 0.15,
            square.width() * 1.3,
            square.height() * 0.7,
        )
        path = QPainterPath()
        path.addEllipse(ellipse)
        self._prism(
            painter,
            side,
            section,
            letters,
            path,
            letters["length_m"],
            self._across(ellipse, letters["b_m"], letters["c_m"]),
        )

    def _rect_section(self, painter, side, section, letters, length, width, height) -> None:
        square = self._square(section, 0.62)
        rect = QRectF(
            square.left() - square.width() * 0.15, square.top(), square.width() * 1.3, square.height()
        )
        path = QPainterPath()
        path.addRect(rect)
        self._prism(
            painter,
            side,
            section,
            letters,
            path,
            length,
            self._across(rect, width, height),
        )

    def _draw_rectangular_pillar(self, painter, side, section, letters) -> None:
        self._rect_section(painter, side, section, letters, letters["a_m"], letters["b_m"], letters["c_m"])

    def _draw_circular_pipe(self, painter, side, section, letters) -> None:
        outer = self._square(section)
        inner = self._square(section, 0.4)
        path = QPainterPath()
        path.addEllipse(outer)
        path.addEllipse(inner)
        c = outer.center()
        self._prism(
            painter,
            side,
            section,
            letters,
            path,
            letters["length_m"],
            [
                (
                    c,
                    QPointF(c.x() + outer.width() / 2 * 0.7071, c.y() - outer.height() / 2 * 0.7071),
                    letters["outer_radius_m"],
                ),
                (c, QPointF(c.x() - inner.width() / 2, c.y()), letters["inner_radius_m"]),
            ],
        )

    def _draw_ball(self, painter, side, section, letters) -> None:
        circle = self._square(side.united(section), 0.8)
        path = QPainterPath()
        path.addEllipse(circle)
        self._body(painter, path)
        c = circle.center()
        self._focus = c
        self._axis(painter, QPointF(circle.left() - 10, c.y()), QPointF(circle.right() + 20, c.y()), "x")
        self._dimension(painter, c, QPointF(c.x(), circle.top()), letters["radius_m"])

    def _draw_cone(self, painter, side, section, letters) -> None:
        box = self._side_box(side, 1.0)
        triangle = QPolygonF([box.topLeft(), box.bottomLeft(), QPointF(box.right(), box.center().y())])
        path = QPainterPath()
        path.addPolygon(triangle)
        path.closeSubpath()
        self._side_view(painter, box, path, letters["length_m"])
        self._dimension(
            painter,
            QPointF(box.left() - 8, box.center().y()),
            QPointF(box.left() - 8, box.top()),
            letters["radius_m"],
        )

    def _draw_square_pipe(self, painter, side, section, letters) -> None:
        outer = self._square(section, 0.66)
        inner = outer.adjusted(
            outer.width() * 0.18, outer.height() * 0.18, -outer.width() * 0.18, -outer.height() * 0.18
        )
        path = QPainterPath()
        path.addRect(outer)
        path.addRect(inner)
        self._prism(
            painter,
            side,
            section,
            letters,
            path,
            letters["length_m"],
            [
                (
                    QPointF(outer.left(), outer.bottom() + 8),
                    QPointF(outer.right(), outer.bottom() + 8),
                    letters["side_m"],
                ),
                (
                    QPointF(outer.right() + 8, outer.top()),
                    QPointF(outer.right() + 8, inner.top()),
                    letters["wall_m"],
                ),
            ],
        )

    def _polygon_section(self, painter, side, section, letters, points, length, dims) -> None:
        path = QPainterPath()
        path.addPolygon(QPolygonF(points))
        path.closeSubpath()
        self._prism(painter, side, section, letters, path, length, dims)

    def _draw_rhombus_pillar(self, painter, side, section, letters) -> None:
        r = self._square(section, 0.72)
        c = r.center()
        pts = [
            QPointF(r.left() - r.width() * 0.1, c.y()),
            QPointF(c.x(), r.top()),
            QPointF(r.right() + r.width() * 0.1, c.y()),
            QPointF(c.x(), r.bottom()),
        ]
        self._polygon_section(
            painter,
            side,
            section,
            letters,
            pts,
            letters["length_m"],
            self._across(
                QRectF(QPointF(pts[0].x(), r.top()), QPointF(pts[2].x(), r.bottom())),
                letters["diagonal_b_m"],
                letters["diagonal_c_m"],
            ),
        )

    def _draw_hexagonal_pillar(self, painter, side, section, letters) -> None:
        r = self._square(section, 0.72)
        c, radius = r.center(), r.width() / 2
        pts = [
            QPointF(
                c.x() + radius * math.cos(math.radians(60 * k)),
                c.y() + radius * math.sin(math.radians(60 * k)),
            )
            for k in range(6)
        ]
        self._polygon_section(
            painter, side, section, letters, pts, letters["length_m"], [(pts[4], pts[5], letters["side_m"])]
        )

    def _draw_isosceles_triangle_pillar(self, painter, side, section, letters) -> None:
        r = self._square(section, 0.7)
        pts = [r.bottomLeft(), r.bottomRight(), QPointF(r.center().x(), r.top())]
        self._polygon_section(
            painter,
            side,
            section,
            letters,
            pts,
            letters["length_m"],
            self._across(r, letters["base_m"], letters["height_m"]),
        )

    def _draw_right_triangle_pillar(self, painter, side, section, letters) -> None:
        r = self._square(section, 0.7)
        pts = [r.bottomLeft(), r.bottomRight(), r.topLeft()]
        self._polygon_section(
            painter,
            side,
            section,
            letters,
            pts,
            letters["length_m"],
            [
                (QPointF(r.left(), r.bottom() + 8), QPointF(r.right(), r.bottom() + 8), letters["leg_b_m"]),
                (QPointF(r.left() - 8, r.top()), QPointF(r.left() - 8, r.bottom()), letters["leg_c_m"]),
            ],
        )

    #: How each shape is drawn, by its name (a name built into a method's name is not looked up).
    _DRAWERS: ClassVar[dict[str, Callable[..., None]]] = {
        "cylinder": _draw_cylinder,
        "slanted_cylinder": _draw_slanted_cylinder,
        "elliptic_cylinder": _draw_elliptic_cylinder,
        "rectangular_pillar": _draw_rectangular_pillar,
        "circular_pipe": _draw_circular_pipe,
        "ball": _draw_ball,
        "cone": _draw_cone,
        "square_pipe": _draw_square_pipe,
        "rhombus_pillar": _draw_rhombus_pillar,
        "hexagonal_pillar": _draw_hexagonal_pillar,
        "isosceles_triangle_pillar": _draw_isosceles_triangle_pillar,
        "right_triangle_pillar": _draw_right_triangle_pillar,
    }


__all__ = ["LETTERS", "ShapeFigure"]
