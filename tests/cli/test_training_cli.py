"""``fha-studio training``: list, show (never the answer), check (valid file, faults observable)."""

from __future__ import annotations

from fha_studio.cli import main
from fha_studio.logic.training.scenario import scenarios_dir


def test_list_and_show_tell_the_trainee_what_to_do_but_not_the_faults(capsys):
    assert main(["training", "list"]) == 0
    listed = capsys.readouterr().out.splitlines()
    assert len(listed) >= 8 and listed[0].startswith("first-day")
    assert main(["training", "show", "fault-hunt"]) == 0
    shown = capsys.readouterr().out
    assert "Find everything that is" in shown
    assert "parameter 6" not in shown.lower() and "brake supply" not in shown.lower()


def test_an_unknown_scenario_is_one_line(capsys):
    assert main(["training", "show", "nonesuch"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "no training scenario 'nonesuch'; scenarios: " in err


def test_check_a_wrong_file_names_it(tmp_path, capsys):
    text = (scenarios_dir() / "battery.toml").read_text().replace('battery = "lost"', 'battery = "flat"')
    path = tmp_path / "battery.toml"
    path.write_text(text)
    assert main(["training", "check", str(path), "--no-drive"]) == 2
    err = capsys.readouterr().err.strip()
    assert (
        err.startswith(f"fha-studio training: error: {path}:")
        and "battery: 'flat' is not one of ok, low, lost" in err
    )


def test_check_runs_each_fault_on_the_drive_and_says_what_shows(capsys):
    assert main(["training", "check", str(scenarios_dir() / "error-allowance.toml")]) == 0
    out = capsys.readouterr().out
    assert "the file is valid" in out
    assert "allowance: Position error allowance (parameter 6) far too low: observable" in out
    assert "Parameter 6 (position error allowance): 500 -> 1" in out
    assert "Alarm after the FWD jog: 0 -> 60" in out


def test_training_start_goes_to_the_gui(monkeypatch):
    import fha_studio.gui.app as app
    from fha_studio import main as entry

    seen = []
    monkeypatch.setattr(app, "run", lambda argv: seen.append(list(argv)) or 0)
    assert entry.main(["training", "start", "first-day"]) == 0
    assert seen == [["--training", "first-day"]]
