"""The scope's data to and from files, as plain arrays (no Qt): a recording (``fha-recording/1``)
as the scope's channels and rows, and the data on show as a CSV table.

Rows are the scope's sample layout, ``[t_s, channel values...]``.
"""

from __future__ import annotations

import io
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

import numpy as np

from fha_studio.logic.scope.channels import ScopeChannel
from fha_studio.logic.scope.recorder import CONTRACT_SOURCES
from fha_studio.recording import Recording

#: A sampling is uniform when its steps differ by at most this share of the median step.
UNIFORM_TOLERANCE = 0.01


@dataclass(frozen=True)
class RecordingRows:
    """A recording as the scope shows it: its channels, the rows, whether the samples are evenly
    spaced (a spectrum needs that) and the sample rate its metadata states."""

    channels: tuple[ScopeChannel, ...]
    rows: np.ndarray
    uniform: bool
    sample_rate_hz: float | None


def recording_rows(recording: Recording, known: Iterable[ScopeChannel]) -> RecordingRows:
    """The recording's columns as the scope's channels: the contract columns (``pos``,
    ``current``, ...) as the channels they were recorded from, another column as a channel of
    ``known`` with its name, else as a channel named by the column, without a unit."""
    by_key = {c.key: c for c in known}
    channels, columns = [], []
    for name, values in recording.channels.items():
        if name == "t":
            continue
        key = CONTRACT_SOURCES.get(name, name)
        channels.append(by_key.get(key) or ScopeChannel(key, name, "", 0))
        columns.append(values)
    rows = np.column_stack([recording.t_s, *columns])
    dt = np.diff(recording.t_s)
    uniform = len(dt) > 0 and float(np.ptp(dt)) <= UNIFORM_TOLERANCE * float(np.median(dt))
    return RecordingRows(tuple(channels), rows, uniform, recording.metadata.sample_rate_hz)


def csv_text(channels: Sequence[ScopeChannel], rows: np.ndarray) -> str:
    """``t_s`` and one column per channel, headed ``key [unit]``, nine significant digits."""
    header = ",".join(["t_s"] + [f"{c.key} [{c.unit}]" for c in channels])
    text = io.StringIO()
    np.savetxt(text, rows, delimiter=",", header=header, comments="", fmt="%.9g")
    return text.getvalue()
