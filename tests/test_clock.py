"""The one clock: every stamped fact reads fha_studio.clock, so a test (or a replay) sets the
time in one place, and no module reads the calendar in passing."""

from __future__ import annotations

import datetime as _dt
import re
from pathlib import Path

from fha_studio import clock
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.paramfile import dump_parameter_file, read_parameter_file
from fha_studio.logic.procedures.session import utc_now
from fha_studio.logic.register import Register
from fha_studio.logic.session_log import SessionLog

ROOT = Path(__file__).resolve().parent.parent
# reading the calendar: datetime.now(...), date.today(), utcnow(), time.time(), and localtime() /
# gmtime() / strftime(fmt) without the time they are to format. A file's age is measured against the
# filesystem's clock (its mtimes), which a line says where it does so.
CALENDAR_READ = re.compile(
    r"\bdatetime\.now\(|\bdate\.today\(|\butcnow\(|\btime\.time\(\)|\btime\.time_ns\(\)"
    r"|\b(?:localtime|gmtime)\(\)|\btime\.strftime\([^,()]*\)"
)


def test_no_module_reads_the_calendar_but_the_clock():
    found = [
        f"{path.relative_to(ROOT)}:{number}: {line.strip()}"
        for path in ROOT.joinpath("fha_studio").rglob("*.py")
        if path.name != "clock.py" or path.parent.name != "fha_studio"
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if CALENDAR_READ.search(line) and "the filesystem's clock" not in line
    ]
    assert not found, "stamp with fha_studio.clock instead:\n" + "\n".join(found)


def test_fixed_clock_stands_still_until_set_or_advanced():
    fixed = clock.FixedClock("2031-02-03T04:05:06Z")
    with clock.use(fixed):
        assert clock.now_utc() == _dt.datetime(2031, 2, 3, 4, 5, 6, tzinfo=_dt.UTC)
        assert clock.now_utc() == clock.now_utc()
        fixed.advance(90)
        assert clock.utc_iso() == "2031-02-03T04:06:36+00:00"
        fixed.set(_dt.datetime(2031, 2, 3, 12, 0, tzinfo=_dt.timezone(_dt.timedelta(hours=9))))
        assert clock.now_utc().hour == 3  # held in UTC whatever zone it was set in
        assert clock.now_s() == fixed.now_utc().timestamp()
    assert isinstance(clock.current(), clock.SystemClock)


def test_every_stamp_takes_the_one_clock(tmp_path, fixed_clock):
    fixed_clock.set("2031-02-03T04:05:06Z")
    with Register(tmp_path / "r.sqlite") as reg:
        reg.add_machine("Line 3")
        reg.add_axis("Line 3", "table", "FHA-17C-50-US250")
        reg.record_snapshot("Line 3/table", [("system", 8, "rotary_direction", 1)], "link")
        stamps = {e.at_utc for e in reg.history("Line 3/table")}
    assert stamps == {"2031-02-03T04:05:06.000000+00:00"}
    assert utc_now() == "2031-02-03T04:05:06+00:00"
    assert _dt.datetime.fromisoformat(SessionLog.now()) == fixed_clock.now_utc()
    model = load_parameter_model("HA-655")
    text = dump_parameter_file(model, {("system", 8): 1}, "FHA-17C-50-US250", "HA-655-2-200")
    assert read_parameter_file(text, model).saved.startswith("2031-02-03T04:05:06")


def test_a_process_start_is_counted_from_before_python_imported_the_clock():
    # a command's wall-time promise (drive probe: exit 3 within 5 s) counts Python's start-up: the
    # clock module imported 0.5 s after the start still knows when the process began
    import subprocess
    import sys

    code = ("import time; time.sleep(0.5); from fha_studio import clock; "
            "print(time.monotonic() - clock.process_started_monotonic())")
    done = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                          timeout=60, env={"PYTHONPATH": str(ROOT), "PATH": "/usr/bin:/bin"})
    assert done.returncode == 0, done.stderr
    assert float(done.stdout) >= 0.49
