"""A tuning's plot goes into the session (a file) with its title in plain spaces: the Tuning
page's figures join number and unit with a no-break space for its wrapping labels only."""

from __future__ import annotations

from fha_studio.logic.tuning.record import TuningRecord

CODE = "FHA-25C-50-US250"
BEFORE = {"items": {"speed_loop_gain": 60}, "resonance_hz": 53.6, "antiresonance_hz": 37.8,
          "load_inertia_estimate_kgm2": 0.79, "gain_margin_db": 20.4, "phase_margin_deg": 67.2,
          "crossover_hz": 131.0, "bandwidth_hz": 33.0}


def test_the_tuning_plots_title_in_the_session_has_plain_spaces(make_window, tmp_path):
    window = make_window()
    tuning = window.show_page("tuning")
    tuning.records = [TuningRecord(at="2026-12-04 02:30:00 UTC", who="ana", before=BEFORE)]
    page = window.show_page("procedures")
    page.operator_edit.setText("T. Technician")
    page.new_session(tmp_path / "axis.json", CODE)
    page._add_tuning_plots()
    (plot,) = page.session.plots
    assert "resonance 53.6 Hz" in plot["title"] and "\u00a0" not in plot["title"]
