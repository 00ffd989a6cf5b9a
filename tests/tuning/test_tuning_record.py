"""A tuning in the commissioning report: before and after as a note, with who and when."""

from __future__ import annotations

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.procedures import ProcedureSession
from fha_studio.logic.procedures.report_inputs import ReportInputs, collect_for_report
from fha_studio.logic.tuning.excitation import ExcitationPlan
from fha_studio.logic.tuning.record import TuningRecord, result_figure_words, tuning_notes

BEFORE = {"items": {"speed_loop_gain": 60}, "resonance_hz": 53.6, "antiresonance_hz": 37.8,
          "load_inertia_estimate_kgm2": 0.79, "gain_margin_db": 20.4, "phase_margin_deg": 67.2,
          "crossover_hz": 131.0, "bandwidth_hz": 33.0}
AFTER = {**BEFORE, "items": {"speed_loop_gain": 160}, "gain_margin_db": 13.3, "phase_margin_deg": 45.1}


def test_a_tuning_becomes_a_note_with_before_and_after() -> None:
    record = TuningRecord(at="2026-12-04 02:30:00 UTC", who="ana", before=BEFORE,
                          items={"speed_loop_gain": 160}, aim="standard", after=AFTER)
    ((text, who),) = tuning_notes([record])
    assert who == "ana"
    assert "2026-12-04 02:30:00 UTC" in text and "resonance 53.6 Hz" in text
    assert "gain margin 20.4 dB" in text and "Applied (standard)" in text and "gain margin 13.3 dB" in text
    # the items in the front panel's words, not a Python dictionary
    assert "tune 0 Speed loop gain (Kv) 60 Hz" in text and "tune 0 Speed loop gain (Kv) 160 Hz" in text
    assert "{" not in text and "speed_loop_gain" not in text
    session = ProcedureSession(actuator_code="FHA-25C-50-US250")
    inputs = ReportInputs(who="ana", parameter_model=load_parameter_model("HA-655"),
                          tuning_notes=tuning_notes([record]))
    collect_for_report(session, inputs)
    collect_for_report(session, inputs)  # twice: one note
    assert [n["text"] for n in session.notes].count(text) == 1


def test_a_gain_margin_beyond_the_measured_band_is_the_models_not_none() -> None:
    # the measured phase stays above -180 deg to 500 Hz; the model's crosses beyond it (28.2 dB):
    # "none" beside the table's 28.2 dB would contradict it
    result = {**BEFORE, "gain_margin_db": None, "measured_to_hz": 500.0,
              "predicted": {"gain_margin_db": 28.16}}
    words = result_figure_words(result, "gain_margin_db", "dB", manual_units=True)
    # on a page: a number and its unit joined by a no-break space (a wrapping label keeps them together)
    assert words == "28.2\u00a0dB by the model (the measured phase stays above −180° up to 500\u00a0Hz)"
    ((text, _who),) = tuning_notes([TuningRecord(at="2026-12-04 02:30:00 UTC", who="ana", before=result)])
    assert "gain margin 28.2 dB by the model" in text and "none" not in text
    # a measured margin is the measurement's; manual units for a page, ASCII for the command line
    assert result_figure_words(BEFORE, "gain_margin_db", "dB") == "20.4 dB"
    assert result_figure_words(BEFORE, "gain_margin_db", "dB", manual_units=True) == "20.4\u00a0dB"
    assert result_figure_words(BEFORE, "phase_margin_deg", "deg", manual_units=True) == "67.2°"
    assert result_figure_words(BEFORE, "phase_margin_deg", "deg") == "67.2 deg"


def test_the_excitation_in_the_manuals_symbols_on_a_page() -> None:
    plan = ExcitationPlan(amplitude_rpm=0.753, hold_periods=1, period_samples=4092, records=5,
                          travel_bound_deg=0.113, travel_limit_deg=0.236, peak_current_a=2.77, f_max_hz=500.0,
                          settle_s=0.1, duration_s=4.8)
    page = plan.describe(manual_units=True)
    assert "±0.753 r/min" in page and "±0.113° (the drive stops at 0.236°)" in page
    assert "+/-" not in page and "deg" not in page and "1 servo period," in page
    terminal = plan.describe()  # plain ASCII for a terminal or a log
    assert "+/-0.113 deg" in terminal and "±" not in terminal and "°" not in terminal
