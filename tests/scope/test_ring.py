import threading

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from fha_studio.logic.scope.ring import RingBuffer


def rows(start, n, channels=2):
    return np.column_stack([np.arange(start, start + n, dtype=float)] * channels)


def test_drain_returns_what_was_written_in_order():
    ring = RingBuffer(2, 10)
    ring.write(rows(0, 3))
    ring.write(rows(3, 4))
    out = ring.drain()
    assert out[:, 0].tolist() == list(range(7))
    assert ring.drain().shape == (0, 2)
    assert ring.dropped == 0


def test_overflow_is_counted_and_the_newest_rows_kept():
    ring = RingBuffer(2, 10)
    ring.write(rows(0, 8))
    ring.write(rows(8, 7))  # 15 written, capacity 10: the 5 oldest were never drained
    assert ring.dropped == 5
    assert ring.drain()[:, 0].tolist() == list(range(5, 15))


def test_window_is_a_contiguous_view_without_copy():
    ring = RingBuffer(1, 5)
    ring.write(rows(0, 13, 1))
    view = ring.window(4)
    assert view[:, 0].tolist() == [9, 10, 11, 12]
    assert view.base is not None and not view.flags.writeable
    assert ring.window()[:, 0].tolist() == [8, 9, 10, 11, 12]


def test_a_copied_window_of_the_whole_ring_stays_in_time_order_while_the_writer_goes_on():
    """A view of the whole ring turns into newer rows at its start once the writer goes on (the
    bench's Time plot drew a line from the newest row back to the oldest); the copy does not."""
    ring = RingBuffer(1, 10)
    ring.write(rows(0, 23, 1))
    view, copied = ring.window(), ring.window(copy=True)
    ring.write(rows(23, 3, 1))  # the stream's thread, while the GUI reads
    assert copied[:, 0].tolist() == list(range(13, 23))
    assert copied.flags.writeable and copied.base is None
    assert view[:3, 0].tolist() == [23, 24, 25]  # what the view holds now: out of time order
    assert ring.window(4, copy=True)[:, 0].tolist() == [22, 23, 24, 25]


def test_wrong_channel_count_is_refused():
    ring = RingBuffer(3, 5)
    with pytest.raises(ValueError, match="2 channels, the buffer 3"):
        ring.write(np.zeros((1, 2)))


@settings(max_examples=60, deadline=None)
@given(capacity=st.integers(1, 20), blocks=st.lists(st.integers(0, 30), max_size=12),
       drain_every=st.integers(1, 4))
def test_nothing_is_lost_without_being_counted(capacity, blocks, drain_every):
    ring = RingBuffer(1, capacity)
    seen, start = [], 0
    for i, n in enumerate(blocks):
        ring.write(rows(start, n, 1))
        start += n
        if i % drain_every == 0:
            seen.extend(ring.drain()[:, 0].tolist())
    seen.extend(ring.drain()[:, 0].tolist())
    assert len(seen) + ring.dropped == start
    assert seen == sorted(seen)  # in order, no duplicates
    assert len(set(seen)) == len(seen)


def test_concurrent_writer_and_drainer_lose_nothing_uncounted():
    ring = RingBuffer(1, 64)
    total = 20000
    got = []

    def writer():
        for k in range(0, total, 10):
            ring.write(rows(k, 10, 1))

    thread = threading.Thread(target=writer)
    thread.start()
    while thread.is_alive():
        got.extend(ring.drain()[:, 0].tolist())
    thread.join()
    got.extend(ring.drain()[:, 0].tolist())
    assert len(got) + ring.dropped == total
    assert got == sorted(got)
