"""`fha-studio` without a command: the main window, connected to the embedded simulated drive."""

from __future__ import annotations

import argparse
import logging
import sys
import time
from collections.abc import Sequence
from typing import Any, NoReturn

from fha_studio.gui.pages.base import PageId
from fha_studio.gui.session import DEFAULT_SIM_URL
from fha_studio.hardware.protocol import BAUD_RATES, BAUDRATE

ORGANISATION = "FHA Studio"
APPLICATION = "fha-studio"
#: Python's GIL switch interval in the GUI process [s] (Python's default: 0.005). The link thread
#: wakes for every few characters of a reply and must get the GIL at once; with 5 ms a GUI thread
#: busy in Python (a frame being drawn) keeps it waiting up to 5 ms each time, line time lost for
#: every polled sample (a 1-item sample takes 7 ms on the line). 0.5 ms bounds that wait; the
#: extra switches cost nothing measurable (benchmarks/scope_throughput.py).
GIL_SWITCH_INTERVAL_S = 0.0005


class _OneLineParser(argparse.ArgumentParser):
    """A refusal is one line saying what is allowed, exit status 2 (as the CLI's); options only
    as written (no prefix matching, as the CLI's)."""

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see fha-studio gui --help)\n")


def _url(text: str) -> str:
    from fha_studio.hardware.transport import check_url

    try:
        check_url(text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def _baud(text: str) -> int:
    if not text.strip().isascii() or not text.strip().isdigit() or int(text) not in BAUD_RATES:
        raise argparse.ArgumentTypeError(
            f"{text[:20]} is not a baud rate; one of {', '.join(map(str, BAUD_RATES))}"
        )
    return int(text)


def _parser() -> argparse.ArgumentParser:
    parser = _OneLineParser(prog="fha-studio [gui]", description="FHA Studio, the commissioning GUI")
    parser.add_argument(
        "--url",
        default=None,
        type=_url,
        help=f"drive to connect to at start (default: the embedded simulated drive, {DEFAULT_SIM_URL}, "
        "with the catalogue's friction and the declared load inertia); a serial device, a pty path or "
        "socket://host:port",
    )
    parser.add_argument(
        "--baud",
        type=_baud,
        default=BAUDRATE,
        help=f"baud rate of a serial link (default {BAUDRATE}, CN3's; one of "
        f"{', '.join(map(str, BAUD_RATES))})",
    )
    parser.add_argument("--no-connect", action="store_true", help="start without connecting")
    parser.add_argument(
        "--page",
        default=None,
        choices=[page.value for page in PageId],
        metavar="PAGE",
        help=f"page to show first: {', '.join(PageId)}",
    )
    parser.add_argument(
        "--machine",
        metavar="NAME",
        help="open the machine NAME of the register: its axes beside the pages, each connected to its "
        "port; with --axis, the single-axis window records under that machine",
    )
    parser.add_argument(
        "--axis",
        metavar="NAME",
        help="the single-axis window records what it learns in the register under this axis (of "
        "--machine, else of this computer's bench); without it, under an axis named after the "
        "actuator or the connection (the toolbar's Register line names and changes it)",
    )
    parser.add_argument(
        "--machine-file",
        metavar="FILE",
        help="open a machine project file (fha-machine/1) and put it in the register",
    )
    parser.add_argument(
        "--register",
        metavar="FILE_OR_URL",
        help="the register: a file, or postgresql://USER:PASSWORD@HOST/DB for a plant's register on a "
        "server (default: $FHA_STUDIO_REGISTER, else register.sqlite in the user data directory), as "
        "for fha-studio register",
    )
    parser.add_argument(
        "--training",
        metavar="SCENARIO",
        help="start a training scenario (an id of fha-studio training list, or a .toml file)",
    )
    parser.add_argument("--quit-after-ms", type=int, default=None, help=argparse.SUPPRESS)
    return parser


def _machine_window(args):
    """The machine window for --machine / --machine-file, or None; SystemExit(2) with one line
    when the machine or the register cannot be opened."""
    if args.axis is not None:
        if args.machine_file:
            print("fha-studio: --axis names the single-axis window's axis; a machine file opens the "
                  "machine window, whose axes are named by the file", file=sys.stderr)
            raise SystemExit(2)
        return None
    if not (args.machine or args.machine_file):
        return None
    from fha_studio.gui.machine_window import MachineWindow
    from fha_studio.logic.machine import MachineError, MachineProject
    from fha_studio.logic.register import Register, RegisterError, register_location
    from fha_studio.logic.register.server import is_server_url

    location = register_location(args.register)
    if is_server_url(location):
        return _machine_window_on_server(args, str(location))
    try:
        # a machine file is read (and refused) before the register is opened: a refused file
        # leaves no new register behind; it is put into the register (made when missing), while
        # a machine by name must be there
        project = MachineProject.load(args.machine_file) if args.machine_file else None
        register = Register(location, create=bool(args.machine_file))
        try:
            if project is None:
                project = MachineProject.from_register(register, args.machine)
        except (MachineError, RegisterError, ValueError):
            register.close()
            raise
    except (MachineError, RegisterError, ValueError) as exc:
        print(f"fha-studio: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    if not len(project):
        register.close()
        print(
            f"fha-studio: machine '{project.name}' has no axes (fha-studio register add-axis ...)",
            file=sys.stderr,
        )
        raise SystemExit(2)
    return MachineWindow(project, register)


def _machine_window_on_server(args, url: str):
    """The machine window on a plant's register on a server, shown at once whether the server
    answers or not (a laptop on a shop floor without the plant's network): the machine of a file,
    or the one named as this computer's queue for the server knows it (perhaps no axis yet), whose
    axes the window asks the server for from a thread of its own. SystemExit(2) with one line for a
    machine file or a name that is refused."""
    from fha_studio.gui.machine_window import MachineWindow
    from fha_studio.gui.register_worker import machine_known_here
    from fha_studio.logic.machine import MachineError, MachineProject

    try:
        if args.machine_file:
            project = MachineProject.load(args.machine_file)
        else:
            project = machine_known_here(url, args.machine) or MachineProject(args.machine)
    except (MachineError, ValueError) as exc:
        print(f"fha-studio: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    return MachineWindow(project, server_url=url, ask_for_axes=not args.machine_file)


def single_axis_window(args: argparse.Namespace):
    """The single-axis window, recording into the register (``--register``) under ``--machine`` /
    ``--axis`` or the default names; SystemExit(2) with one line for a name the register refuses."""
    from fha_studio.gui.main_window import MainWindow
    from fha_studio.gui.window_register import WindowRegister
    from fha_studio.logic.register.window_axis import check_names
    from fha_studio.names import NameProblem

    try:
        machine, axis = check_names(args.machine or "", args.axis or "")
    except NameProblem as exc:
        print(f"fha-studio: {exc}", file=sys.stderr)
        raise SystemExit(2) from None
    window = MainWindow()
    WindowRegister(window, args.register, machine, axis)
    return window


def parse_arguments(argv: Sequence[str]) -> argparse.Namespace:
    """The GUI's options (SystemExit(2) with one line for a refused one)."""
    return _parser().parse_args(list(argv))


def make_application(argv: Sequence[str] = ()):
    """The QApplication (created once), with the names QSettings uses, in a process whose GIL
    switches fast enough for the link thread (``GIL_SWITCH_INTERVAL_S``)."""
    from PySide6.QtWidgets import QApplication

    sys.setswitchinterval(GIL_SWITCH_INTERVAL_S)
    existing = QApplication.instance()
    app = (
        existing
        if isinstance(existing, QApplication)
        else QApplication([sys.argv[0] if sys.argv else "fha-studio", *argv])
    )
    if not app.organizationName() or app.organizationName() == "":
        app.setOrganizationName(ORGANISATION)
        app.setApplicationName(APPLICATION)
    app.setApplicationDisplayName("FHA Studio")
    return app


def run(argv: Sequence[str] = ()) -> int:
    """Starts the GUI; returns the exit code."""
    started = time.perf_counter()
    args = parse_arguments(argv)
    logging.basicConfig(level=logging.WARNING, format="%(levelname)s %(name)s: %(message)s")
    scenario = None
    if args.training:
        from fha_studio.logic.training.scenario import ScenarioError, find_scenario

        try:
            scenario = find_scenario(args.training)
        except ScenarioError as exc:
            print(f"fha-studio: {exc}", file=sys.stderr)
            return 2
    app = make_application()
    from PySide6.QtCore import QCoreApplication, QEvent, QTimer
    from PySide6.QtGui import QIcon

    from fha_studio.paths import resources_dir

    icon = resources_dir() / "icons" / "fha-studio.png"
    if icon.exists():
        app.setWindowIcon(QIcon(str(icon)))
    machine = _machine_window(args)
    if machine is not None:
        window = machine
        if args.page:
            for axis_window in machine.axis_windows:
                axis_window.show_page(args.page)
        window.show()
        if not args.no_connect:
            machine.connect_all()
    else:
        window = single_axis_window(args)
        if args.page:
            window.show_page(args.page)
        window.show()
        if scenario is not None:
            window.training.start(scenario)
        elif not args.no_connect:
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
    if machine is not None and machine.register is not None:
        machine.register.close()
    # the window goes while the QApplication is still there: left to the interpreter's exit the
    # order is arbitrary, and Qt can crash there after a clean close
    window.deleteLater()
    QCoreApplication.sendPostedEvents(None, QEvent.Type.DeferredDelete.value)
    del window
    return int(code)
