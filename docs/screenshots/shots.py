"""What the screenshot scripts share: settings and data in a temporary folder (never the user's),
the application and the main window as fha-studio makes them, waiting with a deadline, and the
grab that saves a PNG into the output folder (the first argument, else docs/screenshots).

A script imports this first, before anything of Qt or fha_studio (its own folder is on the path
when it runs as ``python docs/screenshots/take_X.py``)::

    from shots import ScreenshotRun, private_folder

    TMP = private_folder("fha-shots-")
    ...
    run = ScreenshotRun((1366, 768))
    run.window.connect_to(URL)
    run.wait_until(lambda: run.window.link.status is not None, "the drive's first status")
    run.shot("connection")
    run.close()
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
OUT = Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "screenshots"


def private_folder(prefix: str) -> str:
    """A new temporary folder holding the run's settings (XDG_CONFIG_HOME) and data
    (XDG_DATA_HOME), set before Qt reads them."""
    folder = tempfile.mkdtemp(prefix=prefix)
    os.environ["XDG_CONFIG_HOME"] = f"{folder}/config"
    os.environ["XDG_DATA_HOME"] = f"{folder}/data"
    return folder


class ScreenshotRun:
    """The application and a shown main window of ``size`` (width, height)."""

    def __init__(self, size: tuple[int, int], *, settle_before_shot_s: float = 0.3):
        from PySide6.QtCore import QCoreApplication
        from PySide6.QtWidgets import QApplication

        self.app = QApplication(sys.argv[:1])
        QCoreApplication.setOrganizationName("FHA Studio Screenshots")
        QCoreApplication.setApplicationName("fha-studio-screenshots")
        from fha_studio.gui.main_window import MainWindow

        self.window = MainWindow()
        self.window.resize(*size)
        self.window.show()
        self.settle_before_shot_s = settle_before_shot_s

    def wait_until(self, condition: Callable[[], Any], what: str = "a step", timeout_s: float = 30.0) -> None:
        """Runs the event loop until ``condition()``; TimeoutError naming ``what`` after ``timeout_s``."""
        end = time.monotonic() + timeout_s
        while not condition():
            if time.monotonic() > end:
                raise TimeoutError(f"screenshot script: {what} did not come within {timeout_s:g} s")
            self.app.processEvents()
            time.sleep(0.01)

    def settle(self, seconds: float = 0.3) -> None:
        """Runs the event loop for ``seconds`` (what was asked for is drawn)."""
        end = time.monotonic() + seconds
        self.app.processEvents()
        while time.monotonic() < end:
            time.sleep(0.01)
            self.app.processEvents()

    def shot(self, name: str, widget: Any = None) -> Path:
        """Saves ``widget`` (the main window unless given) as ``OUT/name.png``."""
        self.settle(self.settle_before_shot_s)
        path = OUT / f"{name}.png"
        (widget or self.window).grab().save(str(path))
        print("saved", path)
        return path

    def panel(self, action: str, value: Any, timeout_s: float = 30.0) -> None:
        """The simulated drive's panel (the controller's inputs, the technician's hands): waits
        until the link thread has done it."""
        from fha_studio.gui.link import SimPanelAction, SimPanelRequest

        done: list[Any] = []
        self.window.link.send(SimPanelRequest(SimPanelAction(action), value), done.append)
        self.wait_until(lambda: done, f"the drive panel's {action}", timeout_s)

    def close(self) -> None:
        """Closes the window without asking and ends its link."""
        self.window._closing_confirmed = True
        self.window.close()
        self.window.shutdown()
