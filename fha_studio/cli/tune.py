"""``fha-studio tune measure|propose|excitation|analyse``: the speed loop's frequency response and
proposed gains, over CN3 or from the bench.

    fha-studio tune measure --url URL --actuator CODE --load-inertia KGM2 [--amplitude-rpm R]
                            [--bias fwd|rev|none] [--limit-switches LS1,LS2] [--json OUT]
    fha-studio tune propose --url URL --actuator CODE --load-inertia KGM2 [--aim stiff|standard|soft]
                            [--json OUT]
    fha-studio tune excitation --actuator CODE --parameters P.toml --load-inertia KGM2
                               [--form multisine|prbs|chirp] [--amplitude-rpm R] [--rate HZ]
                               [--bias fwd|rev|none] -o EXC
    fha-studio tune analyse --actuator CODE --parameters P.toml --load-inertia KGM2
                            --signal ROLE=FILE[#CHANNEL] ... [--excitation EXC] [--json OUT]

``excitation`` writes the file an instrument's output plays into SPD-CMD of a real HA-655 in speed
mode (a CSV of time and volts, a WAV, or one normalised cycle), its bounds stated first;
``analyse`` takes the capture (SPD-MON, and SPD-CMD or the excitation file) and gives the JSON of
``measure``. A drive that cannot be excited (a drive of the manual's commands, servo off, an
alarm, parameter 0 not speed for SPD-CMD) gets one line saying what is needed and exit 4; nothing
moves. A drive that gives no parameter access over CN3 gets the same for ``propose`` (its tune
items are read on its front panel: the Tuning page's worksheet, or ``analyse`` with the parameter
file); a port that does not open or a drive that does not answer, one line and exit 3.

Waiting is on what the drive reports (its trace's state and count: the drive's own time), never on
the computer's clock; a stepped simulated drive (``sim://...&stepped=1``) is advanced between looks.
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from typing import Any

from fha_studio.cli import CliError
from fha_studio.plausible import Range

ORDER = 60
EXIT_NO_ANSWER = 3
EXIT_NOT_EXCITABLE = 4
NO_PARAMETER_ACCESS = (
    "the drive gives no parameter access over CN3 (a drive of the manual's commands): read its tune "
    "items on the front panel and propose on the Tuning page (a front-panel worksheet), or from the "
    "bench with 'tune analyse --parameters PARAMS.toml'"
)


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
            q.add_argument("--bias", choices=("fwd", "rev", "none"), default=None,
                           help="the slow jog the excitation rides on (the bias speed that keeps the axis "
                           "from sticking on its friction): FWD (the default) or REV command, or none: "
                           "about standstill, for an axis that may not turn that far; the friction then "
                           "spoils the response at low frequency (warned of)")
            q.add_argument("--in-place", action="store_true", help="the same as --bias none")
            q.add_argument("--limit-switches", type=_switch_angles, metavar="LS1,LS2",
                           help="the switching angles of limit switch 1 (CCW end) and 2 (CW end) [deg of "
                           "the output's feedback position, as the procedures record them]: the plan is "
                           "refused where its travel does not fit the room to them (write "
                           "--limit-switches=-120,95 for a negative first angle)")
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
    _add_bench(sub)


class _TuneStop(Exception):
    """Ends the command with ``code`` and one line."""

    def __init__(self, code: int, message: str):
        super().__init__(message)
        self.code = code


@contextmanager
def _open(url: str) -> Iterator[Any]:
    """The drive at ``url``; a port that does not open or a line that fails is one line and exit 3
    (as ``fha-studio drive``), a drive's refusal or one that cannot be excited one line and exit 4
    (``_TuneStop``: :func:`_stopped` says it)."""
    from fha_studio.hardware.client import DriveClient
    from fha_studio.hardware.errors import DriveRefused, LinkFailure
    from fha_studio.logic.tuning.excitation import NotExcitable

    try:
        client = DriveClient.open(url)
    except ValueError as exc:
        raise CliError(f"--url: {exc}") from None
    except LinkFailure as exc:
        raise _TuneStop(EXIT_NO_ANSWER, str(exc)) from None
    try:
        yield client
    except LinkFailure as exc:
        raise _TuneStop(EXIT_NO_ANSWER, f"the link to {url} failed: {exc}") from None
    except DriveRefused as exc:
        raise _TuneStop(EXIT_NOT_EXCITABLE, f"the drive refused: {exc}") from None
    except NotExcitable as exc:
        raise _TuneStop(EXIT_NOT_EXCITABLE, str(exc)) from None
    finally:
        client.close()


def _stopped(command: str, why: Exception, code: int) -> int:
    """A ``tune`` command ended by ``why``: one line, and its exit status ``code``."""
    print(f"fha-studio tune {command}: {why}", file=sys.stderr)
    return code


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


def _switch_angles(text: str) -> dict[str, float]:
    """``--limit-switches LS1,LS2``: two finite angles (deg)."""
    import math

    parts = text.split(",")
    try:
        one, two = (float(v) for v in parts)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r}: two angles in deg, --limit-switches=LS1,LS2 "
                                         "(e.g. =-120,95)") from None
    if not (math.isfinite(one) and math.isfinite(two)) or one == two:
        raise argparse.ArgumentTypeError(f"{text!r}: two different finite angles in deg")
    return {"limit_switch_1": one, "limit_switch_2": two}


def _bias(args: argparse.Namespace) -> str:
    """--bias, or --in-place (the same as --bias none); both, only where they agree."""
    if args.in_place and args.bias not in (None, "none"):
        raise CliError(f"--in-place with --bias {args.bias}: choose one (--in-place is --bias none)")
    return "none" if args.in_place else (args.bias or "fwd")


def run_measure(args: argparse.Namespace) -> int:
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.tuning.measure import check_excitable
    from fha_studio.logic.tuning.record import figure_words
    from fha_studio.logic.tuning.session import drive_clock, measure_report, tuner_for

    model = _model(args)
    bias = _bias(args)
    parameters = load_parameter_model("HA-655")
    try:
        with _open(args.url) as client:
            check_excitable(client)
            tuner = tuner_for(client, parameters, model)
            pace, now = drive_clock(client)
            result = measure_report(client, tuner, pace, now, args.amplitude_rpm,
                                    announce=lambda s: print(s, file=sys.stderr), bias=bias,
                                    switch_angles_deg=args.limit_switches)
    except _TuneStop as stop:
        return _stopped("measure", stop, stop.code)
    except ValueError as exc:
        raise CliError(str(exc)) from None

    def f(key: str, unit: str) -> str:
        return figure_words(key, result[key], unit)

    words = [f"resonance {f('resonance_hz', 'Hz')} (predicted {f('predicted_resonance_hz', 'Hz')})",
             f"anti-resonance {f('antiresonance_hz', 'Hz')}",
             f"load inertia {f('load_inertia_estimate_kgm2', 'kg m^2')}",
             f"gain margin {f('gain_margin_db', 'dB')}", f"phase margin {f('phase_margin_deg', 'deg')}",
             f"crossover {f('crossover_hz', 'Hz')}", f"bandwidth {f('bandwidth_hz', 'Hz')}"]
    if result.get("stick_slip_warning"):
        print(f"warning: {result['stick_slip_warning']}", file=sys.stderr)
    _emit(args, result, ", ".join(words))
    return 0


def run_propose(args: argparse.Namespace) -> int:
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.tuning.measure import check_excitable
    from fha_studio.logic.tuning.session import tuner_for

    model = _model(args)
    parameters = load_parameter_model("HA-655")
    try:
        with _open(args.url) as client:
            if args.apply:
                check_excitable(client)
            if not client.capabilities.parameters:
                raise _TuneStop(EXIT_NOT_EXCITABLE, NO_PARAMETER_ACCESS)
            tuner = tuner_for(client, parameters, model)
            proposal = tuner.propose(args.aim)
            result: dict[str, Any] = {"aim": proposal.aim, "used_aim": proposal.used_aim,
                                      "warning": proposal.warning, "present": proposal.present.to_dict(),
                                      "proposed": proposal.proposed.to_dict()}
            if proposal.reference is not None:  # beyond 2-1: what the standard aim would have proposed
                result["reference"] = proposal.reference.to_dict()
            if proposal.warning:
                print(f"warning: {proposal.warning}", file=sys.stderr)
            if args.apply:
                result["measured"] = _apply(args, client, parameters, tuner, proposal)
    except _TuneStop as stop:
        return _stopped("propose", stop, stop.code)
    from fha_studio.logic.tuning.record import figure_words

    items = ", ".join(f"{k} {v}" for k, v in proposal.proposed.items.items())
    figs = proposal.proposed
    _emit(args, result, f"proposed ({proposal.used_aim}): {items}; gain margin "
          f"{figure_words('gain_margin_db', figs.gain_margin_db, 'dB')}, phase margin "
          f"{figure_words('phase_margin_deg', figs.phase_margin_deg, 'deg')}")
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
        drive_clock,
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
    pace, now = drive_clock(client)
    report = measure_report(client, after, pace, now)
    measured: dict[str, Any] = {**proposal.proposed.items, "gain_margin_db": report["gain_margin_db"],
                                "phase_margin_deg": report["phase_margin_deg"], "backup": str(path)}
    try:
        measured.update(verify_move(client, parameters, after, pace).to_dict())
    except MoveAlarm as exc:
        measured.update({"overshoot_pct": None, "settling_ms": None, "alarm": exc.code})
    return measured


# ----- from the bench: a drive whose CN3 is silent while the servo is on ------------------------------


def _add_bench(sub: argparse._SubParsersAction) -> None:
    from fha_studio.cli._values import in_range, number, output_path, whole
    from fha_studio.logic.tuning.bench_names import ANALYSE_ROLES, EXCITATION_FORMS
    from fha_studio.plausible import LOAD_INERTIA_KGM2

    def common(q: argparse.ArgumentParser) -> None:
        q.add_argument("--actuator", required=True, help="model code, e.g. FHA-25C-50-US250")
        q.add_argument("--parameters", required=True, metavar="PARAMS.toml",
                       help="the drive's parameter file (fha-parameters/1, front-panel values included): "
                       "parameters 0 and 9 and the tune items are read from it")
        q.add_argument("--load-inertia", type=in_range(LOAD_INERTIA_KGM2), required=True, metavar="KGM2",
                       help="the declared load inertia on the output [kg m^2]")

    q = sub.add_parser("excitation", help="write an excitation file for SPD-CMD (an instrument's output)",
                       description="The bounded excitation of the speed loop of a real HA-655 in speed mode, "
                       "as a file an instrument's analog output plays into SPD-CMD (CN2-31/32): its bounds "
                       "(amplitude, angle travelled, current) are printed before anything is played.")
    common(q)
    q.add_argument("--form", choices=EXCITATION_FORMS, default="multisine",
                   help="the excitation (default multisine)")
    q.add_argument("--amplitude-rpm", type=number, metavar="R",
                   help="the speed command's peak at the output [r/min] (default: the largest the axis "
                   "allows)")
    q.add_argument("--rate", type=in_range(_RATE), default=10000.0, metavar="HZ",
                   help="the instrument's output rate [samples/s] (default 10000)")
    q.add_argument("--periods", type=whole(3, 100), default=6, metavar="N",
                   help="periods played; the first settles the loop (default 6)")
    q.add_argument("--bias", choices=("fwd", "rev", "none"), default=None,
                   help="the constant speed under the periods that keeps the axis from sticking on its "
                   "friction: FWD (the default, SPD-CMD positive) or REV, whichever way the axis has room, "
                   "or none: about standstill, for an axis that may not turn that far; the friction then "
                   "spoils the response at low frequency")
    q.add_argument("--in-place", action="store_true", help="the same as --bias none")
    q.add_argument("-o", "--output", required=True, type=output_path, metavar="EXC",
                   help="the file to write: .csv (time and volts), .wav (16-bit, its full scale stated), "
                   ".txt (one cycle normalised to ±1)")
    q.add_argument("--json", metavar="OUT", help="write the excitation's figures as JSON to OUT (- = stdout)")
    q.set_defaults(func=run_excitation)

    q = sub.add_parser("analyse", help="the loop from a bench capture: a frequency response or a move",
                       description="The speed loop's frequency response, resonance, load inertia and "
                       "margins from a capture of SPD-MON (CN2-23) while the excitation played into "
                       "SPD-CMD (speed mode); or, where no output can drive SPD-CMD, the loop fitted to a "
                       "move captured in position mode (the command pulses, the encoder outputs, SPD-MON): "
                       "the JSON of 'tune measure'.")
    common(q)
    q.add_argument("--signal", action="append", default=[], metavar="ROLE=FILE[#CHANNEL]",
                   help=f"a signal and where it was captured; ROLE: {', '.join(ANALYSE_ROLES)} (a response: "
                   "speed_monitor with speed_command or --excitation; a move: encoder_a, encoder_b, "
                   "command_a [command_b] [speed_monitor] [in_position])")
    q.add_argument("--excitation", metavar="EXC",
                   help="the excitation file played (CSV or WAV as 'tune excitation' writes it): the input "
                   "when SPD-CMD was not recorded, aligned by cross-correlation")
    q.add_argument("--monitor-bandwidth-hz", type=in_range(_MONITOR_BANDWIDTH), metavar="HZ",
                   help="SPD-MON's own bandwidth, when known: its lag is taken out of the phase")
    q.add_argument("--json", metavar="OUT", help="write the result as JSON to OUT (- = stdout)")
    q.set_defaults(func=run_analyse)


_RATE = Range("rate", 1000.0, 1e6, "samples/s", "an instrument's analog output rate")
_MONITOR_BANDWIDTH = Range("monitor bandwidth", 10.0, 1e6, "Hz", "an analog monitor's bandwidth")


def _bench_tuner(args: argparse.Namespace) -> tuple[Any, dict[tuple[str, int], int]]:
    """The declared axis with the parameter file's items, and the file's values."""
    from fha_studio.cli._bench_common import parameter_values
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.bench.importer import BenchImportError
    from fha_studio.logic.tuning.bench_session import bench_tuner

    try:
        values = parameter_values(args.parameters)
    except BenchImportError as exc:
        raise CliError(str(exc)) from None
    try:
        return bench_tuner(args.actuator, args.load_inertia, load_parameter_model("HA-655"), values), values
    except ValueError as exc:
        raise CliError(f"--actuator {args.actuator}: {exc}") from None


def run_excitation(args: argparse.Namespace) -> int:
    from fha_studio.hardware.bench.waveform import form_of, write_waveform
    from fha_studio.logic.tuning.bench_excitation import NotInSpeedMode, design_excitation

    tuner, _values = _bench_tuner(args)
    try:
        excitation = design_excitation(tuner, args.form, args.amplitude_rpm, args.rate, args.periods,
                                       bias=_bias(args))
    except NotInSpeedMode as exc:
        return _stopped("excitation", exc, EXIT_NOT_EXCITABLE)
    except ValueError as exc:
        raise CliError(str(exc)) from None
    form = form_of(args.output)
    try:
        write_waveform(args.output, excitation.waveform, form)
    except ValueError as exc:
        raise CliError(f"{args.output}: {exc}") from None
    how = {"csv": "time (s) and SPD-CMD (V)", "wav": f"16-bit WAV, full scale {excitation.peak_v:.4g} V",
           "cycle": f"one cycle normalised to ±1: set the generator to {excitation.peak_v:.4g} V peak "
                    f"and {1.0 / excitation.period_s:.6g} Hz, and record SPD-CMD too"}[form]
    _emit(args, {**excitation.to_dict(), "file": str(args.output), "file_form": form},
          f"{excitation.describe()}\nwritten to {args.output} ({how})")
    return 0


def run_analyse(args: argparse.Namespace) -> int:
    from fha_studio.logic.tuning.bench_excitation import NotInSpeedMode
    from fha_studio.logic.tuning.bench_names import ANALYSE_ROLES
    from fha_studio.logic.tuning.bench_response import BenchResponseError
    from fha_studio.logic.tuning.bench_session import (
        bench_move_report,
        bench_response_report,
        is_move,
        parse_role,
    )

    tuner, values = _bench_tuner(args)
    try:
        signals = [parse_role(text, ANALYSE_ROLES) for text in args.signal]
        if is_move(signals) and not args.excitation:
            result = bench_move_report(tuner, signals, values)
        else:
            result = bench_response_report(tuner, signals, args.excitation, args.monitor_bandwidth_hz)
    except NotInSpeedMode as exc:
        return _stopped("analyse", exc, EXIT_NOT_EXCITABLE)
    except (BenchResponseError, ValueError) as exc:
        raise CliError(str(exc)) from None
    _emit(args, _finite(result), _summary(result))
    for note in result.get("notes", []):
        print(note)
    return 0


def _finite(obj: Any) -> Any:
    from fha_studio.cli._bench_common import finite

    return finite(obj)


def _summary(result: dict[str, Any]) -> str:
    def f(v: float | None, unit: str) -> str:
        return "none found" if v is None else f"{v:.3g} {unit}"

    spread = result.get("load_inertia_uncertainty_kgm2")
    load = f(result["load_inertia_estimate_kgm2"], "kg m^2") + (f" ± {spread:.2g}" if spread else "")
    return (f"resonance {f(result['resonance_hz'], 'Hz')} (predicted "
            f"{f(result['predicted_resonance_hz'], 'Hz')}), anti-resonance "
            f"{f(result['antiresonance_hz'], 'Hz')}; load inertia {load}; gain margin "
            f"{f(result['gain_margin_db'], 'dB')}, phase margin {f(result['phase_margin_deg'], 'deg')}, "
            f"crossover {f(result['crossover_hz'], 'Hz')}, bandwidth {f(result['bandwidth_hz'], 'Hz')}")
