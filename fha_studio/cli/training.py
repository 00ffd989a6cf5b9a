"""``fha-studio training ...``: scenarios for training on the simulated drive (docs/training.md).

- ``training list``: the scenarios shipped, first-day ones first.
- ``training show SCENARIO``: what the trainee is told (never the hidden faults).
- ``training start SCENARIO``: the GUI on the scenario's drive (started by the entry point, which
  alone imports Qt: fha_studio.main).
- ``training check FILE``: check a scenario file and show that each of its faults can be observed
  on the simulated drive through the ordinary client (the answer: for the trainer only).
"""

from __future__ import annotations

import argparse
import textwrap

from fha_studio.cli import CliError
from fha_studio.cli._values import text

ORDER = 65


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "training",
        help="training scenarios on the simulated drive: hidden faults and a score sheet",
        description="Training on the embedded simulated drive: each scenario hides faults a trainee "
        "has to find with the ordinary pages; the score sheet says what was found (docs/training.md).",
    )
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    ls = sub.add_parser("list", help="the training scenarios")
    ls.set_defaults(func=_list)
    show = sub.add_parser("show", help="what the trainee is told (not the hidden faults)")
    show.add_argument("scenario", metavar="SCENARIO", type=text, help="a scenario id or a .toml file")
    show.set_defaults(func=_show)
    start = sub.add_parser("start", help="start the GUI on the scenario's simulated drive")
    start.add_argument("scenario", metavar="SCENARIO", type=text, help="a scenario id or a .toml file")
    start.set_defaults(func=_start)
    check = sub.add_parser(
        "check",
        help="check a scenario file and that each fault shows on the drive (prints the answer: for trainers)",
    )
    check.add_argument("file", metavar="FILE", type=text, help="a scenario file (.toml) or a scenario id")
    check.add_argument("--no-drive", action="store_true", help="only check the file, do not run the faults")
    check.set_defaults(func=_check)


def _scenario(name: str):
    from fha_studio.logic.training.scenario import ScenarioError, find_scenario

    try:
        return find_scenario(name)
    except ScenarioError as exc:
        raise CliError(str(exc)) from None


def _list(args: argparse.Namespace) -> int:
    from fha_studio.logic.training.scenario import ScenarioError, list_scenarios

    try:
        scenarios = list_scenarios()
    except ScenarioError as exc:
        raise CliError(str(exc)) from None
    width = max(len(s.id) for s in scenarios)
    for s in scenarios:
        print(f"{s.id:<{width}}  {s.level:<12}  {s.time_guide_min:>3g} min  {s.title}")
    return 0


def _show(args: argparse.Namespace) -> int:
    s = _scenario(args.scenario)
    print(s.title)
    print(f"Level: {s.level}; time guide {s.time_guide_min:g} min")
    print(
        f"Actuator: {s.actuator}; driver: {s.driver or 'as the combination table gives'}; "
        f"declared load inertia {s.load_inertia_kgm2:g} kg·m²"
    )
    print()
    for paragraph in s.briefing.split("\n\n"):
        print(textwrap.fill(" ".join(paragraph.split()), 88))
        print()
    print(f"The drive hides what you are to find. Start it with fha-studio training start {s.id}")
    return 0


def _start(args: argparse.Namespace) -> int:
    raise CliError(
        "the training GUI is started by the fha-studio command itself "
        f"(fha-studio training start {args.scenario})"
    )


def _check(args: argparse.Namespace) -> int:
    from fha_studio.hardware.errors import LinkError
    from fha_studio.logic.training.check import check_scenario

    s = _scenario(args.file)
    faults = f"{len(s.faults)} fault{'s' if len(s.faults) != 1 else ''}"
    steps = f"{len(s.steps)} step{'s' if len(s.steps) != 1 else ''}"
    print(f"{s.path}: the file is valid: {s.title} ({faults}, {steps})")
    if args.no_drive:
        return 0
    try:
        results = check_scenario(s)
    except LinkError as exc:
        raise CliError(f"the simulated drive of {s.id} could not be walked: {exc}") from None
    hidden = 0
    for result in results:
        f = result.fault
        if result.observable:
            print(f"  {f.id}: {f.title}: observable")
            for what, before, after in result.differences:
                print(f"      {what}: {before} -> {after}")
        else:
            hidden += 1
            print(
                f"  {f.id}: {f.title}: NOT observable by the check's walk (no difference to the drive "
                "without it); make sure the evidence asks for something the trainee can see"
            )
    return 1 if hidden else 0
