"""The link worker against the in-memory DriveApi fake: typed results, typed failures, dispatch."""

from __future__ import annotations

import threading

import pytest

from fha_studio.gui.link import (
    ClearAlarm,
    Jog,
    LinkController,
    LinkReply,
    LinkRequest,
    LinkWorker,
    NotConnected,
    PowerCycle,
    ReadAlarmHistory,
    Servo,
    Stop,
    WriteParameters,
)
from fha_studio.gui.link_requests import REQUESTS
from fha_studio.gui.pages.scope.driver import ScopeCmd, ScopeDriver
from fha_studio.hardware.api import CommandRejected, DriveRefused, LinkTimeout, ServoOnRefused
from tests.gui.fake_drive import FakeDriveClient


def test_every_link_command_has_a_handler(qtbot):
    worker = LinkWorker(threading.Event())
    assert set(worker.handlers) == set(REQUESTS)


def test_every_scope_command_has_a_handler(qtbot):
    driver = ScopeDriver()
    assert set(driver.handlers) == set(ScopeCmd)


@pytest.fixture
def fake():
    return FakeDriveClient()


@pytest.fixture
def link(qtbot):
    controllers = []

    def make(open_client=None) -> LinkController:
        controller = LinkController(open_client=open_client)
        controllers.append(controller)
        return controller

    yield make
    for controller in controllers:
        assert controller.shutdown(10000)


def _result_of(qtbot, link: LinkController, request: LinkRequest) -> LinkReply:
    got: list[LinkReply] = []
    link.send(request, got.append)  # the reply goes to whoever asked
    qtbot.waitUntil(lambda: bool(got), timeout=10000)
    return got[0]


def test_a_command_without_a_link_fails_as_not_connected(qtbot, link):
    controller = link()
    result = _result_of(qtbot, controller, Servo(True))
    assert not result.ok and result.error_type is NotConnected and result.error == "not connected"
    assert not controller.busy  # STOP without a link answers too: nothing stays pending
    assert _result_of(qtbot, controller, Stop()).ok
    assert not controller.busy


def test_failures_carry_the_exception_class(qtbot, link, fake):
    controller = link(lambda url, baud: fake)
    with qtbot.waitSignal(controller.sigConnected, timeout=10000):
        controller.open("fake://")
    assert _result_of(qtbot, controller, Servo(True)).ok
    refused = _result_of(qtbot, controller, PowerCycle())
    assert refused.error_type is ServoOnRefused and refused.failed_with(DriveRefused)
    assert "servo is on" in refused.error
    fake.raise_alarm(71)  # needs a power cycle
    rejected = _result_of(qtbot, controller, ClearAlarm())
    assert rejected.failed_with(CommandRejected) and not rejected.failed_with(ServoOnRefused)


def test_writes_are_reported_from_the_typed_write_result(qtbot, link, fake):
    controller = link(lambda url, baud: fake)
    with qtbot.waitSignal(controller.sigConnected, timeout=10000):
        controller.open("fake://")
    direction = fake.model.by_key("rotary_direction")
    writes = ((direction.mode, direction.number, 1),)
    result = _result_of(qtbot, controller, WriteParameters(writes))
    [entry] = result.value
    assert entry["old"] == 0 and entry["read_back"] == 1 and entry["verified"]
    assert entry["restart_required"] and "power cycle" in entry["message"]


def test_alarm_history_is_alarm_records(qtbot, link, fake):
    controller = link(lambda url, baud: fake)
    with qtbot.waitSignal(controller.sigConnected, timeout=10000):
        controller.open("fake://")
    fake.raise_alarm(20)
    result = _result_of(qtbot, controller, ReadAlarmHistory())
    assert [(r.code, r.seconds_since_power_on) for r in result.value] == [(20, 123)]


def test_a_reply_goes_to_whoever_asked(qtbot, link, fake):
    controller = link(lambda url, baud: fake)
    with qtbot.waitSignal(controller.sigConnected, timeout=10000):
        controller.open("fake://")
    servo: list[LinkReply] = []
    history: list[LinkReply] = []
    controller.send(Servo(True), servo.append)
    controller.send(ReadAlarmHistory(), history.append)
    qtbot.waitUntil(lambda: bool(servo and history), timeout=10000)
    assert [type(r.request) for r in servo] == [Servo] and servo[0].answer is True
    assert [type(r.request) for r in history] == [ReadAlarmHistory] and history[0].answer == []


def test_a_held_jog_that_fails_later_is_told_to_its_sender(qtbot, link, fake):
    controller = link(lambda url, baud: fake)
    with qtbot.waitSignal(controller.sigConnected, timeout=10000):
        controller.open("fake://")
    assert _result_of(qtbot, controller, Servo(True)).ok
    jog: list[LinkReply] = []
    controller.jog_press(5.0, jog.append)
    qtbot.waitUntil(lambda: bool(jog), timeout=10000)
    assert jog[0].ok and jog[0].answer == 5.0
    fake.servo_on = False  # the controller's servo-OFF: the next renewal is refused
    qtbot.waitUntil(lambda: len(jog) == 2, timeout=10000)
    assert jog[1].answers(Jog) and jog[1].failed_with(CommandRejected) and jog[1].token == 0
    assert not controller.moving  # the lease is let go


def test_the_link_is_lost_only_on_the_transaction_layers_verdict(qtbot, link, fake, monkeypatch):
    controller = link(lambda url, baud: fake)
    with qtbot.waitSignal(controller.sigConnected, timeout=10000):
        controller.open("fake://")

    def timed_out() -> None:
        raise LinkTimeout("ALC on fake://: no reply after 2 attempt(s)")

    monkeypatch.setattr(fake, "clear_alarm", timed_out)
    lost: list[bool] = []
    controller.sigDisconnected.connect(lambda reason, was_lost: lost.append(was_lost))
    failed = _result_of(qtbot, controller, ClearAlarm())
    assert failed.failed_with(LinkTimeout) and controller.connected  # not LinkLost: the link stays
    fake.close()  # now the drive's side says LinkLost
    qtbot.waitUntil(lambda: bool(lost), timeout=10000)
    assert lost == [True] and not controller.connected
