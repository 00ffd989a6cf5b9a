"""``fha-studio bench devices`` and ``fha-studio bench record``: live bench instruments through
sigrok-cli (added to ``fha-studio bench`` by :mod:`fha_studio.cli.bench`).

``bench record`` exits 2 with one line for bad input (a role, channel, device or rate), and 3 with
one line when the instrument vanishes mid-stream; what it sent before is written all the same.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import replace
from typing import Any

from fha_studio import fileio
from fha_studio.cli import CliError
from fha_studio.cli._bench_common import finite, parameter_values
from fha_studio.cli._values import in_range, output_path
from fha_studio.plausible import CURRENT_PROBE_A_PER_V, Range

#: Exit status when the instrument went away mid-stream (the partial recording is kept).
EXIT_VANISHED = 3
RECORD_SECONDS = Range("recording time", 0.0, 3600.0, "s", "a live recording is held in memory",
                       open_minimum=True)
SAMPLE_RATE_HZ = Range("sample rate", 0.0, 1e10, "Hz", "what a bench instrument samples at",
                       open_minimum=True)


def add_devices(commands: argparse._SubParsersAction) -> None:
    p = commands.add_parser(
        "devices",
        help="the bench instruments sigrok-cli finds (logic analyzers, oscilloscopes, DAQs)",
        description="List what `sigrok-cli --scan` finds: each instrument's driver (with its "
        "connection, as --device takes it) and its channels.",
    )
    p.add_argument("--driver", metavar="DRIVER[:OPTIONS]",
                   help="scan only this driver, e.g. fx2lafw or demo:analog_channels=2")
    p.add_argument("--json", action="store_true", help="print the devices as JSON")
    p.set_defaults(func=run_devices)


def _sigrok_error(exc: Exception) -> CliError:
    return CliError(str(exc))


def run_devices(args: argparse.Namespace) -> int:
    from fha_studio.hardware.bench import sigrok

    try:
        devices = sigrok.scan(args.driver)
    except sigrok.SigrokError as exc:
        raise _sigrok_error(exc) from None
    if args.json:
        print(json.dumps([{"device": d.spec, "driver": d.driver, "options": d.options,
                           "description": d.description, "channels": list(d.channels),
                           "logic_channels": list(d.logic_channels),
                           "analog_channels": list(d.analog_channels)} for d in devices], indent=2))
        return 0
    if not devices:
        print("sigrok-cli finds no instrument (is it plugged in, and may this user open it?)")
        return 0
    for d in devices:
        kinds = []
        if d.logic_channels:
            kinds.append(f"logic {' '.join(d.logic_channels)}")
        if d.analog_channels:
            kinds.append(f"analog {' '.join(d.analog_channels)}")
        print(f"{d.spec}: {d.description}; {'; '.join(kinds) or 'no channels'}")
    return 0


def add_record(commands: argparse._SubParsersAction) -> None:
    from fha_studio.logic.bench.importer import ROLES

    p = commands.add_parser(
        "record",
        help="record the drive's CN2 signals live from a bench instrument (through sigrok-cli)",
        description="Stream the mapped channels of one instrument for a set time. With --actuator and "
        "--parameters the signals are decoded as `bench import` decodes files, into an fha-recording; "
        "without them the raw channels are written as sigrok-cli's CSV (for `bench import` later). "
        "One instrument records logic channels or analog ones. Exit 3 when the instrument goes away: "
        "what it sent is written all the same.",
    )
    p.add_argument("--device", required=True, metavar="DRIVER[:OPTIONS]",
                   help="the instrument, as `fha-studio bench devices` names it (e.g. fx2lafw, demo)")
    p.add_argument("--signal", action="append", default=[], metavar="ROLE=CHANNEL",
                   help=f"a signal and the instrument's channel it is wired to; ROLE is one of "
                   f"{', '.join(ROLES)}")
    p.add_argument("--seconds", required=True, type=in_range(RECORD_SECONDS), metavar="S",
                   help="how long to record")
    p.add_argument("--rate", type=in_range(SAMPLE_RATE_HZ), metavar="HZ",
                   help="the sample rate (default: the instrument's own setting)")
    p.add_argument("--actuator", metavar="CODE", help="the actuator's model code (to decode)")
    p.add_argument("--parameters", metavar="PARAMS.toml", help="the drive's parameter file (to decode)")
    p.add_argument("--current-scale", type=in_range(CURRENT_PROBE_A_PER_V), metavar="A_PER_V",
                   help="the current probe's amperes per volt (with --signal current_probe=...)")
    p.add_argument("-o", "--output", required=True, type=output_path, metavar="RECORDING.csv",
                   help="the recording to write")
    p.add_argument("--json", type=output_path, metavar="SUMMARY.json", help="write the summary as JSON")
    p.set_defaults(func=run_record)


def run_record(args: argparse.Namespace) -> int:
    from fha_studio.hardware.bench import sigrok
    from fha_studio.hardware.bench.writers import write_sigrok_csv
    from fha_studio.logic.bench.importer import (
        AxisFacts,
        BenchImportError,
        DriveSettings,
        SignalSpec,
        import_bench,
    )
    from fha_studio.logic.bench.live import check_signals, parse_live_signal, record_live
    from fha_studio.recording import write_recording

    if (args.actuator is None) != (args.parameters is None):
        given, other = ("--actuator", "--parameters") if args.actuator else ("--parameters", "--actuator")
        raise CliError(f"{given} without {other}: both are needed to decode the signals")
    try:
        roles = check_signals([parse_live_signal(text) for text in args.signal])
        if "current_probe" in roles and args.current_scale is None:
            raise BenchImportError("--signal current_probe needs --current-scale A_PER_V")
        decoding = None
        if args.actuator is not None:
            decoding = (AxisFacts.for_actuator(args.actuator),
                        DriveSettings.from_values(parameter_values(args.parameters), args.parameters))
    except BenchImportError as exc:
        raise CliError(str(exc)) from None
    try:
        live = record_live(args.device, roles, args.seconds, args.rate)
    except sigrok.DeviceVanished as exc:  # before any sample came: nothing to keep
        print(f"fha-studio bench: {exc}", file=sys.stderr)
        return EXIT_VANISHED
    except sigrok.SigrokError as exc:
        raise _sigrok_error(exc) from None
    capture = live.capture
    origin = f"{args.device} through sigrok-cli (fha-studio bench record)"
    summary: dict[str, Any] = {"device": args.device, "complete": live.complete,
                               "seconds_asked": args.seconds}
    decoded_note = ""
    if decoding is not None:
        specs = [SignalSpec(role, args.device, channel) for role, channel in roles.items()]
        try:
            result = import_bench(specs, *decoding, current_scale_a_per_v=args.current_scale,
                                  loader=lambda _path: capture)
        except BenchImportError as exc:
            if live.complete:
                raise CliError(str(exc)) from None
            decoded_note = f" (not decoded: {exc})"
            result = None
        if result is not None:
            metadata = result.recording.metadata
            recording = replace(result.recording, metadata=replace(
                metadata, extra={**metadata.extra, "recorded_by": "fha-studio bench record"}))
            write_recording(args.output, recording)
            summary.update(result.summary)
            what = f"decoded into {args.output}: columns {', '.join(result.recording.channels)}"
        else:
            write_sigrok_csv(args.output, capture.block, source=origin)
            what = f"written raw to {args.output}{decoded_note}"
    else:
        write_sigrok_csv(args.output, capture.block, source=origin)
        what = (f"written raw to {args.output} (channels {', '.join(capture.channels)}; decode with "
                "fha-studio bench import, or record with --actuator and --parameters)")
    summary.update({"samples": capture.samples, "duration_s": capture.samples / capture.sample_rate_hz,
                    "sample_rate_hz": capture.sample_rate_hz,
                    "channels": {role: channel for role, channel in roles.items()}})
    if args.json:
        fileio.write_text(args.json, json.dumps(finite(summary), indent=2) + "\n")
    print(f"{capture.samples} samples at {sigrok.rate_text(capture.sample_rate_hz)} "
          f"({summary['duration_s']:.4g} s) from {args.device} {what}")
    if not live.complete:
        print(f"fha-studio bench: {live.vanished}; the {capture.samples} samples before are kept in "
              f"{args.output}", file=sys.stderr)
        return EXIT_VANISHED
    return 0
