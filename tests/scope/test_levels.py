"""Pre-decimated min/max levels: the envelope drawn equals the brute-force one, however the
samples arrive."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.logic.scope.levels import MinMaxLevels


def _signal(n: int, channels: int = 3, seed: int = 1) -> np.ndarray:
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 1000.0
    return np.column_stack([t] + [np.cumsum(rng.normal(size=n)) * (k + 1) for k in range(channels)])


def test_appending_in_blocks_gives_the_envelope_of_each_bin():
    rows = _signal(60_000)
    levels = MinMaxLevels(3, 65_536)
    for chunk in np.array_split(rows, 977):  # uneven blocks, as a GUI timer drains them
        levels.append(chunk)
    t, y = levels.window(0.0, 60.0, 1000)
    assert levels.level_for(0.0, 60.0, 1000) == 6  # 60 000 / 2^6 = 937 full bins <= 1000
    assert len(t) == 2 * 937 and y.shape == (2 * 937, 3)
    bins = rows[: 937 * 64].reshape(937, 64, 4)
    np.testing.assert_array_equal(y[0::2], bins[:, :, 1:].min(axis=1))
    np.testing.assert_array_equal(y[1::2], bins[:, :, 1:].max(axis=1))
    np.testing.assert_array_equal(t[0::2], bins[:, 0, 0])
    np.testing.assert_array_equal(t[1::2], bins[:, -1, 0])


def test_a_short_window_is_drawn_from_the_samples_themselves_with_one_either_side():
    rows = _signal(5000)
    levels = MinMaxLevels(3, 8192)
    levels.append(rows)
    t, y = levels.window(1.0, 1.5, 1000)
    np.testing.assert_array_equal(t, rows[999:1502, 0])
    np.testing.assert_array_equal(y, rows[999:1502, 1:])


def test_old_samples_drop_out_and_the_newest_are_always_there():
    levels = MinMaxLevels(1, 1024)
    rows = _signal(10_000, channels=1)
    for chunk in np.array_split(rows, 37):
        levels.append(chunk)
    assert len(levels) == 1024
    t, y = levels.window(0.0, 20.0, 100)
    assert t[-1] >= rows[-2, 0] and t[0] >= rows[-1100, 0]
    assert y.max() <= rows[-1024:, 1].max() + 1e-12 and y.max() >= rows[-900:, 1].max() - 1e-12


def test_wrong_rows_are_refused_by_name():
    with pytest.raises(ValueError, match="2 channels, the levels 3"):
        MinMaxLevels(3, 100).append(np.zeros((4, 3)))
