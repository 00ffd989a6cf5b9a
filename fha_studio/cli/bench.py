"""``fha-studio bench``: the drive's CN2 signals from bench instruments.

``bench import`` decodes capture files (sigrok ``.sr``, VCD, sigrok-cli's CSV, a generic CSV)
into a recording (:mod:`fha_studio.logic.bench.importer`); ``bench devices`` and ``bench record``
(live instruments through sigrok-cli) are in :mod:`fha_studio.cli._bench_live`.
"""

from __future__ import annotations

import argparse
import json

from fha_studio import fileio
from fha_studio.cli import CliError
from fha_studio.cli._bench_common import finite, parameter_values
from fha_studio.cli._values import in_range, output_path
from fha_studio.plausible import CURRENT_PROBE_A_PER_V, LOAD_ENCODER_COUNTS

ORDER = 45


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "bench",
        help="decode the drive's CN2 signals captured by a logic analyzer, oscilloscope or DAQ",
        description="The drive's CN2 monitor outputs (SPD-MON, encoder A/B/Z, IN-POS, ALARM) and the "
        "command pulses, captured by bench instruments: what a drive whose CN3 is silent while the servo "
        "is on does in motion.",
    )
    commands = p.add_subparsers(dest="bench_command", metavar="COMMAND", parser_class=type(p))
    p.set_defaults(func=lambda args: _no_command(p))
    add_import(commands)
    from fha_studio.cli._bench_live import add_devices, add_record

    add_devices(commands)
    add_record(commands)


def _no_command(parser: argparse.ArgumentParser) -> int:
    parser.print_help()
    return 2


def add_import(commands: argparse._SubParsersAction) -> None:
    from fha_studio.logic.bench.importer import ROLES

    p = commands.add_parser(
        "import",
        help="decode capture files into a recording (t, cmd_pos, pos, vel, in_pos, current)",
        description="Decode capture files (sigrok .sr, VCD, sigrok-cli CSV, CSV with a time column) of "
        "the drive's CN2 signals into an fha-recording file: the encoder counted x4 (glitches, illegal "
        "transitions and Z pulses checked), the command pulses by parameters 1, 2, 3 and 4, SPD-MON by "
        "parameter 9 with its offset at standstill. Each column's source is named in the recording.",
    )
    p.add_argument(
        "--actuator",
        required=True,
        metavar="CODE",
        help="the actuator's model code, e.g. FHA-25C-50-US250 (its encoder's counts per turn)",
    )
    p.add_argument(
        "--parameters",
        required=True,
        metavar="PARAMS.toml",
        help="the drive's parameter file (fha-parameters/1, as the Parameters page saves it): "
        "parameters 1, 2, 3, 4 and 9 are read from it",
    )
    p.add_argument(
        "--signal",
        action="append",
        default=[],
        metavar="ROLE=FILE[#CHANNEL]",
        help=f"a signal and where it was captured; ROLE is one of {', '.join(ROLES)}; CHANNEL is "
        "the channel's name in the file (needed when the file has more than one)",
    )
    p.add_argument(
        "--current-scale",
        type=in_range(CURRENT_PROBE_A_PER_V),
        metavar="A_PER_V",
        help="the current probe's amperes per volt (with --signal current_probe=...)",
    )
    p.add_argument(
        "--load-encoder-counts",
        type=in_range(LOAD_ENCODER_COUNTS),
        metavar="COUNTS",
        help="an external encoder on the output flange (--signal load_encoder_a=... and load_encoder_b=...): "
        "its counts per output turn, x4; the recording then has load_pos",
    )
    p.add_argument(
        "-o",
        "--output",
        required=True,
        type=output_path,
        metavar="RECORDING.csv",
        help="the recording to write",
    )
    p.add_argument("--json", type=output_path, metavar="SUMMARY.json", help="write the summary as JSON")
    p.set_defaults(func=run_import)


def run_import(args: argparse.Namespace) -> int:
    from fha_studio.logic.bench.importer import (
        AxisFacts,
        BenchImportError,
        DriveSettings,
        import_bench,
        parse_signal,
    )
    from fha_studio.recording import write_recording

    if args.current_scale is not None and not any(t.startswith("current_probe=") for t in args.signal):
        raise CliError("--current-scale without --signal current_probe=FILE[#CHANNEL]")
    if args.load_encoder_counts is not None and not any(t.startswith("load_encoder_a=") for t in args.signal):
        raise CliError("--load-encoder-counts without --signal load_encoder_a=FILE[#CHANNEL]")
    load_counts = None if args.load_encoder_counts is None else round(args.load_encoder_counts)
    try:
        signals = [parse_signal(text) for text in args.signal]
        axis = AxisFacts.for_actuator(args.actuator)
        settings = DriveSettings.from_values(parameter_values(args.parameters), args.parameters)
        result = import_bench(
            signals,
            axis,
            settings,
            current_scale_a_per_v=args.current_scale,
            load_counts_per_turn=load_counts,
        )
    except BenchImportError as exc:
        raise CliError(str(exc)) from None
    summary = result.summary
    write_recording(args.output, result.recording)
    if args.json:
        fileio.write_text(args.json, json.dumps(finite(summary), indent=2) + "\n")
    rate = summary["sample_rate_hz"]
    print(
        f"{summary['samples']} samples at {_hz(rate)} ({summary['duration_s']:.4g} s) decoded into "
        f"{args.output}: {summary['recording']['rows']} rows, columns "
        f"{', '.join(result.recording.channels)}"
    )
    encoder = summary["encoder"]
    if encoder is not None:
        z = (
            ""
            if encoder["z_pulses"] is None
            else f", {encoder['z_pulses']} Z pulses ({encoder['z_count_errors']} off the "
            f"{encoder['counts_per_motor_turn']} counts per motor turn)"
        )
        print(
            f"encoder: {encoder['counts']} counts, {encoder['glitches']} glitches, "
            f"{encoder['illegal_transitions']} illegal transitions{z}"
        )
    load = summary.get("load_encoder")
    if load is not None:
        print(
            f"load encoder: {load['counts']} counts of {load['counts_per_output_turn']} per output turn, "
            f"{load['glitches']} glitches, {load['illegal_transitions']} illegal transitions"
        )
    if summary["command_counts"] is not None:
        print(f"command: {summary['command_counts']} counts")
    if summary["speed_offset_v"] is not None:
        print(f"speed monitor: offset {1000 * summary['speed_offset_v']:.1f} mV taken at standstill")
    for note in result.notes:
        print(note)
    if args.json:
        print(f"summary written to {args.json}")
    return 0


def _hz(value: float) -> str:
    for factor, unit in ((1e6, "MHz"), (1e3, "kHz")):
        if value >= factor:
            return f"{value / factor:g} {unit}"
    return f"{value:g} Hz"
