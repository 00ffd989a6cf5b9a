"""A bench instrument's stream on the scope's Time plot, beside the CN3 channels.

The Bench tab's rows (``[t_s, channels..., counts, command]``) become traces named with their
source, ``bench sim-cn2: ENC_A/ENC_B position (output) [°]``: the encoder and command counts
in output degrees (the axis's counts per output turn), so they share the plot of CN3's positions;
other logic channels as bits (not the lines decoded into those counts), analog ones in volts. Drawn
as the live view draws, time before now.
The scope's recording takes the same stream as columns beside its CN3 channels
(:func:`recorder_columns`: ``bench_pos``, ``bench_cmd_pos`` [deg], ``bench_<channel>``).
"""

from __future__ import annotations

import numpy as np

from fha_studio.logic.bench.display import peak_rows
from fha_studio.logic.scope.recorder import BesideColumns
from fha_studio.logic.wording import unit_words

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
        if name in _decoded_lines(started):
            continue  # the encoder's and the command's lines: their position is drawn instead
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
            traces[f"bench {device}: {lines} {what} [{unit_words('deg')}]"] = ("deg", t, degrees)
        else:
            traces[f"bench {device}: {label} [counts]"] = ("counts", t, values)
    return traces


def _decoded_lines(started: BenchStarted) -> set[str]:
    """The channels decoded into counts (named in the counts' labels: "sim-cn2:ENC_A/ENC_B counts")."""
    lines: set[str] = set()
    for label in started.labels[len(started.channels):]:
        lines.update(label.split(":", 1)[1].split(" ", 1)[0].split("/"))
    return lines


def _column_name(text: str) -> str:
    return "bench_" + "".join(ch if ch.isalnum() else "_" for ch in text.lower()).strip("_")[:50]


def recorder_columns(started: BenchStarted, live_t0: float, counts_per_output_turn: int) -> BesideColumns:
    """The bench stream as columns of the scope's recording, beside its CN3 channels: at each
    CN3 sample the bench row at or before it (the same host clock), each column's source named."""
    device = started.device.split(":", 1)[0]
    names: list[str] = []
    sources: dict[str, str] = {}
    scale: list[float] = []
    for name in started.channels:
        column = _column_name(name)
        names.append(column)
        unit = "logic, 1 = high" if name in started.logic else "V"
        sources[column] = f"bench {device}: {name} ({unit}, the display row at or before each sample)"
        scale.append(1.0)
    for j, extra in enumerate(started.extra):
        label = started.labels[len(started.channels) + j].split(":", 1)[1]
        if counts_per_output_turn > 0:
            column = "bench_pos" if extra == "counts" else "bench_cmd_pos"
            sources[column] = (f"bench {device}: {label} x 360 / {counts_per_output_turn} counts per "
                               "output turn [deg]")
            scale.append(360.0 / counts_per_output_turn)
        else:
            column = _column_name(label)
            sources[column] = f"bench {device}: {label}"
            scale.append(1.0)
        names.append(column)
    factors = np.asarray(scale)
    offset = live_t0 - started.t0  # CN3's t_s + offset = the bench's t_s

    def sample(t_s: np.ndarray) -> np.ndarray:
        t = np.asarray(t_s, dtype=float) + offset
        ring = started.ring
        if not len(ring):
            return np.zeros((t.size, len(names)))
        newest = float(ring.window(1)[0, 0])
        back = int(max(0.0, newest - float(t.min())) * started.row_rate_hz) + 2
        rows = ring.window(min(len(ring), back))
        at = np.clip(np.searchsorted(rows[:, 0], t, side="right") - 1, 0, len(rows) - 1)
        values: np.ndarray = rows[at, 1:] * factors
        return values

    return BesideColumns(tuple(names), sources, sample)
