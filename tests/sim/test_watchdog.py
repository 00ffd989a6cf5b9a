"""The JOG watchdog (docs/sim.md): after the last keep-alive the command ramps down at the stated
deceleration, the axis stands still within the stated time, and the moving bit is true to the
motion of the output, not of the command."""

from __future__ import annotations

import math

import pytest

from fha_studio.logic.tuning.propose import ALLOWED_LOAD_RATIO
from fha_studio.physics import AxisModel, PanelGains
from tests.sim.conftest import jog_for

RPM = 2 * math.pi / 60
SETTLE_S = 0.1  # docs/sim.md: standstill at most speed / deceleration + 100 ms after the watchdog
#: the speed loop's crossover (Hz, with the load) a technician tunes an axis beyond 2-1 to
HEAVY_CROSSOVER_HZ = 30.0


def _preset(actuator: str, load_inertia_kgm2: float) -> tuple[tuple[str, int, int], ...]:
    """The factory's items, or beyond FHA-C manual 2-1's allowance a speed loop gain raised for the
    load: tune 0 is read on the actuator's own inertia, so with 7 x its inertia the factory's 60 Hz
    crosses over at about 7 Hz and the axis creeps back and forth for a while after it first stands
    still."""
    model = AxisModel.from_code(actuator, load_inertia_kgm2=load_inertia_kgm2)
    if load_inertia_kgm2 <= ALLOWED_LOAD_RATIO * model.actuator_inertia_kgm2:
        return ()
    return (("tune", 0, round(PanelGains.speed_loop_gain_for(model, HEAVY_CROSSOVER_HZ))),)


@pytest.mark.parametrize("load_inertia_kgm2", [0.0, 1.5, 6.0])
@pytest.mark.parametrize("speed_rpm", [10, 30, 60, 85])
def test_after_the_last_jog_the_axis_stands_still_in_the_stated_time(make_drive, speed_rpm,
                                                                      load_inertia_kgm2):
    drive = make_drive(load_inertia_kgm2=load_inertia_kgm2,
                       preset=_preset("FHA-25C-50-US250", load_inertia_kgm2))
    drive.set_servo(True)
    jog_for(drive, speed_rpm, 1.5)
    last_jog = drive.time_s
    decel = drive.watchdog_decel_rad_s2(speed_rpm * RPM)
    assert decel <= 0.8 * drive.model.max_acceleration_rad_s2() + 1e-9
    assert decel == pytest.approx(min(speed_rpm * RPM / 0.05, 0.8 * drive.model.max_acceleration_rad_s2()))
    standstill = drive.constants.standstill_speed_rpm
    still_since = None
    while drive.time_s - last_jog < 2.0:
        drive.advance(0.001)
        turning = abs(drive.axis.output_speed_rad_s) / RPM >= standstill
        if turning:
            still_since = None
            # the bit is true to the motion: never clear while the output still turns
            assert drive.moving, f"moving bit clear at {drive.time_s - last_jog:.3f} s while turning"
        elif still_since is None:
            still_since = drive.time_s
    assert still_since is not None
    stood_still_after_watchdog = still_since - last_jog - drive.constants.jog_watchdog_s
    assert stood_still_after_watchdog <= speed_rpm * RPM / decel + SETTLE_S
    assert not drive.moving
