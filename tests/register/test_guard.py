"""What the register refuses to open, and SQLite's errors as one line naming the file: a device,
a FIFO, an empty or foreign file are refused before SQLite touches them; a read-only, damaged or
locked register says so (and what to do) instead of raising sqlite3's errors; nothing is written
on a refusal; ``register check`` says what a damaged register still holds."""

from __future__ import annotations

import os
import sqlite3
import textwrap

import pytest

from fha_studio.logic.register import Register, RegisterError
from fha_studio.logic.register.check import check_register
from fha_studio.main import main
from tests.support.processes import Child
from tests.support.read_only import ReadOnlyPlace


def _filled(path):
    with Register(path) as reg:
        reg.add_machine("Press 7", site="hall 2")
        for n in range(3):
            reg.add_axis("Press 7", f"axis {n}", "FHA-25C-50-US250", port_url=f"/dev/ttyUSB{n}")
        reg.record_snapshot("Press 7/axis 0", [("system", 8, "rotary_direction", 1)], "link")
    db = sqlite3.connect(path)
    db.execute("PRAGMA wal_checkpoint(TRUNCATE)")
    db.close()
    return path


def _damage_table(path, table):
    """Overwrites the first page of ``table`` with garbage; returns that page's number."""
    db = sqlite3.connect(path)
    page_size = db.execute("PRAGMA page_size").fetchone()[0]
    root = db.execute("SELECT rootpage FROM sqlite_master WHERE name = ?", (table,)).fetchone()[0]
    db.close()
    with open(path, "r+b") as fh:
        fh.seek((root - 1) * page_size)
        fh.write(b"\xff" * page_size)
    return root


@pytest.mark.parametrize("target, message", [
    ("/dev/zero", "register /dev/zero: a device, not a register file: nothing was opened"),
    ("/dev/ttyUSB9", "register /dev/ttyUSB9: a device, not a register file: nothing was opened"),
])
def test_a_device_is_never_opened(target, message):
    journal_before = os.path.exists("/dev/zero-journal")
    for create in (False, True):
        with pytest.raises(RegisterError) as err:
            Register(target, create=create)
        assert str(err.value) == message
    assert os.path.exists("/dev/zero-journal") == journal_before and not os.path.exists("/dev/ttyUSB9")


def test_a_link_to_a_device_a_fifo_and_a_foreign_file_are_refused_unchanged(tmp_path):
    link = tmp_path / "r.sqlite"
    link.symlink_to("/dev/zero")
    with pytest.raises(RegisterError, match="is a character device, not a register file"):
        Register(link)
    os.mkfifo(tmp_path / "fifo")
    with pytest.raises(RegisterError, match=r"is a FIFO \(named pipe\), not a register file"):
        Register(tmp_path / "fifo")  # and does not wait for a writer
    foreign = tmp_path / "notes.txt"
    foreign.write_text("my notes\n")
    with pytest.raises(RegisterError, match=r"notes.txt is not a register \(not an SQLite database file\)"):
        Register(foreign)
    assert foreign.read_text() == "my notes\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fifo", "notes.txt", "r.sqlite"]


def test_an_empty_file_is_no_register_to_ask_but_may_become_one(tmp_path):
    empty = tmp_path / "empty.sqlite"
    empty.touch()
    with pytest.raises(RegisterError, match=r"empty\.sqlite is an empty file, not a register"):
        Register(empty, create=False)
    assert empty.stat().st_size == 0 and sorted(p.name for p in tmp_path.iterdir()) == ["empty.sqlite"]
    with Register(empty) as reg:  # adding to it starts a register there
        reg.add_machine("m")


def test_a_refusal_names_a_register_deep_in_folders_whole_and_cuts_only_an_absurd_path(tmp_path):
    folder = tmp_path / "Plant A hall 2" / "commissioning" / "Line 3 positioner" / "registers"
    folder.mkdir(parents=True)
    empty = folder / "line-3-positioner.sqlite"
    empty.touch()
    assert len(str(empty)) > 100
    with pytest.raises(RegisterError) as refused:
        Register(empty, create=False)
    assert str(refused.value).startswith(f"{empty} is an empty file, not a register")
    absurd = "/" + "x" * 250 + "/" + "y" * 250 + "/r.sqlite"
    with pytest.raises(RegisterError) as refused:
        Register(absurd, create=False)
    said = str(refused.value)
    assert "\n" not in said and f"… ({len(absurd)} characters)" in said and "r.sqlite" not in said


#: What a read-only register answers and refuses, run as a user that cannot write it
#: (tests/support/read_only.py): its axes, then each write's refusal, a line each.
READ_ONLY_QUESTIONS = """
import sys
from fha_studio.logic.register import Register, RegisterError

with Register(sys.argv[1], create=False) as reg:
    print(reg.read_only)
    print([a.name for a in reg.axes("Press 7")])
    for write in (
        lambda: reg.add_machine("Press 8"),
        lambda: reg.ensure_machine("Press 8"),
        lambda: reg.ensure_axis("Press 8", "feed"),
        lambda: reg.record_alarm("Press 7/axis 0", 20),
        lambda: reg.update_axis("Press 7/axis 1", notes="x"),
    ):
        try:
            write()
            print("written")
        except RegisterError as exc:
            print(exc)
"""


def test_a_read_only_register_answers_questions_and_refuses_writes_unchanged():
    with ReadOnlyPlace() as place:
        path = _filled(place.folder / "r.sqlite")
        place.seal()
        before = path.read_bytes()
        done = place.run("-c", READ_ONLY_QUESTIONS, str(path))
        assert done.returncode == 0 and done.stderr == "", done.stderr
        refused = (f"the register {path} is read-only: nothing was changed "
                   "(it needs write access to the file and its folder)")
        assert done.stdout.splitlines() == ["True", "['axis 0', 'axis 1', 'axis 2']", *[refused] * 5]
        assert path.read_bytes() == before
        assert sorted(p.name for p in place.folder.iterdir()) == ["r.sqlite"]


def test_a_damaged_register_names_the_page_and_the_check(tmp_path):
    path = _filled(tmp_path / "r.sqlite")
    page = _damage_table(path, "axis")
    with Register(path, create=False) as reg, pytest.raises(RegisterError) as err:
        reg.axes()
    assert str(err.value) == (f"{path} is damaged at page {page} (axes); "
                              "`fha-studio register check` says what can be saved")
    result = check_register(path)
    assert not result.ok
    states = {t.table: t for t in result.tables}
    assert states["machine"].complete and states["machine"].rows == 1
    assert not states["axis"].complete and states["axis"].rows == 0
    assert states["snapshot_value"].complete and states["snapshot_value"].rows == 1
    assert result.machines == ("Press 7",)


def test_a_damaged_register_takes_no_write_even_beside_the_damage(tmp_path):
    # the machines' table is sound, the axes' is not: SQLite would take a new machine (it finds
    # damage only where it reads) and the file would be damaged further; the first write of a
    # connection runs SQLite's quick check
    path = _filled(tmp_path / "r.sqlite")
    page = _damage_table(path, "axis")
    before = path.read_bytes()
    with Register(path, create=False) as reg:
        for write in (lambda: reg.add_machine("Press 8"), lambda: reg.ensure_machine("Press 9")):
            with pytest.raises(RegisterError) as err:
                write()
            assert str(err.value) == (f"{path} is damaged at page {page} (axes); "
                                      "`fha-studio register check` says what can be saved")
    assert path.read_bytes() == before
    assert main(["register", "--register", str(path), "add-machine", "Press 8"]) == 2


def test_a_locked_register_says_who_holds_it(tmp_path, children):
    path = _filled(tmp_path / "r.sqlite")
    holder = children(Child.python, "-c", textwrap.dedent("""
            import sqlite3, sys
            db = sqlite3.connect(sys.argv[1], isolation_level=None)
            db.execute("BEGIN IMMEDIATE")
            db.execute("INSERT INTO machine (name, site, notes, created_utc) VALUES ('x', '', '', '')")
            print("holding", flush=True)
            sys.stdin.read()
        """), path, stdin=True, text=True)
    try:
        assert holder.first_line("the register's holder") == "holding"
        with Register(path, busy_timeout_s=0.2) as reg, pytest.raises(RegisterError) as err:
            reg.add_machine("Press 8")
        message = str(err.value)
        assert message.startswith(f"the register {path} is locked by ")
        assert f"(pid {holder.pid})" in message
        assert message.endswith("for more than 0.2 s: nothing was changed; try again when it is done")
    finally:
        holder.communicate(60, "")
    with Register(path) as reg:
        assert [m.name for m in reg.machines()] == ["Press 7"]


def test_register_check_on_the_command_line(tmp_path, capsys):
    path = _filled(tmp_path / "r.sqlite")
    assert main(["register", "--register", str(path), "check"]) == 0
    assert capsys.readouterr().out.startswith(f"{path}: sound (SQLite's integrity check: ok); 1 machine(s)")
    _damage_table(path, "axis")
    before = path.read_bytes()
    assert main(["register", "--register", str(path), "check"]) == 1
    out = capsys.readouterr().out
    assert out.startswith(f"{path}: DAMAGED. SQLite's integrity check: ")
    assert "  machines               1 (all)\n" in out and "  axes                   none: damaged\n" in out
    assert "Machines that can be read: 'Press 7'\n" in out
    assert path.read_bytes() == before  # the check changes nothing


def test_a_machine_report_is_not_written_when_the_register_cannot_record_it():
    with ReadOnlyPlace() as place:
        path = _filled(place.folder / "r.sqlite")
        place.seal()
        out = place.home / "report.html"  # where the report could be written
        done = place.run("-m", "fha_studio", "register", "--register", str(path), "report", "Press 7",
                         "-o", str(out))
        assert done.returncode == 2
        assert done.stderr == (
            f"fha-studio register: error: the register {path} is read-only: "
            "nothing was changed (it needs write access to the file and its folder)\n")
        assert not out.exists()
