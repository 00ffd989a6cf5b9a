"""A soak test for the Qt binding: thousands of repaints of a pyqtgraph plot.

PySide6 6.12.0 on Python < 3.12 loses one reference to None per void Qt call and kills the
process (``none_dealloc``) after a few hundred redraws (shared/reference/qt-stack-notes.md).
Short GUI tests pass on it; these do not. A *gain* of references to None (seen with 6.11.3:
about 6 per setData+repaint) is harmless, since it can only keep None alive; a loss is fatal.
"""

from __future__ import annotations

import sys

import numpy as np
import pyqtgraph as pg
from PySide6.QtGui import QColor, QImage, QPainter, QPen

REPAINTS = 2000


def test_void_qt_calls_do_not_lose_references_to_none():
    image = QImage(16, 16, QImage.Format.Format_ARGB32)
    painter = QPainter(image)
    pen = QPen(QColor("red"))
    before = sys.getrefcount(None)
    for _ in range(1000):
        painter.setPen(pen)
        painter.drawLine(0, 0, 15, 15)
    lost = before - sys.getrefcount(None)
    painter.end()
    assert lost < 100, f"None lost {lost} references in 1000 void Qt calls: a broken PySide6 build"


def test_none_survives_thousands_of_plot_repaints(qtbot):
    widget = pg.PlotWidget()
    qtbot.addWidget(widget)
    widget.resize(400, 300)
    curve = widget.plot(pen="y")
    x = np.linspace(0.0, 1.0, 500)
    widget.grab()  # the first paint allocates caches
    before = sys.getrefcount(None)
    for i in range(REPAINTS):
        curve.setData(x, np.sin(2 * np.pi * (x + i / 100.0)))
        image = widget.grab()
    lost = before - sys.getrefcount(None)
    assert not image.isNull()
    assert lost < REPAINTS // 4, f"None lost {lost} references in {REPAINTS} repaints"
