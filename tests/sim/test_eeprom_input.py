"""The simulated drive's EEPROM file as input: refused whole, naming the file, before the drive runs."""

from __future__ import annotations

import json
import os

import pytest

from fha_studio.hardware.sim import EepromError
from fha_studio.hardware.sim.eeprom import EepromFile


def _saved_image(make_drive, path) -> dict:
    make_drive(eeprom=str(path)).close()
    return json.loads(path.read_text())


@pytest.mark.parametrize(
    ("change", "words"),
    [
        (lambda d: d["encoder"].update(mechanical_angle_rad=1e308), "encoder.mechanical_angle_rad"),
        (lambda d: d["encoder"].update(absolute_zero_rad="x"), "encoder.absolute_zero_rad"),
        (lambda d: d.update(alarm_history=[{"code": 51, "seconds": 1e308, "time_utc": "x"}]),
         "alarm_history[0].seconds"),
        (lambda d: d.update(alarm_history=[1]), "alarm_history[0] must be a table"),
        (lambda d: d.update(parameters={"tune": [1]}), "parameters.tune must be a table"),
        (lambda d: d["parameters"]["tune"].update(in_position_range=1.5), "must be a whole number"),
    ],
)
def test_an_implausible_eeprom_is_refused_before_the_drive_runs(make_drive, tmp_path, change, words):
    path = tmp_path / "e.json"
    doc = _saved_image(make_drive, path)
    change(doc)
    path.write_text(json.dumps(doc))
    with pytest.raises(EepromError) as err:
        make_drive(eeprom=str(path))
    assert str(path) in str(err.value) and words in str(err.value)


def test_a_binary_or_special_eeprom_file_is_refused_naming_it(make_drive, tmp_path):
    binary = tmp_path / "bin.json"
    binary.write_bytes(b"\x00\xff\xfe" * 100)
    os.mkfifo(tmp_path / "fifo.json")
    for path, words in ((binary, "not UTF-8"), (tmp_path / "fifo.json", "FIFO"),
                        ("/dev/zero", "character device")):
        with pytest.raises(EepromError, match=words):
            make_drive(eeprom=str(path))


def test_temporary_files_left_by_a_killed_save_are_removed_at_the_next_start(make_drive, tmp_path):
    path = tmp_path / "drive.json"
    make_drive(eeprom=str(path)).close()
    left = [tmp_path / f".drive.json.a{i}b.tmp" for i in range(5)] + [tmp_path / "drive.json.x_y.tmp"]
    for leftover in left:
        leftover.write_text('{"format": "fha-sim-eeprom/1"')  # cut mid-save
    other = tmp_path / "other.json.abc.tmp"
    other.write_text("not ours")
    make_drive(eeprom=str(path)).close()
    assert not any(p.exists() for p in left)
    assert other.exists() and path.exists()


def test_a_save_that_fails_leaves_the_image_whole(tmp_path):
    (tmp_path / "afile").write_text("")
    image = EepromFile(tmp_path / "afile" / "e.json")
    with pytest.raises(EepromError, match="not a directory"):
        image.save({"parameters": {}})
