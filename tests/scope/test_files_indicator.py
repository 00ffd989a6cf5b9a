"""The scope's files and indicator without Qt: a recording as channels and rows, the data on show
as CSV, and what the indicator may claim."""

from __future__ import annotations

import numpy as np

from fha_studio.logic.scope.acquisition import LiveMode, LiveStatus
from fha_studio.logic.scope.channels import ScopeChannel
from fha_studio.logic.scope.files import csv_text, recording_rows
from fha_studio.logic.scope.indicator import IndicatorKind, live_indicator
from fha_studio.recording import RecordingMetadata, RecordingWriter, read_recording


def _status(live=True, rate_hz=100.0, reason=""):
    return LiveStatus(live, reason, LiveMode.MONITORS, 10, rate_hz, 200.0, 0, 0.0)


def test_live_only_while_the_newest_sample_is_current():
    assert live_indicator(None, None, False) == (IndicatorKind.NOT, "NOT LIVE: waiting for the first sample")
    assert live_indicator(_status(), 0.01, False) == (IndicatorKind.LIVE, "LIVE")
    assert live_indicator(_status(), 0.6, False) == (IndicatorKind.NOT, "NOT LIVE: no new sample for 0.6 s")
    assert live_indicator(_status(rate_hz=5.0), 0.9, False)[0] is IndicatorKind.LIVE  # five periods: 1 s
    assert live_indicator(_status(), None, False)[1] == "NOT LIVE: no new sample for a while"
    assert live_indicator(_status(False, reason="link lost"), 0.0, False)[1] == "NOT LIVE: link lost"
    assert live_indicator(_status(), 0.01, True) == (IndicatorKind.PAUSED, "PAUSED (acquisition goes on)")
    assert live_indicator(None, None, True) == (IndicatorKind.PAUSED,
                                                "PAUSED · NOT LIVE: waiting for the first sample")


def test_a_recording_becomes_the_scopes_channels_and_rows(tmp_path):
    path = tmp_path / "move.csv"
    meta = RecordingMetadata("FHA-25C-50-US250", 0.5, 200, 1000.0)
    writer = RecordingWriter(path, meta, ["t", "pos", "current", "torque_cmd"])
    for i in range(5):
        writer.append([i / 1000.0, 0.1 * i, 0.5, 2.0])
    writer.close()
    known = [ScopeChannel("feedback_position", "Position", "deg", 1),
             ScopeChannel("motor_current", "Current", "A", 2)]
    shown = recording_rows(read_recording(path), known)
    assert [c.key for c in shown.channels] == ["feedback_position", "motor_current", "torque_cmd"]
    assert shown.channels[0] is known[0] and shown.channels[2].unit == ""
    assert shown.rows.shape == (5, 4) and shown.uniform and shown.sample_rate_hz == 1000.0
    text = csv_text(shown.channels, shown.rows)
    assert text.splitlines()[0] == "t_s,feedback_position [deg],motor_current [A],torque_cmd []"
    assert np.allclose(np.loadtxt(text.splitlines()[1:], delimiter=","), shown.rows)
