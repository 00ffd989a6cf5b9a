"""The simulated drive's CN3 face: a decoded request in, a reply carrying its Status out, and what
a training drive's journal records of commands and panel actions (typed, not names)."""

from __future__ import annotations

from fha_studio.hardware.parameters import Mode
from fha_studio.hardware.protocol import Command, Request, Status, UnknownRequest
from fha_studio.hardware.sim import SimResponder
from fha_studio.hardware.sim.journal import PanelAction
from fha_studio.hardware.sim.options import forget_training, register_training


def test_a_reply_carries_the_protocol_status_and_an_unknown_name_does_nothing(make_drive):
    sim = SimResponder(make_drive())
    assert sim.respond(Request(Command.PSL, 8)).terminal is Status.DONE
    assert sim.respond(Request(Command.PRD)).lines == ("0",)
    refused = sim.respond(Request(Command.JOG, 1000))
    assert refused.terminal is Status.REJECTED and "servo is off" in refused.reason
    assert sim.respond(UnknownRequest("XYZ", 0)).terminal is Status.REJECTED


def test_the_journal_records_commands_and_panel_actions_with_the_state_before(make_drive):
    registration = register_training("")
    try:
        drive = make_drive("FHA-25C-50-S248", profile="documented", training=registration.token)
        sim = SimResponder(drive)
        sim.turn_by_hand(5.0)
        sim.set_servo(True)
        assert sim.respond(Request(Command.DGR)).terminal is Status.SERVO_ON
        sim.controller_command(-2.0)
        sim.respond(UnknownRequest("XYZ", 0))  # nothing done to the drive: not written
        entries = registration.journal.entries()
    finally:
        forget_training(registration.token)
    assert [(e.command, e.value, e.terminal) for e in entries] == [
        (PanelAction.HAND_TURN, 5, Status.DONE),
        (Command.DGR, 0, Status.SERVO_ON),
        (PanelAction.CN2_MOVE, -2, Status.DONE),
    ]
    assert [e.servo_on for e in entries] == [False, True, True]


def test_oww_in_the_journal_has_no_reply_yet_and_psl_names_the_item(make_drive):
    registration = register_training("")
    try:
        drive = make_drive("FHA-25C-50-S248", training=registration.token)
        sim = SimResponder(drive)
        assert sim.respond(Request(Command.OWW)) is None
        sim.respond(Request(Command.TSL, 4))
        sim.respond(Request(Command.PWR, 20))
        drive.advance(6.0)
        assert [r.terminal for r in sim.take_deferred_replies()] == [Status.DONE]
        entries = registration.journal.entries()
    finally:
        forget_training(registration.token)
    assert entries[0].command is Command.OWW and entries[0].terminal is None
    assert entries[-1].command is Command.PWR and entries[-1].item == (Mode.TUNE, 4)
