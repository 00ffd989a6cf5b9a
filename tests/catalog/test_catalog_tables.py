"""The catalogue tables load, and the cross-checks the FHA-C manual itself gives hold."""

from __future__ import annotations

import pytest
from catalog_rounding import KGF_N, RAD_PER_ARCMIN, agree_within_rounding, half_unit

from fha_studio.catalog import discrepancies, get_actuator
from fha_studio.catalog import tables as t
from fha_studio.paths import resources_dir

FRAME_RATIO = [(f, r) for f in t.FRAMES for r in t.RATIOS]
KGF_CM_S2 = KGF_N / 100  # kg·m² per kgf·cm·s²


def test_every_table_loads_with_every_frame_and_ratio():
    for encoder in t.ENCODERS:
        for frame in t.FRAMES:
            spec = t.spec_table(encoder, frame)
            assert len(spec.max_torque_nm) == 3
            assert set(spec.torque_constant_nm_per_a_by_voltage) == {200, 100}
    for frame in t.FRAMES:
        t.torsional_stiffness_table(frame)
        t.moment_stiffness_table(frame)
        t.allowable_inertia_table(frame)
        t.continuous_table(frame)
        t.brake_table(frame)
    assert len(t.windup_table().torque_nm) == 12
    assert [o.code for o in t.option_table()] == ["A", "B", "L", "C", "K", "W", "D", "F5", "E"]
    assert len(t.combination_table()) == 16
    assert len(t.discrepancies()) > 10
    names = sorted(p.stem for p in resources_dir().joinpath("catalog").glob("*.toml"))
    assert names == [
        "ac100v",
        "accuracy",
        "brake",
        "cables",
        "discrepancies",
        "mechanical",
        "options",
        "selection",
        "sensors",
        "specs",
        "stiffness",
    ]
    for name in names:
        assert t.load_toml(name)
    t.cable_tables()
    t.environment()
    t.position_sensors()
    for frame in t.ac100v_frames():
        t.ac100v_table(frame)
    for encoder in t.ENCODERS:
        t.encoder_resolution_table(encoder)


def test_bad_table_shape_is_reported_with_where():
    with pytest.raises(t.CatalogDataError, match="somewhere"):
        t._per_ratio([1, 2], "somewhere")


def test_incremental_and_absolute_tables_agree_except_inertia_mass_and_encoder():
    for frame in t.FRAMES:
        inc, ab = t.spec_table("incremental", frame), t.spec_table("absolute", frame)
        for name in inc.__dataclass_fields__:
            if name in {
                "encoder",
                "section",
                "encoder_code",
                "motor_encoder_ppr",
                "quadrature_factor",
                "inertia_kgm2",
                "inertia_kgf_cm_s2",
                "output_resolution_ppr",
                "mass_kg",
            }:
                continue
            assert getattr(inc, name) == getattr(ab, name), (frame, name)
        assert ab.mass_kg > inc.mass_kg


@pytest.mark.parametrize("encoder", t.ENCODERS)
def test_output_resolution_is_motor_pulses_times_quadrature_times_ratio(encoder):
    # 1-4-1 note 3 / 1-8: incremental 2500 x 4 x ratio; absolute 8192 x ratio (no quadrature).
    for frame in t.FRAMES:
        spec = t.spec_table(encoder, frame)
        factor = 4 if encoder == "incremental" else 1
        assert spec.quadrature_factor == factor
        for ratio, ppr in zip(t.RATIOS, spec.output_resolution_ppr, strict=True):
            assert ppr == spec.motor_encoder_ppr * factor * ratio


def test_resolvable_angle_matches_1_8():
    printed = {"incremental": (2.6, 1.3, 0.8), "absolute": (3.2, 1.6, 1.0)}
    for encoder, angles in printed.items():
        code = "US250" if encoder == "incremental" else "S248"
        for ratio, angle in zip(t.RATIOS, angles, strict=True):
            a = get_actuator(f"FHA-25C-{ratio}-{code}")
            assert abs(a.resolvable_angle_arcsec - angle) <= half_unit(angle)


@pytest.mark.parametrize(("frame", "ratio"), FRAME_RATIO)
def test_windup_table_reproduced_from_k1_k3_t1_t2_theta_within_printed_rounding(frame, ratio, known_ids):
    """Torque at 2/4/6 arc-min from the 1-9-2 piecewise formula (printed K1..K3, T1, T2, theta1, theta2).

    Tolerance: the relative rounding of the spring rate of the region reached (K printed to two
    figures, e.g. 1.3e4 -> +-3.8 %) plus the rounding of the printed torque. The one cell outside it
    (FHA-32C-100/160 at 2 arc-min) is recorded in discrepancies.toml.
    """
    s = get_actuator(f"FHA-{frame}-{ratio}-US250").stiffness
    table = t.windup_table()
    for arcmin, printed in zip(table.windup_arcmin, table.torque_nm[(frame, ratio)], strict=True):
        phi = arcmin * RAD_PER_ARCMIN
        k = (
            s.k1_nm_per_rad
            if phi <= s.theta1_rad
            else s.k2_nm_per_rad
            if phi <= s.theta2_rad
            else s.k3_nm_per_rad
        )
        tol = half_unit(k) / k + half_unit(printed) / printed
        calc = s.torque_nm(phi)
        if frame == "32C" and ratio in (100, 160) and arcmin == 2:
            assert "windup-32c-100-2arcmin" in known_ids
            assert abs(calc - printed) / printed > tol  # still disagrees: the record is needed
            continue
        assert abs(calc - printed) / printed <= tol, (arcmin, calc, printed, tol)


@pytest.mark.parametrize(("frame", "ratio"), FRAME_RATIO)
def test_theta_follows_t_over_k_within_rounding(frame, ratio):
    s = get_actuator(f"FHA-{frame}-{ratio}-US250").stiffness
    # theta1 = T1/K1: the widest quotient the rounded T1 and K1 allow.
    lo = (s.t1_nm - half_unit(s.t1_nm)) / (s.k1_nm_per_rad + half_unit(s.k1_nm_per_rad))
    hi = (s.t1_nm + half_unit(s.t1_nm)) / (s.k1_nm_per_rad - half_unit(s.k1_nm_per_rad))
    ok1 = lo - half_unit(s.theta1_rad) <= s.theta1_rad <= hi + half_unit(s.theta1_rad)
    # FHA-17C-100: 7.0/1.3e4 = 5.4e-4 looks far from 5.1e-4, but K1 = 1.35e4 and theta1 = 5.149e-4 meet.
    assert ok1, (s.theta1_rad, lo, hi)
    # theta2 = theta1 + (T2 - T1)/K2, to 4 % (two-figure K2).
    theta2 = s.theta1_rad + (s.t2_nm - s.t1_nm) / s.k2_nm_per_rad
    assert s.theta2_rad == pytest.approx(theta2, rel=0.04)


def test_stiffness_kgf_columns_agree_with_si_columns(known_ids):
    per_arcmin = 1 / (KGF_N / RAD_PER_ARCMIN)  # N·m/rad -> kgf·m/arc-min is x this
    exceptions = {("32C", 50, "k1"), ("32C", 50, "theta2")}
    assert {"k1-32c-50-kgf", "theta2-32c-50-arcmin"} <= known_ids
    for frame in t.FRAMES:
        row = t.torsional_stiffness_table(frame)
        assert agree_within_rounding(row.t1_nm, row.t1_kgf_m, KGF_N)
        assert agree_within_rounding(row.t2_nm, row.t2_kgf_m, KGF_N)
        for i, ratio in enumerate(t.RATIOS):
            for k in ("k1", "k2", "k3"):
                si = getattr(row, f"{k}_nm_per_rad")[i]
                kgf = getattr(row, f"{k}_kgf_m_per_arcmin")[i]
                ok = agree_within_rounding(si, kgf, 1 / per_arcmin)
                assert ok != ((frame, ratio, k) in exceptions), (frame, ratio, k, si, kgf)
            for th in ("theta1", "theta2"):
                rad = getattr(row, f"{th}_rad")[i]
                arcmin = getattr(row, f"{th}_arcmin")[i]
                ok = agree_within_rounding(rad, arcmin, RAD_PER_ARCMIN)
                assert ok != ((frame, ratio, th) in exceptions), (frame, ratio, th, rad, arcmin)
        m = t.moment_stiffness_table(frame)
        assert agree_within_rounding(m.nm_per_rad, m.kgf_m_per_rad, KGF_N)
        assert agree_within_rounding(m.nm_per_rad, m.kgf_m_per_arcmin, 1 / per_arcmin)
        assert m.nm_per_rad == t.spec_table("incremental", frame).moment_stiffness_nm_per_rad


def test_inertia_kgf_columns_agree_with_si_columns(known_ids):
    for frame in t.FRAMES:
        for encoder in t.ENCODERS:
            spec = t.spec_table(encoder, frame)
            for si, kgf in zip(spec.inertia_kgm2, spec.inertia_kgf_cm_s2, strict=True):
                assert agree_within_rounding(si, kgf, KGF_CM_S2), (frame, encoder, si, kgf)
        allow = t.allowable_inertia_table(frame)
        for ratio, si, kgf in zip(
            t.RATIOS, allow.allowable_inertia_kgm2, allow.allowable_inertia_kgf_cm_s2, strict=True
        ):
            recorded = (frame, ratio) == ("17C", 50) and "allowable-inertia-17c-50-kgf" in known_ids
            assert agree_within_rounding(si, kgf, KGF_CM_S2) != recorded, (frame, si, kgf)
        assert allow.actuator_inertia_kgm2 == t.spec_table("incremental", frame).inertia_kgm2
        assert allow.max_speed_rpm == t.spec_table("incremental", frame).max_speed_rpm
        brake = t.brake_table(frame)
        for si, kgf in zip(brake.inertia_kgm2, brake.inertia_kgf_cm_s2, strict=True):
            assert agree_within_rounding(si, kgf, KGF_CM_S2), (frame, si, kgf)
        for si, kgf in zip(brake.holding_torque_nm, brake.holding_torque_kgf_m, strict=True):
            assert agree_within_rounding(si, kgf, KGF_N), (frame, si, kgf)


def test_brake_adds_inertia_and_mass():
    for frame in t.FRAMES:
        brake, inc = t.brake_table(frame), t.spec_table("incremental", frame)
        assert brake.mass_kg > inc.mass_kg
        assert all(b > a for b, a in zip(brake.inertia_kgm2, inc.inertia_kgm2, strict=True))
        assert brake.holding_current_a < brake.activating_current_a


def test_bearing_table_matches_the_specification_rows():
    for frame in t.FRAMES:
        spec = t.spec_table("incremental", frame)
        b = get_actuator(f"FHA-{frame}-50-US250").bearing
        assert b.allowable_radial_load_n == pytest.approx(spec.allowable_radial_load_kn * 1000, rel=0.02)
        assert b.allowable_axial_load_n == pytest.approx(spec.allowable_axial_load_kn * 1000)
        assert b.allowable_torsional_moment_nm == spec.allowable_torsional_moment_nm
        assert b.basic_static_load_rating_n > b.basic_dynamic_load_rating_n


def test_tightening_kgf_cm_agrees_with_n_m():
    tight = t.load_toml("mechanical")["tightening"]
    for part in ("output_flange", "mounting_flange"):
        for frame in t.FRAMES:
            nm, kgf_cm = tight[part]["torque_nm"][frame], tight[part]["torque_kgf_cm"][frame]
            assert agree_within_rounding(nm, kgf_cm, KGF_N / 100), (part, frame)


def test_specs_100v_rows_are_the_200v_winding_halved():
    # Why the 1-4 100 V rows are used (ac100v-choice): KT and EMF halve, current doubles, R and L quarter.
    for encoder in t.ENCODERS:
        for frame in t.FRAMES:
            s = t.spec_table(encoder, frame)
            for v200, v100 in zip(
                s.torque_constant_nm_per_a_by_voltage[200],
                s.torque_constant_nm_per_a_by_voltage[100],
                strict=True,
            ):
                assert v100 == pytest.approx(v200 / 2, rel=0.1)
            for v200, v100 in zip(
                s.max_current_a_by_voltage[200], s.max_current_a_by_voltage[100], strict=True
            ):
                assert v100 == pytest.approx(v200 * 2, rel=0.1)
            assert s.phase_resistance_ohm_by_voltage[100] == pytest.approx(
                s.phase_resistance_ohm_by_voltage[200] / 4, rel=0.05
            )
            assert s.phase_inductance_mh_by_voltage[100] == pytest.approx(
                s.phase_inductance_mh_by_voltage[200] / 4, rel=0.05
            )


def test_every_discrepancy_has_used_printed_and_reason():
    ids = [d.id for d in discrepancies()]
    assert len(ids) == len(set(ids))
    for d in discrepancies():
        assert d.printed and d.reason and d.section
        if d.ratios is not None:
            assert len(d.used) == len(d.ratios)
            assert set(d.ratios) <= set(t.RATIOS)
        assert d.frame in (None, *t.FRAMES)
        assert d.encoder in (None, *t.ENCODERS)


def _codes_for(d):
    for encoder, enc_code in (("incremental", "US250"), ("absolute", "S248")):
        if d.encoder not in (None, encoder):
            continue
        for frame in t.FRAMES if d.frame is None else (d.frame,):
            for ratio in t.RATIOS if d.ratios is None else d.ratios:
                for volt in (200, 100):
                    if d.supply_voltage not in (None, volt) or (volt == 100 and frame == "40C"):
                        continue
                    yield f"FHA-{frame}-{ratio}-{enc_code}" + ("-A" if volt == 100 else ""), ratio


def test_the_used_value_of_every_discrepancy_is_what_get_actuator_gives():
    checked = 0
    for d in discrepancies():
        for code, ratio in _codes_for(d):
            a = get_actuator(code)
            obj, _, attr = d.quantity.rpartition(".")
            target = getattr(a, obj, None) if obj else a
            if target is None or not hasattr(target, attr):
                continue  # a table-only quantity ("1:60", the wind-up table, 4-1's kgf column)
            assert getattr(target, attr) == d.used_for(ratio), (d.id, code)
            assert any(d.reason in n for n in a.notes), (d.id, code)
            checked += 1
    assert checked > 50
