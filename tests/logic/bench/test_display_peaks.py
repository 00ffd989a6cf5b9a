"""Rows brought down to a plot's pixels keep each pixel's least and largest value."""

from __future__ import annotations

import numpy as np

from fha_studio.logic.bench.display import peak_rows


def test_a_pulse_narrower_than_a_pixel_still_shows_and_few_rows_pass_as_they_are():
    t = np.arange(20_000) / 1e4
    level = np.zeros(t.size)
    level[12_345] = 1.0  # one row high
    dip = np.ones(t.size)
    dip[777] = -3.0
    rows = np.column_stack([t, level, dip])
    shown = peak_rows(rows, 1000)
    assert len(shown) <= 2000 + 20 and shown[:, 1].max() == 1.0 and shown[:, 2].min() == -3.0
    assert np.all(np.diff(shown[:, 0]) >= 0) and shown[0, 0] == 0.0 and shown[-1, 0] == t[-1]
    assert peak_rows(rows[:1500], 1000) is not None and len(peak_rows(rows[:1500], 1000)) == 1500
