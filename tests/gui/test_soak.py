"""A soak test for the Qt binding: thousands of void Qt calls and of pyqtgraph repaints.

PySide6 6.12.0 on Python < 3.12 loses one reference to None per void Qt call and kills the
process (``none_dealloc``) after a few hundred redraws (shared/reference/qt-stack-notes.md).
Short GUI tests pass on it; these do not. What the tests count can grow on every Python: the
references to the (mortal) objects handed to Qt, the objects the garbage collector tracks, the
scene's items and the process's resident memory; the references to None only where None is
mortal (Python < 3.12; from 3.12 on its count is a constant and proves nothing). A *gain* of
references to None (seen with 6.11.3: about 6 per setData+repaint) is harmless, since it can
only keep None alive; a loss is fatal.
"""

from __future__ import annotations

import gc
import resource
import sys
from pathlib import Path

import numpy as np
import pyqtgraph as pg
from PySide6.QtGui import QColor, QImage, QPainter, QPen

REPAINTS = 2000
WARM_UP = 200  # repaints before counting: the first ones fill pyqtgraph's caches
#: Objects the collector may gain over REPAINTS repaints (measured: under 60 per 1000): one
#: leaked object per ten repaints fails.
OBJECTS_GAINED_MAX = REPAINTS // 10
#: Resident memory the process may gain over REPAINTS repaints (measured: under 0.1 MB); a
#: leaked 400 x 300 picture per repaint (480 kB) or 8 kB per repaint fails.
RESIDENT_GAINED_MAX_BYTES = 16_000_000


def none_is_mortal() -> bool:
    """Whether references to None are counted (Python < 3.12): 1000 more must show."""
    before = sys.getrefcount(None)
    more = [None] * 1000
    counted = sys.getrefcount(None) - before >= len(more)
    del more
    return counted


def resident_bytes() -> int:
    """The process's resident memory now (Linux), or its peak where /proc is absent."""
    statm = Path("/proc/self/statm")
    if statm.exists():
        return int(statm.read_text().split()[1]) * resource.getpagesize()
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak if sys.platform == "darwin" else peak * 1024


def tracked_objects() -> int:
    gc.collect()
    return len(gc.get_objects())


def test_void_qt_calls_keep_the_references_they_are_given():
    image = QImage(16, 16, QImage.Format.Format_ARGB32)
    painter = QPainter(image)
    pen = QPen(QColor("red"))
    objects = tracked_objects()  # first: the collection frees garbage that holds None
    pen_refs, none_refs = sys.getrefcount(pen), sys.getrefcount(None)
    for _ in range(1000):
        painter.setPen(pen)
        painter.drawLine(0, 0, 15, 15)
    pen_change = sys.getrefcount(pen) - pen_refs
    none_lost = none_refs - sys.getrefcount(None)
    objects_gained = tracked_objects() - objects
    painter.end()
    assert pen_change == 0, f"the pen handed to Qt 1000 times changed by {pen_change} references"
    assert objects_gained < 100, f"1000 void Qt calls left {objects_gained} more objects"
    if none_is_mortal():
        assert none_lost < 100, f"None lost {none_lost} references in 1000 void Qt calls: a broken PySide6"


def test_thousands_of_plot_repaints_leave_nothing_behind(qtbot):
    widget = pg.PlotWidget()
    qtbot.addWidget(widget)
    widget.resize(400, 300)
    curve = widget.plot(pen="y")
    x = np.linspace(0.0, 1.0, 500)

    def repaint(times: int, offset: int):
        image = None
        for i in range(offset, offset + times):
            curve.setData(x, np.sin(2 * np.pi * (x + i / 100.0)))
            image = widget.grab()
        return image

    repaint(WARM_UP, 0)
    items = len(widget.scene().items())
    objects = tracked_objects()  # first: the collection frees garbage that holds None
    none_refs, resident = sys.getrefcount(None), resident_bytes()
    image = repaint(REPAINTS, WARM_UP)
    none_lost = none_refs - sys.getrefcount(None)
    objects_gained = tracked_objects() - objects
    resident_gained = resident_bytes() - resident
    assert image is not None and not image.isNull()
    assert len(widget.scene().items()) == items, "repaints added items to the plot's scene"
    assert objects_gained < OBJECTS_GAINED_MAX, f"{REPAINTS} repaints left {objects_gained} more objects"
    assert resident_gained < RESIDENT_GAINED_MAX_BYTES, (
        f"{REPAINTS} repaints grew the process by {resident_gained / 1e6:.1f} MB"
    )
    if none_is_mortal():
        assert none_lost < REPAINTS // 4, f"None lost {none_lost} references in {REPAINTS} repaints"
