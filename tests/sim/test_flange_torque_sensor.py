"""The simulated drive's torque sensor between the output flange and the load: monitor item 111 and
the recording's ``torque`` column carry what the load takes (its inertia x its acceleration + its
own torques), + = the flange driving the load CW whatever parameter 8 says; Kt x current minus it
is what the gear side takes (its friction)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from fha_studio.hardware.parameters import MonitorItem
from fha_studio.recording import read_recording
from tests.support.recorded_moves import record_moves

LOAD_KGM2 = 1.5
GRAVITY_NM, PHASE_DEG, FRICTION_NM = 20.0, 30.0, 5.0


def _drive(make_drive, **options):
    effects = {"gravity_load": {"amplitude_nm": GRAVITY_NM, "phase_deg": PHASE_DEG},
               "coulomb_friction": {"torque_nm": FRICTION_NM}}
    return make_drive(load_inertia_kgm2=LOAD_KGM2, effects=effects, **options)


def test_monitor_111_reads_the_load_the_flange_holds_in_the_physical_sense(make_drive):
    drive = _drive(make_drive)
    drive.set_servo(True)
    drive.advance(0.5)
    x = drive.axis.load_pos_rad
    holding = GRAVITY_NM * math.sin(x + math.radians(PHASE_DEG))
    # at rest the flange holds the unbalance alone (0.01 N m steps on the wire)
    assert drive.monitor(MonitorItem.FLANGE_TORQUE) / 100.0 == pytest.approx(holding, abs=0.05)


def test_the_recording_carries_the_sensors_torque_column(make_drive, tmp_path):
    drive = _drive(make_drive)
    path = tmp_path / "sensor.csv"
    record_moves(drive, path, [(90, 30), (-60, 15)], torque_sensor=True)
    rec = read_recording(path)
    torque = rec.channels["torque"]
    x = np.radians(rec.channels["load_pos"])
    t = rec.channels["t"]
    vel = np.gradient(x, t)
    acc = np.gradient(vel, t)
    # least squares: torque = J acc + a sin x + b cos x; the sensor gives the load's inertia and
    # the unbalance (the 1 kHz samples are instantaneous, the acceleration a central difference:
    # a few per cent is what the sampling leaves)
    basis = np.column_stack([acc, np.sin(x), np.cos(x)])
    (j, a, b), *_ = np.linalg.lstsq(basis, torque, rcond=None)
    assert j == pytest.approx(LOAD_KGM2, rel=0.05)
    assert math.hypot(a, b) == pytest.approx(GRAVITY_NM, rel=0.02)
    assert math.degrees(math.atan2(b, a)) == pytest.approx(PHASE_DEG, abs=2.0)
    # what the gear side takes while turning steadily: its friction, by the sense of motion
    kt = drive.model.torque_constant_nm_per_a
    gear = kt * rec.channels["current"] - torque - drive.model.actuator_inertia_kgm2 * acc
    steady = np.abs(acc) < 0.5
    assert np.median(gear[steady & (vel > 0.5)]) == pytest.approx(FRICTION_NM, rel=0.1)
    assert np.median(gear[steady & (vel < -0.5)]) == pytest.approx(-FRICTION_NM, rel=0.1)
    # without asking, the recording has no sensor
    drive.start_recording(tmp_path / "plain.csv", 1000.0)
    drive.advance(0.05)
    drive.stop_recording()
    assert "torque" not in read_recording(tmp_path / "plain.csv").channels


def test_the_sensor_does_not_follow_the_rotary_direction(make_drive):
    readings = []
    for direction in (0, 1):
        drive = _drive(make_drive)
        drive.write_parameter("system", 8, direction)  # on the front panel, then a power cycle
        drive.power_cycle()
        drive.set_servo(True)
        drive.advance(0.3)
        readings.append((drive.monitor(MonitorItem.FLANGE_TORQUE), drive.monitor(MonitorItem.OUTPUT_TORQUE)))
    (sensor0, kt_i0), (sensor1, kt_i1) = readings
    assert sensor0 == pytest.approx(sensor1, abs=2) and abs(sensor0) > 500
    assert kt_i0 == pytest.approx(-kt_i1, abs=2)  # item 108 counts in the command sense
