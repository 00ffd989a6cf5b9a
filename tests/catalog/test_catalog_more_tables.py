"""4-1 (AC100V as printed), 1-7, 1-8, 1-14 / 4-2-2 cables, 1-3 combinations, 3-3-1 environment."""

from __future__ import annotations

import pytest
from catalog_rounding import KGF_N, agree_within_rounding, half_unit

from fha_studio.catalog import discrepancies, environment, get_actuator
from fha_studio.catalog import tables as t

ELECTRICAL = ("torque_constant_nm_per_a", "max_current_a", "emf_constant_v_per_rpm")
PER_FRAME_ELECTRICAL = ("phase_resistance_ohm", "phase_inductance_mh")


def test_ac100v_table_covers_17c_25c_32c_only():
    assert t.ac100v_frames() == ("17C", "25C", "32C")
    with pytest.raises(KeyError):
        t.ac100v_table("40C")


@pytest.mark.parametrize("frame", ["17C", "25C", "32C"])
def test_ac100v_table_equals_1_4_except_recorded_electrical_differences(frame):
    row, spec = t.ac100v_table(frame), t.spec_table("incremental", frame)
    for name in (
        "max_torque_nm",
        "max_speed_rpm",
        "inertia_kgm2",
        "inertia_kgf_cm_s2",
        "one_way_accuracy_arcsec",
        "output_resolution_ppr",
        "mass_kg",
        "allowable_radial_load_kn",
        "allowable_axial_load_kn",
        "allowable_torsional_moment_nm",
        "moment_stiffness_nm_per_rad",
    ):
        assert getattr(row, name) == getattr(spec, name), name
    recorded = {
        (d.quantity, d.frame): d
        for d in discrepancies()
        if d.supply_voltage == 100 and d.id.startswith("ac100v-") and d.frame == frame
    }
    for name in ELECTRICAL + PER_FRAME_ELECTRICAL:
        printed = getattr(row, name)
        used = getattr(spec, f"{name}_by_voltage")[100]
        if printed == used:
            assert (name, frame) not in recorded
            continue
        d = recorded[(name, frame)]  # every difference is in discrepancies.toml ...
        assert d.printed["4-1"] == (list(printed) if isinstance(printed, tuple) else [printed])
        assert d.used == (list(used) if isinstance(used, tuple) else used)  # ... with 1-4's value used


def test_ac100v_kgf_columns(known_ids):
    for frame in t.ac100v_frames():
        row = t.ac100v_table(frame)
        for si, kgf in zip(row.max_torque_nm, row.max_torque_kgf_m, strict=True):
            assert agree_within_rounding(si, kgf, KGF_N)
        for ratio, si, kgf in zip(
            t.RATIOS, row.torque_constant_nm_per_a, row.torque_constant_kgf_m_per_a, strict=True
        ):
            recorded = (frame, ratio) == ("32C", 100) and "ac100v-kt-kgf-32c-100" in known_ids
            assert agree_within_rounding(si, kgf, KGF_N) != recorded, (frame, ratio)
        assert agree_within_rounding(
            row.allowable_radial_load_kn * 1000, row.allowable_radial_load_kgf, KGF_N
        )
        assert agree_within_rounding(row.allowable_axial_load_kn * 1000, row.allowable_axial_load_kgf, KGF_N)
        assert agree_within_rounding(
            row.allowable_torsional_moment_nm, row.allowable_torsional_moment_kgf_m, KGF_N
        )
        assert agree_within_rounding(
            row.moment_stiffness_nm_per_rad, row.moment_stiffness_kgf_m_per_rad, KGF_N
        )


def test_ac100v_printed_currents_cannot_reach_max_torque_for_32c_50():
    # The reason recorded in "ac100v-choice": 4-1's FHA-32C-50 KT x Im is below TM.
    row = t.ac100v_table("32C")
    assert row.torque_constant_nm_per_a[0] * row.max_current_a[0] < row.max_torque_nm[0]
    assert get_actuator("FHA-32C-50-US250-A").friction_torque_nm > 0


def test_1_7_one_way_accuracy_equals_the_specification_rows():
    for frame in t.FRAMES:
        for encoder in t.ENCODERS:
            assert t.one_way_accuracy_table(frame) == t.spec_table(encoder, frame).one_way_accuracy_arcsec


@pytest.mark.parametrize("encoder", t.ENCODERS)
def test_1_8_encoder_resolution(encoder):
    row = t.encoder_resolution_table(encoder)
    spec = t.spec_table(encoder, "25C")
    assert row.encoder_ppr == spec.motor_encoder_ppr
    assert row.counts_per_motor_rev == spec.motor_encoder_ppr * spec.quadrature_factor
    assert row.output_resolution_ppr == spec.output_resolution_ppr
    for ratio, ppr, angle in zip(
        t.RATIOS, row.output_resolution_ppr, row.resolvable_angle_arcsec, strict=True
    ):
        assert ppr == row.counts_per_motor_rev * ratio
        assert abs(1_296_000 / ppr - angle) <= half_unit(angle)


def test_cable_tables():
    c = t.cable_tables()
    assert len(c.incremental_14_wire) == 14
    assert [lead.signal for lead in c.incremental_4_wire] == ["+5V", "0V", "SD", "/SD", "FG"]
    assert {lead.signal for lead in c.absolute} >= {"BAT+", "BAT-", "CLR", "SD", "/SD"}
    # 4-2-2 brake leads are the 1-14 motor cable with the brake option.
    assert [(x.colour, x.signal.replace("Motor phase-", "Motor-")) for x in c.motor_brake_option] == [
        (x.colour, x.signal) for x in c.brake_leads
    ]
    for table in (c.motor_standard, c.incremental_14_wire, c.incremental_4_wire, c.absolute):
        colours = [lead.colour for lead in table]
        assert len(colours) == len(set(colours))
    assert [x.signal for x in c.motor_standard if x.colour in ("Blue", "Yellow")] == ["No connection"] * 2


def test_actuator_cables_follow_the_options():
    inc = get_actuator("FHA-25C-50-US250")
    assert set(inc.cables.encoder) == {"14-wire", "4-wire"}
    assert inc.cables.connectors == {}
    braked = get_actuator("FHA-25C-50-S248-B-C")
    assert set(braked.cables.encoder) == {"absolute"}
    assert [x.signal for x in braked.cables.motor if x.colour == "Blue"] == ["Brake"]
    assert "09-0471-02-08" in braked.cables.connectors["absolute_encoder"]


def test_1_3_combinations_follow_the_drivers_naming():
    table = t.combination_table()
    for (frame, enc, volt), drivers in table.items():
        if frame == "40C" and volt == 100:
            assert drivers == ()
            continue
        assert [d.split("-")[1] for d in drivers] == ["655", "675"]
        for d in drivers:
            assert d.endswith(f"-{volt}")
            assert d.split("-")[2].endswith("A") == (enc == "S248")
        size = drivers[0].split("-")[2].rstrip("A")
        # 2 A drivers for the small frames at 200 V; 100 V FHA-25C needs the 4 A driver.
        expected = "2" if frame == "17C" or (frame == "25C" and volt == 200) else "4"
        assert size == expected, (frame, enc, volt)


def test_environment():
    e = environment()
    assert (e.service_temperature_min_c, e.service_temperature_max_c) == (0, 40)
    assert (e.storage_temperature_min_c, e.storage_temperature_max_c) == (-20, 60)
    assert e.vibration_max_m_per_s2 == 24.5 and e.impact_max_m_per_s2 == 294
    assert e.min_cable_bending_radius_m == 0.04


def test_mechanical_accuracy_and_tightening_on_the_actuator():
    a = get_actuator("FHA-40C-100-US250")
    assert a.mechanical_accuracy.axial_runout_m == pytest.approx(14e-6)
    assert a.mechanical_accuracy.parallelism_m == pytest.approx(60e-6)
    assert (a.tightening.output_flange.screw_count, a.tightening.output_flange.screw_size) == (8, "M10")
    assert a.tightening.output_flange.torque_nm == 45 and a.tightening.mounting_flange.torque_nm == 25
    assert a.tightening.output_flange.screw_hole_depth_m == pytest.approx(0.015)
    b = get_actuator("FHA-32C-50-US250")
    assert (b.tightening.output_flange.screw_count, b.tightening.mounting_flange.screw_count) == (16, 12)


def test_position_sensor_set_and_rotary_direction():
    s = t.position_sensors()
    assert s.origin_sensor.model == "EE-SX672" and s.origin_sensor.current_consumption_max_a == 0.035
    assert s.limit_switch.model == "D2JW-01K21" and s.limit_switch.count == 2
    assert s.limit_switch.electrical_life_operations < s.limit_switch.mechanical_life_operations
    rd = t.rotary_direction()
    assert [(r.value, r.default) for r in rd] == [(0, True), (1, False)]
    assert rd[0].fwd_command == "FWD rotation" and rd[1].fwd_command == "REV rotation"


def test_1_10_rotary_direction_says_where_a_fwd_command_turns():
    default = t.default_rotary_direction()
    assert default.value == 0 and default.fwd_turns_cw and default.fwd_direction == "CW"
    assert t.rotary_direction_setting(1).fwd_direction == "CCW"
    with pytest.raises(ValueError, match="0 or 1"):
        t.rotary_direction_setting(2)
