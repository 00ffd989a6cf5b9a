"""The ``fha-studio`` entry point: the GUI when called without a command, else the CLI.

It sits above both so that the CLI never imports Qt and the GUI is imported only when asked for.
``fha-studio --url URL`` (options but no command) starts the GUI too, as does ``fha-studio gui ...``.
Either start first removes the temporary files that writes killed in an earlier run left
(:mod:`fha_studio.temporaries`).
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

_HELP = ("-h", "--help")


def _wants_gui(args: list[str]) -> bool:
    """No command, ``gui``, or GUI options without a command (``--url URL``)."""
    if not args or args[0] == "gui":
        return True
    return args[0].startswith("-") and args[0] not in _HELP


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    from fha_studio import temporaries

    temporaries.sweep()  # what writes killed in an earlier run left (a living writer's stays)
    if args[:2] == ["training", "start"] and len(args) == 3 and args[2] not in _HELP:
        args = ["gui", "--training", args[2]]  # a trainee's session is the GUI's
    if _wants_gui(args):
        try:
            from fha_studio.gui.app import run
        except ImportError as exc:  # the GUI package is not there yet, or Qt is missing
            print(f"fha-studio: the GUI cannot start: {exc}", file=sys.stderr)
            return 1
        return run(args[1:] if args and args[0] == "gui" else args)
    from fha_studio.cli import main as cli_main

    return cli_main(args)
