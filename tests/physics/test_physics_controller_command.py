"""The controller's command (trace channel ``controller_pos``): the command while the servo is on,
held while it is off and the axis coasts, and not moved when the error counter is cleared."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fha_studio.physics import AxisModel, ServoAxis

RPM = 2 * math.pi / 60


@pytest.mark.parametrize("every", [1, 3])
def test_the_controllers_command_holds_while_the_servo_is_off(every):
    model = AxisModel.from_code("FHA-25C-50-US250", 0.5)
    axis = ServoAxis(model)
    axis.set_settings(axis.settings.replace(rotary_direction=1))  # command frame = -physical
    axis.servo_on()
    axis.start_trace(every)
    axis.move_by(math.radians(2.0), speed_rad_s=10 * RPM)
    axis.advance(0.02)  # 2 deg at 60 deg/s: still moving
    on = axis.read_trace()
    # with the servo on it is the drive's command (physical) in the command frame
    np.testing.assert_allclose(on["controller_pos"], -on["cmd_pos"], atol=1e-12)
    sent = axis.controller_pos_rad
    axis.servo_off()  # mid-move: the axis coasts, the drive's command follows it
    axis.advance(0.05)
    off = axis.read_trace()
    assert np.ptp(off["cmd_pos"]) > 100 * model.output_pulse_rad
    assert set(off["controller_pos"]) == {sent}
    axis.servo_on()  # the drive's command := the feedback
    axis.clear_error()
    axis.advance(0.01)
    assert set(axis.read_trace()["controller_pos"]) == {sent}
    axis.add_command_pulses(100)  # the controller's next pulses count on from where it stopped
    axis.advance(0.01)
    assert axis.controller_pos_rad == pytest.approx(sent + 100 * model.output_pulse_rad)
