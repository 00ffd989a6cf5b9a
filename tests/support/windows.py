"""Window teardown for the GUI tests (imports Qt: only tests/gui takes it).

``torn_down(links)`` is the one teardown of the window factories (``make_window`` of
tests/gui/conftest.py, ``make_machine`` of test_machine_window.py): a window is closed without
asking, its link threads must have ended, it is deleted, and no top-level widget made during the
test may be left open (a leak fails the test naming the widgets' types).
"""

from __future__ import annotations

import gc
import sys
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

from PySide6.QtCore import QCoreApplication
from PySide6.QtWidgets import QApplication, QWidget


@contextmanager
def torn_down(links: Callable[[QWidget], Iterable[object]]) -> Iterator[list[QWidget]]:
    """The windows a factory puts in the list it is given, torn down when the block ends;
    ``links(window)`` names each window's LinkControllers (their threads must have ended)."""
    app = QApplication.instance()
    assert isinstance(app, QApplication)
    before = set(app.topLevelWidgets())
    windows: list[QWidget] = []
    try:
        yield windows
    finally:
        # also when the block failed (a test's own ``with``): its threads end all the same, and
        # only the failure is reported
        failed = sys.exc_info()[0] is not None
        running = []
        for window in windows:
            window._closing_confirmed = True  # no "the servo is on: close?" question
            window.shutdown()
            running += [link for link in links(window) if link._thread.isRunning()]
            window.close()
            window.deleteLater()
        QApplication.processEvents()
        QCoreApplication.sendPostedEvents(None, 0)  # every posted event, DeferredDelete among them
        QApplication.processEvents()
        gc.collect()
        leaked = [w for w in app.topLevelWidgets() if w not in before and w.isVisible()]
        for w in leaked:
            w.close()
        if not failed:
            assert not running, "a link thread is still running"
            assert not leaked, f"top-level widgets left open: {[type(w).__name__ for w in leaked]}"
