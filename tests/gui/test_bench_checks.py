"""DGR checks of a moving axis from CN2 on the documented profile (CN3 silent while the servo is
on): the controller's 10 deg FWD move seen on the sim-cn2 instrument gives the encoder check, the
direction as the encoder outputs count it, IN-POS and ALARM; they are recorded on the DGR checks
page, with where their figures came from, and go into the report's notes."""

from __future__ import annotations

import re

import pytest

from fha_studio.gui.pages.base import PageId
from fha_studio.logic.procedures.report_inputs import dgr_check_notes
from tests.gui.controller import bench_standing, bench_streaming, panel_done

CODE = "FHA-25C-50-US250"


@pytest.fixture
def window(documented_window):
    return documented_window(CODE)


def test_a_controller_move_on_cn2_is_checked_and_recorded_with_its_source(window, qtbot):
    bench = window.show_page("scope").bench
    window.state.enter_front_panel("system", 8, 0, "T. Technician")  # rotary direction, from the panel
    assert bench.parameter_8 == 0
    bench_streaming(qtbot, bench, "ENC_A,ENC_B,CMD_A,CMD_B,IN_POS,ALARM", "250k", "ENC_A,ENC_B",
                    "CMD_A,CMD_B", "IN_POS", "ALARM")
    panel_done(window, qtbot, lambda: window.sim_panel.servo_check.setChecked(True))
    qtbot.waitUntil(lambda: window.link.status is not None and window.link.status.servo_on, timeout=10000)
    bench_standing(qtbot, bench)  # standing under servo: what the move starts from
    window.sim_panel.command_spin.setValue(10.0)
    with qtbot.waitSignal(bench.sigChecks, timeout=30000) as checked:
        panel_done(window, qtbot, window.sim_panel.fwd_button.click)
    checks = {c.check: c for c in checked.args[0]}
    assert {name: c.passed for name, c in checks.items()} == {
        "bench_encoder": True, "bench_direction": True, "bench_in_position": True, "bench_alarm": True}
    source = "from the bench instrument sim-cn2 (encoder A, B on ENC_A, ENC_B; command pulses on CMD_A, " \
        "CMD_B; IN-POS; ALARM)"
    assert all(source in c.detail for c in checks.values())
    assert "a FWD command (+13889 counts) turned the axis FWD" in checks["bench_direction"].detail
    assert "encoder outputs follow the command: pass" in bench.move_label.text()
    assert "direction: pass (FWD rotation, CW viewing the output flange)" in bench.move_label.text()
    assert "with parameter 8 = 0 that is FWD rotation, CW viewing the output flange (1-10)" \
        in checks["bench_direction"].detail

    page = window.page(PageId.ABSOLUTE)
    recorded = [r for r in page.records if r.check.startswith("bench_")]
    assert [r.check for r in recorded] == ["bench_encoder", "bench_direction", "bench_in_position",
                                           "bench_alarm"]
    assert all(r.passed and not r.by_hand for r in recorded)
    notes = [text for text, _who in dgr_check_notes(recorded)]
    assert notes[0].startswith("Encoder outputs follow the command (CN2, bench) (")
    # the checked window may end a count or two before the axis has settled (within the in-position range)
    counted = re.search(r", from CN2 on a bench instrument\): pass: the encoder outputs counted \+(\d+) for "
                        r"\+13889 commanded counts", notes[0])
    assert counted and abs(int(counted[1]) - 13889) <= 2, notes[0]
    with qtbot.waitSignal(bench.source.sigStopped, timeout=10000):
        bench.start_button.click()
