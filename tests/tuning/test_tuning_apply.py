"""The command line's proposal (``tune propose``): the JSON contract, nothing written without
--apply. Applying on the simulated drive (backup first, verified writes, the verification move
before and after) is test_tuning_cases.py's, for all twelve cases."""

from __future__ import annotations

import json

import pytest

from fha_studio.cli import main as cli_main
from fha_studio.hardware.parameters import load_parameter_model

PARAMETERS = load_parameter_model("HA-655")
ACTUATORS = ("FHA-17C-100-US250", "FHA-25C-50-US250", "FHA-40C-160-S248")


def test_cli_propose_prints_the_contract(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "propose.json"
    code = cli_main(["tune", "propose", "--url", "sim://FHA-25C-50-US250?load_inertia=0.81&paced=0",
                     "--actuator", "FHA-25C-50-US250", "--load-inertia", "0.81", "--json", str(out)])
    assert code == 0
    result = json.loads(out.read_text())
    for side in ("present", "proposed"):
        for key in ("speed_loop_gain", "speed_loop_integral_compensation", "position_loop_gain",
                    "feed_forward_gain", "gain_margin_db", "phase_margin_deg", "overshoot_pct",
                    "settling_ms"):
            assert key in result[side]
    assert "measured" not in result


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
