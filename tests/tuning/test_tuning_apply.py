"""The command line's proposal (``tune propose``): the JSON contract, nothing written without
--apply; with --apply the backup, the verified writes and the figures measured after them. Applying
on the simulated drive for all twelve cases (the verification move before and after) is
test_tuning_cases.py's."""

from __future__ import annotations

import json

import pytest

from fha_studio.cli import main as cli_main
from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.tuning.propose import AIMS

PARAMETERS = load_parameter_model("HA-655")
ACTUATORS = ("FHA-17C-100-US250", "FHA-25C-50-US250", "FHA-40C-160-S248")
CODE = "FHA-25C-50-US250"
URL = f"sim://{CODE}?load_inertia=0.81&effects=torsional_compliance&stepped=1&paced=0"
TUNE_ITEMS = (
    "speed_loop_gain", "speed_loop_integral_compensation", "position_loop_gain", "feed_forward_gain",
)
FIGURES = ("gain_margin_db", "phase_margin_deg", "overshoot_pct", "settling_ms")


def _tune_items(drive) -> dict[str, int]:
    return {key: int(drive.memory.value(key)) for key in TUNE_ITEMS}


def test_cli_propose_prints_the_contract_and_writes_nothing(drives, tmp_path) -> None:
    out = tmp_path / "propose.json"
    code = cli_main(["tune", "propose", "--url", URL, "--actuator", CODE, "--load-inertia", "0.81",
                     "--json", str(out)])
    assert code == 0
    result = json.loads(out.read_text())
    for side in ("present", "proposed"):
        for key in (*TUNE_ITEMS, *FIGURES):
            assert key in result[side]
    assert "measured" not in result
    ((drive,),) = (drives,)
    assert _tune_items(drive) == {k: result["present"][k] for k in TUNE_ITEMS}


def test_cli_propose_apply_backs_up_writes_and_measures_again(drives, tmp_path, capsys) -> None:
    out, backup = tmp_path / "apply.json", tmp_path / "backup.toml"
    code = cli_main(["tune", "propose", "--url", URL, "--actuator", CODE, "--load-inertia", "0.81",
                     "--apply", "--backup", str(backup), "--json", str(out)])
    err = capsys.readouterr().err
    assert code == 0, err
    result = json.loads(out.read_text())
    proposed, measured = result["proposed"], result["measured"]
    assert f"backup of the drive's items: {backup}" in err and backup.exists()
    assert "speed_loop_gain" in backup.read_text()  # the items as they were, before any write
    ((drive,),) = (drives,)
    assert _tune_items(drive) == {k: proposed[k] for k in TUNE_ITEMS} == {k: measured[k] for k in TUNE_ITEMS}
    assert drive.memory.value("speed_loop_gain") != result["present"]["speed_loop_gain"]
    for key in FIGURES:
        assert key in measured, key
    # measured after the writes: the standard aim's phase margin (within the 5 deg a measured
    # response is held to) and a 90 deg move that settles, overshooting at most 10 %
    assert measured["phase_margin_deg"] >= AIMS["standard"][1] - 5.0
    assert measured["settling_ms"] is not None and measured["overshoot_pct"] <= 10.0


@pytest.mark.parametrize("action", ["propose", "measure"])
def test_cli_a_drive_without_parameter_access_or_no_drive_is_one_line(
        action: str, tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    """A drive of the manual's commands: exit 4, what is needed (its tune items are on its front
    panel); a port that does not open: exit 3, as ``fha-studio drive`` says it. No traceback."""
    code = "FHA-25C-50-US250"
    for url, exit_code, said in ((f"sim://{code}?paced=0&profile=documented", 4, "manual's commands"),
                                 (str(tmp_path / "no-such-port"), 3, "no-such-port")):
        assert cli_main(["tune", action, "--url", url, "--actuator", code, "--load-inertia", "0.81"]) \
            == exit_code, url
        out, err = capsys.readouterr()
        assert err.count("\n") == 1 and err.startswith(f"fha-studio tune {action}: ") and said in err, err
        assert "Traceback" not in err and out == ""
