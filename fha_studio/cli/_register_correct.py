"""``fha-studio register correct KIND NUMBER --reason TEXT ...``: a mistake corrected by a new fact
that points at the one it corrects (the register never changes a fact). KIND and NUMBER are a
history line's (``history --numbers``):

- ``snapshot N --set KEY=VALUE ...``: the values read wrong off the front panel, as they are;
- ``check N --passed yes|no [--value V]``: the answer a check should have had;
- ``note N --text TEXT``: a note that corrects an entry of the axis's history.
"""

from __future__ import annotations

import argparse
import json
import re

from fha_studio.cli import CliError


def add_actions(sub: argparse._SubParsersAction, common: argparse.ArgumentParser, opener) -> None:
    """The ``correct`` action of ``fha-studio register``; ``opener(args)`` opens the register."""
    s = sub.add_parser(
        "correct", parents=[common], help="correct a mistake: a new fact that points at the wrong one",
        description="The register never changes a fact: a mistake is corrected by a new fact of the same "
        "kind that points at the one it corrects; the history shows both. KIND NUMBER: snapshot N, check N "
        "or note N (history --numbers gives each line's number).")
    s.add_argument("kind", choices=("snapshot", "check", "note"), metavar="KIND",
                   help="snapshot | check | note")
    s.add_argument("number", type=int, metavar="NUMBER", help="the number of the fact that is wrong")
    s.add_argument("--reason", default="", help="why it was wrong (snapshot, check; kept in the history)")
    s.add_argument("--set", dest="values", action="append", default=[], metavar="KEY=VALUE",
                   help="snapshot: a parameter's right value (the drive's number), e.g. in_position_range=10")
    s.add_argument("--passed", choices=("yes", "no"), help="check: whether it passed")
    s.add_argument("--value", help="check: the value that was read or measured")
    s.add_argument("--text", default="", help="note: the note that corrects the entry")
    s.add_argument("--operator", default="", help="who corrects it")
    s.set_defaults(func=_correct, writes=True, open_register=opener)


def _values(items: list[str]) -> dict[str, int]:
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.register.words import parameter_item

    by_name = {i.name.lower().replace(" ", "_"): i for i in load_parameter_model("HA-655")}
    out: dict[str, int] = {}
    for item in items:
        key_text, equals, value_text = item.partition("=")
        wanted = key_text.strip().lower().replace(" ", "_").replace("-", "_")
        if not equals or not wanted or not re.fullmatch(r"[+-]?[0-9]{1,11}", value_text.strip()):
            raise CliError(f"--set {item!r}: KEY=VALUE expected, VALUE the drive's whole number "
                           "(e.g. in_position_range=10)")
        found = parameter_item(wanted) or by_name.get(wanted)
        value = int(value_text.strip())
        if found is not None:
            try:
                found.check(value)
            except ValueError as exc:
                raise CliError(f"--set: {exc}") from None
        out[found.key if found is not None else wanted] = value
    return out


def _check_value(text: str | None):
    if text is None:
        return None
    try:
        return json.loads(text) if re.fullmatch(r"[+-]?[0-9.eE+-]+|true|false", text.strip()) else text
    except ValueError:
        return text


def _correct(args) -> int:
    from fha_studio.logic.register import corrections

    if args.kind != "snapshot" and args.values:
        raise CliError("--set corrects a snapshot's values")
    if args.kind != "check" and (args.passed or args.value is not None):
        raise CliError("--passed and --value correct a check")
    if args.kind != "note" and args.text:
        raise CliError("--text is a correcting note's (KIND note)")
    values = _values(args.values) if args.kind == "snapshot" else {}
    with args.open_register(args) as reg:
        if args.kind == "snapshot":
            made = corrections.correct_snapshot(reg, args.number, values, args.reason, args.operator)
        elif args.kind == "check":
            passed = None if args.passed is None else args.passed == "yes"
            made = corrections.correct_check(reg, args.number, args.reason, passed, _check_value(args.value),
                                             args.operator)
        else:
            made = corrections.correct_note(reg, args.number, args.text, args.operator)
    if args.json:
        print(json.dumps(made.as_dict(), indent=2, ensure_ascii=False))
    else:
        print(f"{made.axis}: {made.kind} {made.number} corrects {made.kind} {made.corrects} ({made.what})")
    return 0
