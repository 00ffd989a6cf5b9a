"""Current-less recordings made the way a technician makes them on a real HA-655, on the simulated
drive: its hidden effects given as ``sim://...&effects=...``, a move program sent as the
controller's command pulses (CN2; CN3 stays silent in motion), the CN2 outputs sampled by the
virtual bench instrument (a logic analyzer) into a sigrok session file, and that file decoded by
``bench import`` (``import_bench``) into a recording without a current column. The technician then
declares the load inertia (as the Model check page does) and runs the model check.

The test knows the truth (the effects it hid); the model check sees only the recording.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.hardware.sim.cn2 import VirtualBenchInstrument
from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.hardware.sim.io import BIT_BRAKE_RELEASED
from fha_studio.logic.bench.importer import AxisFacts, DriveSettings, SignalSpec, import_bench
from fha_studio.logic.paramfile import dump_parameter_file
from fha_studio.recording import Recording, read_recording, write_recording

#: the logic analyzer's lines on CN2
ROLES = {
    "encoder_a": "ENC_A",
    "encoder_b": "ENC_B",
    "command_a": "CMD_A",
    "command_b": "CMD_B",
    "in_position": "IN_POS",
}
PARAMETERS = {
    1: "command_pulse_configuration",
    2: "two_phase_pulse_multiplication",
    3: "electronic_gear_numerator",
    4: "electronic_gear_denominator",
    9: "speed_conversion_factor",
}
#: the ALARM line, recorded when a case ends in an alarm (the axis then coasts)
ALARM_ROLES = {"alarm": "ALARM"}
#: the alarm raised at speed (60: the deviation counter overflowed, as a blocked or runaway axis trips it)
COAST_ALARM = 60
#: the lines of an external encoder on the output flange, when the bench has one
LOAD_ROLES = {"load_encoder_a": "LOAD_A", "load_encoder_b": "LOAD_B"}
#: its counts per output turn (x4): a 131072-line encoder, 2.5 arcsec a count
LOAD_COUNTS_PER_TURN = 1 << 19
#: samples per encoder edge at the program's top speed (the instrument refuses fewer than 2)
SAMPLES_PER_EDGE = 2.2


@dataclass(frozen=True)
class BenchAxis:
    """An actuator, its load, and the tune items the drive runs (``preset``: mode.number=value)."""

    code: str
    load_kgm2: float
    preset: str = ""
    #: the program's top speed (output r/min): the instrument's rate follows it
    top_rpm: float = 15.0

    @property
    def name(self) -> str:
        return f"{self.code}-{self.load_kgm2:g}kgm2"


@dataclass(frozen=True)
class BenchCase:
    axis: BenchAxis
    effects: dict[str, dict[str, float]] = field(default_factory=dict)
    load_encoder: bool = False  # an external encoder on the output flange
    #: after the program, a move at ``coast_rpm`` (output r/min), an alarm at that speed and this
    #: much more recorded while the de-energised axis coasts (0: no alarm, no ALARM line recorded)
    coast_s: float = 0.0
    coast_rpm: float = 0.0
    #: the controller drops the brake's 24 V with the alarm (an actuator with the brake option)
    brake: bool = False
    #: after the coast the alarm is cleared, the servo turned on again and the same done the other way
    both_ways: bool = False
    catalogue_friction: bool = False

    @property
    def name(self) -> str:
        name = f"{self.axis.name}-{'+'.join(self.effects) or 'none'}{'-loadenc' if self.load_encoder else ''}"
        if self.catalogue_friction:
            name += "-catalogue"
        if self.coast_s:
            name += f"-coast{self.coast_s:g}s-{self.coast_rpm:g}rpm{'-brake' if self.brake else ''}"
            name += "-both-ways" if self.both_ways else ""
        return name

    def url(self) -> str:
        url = f"sim://{self.axis.code}?load_inertia={self.axis.load_kgm2:g}&stepped=1&paced=0"
        if self.axis.preset:
            url += f"&preset={self.axis.preset}"
        if self.catalogue_friction:
            url += "&catalogue_friction=1"
        if self.brake:
            url += "&brake=1"
        if self.effects:
            url += "&effects=" + ";".join(
                f"{effect}:" + ",".join(f"{k}={v:g}" for k, v in params.items())
                for effect, params in self.effects.items()
            )
        return url


#: the program's accelerations need at most this share of the actuator's maximum torque
ACCEL_SHARE_OF_MAX_TORQUE = 0.3


def move_program(axis: BenchAxis, accel_rpm_s: float) -> list[tuple[float, float, float, float]]:
    """(output deg, output r/min, r/min per s, dwell s): both directions, standstills between the
    moves, speeds from a tenth of the top speed to it (slow starts show breakaway), and enough
    travel (half a turn each way) to show a load that varies with the position. ``accel_rpm_s``:
    the fastest acceleration the axis takes (a share of its torque)."""
    top = axis.top_rpm
    a = min(accel_rpm_s, 10.0 * top)
    return [
        (120.0, top, a, 0.2),
        (-40.0, 0.4 * top, 0.8 * a, 0.2),
        (-150.0, top, a, 0.2),
        (5.0, 0.08 * top, 0.4 * a, 0.2),
        (-5.0, 0.15 * top, 0.4 * a, 0.2),
        (60.0, 0.6 * top, 0.6 * a, 0.2),
    ]


@dataclass(frozen=True)
class BenchCapture:
    recording: Recording  # imported, the load inertia declared
    capture: Path  # the instrument's sigrok session file
    parameters: Path  # the drive's parameter file (fha-parameters/1), as bench import reads it


def make_capture(case: BenchCase, directory: Path) -> BenchCapture:
    """The case's capture (a ``.sr`` file in ``directory``) imported into a recording, with the
    load inertia declared as the technician knows it."""
    directory.mkdir(parents=True, exist_ok=True)
    capture = directory / f"{case.name}.sr"
    drive = SimDrive.from_url(case.url(), eeprom=str(directory / f"{case.name}.eeprom.json"))
    try:
        model = drive.model
        counts_per_motor_turn = round(model.output_resolution_ppr / (model.ratio or 1))
        top_motor_rpm = max(case.axis.top_rpm, case.coast_rpm) * (model.ratio or 1)
        edges = VirtualBenchInstrument.fastest_edges_hz(top_motor_rpm, counts_per_motor_turn)
        load_counts = LOAD_COUNTS_PER_TURN if case.load_encoder else None
        if load_counts:
            edges = max(edges, VirtualBenchInstrument.fastest_edges_hz(case.axis.top_rpm, load_counts))
        rate = math.ceil(SAMPLES_PER_EDGE * edges / 10e3) * 10e3
        # a logic analyzer on the encoder, command and IN-POS lines (SPD-MON needs an analog input
        # the check does not use)
        instrument = VirtualBenchInstrument.on_drive(
            drive, rate, load_counts_per_turn=load_counts, speed_monitor=False
        )
        if case.brake:
            drive.set_inputs(1 << BIT_BRAKE_RELEASED)  # 24 V on the brake: released while the servo runs
        drive.set_servo(True)
        instrument.keep(0.4)  # standing: the servo holds, the integrator settles
        accel = ACCEL_SHARE_OF_MAX_TORQUE * model.max_torque_nm / model.total_inertia_kgm2 * 30.0 / math.pi
        for angle, rpm, rpm_s, dwell in move_program(case.axis, accel):
            drive.write_parameter("test", 1, max(1, round(rpm_s)))  # the move's acceleration
            drive.set_move_speed(rpm)
            drive.controller_command(angle)
            while drive.moving:
                instrument.keep(0.02)
            instrument.keep(dwell)
        if case.coast_s:
            _coast(drive, instrument, case, accel, 720.0)
        if case.both_ways:
            drive.clear_alarm()  # ACL: alarm 60 clears; the technician turns the servo on again
            drive.set_servo(True)
            instrument.keep(0.3)
            _coast(drive, instrument, case, accel, -720.0)
        instrument.write(capture, "sr")
        values = {("system", n): drive.memory.value(key) for n, key in PARAMETERS.items()}
        parameters = directory / f"{case.name}.params.toml"
        model_items = load_parameter_model("HA-655")
        items = {
            (i.mode, i.number): drive.read_parameter(i.mode, i.number)
            for i in model_items
            if i.mode in ("tune", "system")
        }
        parameters.write_text(dump_parameter_file(model_items, items, case.axis.code, drive.resolved.driver))
    finally:
        drive.close()
    roles = {**ROLES, **(LOAD_ROLES if case.load_encoder else {}), **(ALARM_ROLES if case.coast_s else {})}
    result = import_bench(
        [SignalSpec(role, str(capture), channel) for role, channel in roles.items()],
        AxisFacts.for_actuator(case.axis.code),
        DriveSettings.from_values(values),
        load_counts_per_turn=LOAD_COUNTS_PER_TURN if case.load_encoder else None,
    )
    path = directory / f"{case.name}.csv"
    write_recording(path, result.recording)
    return BenchCapture(read_recording(path).with_declared_load(case.axis.load_kgm2), capture, parameters)


def _coast(drive: SimDrive, instrument: VirtualBenchInstrument, case: BenchCase, accel_rpm_s: float,
           angle_deg: float) -> None:
    """A long move (``angle_deg``) at the case's coast speed, the alarm once the axis runs steadily
    at it, and the coast recorded (the controller stops sending pulses: the drive is in alarm)."""
    drive.write_parameter("test", 1, max(1, round(accel_rpm_s)))
    drive.set_move_speed(case.coast_rpm)
    drive.controller_command(angle_deg)
    instrument.keep(case.coast_rpm / accel_rpm_s + 0.15)  # up to speed, the loop settled
    assert drive.moving, "the coast's move ended before the alarm"
    drive.raise_alarm(COAST_ALARM)
    if case.brake:
        drive.set_inputs(0)  # the controller takes the brake's 24 V away with the alarm: it holds
    instrument.keep(case.coast_s)


def checked_captures(directory: Path):
    """``get(case)``: the case captured into ``directory`` and model-checked once, then
    (capture, result) from the cache (a module fixture's, so every test of a case shares it)."""
    from fha_studio.logic.modelcheck import run_modelcheck

    cache: dict[str, tuple[BenchCapture, object]] = {}

    def get(case: BenchCase):
        if case.name not in cache:
            capture = make_capture(case, directory)
            cache[case.name] = (capture, run_modelcheck(capture.recording))
        return cache[case.name]

    return get
