"""Small files in the CSV layouts instruments export, read, and each layout malformed: one line
naming the file, the line and what was expected, nothing half-read."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio.hardware.bench.capture import CaptureError
from fha_studio.hardware.bench.readers import read_capture

# Saleae Logic 2, File > Export Data > CSV of digital channels: one row per change
SALEAE = (
    "Time [s],ENC_A,ENC_B\n"
    "-0.000010000,0,0\n"
    "0.000000000,1,0\n"
    "0.000005000,1,1\n"
    "0.000015000,0,1\n"
    "0.000025000,0,0\n"
)


def test_a_saleae_export_of_changes_is_held_between_them(tmp_path):
    path = tmp_path / "digital.csv"
    path.write_text(SALEAE)
    capture = read_capture(path)
    assert capture.sample_rate_hz == pytest.approx(200e3)  # 5 us, the finest interval
    assert capture.start_s == pytest.approx(-10e-6)
    assert capture.logic("ENC_A").astype(int).tolist() == [0, 0, 1, 1, 1, 0, 0, 0]
    assert capture.logic("ENC_B").astype(int).tolist() == [0, 0, 0, 1, 1, 1, 1, 0]
    assert "200 kHz (the finest interval between them)" in capture.form


def test_logic_1_and_a_steady_logic_table_read_too(tmp_path):
    path = tmp_path / "logic1.csv"
    path.write_text(
        "Time[s], Channel 0, Channel 1\n0.000000000000000, 1, 0\n0.000002000000000, 0, 0\n"
        "0.000003000000000, 0, 1\n"
    )
    capture = read_capture(path)
    assert capture.channels == ("Channel 0", "Channel 1") and capture.sample_rate_hz == pytest.approx(1e6)
    assert capture.logic("Channel 0").astype(int).tolist() == [1, 1, 0, 0]
    # a logic table sampled at one rate (rows repeat while nothing changes) stays a CSV at its rate
    path.write_text("time,IN_POS\n0,0\n0.001,0\n0.002,1\n0.003,1\n")
    steady = read_capture(path)
    assert steady.form == "CSV" and steady.samples == 4 and steady.sample_rate_hz == pytest.approx(1000)


def test_rigol_reads_time_from_start_and_increment(tmp_path):
    path = tmp_path / "NewFile1.csv"
    path.write_text(
        "X,CH1,CH2,Start,Increment,\nSequence,Volt,Volt,-6.000000e-03,2.000000e-06\n"
        "0,4.72e+00,2.40e-02,\n1,4.64e+00,3.20e-02,\n2,-1.20e-01,5.00e+00,\n"
    )
    capture = read_capture(path)
    assert capture.form == "Rigol CSV" and capture.channels == ("CH1", "CH2")
    assert capture.sample_rate_hz == pytest.approx(500e3) and capture.start_s == pytest.approx(-6e-3)
    assert np.allclose(capture.analog("CH2"), [0.024, 0.032, 5.0]) and capture.units["CH1"] == "V"


def test_tektronix_siglent_picoscope_and_keysight_headers(tmp_path):
    files = {
        "tek.csv": (
            "Model,MSO4104,,\nFirmware Version,2.48,,\n,,\nPoint Format,Y,Y\nHorizontal Units,s,s\n"
            "Sample Interval,1e-06,1e-06\nRecord Length,3,3\nVertical Units,V,V\n,,\n,,\nLabel,,\n"
            "TIME,CH1,CH2\n-1.0000000e-06,0.1,2\n0.0000000e+00,0.2,3\n1.0000000e-06,0.3,4\n"
        ),
        "SDS00001.CSV": (
            "Record Length,Analog:3\nSample Rate,1000000.0\nVertical Scale,CH2: 0.05\n"
            "Vertical Offset,CH2:0.00000\nHorizontal Scale, 0.000001000\nSecond,Volt\n"
            "-0.00000100000,0.10000\n0.00000000000,0.20000\n0.00000100000,0.30000\n"
        ),
        "sds_source.csv": (
            "Source,CH1,CH2\nSecond,Volt,Volt\n-1.0E-06,0.1,2\n0.0E+00,0.2,3\n1.0E-06,0.3,4\n"
        ),
        "pico.csv": (
            "Time,Channel A,Channel B\n(ms),(V),(V)\n\n-0.00100000,0.10000000,2.00000000\n"
            "0.00000000,0.20000000,3.00000000\n0.00100000,0.30000000,4.00000000\n"
        ),
        "keysight.csv": (
            "x-axis,1,2\nsecond,Volt,Volt\n-1.000000E-06,+0.1E+00,2\n+0.0E+00,0.2,3\n1.000000E-06,0.3,4\n"
        ),
    }
    names = {
        "tek.csv": ("CH1", "CH2"),
        "SDS00001.CSV": ("CH2",),
        "sds_source.csv": ("CH1", "CH2"),
        "pico.csv": ("Channel A", "Channel B"),
        "keysight.csv": ("1", "2"),
    }
    for file, text in files.items():
        (tmp_path / file).write_text(text)
        capture = read_capture(tmp_path / file)
        assert capture.channels == names[file], file
        assert capture.sample_rate_hz == pytest.approx(1e6), file
        assert capture.start_s == pytest.approx(-1e-6), file
        assert np.allclose(capture.analog(names[file][0]), [0.1, 0.2, 0.3]), file
        assert set(capture.units.values()) == {"V"}, file


TDS = (
    "Record Length,4.000000e+00,,-0.000002000000,0.08000,\n"
    "Sample Interval,1.000000e-06,,-0.000001000000,0.08000,\n"
    "Trigger Point,2.000000000000e+00,,0.000000000000,4.96000,\n"
    ",,,0.000001000000,4.96000,\n"
    "Source,CH2,,0.000002000000,4.96000,\n"
    "Vertical Units,V,,0.000003000000,0.08000,\n"
)


def test_an_older_tektronix_file_has_its_samples_beside_the_settings(tmp_path):
    path = tmp_path / "F0000CH2.CSV"
    path.write_text(TDS.replace("Record Length,4.000000e+00", "Record Length,6.000000e+00"))
    capture = read_capture(path)
    assert capture.form == "Tektronix TDS/TBS CSV" and capture.channels == ("CH2",)
    assert capture.sample_rate_hz == pytest.approx(1e6) and capture.start_s == pytest.approx(-2e-6)
    assert np.allclose(capture.analog("CH2"), [0.08, 0.08, 4.96, 4.96, 4.96, 0.08])


@pytest.mark.parametrize(
    ("text", "expect"),
    [
        # Saleae: the time goes back; a level that is not 0 or 1
        (
            SALEAE.replace("0.000015000,0,1", "0.000001000,0,1"),
            "line 5: time 1e-06 s after 5e-06 s: the changes of a logic analyzer's export go forward in time",
        ),
        (
            SALEAE.replace("0.000015000,0,1", "0.000015000,0,2"),
            "line 5: ENC_B is 2, expected 0 or 1 (a logic analyzer's export of changes)",
        ),
        # Rigol: no Increment; an index that jumps; a value that is not a number; a row cut short
        (
            "X,CH1,Start,Increment,\nSequence,Volt,-1.0e-05,\n0,1.0,\n1,2.0,\n",
            "line 2: expected the units, then Start and Increment as numbers",
        ),
        (
            "X,CH1,Start,Increment,\nSequence,Volt,-1.0e-05,1.0e-07,\n0,1.0,\n1,2.0,\n3,2.0,\n",
            "line 5: sample index 3 after 1: the samples of one acquisition, one after another, are expected",
        ),
        (
            "X,CH1,Start,Increment,\nSequence,Volt,-1.0e-05,1.0e-07,\n0,1.0,\n1,****,\n",
            "line 4: field 2 '****' is not a number",
        ),
        (
            "X,CH1,CH2,Start,Increment,\nSequence,Volt,Volt,0,1.0e-07\n0,1.0,2.0,\n1,2.0,\n",
            "line 4: 3 fields, expected 4",
        ),
        (
            "X,CH1,Start,Increment,\nSequence,Volt,0,0\n0,1.0,\n1,2.0,\n",
            "line 2: Increment 0: a sample interval > 0 s is expected",
        ),
        # Tektronix with a preamble and no TIME row; a row cut short
        (
            "Model,MSO4104\nSample Interval,1e-06\nRecord Length,2\n-1e-06,0.1\n0,0.2\n",
            "line 1: no time column",
        ),
        (
            "Model,MSO4104\nRecord Length,3\nTIME,CH1\n-1e-06,0.1\n0,0.2,7\n1e-06,0.3\n",
            "line 5: 3 fields, expected 2",
        ),
        # Siglent: a value that is not a number
        (
            "Record Length,Analog:3\nSample Rate,1000000.0\nSecond,Volt\n"
            "0.000000,0.1\n0.000001,0.2V\n0.000002,0.3\n",
            "line 5: field 2 '0.2V' is not a number",
        ),
        # PicoScope writes infinity for a sample beyond the range
        (
            "Time,Channel A\n(ms),(V)\n\n0.000,0.1\n0.001,\u221e\n0.002,0.3\n",
            "line 5: field 2 '\u221e' is not a number",
        ),
        # Tektronix TDS: cut short of its Record Length; a sample that is not a number
        (
            TDS.replace("Record Length,4.000000e+00", "Record Length,2.500000e+03"),
            "line 6: 6 samples, but Record Length says 2.500000e+03: the file is cut short or has more "
            "than one record",
        ),
        (
            TDS.replace("-0.000001000000,0.08000", "-0.000001000000,x"),
            "line 2: '-0.000001000000', 'x' in columns 4 and 5, expected the time and the value (numbers)",
        ),
    ],
)
def test_each_layout_malformed_is_one_line_naming_the_file_and_line(tmp_path, text, expect):
    path = tmp_path / "bad.csv"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(CaptureError) as err:
        read_capture(path)
    message = str(err.value)
    assert message.startswith(f"{path}: ") and "\n" not in message
    assert expect in message, message


def test_streaming_through_sigrok_cli_says_which_layouts_it_cannot_take(tmp_path):
    """sigrok-cli's CSV input takes samples at one rate in columns: a Rigol file, an older
    Tektronix one and an export of changes are refused in one line before it is started."""
    from fha_studio.hardware.bench.sigrok import SigrokError
    from fha_studio.hardware.bench.sigrok_input import plan_input

    files = {
        "rigol.csv": ("X,CH1,Start,Increment,\nSequence,Volt,0,1.0e-06,\n0,1.0,\n1,2.0,\n", "a Rigol CSV"),
        "tds.csv": (TDS, "a Tektronix TDS/TBS CSV"),
        "digital.csv": (SALEAE, "line 2: a logic analyzer's export of changes"),
    }
    for file, (text, expect) in files.items():
        (tmp_path / file).write_text(text)
        with pytest.raises(SigrokError) as err:
            plan_input(tmp_path / file, program="/nonexistent/sigrok-cli")
        assert str(err.value).startswith(f"{tmp_path / file}: ") and expect in str(err.value)
