"""Tuning a drive whose CN3 is silent while the servo is on, from the bench: what the command line
and the Tuning page share (no Qt).

- the drive's items from a parameter file (``fha-parameters/1``, front-panel values included),
  the rest at their defaults;
- the capture's signals by role (``ROLE=FILE[#CHANNEL]``, as ``bench import`` takes them):
  ``speed_monitor`` (SPD-MON, CN2-23) and ``speed_command`` (SPD-CMD, CN2-31/32);
- the frequency response from them (:mod:`.bench_response`), ``tune measure``'s JSON;
- or, where no output can drive SPD-CMD, a position-mode move (the command pulses, the encoder
  outputs, SPD-MON: ``bench import``) and the loop fitted to it (:mod:`.bench_move`).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from fha_studio.hardware.bench.capture import Capture
from fha_studio.hardware.bench.readers import read_capture
from fha_studio.hardware.bench.waveform import Waveform, read_waveform
from fha_studio.hardware.parameters import Mode, ParameterModel
from fha_studio.hardware.sim.axis import DEFAULT_SERVO_RATE_HZ
from fha_studio.logic.bench.importer import SignalSpec, parse_signal
from fha_studio.logic.tuning import bench_names
from fha_studio.logic.tuning.bench_move import MoveFitError, MoveSamples, move_fit_report
from fha_studio.logic.tuning.bench_response import BenchCapture, BenchResponseError, analyse_bench_response
from fha_studio.logic.tuning.propose import Tuner, present_items
from fha_studio.logic.tuning.session import declared_model

RESPONSE_ROLES = bench_names.RESPONSE_ROLES
MOVE_ROLES = bench_names.MOVE_ROLES


#: ``ROLE=FILE[#CHANNEL]``: a signal as ``bench import`` takes it.
RoleSignal = SignalSpec


def parse_role(text: str, roles: Sequence[str]) -> RoleSignal:
    """``ROLE=FILE[#CHANNEL]`` with ROLE one of ``roles``; BenchResponseError naming what is wrong."""
    return parse_signal(text, roles, BenchResponseError)


def bench_items(parameters: ParameterModel,
                values: Mapping[tuple[str, int], int] | None = None) -> dict[str, int]:
    """Every tune and parameter-mode item by key: the defaults, then ``values`` ((mode, number) ->
    wire value, a parameter file's or the front-panel worksheet's)."""
    items = {it.key: int(it.default) for it in parameters if it.mode in (Mode.TUNE, Mode.SYSTEM)
             and it.default is not None}
    items.update(present_items(parameters, {(Mode(m), n): v for (m, n), v in (values or {}).items()}))
    return items


def bench_tuner(actuator: str, load_inertia_kgm2: float, parameters: ParameterModel,
                values: Mapping[tuple[str, int], int] | None = None,
                quantised_feedback: bool = True) -> Tuner:
    """The declared axis with the drive's items, at the servo rate the models assume (the speed fed
    back from whole encoder pulses, as a real drive's, unless ``quantised_feedback`` is off)."""
    return Tuner(declared_model(actuator, load_inertia_kgm2), bench_items(parameters, values), parameters,
                 DEFAULT_SERVO_RATE_HZ, quantised_feedback)


def _read(path: str) -> Capture:
    try:
        return read_capture(path)
    except ValueError as exc:  # FileProblem, CaptureError: one line naming the file already
        raise BenchResponseError(str(exc)) from None


def _analog(capture: Capture, signal: RoleSignal) -> np.ndarray:
    names = list(capture.block.analog)
    channel = signal.channel
    if channel is None:
        if len(names) != 1:
            raise BenchResponseError(f"--signal {signal.role}={signal.path}: the file has "
                                     f"{len(names)} analog channels ({', '.join(names) or 'none'}): name "
                                     "one after '#'")
        channel = names[0]
    try:
        return np.asarray(capture.analog(channel), float)
    except ValueError as exc:
        raise BenchResponseError(str(exc)) from None


def response_capture(signals: Sequence[RoleSignal]) -> BenchCapture:
    """SPD-MON (and SPD-CMD) from the capture files, at one rate, cut to the shorter."""
    by_role: dict[str, RoleSignal] = {}
    for s in signals:
        if s.role in by_role:
            raise BenchResponseError(f"--signal {s.role}: given twice ({by_role[s.role].text} and {s.text})")
        by_role[s.role] = s
    if "speed_monitor" not in by_role:
        raise BenchResponseError("--signal speed_monitor=FILE[#CHANNEL] is needed: SPD-MON (CN2-23) recorded "
                                 "while the excitation played")
    captures = {s.path: _read(s.path) for s in by_role.values()}
    monitor = by_role["speed_monitor"]
    rate = captures[monitor.path].sample_rate_hz
    for s in by_role.values():
        other = captures[s.path].sample_rate_hz
        if abs(other / rate - 1.0) > 1e-9:
            raise BenchResponseError(f"{s.path}: sampled at {other:g} Hz but {monitor.path} at {rate:g} Hz: "
                                     "SPD-MON and SPD-CMD must be recorded together, at one rate")
    y = _analog(captures[monitor.path], monitor)
    u = None
    if "speed_command" in by_role:
        command = by_role["speed_command"]
        u = _analog(captures[command.path], command)
        n = min(len(u), len(y))
        u, y = u[:n], y[:n]
    return BenchCapture(rate, y, u, {s.role: s.text for s in by_role.values()})


def read_excitation(path: str) -> Waveform:
    try:
        return read_waveform(path)
    except ValueError as exc:
        raise BenchResponseError(str(exc)) from None


def bench_response_report(tuner: Tuner, signals: Sequence[RoleSignal], excitation: str | None = None,
                          monitor_bandwidth_hz: float | None = None) -> dict[str, Any]:
    """``tune analyse``'s JSON for a frequency response from the bench."""
    capture = response_capture(signals)
    wave = read_excitation(excitation) if excitation else None
    result = analyse_bench_response(tuner, capture, wave, monitor_bandwidth_hz)
    if excitation:
        result["bench"]["excitation_file"] = excitation
    return result


def is_move(signals: Sequence[RoleSignal]) -> bool:
    """True when the signals are a move's (no SPD-CMD: the encoder and the command pulses)."""
    roles = {s.role for s in signals}
    return "speed_command" not in roles and bool(roles & {"encoder_a", "command_a"})


def move_samples(tuner: Tuner, signals: Sequence[RoleSignal],
                 values: Mapping[tuple[str, int], int]) -> MoveSamples:
    """The move in the capture files, imported as ``bench import`` does (parameters 1, 2, 3, 4 and
    9 from ``values``) and resampled to the servo rate."""
    from fha_studio.logic.bench.importer import (
        AxisFacts,
        BenchImportError,
        DriveSettings,
        import_bench,
    )

    if int(tuner.items.get("control_mode", 0)) != 0:
        raise BenchResponseError("parameter 0 (control mode) is speed: a move by command pulses needs "
                                 "position mode (in speed mode give the SPD-CMD excitation's capture)")
    missing = [r for r in ("encoder_a", "encoder_b", "command_a") if r not in {s.role for s in signals}]
    if missing:
        raise BenchResponseError(f"a move needs {', '.join(missing)} too: the encoder outputs and the "
                                 "command pulses, captured together")
    try:
        settings = DriveSettings.from_values({(str(m), n): v for (m, n), v in values.items()})
        result = import_bench(signals, AxisFacts.for_actuator(tuner.model.actuator_code), settings,
                              output_rate_hz=tuner.servo_rate_hz)
    except BenchImportError as exc:
        raise BenchResponseError(str(exc)) from None
    try:
        return MoveSamples.from_recording(result.recording, tuner.servo_rate_hz, tuner.model.output_pulse_rad)
    except MoveFitError as exc:
        raise BenchResponseError(str(exc)) from None


def bench_move_report(tuner: Tuner, signals: Sequence[RoleSignal],
                      values: Mapping[tuple[str, int], int]) -> dict[str, Any]:
    """``tune analyse``'s JSON for a move captured on the bench: the loop fitted to it."""
    result = move_fit_report(tuner, move_samples(tuner, signals, values))
    result["bench"] = {"sources": {s.role: s.text for s in signals}}
    return result
