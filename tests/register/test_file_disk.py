"""A full disk under a register file, for real: the file on a tiny tmpfs filled to its last byte.
A write that needs room is refused in one line (the command's too), nothing of it is half there,
nothing recorded before is lost and the file stays whole; a sync into it is refused in one line
and, once there is room, run again it brings each fact once. Needs root (to mount the tmpfs):
else the test is skipped, saying so."""

from __future__ import annotations

import json
import secrets

import pytest

from fha_studio.cli import main
from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register.identity import UID_TABLES
from tests.support.disk import fill, small_disk

M = "Press 7"
RAM = f"{M}/ram"
FULL = "no space left on the device: nothing was changed"


def _filled(register: Register) -> None:
    register.add_machine(M)
    register.add_axis(M, "ram", "FHA-25C-50-US250", "HA-655-2-200", "/dev/ttyUSB0")
    register.record_snapshot(RAM, [("tune", k, f"item_{k}", k) for k in range(50)], "link", who="ana")
    register.record_alarm(RAM, 10, "overspeed", who="ana")


def test_a_full_disk_under_a_register_file_is_one_line_and_loses_nothing(tmp_path, capsys):
    with small_disk(tmp_path / "disk") as disk:
        path = disk / "register.sqlite"
        with Register(path) as reg:
            _filled(reg)
            junk = fill(disk)
            with pytest.raises(RegisterError) as full, reg.batch():  # a session's facts: all or none
                reg.record_alarm(RAM, 11, "overload", who="ana")
                reg.record_snapshot(RAM, [("tune", k, f"item_{k}", -k) for k in range(500)], "link")
            said = str(full.value)
            assert "\n" not in said and said.endswith(FULL) and str(path) in said
            # the command's write: notes too long for a page
            notes = secrets.token_hex(4000)
            code = main(["register", "--register", str(path), "add-axis", f"{M}/feed", "--notes", notes])
            err = capsys.readouterr().err
            assert code == 2 and err.count("\n") == 1 and FULL in err
            assert [e.kind.value for e in reg.history(RAM)] == ["axis", "snapshot", "alarm"]
            assert [a.name for a in reg.axes(M)] == ["ram"]
            assert reg.integrity_check() == "ok"
            junk.unlink()  # room again: the same write goes through
            with reg.batch():
                reg.record_alarm(RAM, 11, "overload", who="ana")
                reg.record_snapshot(RAM, [("tune", k, f"item_{k}", -k) for k in range(500)], "link")
            assert [e.kind.value for e in reg.history(RAM)] == ["axis", "snapshot", "alarm", "alarm",
                                                                  "snapshot"]
            assert reg.integrity_check() == "ok"


@pytest.mark.parametrize("room_bytes", [0, 192 * 1024])
def test_a_sync_into_a_register_on_a_full_disk_is_one_line_and_a_second_run_finishes(
    tmp_path, capsys, room_bytes
):
    """``room_bytes``: none (the register cannot even be opened), or room for part of the facts
    (the disk fills in the middle of the sync: what was moved is kept)."""
    plant = tmp_path / "plant.sqlite"
    with Register(plant) as reg:
        _filled(reg)
        for number in range(60):
            reg.record_snapshot(RAM, [("tune", k, f"item_{k}", number * k) for k in range(60)], "link")
    with small_disk(tmp_path / "disk") as disk:
        laptop = disk / "laptop.sqlite"
        Register(laptop).close()
        junk = fill(disk)
        with junk.open("r+b") as out:  # room for part of the facts
            out.truncate(max(0, junk.stat().st_size - room_bytes))
        # batches of 10 facts (some 80 kB): the disk fills after a few
        code = main(["register", "sync", "--from", str(plant), "--to", str(laptop), "--batch", "10",
                     "--json"])
        out, err = capsys.readouterr()
        assert out == "" and err.count("\n") == 1, err
        if room_bytes:  # stopped: what it moved is kept, run again it finishes
            assert code == 3 and err.startswith("fha-studio register: error: sync stopped: the register ")
            assert "no space left on the device: nothing was changed (the sync had moved " in err
            assert "facts: they are kept; run it again to finish)" in err
        else:  # the register cannot even be opened
            assert code == 2 and err.rstrip().endswith(FULL)
        junk.unlink()  # room again: run once more
        with Register(laptop) as reg:
            assert reg.integrity_check() == "ok"
        code = main(["register", "sync", "--from", str(plant), "--to", str(laptop), "--json"])
        out, err = capsys.readouterr()
        assert code == 0, err
        moved = json.loads(out)
        with Register(plant) as source, Register(laptop) as target:
            assert target.integrity_check() == "ok"
            assert len(target.history(RAM)) == len(source.history(RAM)) == 63
            for table in UID_TABLES:  # every fact of the plant's once, nothing half
                source_uids = [r[0] for r in source._db.execute(f"SELECT uid FROM {table}")]
                target_uids = [r[0] for r in target._db.execute(f"SELECT uid FROM {table}")]
                assert len(target_uids) == len(set(target_uids)), f"{table}: a fact twice"
                assert set(source_uids) <= set(target_uids), table
        assert moved["conflicts"] == []
