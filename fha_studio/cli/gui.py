"""``fha-studio gui``: listed here so that ``--help`` shows it; the entry point (fha_studio.main)
starts the GUI itself, because the CLI never imports Qt."""

from __future__ import annotations

from typing import Any

from fha_studio.cli import CliError

ORDER = 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "gui",
        help="the commissioning GUI (also without a command, e.g. fha-studio --url /dev/ttyUSB0)",
        description="Start the GUI. Without --url it connects to the embedded simulated drive.",
    )
    p.add_argument("--url", help="drive to connect to at start: a serial device, a pty path, "
                   "socket://host:port or sim://ACTUATOR-CODE?...")
    p.add_argument("--baud", type=int, help="baud rate of a serial link (default 19200; 1200 ... 115200)")
    p.add_argument("--no-connect", action="store_true", help="start without connecting")
    p.add_argument("--page", help="page to show first")
    p.set_defaults(func=run)


def run(args: Any) -> int:
    raise CliError("the GUI is started by the fha-studio command itself (fha-studio gui ...)")
