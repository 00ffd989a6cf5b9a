"""``fha-studio discrepancy``: find where a recording and the catalogue model disagree.

Prints a human summary (each missing effect with its fitted parameters and the gap on held-out
data), optionally writes the JSON report and the updated model file (fha-axis-model/1 TOML).
"""

from __future__ import annotations

import argparse
import json
import math

from fha_studio import fileio
from fha_studio.cli import CliError
from fha_studio.cli._values import in_range, output_path
from fha_studio.plausible import LOAD_INERTIA_KGM2

ORDER = 40


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "discrepancy",
        help="name the effect missing from the model of a recorded axis and show the gap shrink",
        description="Compare an fha-recording/1 file with the catalogue model of its declared actuator: "
        "where they disagree, which effect is missing (Coulomb/viscous friction, friction by direction, "
        "breakaway friction, gravity, offset, inertia or torque-constant error, torque ripple; with "
        "load_pos: kinematic error, wind-up, lost motion), its parameters, and "
        "the RMS gap before and after on held-out data.",
    )
    p.add_argument("recording", metavar="RECORDING.csv", help="the recording (fha-recording/1)")
    p.add_argument("--json", metavar="REPORT.json", type=output_path, help="write the report as JSON")
    p.add_argument(
        "--model-out", metavar="MODEL.toml", type=output_path,
        help="write the updated axis model (fha-axis-model/1)",
    )
    p.add_argument(
        "--window",
        type=int,
        metavar="SAMPLES",
        help="Savitzky-Golay window in samples, which sets the analysis bandwidth (default: chosen from "
        "the recording); refused outside what the recording supports",
    )
    p.add_argument(
        "--load-inertia",
        type=in_range(LOAD_INERTIA_KGM2),
        metavar="KGM2",
        help="the axis's declared load inertia [kg m^2], for a recording that declares none (a bench "
        "capture made by 'bench import') or instead of the one it declares",
    )
    p.add_argument("--no-resim", action="store_true", help="skip the closed-loop re-simulation")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from fha_studio.logic.modelcheck import ModelCheckError, run_modelcheck
    from fha_studio.recording import RecordingError, read_recording

    try:
        rec = read_recording(args.recording)
    except RecordingError as exc:
        raise CliError(str(exc)) from None
    if args.load_inertia is not None:
        rec = rec.with_declared_load(args.load_inertia)
    try:
        result = run_modelcheck(rec, window=args.window, resimulate=not args.no_resim)
    except ModelCheckError as exc:
        raise CliError(f"{args.recording}: {exc}") from None
    # the files first: a write that fails is reported before anything reads as a result
    written = []
    if args.json:
        fileio.write_text(args.json, json.dumps(_finite(result.to_json()), indent=2) + "\n")
        written.append(f"report written to {args.json}")
    if args.model_out:
        result.write_model(args.model_out)
        written.append(f"updated model written to {args.model_out}")
    print(
        f"{args.recording}: {result.actuator}, {len(rec)} samples over {rec.duration_s:.3g} s "
        f"(analysis bandwidth {result.bandwidth_hz:.3g} Hz: Savitzky-Golay window "
        f"{result.window_samples} samples = {1000 * result.window_s:.0f} ms, {result.window_reason})"
    )
    for line in result.summary_lines():
        print(line)
    for line in written:
        print(line)
    return 0


def _finite(obj):
    """JSON has no infinity or NaN: write them as null."""
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_finite(v) for v in obj]
    return obj
