"""``fha-studio tune measure|propose``: the speed loop's frequency response and proposed gains.

    fha-studio tune measure --url URL --actuator CODE --load-inertia KGM2 [--amplitude-rpm R] [--json OUT]
    fha-studio tune propose --url URL --actuator CODE --load-inertia KGM2 [--aim stiff|standard|soft]
                            [--json OUT]

A drive that cannot be excited (a drive of the manual's commands, servo off, an alarm) gets one
line saying what is needed and exit 4; nothing moves.
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from typing import Any

from fha_studio.cli import CliError

ORDER = 60
EXIT_NOT_EXCITABLE = 4


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser("tune", help="frequency response, resonance, load inertia and proposed gains",
                              description="Tuning of the speed loop: response, margins, inertia, gains.")
    sub = p.add_subparsers(dest="tune_command", metavar="ACTION", required=True)
    for name, helptext in (("measure", "excite the speed loop and measure its frequency response"),
                           ("propose", "propose tune items for an aim, with predicted figures")):
        q = sub.add_parser(name, help=helptext, description=helptext)
        q.add_argument("--url", required=True, help="the drive, e.g. sim://FHA-25C-50-US250")
        q.add_argument("--actuator", required=True, help="model code, e.g. FHA-25C-50-US250")
        q.add_argument("--load-inertia", type=float, required=True, metavar="KGM2",
                       help="the declared load inertia on the output [kg m^2]")
        q.add_argument("--json", metavar="OUT", help="write the result as JSON to OUT (- = stdout)")
        if name == "measure":
            q.add_argument("--amplitude-rpm", type=float, metavar="R",
                           help="excitation amplitude [r/min] (default: the largest the axis allows)")
            q.set_defaults(func=run_measure)
        else:
            q.add_argument("--aim", choices=("stiff", "standard", "soft"), default="standard")
            q.add_argument("--apply", action="store_true",
                           help="back the drive's items up, write the proposed tune items (verified), "
                           "then measure again and move 90 deg")
            q.add_argument("--backup", metavar="PATH",
                           help="where --apply saves the backup "
                           "(default: fha-tune-backup-<UTC time>.toml here)")
            q.set_defaults(func=run_propose)


def _emit(args: argparse.Namespace, result: dict[str, Any], text: str) -> None:
    if args.json:
        data = json.dumps(result, indent=2)
        if args.json == "-":
            print(data)
            return
        with open(args.json, "w", encoding="utf-8") as f:
            f.write(data + "\n")
    print(text)


def _model(args: argparse.Namespace) -> Any:
    from fha_studio.logic.tuning.session import declared_model

    if not args.load_inertia >= 0:
        raise CliError(f"--load-inertia {args.load_inertia:g}: must be 0 or more kg m^2")
    try:
        return declared_model(args.actuator, args.load_inertia)
    except ValueError as exc:
        raise CliError(f"--actuator {args.actuator}: {exc}") from None


def run_measure(args: argparse.Namespace) -> int:
    from fha_studio.hardware.client import DriveClient
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.tuning.measure import NotExcitable, check_excitable
    from fha_studio.logic.tuning.session import measure_report, tuner_for

    model = _model(args)
    parameters = load_parameter_model("HA-655")
    with DriveClient.open(args.url) as client:
        try:
            check_excitable(client)
            tuner = tuner_for(client, parameters, model)
            result = measure_report(client, tuner, time.sleep, time.monotonic, args.amplitude_rpm,
                                    announce=lambda s: print(s, file=sys.stderr))
        except NotExcitable as exc:
            print(f"fha-studio tune measure: {exc}", file=sys.stderr)
            return EXIT_NOT_EXCITABLE
        except ValueError as exc:
            raise CliError(str(exc)) from None

    def f(v: float | None, unit: str) -> str:
        return "none found" if v is None else f"{v:.3g} {unit}"

    _emit(args, result, f"resonance {f(result['resonance_hz'], 'Hz')} (predicted "
          f"{f(result['predicted_resonance_hz'], 'Hz')}), "
          f"anti-resonance {f(result['antiresonance_hz'], 'Hz')}; "
          f"load inertia {f(result['load_inertia_estimate_kgm2'], 'kg m^2')}; gain margin "
          f"{f(result['gain_margin_db'], 'dB')}, phase margin {f(result['phase_margin_deg'], 'deg')}, "
          f"crossover {f(result['crossover_hz'], 'Hz')}, bandwidth {f(result['bandwidth_hz'], 'Hz')}")
    return 0


def run_propose(args: argparse.Namespace) -> int:
    from fha_studio.hardware.client import DriveClient
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.tuning.measure import NotExcitable, check_excitable
    from fha_studio.logic.tuning.session import tuner_for

    model = _model(args)
    parameters = load_parameter_model("HA-655")
    with DriveClient.open(args.url) as client:
        if args.apply:
            try:
                check_excitable(client)
            except NotExcitable as exc:
                print(f"fha-studio tune propose: {exc}", file=sys.stderr)
                return EXIT_NOT_EXCITABLE
        tuner = tuner_for(client, parameters, model)
        proposal = tuner.propose(args.aim)
        result: dict[str, Any] = {"aim": proposal.aim, "used_aim": proposal.used_aim,
                                  "warning": proposal.warning, "present": proposal.present.to_dict(),
                                  "proposed": proposal.proposed.to_dict()}
        if proposal.warning:
            print(f"warning: {proposal.warning}", file=sys.stderr)
        if args.apply:
            result["measured"] = _apply(args, client, parameters, tuner, proposal)
    items = ", ".join(f"{k} {v}" for k, v in proposal.proposed.items.items())
    _emit(args, result, f"proposed ({proposal.used_aim}): {items}; gain margin "
          f"{proposal.proposed.gain_margin_db}, phase margin {proposal.proposed.phase_margin_deg}")
    return 0


def _apply(args: argparse.Namespace, client: Any, parameters: Any, tuner: Any,
           proposal: Any) -> dict[str, Any]:
    """Backup, verified writes, then the same figures measured: margins from a new frequency
    response, overshoot and settling from a 90 deg move."""
    from pathlib import Path

    from fha_studio import clock
    from fha_studio.logic.tuning.move import MoveAlarm
    from fha_studio.logic.tuning.session import (
        backup_parameters,
        measure_report,
        tuner_for,
        verify_move,
        write_tune_items,
    )

    stamp = clock.now_utc().strftime("%Y%m%dT%H%M%SZ")
    path = Path(args.backup) if args.backup else Path(f"fha-tune-backup-{stamp}.toml")
    try:
        backup_parameters(client, parameters, args.actuator, path)
        print(f"backup of the drive's items: {path}", file=sys.stderr)
        write_tune_items(client, parameters, proposal.proposed.items)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    after = tuner_for(client, parameters, tuner.model)
    report = measure_report(client, after, time.sleep, time.monotonic)
    measured: dict[str, Any] = {**proposal.proposed.items, "gain_margin_db": report["gain_margin_db"],
                                "phase_margin_deg": report["phase_margin_deg"], "backup": str(path)}
    try:
        measured.update(verify_move(client, parameters, after, time.sleep).to_dict())
    except MoveAlarm as exc:
        measured.update({"overshoot_pct": None, "settling_ms": None, "alarm": exc.code})
    return measured
