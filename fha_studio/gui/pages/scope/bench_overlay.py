"""A bench instrument's stream on the scope's Time plot, beside the CN3 channels.

The Bench tab's rows (``[t_s, channels..., counts, command]``) become traces named with their
source, ``bench sim-cn2: ENC_A/ENC_B position (output) [deg]``: the encoder and command counts
in output degrees (the axis's counts per output turn), so they share the plot of CN3's positions;
logic channels as bits, analog ones in volts. Drawn as the live view draws, time before now.
"""

from __future__ import annotations

import numpy as np

from fha_studio.logic.bench.display import peak_rows

from .bench_source import BenchStarted

#: Pens of the bench traces (dashed on the plot: CN3's are solid).
COLORS = ("#444444", "#8c564b", "#17becf", "#bcbd22", "#7f7f7f", "#e377c2")


def bench_traces(started: BenchStarted, rows: np.ndarray, counts_per_output_turn: int, buckets: int
                 ) -> dict[str, tuple[str, np.ndarray, np.ndarray]]:
    """label -> (unit, time before now [s], values) of the rows (at most 2 x ``buckets`` each)."""
    if not len(rows):
        return {}
    rows = peak_rows(rows, buckets)
    t = rows[:, 0] - rows[-1, 0]
    device = started.device.split(":", 1)[0]
    traces: dict[str, tuple[str, np.ndarray, np.ndarray]] = {}
    for i, name in enumerate(started.channels):
        unit = "bit" if name in started.logic else "V"
        traces[f"bench {device}: {name} [{unit}]"] = (unit, t, rows[:, 1 + i])
    first = 1 + len(started.channels)
    for j, extra in enumerate(started.extra):
        label = started.labels[len(started.channels) + j].split(":", 1)[1]  # "ENC_A/ENC_B counts"
        values = rows[:, first + j]
        if counts_per_output_turn > 0:
            what = "position (output)" if extra == "counts" else "command position (output)"
            lines = label.rsplit(" ", 1 if extra == "counts" else 2)[0]
            degrees = values * 360.0 / counts_per_output_turn
            traces[f"bench {device}: {lines} {what} [deg]"] = ("deg", t, degrees)
        else:
            traces[f"bench {device}: {label} [counts]"] = ("counts", t, values)
    return traces
