"""The driver's parameter model and alarm table, as loaded from resources/drive/."""

from __future__ import annotations

import pytest

from fha_studio.hardware import parameters as P
from fha_studio.hardware.parameters import Mode, ParameterValueError


@pytest.fixture(scope="module")
def model():
    return P.load_parameter_model("HA-655")


def test_rotary_direction_is_parameter_item_8_as_the_fha_c_manual_says(model):
    item = model.item("system", 8)
    assert item.key == "rotary_direction"
    assert item.default == 0
    assert set(item.choices) == {0, 1}
    assert "CW" in item.choices[0]
    assert item.source == "FHA-C manual 1-10"
    # only the power-cycle behaviour is this project's assumption
    assert item.assumed == ("restart_required",)
    assert not item.certain


def test_every_mode_has_the_items_the_brief_names(model):
    keys = {i.key for i in model}
    for key in (
        "rotary_direction", "in_position_range", "position_loop_gain", "speed_loop_gain",
        "speed_loop_integral_compensation", "feed_forward_gain", "control_mode",
        "command_pulse_configuration", "electronic_gear_numerator", "electronic_gear_denominator",
        "position_error_allowance", "speed_conversion_factor", "jog_speed", "jog_acceleration",
        "error_pulse_count_low", "command_pulse_high",
    ):
        assert key in keys
    assert {i.mode for i in model} == set(Mode)


def test_items_the_manual_states_are_certain_and_guesses_are_not(model):
    assert model.item("monitor", 9).certain  # command pulse low, p.87
    assert not model.item("tune", 2).certain  # Kp: item number not visible
    assert not model.by_key("jog_speed").certain
    for item in model:
        if not item.certain:
            assert item.note, item.label


def test_defaults_lie_in_range_and_monitors_are_read_only(model):
    for item in model:
        if item.mode is Mode.MONITOR:
            assert not item.writable and item.default is None
        else:
            item.check(item.default)


def test_scale_converts_between_wire_and_unit(model):
    jog = model.by_key("jog_speed")
    assert jog.to_unit(500) == pytest.approx(5.0)
    assert jog.to_wire(12.345) == 1234 or jog.to_wire(12.345) == 1235
    allowance = model.by_key("position_error_allowance")
    assert allowance.to_unit(500) == 50000
    assert model.item("monitor", 103).format(-1250) == "-12.5 r/min"


def test_check_names_the_item_and_the_range(model):
    with pytest.raises(ParameterValueError, match=r"parameter 8, rotary direction: 2 is not one of"):
        model.item("system", 8).check(2)
    outside = r"tune 0, speed loop gain \(Kv\): .* is outside 1 Hz … 500 Hz"
    with pytest.raises(ParameterValueError, match=outside):
        model.by_key("speed_loop_gain").check(0)
    with pytest.raises(ParameterValueError, match="integer"):
        model.by_key("speed_loop_gain").check(1.5)


def test_unknown_item_says_what_exists(model):
    with pytest.raises(KeyError, match="no system item 5"):
        model.item(Mode.SYSTEM, 5)
    with pytest.raises(KeyError, match="no item 'nope'"):
        model.by_key("nope")


def test_low_high_halves_round_trip():
    assert P.combine_low_high(6802, 31) == 316802
    for count in (0, 1, -1, 9999, 10000, -316802, 99999999):
        assert P.combine_low_high(*P.split_low_high(count)) == count


def test_ha675_is_the_ha655_model_all_uncertain(model):
    ha675 = P.load_parameter_model("HA-675")
    assert ha675.driver == "HA-675"
    assert [i.key for i in ha675] == [i.key for i in model]
    assert not any(i.certain for i in ha675)


def test_unknown_driver_is_refused():
    with pytest.raises(ValueError, match="unknown driver 'HA-800'"):
        P.load_parameter_model("HA-800")


def test_alarm_table_matches_the_manual():
    alarms = P.load_alarm_table()
    assert [a.code for a in alarms] == [10, 20, 21, 30, 41, 50, 51, 52, 53, 54, 55, 56, 57, 60, 70, 71, 76]
    assert {a.code for a in alarms if a.clearable} == {20, 60}
    assert alarms.get(10).alm_bits == 0b1011
    assert alarms.get(20).alm_bits == 0b0001
    assert alarms.get(54).absolute_only
    assert alarms.describe(0) == "no alarm"
    assert alarms.describe(60) == "60 Error counter overflow"
    assert "unknown" in alarms.describe(99)


def test_malformed_item_is_reported_with_file_and_item(tmp_path, monkeypatch):
    bad = tmp_path / "drive"
    bad.mkdir()
    (bad / "ha655-parameters.toml").write_text(
        'driver = "HA-655"\n[[item]]\nmode = "tune"\nnumber = 0\nkey = "k"\nname = "n"\nunit = ""\n'
        "scale = 1\nminimum = 5\nmaximum = 1\ndefault = 1\nrestart_required = false\nwritable = true\n"
        'description = ""\nsource = ""\nassumed = []\n'
    )
    monkeypatch.setattr(P, "resource", lambda *parts: tmp_path.joinpath(*parts))
    with pytest.raises(P.ParameterTableError, match=r"ha655-parameters.toml: item #1 \(tune 0 k\).*minimum"):
        P.load_parameter_model()


def test_named_monitor_items_are_the_parameter_models():
    from fha_studio.hardware.parameters import MonitorItem

    model = P.load_parameter_model()
    for item in MonitorItem:
        assert model.item("monitor", item).key == item.name.lower()
    extension = {i.number for i in model.in_mode("monitor") if i.number >= 100}
    assert extension == {int(i) for i in MonitorItem}


def test_cn2_gives_the_pins_our_sources_state_and_points_to_the_manual_for_the_rest():
    from fha_studio.hardware.parameters import load_cn2

    cn2 = load_cn2("HA-655")
    assert cn2.pins_text("speed_monitor") == "CN2-23" and cn2.pins_text("in_position") == "CN2-33"
    assert cn2.pins_text("encoder_b") == "CN2-42 to 49"
    assert cn2.pins_text("alm_c") == "CN2 pin: see the CN2 pin table in chapter 3 of the HA-655 manual"
    assert cn2.encoder_counts_up_on == "FWD command" and cn2.encoder_sense_assumed
    assert load_cn2("HA-675").signals == cn2.signals
