"""DriveClient against scripted in-process drives: the transaction layer and the API."""

from __future__ import annotations

import threading
import time

import pytest
from drive_fakes import FAST, OK, MiniDrive, S, X

from fha_studio.hardware import protocol as p
from fha_studio.hardware.client import (
    CapabilityLevel,
    CommandNotSupported,
    CommandRejected,
    DriveClient,
    Identity,
    LinkLost,
    LinkSettings,
    LinkSilent,
    LinkTimeout,
    ReadAborted,
    ServoOnRefused,
)
from fha_studio.hardware.parameters import ParameterValueError
from fha_studio.hardware.protocol import Command, Reply
from fha_studio.hardware.transport import corrupt_at, split_every
from tests.support.documented import DocumentedDrive

# --- settings ---------------------------------------------------------------------------------


def test_timeouts_follow_the_baud_rate():
    s = LinkSettings()
    assert s.character_time_s == pytest.approx(10 / 19200)
    assert s.first_byte_timeout_s(Command.IOS) == pytest.approx(10 * 10 / 19200 + s.response_timeout_s)
    assert s.first_byte_timeout_s(Command.OWW) > 5.0  # "q about 5 s later"
    slow = LinkSettings(baudrate=1200)
    assert slow.first_byte_timeout_s(Command.IOS) > s.first_byte_timeout_s(Command.IOS)
    with pytest.raises(ValueError, match="retries"):
        LinkSettings(retries=-1)


# --- a full drive ------------------------------------------------------------------------------


def test_capabilities_and_identity_of_a_full_drive(client_for, mini):
    client, drive = client_for(mini)
    caps = client.capabilities
    assert caps.level is CapabilityLevel.TRACE
    assert caps.absolute_position is True and caps.simulated and caps.parameters
    assert "records traces" in caps.describe()
    assert client.identify() == Identity("HA-655-2-200", "FHA-17C-50-US250", "mini 0.1")
    assert drive.commands()[:2] == ["CAP", "DGR"]


def test_an_ha675_gets_its_parameter_model(client_for, mini):
    mini.override["IDN"] = lambda r: Reply(("HA-675-4-200", "FHA-32C-100-S248", "fw 2"))
    client, _ = client_for(mini)
    assert client.model.driver == "HA-655"
    client.identify()
    assert client.model.driver == "HA-675" and not client.model.by_key("rotary_direction").certain


def test_read_and_verified_write_of_rotary_direction(client_for, mini):
    client, _ = client_for(mini)
    assert client.read_parameter("system", 8) == 0
    result = client.write_parameter("system", 8, 1)
    assert result.verified and result.holds == "new" and result.previous == 0 and result.value == 1
    assert result.needs_restart  # restart_required (assumed) and changed
    assert client.read_parameter("system", 8) == 1
    assert mini.values[("system", 8)] == 1


def test_bad_value_is_refused_before_anything_is_sent(client_for, mini):
    client, drive = client_for(mini)
    sent = len(drive.requests)
    with pytest.raises(ParameterValueError, match=r"parameter 8, rotary direction: 7 is not one of"):
        client.write_parameter("system", 8, 7)
    with pytest.raises(ParameterValueError, match="no system item 5"):
        client.write_parameter("system", 5, 0)
    with pytest.raises(ParameterValueError, match="read-only"):
        client.write_parameter("monitor", 3, 0)
    assert len(drive.requests) == sent


def test_write_refused_with_servo_on_says_the_old_value_is_held(client_for, mini):
    client, _ = client_for(mini)
    client.servo(True)
    held = r"parameter 8, rotary direction: .*holds 0: FWD turns CW .*, the old value"
    with pytest.raises(ServoOnRefused, match=held):
        client.write_parameter("system", 8, 1)
    # tune items may be changed with the servo on
    assert client.write_parameter("tune", 4, 20).verified


def test_write_that_does_not_take_reports_old_value(client_for, mini):
    mini.override["PWR"] = lambda r: OK  # acknowledges, stores nothing
    client, _ = client_for(mini)
    result = client.write_parameter("tune", 0, 77)
    assert not result.verified and result.holds == "old" and result.value == 60
    assert "still holds 60" in result.message


def test_write_whose_acknowledgement_is_lost_is_judged_by_read_back(client_for, mini):
    def store_silently(request):
        mini.values[mini.selected] = request.value
        return None  # the q never comes

    mini.override["PWR"] = store_silently
    client, _ = client_for(mini)
    result = client.write_parameter("tune", 0, 77)
    assert result.holds == "new" and result.verified


def test_read_all_parameters_marks_items_the_drive_lacks(client_for, mini):
    del mini.values[("system", 9)]
    client, _ = client_for(mini)
    values = client.read_all_parameters("system")
    assert values[8] == 0 and values[0] == 0
    assert values[9] is None
    assert set(values) == {i.number for i in client.model.in_mode("system")}


def test_monitors_by_mmr_and_by_mon(client_for):
    full = MiniDrive()
    client, drive = client_for(full)
    assert client.read_monitors([103, 100]) == {100: 1100, 103: 1103}
    assert drive.commands()[-1] == "MMR"
    assert client.read_monitors([3, 4]) == {3: 1003, 4: 1004}  # not maskable: MON each
    assert drive.commands()[-2:] == ["MON", "MON"]


def test_monitors_fall_back_to_mon_without_mmr(client_for):
    drive_model = MiniDrive(caps=["MON"])
    client, drive = client_for(drive_model)
    assert client.capabilities.level is CapabilityLevel.POLLING
    assert "polls" in client.capabilities.describe()
    assert client.read_monitors([100, 103]) == {100: 1100, 103: 1103}
    assert "MMR" not in drive.commands()


def test_motion_commands_scale_to_the_wire(client_for, mini):
    client, drive = client_for(mini)
    client.servo(True)
    client.jog(-12.345)
    client.set_move_speed(5)
    client.move_by(90.0)
    client.stop()
    sent = [(r.command.value, r.value) for r in drive.requests[-5:]]
    assert sent == [("SVO", 1), ("JOG", -1234), ("SPD", 500), ("MOV", 9000), ("STP", 0)] or sent == [
        ("SVO", 1), ("JOG", -1235), ("SPD", 500), ("MOV", 9000), ("STP", 0)
    ]
    with pytest.raises(ValueError, match="outside"):
        client.move_by(1000.0)
    with pytest.raises(ValueError, match="positive"):
        client.set_move_speed(0)


def test_alarms_and_io(client_for, mini):
    client, _ = client_for(mini)
    assert client.alarm() == 0
    assert [(a.code, a.seconds_since_power_on) for a in client.alarm_history()] == [(60, 12), (20, 3)]
    client.clear_alarm()
    state = client.set_inputs(brake_released=True, fwd_inhibit=True)
    assert state.brake_released and state.fwd_inhibit and not state.rev_inhibit
    assert state.alm_bits == 0b0010
    state = client.set_inputs(fwd_inhibit=False)
    assert state.brake_released and not state.fwd_inhibit
    assert mini.inputs == 1 << p.IoBit.BRAKE_RELEASED
    with pytest.raises(ValueError, match="unknown inputs"):
        client.set_inputs(warp_drive=True)


def test_sim_only_training_commands(client_for, mini):
    client, _drive = client_for(mini)
    client.inject_alarm(50)
    client.set_sensor_angle("ls1", -95.5)
    assert client.sensor_angles() == pytest.approx({"origin": 0.0, "ls1": -90.0, "ls2": 90.0})
    assert mini.moves == [("FLT", 50), ("SNA", -9550)]


WITHOUT_PACKED = sorted(c.value for c in p.EXTENSION_COMMANDS if c is not Command.TRP)


@pytest.mark.parametrize(("caps", "encoding", "command"), [
    (None, "packed", "TRP"),  # a drive that lists TRP in CAP
    (WITHOUT_PACKED, "text", "TRB"),  # an older drive: text blocks only
])
def test_trace_capture_reads_all_blocks(client_for, caps, encoding, command):
    client, drive = client_for(MiniDrive(caps))
    assert client.trace_encoding == encoding
    assert client.configure_trace([103, 100], divider=2) == (100, 103)
    client.arm_trace(130)
    status = client.trace_status()
    assert status.state is p.TraceState.DONE and status.count == 130
    capture = client.read_trace()
    assert len(capture.samples) == 130
    assert capture.column(103)[129] == 1291
    assert list(capture.column(100)[:3]) == [0, 10, 20]
    other = "TRB" if command == "TRP" else "TRP"
    assert drive.commands().count(command) == 3 and drive.commands().count(other) == 0
    with pytest.raises(ValueError, match="channels"):
        client.configure_trace([100, 101, 102, 103, 104])


def test_trace_read_out_block_by_block_gives_up_when_asked(client_for, mini):
    client, drive = client_for(mini)
    client.configure_trace([103, 100], divider=2)
    client.arm_trace(130)  # 3 blocks: 64, 64, 2
    assert client.read_trace_block(2, 130) == [(1280, 1281), (1290, 1291)]
    with pytest.raises(ValueError, match="outside a capture of 130"):
        client.read_trace_block(3, 130)
    asked = []

    def stop_after_two_blocks() -> bool:
        asked.append(len(asked))
        return len(asked) > 2

    before = drive.commands().count("TRP")
    with pytest.raises(ReadAborted, match="after 128 of 130 samples") as stopped:
        client.read_trace(should_abort=stop_after_two_blocks)
    assert (stopped.value.done, stopped.value.total) == (128, 130)
    assert drive.commands().count("TRP") - before == 2  # the third block was never asked for
    assert len(client.read_trace(should_abort=lambda: False).samples) == 130  # the link is fine
    with pytest.raises(ReadAborted, match="after 0 of 130"):
        client.read_trace(should_abort=lambda: True)  # a STOP before the read-out: nothing read


def test_clear_multiturn_waits_for_the_late_acknowledgement(client_for, mini):
    client, _ = client_for(mini)  # answers OWW after 0.2 s, beyond response_timeout_s
    client.clear_multiturn()
    assert client.statistics["failed_attempts"] == 0


def test_trace_packet_sees_both_directions(client_for, mini):
    client, _ = client_for(mini)
    seen = []
    client.trace_packet = lambda sending, data: seen.append((sending, data))
    client.alarm()
    assert (True, b"ALM+00000\r") in seen
    assert b"".join(d for s, d in seen if not s) == b"0\rq\r"


def test_many_threads_share_one_client(client_for, mini):
    client, _ = client_for(mini)
    errors, results = [], []

    def work(number):
        try:
            for _ in range(10):
                results.append(client.read_parameter("tune", number) == mini.values[("tune", number)])
        except Exception as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work, args=(n,)) for n in (0, 1, 2, 4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and len(results) == 40 and all(results)


# --- faults: timeouts, garbage, half frames, s, unplugging -------------------------------------


def test_silence_times_out_after_the_retries(client_for, mini, time_ceiling):
    mini.override["ALM"] = lambda r: None
    client, drive = client_for(mini)
    t0 = time.monotonic()
    with pytest.raises(LinkSilent, match=r"nothing arrives on test:host \(to .*: 3 attempt"):
        client.alarm()
    assert drive.commands().count("ALM") == 3  # the retries are counted, not timed
    # 3 x 0.08 s of timeouts by design
    time_ceiling("three silent attempts at 0.08 s", time.monotonic() - t0, 10.0)
    assert not client.link_lost


def test_consecutive_failures_mark_the_link_lost_and_one_success_resets(client_for, mini):
    silent = {"on": True}
    mini.override["ALM"] = lambda r: None if silent["on"] else Reply(("0",))
    client, _ = client_for(mini, LinkSettings(response_timeout_s=0.03, retries=0, max_consecutive_failures=3))
    for _ in range(2):
        with pytest.raises(LinkTimeout):
            client.alarm()
    silent["on"] = False
    assert client.alarm() == 0  # resets the count
    silent["on"] = True
    for _ in range(2):
        with pytest.raises(LinkTimeout):
            client.alarm()
    with pytest.raises(LinkLost, match="3 failed transactions in a row"):
        client.alarm()
    with pytest.raises(LinkLost):
        client.io_state()  # stays lost
    assert client.link_lost


def test_a_supervisor_sets_how_many_failures_lose_the_link(client_for, mini):
    """The GUI's link worker asks for a dead link at the first unanswered exchange: the same
    rule, one failure (not a second count of its own)."""
    silent = {"on": False}
    mini.override["ALM"] = lambda r: None if silent["on"] else Reply(("0",))
    client, _ = client_for(mini, LinkSettings(response_timeout_s=0.03, retries=0, max_consecutive_failures=3))
    client.lose_link_after(1)
    assert client.settings.max_consecutive_failures == 1 and client.alarm() == 0
    silent["on"] = True
    with pytest.raises(LinkLost, match="link marked lost") as lost:
        client.alarm()
    assert "in a row" not in str(lost.value) and client.link_lost


def test_noise_before_a_reply_is_skipped_without_a_retry(client_for, mini):
    mini.override["ALM"] = lambda r: [b"\x00\xff\r\n", Reply(("20",))]
    client, drive = client_for(mini)
    assert client.alarm() == 20
    assert drive.commands().count("ALM") == 1
    assert client.statistics["garbage_bytes"] == 4


def test_printable_garbage_before_a_reply_is_retried(client_for, mini):
    calls = []

    def once_garbage(request):
        calls.append(request)
        return [b"junk\r", Reply(("20",))] if len(calls) == 1 else Reply(("20",))

    mini.override["ALM"] = once_garbage
    client, _ = client_for(mini)
    assert client.alarm() == 20
    assert len(calls) == 2


def test_half_a_reply_then_silence_is_retried(client_for, mini):
    calls = []
    mini.override["IOS"] = lambda r: calls.append(r) or (b"12" if len(calls) == 1 else Reply(("12",)))
    client, _ = client_for(mini)
    assert client.io_state().raw == 12
    assert len(calls) == 2


def test_a_late_reply_is_not_taken_for_the_next_one(client_for, mini):
    calls = []

    def late_then_ok(request):
        calls.append(request)
        # first answer arrives after the client gave up on the attempt
        return [0.15, Reply(("111",))] if len(calls) == 1 else Reply(("222",))

    mini.override["ALM"] = late_then_ok
    client, _ = client_for(mini)
    assert client.alarm() == 222


def test_corrupted_reply_is_retried(client_for, mini, pipes):
    client, _ = client_for(mini)
    pipes[1].write_filter = corrupt_at(0, 0x00)  # noise in the first byte of every drive write
    with pytest.raises(LinkTimeout, match=r"corrupt|malformed"):
        client.alarm()
    pipes[1].write_filter = split_every(1)  # byte by byte is fine
    assert client.alarm() == 0


def test_servo_on_is_an_answer_not_a_link_fault(client_for, mini):
    client, drive = client_for(mini)
    client.servo(True)
    before = drive.commands().count("DGR")
    with pytest.raises(ServoOnRefused, match="servo is on"):
        client.absolute_position()
    assert drive.commands().count("DGR") == before + 1  # not retried
    assert client.statistics["consecutive_failures"] == 0 and not client.link_lost


def test_x_is_raised_as_command_rejected_once(client_for, mini):
    mini.override["ACL"] = lambda r: X
    client, drive = client_for(mini)
    with pytest.raises(CommandRejected, match="the drive refused to clear the alarm"):
        client.clear_alarm()
    assert drive.commands().count("ACL") == 1


def test_move_is_never_repeated(client_for, mini):
    mini.override["MOV"] = lambda r: mini.moves.append(r.value)
    client, _ = client_for(mini)
    with pytest.raises(LinkTimeout, match="unknown whether the drive acted"):
        client.move_by(10)
    assert mini.moves == [1000]


def test_unplugged_port_raises_link_lost_naming_it(client_for, mini, pipes):
    client, _ = client_for(mini)
    pipes[0].unplug()
    with pytest.raises(LinkLost, match="test:host"):
        client.alarm()
    assert client.link_lost
    with pytest.raises(LinkLost):
        client.alarm()


# --- drives of the manual's command set --------------------------------------------------------


def test_documented_only_drive_degrades_to_dgr(client_for):
    client, drive = client_for(DocumentedDrive(position=-8193))
    caps = client.capabilities
    assert caps.level is CapabilityLevel.ABSOLUTE_POSITION
    assert "absolute position (DGR)" in caps.describe() and "servo is off" in caps.describe()
    assert client.identify() is None
    assert client.absolute_position() == -8193
    assert p.split_absolute_position(-8193) == (-2, 8191)
    sent = len(drive.requests)
    with pytest.raises(CommandNotSupported, match="does not have MON"):
        client.read_monitor(3)
    with pytest.raises(CommandNotSupported):
        client.read_parameter("system", 8)
    with pytest.raises(CommandNotSupported):
        client.configure_trace([100])
    assert len(drive.requests) == sent  # nothing sent for what the drive lacks
    client.clear_multiturn()


def test_documented_only_drive_with_servo_on(client_for):
    client, _ = client_for(DocumentedDrive(servo_on=True))
    assert client.capabilities.absolute_position is None
    assert "not known yet" in client.capabilities.describe()
    with pytest.raises(ServoOnRefused):
        client.absolute_position()


def test_incremental_documented_only_drive_offers_nothing(client_for):
    client, _ = client_for(DocumentedDrive(incremental=True))
    assert client.capabilities.level is CapabilityLevel.NOTHING
    assert "front panel" in client.capabilities.describe()


def test_drive_silent_to_cap_but_answering_dgr(client_for):
    def handler(request):
        if isinstance(request, p.Request) and request.command is Command.DGR:
            return Reply(("5",))
        return None  # ignores what it does not know

    client, _ = client_for(handler, LinkSettings(response_timeout_s=0.03, retries=0))
    assert client.capabilities.level is CapabilityLevel.ABSOLUTE_POSITION
    assert "did not answer CAP" in client.capabilities.describe()


def test_no_drive_at_all_fails_to_attach_and_closes(pipes, scripted, time_ceiling):
    drive = scripted(lambda r: None)
    t0 = time.monotonic()
    with pytest.raises(LinkTimeout, match="no drive answers on test:host"):
        DriveClient.attach(pipes[0], LinkSettings(response_timeout_s=0.03, retries=1))
    time_ceiling("attaching to no drive at 0.03 s a try", time.monotonic() - t0, 5.0)
    assert drive.commands() == ["CAP", "CAP", "DGR", "DGR"]  # each asked twice, then given up
    assert not pipes[0].is_open


def test_closed_client_refuses(client_for, mini):
    client, _ = client_for(mini)
    client.close()
    client.close()
    with pytest.raises(LinkLost, match="closed"):
        client.alarm()


def test_fast_settings_are_what_the_tests_assume():
    assert FAST.response_timeout_s < 0.1 and S.status is p.Status.SERVO_ON and OK.status is p.Status.DONE


def test_the_client_is_a_drive_api_and_its_transaction_layer_knows_no_command_meaning(client_for, mini):
    from fha_studio.hardware.api import DriveApi
    from fha_studio.hardware.transaction import one_int

    client, _ = client_for(mini)
    assert isinstance(client, DriveApi)
    # the transaction layer alone: one exchange, its parser, its statistics
    assert client.transaction.transact(Command.MON, 103, parse=one_int) == 1103
    assert client.transaction.statistics["transactions"] >= 3  # CAP, DGR, MON
