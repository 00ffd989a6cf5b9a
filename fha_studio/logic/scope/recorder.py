"""Record scope samples to disk as ``fha-recording/1`` (plus extra channels) while plotting.

The contract columns come from the channels the model check needs: ``pos`` = feedback position
[deg], ``current`` = motor current [A], and when present ``cmd_pos`` [deg], ``load_pos`` [deg],
``vel`` [r/min], ``torque`` [N m, the flange's torque sensor]; every other channel is written as an
extra column under its key. The writer flushes at least once per second, so a crash loses at most a
second of data.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from fha_studio.logic.scope.channels import POSITION_KEYS, ScopeChannel
from fha_studio.recording import RecordingMetadata, RecordingWriter

CONTRACT_SOURCES = {
    "pos": "feedback_position",
    "current": "motor_current",
    "cmd_pos": "command_position",
    "load_pos": "load_position",
    "vel": "output_speed",
    "torque": "flange_torque",  # the simulated drive's torque sensor on the flange (monitor 111)
}


@dataclass(frozen=True)
class BesideColumns:
    """Columns recorded beside the scope's channels (a bench instrument's stream): their names,
    where each came from (the recording's ``source_<column>``), and their values at the scope's
    sample times (``sample(t_s)`` -> ``(len(t_s), len(columns))``)."""

    columns: tuple[str, ...]
    sources: Mapping[str, str]
    sample: Callable[[np.ndarray], np.ndarray]


class ScopeRecorder:
    """Writes rows of ``[t_s, channel values...]`` (the scope's sample layout) to a recording;
    ``beside``: columns of another source at the same times, after the channels."""

    def __init__(self, path: str | os.PathLike[str], metadata: RecordingMetadata,
                 channels: Sequence[ScopeChannel], beside: BesideColumns | None = None):
        keys = [c.key for c in channels]
        for column in ("pos", "current"):
            if CONTRACT_SOURCES[column] not in keys:
                raise ValueError(
                    f"recording needs the channel '{CONTRACT_SOURCES[column]}' for the column '{column}'"
                )
        for channel in channels:
            if channel.key in POSITION_KEYS and channel.unit != "deg":
                raise ValueError(f"channel '{channel.key}' is in {channel.unit}, the recording wants deg")
        columns = ["t"]
        index: list[int | None] = [None]  # sample column (0 = time) for each file column
        for column, key in CONTRACT_SOURCES.items():
            if key in keys:
                columns.append(column)
                index.append(keys.index(key) + 1)
        used = set(index)
        for i, key in enumerate(keys, start=1):
            if i not in used:
                columns.append(key)
                index.append(i)
        index[0] = 0
        self._index = np.asarray(index)
        self._t0: float | None = None
        self._beside = beside
        if beside is not None:
            columns += list(beside.columns)
            metadata = replace(metadata, extra={**metadata.extra, **{
                f"source_{name}": text for name, text in beside.sources.items()}})
        self._writer = RecordingWriter(path, metadata, columns)

    @property
    def path(self) -> Path:
        return self._writer.path

    @property
    def rows_written(self) -> int:
        return self._writer.rows_written

    def write(self, block: np.ndarray) -> None:
        """Append scope rows (time in column 0, in s); the file's time starts at 0."""
        block = np.asarray(block, dtype=float)
        if block.size == 0:
            return
        if self._t0 is None:
            self._t0 = float(block[0, 0])
        rows = block[:, self._index]
        if self._beside is not None:
            rows = np.column_stack([rows, self._beside.sample(block[:, 0])])
        rows[:, 0] -= self._t0
        self._writer.append_rows(rows)

    def close(self) -> None:
        self._writer.close()

