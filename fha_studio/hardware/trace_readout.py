"""A finished capture's read-out, block by block, over any drive's ``trace_status`` and
``read_trace_block``: the one loop :meth:`DriveClient.read_trace
<fha_studio.hardware.client.DriveClient.read_trace>` runs (and every fake of a drive with it)."""

from __future__ import annotations

import math
from collections.abc import Callable

from fha_studio.hardware import protocol as p
from fha_studio.hardware.api import TraceCapture, TraceStatus
from fha_studio.hardware.errors import CommandRejected, ReadAborted


def block_samples(block: int, count: int) -> int:
    """Samples in block ``block`` of a capture of ``count`` (64 but the last); ValueError for a
    block outside the capture."""
    samples = min(p.TRACE_BLOCK_SAMPLES, count - block * p.TRACE_BLOCK_SAMPLES)
    if block < 0 or samples <= 0:
        raise ValueError(f"read_trace_block: block {block} is outside a capture of {count} samples")
    return samples


def read_out(
    channels: tuple[int, ...],
    trace_status: Callable[[], TraceStatus],
    read_trace_block: Callable[[int, int], list[tuple[int, ...]]],
    should_abort: Callable[[], bool] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> TraceCapture:
    """The finished capture of ``channels`` (as ``configure_trace`` returned them), read block by
    block. ``should_abort`` is asked before every block: True gives up there with
    ``ReadAborted`` (``done`` / ``total`` samples). ``progress(done, total)`` before the first
    block and after every block. CommandRejected when no capture is finished."""
    if not channels:
        raise ValueError("read_trace: configure_trace first (the channels are not known)")
    status = trace_status()
    if status.state is not p.TraceState.DONE:
        raise CommandRejected(f"no finished capture (state {status.state.name.lower()})")
    rows: list[tuple[int, ...]] = []
    if progress is not None:
        progress(0, status.count)
    for block in range(math.ceil(status.count / p.TRACE_BLOCK_SAMPLES)):
        if should_abort is not None and should_abort():
            raise ReadAborted(f"trace read-out stopped after {len(rows)} of {status.count} samples",
                              len(rows), status.count)
        rows += read_trace_block(block, status.count)
        if progress is not None:
            progress(len(rows), status.count)
    return TraceCapture(channels, tuple(rows))
