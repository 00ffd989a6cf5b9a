"""The simulated drive's command table: every CN3 command of the protocol has its handler."""

from __future__ import annotations

from fha_studio.hardware.protocol import DOCUMENTED_COMMANDS, EXTENSION_COMMANDS, Command
from fha_studio.hardware.sim.responder import COMMANDS
from tests.sim.conftest import ask


def test_every_protocol_command_has_a_handler_keyed_by_the_enum():
    assert all(isinstance(key, Command) for key in COMMANDS)
    assert set(Command) - set(COMMANDS) == set()


def test_no_command_the_drive_speaks_is_answered_as_unknown(make_drive):
    drive = make_drive("FHA-25C-50-S248-L")  # absolute encoder and sensors: every command applies
    for command in Command:
        reply = ask(drive, command, 0)
        assert reply is None or "unknown command" not in reply.reason, (command, reply)


def test_cap_lists_every_extension_and_an_unknown_name_is_refused(make_drive):
    drive = make_drive()
    (line,) = ask(drive, Command.CAP, 0).lines
    assert set(line.split()) == {c.value for c in EXTENSION_COMMANDS}
    assert not set(line.split()) & {c.value for c in DOCUMENTED_COMMANDS}
    reply = ask(drive, "XYZ", 0)
    assert reply.terminal == "x" and "unknown command XYZ" in reply.reason
