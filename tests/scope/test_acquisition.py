"""Acquisition without Qt: the line's budget, polling, the documented-only drive, trace read-out."""

from __future__ import annotations

import numpy as np
import pytest
from scope_fakes import FAST, MonitorDrive

from fha_studio.hardware import protocol as p
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.scope.acquisition import (
    LiveMode,
    PollingAcquisition,
    TraceAcquisition,
    TraceSettings,
    Trigger,
    load_scope_config,
    mmr_reply_chars,
    sample_line_time_s,
    theoretical_rate_hz,
)
from fha_studio.logic.scope.channels import scope_channels
from tests.support.clock import FakeClock
from tests.support.documented import DocumentedDrive

PPR = 500_000  # output resolution of the channels: 500 000 pulses = 360 deg


@pytest.fixture(scope="module")
def channels():
    return {c.key: c for c in scope_channels(load_parameter_model(), PPR)}


def pick(channels, *keys):
    return [channels[k] for k in keys]


def test_line_budget_counts_request_and_reply_characters():
    # "123456,-5,0" CR, then "q" CR: 14 characters; the request is 10; 10 bits each at 19200 bit/s
    assert mmr_reply_chars([123456, -5, 0]) == 14
    assert sample_line_time_s([123456, -5, 0]) == pytest.approx(24 * 10 / 19200)
    assert theoretical_rate_hz([123456, -5, 0]) == pytest.approx(80.0)
    assert theoretical_rate_hz([1] * 4) > theoretical_rate_hz([1_000_000] * 4)


def test_polling_delivers_converted_rows_and_the_bound(client_for, channels):
    drive = MonitorDrive()
    client, _ = client_for(drive, FAST)
    chosen = pick(channels, "feedback_position", "output_speed", "motor_current", "in_position", "servo_on")
    acq = PollingAcquisition(client, chosen, capacity=1000)
    assert acq.mode is LiveMode.MONITORS and acq.items == [100, 103, 104, 106]
    got = 0
    while got < 5:
        got += acq.step(0.02)
    rows = acq.ring.drain()
    assert rows.shape == (got, 6)
    assert np.all(np.diff(rows[:, 0]) > 0)
    assert rows[-1, 1:] == pytest.approx([360.0, -12.34, 1.5, 1.0, 1.0])
    status = acq.status()
    assert status.live and status.label == "LIVE" and status.samples == got
    # the bound for "500000,-1234,1500,9" + CR + q CR = 22 + 10 request characters
    assert acq.limit_hz == pytest.approx(1920 / 32)


def test_a_silent_drive_is_not_live_and_old_samples_go_stale(client_for, channels):
    drive = MonitorDrive()
    client, _ = client_for(drive, FAST)
    clock = FakeClock(now=0.0)
    acq = PollingAcquisition(client, pick(channels, "feedback_position"), clock=clock)
    assert acq.step(0) == 1 and acq.status().live
    clock.now = 10.0
    status = acq.status()
    assert not status.live and "no new sample for 10.0 s" in status.reason
    drive.silent = True
    assert acq.step(0) == 0
    assert acq.status().label.startswith("NOT LIVE: no answer from the drive")


def test_documented_only_drive_shows_position_by_dgr_labelled_as_such(client_for, channels):
    drive = DocumentedDrive(position=8192 * 50 * 3 // 4)  # 3/4 of an output turn on a ratio-50 axis
    client, _ = client_for(drive, FAST)
    acq = PollingAcquisition(client, pick(channels, "feedback_position", "motor_current"), ratio=50)
    assert acq.mode is LiveMode.POSITION
    assert [c.key for c in acq.channels] == ["feedback_position"]
    assert acq.step(0) == 1
    assert acq.ring.drain()[0, 1] == pytest.approx(270.0)
    status = acq.status()
    assert status.live and status.label == "LIVE: position only (DGR, servo off)"
    assert acq.retry_interval_s == 0.25
    drive.servo_on = True
    assert acq.step(0) == 0
    status = acq.status()
    assert status.label.startswith("NOT LIVE: servo on (controller)") and "until servo off" in status.reason
    assert status.rate_hz == 0.0  # nothing polled: no rate figure
    assert acq.retry_interval_s == 1.0  # at most one DGR a second while the drive answers s
    assert len(acq.ring.drain()) == 0  # nothing pretends to be a new sample
    drive.servo_on = False
    assert acq.step(0) == 1 and acq.retry_interval_s == 0.25


def test_documented_only_drive_without_a_known_ratio_reads_nothing(client_for, channels):
    client, _ = client_for(DocumentedDrive(), FAST)
    acq = PollingAcquisition(client, pick(channels, "feedback_position"))
    assert acq.mode is LiveMode.NONE and acq.step(0) == 0
    assert "ratio" in acq.status().reason


def test_trace_is_configured_on_the_wire_and_read_back_in_display_units(client_for, channels):
    drive = MonitorDrive()
    drive.trace_rows = [(k * 100, k * 10, 0b1000 if k >= 30 else 0) for k in range(100)]
    client, _ = client_for(drive, FAST)
    trace = TraceAcquisition(client)
    assert trace.available() == (True, "")
    chosen = tuple(pick(channels, "feedback_position", "output_speed", "in_position"))
    settings = TraceSettings(chosen, sample_rate_hz=1000, samples=100, pre_trigger=20,
                             trigger=Trigger(p.TriggerKind.RISING_LEVEL, channels["output_speed"], 1.5))
    trace.configure(settings)
    trace.arm()
    servo_rate = load_scope_config().servo_rate_hz
    assert drive.trace == {"TCH": 0b1001001, "TDV": round(servo_rate / 1000), "TTG": 1, "TTC": 103,
                           "TTL": 150, "TPR": 20, "TAR": 100}
    result = trace.read()
    assert result.t_s[20] == 0 and result.t_s[0] == pytest.approx(-0.02)
    assert result.column("feedback_position")[1] == pytest.approx(100 * 360 / PPR)
    assert result.column("output_speed")[3] == pytest.approx(0.3)
    assert result.column("in_position")[29:31].tolist() == [0.0, 1.0]
    assert result.rows().shape == (100, 4)


def test_trace_settings_say_what_is_wrong(channels):
    five = tuple(pick(channels, "feedback_position", "command_position", "error_pulses", "output_speed",
                      "motor_current"))
    with pytest.raises(ValueError, match="at most 4 monitor items"):
        TraceSettings(five).check()
    with pytest.raises(ValueError, match="edge trigger needs an I/O bit"):
        Trigger(p.TriggerKind.IO_BIT_RISES, channels["output_speed"]).wire()
    assert Trigger(p.TriggerKind.IO_BIT_FALLS, channels["in_position"]).wire() == (4, 3, 0)
    assert Trigger(p.TriggerKind.ALARM).describe() == "on an alarm"


def test_a_drive_without_trace_says_so(client_for):
    client, _ = client_for(MonitorDrive(caps="MON MMR IOS"), FAST)
    ok, why = TraceAcquisition(client).available()
    assert not ok and "no trace capture" in why


def test_every_phase_of_the_move_test_has_a_handler(channels):
    from fha_studio.logic.scope.acquisition import MoveTest, _Phase
    from tests.gui.fake_drive import FakeDriveClient

    picked = pick(channels, "feedback_position", "command_position")
    test = MoveTest(FakeDriveClient(), picked, 10.0, 5.0, use_trace=False)
    assert set(test._phases) == set(_Phase)
