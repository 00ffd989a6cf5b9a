"""The Tuning page on a drive of the manual's commands (the documented profile: CN3 silent while
the servo is on), tuned from the bench: the excitation file written with its bounds shown first,
played into the simulated drive's SPD-CMD in speed mode, the capture of CN2 analysed on the page
(the response plotted with its prediction, the resonance marked), a proposal for the front-panel
worksheet, and a capture made after typing it verified against its prediction."""

from __future__ import annotations

from pathlib import Path

import pytest

from fha_studio.gui.pages.base import PageId
from fha_studio.hardware.sim.cn2 import record_playback
from fha_studio.hardware.sim.drive import SimDrive

CODE = "FHA-25C-50-US250"
LOAD = 0.81  # the actuator's own inertia
RATE_HZ = 25000.0


def _capture(folder: Path, excitation: Path, preset: tuple[tuple[str, int, int], ...] = ()) -> Path:
    """The bench: the drive in speed mode (its items as typed on the front panel), the page's
    excitation file played into SPD-CMD, CN2 recorded as a sigrok session."""
    with SimDrive(CODE, load_inertia_kgm2=LOAD, effects={"torsional_compliance": {}},
                  preset=(("system", 0, 1), *preset)) as drive:
        drive.set_servo(True)
        drive.advance(0.05)
        return record_playback(drive, excitation, RATE_HZ).write(folder / "capture.sr", "sr")


@pytest.mark.slow
def test_a_documented_drive_tuned_from_the_bench(make_window, qtbot, tmp_path: Path) -> None:
    window = make_window(connect=f"sim://{CODE}?paced=0&profile=documented")
    page = window.show_page(PageId.TUNING)
    page.actuator_edit.setText(CODE)
    page.load_spin.setValue(LOAD)
    window.session.state.enter_front_panel("system", 0, 1, "T. Technician")  # speed mode, from the panel
    bench = page.bench
    written = bench.write_excitation(str(tmp_path / "excitation.csv"))
    assert written.exists()
    assert "travels at most" in bench.status.text() and "SPD-CMD" in bench.status.text()

    bench.load_capture(str(_capture(tmp_path, written)))
    assert bench.combos["speed_monitor"].currentText() == "SPD_MON"
    assert bench.combos["speed_command"].currentText() == "SPD_CMD"
    with qtbot.waitSignal(bench.sigAnalysed, timeout=60000) as analysed:
        bench.analyse()
    result = analysed.args[0]
    assert result["resonance_hz"] == pytest.approx(result["predicted_resonance_hz"], rel=0.1)
    assert page.result is result and "Resonance" in page.result_label.text()
    assert len(page.curves["predicted"][0].getData()[0]) == len(result["frequency_response"]["freq_hz"])
    assert len(page.markers) == 4

    with qtbot.waitSignal(page.sigProposed, timeout=60000):
        page.propose_button.click()
    assert "tune item 0" in page.worksheet.toPlainText()
    typed = page.proposal.proposed.items
    model = window.session.parameter_model
    preset = tuple(("tune", model.by_key(k).number, int(v)) for k, v in typed.items())
    folder = tmp_path / "after"
    folder.mkdir()
    bench.load_capture(str(_capture(folder, written, preset)))
    with qtbot.waitSignal(bench.sigVerified, timeout=60000) as verified:
        bench.verify()
    check = verified.args[0]
    assert check["items"] == {k: int(v) for k, v in typed.items()}
    assert bench.status.text().startswith("Verified from the bench")
    # a figure and its unit never part where the label wraps: a no-break space joins them
    assert f"{check['deviation']['magnitude_db']:.2g}\u00a0dB and" in bench.status.text()
    # the capture agrees with the proposal's prediction, not with the items before the worksheet
    with qtbot.waitSignal(bench.sigAnalysed, timeout=60000) as before:
        bench.analyse()
    assert check["deviation"]["magnitude_db"] < 0.5 * before.args[0]["deviation"]["magnitude_db"]


def test_a_capture_of_the_wrong_shape_is_one_line(make_window, tmp_path: Path) -> None:
    window = make_window()
    page = window.show_page(PageId.TUNING)
    bad = tmp_path / "bad.csv"
    bad.write_text("time (s),SPD_MON (V)\n0,1\nx,2\n")
    page.bench.load_capture(str(bad))
    text = page.bench.status.text()
    assert str(bad) in text and "\n" not in text
    assert not page.bench.analyse_button.isEnabled()
