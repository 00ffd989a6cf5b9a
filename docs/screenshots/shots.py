"""What the screenshot scripts share: settings and data in a temporary folder (never the user's,
removed when the script ends, also when it fails), the application and the main window as
fha-studio makes them, waiting with a deadline, and the grab that saves a PNG into the output
folder (the first argument, else docs/screenshots).

A script imports this first, before anything of Qt or fha_studio (its own folder is on the path
when it runs as ``python docs/screenshots/take_X.py``)::

    from shots import ScreenshotRun, private_folder

    TMP = private_folder()
    ...
    run = ScreenshotRun((1366, 740))
    run.window.connect_to(URL)
    run.wait_until(lambda: run.window.link.status is not None, "the drive's first status")
    run.shot("connection")
    run.close()

``FHA_SHOT_WIDTH`` and ``FHA_SHOT_HEIGHT`` take every picture at another window size (1280 x 720:
does the page still fit?) without changing a script.
"""

from __future__ import annotations

import atexit
import json
import os
import shutil
import signal
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

#: What every screenshot script's temporary folder is called (and what the sweep looks for).
FOLDER_PREFIX = "fha-shots-"
#: The note in a folder that says which process owns it.
OWNER_NOTE = "owner.json"
#: A folder without an owner's note (left by a script before the note existed) is removed once
#: nobody has touched it for this long.
UNOWNED_STALE_S = 3600.0
#: Where the pictures show the run's files: a technician's home, not the temporary folder the
#: script really uses (a reader would take ``/tmp/fha-shots-x1y2/...`` for where FHA Studio puts
#: them). Only the picture changes: the widgets get their own text back after the grab.
SHOWN_HOME = "/home/technician"
#: The run's temporary folder (private_folder's), once made.
_folder = ""


def private_folder() -> str:
    """A new temporary folder holding the run's settings (XDG_CONFIG_HOME) and data
    (XDG_DATA_HOME), set before Qt reads them (and the register named by the environment left
    out). It is removed when the script ends, whether it succeeds or fails (an exception, exit,
    SIGTERM, SIGHUP); one that a killed script left is removed by the next script's start."""
    from fha_studio.temporaries import started_ticks

    sweep_left_folders()
    global _folder
    folder = _folder = tempfile.mkdtemp(prefix=FOLDER_PREFIX)
    pid = os.getpid()
    Path(folder, OWNER_NOTE).write_text(json.dumps({"pid": pid, "pid_started_ticks": started_ticks(pid)}))
    atexit.register(shutil.rmtree, folder, True)
    for number in (signal.SIGTERM, signal.SIGHUP):
        if signal.getsignal(number) is signal.SIG_DFL:  # end through SystemExit: atexit runs
            signal.signal(number, _exit_on_signal)
    os.environ["XDG_CONFIG_HOME"] = f"{folder}/config"
    os.environ["XDG_DATA_HOME"] = f"{folder}/data"
    os.environ.pop("FHA_STUDIO_REGISTER", None)
    return folder


def users_sim_drive(actuator_code: str, load_inertia_kgm2: float = 0.0, documented: bool = False,
                    **options: str) -> str:
    """The simulated drive a person gets from the Connect dialog as it is first shown (its
    defaults, the catalogue's friction among them: ``connect_dialog.sim_url``), for
    ``actuator_code``, with ``options`` added (``paced="0"``: the pictures need no 19200 baud
    pacing). Call it after :func:`private_folder` (it imports FHA Studio)."""
    from fha_studio.gui.connect_dialog import sim_url

    return sim_url(actuator_code, load_inertia_kgm2, documented=documented, **options)


def _exit_on_signal(number: int, _frame: Any) -> None:
    raise SystemExit(128 + number)


def sweep_left_folders(base: str | None = None) -> list[Path]:
    """Removes the screenshot folders in ``base`` (the temporary directory) whose owner is no
    longer running (a script killed with SIGKILL, or a machine that went down), and those
    without an owner's note untouched for :data:`UNOWNED_STALE_S`; returns what it removed."""
    from fha_studio import clock
    from fha_studio.temporaries import process_alive

    removed = []
    for folder in Path(base or tempfile.gettempdir()).glob(f"{FOLDER_PREFIX}*"):
        try:
            if not folder.is_dir() or folder.is_symlink():
                continue
            try:
                owner = json.loads(folder.joinpath(OWNER_NOTE).read_text())
                alive = process_alive(int(owner["pid"]), owner.get("pid_started_ticks"))
            except FileNotFoundError:
                alive = clock.now_s() - folder.stat().st_mtime < UNOWNED_STALE_S
            except (OSError, ValueError, TypeError, KeyError):
                alive = True  # a note being written, or not ours to judge: left alone
            if not alive:
                shutil.rmtree(folder, ignore_errors=True)
                removed.append(folder)
        except OSError:
            continue
    return removed


def shown_paths(text: str, folder: str | None = None) -> str:
    """``text`` with the run's temporary ``folder`` (private_folder's) as :data:`SHOWN_HOME`'s
    folders: its data and settings where the user's are, the rest in ``commissioning``."""
    folder = _folder if folder is None else folder
    if not folder or folder not in text:
        return text
    home = SHOWN_HOME
    qt_data = f"{folder}/data/FHA Studio Screenshots/fha-studio-screenshots"  # Qt's, by the run's name
    for real, shown in (
        (qt_data, f"{home}/.local/share/FHA Studio/fha-studio"),
        (f"{folder}/data", f"{home}/.local/share"),
        (f"{folder}/config", f"{home}/.config"),
        (folder, f"{home}/commissioning"),
    ):
        text = text.replace(real, shown)
    return text


def reports_show_plausible_paths() -> None:
    """The commissioning reports this run writes name their parameter file as :func:`shown_paths`
    does (a report is a PDF made into pictures: no widget text to change at the grab). The file
    itself is written where it is."""
    from fha_studio.logic.procedures import report_inputs

    collect = report_inputs._parameters

    def shown(session: Any, inputs: Any) -> dict[str, object]:
        parameters = collect(session, inputs)
        parameters["file"] = shown_paths(str(parameters["file"]))
        return parameters

    report_inputs._parameters = shown


def _paths_shown_plausibly(widget: Any) -> Callable[[], None]:
    """Shows the run's folder as :func:`shown_paths` does in the texts of ``widget`` and its
    children (labels, fields, buttons, text views) without a signal; returns what
    puts the texts back."""
    from PySide6.QtWidgets import (
        QAbstractButton,
        QLabel,
        QLineEdit,
        QPlainTextEdit,
        QTextEdit,
        QWidget,
    )

    undo: list[Callable[[], None]] = []

    def change(obj: Any, get: Callable[[], str], put: Callable[[str], None]) -> None:
        text = get()
        shown = shown_paths(text)
        if shown != text:
            blocked = obj.blockSignals(True)
            put(shown)
            obj.blockSignals(blocked)

            def back(obj: Any = obj, put: Callable[[str], None] = put, text: str = text) -> None:
                blocked = obj.blockSignals(True)
                put(text)
                obj.blockSignals(blocked)

            undo.append(back)

    for w in [widget, *widget.findChildren(QWidget)]:
        if isinstance(w, QLabel | QLineEdit | QAbstractButton):
            change(w, w.text, w.setText)
        elif isinstance(w, QPlainTextEdit):
            change(w, w.toPlainText, w.setPlainText)
        elif isinstance(w, QTextEdit):
            change(w, w.toHtml, w.setHtml)
    def put_back() -> None:
        for back in reversed(undo):
            back()

    return put_back


def window_size(default: tuple[int, int]) -> tuple[int, int]:
    """``default``, or FHA_SHOT_WIDTH x FHA_SHOT_HEIGHT where they are set."""
    width, height = default
    return int(os.environ.get("FHA_SHOT_WIDTH", width)), int(os.environ.get("FHA_SHOT_HEIGHT", height))


class ScreenshotRun:
    """The application and a shown window of ``size`` (width, height; see :func:`window_size`):
    fha-studio's single-axis window unless ``make_window`` (called once the application is
    there) makes another."""

    def __init__(self, size: tuple[int, int], *, settle_before_shot_s: float = 0.3,
                 make_window: Callable[[], Any] | None = None):
        from PySide6.QtCore import QCoreApplication
        from PySide6.QtWidgets import QApplication

        self.app = QApplication(sys.argv[:1])
        QCoreApplication.setOrganizationName("FHA Studio Screenshots")
        QCoreApplication.setApplicationName("fha-studio-screenshots")
        if make_window is None:
            from fha_studio.gui.app import parse_arguments, single_axis_window

            make_window = lambda: single_axis_window(parse_arguments(["--no-connect"]))  # noqa: E731
        self.window = make_window()
        self.window.resize(*window_size(size))
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

    def wait_signal(self, signal: Any, what: str, timeout_s: float = 30.0) -> tuple[Any, ...]:
        """Runs the event loop until ``signal`` is emitted; its arguments (TimeoutError as
        :meth:`wait_until`)."""
        got: list[tuple[Any, ...]] = []
        signal.connect(lambda *args: got.append(args))
        self.wait_until(lambda: got, what, timeout_s)
        return got[0]

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
        OUT.mkdir(parents=True, exist_ok=True)
        path = OUT / f"{name}.png"
        widget = widget or self.window
        put_back = _paths_shown_plausibly(widget)
        try:
            self.app.processEvents()
            widget.grab().save(str(path))
        finally:
            put_back()
        print("saved", path)
        return path

    def panel(self, action: str, value: Any, timeout_s: float = 30.0) -> None:
        """The simulated drive's panel (the controller's inputs, the technician's hands): waits
        until the link thread has done it."""
        from fha_studio.gui.link import SimPanelAction, SimPanelRequest

        done: list[Any] = []
        self.window.link.send(SimPanelRequest(SimPanelAction(action), value), done.append)
        self.wait_until(lambda: done, f"the drive panel's {action}", timeout_s)

    def sim_drive(self) -> Any:
        """The embedded simulated drive behind the window's link (to raise an alarm)."""
        return self.window.link._worker._client.transaction.transport.inner.sim_drive

    def close(self) -> None:
        """Closes the window without asking and ends its link(s), if it has any (a dialog)."""
        self.window._closing_confirmed = True
        self.window.close()
        shutdown = getattr(self.window, "shutdown", None)
        if shutdown is not None:
            shutdown()
