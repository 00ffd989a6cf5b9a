"""The parameter file: round trip, refusal of corrupt/foreign files with the line, partial mapping."""

from __future__ import annotations

import datetime as dt

import pytest

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.paramfile import ParameterFileError, dump_parameter_file, read_parameter_file


@pytest.fixture(scope="module")
def model():
    return load_parameter_model("HA-655")


def _values(model):
    return {(i.mode, i.number): i.default for i in model if i.mode in ("tune", "system") and i.writable}


def test_round_trip_keeps_every_value_and_the_header(model):
    values = _values(model)
    values[("system", 8)] = 1
    text = dump_parameter_file(
        model,
        values,
        "FHA-25C-50-US250",
        "HA-655-2-200",
        saved=dt.datetime(2026, 11, 25, 17, 0, tzinfo=dt.UTC),
    )
    loaded = read_parameter_file(text, model)
    assert loaded.values == values
    assert loaded.actuator == "FHA-25C-50-US250"
    assert loaded.driver_model == "HA-655-2-200"
    assert loaded.saved.startswith("2026-11-25T17:00")
    assert not loaded.not_mapped
    assert "rotary_direction" in text and "reversed" in text  # the meaning is beside the value


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ('format = "fha-parameters/1"\n[system]\nrotary_direction = = 1\n', 3, "not valid TOML"),
        ('title = "something else"\n', 1, "not an FHA Studio parameter file"),
        ('# x\n\nformat = "other/2"\n', 3, "not an FHA Studio parameter file"),
        ('format = "fha-parameters/1"\n[system]\nrotary_direction = "CW"\n', 3, "not an integer"),
        ('format = "fha-parameters/1"\n\n[motor]\nx = 1\n', 3, "unknown table"),
    ],
)
def test_corrupt_or_foreign_file_is_refused_whole_with_the_line(model, text, line, words):
    with pytest.raises(ParameterFileError) as err:
        read_parameter_file(text, model, name="p.toml")
    assert f"p.toml: line {line}:" in str(err.value)
    assert words in str(err.value)


def test_file_for_another_driver_loads_what_fits_and_lists_the_rest(model):
    text = (
        'format = "fha-parameters/1"\nactuator = "FHA-40C-160-S248"\ndriver_model = "HA-675-4A-200"\n'
        "[tune]\nin_position_range = 20\nnotch_filter = 3\n"
        "[system]\nrotary_direction = 1\nelectronic_gear_numerator = 500\n"
    )
    loaded = read_parameter_file(text, model)
    assert loaded.values == {("tune", 4): 20, ("system", 8): 1}
    assert len(loaded.not_mapped) == 2
    assert any("notch_filter" in m and "line 6" in m for m in loaded.not_mapped)
    assert any("electronic_gear_numerator" in m and "outside" in m for m in loaded.not_mapped)


@pytest.mark.parametrize(
    ("text", "line", "words"),
    [
        ('format = "fha-parameters/1"\ntune = 5\n', 2, "tune = 5: tune must be the table [tune]"),
        ('format = "fha-parameters/1"\ntune = [1, 2]\n', 2, "tune = a list [1, 2]: tune must be the table"),
        ('format = "fha-parameters/1"\n\nsystem = "x"\n', 3, 'system = "x": system must be the table'),
        ('format = "fha-parameters/1"\nactuator = 5\n', 2, "actuator must be text"),
        ('format = "fha-parameters/1"\ncolour = "red"\n', 2, "unknown key \"colour\""),
        # a dotted key is reported at its own line, not "line None"
        ('format = "fha-parameters/1"\n\n\ntune.in_position_range = "x"\n', 4, "not an integer"),
        ('format = "fha-parameters/1"\n[system]\n"rotary_direction" = 1.5\n', 3, "not an integer"),
        ('format = "fha-parameters/1"\n[tune]\nin_position_range.x = 1\n', 3, "a table is not an integer"),
    ],
)
def test_wrong_shapes_are_refused_with_their_line(model, text, line, words):
    with pytest.raises(ParameterFileError) as err:
        read_parameter_file(text, model, name="p.toml")
    message = str(err.value)
    assert message.startswith(f"p.toml: line {line}: ")
    assert words in message
    assert "None" not in message and "\n" not in message


def test_a_file_cut_at_a_line_boundary_lists_what_is_missing(model):
    values = _values(model)
    text = dump_parameter_file(model, values, "FHA-25C-50-US250", "HA-655-2-200")
    lines = text.splitlines(keepends=True)
    cut = "".join(lines[: len(lines) // 2])
    loaded = read_parameter_file(cut, model)
    assert 0 < len(loaded.values) < len(values)
    assert len(loaded.missing) == len(values) - len(loaded.values)
    absent = [model.item(mode, number).key for (mode, number) in values
              if (mode, number) not in loaded.values]
    for key in absent:
        assert any(f".{key} (" in line and "not in the file" in line for line in loaded.missing)
    assert not read_parameter_file(text, model).missing


def test_a_byte_order_mark_is_accepted(model):
    text = dump_parameter_file(model, _values(model), "FHA-25C-50-US250", "HA-655-2-200")
    assert read_parameter_file("\ufeff" + text, model).values == _values(model)


def test_load_parameter_file_reads_only_regular_files(model, tmp_path):
    import os

    from fha_studio.logic.paramfile import load_parameter_file

    good = tmp_path / "p.toml"
    good.write_bytes(b"\xef\xbb\xbf" + dump_parameter_file(model, _values(model), "A", "B").encode())
    assert load_parameter_file(good, model).values == _values(model)
    os.mkfifo(tmp_path / "fifo.toml")
    (tmp_path / "bin.toml").write_bytes(b"format = \xff\xfe\n")
    for path, words in ((tmp_path / "fifo.toml", "FIFO"), ("/dev/zero", "character device"),
                        (good / "x.toml", "not a directory"), (tmp_path / "bin.toml", "line 1: not UTF-8")):
        with pytest.raises(ParameterFileError, match=words):
            load_parameter_file(path, model)
