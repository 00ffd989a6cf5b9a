"""`fha-studio` without a command: the main window, connected to the embedded simulated drive."""

from __future__ import annotations

import argparse
import logging
import sys
import time
from collections.abc import Sequence

from fha_studio.gui.session import DEFAULT_SIM_URL

ORGANISATION = "FHA Studio"
APPLICATION = "fha-studio"


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="fha-studio [gui]", description="FHA Studio, the commissioning GUI")
    parser.add_argument(
        "--url",
        default=DEFAULT_SIM_URL,
        help=f"drive to connect to at start (default: the embedded simulated drive, {DEFAULT_SIM_URL}); "
        "a serial device, a pty path or socket://host:port",
    )
    parser.add_argument("--baud", type=int, default=19200, help="baud rate of a serial link (default 19200)")
    parser.add_argument("--no-connect", action="store_true", help="start without connecting")
    parser.add_argument(
        "--page",
        default=None,
        help="page to show first (connection, parameters, direction, alarms, jog, sizing)",
    )
    parser.add_argument("--quit-after-ms", type=int, default=None, help=argparse.SUPPRESS)
    return parser


def make_application(argv: Sequence[str] = ()):
    """The QApplication (created once), with the names QSettings uses."""
    from PySide6.QtWidgets import QApplication

    app = QApplication.instance()
    if app is None:
        app = QApplication([sys.argv[0] if sys.argv else "fha-studio", *argv])
    if not app.organizationName() or app.organizationName() == "":
        app.setOrganizationName(ORGANISATION)
        app.setApplicationName(APPLICATION)
    app.setApplicationDisplayName("FHA Studio")
    return app


def run(argv: Sequence[str] = ()) -> int:
    """Starts the GUI; returns the exit code."""
    started = time.perf_counter()
    args = _parser().parse_args(list(argv))
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    app = make_application()
    from PySide6.QtCore import QTimer
    from PySide6.QtGui import QIcon

    from fha_studio.gui.main_window import MainWindow
    from fha_studio.paths import resources_dir

    icon = resources_dir() / "icons" / "fha-studio.png"
    if icon.exists():
        app.setWindowIcon(QIcon(str(icon)))
    window = MainWindow()
    if args.page:
        window.show_page(args.page)
    window.show()
    if not args.no_connect:
        window.connect_to(args.url, args.baud)
    QTimer.singleShot(
        0,
        lambda: logging.getLogger(__name__).info(
            "usable window after %.0f ms", (time.perf_counter() - started) * 1000
        ),
    )
    if args.quit_after_ms is not None:
        QTimer.singleShot(args.quit_after_ms, window.close)
    code = app.exec()
    window.shutdown()
    return int(code)
