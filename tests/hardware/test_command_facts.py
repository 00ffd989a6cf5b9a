"""Each CN3 command's facts are one row of protocol.COMMAND_FACTS, and the command sets and the
link's timeouts follow from the rows."""

from __future__ import annotations

import pytest

from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import Capabilities, CapabilityLevel
from fha_studio.hardware.protocol import Command
from fha_studio.hardware.transaction import LinkSettings


def test_every_command_has_its_row():
    assert set(p.COMMAND_FACTS) == set(Command)
    assert all(facts.words for facts in p.COMMAND_FACTS.values())


def test_the_command_sets_follow_from_the_rows():
    documented = {Command.DGR, Command.OWW}
    sim_only = {Command.INP, Command.PWC, Command.FLT, Command.SNO, Command.SNA, Command.SNB, Command.SNQ}
    assert documented == p.DOCUMENTED_COMMANDS
    assert set(Command) - documented == p.EXTENSION_COMMANDS
    assert {Command.MOV, Command.OWW, Command.PWC} == p.NOT_RETRIED
    assert sim_only == p.SIM_ONLY_COMMANDS
    assert Command.TRP not in p.TRACE_COMMANDS and Command.TRB in p.TRACE_COMMANDS
    # the packed read is not needed for a capture: a drive without it still records traces
    without_packed = Capabilities(frozenset(p.TRACE_COMMANDS), True, True)
    assert without_packed.level is CapabilityLevel.TRACE


@pytest.mark.parametrize("command, field", [
    (Command.OWW, "oww_timeout_s"),
    (Command.PWC, "power_cycle_timeout_s"),
    (Command.PWR, "eeprom_write_timeout_s"),
])
def test_a_slow_reply_waits_as_long_as_its_kind_may_take(command, field):
    settings = LinkSettings(**{field: 3.0})
    request_s = settings.transfer_time_s(p.FRAME_LENGTH)
    assert settings.first_byte_timeout_s(command) == pytest.approx(request_s + 3.0)
    one_line = settings.first_byte_timeout_s(Command.PRD)
    assert one_line == pytest.approx(request_s + settings.response_timeout_s)


def test_a_trace_block_may_take_longer_than_a_one_line_reply():
    s = LinkSettings()
    assert s.reply_time_limit_s(Command.TRB) > s.reply_time_limit_s(Command.IOS)
    assert s.reply_time_limit_s(Command.TRP) == s.reply_time_limit_s(Command.TRB)
