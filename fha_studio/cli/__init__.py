"""The command line: ``fha-studio COMMAND ...``. No Qt is imported here.

Each command is a module in this package (found automatically) with ``register(subparsers)``
that adds its sub-parser and sets ``func`` (a callable taking the parsed args, returning an exit
code), and ``ORDER`` (an int: where --help lists it).
Errors meant for the user are raised as :class:`CliError` and printed as one line.
"""

from __future__ import annotations

import argparse
import importlib
import os
import pkgutil
import sys
from collections.abc import Sequence
from typing import Any, NoReturn

from fha_studio.fileio import FileProblem, os_reason
from fha_studio.names import printable


class CliError(Exception):
    """A mistake in the user's input: printed as one line, exit status 2."""


class OneLineParser(argparse.ArgumentParser):
    """An argument parser whose refusal is one line (what, and what is allowed), exit status 2.

    Options are taken only as written: argparse's prefix matching (``--model`` taken as
    ``--model-out``) would let a mistyped flag overwrite a file, so it is off (``allow_abbrev``).
    """

    def __init__(self, *args: Any, **kwargs: Any) -> None:
        kwargs["allow_abbrev"] = False
        super().__init__(*args, **kwargs)

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {one_line(message)} (see {self.prog} --help)\n")


def one_line(message: str, limit: int = 1000) -> str:
    """A refusal as one readable line: what the user typed may hold line breaks or terminal
    escape sequences (escaped here), and may be long (cut)."""
    text = "".join(c if printable(c) else c.encode("unicode_escape").decode("ascii") for c in message)
    return text if len(text) <= limit else text[: limit - 1] + "…"


def build_parser() -> argparse.ArgumentParser:
    parser = OneLineParser(
        prog="fha-studio",
        description="Commissioning tool for Harmonic Drive FHA-C actuators on HA-655 / HA-675 drivers. "
        "Without a command it starts the GUI on the embedded simulated drive.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=OneLineParser)
    modules = [
        importlib.import_module(f"{__name__}.{info.name}")
        for info in pkgutil.iter_modules(__path__)
        if not info.name.startswith("_")
    ]
    for module in sorted(modules, key=lambda m: (getattr(m, "ORDER", 100), m.__name__)):
        module.register(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run one command; returns the process exit status."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 2
    try:
        code = int(args.func(args) or 0)
        sys.stdout.flush()  # a closed pipe shows here, inside the handler below
        return code
    except CliError as exc:
        print(f"fha-studio {args.command}: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except FileProblem as exc:
        print(f"fha-studio {args.command}: error: {one_line(str(exc))}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    except BrokenPipeError:
        # the reader went away (e.g. `| head`): stop quietly, and keep Python's exit-time flush
        # of stdout from raising again
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except OSError as exc:  # a file or device the command could not use: one line, no traceback
        where = f"{exc.filename}: " if exc.filename else ""
        print(f"fha-studio {args.command}: error: {where}{os_reason(exc)}", file=sys.stderr)
        return 2
