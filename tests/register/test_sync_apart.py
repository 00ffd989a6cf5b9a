"""Two laptops and the plant's register (a file, or the tests' PostgreSQL server): what was changed
while they were apart is a conflict, a change made after the value it replaces was known is not;
and every register that holds the same facts tells an axis's history in the same order."""

from __future__ import annotations

import re

import pytest

from fha_studio.cli import main
from fha_studio.logic.register import Register
from fha_studio.logic.register.conflicts import SideValue, changed_apart
from fha_studio.logic.register.sync import sync_registers

M = "Line 3 positioner"
TABLE = f"{M}/table"
IN_POSITION = ("tune", 4, "in_position_range")
DIRECTION = ("system", 8, "rotary_direction")


def _read(where, values, who, clock) -> None:
    """A technician's laptop reads the axis's parameters (a snapshot over the link)."""
    clock.advance(60)
    with Register(where) as reg:
        reg.ensure_axis(M, "table", actuator_code="FHA-25C-50-US250", driver_model="HA-655-2-200")
        reg.record_snapshot(TABLE, [(*IN_POSITION[:3], values[0]), (*DIRECTION, values[1])], "link", who=who)


def _write(where, old, new, who, clock) -> None:
    """A technician's laptop changes In-position range (a verified write)."""
    clock.advance(60)
    with Register(where) as reg:
        reg.record_write(TABLE, *IN_POSITION, new, old, new, True, who=who)


def _open(where) -> list:
    with Register(where) as reg:
        return reg.conflicts()


def _latest(where) -> int:
    with Register(where) as reg:
        return reg.current_values(TABLE).values["in_position_range"].value


def test_a_change_made_after_the_other_side_was_known_is_no_conflict(tmp_path, register_target, fixed_clock):
    ana, ben, plant = tmp_path / "ana.sqlite", tmp_path / "ben.sqlite", register_target
    _read(ana, (10, 0), "ana", fixed_clock)
    sync_registers(ana, plant)  # A syncs
    _read(ben, (10, 0), "ben", fixed_clock)  # Ben reads the same values before he syncs
    assert sync_registers(ben, plant).conflicts == ()  # B syncs: both read the same
    _write(ana, 10, 25, "ana", fixed_clock)  # A changes, after Ben's values were read
    for laptop in (ana, ben, ana):  # both sync: a later change, not a conflict
        assert sync_registers(laptop, plant).conflicts == ()
    for where in (ana, ben, plant):
        assert _open(where) == [] and _latest(where) == 25

    # both change while apart: one conflict, the two values side by side, in every register
    _write(ana, 25, 30, "ana", fixed_clock)
    _write(ben, 25, 40, "ben", fixed_clock)
    sync_registers(ana, plant)
    (conflict,) = sync_registers(ben, plant).conflicts
    assert (conflict.subject, conflict.items()) == ("parameters", ["in_position_range"])
    assert sorted(
        (s.values["in_position_range"].value, s.values["in_position_range"].who) for s in conflict.sides
    ) == [(30, "ana"), (40, "ben")]
    sync_registers(ana, plant)
    for where in (ana, ben, plant):
        assert [c.uid for c in _open(where)] == [conflict.uid]


def test_the_old_value_read_after_a_change_made_apart_is_a_conflict(tmp_path, fixed_clock):
    """Ben reads the value both knew after Ana changed it, not knowing of her change: the latest
    value would silently undo hers, so a person looks (a write not saved in the drive's EEPROM,
    a drive swapped)."""
    ana, ben = tmp_path / "ana.sqlite", tmp_path / "ben.sqlite"
    _read(ana, (10, 0), "ana", fixed_clock)
    sync_registers(ana, ben)
    _write(ana, 10, 25, "ana", fixed_clock)
    _read(ben, (10, 0), "ben", fixed_clock)  # later than Ana's change
    (conflict,) = sync_registers(ana, ben).conflicts
    assert conflict.items() == ["in_position_range"]  # the direction both read alike


def test_the_rule_item_by_item():
    def held(value, at):
        return SideValue(value, f"uid-{at}", "snapshot", at_utc=f"2026-12-05T0{at}:00:00+00:00")

    before = {"p": held(10, 1)}
    # both changed: a conflict, whichever came first
    assert changed_apart({"p": held(25, 2)}, {"p": held(40, 3)}, before) == ["p"]
    # one changed after the other read the old value: a later change
    assert changed_apart({"p": held(25, 3)}, {"p": held(10, 2)}, before) == []
    assert changed_apart({"p": held(10, 2)}, {"p": held(25, 3)}, before) == []
    # the old value read after the change: a conflict
    assert changed_apart({"p": held(25, 2)}, {"p": held(10, 3)}, before) == ["p"]
    # nothing both held before: both are changes
    assert changed_apart({"p": held(25, 2)}, {"p": held(10, 3)}, {}) == ["p"]
    assert changed_apart({"p": held(25, 2)}, {"p": held(25, 3)}, {}) == []


@pytest.mark.parametrize("first", ["ana", "plant"])
def test_two_synced_registers_tell_the_same_history(tmp_path, register_target, fixed_clock, capsys, first):
    """Facts recorded at the same second on two laptops (a session file's times, the front
    panel's) reach each register in another order: each tells them by time, then stable id."""
    ana, plant = tmp_path / "ana.sqlite", register_target
    at = "2026-12-05T08:00:00Z"
    for where, who, codes in ((ana, "ana", (20, 31, 40)), (plant, "ben", (21, 30))):
        with Register(where) as reg:
            reg.ensure_axis(M, "table", actuator_code="FHA-25C-50-US250")
            for code in codes:
                reg.record_alarm(TABLE, code, f"alarm {code}", who=who, at_utc=at)
            reg.record_snapshot(TABLE, [(*DIRECTION, 1 if who == "ana" else 0)], "link", who=who, at_utc=at)
            reg.record_write(TABLE, *IN_POSITION, 20, 10, 20, True, who=who, at_utc=at)
    sync_registers(ana, plant) if first == "ana" else sync_registers(plant, ana)
    told = []
    for where in (ana, plant):
        assert main(["register", "--register", str(where), "history", TABLE]) == 0
        text = capsys.readouterr().out
        told.append(re.sub(r"snapshot \d+", "snapshot N", text))  # each register numbers its own rows
        with Register(where) as reg:
            told.append([e.uid for e in reg.history(TABLE)])
    assert told[0] == told[2] and told[1] == told[3]
    assert told[0].count("alarm") >= 5 and "conflict" in told[0]  # both read the direction apart
