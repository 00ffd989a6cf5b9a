"""A sync that only sends (``sync_registers(..., send_only=True)``, ``register sync --send-only``):
what the source has and the target lacks goes to the target, each fact once by its stable id, and
nothing comes back (the GUI's queue for a server delivers so: a window on a large plant register
does not copy the plant's history to this computer). What both changed while apart is still a
conflict; what the target knew before is not."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from fha_studio.cli import main
from fha_studio.logic.register import Register
from fha_studio.logic.register import facts_from_session as f
from fha_studio.logic.register.sync import BATCH_FACTS, sync_registers
from tests.register.test_sync import MODEL, SHARED, M, contents, fill_offline, sound

README = Path(__file__).resolve().parents[2] / "README.md"


def test_the_batch_size_is_said_as_the_code_has_it(capsys):
    with pytest.raises(SystemExit):
        main(["register", "sync", "--help"])
    assert f"(default {BATCH_FACTS};" in " ".join(capsys.readouterr().out.split())
    assert f"each batch of facts ({BATCH_FACTS}, `--batch N`)" in " ".join(README.read_text("utf-8").split())


def _read(where, who: str, clock, values: dict[tuple[str, int], int], axis: str = SHARED) -> None:
    """Parameters of ``axis`` read (one snapshot), in ``where``."""
    with Register(where) as reg:
        f.record_fact(reg, axis, f.axis_fact({"actuator_code": "FHA-25C-50-US250"}, who))
        for fact in f.read_facts(MODEL, values, who, "HA-655-2-200"):
            f.record_fact(reg, axis, fact)
    clock.advance(1)


def _facts_of(where) -> dict[str, set[str]]:
    return {table: set(rows) for table, rows in contents(where).items()}


def test_sending_only_moves_each_fact_once_and_nothing_back(tmp_path, fixed_clock, register_target):
    laptop = tmp_path / "laptop.sqlite"
    plant = register_target
    fill_offline(plant, "ben", fixed_clock, 0, "gripper")  # the plant's history, before
    fill_offline(laptop, "ana", fixed_clock, 1, "tilt", facts_per_axis=2)
    before = contents(laptop)
    first = sync_registers(laptop, plant, who="ana", send_only=True)
    assert first.received == 0 and first.sent == sum(len(t) for t in before.values())
    assert (first.machines_added, first.axes_added) == (0, 1)  # tilt; the machine and table were there
    again = sync_registers(laptop, plant, send_only=True)
    assert (again.sent, again.received, again.already_there) == (0, 0, first.sent)
    assert contents(laptop) == before  # nothing came back
    with Register(laptop) as reg:
        assert sorted(a.ref for a in reg.axes()) == [SHARED, f"{M}/tilt"]  # not the gripper
    mine, theirs = _facts_of(laptop), _facts_of(plant)
    for table, uids in mine.items():
        assert uids <= theirs[table], table
    sound(plant)
    # what the plant had before is the history the laptop's facts add to: no conflict, the
    # newest value is the axis's
    assert first.conflicts == ()
    with Register(plant) as reg:
        assert reg.current_values(SHARED).values["rotary_direction"].value == 1


def test_what_both_changed_while_apart_is_a_conflict(tmp_path, fixed_clock, register_target):
    laptop = tmp_path / "laptop.sqlite"
    plant = register_target
    direction, in_position = ("system", 8), ("tune", 4)
    _read(laptop, "ana", fixed_clock, {direction: 1, in_position: 10})
    # the plant heard of the axis after the laptop's fact, before the laptop delivered it
    _read(plant, "ben", fixed_clock, {direction: 0, in_position: 10})
    (conflict,) = sync_registers(laptop, plant, send_only=True).conflicts
    assert conflict.subject == "parameters" and conflict.items() == ["rotary_direction"]
    assert {s.values["rotary_direction"].who for s in conflict.sides} == {"ana", "ben"}
    # delivered since: what the plant hears later, the laptop did not know when it changed the
    # axis (both changed the in-position range from the 10 both held)
    _read(plant, "cy", fixed_clock, {in_position: 20})
    _read(laptop, "ana", fixed_clock, {in_position: 30})
    result = sync_registers(laptop, plant, send_only=True)
    assert len(result.found_now) == 1 and len(result.conflicts) == 2
    newest = next(c for c in result.conflicts if c.uid in result.found_now)
    assert newest.items() == ["in_position_range"]
    assert {s.values["in_position_range"].who for s in newest.sides} == {"ana", "cy"}
    # nothing came meanwhile: the laptop's next fact is the axis's newest, no conflict
    _read(laptop, "ana", fixed_clock, {in_position: 40})
    assert sync_registers(laptop, plant, send_only=True).found_now == frozenset()
    with Register(laptop) as reg:  # the conflicts are in both; nothing else came back
        assert len(reg.conflicts()) == 2 and [s["who"] for s in reg.snapshots(SHARED)] == ["ana"] * 3


def test_a_send_stopped_anywhere_and_run_again_leaves_each_fact_once(tmp_path, fixed_clock, register_target):
    laptop = tmp_path / "laptop.sqlite"
    fill_offline(laptop, "ana", fixed_clock, 1, "tilt", facts_per_axis=2)
    fill_offline(register_target, "ben", fixed_clock, 0, "gripper")
    stops = 0
    with Register(laptop) as mine, Register(register_target) as theirs:
        for after in (1, 3, 2, 5, 1):

            def at_batch(p, after=after):
                if p.stage == "sending" and p.batches == after:
                    raise _Stopped(after)

            try:
                sync_registers(mine, theirs, progress=at_batch, batch_facts=1, send_only=True)
            except _Stopped:
                stops += 1
            assert not mine._db.in_transaction and not theirs._db.in_transaction
        done = sync_registers(mine, theirs, send_only=True)
    assert stops == 5 and done.sent > 0 and done.received == 0
    again = sync_registers(laptop, register_target, send_only=True)
    assert (again.sent, again.received) == (0, 0)
    mine_now, theirs_now = _facts_of(laptop), _facts_of(register_target)
    for table, uids in mine_now.items():
        assert uids <= theirs_now[table], table
    sound(register_target)
    # found once, whichever run found them: both changed the shared axis
    assert sorted(c.subject for c in again.conflicts) == ["origin", "parameters"]
    # a sync both ways afterwards has only what the plant had to bring back
    both = sync_registers(laptop, register_target)
    assert both.sent == 0 and both.received > 0
    assert contents(laptop) == contents(register_target)


def test_register_sync_send_only(tmp_path, fixed_clock, capsys):
    laptop, plant = tmp_path / "laptop.sqlite", tmp_path / "plant.sqlite"
    fill_offline(plant, "ben", fixed_clock, 1, "gripper")
    fill_offline(laptop, "ana", fixed_clock, 1, "tilt")
    assert main(["register", "sync", "--from", str(laptop), "--to", str(plant), "--send-only", "--json"]) == 0
    said = json.loads(capsys.readouterr().out)
    assert said["received"] == 0 and said["sent"] > 0 and said["axes_added"] == 1
    with Register(laptop) as reg:
        assert f"{M}/gripper" not in [a.ref for a in reg.axes()]


class _Stopped(Exception):
    pass
