"""get_actuator, compatible_drivers and the listing helpers."""

from __future__ import annotations

import dataclasses

import pytest

from fha_studio.catalog import (
    Actuator,
    ModelCodeError,
    all_model_codes,
    compatible_drivers,
    get_actuator,
    options_allowed,
    parse_model_code,
)


def test_example_1_friction_torque_fha_25c_50():
    # 2-4-4 Example 1: JA = 0.81, TM = 150, KT = 22, Im = 7.3 -> TF = 22 x 7.3 - 150 = 10.6 N·m.
    a = get_actuator("FHA-25C-50-US250")
    assert (a.inertia_kgm2, a.max_torque_nm, a.torque_constant_nm_per_a, a.max_current_a) == (
        0.81,
        150,
        22,
        7.3,
    )
    assert a.friction_torque_nm == 10.6


@pytest.mark.parametrize("code", all_model_codes())
def test_every_model_code_resolves_consistently(code):
    a = get_actuator(code)
    assert isinstance(a, Actuator)
    assert a.model_code == code
    assert a.friction_torque_nm == pytest.approx(
        a.torque_constant_nm_per_a * a.max_current_a - a.max_torque_nm
    )
    assert a.friction_torque_nm > 0  # KT x Im must reach TM
    assert a.continuous_torque_nm < a.max_torque_nm
    assert a.continuous_speed_rpm < a.max_speed_rpm
    assert a.allowable_inertia_kgm2 > a.inertia_kgm2
    assert a.stiffness.t1_nm < a.stiffness.t2_nm
    assert a.stiffness.k1_nm_per_rad <= a.stiffness.k2_nm_per_rad <= a.stiffness.k3_nm_per_rad
    assert a.brake is None
    assert a.compatible_drivers
    assert a.supply_voltage == (100 if code.endswith("-A") else 200)


def test_fields_named_in_the_architecture_contract():
    a = get_actuator("FHA-32C-100-S248-B")
    for name in (
        "max_torque_nm",
        "max_speed_rpm",
        "torque_constant_nm_per_a",
        "max_current_a",
        "emf_constant_v_per_rpm",
        "phase_resistance_ohm",
        "phase_inductance_mh",
        "inertia_kgm2",
        "ratio",
        "motor_encoder_ppr",
        "output_resolution_ppr",
        "continuous_torque_nm",
        "continuous_speed_rpm",
        "allowable_inertia_kgm2",
        "friction_torque_nm",
        "stiffness",
        "bearing",
        "brake",
        "code",
        "model_code",
        "mass_kg",
    ):
        assert hasattr(a, name), name
    for name in (
        "t1_nm",
        "t2_nm",
        "k1_nm_per_rad",
        "k2_nm_per_rad",
        "k3_nm_per_rad",
        "theta1_rad",
        "theta2_rad",
    ):
        assert hasattr(a.stiffness, name), name
    assert a.brake.holding_torque_nm == 150
    with pytest.raises(dataclasses.FrozenInstanceError):
        a.max_torque_nm = 1  # type: ignore[misc]
    with pytest.raises(TypeError):
        a.cables.encoder["absolute"] = ()  # type: ignore[index]
    assert hash(a) == hash(get_actuator("FHA-32C-100-S248-B"))
    assert get_actuator("FHA-32C-100-S248-B") is a  # cached


def test_brake_option_takes_inertia_and_mass_from_the_brake_table():
    plain, braked = get_actuator("FHA-17C-100-US250"), get_actuator("FHA-17C-100-US250-B")
    assert (plain.inertia_kgm2, plain.mass_kg) == (0.67, 2.5)
    assert (braked.inertia_kgm2, braked.mass_kg) == (0.96, 2.9)
    assert braked.brake.holding_torque_nm == 49
    assert braked.brake.activating_current_a == 1.0
    assert braked.brake.holding_current_a == 0.15
    assert not braked.brake.estimated
    # Absolute + brake: the brake's increase over the incremental table, flagged as an estimate.
    ab = get_actuator("FHA-17C-100-S248-B")
    assert ab.brake.estimated
    assert ab.inertia_kgm2 == pytest.approx(0.74 + (0.96 - 0.67))
    assert ab.mass_kg == pytest.approx(2.9 + (2.9 - 2.5))
    assert any("estimate" in n for n in ab.notes)


def test_option_a_uses_the_100v_rows():
    a = get_actuator("FHA-32C-50-US250-A")
    assert (a.supply_voltage, a.torque_constant_nm_per_a, a.max_current_a) == (100, 13, 23)
    assert a.phase_resistance_ohm == 0.25
    assert a.compatible_drivers == ("HA-655-4-100", "HA-675-4-100")
    assert any("4-1 note 4" in n for n in a.notes)


def test_absolute_100v_torque_constant_typo_is_corrected():
    a = get_actuator("FHA-25C-100-S248-A")
    assert a.torque_constant_nm_per_a == 22
    assert any("2.2" in n for n in a.notes)


def test_fha_17c_160_max_speed_is_27():
    assert get_actuator("FHA-17C-160-US250").max_speed_rpm == 27


def test_compatible_drivers_from_1_3():
    assert compatible_drivers("FHA-17C-50-US250") == ["HA-655-2-200", "HA-675-2-200"]
    assert compatible_drivers("FHA-25C-50-US250-A") == ["HA-655-4-100", "HA-675-4-100"]
    assert compatible_drivers("FHA-40C-160-S248", 200) == ["HA-655-4A-200", "HA-675-4A-200"]
    assert compatible_drivers(parse_model_code("FHA-17C-50-S248-A"), 100) == [
        "HA-655-2A-100",
        "HA-675-2A-100",
    ]
    with pytest.raises(ValueError, match="wound for 200 V"):
        compatible_drivers("FHA-17C-50-US250", 100)
    with pytest.raises(ValueError, match="allowed 200 or 100"):
        compatible_drivers("FHA-17C-50-US250", 230)
    with pytest.raises(ModelCodeError):
        compatible_drivers("FHA-40C-50-US250-A")


def test_listing_helpers():
    codes = all_model_codes()
    assert len(codes) == 2 * 4 * 3 + 2 * 3 * 3
    assert "FHA-40C-160-S248" in codes and "FHA-40C-160-S248-A" not in codes
    assert len(all_model_codes(include_ac100v=False)) == 24
    assert options_allowed("40C") == ["B", "L", "C", "K", "W", "F5"]
    assert options_allowed("17C") == ["A", "B", "L", "C", "K", "W", "D", "F5", "E"]


def test_windup_formula_is_odd_and_inverts_inside_each_region():
    s = get_actuator("FHA-25C-100-US250").stiffness
    for torque in (10.0, 50.0, 200.0):
        phi = s.windup_rad(torque)
        assert s.windup_rad(-torque) == -phi
        assert s.torque_nm(phi) == pytest.approx(torque, rel=0.05)
    assert s.torque_nm(0.0) == 0.0


def test_as_dict_is_json_ready():
    import json

    d = get_actuator("FHA-25C-50-US250-B-L").as_dict()
    json.dumps(d)
    assert d["options"] == ["B", "L"]
    assert d["stiffness"]["k1_nm_per_rad"] == 4.7e4
    assert d["brake"]["holding_torque_nm"] == 49


def test_get_actuator_rejects_a_non_code():
    with pytest.raises(ModelCodeError, match="expected a string or ModelCode"):
        get_actuator(25)  # type: ignore[arg-type]
    with pytest.raises(ModelCodeError, match="option A"):
        get_actuator("FHA-40C-50-S248-A")


def test_a_hand_built_model_code_is_checked_like_a_parsed_one():
    from fha_studio.catalog import ModelCode

    assert get_actuator(ModelCode("25C", 50, "incremental", "US250")) is get_actuator("FHA-25C-50-US250")
    with pytest.raises(ModelCodeError, match="frame '99C'"):
        get_actuator(ModelCode("99C", 50, "incremental", "US250"))
    with pytest.raises(ModelCodeError, match="option A"):
        compatible_drivers(ModelCode("40C", 50, "incremental", "US250", frozenset({"A"})))
    with pytest.raises(ModelCodeError, match="does not match"):
        get_actuator(ModelCode("25C", 50, "absolute", "US250"))
