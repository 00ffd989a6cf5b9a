"""``fha-studio catalog MODEL-CODE [--json]``: the resolved catalogue entry of one actuator."""

from __future__ import annotations

import argparse
import json
from typing import Any

from fha_studio.catalog import Actuator, ModelCodeError, get_actuator
from fha_studio.cli import CliError

ORDER = 10


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "catalog",
        help="show the catalogue entry of an actuator model code",
        description="Show the FHA-C manual's data for one actuator, e.g. FHA-25C-50-US250 or "
        "FHA-32C-100-S248-B. Values are SI with the unit in the name, output-referred.",
    )
    p.add_argument("model_code", metavar="MODEL-CODE", help="e.g. FHA-25C-50-US250, FHA-17C-100-S248-A-B")
    p.add_argument("--json", action="store_true", help="print JSON (SI keys with units in the names)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    try:
        actuator = get_actuator(args.model_code)
    except ModelCodeError as exc:
        raise CliError(str(exc)) from None
    if args.json:
        print(json.dumps(actuator.as_dict(), indent=2, ensure_ascii=False))
    else:
        print(format_table(actuator))
    return 0


def _fmt(value: Any) -> str:
    if isinstance(value, dict) and "colour" in value:  # a cable lead
        return f"{value['colour']}={value['signal']}"
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, (list, tuple)):
        return ", ".join(_fmt(v) for v in value) or "-"
    return str(value)


def format_table(a: Actuator) -> str:
    """A readable two-column listing of an actuator, nested objects indented."""
    d = a.as_dict()
    notes = d.pop("notes")
    lines = [f"{a.model_code}  ({a.encoder}, {a.supply_voltage} V)"]
    width = 40

    def emit(key: str, value: Any, indent: str) -> None:
        if isinstance(value, dict):
            lines.append(f"{indent}{key}:")
            for k, v in value.items():
                emit(k, v, indent + "  ")
        else:
            lines.append(f"{indent}{key:<{width - len(indent)}} {_fmt(value)}")

    for key, value in d.items():
        if key == "brake" and value is None:
            lines.append(f"{'brake':<{width}} none (no option B)")
            continue
        emit(key, value, "")
    if notes:
        lines.append("notes (where the manual contradicts itself, and caveats):")
        lines += [f"  - {n}" for n in notes]
    return "\n".join(lines)
