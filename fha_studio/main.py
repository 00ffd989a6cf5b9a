"""The ``fha-studio`` entry point: the GUI when called without a command, else the CLI.

It sits above both so that the CLI never imports Qt and the GUI is imported only when asked for.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence


def main(argv: Sequence[str] | None = None) -> int:
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] == "gui":
        try:
            from fha_studio.gui.app import run
        except ImportError as exc:  # the GUI package is not there yet, or Qt is missing
            print(f"fha-studio: the GUI cannot start: {exc}", file=sys.stderr)
            return 1
        return run(args[1:])
    from fha_studio.cli import main as cli_main

    return cli_main(args)
