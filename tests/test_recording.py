"""The fha-recording/1 reader and streaming writer."""

from __future__ import annotations

import numpy as np
import pytest

from fha_studio import recording as rec
from fha_studio.recording import (
    Recording,
    RecordingError,
    RecordingMetadata,
    RecordingWriter,
    make_recording,
    parse_recording,
    read_recording,
    write_recording,
)
from tests.support.clock import FakeClock
from tests.support.processes import Child

GOOD = """\
# format: fha-recording/1
# actuator: FHA-25C-50-US250
# load_inertia_kgm2: 1.5
# supply_voltage: 200
# sample_rate_hz: 1000
# operator: J. Smith: night shift
t,pos,current,cmd_pos,load_pos,vel,error_pulse
0,0,0.01,0,0,0,0
0.001,0.0002,0.35,0.0003,0.0001,0.05,3
0.002,0.0009,0.41,0.0011,0.0008,0.1,4
"""


def _meta(**kw) -> RecordingMetadata:
    base = {"actuator": "FHA-25C-50-US250", "load_inertia_kgm2": 1.5, "sample_rate_hz": 1000.0}
    base.update(kw)
    return RecordingMetadata(**base)


def test_reads_metadata_contract_columns_and_extra_channels():
    r = parse_recording(GOOD, source="good.csv")
    m = r.metadata
    assert (m.actuator, m.load_inertia_kgm2, m.supply_voltage, m.sample_rate_hz) == (
        "FHA-25C-50-US250", 1.5, 200, 1000.0)
    assert m.extra == {"operator": "J. Smith: night shift"}
    assert len(r) == 3
    np.testing.assert_allclose(r.t_s, [0, 0.001, 0.002])
    np.testing.assert_allclose(r.current_a, [0.01, 0.35, 0.41])
    assert r.load_pos_deg is not None and r.vel_rpm is not None and r.cmd_pos_deg is not None
    assert list(r.extra_channels) == ["error_pulse"]
    assert r.channels["t"].dtype == np.float64


def test_optional_columns_and_defaults():
    text = ("# format: fha-recording/1\n# actuator: FHA-17C-100-S248\n# load_inertia_kgm2: 0\n"
            "t,current,pos\n0,1,2\n1,1,2\n")
    r = parse_recording(text)
    assert r.metadata.supply_voltage == 200 and r.metadata.sample_rate_hz is None
    assert r.cmd_pos_deg is None and r.load_pos_deg is None and r.vel_rpm is None
    np.testing.assert_allclose(r.pos_deg, [2, 2])


def test_custom_actuator_needs_its_constants():
    head = "# format: fha-recording/1\n# actuator: custom\n# load_inertia_kgm2: 1\n"
    body = "t,pos,current\n0,0,0\n1,1,1\n"
    with pytest.raises(RecordingError) as err:
        parse_recording(head + "# torque_constant_nm_per_a: 22\n" + body)
    assert err.value.field == "actuator_inertia_kgm2" and err.value.line == 2
    constants = "# torque_constant_nm_per_a: 22\n# actuator_inertia_kgm2: 0.81 kg m^2\n"
    r = parse_recording(head + constants + body)
    assert r.metadata.is_custom and r.metadata.torque_constant_nm_per_a == 22
    assert r.metadata.actuator_inertia_kgm2 == 0.81 and r.metadata.motor_turns_per_output_rev is None


LI = "load_inertia_kgm2"


def _replace(old: str, new: str) -> str:
    assert old in GOOD
    return GOOD.replace(old, new)


@pytest.mark.parametrize(
    ("text", "line", "field", "words"),
    [
        (_replace("# format: fha-recording/1\n", ""), 1, "format", "format"),
        (_replace("fha-recording/1", "fha-recording/9"), 1, "format", "expected"),
        (_replace("# actuator: FHA-25C-50-US250\n", ""), None, "actuator", "missing"),
        (_replace("FHA-25C-50-US250", "FHA-99C-50-US250"), 2, "actuator", "model code"),
        (_replace("# load_inertia_kgm2: 1.5\n", ""), None, "load_inertia_kgm2", "missing"),
        (_replace("load_inertia_kgm2: 1.5", "load_inertia: 1.5"), 3, "load_inertia", "no unit"),
        (_replace("load_inertia_kgm2: 1.5", "load_inertia_kgm2: 1.5 lb ft^2"), 3, LI, "unit"),
        (_replace("load_inertia_kgm2: 1.5", "load_inertia_kgm2: heavy"), 3, LI, "not a number"),
        (_replace("load_inertia_kgm2: 1.5", "load_inertia_kgm2: nan"), 3, LI, "not a number"),
        (_replace("supply_voltage: 200", "supply_voltage: 230"), 4, "supply_voltage", "200 or 100"),
        (_replace("sample_rate_hz: 1000", "sample_rate: 1000"), 5, "sample_rate", "sample_rate_hz"),
        (_replace("t,pos,current,", "t,position,current,"), 7, "pos", "required column"),
        (_replace("t,pos,current,", "t,pos,pos,"), 7, "pos", "twice"),
        (_replace("0.001,0.0002,0.35", "0.001,0.0002,abc"), 9, "current", "not a number"),
        (_replace("0.001,0.0002,0.35", "0.001,nan,0.35"), 9, "pos", "not a number"),
        # float() accepts these, a CSV number is a plain decimal
        (_replace("0.001,0.0002,0.35", "0.001,0.0002,3_5"), 9, "current", "not a number"),
        (_replace("0.001,0.0002,0.35", "0.001,0.0002,inf"), 9, "current", "not a number"),
        (_replace("0.001,0.0002,0.35", "0.001,0.0002,\u0663"), 9, "current", "not a number"),
        (_replace("0.001,0.0002,0.35", "0.001,0.0002,1e999"), 9, "current", "too large"),
        (_replace("load_inertia_kgm2: 1.5", "load_inertia_kgm2: 1_5"), 3, LI, "not a number"),
        (_replace("load_inertia_kgm2: 1.5", "load_inertia_kgm2: 1e30"), 3, LI, "plausible range 0 ... 1500"),
        (_replace("load_inertia_kgm2: 1.5", "load_inertia_kgm2: -1"), 3, LI, "plausible range"),
        (_replace("sample_rate_hz: 1000", "sample_rate_hz: 0"), 5, "sample_rate_hz", "plausible range"),
        (_replace("0.002,0.0009", "0.001,0.0009"), 10, "t", "does not increase"),
        (_replace("0.002,0.0009,0.41,0.0011,0.0008,0.1,4", "0.002,0.0009"), 10, None, "2 values"),
    ],
)
def test_malformed_input_is_refused_naming_line_and_field(text, line, field, words):
    with pytest.raises(RecordingError) as err:
        parse_recording(text, source="bad.csv")
    assert err.value.field == field
    if line is not None:
        assert err.value.line == line
        assert f"line {line}" in str(err.value)
    assert str(err.value).startswith("bad.csv")
    assert words in str(err.value)
    if field is not None:
        assert f"'{field}'" in str(err.value)


def test_header_missing_and_too_few_rows():
    with pytest.raises(RecordingError, match="no header"):
        parse_recording("# format: fha-recording/1\n# actuator: FHA-25C-50-US250\n# load_inertia_kgm2: 1\n")
    with pytest.raises(RecordingError, match="at least 2"):
        parse_recording("# format: fha-recording/1\n# actuator: FHA-25C-50-US250\n# load_inertia_kgm2: 1\n"
                        "t,pos,current\n0,0,0\n")


def test_not_utf8_is_refused(tmp_path):
    path = tmp_path / "latin.csv"
    path.write_bytes(GOOD.replace("J. Smith", "J. M\xfcller").encode("latin-1"))
    with pytest.raises(RecordingError, match="UTF-8"):
        read_recording(path)


def _sample(n=2500, extra=True) -> Recording:
    t = np.arange(n) / 1000.0
    ch = {"t": t, "pos": 30 * np.sin(t), "current": 0.1 * np.cos(3 * t) + 1e-9,
          "cmd_pos": 30 * np.sin(t + 1e-3), "load_pos": 30 * np.sin(t) - 1e-4}
    if extra:
        ch["torque_cmd_nm"] = np.full(n, -2.5)
    return make_recording(_meta(extra={"source": "unit test"}), **ch)


def test_write_then_read_round_trip(tmp_path):
    original = _sample()
    path = tmp_path / "r.csv"
    write_recording(path, original)
    back = read_recording(path)
    assert back.metadata == original.metadata
    assert list(back.channels) == list(original.channels)
    for name in original.channels:
        np.testing.assert_allclose(back.channels[name], original.channels[name], rtol=1e-11, atol=1e-12)


def test_plain_numpy_loads_the_file(tmp_path):
    original = _sample()
    path = tmp_path / "r.csv"
    write_recording(path, original)
    # genfromtxt: comment lines skipped, the header row reads as NaN
    table = np.genfromtxt(path, delimiter=",", comments="#")
    assert np.all(np.isnan(table[0]))
    np.testing.assert_allclose(table[1:, 0], original.t_s, atol=1e-12)
    np.testing.assert_allclose(table[1:, 2], original.current_a, atol=1e-12)
    # loadtxt: skip the comment lines and the header by count
    n_head = sum(1 for line in path.read_text().splitlines() if line.startswith("#")) + 1
    data = np.loadtxt(path, delimiter=",", comments="#", skiprows=n_head)
    assert data.shape == (len(original), len(original.channels))
    np.testing.assert_allclose(data[:, 1], original.pos_deg, atol=1e-9)


def test_streaming_writer_flushes_within_a_second(tmp_path, monkeypatch):
    clock = FakeClock(now=1000.0)
    monkeypatch.setattr(rec.time, "monotonic", clock)
    path = tmp_path / "s.csv"
    with RecordingWriter(path, _meta(), ["t", "pos", "current", "torque_cmd_nm"]) as w:
        assert w.partial_path == tmp_path / "s.csv.partial" and not path.exists()
        w.append([0.0, 0.0, 0.1, 1.0])
        w.append({"t": 0.001, "pos": 0.1, "current": 0.2, "torque_cmd_nm": 2.0})
        clock.now += 0.5
        w.append_rows([[0.002, 0.2, 0.3, 3.0], [0.003, 0.3, 0.4, 4.0]])
        clock.now += 0.6  # a second has passed since the last flush: this append reaches the file
        w.append([0.004, 0.4, 0.5, 5.0])
        # what a crash now would leave: everything up to the last second, readable
        on_disk = read_recording(w.partial_path)
        assert len(on_disk) == 5 and list(on_disk.extra_channels) == ["torque_cmd_nm"]
        w.append([0.005, 0.5, 0.6, 6.0])
        assert w.rows_written == 6
    assert len(read_recording(path)) == 6
    assert not w.partial_path.exists()  # renamed to the final name on close


def _data_lines(path) -> int:
    """The lines on the disk below the metadata (the header and whole rows); 0 before the file."""
    if not path.exists():
        return 0
    return sum(1 for line in path.read_text().splitlines(keepends=True)
               if line.endswith("\n") and not line.startswith("#"))


def test_rows_reach_the_disk_on_time_when_appends_stop(tmp_path):
    """Rows appended and then nothing more: they are on the disk within the flush interval,
    not held until a next append that never comes."""
    w = RecordingWriter(tmp_path / "quiet.csv", _meta(), ["t", "pos", "current"])
    try:
        w.append_rows([[i / 1000, 0.0, 0.0] for i in range(7)])
        deadline = rec.time.monotonic() + 10 * w.FLUSH_INTERVAL_S
        while rec.time.monotonic() < deadline:
            if _data_lines(w.partial_path) >= 1 + 7:  # header, rows
                break
            rec.time.sleep(0.05)
        assert len(read_recording(w.partial_path)) == 7
    finally:
        w.close()


def test_a_killed_recording_keeps_its_rows_in_the_partial_file(tmp_path):
    """The process is killed within 5 s of its last append, without closing: the 7 rows are on
    the disk, readable."""
    path = tmp_path / "killed.csv"
    script = (
        "import sys, time\n"
        "from fha_studio.recording import RecordingMetadata, RecordingWriter\n"
        "meta = RecordingMetadata('FHA-25C-50-US250', 1.5, sample_rate_hz=1000.0)\n"
        "w = RecordingWriter(sys.argv[1], meta)\n"
        "w.append_rows([[i / 1000, i * 0.1, 0.5] for i in range(7)])\n"
        "print('appended', flush=True)\n"
        "time.sleep(60)\n"
    )
    partial = tmp_path / "killed.csv.partial"
    with Child.python("-c", script, path, text=True) as proc:
        assert proc.first_line("the recording writer") == "appended"
        # killed within 5 s of the append, as soon as the rows are seen there (they cannot leave)
        deadline = rec.time.monotonic() + 5.0
        while rec.time.monotonic() < deadline and _data_lines(partial) < 1 + 7:
            rec.time.sleep(0.05)
        proc.kill()
    assert not path.exists()  # never renamed: it does not look complete
    on_disk = read_recording(partial)
    assert len(on_disk) == 7


def _fifo(folder):
    """A FIFO stands for a device such as /dev/full as a target: were a writer ever to rename
    over it, only the test's own folder would suffer."""
    import os

    os.mkfifo(folder / "device")
    return folder / "device"


def test_writer_refuses_what_cannot_be_a_file_before_any_row(tmp_path):
    (tmp_path / "afile").write_text("x")
    for target, words in ((tmp_path / "afile" / "r.csv", "not a directory"),
                          (_fifo(tmp_path), "not a regular file"),
                          (tmp_path / ("n" * 300 + ".csv"), "too long")):
        with pytest.raises(rec.FileProblem, match=words):
            RecordingWriter(target, _meta())
    with pytest.raises(RecordingError, match="plausible range"):
        RecordingWriter(tmp_path / "i.csv", _meta(load_inertia_kgm2=1e30))
    assert not list(tmp_path.glob("i.csv*"))


def test_a_time_column_in_milliseconds_contradicts_the_sample_rate():
    text = GOOD.replace("0.001,", "1,").replace("0.002,", "2,")
    with pytest.raises(RecordingError) as err:
        parse_recording(text, source="ms.csv")
    assert err.value.field == "sample_rate_hz" and err.value.line == 5
    message = str(err.value)
    assert "1000" in message and "0.001 s" in message and "steps by 1 s" in message


def test_only_regular_files_are_read_and_reading_is_bounded(tmp_path, monkeypatch):
    import os

    fifo = tmp_path / "fifo.csv"
    os.mkfifo(fifo)
    (tmp_path / "afile").write_text("x")
    for path, words in ((fifo, "FIFO"), ("/dev/zero", "character device"), (tmp_path, "directory"),
                        (tmp_path / "afile" / "r.csv", "not a directory"),
                        (tmp_path / ("n" * 300), "too long"), ("/proc/self/mem", "cannot be read")):
        with pytest.raises(RecordingError, match=words):
            read_recording(path)
    monkeypatch.setattr(rec, "MAX_RECORDING_BYTES", 100)
    (tmp_path / "big.csv").write_text(GOOD * 3)
    with pytest.raises(RecordingError, match="more than the 100 bytes"):
        read_recording(tmp_path / "big.csv")


def test_writer_refuses_what_the_reader_would_refuse(tmp_path):
    with RecordingWriter(tmp_path / "w.csv", _meta()) as w:
        w.append([0.0, 0.0, 0.0])
        with pytest.raises(ValueError, match="time must increase"):
            w.append([0.0, 1.0, 1.0])
        with pytest.raises(ValueError, match="'current' is not finite"):
            w.append([1.0, 1.0, float("nan")])
        with pytest.raises(ValueError, match="3 values"):
            w.append([1.0, 1.0])
    with pytest.raises(RecordingError, match="required column 'pos'"):
        RecordingWriter(tmp_path / "x.csv", _meta(), ["t", "current"])
    assert not (tmp_path / "x.csv").exists()
    # without current the file is an fha-recording/2 one (tests below), not refused


def test_make_recording_checks_arrays():
    with pytest.raises(RecordingError, match="time does not increase"):
        make_recording(_meta(), t=[0, 0], pos=[0, 0], current=[0, 0])
    with pytest.raises(RecordingError, match="'current'"):
        make_recording(_meta(), t=[0, 1], pos=[0, 0], current=[0, np.nan])


# ----------------------------------------------------------------------- fha-recording/2 (bench)

V2 = """\
# format: fha-recording/2
# actuator: FHA-25C-50-US250
# sample_rate_hz: 1000
t,pos,cmd_pos,vel,in_pos
0,0,0,0,1
0.001,0.01,0.02,1.5,0
0.002,0.03,0.04,2.5,0
"""


def test_a_version_2_recording_may_lack_current_and_load_inertia():
    r = parse_recording(V2)
    assert not r.has_current and r.metadata.load_inertia_kgm2 is None
    assert list(r.in_pos) == [1, 0, 0] and r.vel_rpm is not None
    with pytest.raises(RecordingError, match="no current column"):
        _ = r.current_a


def test_a_version_1_recording_still_needs_current_and_load_inertia():
    with pytest.raises(RecordingError, match="required column 'current'"):
        parse_recording(V2.replace("fha-recording/2", "fha-recording/1").replace(
            "# sample_rate_hz", "# load_inertia_kgm2: 1\n# sample_rate_hz"))
    with pytest.raises(RecordingError, match="missing metadata '# load_inertia_kgm2"):
        parse_recording(GOOD.replace("# load_inertia_kgm2: 1.5\n", ""))
    assert parse_recording(GOOD).metadata.load_inertia_kgm2 == 1.5


def test_the_writer_writes_version_1_when_it_can_and_version_2_without_current(tmp_path):
    t = np.array([0.0, 0.001, 0.002])
    with_current = make_recording(_meta(), t=t, pos=t, current=t)
    write_recording(tmp_path / "a.csv", with_current)
    assert (tmp_path / "a.csv").read_text().startswith("# format: fha-recording/1\n")
    bench = make_recording(_meta(load_inertia_kgm2=None), t=t, pos=t, in_pos=[1, 1, 0])
    write_recording(tmp_path / "b.csv", bench)
    text = (tmp_path / "b.csv").read_text()
    assert text.startswith("# format: fha-recording/2\n") and "load_inertia" not in text
    back = read_recording(tmp_path / "b.csv")
    assert not back.has_current and list(back.in_pos) == [1, 1, 0]


def test_the_model_check_reads_a_recording_without_current_on_its_declared_load():
    """A recording without current is read through the closed loop (it used to be refused for
    having no current column); its torques rest on the declared inertia, so the load must be declared."""
    from fha_studio.logic.modelcheck import ModelCheckError
    from fha_studio.logic.modelcheck.axis import declared_axis

    with pytest.raises(ModelCheckError, match="declares no load inertia"):
        declared_axis(parse_recording(V2))
    declared = V2.replace("# sample_rate_hz", "# load_inertia_kgm2: 1.5\n# sample_rate_hz")
    assert declared_axis(parse_recording(declared)).nominal_inertia_kgm2 > 1.5
