"""Procedures walked against the embedded simulated drive through DriveClient, live checks included."""

from __future__ import annotations

import pytest

from fha_studio.hardware.client import DriveClient
from fha_studio.logic.procedures import (
    Observation,
    ProcedureRun,
    ProcedureSession,
    StepInputError,
    load_procedure,
)
from fha_studio.logic.procedures.context import build_context
from fha_studio.logic.procedures.live import LiveEnv, move_and_watch, output_angle_deg, run_live_check
from fha_studio.logic.procedures.sensor_dogs import SensorDogWizard
from tests.procedures.walk import good_answer

CODE = "FHA-25C-50-US250-B-L"


@pytest.fixture
def drive():
    client = DriveClient.open(f"sim://{CODE}?paced=0&ls1_deg=-30&ls2_deg=30&origin_deg=0")
    yield client
    client.close()


def _walk_live(run: ProcedureRun, client: DriveClient, env: LiveEnv, before=None) -> list:
    """Answer every step: live steps from the drive, the rest with the passing answer."""
    observations = []
    while (step := run.current()) is not None and not run.stopped:
        if before:
            before(step)
        if step.kind == "live":
            seen = run_live_check(client, step, env)
            observations.append((step.id, seen))
            run.submit(seen, who="T. Trainee")
        else:
            run.submit(good_answer(step), who="T. Trainee")
    return observations


def test_receiving_inspection_asks_the_drive_what_it_was_adjusted_for(drive, tmp_path):
    context = build_context(CODE)
    session = ProcedureSession(actuator_code=CODE, operator="T. Trainee")
    run = ProcedureRun(session, load_procedure("receiving-inspection", context), autosave=False)
    seen = _walk_live(run, drive, LiveEnv(context))
    assert run.completed
    assert seen[0][1].value == CODE and "HA-655-2-200" in seen[0][1].detail


def test_a_drive_adjusted_for_another_actuator_stops_the_inspection(drive):
    other = "FHA-25C-100-US250-B-L"  # the order and the labels say 1:100, the drive was tuned for 1:50
    context = build_context(other)
    run = ProcedureRun(
        ProcedureSession(actuator_code=other), load_procedure("receiving-inspection", context), autosave=False
    )
    _walk_live(run, drive, LiveEnv(context))
    assert run.stopped and run.state.stop_step_id == "drive-identity"
    assert "Only connect the actuator specified on the driver label" in run.state.stop_warning
    assert run.state.records[-1].value == CODE


def test_wiring_with_brake_and_encoder_checked_live(drive):
    context = build_context(CODE)
    session = ProcedureSession(actuator_code=CODE, operator="T. Trainee")
    run = ProcedureRun(session, load_procedure("wiring", context), autosave=False)

    def trainee(step):  # the trainee switches the brake's 24 V as the step says
        if step.id == "brake-releases":
            drive.set_inputs(brake_released=True)
        if step.id == "brake-holds":
            drive.set_inputs(brake_released=False)

    seen = dict(_walk_live(run, drive, LiveEnv(context), before=trainee))
    assert run.completed, run.state.stop_warning
    assert seen["brake-releases"].value is True and seen["brake-holds"].value is False
    assert seen["encoder-signals"].detail == "no alarm"
    assert seen["encoder-phases"].value == pytest.approx(2.0, abs=0.3)
    assert not drive.io_state().servo_on and not drive.io_state().brake_released  # left as found


def test_a_brake_that_does_not_release_stops_the_wiring_check(drive):
    context = build_context(CODE)
    run = ProcedureRun(ProcedureSession(actuator_code=CODE), load_procedure("wiring", context),
                       autosave=False)
    _walk_live(run, drive, LiveEnv(context))  # nobody switches the 24 V on
    assert run.stopped and run.state.stop_step_id == "brake-releases"
    assert "did not release" in run.state.stop_warning


def test_rotary_direction_sees_the_axis_turn(drive):
    context = build_context(CODE)
    run = ProcedureRun(
        ProcedureSession(actuator_code=CODE), load_procedure("rotary-direction", context), autosave=False
    )
    seen = dict(_walk_live(run, drive, LiveEnv(context)))
    assert run.completed
    assert seen["parameter"].value == 0
    assert seen["jog-fwd"].value == pytest.approx(5.0, abs=0.3) and "CW" in seen["jog-fwd"].detail
    # the other direction wanted: parameter 8 still 0 stops it
    run2 = ProcedureRun(
        ProcedureSession(actuator_code=CODE), load_procedure("rotary-direction", context), autosave=False
    )
    run2.submit("CCW")
    run2.submit(run_live_check(drive, run2.current(), LiveEnv(context)))
    assert run2.stopped and "Parameter 8" in run2.state.stop_warning


@pytest.mark.slow
def test_sensor_dog_adjustment_on_the_simulated_drive(drive, tmp_path):
    """The whole 4-7-2 procedure: dogs moved on the simulated actuator, angles found live, test run."""
    context = build_context(CODE)
    path = tmp_path / "axis.json"
    session = ProcedureSession(actuator_code=CODE, operator="T. Trainee")
    session.save(path)
    run = ProcedureRun(session, load_procedure("sensor-adjustment", context))
    wizard = SensorDogWizard.for_context(context)
    samples = []

    def watch(angle, io):
        samples.append(angle)
        wizard.observe(
            angle,
            {
                "limit_switch_1": io.limit_switch_1,
                "limit_switch_2": io.limit_switch_2,
                "origin_sensor": io.origin_sensor,
            },
        )

    env = LiveEnv(context, session.sensor_angles_deg, on_sample=watch)
    angle, io = output_angle_deg(drive, env.output_ppr)
    watch(angle, io)
    run.submit(True)
    run.submit(True)
    # LS2: the trainee turns the dog to +20° (by hand; SNB on the simulated drive), then runs towards it
    drive.set_sensor_angle("ls2", 20.0)
    wizard.check_move(25.0)
    move_and_watch(drive, 25.0, env, speed_rpm=5.0)  # the switch stops the axis at its dog
    assert wizard.found("limit_switch_2") == pytest.approx(20.0, abs=1.0)  # the axis stops at the dog
    assert run.submit(Observation(wizard.found("limit_switch_2"), True, "seen live")).passed
    drive.set_sensor_angle("ls1", -15.0)
    here = output_angle_deg(drive, env.output_ppr)[0]
    move_and_watch(drive, -20.0 - here, env, speed_rpm=5.0)
    assert wizard.found("limit_switch_1") == pytest.approx(-15.0, abs=1.0)
    assert run.submit(wizard.found("limit_switch_1")).passed
    run.pause()  # coffee; the app is closed and opened again
    session = ProcedureSession.load(path)
    run = ProcedureRun(session, load_procedure("sensor-adjustment", context))
    assert run.current().sensor == "origin_sensor"
    drive.set_sensor_angle("origin", 3.0)
    here = output_angle_deg(drive, env.output_ppr)[0]
    move_and_watch(drive, 5.0 - here, env, speed_rpm=2.0)
    low, high = wizard.edge_intervals_deg["origin_sensor"]
    assert low - 0.1 <= 2.5 <= high + 0.1  # the slit's CCW edge lies between the two samples
    assert run.submit(wizard.found("origin_sensor")).passed
    run.submit(True)
    step = run.current()
    assert step.check == "sensor_test_run"
    seen = run_live_check(drive, step, LiveEnv(context, session.sensor_angles_deg))
    assert seen.passed, seen.detail
    run.submit(seen)
    assert run.completed
    saved = ProcedureSession.load(path)
    assert set(saved.sensor_angles_deg) == {"limit_switch_1", "limit_switch_2", "origin_sensor"}
    assert saved.runs["sensor-adjustment"].records[-1].value["limit_switch_2"]


def test_a_drive_that_cannot_tell_is_confirmed_by_hand(drive):
    context = build_context(CODE)
    run = ProcedureRun(
        ProcedureSession(actuator_code=CODE), load_procedure("receiving-inspection", context), autosave=False
    )
    while run.current().kind != "live":
        run.submit(good_answer(run.current()))
    with pytest.raises(StepInputError, match="cannot tell"):
        run.submit(
            Observation(None, False, "the drive cannot tell: no IDN; confirm by hand", available=False)
        )
    record = run.submit(True, who="T. Trainee")
    assert record.passed and record.detail == "confirmed by hand"


def test_a_servo_on_refusal_is_not_a_failed_check():
    from fha_studio.hardware.api import IoState, ServoOnRefused
    from fha_studio.hardware.protocol import Command
    from tests.gui.fake_drive import FakeDriveClient

    class DriveServoOn(FakeDriveClient):  # a drive that answers "s" while the servo is on
        def io_state(self) -> IoState:
            raise ServoOnRefused("the drive does not read the I/O state while the servo is on")

    drive = DriveServoOn().without(Command.ALM)  # and has no alarm command (CommandNotSupported)
    context = build_context(CODE)
    wiring = load_procedure("wiring", context)
    step = wiring.step("brake-releases").resolve(context, {})
    seen = run_live_check(drive, step, LiveEnv(context))
    assert not seen.available and "switch it off" in seen.detail
    seen = run_live_check(drive, wiring.step("encoder-signals").resolve(context, {}), LiveEnv(context))
    assert not seen.available and "enter what you saw" in seen.detail
