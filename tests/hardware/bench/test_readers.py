"""Capture readers: files made by sigrok-cli itself, every writer's form read back, and the shapes
that are refused with one line naming the file and the line."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fha_studio.hardware.bench import writers
from fha_studio.hardware.bench._numbers import parse_rows
from fha_studio.hardware.bench.capture import CaptureError, SampleBlock, join_blocks, pack_logic, schmitt
from fha_studio.hardware.bench.readers import parse_rate, read_capture

DATA = Path(__file__).parent / "data"
DEMO_LOGIC = tuple(f"D{i}" for i in range(8))


def test_sigrok_cli_files_of_one_capture_read_the_same_in_every_form():
    # demo.sr: `sigrok-cli -d demo --config samplerate=1m --samples 2000`, and sigrok-cli's own
    # conversions of it to VCD and CSV (with the quirks of 0.5.2: analog lines in both)
    session = read_capture(DATA / "demo.sr")
    assert (session.form, session.samples, session.sample_rate_hz) == ("sigrok session", 2000, 1e6)
    assert session.channels == (*DEMO_LOGIC, "A0")
    assert session.analog("A0").dtype == np.float32 and set(np.unique(session.analog("A0"))) <= {-10, 10}
    for other in ("demo.vcd", "demo-logic.csv", "demo-logic-units.csv"):
        capture = read_capture(DATA / other)
        assert capture.samples == 2000 and capture.sample_rate_hz == 1e6, other
        for channel in DEMO_LOGIC:
            assert np.array_equal(capture.logic(channel), session.logic(channel)), (other, channel)
    # the demo's pattern is not constant: the comparison above compared something
    assert np.count_nonzero(np.diff(session.logic("D0").astype(int))) > 100


def _block(n: int = 3000, seed: int = 3) -> SampleBlock:
    rng = np.random.default_rng(seed)
    bits = [rng.random(n) < 0.5 for _ in range(3)]
    analog = {"SPD": rng.normal(0, 3, n).astype(np.float32),
              "PROBE": rng.normal(0, 0.1, n).astype(np.float32)}
    return SampleBlock(250e3, ("A", "B", "Z"), pack_logic(bits), analog)


@pytest.mark.parametrize("form", ["sr", "sigrok-csv", "sigrok-csv-time", "csv", "csv-ms", "csv-semicolon"])
def test_each_written_form_reads_back(tmp_path, form):
    block = _block()
    path = tmp_path / ("x.sr" if form == "sr" else "x.csv")
    if form == "sr":
        writers.write_sr(path, block)
    elif form.startswith("sigrok-csv"):
        writers.write_sigrok_csv(path, block, time=form.endswith("time"))
    else:
        writers.write_csv(path, block, semicolon=form.endswith("semicolon"),
                          time_unit="ms" if form.endswith("ms") else "s")
    capture = read_capture(path)
    assert capture.samples == block.samples
    assert capture.sample_rate_hz == pytest.approx(250e3, rel=1e-9)
    for name in ("A", "B", "Z"):
        assert np.array_equal(capture.logic(name), block.bit(name)), name
    for name in ("SPD", "PROBE"):
        exact = form == "sr"
        assert np.allclose(capture.analog(name), block.analog[name], rtol=0 if exact else 1e-5,
                           atol=0 if exact else 1e-6), name


def test_vcd_reads_back_and_sigrok_cli_reads_what_we_write(tmp_path):
    # 1 MHz: a VCD's time unit is one sample (sigrok reads a VCD at the rate of its time unit)
    block = _block(2000)
    block = SampleBlock(1e6, block.logic_channels, block.logic, block.analog)
    writers.write_vcd(tmp_path / "x.vcd", block)  # the analog channels as real variables
    back = read_capture(tmp_path / "x.vcd")
    assert back.samples == 2000 and back.sample_rate_hz == 1e6
    assert np.array_equal(back.block.logic, block.logic)
    for name in ("SPD", "PROBE"):  # float32 written with 9 digits: the same numbers back
        assert np.array_equal(back.analog(name), block.analog[name]), name
    assert back.units == {"SPD": "V", "PROBE": "V"}
    writers.write_sr(tmp_path / "x.sr", block)
    if shutil.which("sigrok-cli") is None:
        pytest.skip("sigrok-cli is not installed (scripts/test installs it)")
    for source in ("x.vcd", "x.sr"):
        run = subprocess.run(["sigrok-cli", "-i", str(tmp_path / source), "-O", "csv"],
                             capture_output=True, timeout=60, check=False)
        (tmp_path / "via-sigrok.csv").write_bytes(run.stdout)
        again = read_capture(tmp_path / "via-sigrok.csv")
        assert again.sample_rate_hz == 1e6 and again.samples == 2000, source
        for name in ("A", "B", "Z"):
            assert np.array_equal(again.logic(name), block.bit(name)), (source, name)


def test_a_vcd_at_a_rate_that_is_not_a_whole_number_of_picoseconds():
    block = SampleBlock(24e6, ("A",), pack_logic([np.arange(500) % 3 == 0]))
    capture = _parse_vcd(writers.vcd_bytes(block))
    assert capture.sample_rate_hz == 24e6 and np.array_equal(capture.logic("A"), block.bit("A"))


def test_a_vcds_real_variables_are_held_between_changes_and_a_bad_value_is_one_line():
    # ids as IEEE 1364 allows them: '#' and 'r' are ids here, not a time or a real's value
    head = ("$timescale 1 us $end\n$var wire 1 ! ENC_A $end\n$var real 64 # SPD_MON $end\n"
            "$var real 64 r I $end\n$enddefinitions $end\n")
    capture = _parse_vcd((head + "#0 0! r0.5 # r-1e-3 r\n#2 1! r1.25 #\n#3 0!\n#5\n").encode())
    assert capture.samples == 5 and capture.channels == ("ENC_A", "SPD_MON", "I")
    assert capture.analog("SPD_MON").tolist() == [0.5, 0.5, 1.25, 1.25, 1.25]
    assert np.allclose(capture.analog("I"), -1e-3) and capture.logic("ENC_A").tolist() == [0, 0, 1, 0, 0]
    for bad in ("rfast", "rnan"):
        with pytest.raises(CaptureError) as refused:
            _parse_vcd((head + f"#0 0! r0.5 #\n#1 {bad} #\n").encode())
        assert str(refused.value) == f"x.vcd: line 7: '{bad}' is not a real value ('r' and a number)"


def _parse_vcd(data: bytes):
    from fha_studio.hardware.bench.readers import parse_vcd

    return parse_vcd(data, "x.vcd")


def test_a_generic_csv_with_comments_units_row_and_decimal_commas(tmp_path):
    path = tmp_path / "scope.csv"
    path.write_text("# Oscilloscope export\n# Model XYZ\nTime;CH1;CH2\ns;V;V\n"
                    "0,000;0,5;-1,25e-1\n# marker\n0,001;0,6;2\n0,002;0,7;1e1\n")
    capture = read_capture(path)
    assert capture.sample_rate_hz == pytest.approx(1000)
    assert capture.units == {"CH1": "V", "CH2": "V"}
    assert np.allclose(capture.analog("CH1"), [0.5, 0.6, 0.7])
    assert np.allclose(capture.analog("CH2"), [-0.125, 2, 10])


def test_a_time_column_in_milliseconds_by_its_name(tmp_path):
    path = tmp_path / "trace.csv"
    path.write_text("time_ms,cmd\n0,1\n0.5,2\n1.0,3\n")
    assert read_capture(path).sample_rate_hz == pytest.approx(2000)


@pytest.mark.parametrize(("text", "expect"), [
    ("time,CH1\n0,1\n0.001,1\n0.002,x1\n", "line 4: field 2 'x1' is not a number"),
    ("time,CH1\n0,1\n0.001,1,7\n", "line 3: 3 fields, expected 2"),
    ("time [h],CH1\n0,1\n1,1\n", "the time column's unit 'h' is not s, ms, us or ns"),
    ("time,CH1\n0,1\n0.001,\n0.002,1\n", "line 3: column 'CH1' is empty, expected a number"),
    ("time,CH1\n0,1\n", "fewer than 2 rows of samples"),
    ("1,2\n3,4\n", "line 1: numbers where the header row was expected"),
    ("time,CH1,CH1\n0,1,1\n1,1,1\n", "column 'CH1' given twice"),
    ("time,CH1\n0,1e999\n1,1\n", "line 2: field 2 '1e999' is not a number"),
])
def test_a_csv_of_another_shape_is_refused_with_the_line(tmp_path, text, expect):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(CaptureError) as err:
        read_capture(path)
    assert str(err.value).startswith(f"{path}: ")
    assert expect in str(err.value) and "\n" not in str(err.value)


def test_only_regular_files_are_read(tmp_path):
    with pytest.raises(ValueError, match="a directory"):
        read_capture(tmp_path)


def test_the_vectorised_number_parser_reads_as_float_does():
    rng = np.random.default_rng(0)
    values = np.concatenate([rng.normal(0, 10, 2000), rng.normal(0, 1e-7, 500), rng.normal(0, 1e9, 500)])
    texts = [format(v, fmt) for v, fmt in zip(values, ["g", ".12g", ".6e", "f"] * 750, strict=True)]
    rows = "\n".join(",".join(texts[i:i + 3]) for i in range(0, 3000, 3)) + "\n"
    parsed = parse_rows(rows.encode(), 3)
    assert parsed is not None
    assert np.array_equal(parsed.ravel(), [float(t) for t in texts])
    for bad in ("1,a\n", "1.2.3,4\n", "-,1\n", "1e,2\n", "1 2,3\n", "1-2,3\n", "1,2,3\n", "1e+,2\n"):
        assert parse_rows(bad.encode(), 2) is None, bad
    assert np.array_equal(parse_rows(b" 1 ,\t-2.5e+1\r\n", 2), [[1.0, -25.0]])
    # rows of one length (fields in fixed places) take the column-wise path: the same numbers
    fixed = "".join(f"{a:+09.3f},{b:.4e},{c:08d}\n" for a, b, c in
                    zip(values[:1000], values[1000:2000], range(1000), strict=True))
    expected = [[float(x) for x in line.split(",")] for line in fixed.splitlines()]
    assert np.array_equal(parse_rows(fixed.encode(), 3), expected)
    for bad in ("1,-\n2,3\n", "1.2.,3\n4.5.,6\n", "1e5,1\n1x5,1\n"):
        assert parse_rows(bad.encode(), 2) is None, bad


def test_sigrok_rates_and_blocks():
    assert parse_rate("24 MHz") == 24e6 and parse_rate("200 kHz") == 2e5 and parse_rate("1 Hz") == 1
    assert parse_rate("fast") is None
    a = SampleBlock(1e3, ("X",), np.array([0, 1, 1], np.uint8), {"V": np.zeros(3, np.float32)})
    b = SampleBlock(1e3, ("X",), np.array([0, 0], np.uint8), {"V": np.ones(2, np.float32)}, first_sample=3)
    joined = join_blocks([a, b])
    assert joined.samples == 5 and list(joined.bit("X")) == [False, True, True, False, False]
    with pytest.raises(ValueError, match="a gap"):
        join_blocks([a, a])


def test_an_oscilloscope_trace_of_a_line_driver_reads_as_logic_despite_noise():
    rng = np.random.default_rng(5)
    level = (np.arange(4000) // 50) % 2 == 1
    trace = np.where(level, 5.0, 0.0) + rng.normal(0, 0.4, 4000)
    assert np.array_equal(schmitt(trace), level)
