"""A write killed halfway leaves ``.NAME.XXXXXXXX.tmp`` beside its target; the next write of that
target removes it (when it is older than a write takes), and leaves a write going on alone; the
next start of the program removes it too, through the journal of temporaries in flight (the
writer's pid: a living writer's temporary stays)."""

from __future__ import annotations

import datetime as _dt
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from fha_studio import clock, fileio, temporaries
from fha_studio.main import main
from tests.support.clock import FakeClock
from tests.support.processes import Child


def _left_over(folder, name, age_s, middle="abcd1234"):
    tmp = folder / f".{name}.{middle}.tmp"
    tmp.write_bytes(b"x" * 1000)
    then = time.time() - age_s
    os.utime(tmp, (then, then))
    return tmp


def test_the_next_write_removes_what_a_killed_write_left(tmp_path):
    stale = _left_over(tmp_path, "export.json", 3600)
    fresh = _left_over(tmp_path, "export.json", 0, "wxyz5678")  # another process writing it now
    other = _left_over(tmp_path, "other.json", 3600)
    fileio.write_text(tmp_path / "export.json", "{}\n")
    assert not stale.exists() and fresh.exists() and other.exists()
    assert (tmp_path / "export.json").read_text() == "{}\n"


def test_register_export_removes_a_stale_temporary(tmp_path, capsys):
    from fha_studio.logic.register import Register

    Register(tmp_path / "r.sqlite").close()
    stale = _left_over(tmp_path, "export.json", 3600)
    out = tmp_path / "export.json"
    assert main(["register", "--register", str(tmp_path / "r.sqlite"), "export", "-o", str(out)]) == 0
    assert not stale.exists() and out.exists()


# --- at the next start: the journal of temporaries in flight ---------------------------------------

ROOT = Path(__file__).resolve().parent.parent

#: The real command line, killed in the middle of its write: fsync (after the data, before the
#: rename) says so on stdout and then waits to be killed.
KILLED_WRITER = """
import os, sys, time
real_fsync = os.fsync
def hold(fd):
    real_fsync(fd)
    print("writing", flush=True)
    time.sleep(600)
os.fsync = hold
from fha_studio.main import main
sys.exit(main(sys.argv[1:]))
"""


def _env():
    return {**os.environ, "PYTHONPATH": str(ROOT)}


def _start_fresh():
    """A fresh start of the command line (its cheapest command), as a process of its own."""
    done = subprocess.run([sys.executable, "-m", "fha_studio", "--help"], cwd=ROOT, env=_env(),
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert done.stderr == ""


@pytest.fixture
def writer_in_the_middle(tmp_path):
    """``register export`` of a register of 2000 machines, stopped halfway through its write: the
    process, the export's path and its temporary."""
    from fha_studio.logic.register import Register

    register = tmp_path / "r.sqlite"
    with Register(register) as reg, reg.batch():  # one transaction: 2000 commits took 5-10 s
        for n in range(2000):
            reg.add_machine(f"cell {n}")
    out = tmp_path / "export.json"
    with Child.python("-c", KILLED_WRITER, "register", "--register", register, "export", "-o", out) as proc:
        assert proc.first_line("register export") == "writing"
        (tmp,) = tmp_path.glob(".export.json.*.tmp")
        assert tmp.stat().st_size > 0 and not out.exists()
        yield proc, out, tmp


def _notes():
    folder = temporaries.journal_dir()
    return sorted(folder.glob("*.json")) if folder.is_dir() else []


def _age(path, seconds):
    then = path.stat().st_mtime - seconds
    os.utime(path, (then, then))


def test_a_start_removes_what_a_killed_write_left_and_its_note(writer_in_the_middle):
    proc, out, tmp = writer_in_the_middle
    (note,) = _notes()
    noted = json.loads(note.read_text())
    assert note.name.startswith(f"{proc.pid}.") and noted["temporary"] == str(tmp)
    # the writer lives: its temporary stays, however old it looks
    _age(tmp, 3600)
    _start_fresh()
    assert tmp.exists() and note.exists()
    proc.kill()
    # a start within the minute after the kill leaves it (a write may have touched it just now) ...
    os.utime(tmp)
    _start_fresh()
    assert tmp.exists() and note.exists()
    # ... a start once it is a minute old removes the temporary and its note, and nothing else
    _age(tmp, 61)
    _start_fresh()
    assert not tmp.exists() and not out.exists() and _notes() == []
    assert [p.name for p in tmp.parent.iterdir() if "export" in p.name] == []


def test_the_minute_is_counted_by_the_one_clock_and_a_zombie_is_dead(writer_in_the_middle):
    proc, _, tmp = writer_in_the_middle
    os.kill(proc.pid, signal.SIGKILL)
    os.waitid(os.P_PID, proc.pid, os.WEXITED | os.WNOWAIT)  # dead, not yet reaped: a zombie
    written = _dt.datetime.fromtimestamp(tmp.stat().st_mtime, _dt.UTC)
    with clock.use(FakeClock(written + _dt.timedelta(seconds=59))) as fixed:
        assert temporaries.sweep() == [] and tmp.exists() and len(_notes()) == 1
        fixed.advance(2)
        assert temporaries.sweep() == [tmp]
    assert not tmp.exists() and _notes() == []


def test_a_note_never_removes_what_is_not_a_temporary(tmp_path, fixed_clock):
    keep = tmp_path / "report.html"
    keep.write_text("<p>the user's report</p>")
    _age(keep, 3600)
    dead = subprocess.run([sys.executable, "-c", "import os; print(os.getpid())"], capture_output=True,
                          text=True, check=True)
    pid = int(dead.stdout)
    folder = temporaries.journal_dir()
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{pid}.0123abcd.json").write_text(json.dumps({"temporary": str(keep)}))
    (folder / f"{pid}.4567cdef.json").write_text('{"tempor')  # a note its writer was killed writing
    fixed_clock.set(_dt.datetime.now(_dt.UTC) + _dt.timedelta(hours=2))
    assert temporaries.sweep() == []
    assert keep.read_text() == "<p>the user's report</p>" and _notes() == []


def test_a_write_leaves_no_note_and_a_journal_that_cannot_be_written_does_not_stop_it(
        tmp_path, monkeypatch):
    fileio.write_text(tmp_path / "a.json", "{}\n")
    assert _notes() == [] and temporaries.journal_dir().is_dir()
    (tmp_path / "home-is-a-file").write_text("")
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "home-is-a-file"))  # no journal can be made
    fileio.write_text(tmp_path / "b.json", "{}\n")
    assert (tmp_path / "b.json").read_text() == "{}\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json", "b.json", "home-is-a-file"]
