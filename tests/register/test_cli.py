"""``fha-studio register ...``: the plant's questions on the command line, as text and --json;
bad input is one line on stderr and exit status 2, and nothing is half-done."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from fha_studio.cli import main
from fha_studio.logic.register import Register


@pytest.fixture(params=["sqlite", "postgresql"])
def db(request, tmp_path, capsys):
    """A register (a file, or a database on the throw-away server) with Line 3's two axes."""
    if request.param == "sqlite":
        path = tmp_path / "plant.sqlite"
    else:
        path = request.getfixturevalue("postgres_cluster").new_database()
    assert main(["register", "--register", str(path), "add-machine", "Line 3", "--site", "Plant A"]) == 0
    for axis, port in (("table", "/dev/ttyUSB0"), ("table twin", "/dev/ttyUSB1")):
        args = ["register", "--register", str(path), "add-axis", f"Line 3/{axis}",
                "--actuator", "FHA-25C-50-US250"]
        assert main([*args, "--driver", "HA-655-2-200", "--port", port, "--load-inertia", "1.5"]) == 0
    with Register(path) as reg:
        delivery = [("system", 8, "rotary_direction", 0), ("tune", 4, "in_position_range", 10)]
        reg.record_snapshot("Line 3/table", delivery, "link", who="ana", at_utc="2026-11-30T08:00:00Z")
        reg.record_snapshot("Line 3/table twin", delivery, "link", who="ben", at_utc="2026-11-30T08:00:00Z")
        reg.record_write(
            "Line 3/table",
            "system",
            8,
            "rotary_direction",
            1,
            0,
            1,
            True,
            who="ana",
            at_utc="2026-11-30T08:10:00Z",
        )
    capsys.readouterr()
    return path


def run(capsys, db, *args):
    code = main(["register", "--register", str(db), *args])
    out, err = capsys.readouterr()
    return code, out, err


def test_machines_and_axes(capsys, db):
    code, out, _ = run(capsys, db, "machines")
    assert code == 0 and "Line 3" in out and "Plant A" in out
    code, out, _ = run(capsys, db, "axes", "Line 3", "--json")
    axes = json.loads(out)
    assert [(a["ref"], a["rotary_direction"], a["port_url"]) for a in axes] == [
        ("Line 3/table", 1, "/dev/ttyUSB0"),
        ("Line 3/table twin", 0, "/dev/ttyUSB1"),
    ]
    code, out, _ = run(capsys, db, "axes")
    assert "reversed" in out and "FWD = CW" in out and "1.5 kg m²" in out


def test_history_diff_find_in_words_and_json(capsys, db):
    code, out, _ = run(capsys, db, "history", "Line 3/table")
    assert code == 0
    written = "parameter 8 Rotary direction: 0 → 1: FWD turns CCW (reversed), verified"
    assert f"2026-11-30 08:10:00  write       {written} [ana]" in out
    assert "parameters  parameters read over the link: 2 values, snapshot 1 [ana]" in out
    code, out, _ = run(capsys, db, "diff", "Line 3/table", "Line 3/table twin")
    assert code == 0
    assert "parameter 8 Rotary direction" in out and "1: FWD turns CCW (reversed)" in out
    assert "In-position" not in out and "in_position" not in out  # the same on both
    code, out, _ = run(capsys, db, "diff", "1", "2", "--json")
    assert json.loads(out)["differences"] == []  # both snapshots read the delivery values
    code, out, _ = run(capsys, db, "--json", "find", "rotary_direction=1")
    found = json.loads(out)
    assert [a["axis"] for a in found["axes"]] == ["Line 3/table"] and found["axes"][0]["source"] == "write"
    code, out, _ = run(capsys, db, "find", "Rotary direction")
    assert "Line 3/table twin" in out and "verified write" in out


def test_open_items_import_and_export(capsys, db, tmp_path):
    from fha_studio.logic.procedures import ProcedureSession

    session = ProcedureSession(actuator_code="FHA-25C-50-US250", axis="table", operator="ana")
    session.save(tmp_path / "table.json")
    code, out, _ = run(capsys, db, "import", str(tmp_path / "table.json"), "--machine", "Line 3")
    assert code == 0 and "-> Line 3/table: 0 new check(s), 5 procedure(s)" in out
    code, out, _ = run(capsys, db, "open", "Line 3")
    assert "Line 3/table: check: Receiving inspection (3-1): not started" in out
    assert "Line 3/table twin: report: no commissioning report" in out
    export = tmp_path / "out" / "export.json"
    code, _, err = run(capsys, db, "export", "--machine", "Line 3", "-o", str(export))
    assert code == 0 and "1 machine(s)" in err
    data = json.loads(export.read_text())
    assert data["format"] == "fha-register-export/1"
    assert [a["name"] for a in data["machines"][0]["axes"]] == ["table", "table twin"]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["history", "Line 3/roll"], "machine 'Line 3' has no axis 'roll' (axes: table, table twin)"),
        (["diff", "7", "Line 3/table"], "no parameter snapshot number 7 in the register"),
        (["find", "rotary_direction=2"], "find: parameter 8, rotary direction: 2 is not one of 0"),
        (["find", "speedy=1"], "find: no parameter called 'speedy'"),
        (["add-axis", "table"], "add-axis: 'table': name the axis as MACHINE/AXIS"),
        (["add-axis", "Line 3/roll", "--actuator", "FHA-26C"], "add-axis: --actuator: model code 'FHA-26C'"),
        (["add-machine", "Line 3"], "there is already a machine called 'Line 3'"),
        (["history", "x", "--since", "soon"], "no axis called 'x'"),
        (["history", "table", "--since", "soon"], "'soon' is not a time"),
        (["import", "nowhere.json", "--machine", "Line 3"], "import: nowhere.json: no such file"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(capsys, db, args, message):
    code, out, err = run(capsys, db, *args)
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("fha-studio register: error: ")
    assert message in err
    assert out == ""
    with Register(db) as reg:
        assert [a.name for a in reg.axes("Line 3")] == ["table", "table twin"]


def test_a_load_inertia_that_is_no_number_is_refused_in_one_line(capsys, db):
    refusals = (("nan", "nan is not a number"), ("1e400", "1e400 is too large"),
                ("-1", "-1 is outside 0 ... 1500 kg m^2"))
    for value, words in refusals:
        with pytest.raises(SystemExit) as stop:
            main(["register", "--register", str(db), "add-axis", "Line 3/roll", "--load-inertia", value])
        err = capsys.readouterr().err
        assert stop.value.code == 2 and err.count("\n") == 1 and f"--load-inertia: {words}" in err
    with Register(db) as reg:
        assert [a.name for a in reg.axes("Line 3")] == ["table", "table twin"]


def test_a_parameter_file_needs_an_axis(capsys, db, tmp_path):
    path = tmp_path / "p.toml"
    path.write_text('format = "fha-parameters/1"\n[system]\nrotary_direction = 1\n')
    code, _, err = run(capsys, db, "import", str(path), "--machine", "Line 3")
    assert code == 2 and "is a parameter file: say which axis with --axis" in err
    code, out, _ = run(capsys, db, "import", str(path), "--machine", "Line 3", "--axis", "tilt", "--json")
    assert code == 0 and json.loads(out)[0]["axis"] == "Line 3/tilt"


def test_the_default_register_is_the_sites_choice(tmp_path):
    site = tmp_path / "share" / "plant.sqlite"
    env = {"FHA_STUDIO_REGISTER": str(site), "PATH": "", "XDG_DATA_HOME": str(tmp_path / "data")}
    done = subprocess.run(
        [sys.executable, "-m", "fha_studio", "register", "add-machine", "Press 7"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert done.returncode == 0, done.stderr
    with Register(site) as reg:
        assert [m.name for m in reg.machines()] == ["Press 7"]
    assert not (tmp_path / "data").exists()


def test_machine_report_from_the_register(capsys, db, tmp_path):
    from fha_studio.logic.procedures import ProcedureRun, ProcedureSession, load_procedure
    from fha_studio.logic.procedures.context import build_context
    from tests.procedures.walk import walk

    session = ProcedureSession(actuator_code="FHA-25C-50-US250", axis="table", operator="ana")
    session.save(tmp_path / "table.json")
    walk(
        ProcedureRun(session, load_procedure("receiving-inspection", build_context("FHA-25C-50-US250"))),
        "ana",
    )
    assert run(capsys, db, "import", str(tmp_path / "table.json"), "--machine", "Line 3")[0] == 0
    output = tmp_path / "reports" / "line3.html"
    code, out, _ = run(capsys, db, "report", "Line 3", "-o", str(output))
    assert code == 0
    assert out.splitlines()[1].startswith("  table: 6 passed, 0 failed, not signed")
    assert "  table twin: 0 passed, 0 failed, not signed" in out
    html = output.read_text(encoding="utf-8")
    assert "Machine report — Line 3" in html and "Commissioning report — table — FHA-25C-50-US250" in html
    assert "No procedure session for this axis yet" in html  # the twin
    with Register(db) as reg:
        assert reg.export("Line 3")["machines"][0]["machine_reports"][0]["file"] == str(output.resolve())
    code, _, err = run(capsys, db, "report", "Line 9")
    assert (
        code == 2
        and err.strip()
        == "fha-studio register: error: no machine called 'Line 9' in the register (machines: Line 3)"
    )


def test_a_question_to_a_register_that_is_not_there_is_refused(capsys, tmp_path):
    missing = tmp_path / "tpyo.sqlite"
    assert main(["register", "--register", str(missing), "machines"]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"fha-studio register: error: there is no register at {missing} "
        "(start one: fha-studio register add-machine NAME)\n"
    )
    assert not missing.exists()
    assert main(["register", "--register", str(missing), "add-machine", "Press 7"]) == 0
    assert missing.exists()


def test_a_report_to_a_place_that_cannot_take_it_is_refused_before_the_work(capsys, db, tmp_path):
    (tmp_path / "afile").write_text("a regular file")
    code, out, err = run(capsys, db, "report", "Line 3", "-o", str(tmp_path / "afile" / "r.html"))
    assert (code, out) == (2, "") and err.count("\n") == 1
    assert "a part of the path is not a directory" in err
    with Register(db) as reg:
        assert reg.export("Line 3")["machines"][0]["machine_reports"] == []  # nothing recorded
