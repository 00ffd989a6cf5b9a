"""One client suite over every way to reach a drive, as python-can runs one suite over every bus.

The same tests talk to the simulated drive embedded in this process (``sim://``), to
``fha-studio sim --tcp`` in another process (``socket://``), to ``fha-studio sim --pty`` in
another process (a pseudo-terminal), and to the GUI tests' fake (``FakeDriveClient`` in memory,
with every command of the protocol's table as the simulated drive has them): what passes here,
a GUI test on the fake can take for what ``DriveClient`` does. Each subprocess is started once
per module. Every test leaves the drive as it found it (servo off, no alarm, inputs released,
values restored). No case here is about bytes on a line (framing, resynchronisation: those are
tests/hardware/test_client.py and test_hostile_lines.py), so none is left out for the fake.

The held jog repeats JOG on every pass of its loop (one read of the monitors a pass, a few ms)
and stops when the monitors show the motion, not after a time: a pass that comes late on a loaded
machine lets the drive's 100 ms watchdog stop the axis, and the next JOG starts it again.
"""

from __future__ import annotations

import re
import time
from collections.abc import Callable, Iterator

import pytest

from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import (
    AlarmRecord,
    CapabilityLevel,
    CommandRejected,
    DriveApi,
    Held,
    IoState,
    ServoOnRefused,
)
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.parameters import Mode, MonitorItem
from fha_studio.hardware.protocol import Command, rejected_text, servo_on_text
from tests.gui.fake_drive import SIMULATED_COMMANDS, FakeDriveClient
from tests.support.processes import Child

#: An absolute-encoder actuator, so that DGR answers a position.
ACTUATOR = "FHA-25C-50-S248"
#: Only a hang takes this long: the output reaches the jog speed within some 0.1 s.
HELD_JOG_LIMIT_S = 15.0
E2E = pytest.mark.e2e
BUSES = ["sim", pytest.param("tcp", marks=E2E), pytest.param("pty", marks=E2E), "fake"]


@pytest.fixture(scope="module", params=BUSES)
def bus(request, tmp_path_factory) -> Iterator[str]:
    """The URL of a drive on one bus; a subprocess lives as long as the module's tests of its bus."""
    if request.param == "fake":
        yield "fake://"
        return
    tmp = tmp_path_factory.mktemp(request.param)
    if request.param == "sim":
        yield f"sim://{ACTUATOR}?paced=0&eeprom={tmp / 'eeprom.json'}"
        return
    where = ("--tcp", "0") if request.param == "tcp" else ("--pty",)
    with Child.sim(tmp / "eeprom.json", *where, "--actuator", ACTUATOR) as process:
        yield process.address
    assert process.returncode == 0, "SIGTERM ends the simulated drive cleanly"


@pytest.fixture
def drive(bus: str) -> Iterator[DriveApi]:
    client: DriveApi
    if bus == "fake://":
        client = FakeDriveClient(commands=SIMULATED_COMMANDS, actuator=ACTUATOR)
    else:
        client = DriveClient.open(bus)
    try:
        yield client
    finally:
        try:
            client.servo(False)
        finally:
            client.close()


def _until(condition: Callable[[], bool], timeout_s: float = 15.0) -> None:
    end = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < end, "condition not met in time"
        time.sleep(0.02)


def test_identity_and_capabilities(drive):
    ident = drive.identify()
    assert ident is not None and ident.adjusted_for == ACTUATOR and ident.driver_model.startswith("HA-655")
    caps = drive.capabilities
    assert caps.level is CapabilityLevel.TRACE and caps.simulated and caps.parameters
    assert caps.absolute_position is True and caps.can_move and caps.can_monitor


def test_a_verified_write_and_its_restore(drive):
    item = drive.model.by_key("in_position_range")
    before = drive.read_parameter(item.mode, item.number)
    result = drive.write_parameter(item.mode, item.number, before + 7)
    assert result.holds is Held.NEW and result.previous == before and result.value == before + 7
    assert drive.read_parameter(item.mode, item.number) == before + 7
    assert drive.write_parameter(item.mode, item.number, before).verified


def test_the_servo_on_refuses_parameter_mode_writes_and_dgr(drive):
    direction = drive.model.by_key("rotary_direction")
    assert isinstance(drive.absolute_position(), int)
    drive.servo(True)
    with pytest.raises(ServoOnRefused):
        drive.write_parameter(direction.mode, direction.number, 1)
    with pytest.raises(ServoOnRefused):
        drive.absolute_position()
    drive.servo(False)
    assert drive.read_parameter(direction.mode, direction.number) == 0


def test_a_held_jog_moves_the_output_and_the_monitors_see_it(drive):
    items = [MonitorItem.FEEDBACK_POSITION, MonitorItem.OUTPUT_SPEED, MonitorItem.IO_STATE]
    speed = drive.model.item(Mode.MONITOR, MonitorItem.OUTPUT_SPEED)
    start = drive.read_monitors([MonitorItem.FEEDBACK_POSITION])[MonitorItem.FEEDBACK_POSITION]
    drive.servo(True)
    deadline = time.monotonic() + HELD_JOG_LIMIT_S
    while True:  # the button held: JOG again on every pass, each pass one read of the monitors
        drive.jog(30.0)
        values = drive.read_monitors(items)
        turning_rpm = speed.to_unit(values[MonitorItem.OUTPUT_SPEED])
        if values[MonitorItem.FEEDBACK_POSITION] > start and turning_rpm > 25:
            break
        assert time.monotonic() < deadline, f"a jog held {HELD_JOG_LIMIT_S} s: {turning_rpm:g} r/min"
    drive.stop()
    assert IoState(values[MonitorItem.IO_STATE]).servo_on


def test_an_alarm_comes_with_its_history_and_clears(drive):
    drive.inject_alarm(20)
    assert drive.alarm() == 20 and drive.io_state().alarm
    history = drive.alarm_history()
    assert isinstance(history[0], AlarmRecord) and history[0].code == 20
    drive.clear_alarm()
    assert drive.alarm() == 0


def test_simulated_inputs_show_in_the_io_state(drive):
    state = drive.set_inputs(fwd_inhibit=True)
    assert state.fwd_inhibit and not state.rev_inhibit
    assert drive.io_state().bit(p.IoBit.FWD_INHIBIT)
    assert not drive.set_inputs(fwd_inhibit=False).fwd_inhibit


def test_an_unknown_monitor_item_is_rejected(drive):
    with pytest.raises(CommandRejected):
        drive.read_monitor(99)


def test_a_trace_is_captured_and_read_out(drive):
    channels = drive.configure_trace([MonitorItem.FEEDBACK_POSITION, MonitorItem.IO_STATE])
    assert channels == (MonitorItem.FEEDBACK_POSITION, MonitorItem.IO_STATE)
    drive.arm_trace(100)
    _until(lambda: drive.trace_status().state is p.TraceState.DONE)
    capture = drive.read_trace()
    assert capture.channels == channels and len(capture.samples) == 100
    assert all(len(row) == 2 for row in capture.samples)
    assert all(IoState(bits).ready for bits in capture.column(MonitorItem.IO_STATE))


def exactly(text: str) -> str:
    return f"^{re.escape(text)}$"


def test_refusals_say_what_was_refused_in_the_same_words_on_every_bus(drive):
    direction = drive.model.by_key("rotary_direction")
    with pytest.raises(CommandRejected, match=exactly(rejected_text(Command.JOG))):
        drive.jog(10.0)  # the servo is off
    drive.servo(True)
    held = f"{direction.label}: not written ({servo_on_text(Command.PWR)}); the drive holds "
    with pytest.raises(ServoOnRefused, match=exactly(held + f"{direction.format(0)}, the old value")):
        drive.write_parameter(direction.mode, direction.number, 1)
    with pytest.raises(ServoOnRefused, match=exactly(servo_on_text(Command.DGR))):
        drive.absolute_position()
    with pytest.raises(ServoOnRefused, match=exactly(servo_on_text(Command.PWC))):
        drive.power_cycle()
    drive.servo(False)
    with pytest.raises(CommandRejected, match=exactly(rejected_text(Command.TSL, 99))):
        drive.read_parameter(Mode.TUNE, 99)
    with pytest.raises(CommandRejected, match=exactly(rejected_text(Command.FLT, 99))):
        drive.inject_alarm(99)  # no such alarm
    drive.inject_alarm(30)  # over current: only a power cycle clears it
    try:
        with pytest.raises(CommandRejected, match=exactly(rejected_text(Command.ACL))):
            drive.clear_alarm()
        with pytest.raises(CommandRejected, match=exactly(rejected_text(Command.SVO))):
            drive.servo(True)
    finally:
        drive.power_cycle()
    assert drive.alarm() == 0


@pytest.mark.parametrize(("call", "said"), [
    (lambda d: d.jog(1e9), "jog speed 1000000000.0 r/min is outside -999.99 ... 999.99 r/min"),
    (lambda d: d.set_move_speed(0), "move speed must be positive, got 0 r/min"),
    (lambda d: d.configure_trace([]), "a trace has 1 ... 4 channels, got 0"),
    (lambda d: d.configure_trace([99]), "monitor item 99 cannot be in a mask (items 100 ... 115)"),
    (lambda d: d.arm_trace(0), "trace samples must be 1 ... 4096, got 0"),
    (lambda d: d.read_trace(), "read_trace: configure_trace first (the channels are not known)"),
    (lambda d: d.set_sensor_angle("x", 1.0), "sensor 'x': origin, ls1 or ls2"),
], ids=["jog", "move-speed", "no-channel", "channel-99", "no-samples", "unconfigured", "sensor"])
def test_arguments_are_refused_before_anything_is_sent_in_the_same_words(drive, call, said):
    with pytest.raises(ValueError, match=exactly(said)):
        call(drive)


def test_every_item_of_a_mode_is_read_at_once(drive):
    values = drive.read_all_parameters(Mode.TUNE)
    assert set(values) == {item.number for item in drive.model.in_mode(Mode.TUNE)}
    assert all(isinstance(v, int) for v in values.values())


def test_the_multi_turn_data_is_not_cleared_with_the_servo_on(drive):
    drive.servo(True)
    with pytest.raises(CommandRejected, match=exactly(rejected_text(Command.OWW))):
        drive.clear_multiturn()
    drive.servo(False)
    with pytest.raises(CommandRejected, match=exactly(rejected_text(Command.MOV))):
        drive.move_by(5.0)  # and no move with it off


def test_the_sensors_of_an_actuator_without_option_l_stay_where_they_are(drive):
    angles = drive.sensor_angles()
    assert set(angles) == {"origin", "ls1", "ls2"}
    with pytest.raises(CommandRejected, match=exactly(rejected_text(Command.SNO))):
        drive.set_sensor_angle("origin", 10.0)
    assert drive.sensor_angles() == angles
