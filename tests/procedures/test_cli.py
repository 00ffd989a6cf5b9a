"""``fha-studio procedures``: list, show, walk in the terminal (paused and resumed), report."""

from __future__ import annotations

import io

from fha_studio.cli import main
from fha_studio.logic.procedures import ProcedureSession

CODE = "FHA-17C-50-US250-B"


def test_list_and_show(capsys):
    assert main(["procedures", "list", "--actuator", CODE]) == 0
    out = capsys.readouterr().out
    assert "receiving-inspection" in out and "does not apply" in out  # no sensor set (option L)
    assert main(["procedures", "show", "installation", "--actuator", CODE]) == 0
    out = capsys.readouterr().out
    assert "6-M5 depth: 8" in out and "5 N·m (50 kgf·cm)" in out


def test_bad_input_is_one_line(capsys):
    assert main(["procedures", "list", "--actuator", "FHA-99C-50-US250"]) == 2
    assert main(["procedures", "show", "nope", "--actuator", CODE]) == 2
    assert "no procedure 'nope'" in capsys.readouterr().err


def test_run_in_the_terminal_pause_resume_and_report(tmp_path, monkeypatch, capsys):
    path = tmp_path / "axis.json"
    answers = io.StringIO("y\n" + CODE + "\n")  # then end of input: paused
    monkeypatch.setattr("sys.stdin", answers)
    assert (
        main(
            [
                "procedures",
                "run",
                "receiving-inspection",
                "--session",
                str(path),
                "--actuator",
                CODE,
                "--operator",
                "T. Trainee",
            ]
        )
        == 0
    )
    assert ProcedureSession.load(path).runs["receiving-inspection"].status == "paused"
    answers = io.StringIO(f"{CODE}\nHA-655-2-200\n200\n\ny\n")  # live step: no drive, confirmed by hand
    monkeypatch.setattr("sys.stdin", answers)
    assert (
        main(
            [
                "procedures",
                "run",
                "receiving-inspection",
                "--session",
                str(path),
                "--drive",
                f"sim://{CODE}?paced=0",
            ]
        )
        == 0
    )
    run = ProcedureSession.load(path).runs["receiving-inspection"]
    assert run.status == "completed" and run.records[-1].value == CODE  # seen on the drive
    assert main(["procedures", "report", str(path), "-o", str(tmp_path / "r.html")]) == 0
    html = (tmp_path / "r.html").read_text()
    assert "HA-655-2-200" in html and "T. Trainee" in html
    assert main(["procedures", "report", str(path), "--sign", "T. Trainee"]) == 2
    assert "cannot sign while these are open" in capsys.readouterr().err


def test_a_failed_check_stops_until_put_right(tmp_path, monkeypatch, capsys):
    path = tmp_path / "axis.json"
    monkeypatch.setattr("sys.stdin", io.StringIO("41\n\n"))  # too warm; nothing put right
    assert main(["procedures", "run", "installation", "--session", str(path), "--actuator", CODE]) == 1
    assert "Service temperature must be 0 °C to 40 °C" in capsys.readouterr().out
    monkeypatch.setattr("sys.stdin", io.StringIO("air conditioning on\n25\n"))
    assert main(["procedures", "run", "installation", "--session", str(path)]) == 0
    session = ProcedureSession.load(path)
    assert [r.value for r in session.runs["installation"].records] == [41.0, 25.0]
    assert "air conditioning on" in session.notes[0]["text"]
