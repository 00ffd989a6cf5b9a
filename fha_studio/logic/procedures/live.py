"""Live checks: what the drive itself can tell about a step, through the drive client.

Each check named in a procedure file (``kind = "live"``, ``check = NAME``) is a function here
taking ``(client, step, env)`` and returning an :class:`~.engine.Observation`. They talk to the
drive (so they run in the link's thread, never in the GUI thread), may move the axis slowly, and
always leave the servo as they found it. A drive that cannot tell (a real HA-655 without the
extension commands) gives an Observation with ``available=False``: the step is then confirmed by
hand (``ProcedureRun.submit(True)``) and recorded so.
"""

from __future__ import annotations

import contextlib
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from fha_studio.catalog.tables import rotary_direction
from fha_studio.hardware.api import DriveApi, IoState
from fha_studio.hardware.errors import (
    CommandNotSupported,
    CommandRejected,
    DriveRefused,
    LinkError,
    ServoOnRefused,
)
from fha_studio.hardware.parameters import MonitorItem
from fha_studio.logic.procedures.definitions import Step
from fha_studio.logic.procedures.engine import Observation, normalise_label
from fha_studio.logic.procedures.sensor_dogs import SENSORS, Sensor, SensorDogWizard

LOW_SPEED_RPM = 2.0  # output speed of the moves a live check makes (slow: a person is watching)
ROTARY_DIRECTION = ("system", 8)  # [parameter mode] -> [8: rotary direction] (1-10)


@dataclass
class LiveEnv:
    """What a live check may use besides the drive: the actuator context, the recorded sensor
    angles, a callback for every sample (angle deg, I/O) so a GUI can show a move, a cancel flag."""

    context: Mapping[str, Any]
    sensor_angles_deg: Mapping[str, float] = field(default_factory=dict)
    on_sample: Callable[[float, IoState], None] | None = None
    cancelled: Callable[[], bool] = lambda: False
    #: what a check keeps between two presses of its button (the encoder check by hand-turning)
    memo: dict[str, Any] = field(default_factory=dict)

    @property
    def output_ppr(self) -> int:
        return int(self.context["actuator"]["output_resolution_ppr"])


def unavailable(why: str) -> Observation:
    return Observation(None, False, f"the drive cannot tell: {why}; enter what you saw", available=False)


#: What to enter by hand for each live check when the drive cannot tell (a drive of the manual's
#: commands only): the value that is recorded instead of a bare "OK".
BY_HAND = {
    "driver_adjusted_for": "the ADJUSTED FOR USE WITH line of the driver's label",
    "io_bit": "what you saw (e.g. 'released: the output turns by hand')",
    "alarm_free": "the code on the drive's front panel (0 or blank display: no alarm)",
    "encoder_counts": "the feedback pulses seen on the panel (monitor items 7, 8) for a turn by hand",
    "battery": "the code on the drive's front panel (alarm 56 = low battery; 0: none)",
    "rotary_direction": "parameter 8 on the drive's panel ([parameter mode] -> item 8): 0 or 1",
    "jog_forward": "which way a FWD command from the controller turned the output: CW or CCW",
    "sensor_test_run": "the angles where each sensor switched during the test run",
}


def output_angle_deg(client: DriveApi, ppr: int) -> tuple[float, IoState]:
    """The output angle (deg, CW positive seen from the flange) and the I/O bits, in one exchange."""
    values = client.read_monitors([MonitorItem.FEEDBACK_POSITION, MonitorItem.IO_STATE])
    return values[MonitorItem.FEEDBACK_POSITION] * 360.0 / ppr, IoState(values[MonitorItem.IO_STATE])


def _check_driver_adjusted_for(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    identity = client.identify()
    if identity is None:
        return unavailable("it does not report its identity (no IDN); read the driver label")
    passed = normalise_label(identity.adjusted_for) == normalise_label(str(step.expect))
    return Observation(
        identity.adjusted_for, passed, f"{identity.driver_model}, adjusted for {identity.adjusted_for}"
    )


def _check_io_bit(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    name = str(step.params["bit"])
    state = client.io_state().as_dict()
    if name not in state:
        raise ValueError(f"step '{step.id}': no I/O bit '{name}'; known: {', '.join(state)}")
    want = bool(step.expect)
    return Observation(
        state[name], state[name] == want, f"{name.replace('_', ' ')}: {'on' if state[name] else 'off'}"
    )


def _check_alarm_free(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    code = client.alarm()
    codes = [int(c) for c in step.params.get("codes", [])]
    bad = code != 0 and (not codes or code in codes)
    return Observation(code, not bad, f"alarm {code}" if code else "no alarm")


class _SimBrakeReleased:
    """On a simulated drive, power the brake's 24 V for a move and restore it afterwards."""

    def __init__(self, client: DriveApi):
        self.client = client
        self.restore: bool | None = None

    def __enter__(self) -> _SimBrakeReleased:
        if self.client.capabilities.simulated:
            self.restore = self.client.io_state().brake_released
            if not self.restore:
                self.client.set_inputs(brake_released=True)
        return self

    def __exit__(self, *exc: object) -> None:
        if self.restore is False:
            with contextlib.suppress(LinkError):
                self.client.set_inputs(brake_released=False)


def move_and_watch(
    client: DriveApi,
    angle_deg: float,
    env: LiveEnv,
    speed_rpm: float = LOW_SPEED_RPM,
    stop_when: Callable[[float, IoState], bool] | None = None,
) -> float:
    """Move the output by ``angle_deg`` at ``speed_rpm`` with the servo on, reporting every sample
    to ``env.on_sample`` and ``stop_when``; returns the angle at the end. Servo and (simulated)
    brake are left as found."""
    was_on = client.io_state().servo_on
    deadline = time.monotonic() + abs(angle_deg) / (speed_rpm * 6.0) + 5.0
    with _SimBrakeReleased(client):
        if not was_on:
            client.servo(True)
        try:
            client.set_move_speed(speed_rpm)
            client.move_by(angle_deg)
            while True:
                angle, io = output_angle_deg(client, env.output_ppr)
                if env.on_sample:
                    env.on_sample(angle, io)
                if stop_when and stop_when(angle, io):
                    client.stop()
                    break
                if not io.moving or env.cancelled():
                    if io.moving:
                        client.stop()
                    break
                if time.monotonic() > deadline:
                    client.stop()
                    raise LinkError(f"the move of {angle_deg:+.1f}° did not finish in time")
        finally:
            if not was_on:
                client.servo(False)
    return output_angle_deg(client, env.output_ppr)[0]


def _check_encoder_counts(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    try:
        start, _ = output_angle_deg(client, env.output_ppr)
    except CommandNotSupported:
        return _encoder_counts_by_hand(client, step, env)
    if not _can_move(client):
        return unavailable("it takes no move commands; turn the output by hand and watch the feedback pulses")
    end = move_and_watch(client, float(step.params.get("angle_deg", 2.0)), env)
    moved = end - start
    return Observation(round(moved, 3), abs(moved) > 0.5, f"feedback moved {moved:+.2f}° for a +2° command")


#: The angle the technician turns the output by hand for the encoder check with DGR, deg (CW +).
HAND_TURN_DEG = 10.0


def _encoder_counts_by_hand(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    """A drive without monitor items (a real HA-655): with an absolute encoder, DGR answers the
    encoder check. First press: read the position and ask for a turn by hand; second press: read
    again, the counts must have changed by ratio x 8192 per motor turn in the same sense."""
    from fha_studio.logic.absolute import encoder_check

    try:
        counts = client.absolute_position()
    except CommandRejected:
        return unavailable("it reports no position over CN3 (DGR refused: an incremental encoder); turn the "
                           "output by hand and watch the feedback pulses on the panel (monitor items 7, 8)")
    ratio = int(env.context["actuator"]["ratio"])
    start = env.memo.pop("encoder_start_counts", None)
    if start is None:
        env.memo["encoder_start_counts"] = counts
        return Observation(None, False, f"position read ({counts} counts, DGR). Now, with the servo off, "
                           f"turn the output by hand by {HAND_TURN_DEG:+g}° (CW seen from the flange) and "
                           "press the check again", available=False)
    passed, detail, values = encoder_check(start, counts, HAND_TURN_DEG, ratio)
    return Observation(values["after_counts"] - values["before_counts"], passed, detail)


def _can_move(client: DriveApi) -> bool:
    from fha_studio.hardware.protocol import Command

    return all(client.capabilities.supports(c) for c in (Command.SVO, Command.SPD, Command.MOV))


def _check_battery(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    from fha_studio.hardware.protocol import Command

    # a drive of the manual's commands has no ALM: DGR alone says whether the absolute data is there
    code = client.alarm() if client.capabilities.supports(Command.ALM) else None
    if code == 56:
        return Observation(code, False, "alarm 56: ABS low battery voltage")
    try:
        counts = client.absolute_position()
    except ServoOnRefused:
        return Observation(None, False, "the servo is on: switch it off to read the absolute position")
    except CommandRejected:
        return Observation(None, False, "the drive answers no absolute position (DGR refused)")
    if code is None:
        return Observation(counts, True, f"absolute position {counts} counts (DGR answered; the drive "
                           "reports no alarms over CN3: see its front panel for alarm 56)")
    return Observation(counts, True, f"absolute position {counts} counts, no battery alarm")


def _check_rotary_direction(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    try:
        value = client.read_parameter(*ROTARY_DIRECTION)
    except (CommandNotSupported, ServoOnRefused) as exc:
        return unavailable(f"parameter 8 cannot be read ({exc})")
    want = next((s.value for s in rotary_direction() if s.fwd_direction == str(step.expect)), None)
    return Observation(value, value == want, f"parameter 8 (rotary direction) = {value}")


def _check_jog_forward(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    if not _can_move(client):
        return unavailable("it takes no move commands; give a FWD command from the controller")
    start, _ = output_angle_deg(client, env.output_ppr)
    end = move_and_watch(client, float(step.params.get("angle_deg", 5.0)), env)
    moved = end - start
    seen = "CW" if moved > 0 else "CCW"
    return Observation(
        round(moved, 3), abs(moved) > 1.0, f"the output turned {moved:+.2f}° ({seen} seen from the flange)"
    )


def _check_sensor_test_run(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    if not _can_move(client):
        return unavailable(
            "it takes no move commands; run the axis from the controller and watch the sensors"
        )
    wizard = SensorDogWizard.for_context(env.context)
    targets = wizard.test_run_plan(env.sensor_angles_deg)
    seen: dict[str, list[tuple[float, float]]] = {s: [] for s in SENSORS}
    angle, io = output_angle_deg(client, env.output_ppr)
    wizard.observe(angle, _sensor_states(io))
    speed = float(step.params.get("speed_rpm", LOW_SPEED_RPM))

    def sample(a: float, state: IoState) -> None:
        for sensor in wizard.observe(a, _sensor_states(state)):
            seen[sensor].append(wizard.edge_intervals_deg[sensor])
        if env.on_sample:
            env.on_sample(a, state)

    inner = LiveEnv(env.context, env.sensor_angles_deg, sample, env.cancelled)
    for target in targets:
        wizard.check_move(target)
        current = output_angle_deg(client, env.output_ppr)[0]
        move_and_watch(client, target - current, inner, speed)
        if env.cancelled():
            return Observation(None, False, "test run cancelled")
    passed, detail = wizard.test_run_result(env.sensor_angles_deg, seen)
    # recorded: where each sensor switched on, per pass (the angle of the first sample it was on)
    return Observation({k: [round(e[1], 3) for e in v] for k, v in seen.items()}, passed, detail)


def _sensor_states(io: IoState) -> dict[str, bool]:
    return {
        Sensor.LIMIT_SWITCH_1: io.limit_switch_1,
        Sensor.LIMIT_SWITCH_2: io.limit_switch_2,
        Sensor.ORIGIN_SENSOR: io.origin_sensor,
    }


CHECKS: dict[str, Callable[[DriveApi, Step, LiveEnv], Observation]] = {
    "driver_adjusted_for": _check_driver_adjusted_for,
    "io_bit": _check_io_bit,
    "alarm_free": _check_alarm_free,
    "encoder_counts": _check_encoder_counts,
    "battery": _check_battery,
    "rotary_direction": _check_rotary_direction,
    "jog_forward": _check_jog_forward,
    "sensor_test_run": _check_sensor_test_run,
}


def run_live_check(client: DriveApi, step: Step, env: LiveEnv) -> Observation:
    """Run the live check of ``step`` on the drive. A command the drive does not know gives an
    unavailable Observation, a refusal a failed one; a link failure raises ``LinkFailure``
    (nothing is recorded)."""
    check = CHECKS.get(step.check)
    if check is None:
        raise ValueError(f"step '{step.id}': no live check '{step.check}'; known: {', '.join(CHECKS)}")
    try:
        return check(client, step, env)
    except CommandNotSupported as exc:
        return unavailable(str(exc))
    except ServoOnRefused:  # a real HA-655 answers nothing on CN3 while the servo is on
        return unavailable("the servo is on (CN3 answers only with the servo off): switch it off")
    except DriveRefused as exc:  # the link works and the drive said no: the check fails, saying why
        return Observation(None, False, f"the drive refused: {exc}")
