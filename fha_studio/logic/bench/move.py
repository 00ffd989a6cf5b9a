"""The move test's figures from a bench capture (no Qt): what the scope's move test shows, taken
from the drive's CN2 instead of CN3, where a real HA-655 is silent while the servo is on.

From the command pulses (commanded counts) and the encoder outputs (feedback counts), both in
encoder counts and shown in output degrees: overshoot and settling as
:func:`fha_studio.logic.scope.analysis.move_metrics` measures them, the *in-position time* from
the drive's own IN-POS output (CN2-33: from the end of the command until IN-POS stays on), and
the *following error* = command counts - encoder counts (its largest size during the move and
at the end).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from fha_studio.logic.scope.analysis import MoveMetrics, move_metrics


@dataclass(frozen=True)
class BenchMoveFigures:
    metrics: MoveMetrics  # in output degrees
    in_position_time_s: float | None  # from the command's end until IN-POS stays on; None: never
    following_error_peak_counts: float  # the largest |command - encoder| over the capture
    following_error_end_counts: float  # command - encoder at the capture's end
    counts_per_deg: float

    def describe(self) -> str:
        m = self.metrics

        def ms(value: float | None) -> str:
            return "not reached" if value is None else f"{value * 1000:.1f} ms"

        return (f"move {m.target - m.start:+.4g} deg; overshoot {m.overshoot_percent:.2f} % "
                f"({m.overshoot:.4g} deg); settling (±{m.settling_band:.3g} deg) "
                f"{ms(m.settling_time_s)}; in-position (IN-POS) {ms(self.in_position_time_s)} after the "
                f"command ended; following error {self.following_error_peak_counts:.0f} counts at most, "
                f"{self.following_error_end_counts:.0f} at the end")


def bench_move_figures(t_s: ArrayLike, command_counts: ArrayLike, encoder_counts: ArrayLike,
                       in_position: ArrayLike | None, counts_per_deg: float) -> BenchMoveFigures:
    """The figures of the move in a capture (ValueError when the command does not move)."""
    t = np.asarray(t_s, dtype=float)
    cmd = np.asarray(command_counts, dtype=float)
    enc = np.asarray(encoder_counts, dtype=float)
    metrics = move_metrics(t, cmd / counts_per_deg, enc / counts_per_deg)
    in_pos_time = None
    if in_position is not None:
        on = np.asarray(in_position, dtype=float) > 0.5
        end = int(np.searchsorted(t, metrics.command_end_s))
        if on[-1]:
            off = np.flatnonzero(~on[end:])
            first = end if off.size == 0 else end + int(off[-1]) + 1
            in_pos_time = max(0.0, float(t[first]) - metrics.command_end_s)
    error = cmd - enc
    return BenchMoveFigures(metrics, in_pos_time, float(np.max(np.abs(error))), float(error[-1]),
                            counts_per_deg)
