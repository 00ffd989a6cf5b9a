"""``fha-studio gui``: listed here so that ``--help`` shows it; the entry point (fha_studio.main)
starts the GUI itself, because the CLI never imports Qt. Its options are the GUI's own parser's
(fha_studio.gui.app), which ``fha-studio gui --help`` shows: none are repeated here, where nothing
would read them."""

from __future__ import annotations

from typing import Any

from fha_studio.cli import CliError

ORDER = 0


def register(subparsers: Any) -> None:
    p = subparsers.add_parser(
        "gui",
        help="the commissioning GUI (also without a command, e.g. fha-studio --url /dev/ttyUSB0)",
        description="Start the GUI. Its options (--url, --baud, --page, --machine, ...): "
        "fha-studio gui --help.",
    )
    p.set_defaults(func=run)


def run(args: Any) -> int:
    raise CliError("the GUI is started by the fha-studio command itself (fha-studio gui ...)")
