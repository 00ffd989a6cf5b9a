"""A bench capture of the drive's CN2 signals made into a recording (``fha-studio bench import``).

The technician maps channels of capture files to the drive's signals (*roles*, :data:`ROLES`);
the signals are decoded (:mod:`.decode`) at the capture's rate and the recording is taken from
them at :data:`OUTPUT_RATE_HZ` (or the capture's rate if lower):

- ``pos`` [deg, output]: the encoder counts (x4) / (counts per motor turn x ratio) x 360; without
  an encoder, SPD-MON integrated (the metadata says so);
- ``cmd_pos`` [deg]: the command pulses through parameters 1, 2, 3, 4, in the same counts;
- ``vel`` [r/min, output]: SPD-MON by parameter 9, less its offset at standstill, / ratio, the
  mean over one output interval centred on the sample's instant (the instant ``pos`` is taken);
- ``alm_code``: the alarm code lines ALM-A ... ALM-D (roles ``alm_a`` ... ``alm_d``) as the 4-bit
  code (D C B A, ON = 1; 13 = 1101, the encoder alarms), the summary naming each code that came,
  when, and the alarms of the HA-655's table it can be;
- ``in_pos`` (1 = on), ``alarm`` (1 = on) and ``current`` [A] = probe volts x A per V, the mean
  over the same centred interval, only where a probe measured it;
- ``load_pos`` [deg, output]: an external encoder on the output flange (roles ``load_encoder_a``,
  ``load_encoder_b``; not a CN2 signal: the bench's own), counted x4 at the counts per output turn
  the technician states: the load after the gear's wind-up, kinematic error and lost motion.

Each column's source (file, channel, scale) is named in the recording's metadata
(``source_<column>``). The recording is an ``fha-recording/2`` file when it has no current.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from fha_studio.hardware.bench.capture import Capture
from fha_studio.hardware.bench.readers import on_grid, read_capture
from fha_studio.logic.bench import decode
from fha_studio.logic.bench.alarm_code import LINES, alarms_of_code
from fha_studio.logic.bench.edges import Lines
from fha_studio.recording import Recording, RecordingMetadata, make_recording

ROLES = (
    "speed_monitor",
    "encoder_a",
    "encoder_b",
    "encoder_z",
    "command_a",
    "command_b",
    "in_position",
    "alarm",
    "alm_a",
    "alm_b",
    "alm_c",
    "alm_d",
    "current_probe",
    "load_encoder_a",
    "load_encoder_b",
)
#: The alarm code lines ALM-A ... ALM-D (ON = 1): bit 0 ... bit 3 of the 4-bit code written D C B A.
ALM_ROLES = ("alm_a", "alm_b", "alm_c", "alm_d")
#: The recording's rate, when the capture is faster (the scope's and the model check's 1 kHz).
OUTPUT_RATE_HZ = 1000.0
#: (mode, number) of the parameter items the decoding reads, and what each is
PARAMETERS = {
    ("system", 1): "parameter 1 (command pulse form)",
    ("system", 2): "parameter 2 (multiplication of the two-phase pulse input)",
    ("system", 3): "parameter 3 (electronic gear numerator)",
    ("system", 4): "parameter 4 (electronic gear denominator)",
    ("system", 9): "parameter 9 (speed conversion factor, r/min at +10 V)",
}


class BenchImportError(ValueError):
    """Bad input for an import: one line naming what and where."""


@dataclass(frozen=True)
class SignalSpec:
    """``ROLE=FILE[#CHANNEL]``."""

    role: str
    path: str
    channel: str | None = None

    @property
    def text(self) -> str:
        return f"{self.path}#{self.channel}" if self.channel else self.path


def parse_signal(text: str, roles: Sequence[str] = ROLES,
                 error: type[ValueError] = BenchImportError) -> SignalSpec:
    """``ROLE=FILE[#CHANNEL]`` with ROLE one of ``roles`` -> SignalSpec; ``error`` (BenchImportError)
    naming what is wrong. ``bench import`` and ``tune analyse`` take their signals so."""
    role, sep, rest = text.partition("=")
    role = role.strip()
    if not sep or not rest:
        raise error(f"--signal '{text}': expected ROLE=FILE or ROLE=FILE#CHANNEL")
    if role not in roles:
        raise error(f"--signal '{text}': unknown role '{role}' (roles: {', '.join(roles)})")
    path, hash_, channel = rest.rpartition("#") if "#" in rest else (rest, "", "")
    if hash_ and not channel:
        raise error(f"--signal '{text}': no channel after '#'")
    if not path:
        raise error(f"--signal '{text}': no file before '#'")
    return SignalSpec(role, path, channel or None)


@dataclass(frozen=True)
class DriveSettings:
    """The drive's parameters the decoding needs (wire values of the HA-655's items)."""

    pulse_form: int
    multiplication: int
    gear_numerator: int
    gear_denominator: int
    speed_conversion_rpm: float

    @classmethod
    def from_values(
        cls, values: Mapping[tuple[str, int], int], where: str = "the parameters"
    ) -> DriveSettings:
        missing = [text for key, text in PARAMETERS.items() if key not in values]
        if missing:
            raise BenchImportError(
                f"{where}: {', '.join(missing)} not given; they are needed to decode the capture"
            )
        return cls(
            int(values[("system", 1)]),
            int(values[("system", 2)]),
            int(values[("system", 3)]),
            int(values[("system", 4)]),
            float(values[("system", 9)]),
        )


@dataclass(frozen=True)
class AxisFacts:
    """What the actuator's catalogue entry says about the counts."""

    actuator: str
    ratio: int
    counts_per_motor_turn: int
    supply_voltage: int

    @property
    def counts_per_output_turn(self) -> int:
        return self.counts_per_motor_turn * self.ratio

    @classmethod
    def for_actuator(cls, code: str) -> AxisFacts:
        from fha_studio.catalog import get_actuator
        from fha_studio.catalog.tables import encoder_resolution_table

        try:
            actuator = get_actuator(code)
        except (ValueError, KeyError, LookupError) as exc:
            raise BenchImportError(f"--actuator {code}: {exc}") from None
        counts = encoder_resolution_table(actuator.encoder).counts_per_motor_rev
        return cls(actuator.model_code, int(actuator.ratio), int(counts), int(actuator.supply_voltage))


@dataclass(frozen=True)
class Decoded:
    """The signals decoded per capture sample (what the recording is taken from)."""

    sample_rate_hz: float
    samples: int
    encoder: decode.QuadratureResult | None = None
    z: decode.ZCheck | None = None
    command: decode.CommandPulseResult | None = None
    speed: decode.SpeedResult | None = None
    load_encoder: decode.QuadratureResult | None = None


@dataclass(frozen=True)
class BenchImport:
    recording: Recording
    summary: dict[str, Any]
    decoded: Decoded
    notes: list[str] = field(default_factory=list)


Loader = Callable[[str], Capture]


def import_bench(
    signals: Sequence[SignalSpec],
    axis: AxisFacts,
    settings: DriveSettings,
    *,
    current_scale_a_per_v: float | None = None,
    output_rate_hz: float = OUTPUT_RATE_HZ,
    loader: Loader | None = None,
    load_counts_per_turn: int | None = None,
) -> BenchImport:
    """Decode the mapped signals and make the recording; BenchImportError for bad input.
    ``load_counts_per_turn``: the external load encoder's counts per output turn (x4), needed with
    the roles ``load_encoder_a`` and ``load_encoder_b``."""
    load = loader or _read
    roles: dict[str, SignalSpec] = {}
    for spec in signals:
        if spec.role in roles:
            raise BenchImportError(
                f"--signal {spec.role}: given twice ({roles[spec.role].text} and {spec.text})"
            )
        roles[spec.role] = spec
    if not roles:
        raise BenchImportError("no --signal given: map at least the encoder or the speed monitor")
    if "current_probe" in roles and current_scale_a_per_v is None:
        raise BenchImportError(
            "--signal current_probe needs --current-scale A_PER_V (the probe's amperes per volt)"
        )
    for need, other in (
        ("encoder_a", "encoder_b"),
        ("encoder_b", "encoder_a"),
        ("load_encoder_a", "load_encoder_b"),
        ("load_encoder_b", "load_encoder_a"),
    ):
        if need in roles and other not in roles:
            raise BenchImportError(
                f"--signal {need} without {other}: the encoder is counted from both phases"
            )
    if "load_encoder_a" in roles and not load_counts_per_turn:
        raise BenchImportError(
            "--signal load_encoder_a needs --load-encoder-counts COUNTS (the load encoder's counts per "
            "output turn, x4)"
        )
    if "encoder_z" in roles and "encoder_a" not in roles:
        raise BenchImportError(
            "--signal encoder_z needs encoder_a and encoder_b (Z is checked against counts)"
        )
    if "command_b" in roles and "command_a" not in roles:
        raise BenchImportError("--signal command_b without command_a")
    if "encoder_a" not in roles and "speed_monitor" not in roles:
        raise BenchImportError(
            "neither the encoder (encoder_a, encoder_b) nor the speed monitor "
            "(speed_monitor) is mapped: the recording needs one of them for its position"
        )
    captures: dict[str, Capture] = {}
    for spec in roles.values():
        if spec.path not in captures:
            captures[spec.path] = load(spec.path)
    grid_notes = _on_one_grid(captures)
    rates = {path: c.sample_rate_hz for path, c in captures.items()}
    first_path, rate = next(iter(rates.items()))
    for path, r in rates.items():
        if abs(r / rate - 1.0) > 1e-9:
            raise BenchImportError(
                f"{path}: sampled at {decode._hz(r)} but {first_path} at {decode._hz(rate)}: "
                "the signals of one import must come at one rate"
            )
    n = min(c.samples for c in captures.values())
    if n < 2:
        raise BenchImportError(f"{first_path}: fewer than 2 samples")
    channel_of = {role: _channel(captures[spec.path], spec) for role, spec in roles.items()}

    def lines(*of: str) -> Lines:
        """The roles' lines as lines 0, 1, ...: from one packed word when they share one."""
        paths = {roles[role].path for role in of}
        block = captures[roles[of[0]].path].block
        if len(paths) == 1 and all(channel_of[role] in block.logic_channels for role in of):
            bits = [block.logic_channels.index(channel_of[role]) for role in of]
            return Lines.from_packed(block.logic[:n], *bits)
        if len(of) > 1:
            return Lines.merge(*(lines(role) for role in of))
        return Lines.from_levels(captures[roles[of[0]].path].logic(channel_of[of[0]])[:n])

    def analog(role: str) -> np.ndarray:
        return captures[roles[role].path].analog(channel_of[role])[:n]

    encoder = z = command = speed = None
    if "encoder_a" in roles:
        encoder = decode.quadrature_lines(lines("encoder_a", "encoder_b"))
        if "encoder_z" in roles:
            z = decode.z_check_lines(lines("encoder_z"), encoder.steps, axis.counts_per_motor_turn)
    if "speed_monitor" in roles:
        still = decode.standstill_mask_at(n, encoder.steps.at, rate) if encoder is not None else None
        speed = decode.speed_from_monitor(analog("speed_monitor"), settings.speed_conversion_rpm, still)
    # the edge rate at the speed reached: refused before anything is trusted
    if encoder is not None:
        if speed is not None:
            window = max(1, int(rate * 1e-3))
            peak = _peak_mean(speed.motor_rpm, window)
        else:
            peak = decode.peak_rpm_from_steps(encoder.steps, rate, axis.counts_per_motor_turn)
        try:
            decode.check_edge_rate(rate, peak, axis.counts_per_motor_turn)
        except decode.DecodeError as exc:
            raise BenchImportError(f"{roles['encoder_a'].path}: {exc}") from None
    if "command_a" in roles:
        has_b = "command_b" in roles
        command_lines = lines("command_a", "command_b") if has_b else lines("command_a")
        try:
            command = decode.command_pulse_lines(
                command_lines,
                has_b,
                settings.pulse_form,
                settings.multiplication,
                settings.gear_numerator,
                settings.gear_denominator,
            )
        except decode.DecodeError as exc:
            raise BenchImportError(str(exc)) from None
    load_encoder = None
    if "load_encoder_a" in roles:
        load_encoder = decode.quadrature_lines(lines("load_encoder_a", "load_encoder_b"))
    decoded = Decoded(rate, n, encoder, z, command, speed, load_encoder)
    result = _make(
        decoded,
        roles,
        channel_of,
        axis,
        settings,
        current_scale_a_per_v,
        output_rate_hz,
        load_counts_per_turn,
        {role: analog(role) for role in ("current_probe",) if role in roles},
        {role: lines(role) for role in ("in_position", "alarm", *ALM_ROLES) if role in roles},
    )
    result.notes[:0] = grid_notes
    return result


def _on_one_grid(captures: dict[str, Capture]) -> list[str]:
    """Files of changes (a logic analyzer's digital export, VCD) sampled at the rate of the one
    file of samples at a fixed rate beside them (its analog export, an oscilloscope's CSV), from
    that file's start: an instrument writes its digital and analog channels apart. What was done,
    in a note per file."""
    sampled = [(path, c) for path, c in captures.items() if not c.changes]
    if not sampled or any(abs(c.sample_rate_hz / sampled[0][1].sample_rate_hz - 1.0) > 1e-9
                          for _, c in sampled):
        return []  # nothing to line up with, or files of two fixed rates: refused below
    ref_path, ref = sampled[0]
    notes = []
    for path, capture in list(captures.items()):
        if capture.changes and abs(capture.sample_rate_hz / ref.sample_rate_hz - 1.0) > 1e-9:
            captures[path] = on_grid(capture, ref.sample_rate_hz, ref.start_s, ref.samples)
            notes.append(f"{path}: its changes sampled at {decode._hz(ref.sample_rate_hz)} from "
                         f"{ref.start_s:.9g} s, as {ref_path}")
    return notes


def _read(path: str) -> Capture:
    try:
        return read_capture(path)
    except ValueError as exc:  # FileProblem, CaptureError: one line naming the file already
        raise BenchImportError(str(exc)) from None


def _channel(capture: Capture, spec: SignalSpec) -> str:
    if spec.channel is not None:
        if not capture.has(spec.channel):
            raise BenchImportError(
                f"--signal {spec.role}={spec.text}: {spec.path} has no channel "
                f"'{spec.channel}' (it has {', '.join(capture.channels)})"
            )
        return spec.channel
    if len(capture.channels) == 1:
        return capture.channels[0]
    raise BenchImportError(
        f"--signal {spec.role}={spec.path}: the file has {len(capture.channels)} channels "
        f"({', '.join(capture.channels)}); name one as {spec.role}={spec.path}#CHANNEL"
    )


def _peak_mean(values: np.ndarray, window: int) -> float:
    """The largest |mean| over consecutive windows (noise averaged out)."""
    m = values.shape[0] // window
    if m == 0:
        return float(np.max(np.abs(values))) if values.size else 0.0
    means = values[: m * window].astype(np.float64).reshape(m, window).mean(axis=1)
    return float(np.max(np.abs(means)))


def _centred_means(values: np.ndarray, idx: np.ndarray, n: int, step: float) -> np.ndarray:
    """Mean of ``values`` over a window of one output interval centred on each ``idx[k]`` (cut at
    the capture's ends): an analog channel decimated without aliasing and without a lag against
    the positions, which are taken at the instant ``idx[k]`` (a window starting there made the
    speed lead the position by half an interval, 0.5 ms at 1 kHz)."""
    window = max(1, round(step))
    csum = np.concatenate(([0.0], np.cumsum(values, dtype=np.float64)))
    starts = np.clip(idx - window // 2, 0, n - 1)
    ends = np.clip(idx - window // 2 + window, starts + 1, n)
    means: np.ndarray = (csum[ends] - csum[starts]) / (ends - starts)
    return means


def _make(
    decoded: Decoded,
    roles: Mapping[str, SignalSpec],
    channel_of: Mapping[str, str],
    axis: AxisFacts,
    settings: DriveSettings,
    current_scale: float | None,
    output_rate_hz: float,
    load_counts_per_turn: int | None,
    analog: Mapping[str, np.ndarray],
    logic: Mapping[str, Lines],
) -> BenchImport:
    rate, n = decoded.sample_rate_hz, decoded.samples
    out_rate = min(output_rate_hz, rate)
    step = rate / out_rate
    idx = np.unique(np.floor(np.arange(0, n, step)).astype(np.int64))
    idx = idx[idx < n]
    deg_per_count = 360.0 / axis.counts_per_output_turn
    columns: dict[str, np.ndarray] = {"t": idx / rate}
    sources: dict[str, str] = {}
    notes: list[str] = []

    def src(role: str) -> str:
        return f"{roles[role].path}#{channel_of[role]}"

    if decoded.encoder is not None:
        columns["pos"] = decoded.encoder.steps.sample(idx) * deg_per_count
        sources["pos"] = (
            f"{src('encoder_a')} and {src('encoder_b')}, x4, {axis.counts_per_output_turn} counts "
            f"per output turn ({axis.counts_per_motor_turn} per motor turn x {axis.ratio})"
        )
    elif decoded.speed is not None:
        out_rpm = decoded.speed.motor_rpm.astype(np.float64) / axis.ratio
        turns = np.concatenate(([0.0], np.cumsum(out_rpm[:-1]))) / 60.0 / rate
        columns["pos"] = turns[idx] * 360.0
        sources["pos"] = f"{src('speed_monitor')} integrated (no encoder mapped)"
        notes.append("pos is the speed monitor integrated: no encoder was mapped")
    if decoded.load_encoder is not None and load_counts_per_turn:
        columns["load_pos"] = decoded.load_encoder.steps.sample(idx) * (360.0 / load_counts_per_turn)
        sources["load_pos"] = (
            f"{src('load_encoder_a')} and {src('load_encoder_b')}, x4, {load_counts_per_turn} counts per "
            "output turn (an external encoder on the output flange)"
        )
    if decoded.command is not None:
        columns["cmd_pos"] = decoded.command.count_steps.sample(idx) * deg_per_count
        line_b = f" and {src('command_b')}" if "command_b" in roles else ""
        sources["cmd_pos"] = (
            f"{src('command_a')}{line_b}, {decode.PULSE_FORMS[settings.pulse_form]}"
            + (f" x{settings.multiplication}" if settings.pulse_form == 2 else "")
            + f", electronic gear {settings.gear_numerator}/{settings.gear_denominator}"
        )
    if decoded.speed is not None:
        columns["vel"] = _centred_means(decoded.speed.motor_rpm, idx, n, step) / axis.ratio
        sources["vel"] = (
            f"{src('speed_monitor')}, +10 V = {settings.speed_conversion_rpm:g} r/min motor "
            f"(parameter 9) / {axis.ratio}, offset {decoded.speed.offset_v * 1000:.1f} mV"
        )
    if "in_position" in logic:
        columns["in_pos"] = logic["in_position"].level_at(idx).astype(np.float64)
        sources["in_pos"] = f"{src('in_position')}, high = on"
    if "alarm" in logic:
        columns["alarm"] = logic["alarm"].level_at(idx).astype(np.float64)
        sources["alarm"] = f"{src('alarm')}, high = on"
    alarm_codes: list[dict[str, Any]] = []
    if any(role in logic for role in ALM_ROLES):
        columns["alm_code"], sources["alm_code"], alarm_codes = _alarm_code(logic, idx, columns["t"], src)
    if "current_probe" in analog and current_scale is not None:
        columns["current"] = _centred_means(analog["current_probe"], idx, n, step) * current_scale
        sources["current"] = f"{src('current_probe')}, {current_scale:g} A/V"
    extra = {f"source_{name}": text for name, text in sources.items()}
    extra["recorded_by"] = "fha-studio bench import"
    metadata = RecordingMetadata(
        actuator=axis.actuator,
        load_inertia_kgm2=None,
        supply_voltage=axis.supply_voltage,
        sample_rate_hz=out_rate,
        extra=extra,
    )
    recording = make_recording(metadata, **columns)
    summary = _summary(
        decoded, roles, channel_of, axis, settings, current_scale, sources, len(idx), load_counts_per_turn
    )
    if alarm_codes or "alm_code" in columns:
        summary["alarm_codes"] = alarm_codes
    return BenchImport(recording, summary, decoded, notes)


def _alarm_code(logic: Mapping[str, Lines], idx: np.ndarray, t: np.ndarray,
                src: Callable[[str], str]) -> tuple[np.ndarray, str, list[dict[str, Any]]]:
    """The 4-bit code of ALM-D C B A at each output sample (a line not mapped counts 0), where it
    says so, and each code that came: when first, written D C B A, and the alarms it can be
    (the HA-655's table: 1101 is every encoder alarm, 50 ... 57)."""
    code = np.zeros(idx.size, np.int64)
    for bit, role in enumerate(ALM_ROLES):
        if role in logic:
            code |= logic[role].level_at(idx).astype(np.int64) << bit
    mapped = [f"{LINES[bit]} {src(role)}" for bit, role in enumerate(ALM_ROLES) if role in logic]
    missing = [LINES[bit] for bit, role in enumerate(ALM_ROLES) if role not in logic]
    source = "D C B A, ON = 1: " + ", ".join(mapped)
    if missing:
        source += f" ({', '.join(missing)} not mapped: 0)"
    seen: list[dict[str, Any]] = []
    changes = np.flatnonzero(np.diff(code, prepend=0) != 0)
    for at in changes:
        value = int(code[at])
        if value and all(item["alm_code"] != f"{value:04b}" for item in seen):
            seen.append({"alm_code": f"{value:04b}", "first_s": float(t[at]),
                         "alarms": [f"{a.code} {a.name}" for a in alarms_of_code(value, unmapped=missing)]})
    return code.astype(np.float64), source, seen


def _summary(
    decoded: Decoded,
    roles: Mapping[str, SignalSpec],
    channel_of: Mapping[str, str],
    axis: AxisFacts,
    settings: DriveSettings,
    current_scale: float | None,
    sources: Mapping[str, str],
    rows: int,
    load_counts_per_turn: int | None = None,
) -> dict[str, Any]:
    per_role: dict[str, dict[str, Any]] = {}
    for role, spec in roles.items():
        scale: float | None
        unit: str
        if role in ("encoder_a", "encoder_b", "encoder_z"):
            scale, unit = float(axis.counts_per_output_turn), "counts per output turn (x4)"
        elif role in ("command_a", "command_b"):
            scale = settings.gear_numerator / settings.gear_denominator
            unit = (
                f"counts per command pulse ({decode.PULSE_FORMS[settings.pulse_form]}, "
                f"x{settings.multiplication}, electronic gear)"
            )
        elif role == "speed_monitor":
            scale = settings.speed_conversion_rpm / decode.MONITOR_FULL_SCALE_V
            unit = "motor r/min per V"
        elif role == "current_probe":
            scale, unit = current_scale, "A per V"
        elif role in ("load_encoder_a", "load_encoder_b"):
            scale, unit = float(load_counts_per_turn or 0), "counts per output turn (x4), on the load"
        else:
            scale, unit = None, "logic, high = on"
        per_role[role] = {
            "source": f"{spec.path}#{channel_of[role]}",
            "file": os.fspath(spec.path),
            "channel": channel_of[role],
            "scale": scale,
            "scale_unit": unit,
        }
    summary: dict[str, Any] = {
        "samples": decoded.samples,
        "duration_s": decoded.samples / decoded.sample_rate_hz,
        "sample_rate_hz": decoded.sample_rate_hz,
        "roles": per_role,
        "encoder": None,
        "command_counts": None,
        "speed_offset_v": None,
        "recording": {"rows": rows, "sources": dict(sources)},
    }
    if decoded.encoder is not None:
        summary["encoder"] = {
            "counts": decoded.encoder.total_counts,
            "glitches": decoded.encoder.glitches,
            "illegal_transitions": decoded.encoder.illegal_transitions,
            "z_pulses": decoded.z.pulses if decoded.z else None,
            "z_count_errors": decoded.z.count_errors if decoded.z else None,
            "counts_per_motor_turn": axis.counts_per_motor_turn,
        }
    if decoded.load_encoder is not None:
        summary["load_encoder"] = {
            "counts": decoded.load_encoder.total_counts,
            "glitches": decoded.load_encoder.glitches,
            "illegal_transitions": decoded.load_encoder.illegal_transitions,
            "counts_per_output_turn": load_counts_per_turn,
        }
    if decoded.command is not None:
        final = float(decoded.command.count_steps.final)
        summary["command_counts"] = int(final) if math.isclose(final, round(final)) else final
    if decoded.speed is not None:
        summary["speed_offset_v"] = decoded.speed.offset_v
    return summary
