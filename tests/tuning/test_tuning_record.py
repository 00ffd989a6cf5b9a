"""A tuning in the commissioning report: before and after as a note, with who and when."""

from __future__ import annotations

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.procedures import ProcedureSession
from fha_studio.logic.procedures.report_inputs import ReportInputs, collect_for_report
from fha_studio.logic.tuning.record import TuningRecord, tuning_notes

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
