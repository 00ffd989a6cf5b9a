"""A move of a simulated FHA-25C-50 recorded on CN2 by the virtual bench instrument, as the bench
import tests take it (in files, or through sigrok-cli): standing, 9000 command pulses FWD at
8 r/min, 4000 back at 5 r/min."""

from __future__ import annotations

from fha_studio.catalog import get_actuator
from fha_studio.hardware.sim.cn2 import RAD_S_PER_RPM, Cn2Settings, VirtualBenchInstrument
from fha_studio.physics import AxisModel, ServoAxis

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
