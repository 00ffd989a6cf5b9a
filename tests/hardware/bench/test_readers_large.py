"""Large CSVs read in place and a block of rows at a time: the same numbers across the blocks,
a bad row in a later block named by its line, comment and empty lines after the first 200 lines
taken out, and the file's bytes read in one piece."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio import fileio
from fha_studio.hardware.bench import _numbers
from fha_studio.hardware.bench.capture import CaptureError
from fha_studio.hardware.bench.readers import read_capture


@pytest.fixture
def small_blocks(monkeypatch):
    monkeypatch.setattr(_numbers, "CHUNK_ROWS", 7)


def test_fixed_width_rows_read_block_by_block_as_float_does(small_blocks):
    rng = np.random.default_rng(3)
    a, b = rng.normal(0, 10, 100), rng.normal(0, 1e-3, 100)
    text = "".join(f"{x:+09.3f},{y:+.4e},{i:08d},{i % 2}\n"
                   for i, (x, y) in enumerate(zip(a, b, strict=True)))
    expected = [[float(v) for v in line.split(",")] for line in text.splitlines()]
    data = b"header\n" + text.encode()
    parsed = _numbers.parse_rows(data, 4, start=7)
    assert parsed is not None and np.array_equal(parsed, expected)
    lines = text.splitlines()
    assert len({len(line) for line in lines}) == 1  # fields in fixed places
    for row, at, char in ((60, 7, "x"), (93, 25, "-"), (99, 9, ";")):  # a letter, a sign, a separator
        wrong = lines.copy()
        wrong[row] = wrong[row][:at] + char + wrong[row][at + 1:]
        assert _numbers.parse_rows(("\n".join(wrong) + "\n").encode(), 4) is None


def _scope(rows: int) -> list[str]:
    return [f"{i:06d},{(i % 50) / 10:.3f}" for i in range(rows)]


def test_comment_and_empty_lines_after_the_head_are_taken_out(tmp_path, small_blocks):
    rows = _scope(500)
    body = [*rows[:300], "# trigger", "", *rows[300:]]
    path = tmp_path / "scope.csv"
    path.write_text("time [us],CH1 [V]\n" + "\n".join(body) + "\n")
    capture = read_capture(path)
    assert capture.samples == 500 and capture.sample_rate_hz == pytest.approx(1e6)
    assert np.allclose(capture.analog("CH1"), [(i % 50) / 10 for i in range(500)])
    empty_only = tmp_path / "empty_line.csv"
    empty_only.write_text("time [us],CH1 [V]\n" + "\n".join([*rows[:300], "", *rows[300:]]) + "\n")
    assert read_capture(empty_only).samples == 500


def test_a_bad_row_deep_in_a_large_file_is_named_by_its_line(tmp_path, small_blocks):
    rows = _scope(500)
    rows[400] = rows[400][:-1] + "x"
    path = tmp_path / "bad.csv"
    path.write_text("time [us],CH1 [V]\n" + "\n".join(rows) + "\n")
    with pytest.raises(CaptureError) as err:
        read_capture(path)
    assert str(err.value) == f"{path}: line 402: field 2 '{rows[400].split(',')[1]}' is not a number " \
        "(a plain decimal like 12, -0.5 or 1.5e-3)"


def test_a_file_is_read_in_one_piece_and_whole(tmp_path):
    path = tmp_path / "big.bin"
    data = bytes(range(256)) * 20_000  # 5 MB: more than one chunk of old
    path.write_bytes(data)
    assert fileio.read_bytes(path, limit_bytes=len(data)) == data
    with pytest.raises(fileio.FileProblem, match="more than"):
        fileio.read_bytes(path, limit_bytes=len(data) - 1)
