"""The link's loops without Qt: the status poll, the idle probe of a drive of the manual's commands
only, and the parameter read and write, run straight over the simulated drive (``sim://``)."""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from fha_studio.hardware.api import LinkLost
from fha_studio.hardware.client import DriveClient
from fha_studio.hardware.parameters import Mode
from fha_studio.hardware.protocol import IoBit
from fha_studio.logic.drive_session import (
    POLL_INTERVAL_MS,
    PROBE_INTERVAL_MS,
    SERVO_ON_NOTE,
    SERVO_ON_PROBE_MS,
    StatusPoller,
    WriteEntry,
    read_parameters,
    write_parameters,
)

ACTUATOR = "FHA-25C-50-S248"


@pytest.fixture
def drive(tmp_path) -> Iterator[DriveClient]:
    client = DriveClient.open(f"sim://{ACTUATOR}?paced=0&eeprom={tmp_path / 'eeprom.json'}")
    try:
        yield client
    finally:
        client.close()


@pytest.fixture
def documented(tmp_path) -> Iterator[DriveClient]:
    """A drive that answers only its manual: DGR and OWW."""
    client = DriveClient.open(f"sim://{ACTUATOR}?paced=0&profile=documented&eeprom={tmp_path / 'e.json'}")
    try:
        yield client
    finally:
        client.close()


def test_a_poll_reads_alarm_io_and_the_monitors(drive):
    poller = StatusPoller(drive)
    status, next_ms = poller.poll(jogging=False, time_s=12.5)
    assert next_ms == POLL_INTERVAL_MS and status.time_s == 12.5
    assert status.alarm_code == 0 and status.servo_on is False and status.io_bits is not None
    assert status.bit(IoBit.SERVO_ON) is False and not status.moving
    assert status.position_pulse is not None and status.speed_rpm == pytest.approx(0.0, abs=0.5)
    assert status.current_a is not None and not status.refused and status.absolute_counts is None
    drive.servo(True)
    status, _ = poller.poll(jogging=True)
    assert status.servo_on is True and status.moving  # a held jog counts as moving
    drive.servo(False)


def test_the_poll_never_runs_faster_than_its_period(drive):
    poller = StatusPoller(drive)
    assert poller.set_interval(10) == POLL_INTERVAL_MS
    assert poller.set_interval(250) == 250 and poller.poll()[1] == 250


def test_a_documented_drive_is_probed_with_dgr_and_less_often_while_its_servo_is_on(documented):
    poller = StatusPoller(documented)
    status, next_ms = poller.poll()
    assert next_ms == PROBE_INTERVAL_MS
    assert isinstance(status.absolute_counts, int) and status.servo_on is False
    assert status.alarm_code is None and status.io_bits is None  # the manual has no status commands
    panel = documented.sim_panel
    assert panel is not None
    panel.set_servo(True)  # the controller's servo-ON (CN2): DGR answers s
    status, next_ms = poller.poll()
    assert status.refused and status.servo_on is True and status.note == SERVO_ON_NOTE
    assert next_ms == SERVO_ON_PROBE_MS and status.absolute_counts is None
    panel.set_servo(False)


def test_a_lost_link_comes_out_of_the_poll(drive):
    poller = StatusPoller(drive)
    drive.transaction.transport.inner.close()  # the cable is pulled
    with pytest.raises(LinkLost):
        poller.poll()


def test_a_read_gives_each_item_its_value_or_its_sentence(drive):
    in_position = drive.model.by_key("in_position_range")
    key = (in_position.mode, in_position.number)
    readout = read_parameters(drive, [key, (Mode.SYSTEM, 999)])
    assert readout.values == {key: drive.read_parameter(*key)}
    assert list(readout.errors) == [(Mode.SYSTEM, 999)] and readout.errors[(Mode.SYSTEM, 999)]
    stopped = read_parameters(drive, [key], stopped=lambda: True)
    assert stopped.values == {} and stopped.errors == {key: "stopped"}


def test_writes_are_verified_and_a_refused_one_does_not_stop_the_rest(drive):
    in_position = drive.model.by_key("in_position_range")
    direction = drive.model.by_key("rotary_direction")
    before = drive.read_parameter(in_position.mode, in_position.number)
    drive.servo(True)  # parameter-mode items are refused while the servo is on
    logged: list[WriteEntry] = []
    try:
        done = write_parameters(
            drive,
            [(direction.mode, direction.number, 1), (in_position.mode, in_position.number, before + 3)],
            on_write=logged.append,
        )
    finally:
        drive.servo(False)
    assert logged == done and [e["mode"] for e in done] == [direction.mode, in_position.mode]
    refused, written = done  # a tune-mode item is written with the servo on
    assert direction.mode is Mode.SYSTEM and in_position.mode is Mode.TUNE
    assert refused["error"] and not refused["verified"]
    assert written["verified"] and written["old"] == before and written["read_back"] == before + 3
    assert written["error"] is None
    [stopped] = write_parameters(drive, [(in_position.mode, in_position.number, before)], lambda: True)
    assert stopped["error"] == "not written: stopped"
    assert drive.read_parameter(in_position.mode, in_position.number) == before + 3
    assert write_parameters(drive, [(in_position.mode, in_position.number, before)])[0]["verified"]
