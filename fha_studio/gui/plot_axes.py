"""Axes the plots share (pyqtgraph ``AxisItem`` subclasses)."""

from __future__ import annotations

import numpy as np
import pyqtgraph as pg

from fha_studio.logic.wording import plain_number


class PlainDecadeAxis(pg.AxisItem):
    """A logarithmic axis labelled 1, 2, 5 per decade in plain numbers (0.001, 0.1, 1, 10, 100):
    pyqtgraph writes the decades from 10 up as "10¹", "10²" beside "1" and "0.1" below them, small
    ones as "10⁻⁴", and labels every minor tick (2·10¹, 3·10¹, ...) so they run into each other.
    Used by the scope's spectrum (amplitude) and the tuning page's Bode plots (frequency)."""

    def logTickStrings(self, values, scale, spacing):  # pyqtgraph calls it by this name
        words = []
        for v in values:
            x = 10.0 ** float(v) * scale
            lead = x / 10.0 ** np.floor(np.log10(x) + 1e-9)
            words.append(plain_number(x, 1) if any(abs(lead - d) < 1e-6 for d in (1.0, 2.0, 5.0)) else "")
        return words
