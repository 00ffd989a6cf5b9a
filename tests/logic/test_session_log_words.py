"""The write log reads like the front panel: mode, item number and name, values in their unit."""

from __future__ import annotations

from fha_studio.hardware.parameters import load_parameter_model
from fha_studio.logic.session_log import WriteRecord


def test_a_write_is_logged_in_the_front_panels_words_and_units():
    model = load_parameter_model()
    item = model.by_key("position_error_allowance")
    record = WriteRecord(
        time="2026-11-30T04:20:01+00:00", mode="system", number=item.number, key=item.key, name=item.name,
        old=item.to_wire(50000), new=item.to_wire(100), read_back=item.to_wire(100), verified=True,
    )
    line = record.line(item)
    assert line == "04:20:01 parameter 6, position error allowance: 50000 pulse → 100 pulse, verified"
    assert "system" not in line and "position_error_allowance" not in line
    raw = record.line()  # an item this driver's model does not have: its own numbers, still no key
    assert raw.startswith("04:20:01 parameter 6, Position error allowance: ") and "_" not in raw


def test_a_failed_write_says_so():
    model = load_parameter_model()
    item = model.by_key("rotary_direction")
    record = WriteRecord(
        time="2026-11-30T04:20:01+00:00", mode="system", number=8, key=item.key, name=item.name,
        old=0, new=1, read_back=0, verified=False, error="the servo is on",
    )
    assert record.line(item).endswith(
        "parameter 8, rotary direction: 0: FWD turns CW (seen from the flange) → "
        "1: FWD turns CCW (reversed), NOT verified (the servo is on)"
    )
