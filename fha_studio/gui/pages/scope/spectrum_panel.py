"""The scope's spectrum tab: a captured channel's amplitude spectrum and its prominent peaks."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pyqtgraph as pg
from PySide6.QtCore import Signal
from PySide6.QtWidgets import QComboBox, QHBoxLayout, QLabel, QPushButton, QVBoxLayout, QWidget

from fha_studio.gui.plot_axes import PlainDecadeAxis
from fha_studio.logic.scope.channels import ScopeChannel
from fha_studio.logic.wording import plain_number, unit_words

#: Arc-seconds per degree: a line of an angle's spectrum is read in arc-sec, as the manual gives
#: the actuator's accuracy (a kinematic error of 40 arc-sec, not 0.011 deg or 7.41e-05 deg).
ARCSEC_PER_DEG = 3600.0


class SpectrumPanel(QWidget):
    """Channel and detrend choice, the log-amplitude plot and a line naming the peaks."""

    sigCompute = Signal()

    def __init__(self, parent=None):
        super().__init__(parent)
        lay = QVBoxLayout(self)
        lay.setContentsMargins(0, 0, 0, 0)
        row = QHBoxLayout()
        row.addWidget(QLabel("Channel"))
        self.spectrum_channel = QComboBox()
        row.addWidget(self.spectrum_channel, 1)
        row.addWidget(QLabel("Remove"))
        self.spectrum_detrend = QComboBox()
        self.spectrum_detrend.addItem("ramp (moves)", "linear")
        self.spectrum_detrend.addItem("mean", "constant")
        row.addWidget(self.spectrum_detrend)
        go = QPushButton("Compute")
        go.clicked.connect(self.sigCompute)
        row.addWidget(go)
        lay.addLayout(row)
        self.spectrum_plot = pg.PlotWidget(axisItems={"left": PlainDecadeAxis("left")})
        self.spectrum_plot.setBackground("#111")
        self.spectrum_plot.showGrid(x=True, y=True, alpha=0.25)
        self.spectrum_plot.setLabel("bottom", "frequency", units="Hz")
        self.spectrum_plot.setLogMode(y=True)
        # decades as they are: pyqtgraph's SI scale put "(x0.001)" after a logarithmic axis's unit
        self.spectrum_plot.getAxis("left").enableAutoSIPrefix(False)
        self.spectrum_curve = self.spectrum_plot.plot(pen=pg.mkPen("#4fc3f7"))
        lay.addWidget(self.spectrum_plot, 1)
        self.spectrum_label = QLabel("Capture a trace (uniform sampling), then compute its spectrum.")
        self.spectrum_label.setWordWrap(True)
        lay.addWidget(self.spectrum_label)

    def set_channels(self, channels: Sequence[ScopeChannel]) -> None:
        """The analog channels on show are the ones a spectrum can be computed of."""
        self.spectrum_channel.clear()
        for c in channels:
            if not c.is_bit:
                self.spectrum_channel.addItem(f"{c.name} [{unit_words(c.unit)}]", c.key)

    def channel_key(self) -> str | None:
        return self.spectrum_channel.currentData()

    def detrend(self) -> str:
        return self.spectrum_detrend.currentData()

    def message(self, text: str) -> None:
        self.spectrum_label.setText(text)

    def show_spectrum(self, spec, unit: str) -> None:
        """Plot ``spec`` (analysis.Spectrum) without its DC bin and name its prominent peaks."""
        # an angle's lines in arc-sec, as its peaks are named (a kinematic error is tens of them)
        shown_unit, scale = ("arc-sec", ARCSEC_PER_DEG) if unit == "deg" else (unit, 1.0)
        f, a = spec.frequency_hz[1:], np.maximum(spec.amplitude[1:] * scale, 1e-12)
        self.spectrum_curve.setData(f, a)
        if not len(f):
            self.message("Peaks: none")
            return
        self.spectrum_plot.setLabel("left", f"amplitude ({shown_unit})" if shown_unit else "amplitude")
        peaks = spec.prominent_peaks(4, min_hz=f[0])
        text = ", ".join(f"{hz:.2f} Hz ({peak_amplitude(amp, unit)})" for hz, amp in peaks)
        text = text or "none stand out"
        self.message(f"Peaks: {text}. Resolution {f[0]:.3g} Hz.")


def peak_amplitude(amplitude: float, unit: str) -> str:
    """A peak's amplitude as a person reads it: an angle in arc-sec (``"39.6 arc-sec"``), any other
    unit as it is, never in exponent notation."""
    if unit == "deg":
        return f"{plain_number(amplitude * ARCSEC_PER_DEG, 3)} arc-sec"
    return f"{plain_number(amplitude, 3)} {unit}".strip()
