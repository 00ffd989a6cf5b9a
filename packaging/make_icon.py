"""Draws resources/icons/fha-studio.png: an output flange with a FWD arrow.

QT_QPA_PLATFORM=offscreen python packaging/make_icon.py resources/icons/fha-studio.png
"""

import math
import sys

from PySide6.QtCore import QPointF, QRectF, Qt
from PySide6.QtGui import QColor, QGuiApplication, QImage, QPainter, QPainterPath, QPen, QPolygonF

app = QGuiApplication([])
size = 256
img = QImage(size, size, QImage.Format.Format_ARGB32)
img.fill(Qt.GlobalColor.transparent)
p = QPainter(img)
p.setRenderHint(QPainter.RenderHint.Antialiasing)
p.translate(size / 2, size / 2 + 10)
p.setPen(QPen(QColor("#37474f"), 6))
p.setBrush(QColor("#cfd8dc"))
p.drawRoundedRect(QRectF(-84, -80, 168, 168), 20, 20)
p.setBrush(QColor("#90a4ae"))
p.drawEllipse(QPointF(0, 0), 70, 70)
p.setBrush(QColor("#eceff1"))
p.drawEllipse(QPointF(0, 0), 24, 24)
p.setBrush(QColor("#455a64"))
p.setPen(Qt.PenStyle.NoPen)
for k in range(8):
    a = math.radians(k * 45)
    p.drawEllipse(QPointF(47 * math.cos(a), 47 * math.sin(a)), 7, 7)
r = 100
rect = QRectF(-r, -r, 2 * r, 2 * r)
path = QPainterPath()
path.arcMoveTo(rect, 150)
path.arcTo(rect, 150, -120)
p.setPen(QPen(QColor("#c62828"), 16, Qt.PenStyle.SolidLine, Qt.PenCapStyle.FlatCap))
p.setBrush(Qt.BrushStyle.NoBrush)
p.drawPath(path)
end = QPointF(r * math.cos(math.radians(30)), -r * math.sin(math.radians(30)))
t = QPointF(math.cos(math.radians(-60)), -math.sin(math.radians(-60)))
n = QPointF(-t.y(), t.x())
p.setPen(Qt.PenStyle.NoPen)
p.setBrush(QColor("#c62828"))
p.drawPolygon(QPolygonF([end + t * 26, end + n * 20 - t * 4, end - n * 20 - t * 4]))
p.end()
img.save(sys.argv[1])
