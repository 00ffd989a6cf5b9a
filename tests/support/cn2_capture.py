"""Moves of a simulated FHA-25C-50 recorded on CN2 by the virtual bench instrument, as the bench
import tests take them (in files, or through sigrok-cli): the physics alone (standing, 9000
command pulses FWD at 8 r/min, 4000 back at 5 r/min), or the stepped simulated drive on its
documented profile moved by the controller's pulses."""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from fha_studio.catalog import get_actuator
from fha_studio.hardware.sim.cn2 import RAD_S_PER_RPM, Cn2Settings, VirtualBenchInstrument
from fha_studio.hardware.sim.drive import SimDrive
from fha_studio.logic.bench.importer import DriveSettings
from fha_studio.physics import AxisModel, ServoAxis
from fha_studio.recording import Recording

CODE = "FHA-25C-50-US250"
#: Each role of ``bench import`` and the instrument's channel that carries it.
CHANNELS = {
    "encoder_a": "ENC_A",
    "encoder_b": "ENC_B",
    "encoder_z": "ENC_Z",
    "command_a": "CMD_A",
    "command_b": "CMD_B",
    "in_position": "IN_POS",
    "alarm": "ALARM",
    "speed_monitor": "SPD_MON",
}


def recorded_move(pulse_form: int = 0, multiplication: int = 4, gear: tuple[int, int] = (1, 1),
                  rate_hz: float = 200e3) -> tuple[ServoAxis, VirtualBenchInstrument]:
    """The axis (0.3 kg m^2 load, electronic gear ``gear``) after the move, and the instrument that
    recorded its CN2 at ``rate_hz`` (command pulses of ``pulse_form``/``multiplication``)."""
    model = AxisModel.from_actuator(get_actuator(CODE), load_inertia_kgm2=0.3)
    axis = ServoAxis(model)
    axis.set_settings(
        axis.settings.replace(electronic_gear_numerator=gear[0], electronic_gear_denominator=gear[1])
    )
    axis.servo_on()
    instrument = VirtualBenchInstrument(
        axis, rate_hz, Cn2Settings(pulse_form=pulse_form, multiplication=multiplication)
    )
    instrument.record(0.03)  # standing: where the monitor's offset is taken
    axis.move_by_pulses(9000, speed_rad_s=8 * RAD_S_PER_RPM)
    instrument.record(0.45)
    axis.move_by_pulses(-4000, speed_rad_s=5 * RAD_S_PER_RPM)
    instrument.record(0.3)
    return axis, instrument


@contextmanager
def controller_move(tmp_path: Path) -> Iterator[tuple[SimDrive, VirtualBenchInstrument]]:
    """The stepped SimDrive on its documented profile (CN3 silent in motion), servo on, its CN2
    sampled at 400 kHz while standing 30 ms; then the controller's pulses command 12 deg at
    10 r/min, which the caller records. The drive is closed after."""
    drive = SimDrive(CODE, profile="documented", stepped=True, eeprom=str(tmp_path / "eeprom.json"))
    try:
        instrument = VirtualBenchInstrument.on_drive(drive, 400e3)
        drive.set_servo(True)
        instrument.record(0.03)
        drive.set_move_speed(10.0)
        drive.controller_command(12.0)
        yield drive, instrument
    finally:
        drive.close()


def drive_settings(drive: SimDrive) -> DriveSettings:
    """Parameters 1, 2, 3, 4 and 9 as the drive holds them, as ``bench import`` takes them."""
    values = {("system", n): drive.memory.value(key) for n, key in (
        (1, "command_pulse_configuration"), (2, "two_phase_pulse_multiplication"),
        (3, "electronic_gear_numerator"), (4, "electronic_gear_denominator"),
        (9, "speed_conversion_factor"))}
    return DriveSettings.from_values(values)


def expected_speed_rpm(recording: Recording, truth: dict[str, np.ndarray], rate_hz: float) -> np.ndarray:
    """The drive's output r/min at each of the recording's instants (the speed column is taken at
    the position's instants), from the instrument's truth sampled at ``rate_hz``."""
    idx = np.rint(recording.t_s * rate_hz).astype(int)
    return truth["motor_rpm"][idx] / get_actuator(CODE).ratio
