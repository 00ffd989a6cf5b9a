"""A hand-written context for FHA-25C-50-US250-B-L (brake, sensor set), values from the manual.

The engine tests use it so they do not depend on the catalogue; tests/procedures/test_context.py
checks that the catalogue builds the same context.
"""

from __future__ import annotations

import pytest

MOTOR_BRAKE = [
    {"color": "Red", "signal": "Motor phase-U"},
    {"color": "White", "signal": "Motor phase-V"},
    {"color": "Black", "signal": "Motor phase-W"},
    {"color": "Green/yellow", "signal": "PE"},
    {"color": "Blue", "signal": "Brake"},
    {"color": "Yellow", "signal": "Brake"},
    {"color": "Shield", "signal": "FG"},
]


def _context(brake=True, absolute=False, sensor_set=True):
    code = (
        "FHA-25C-50-"
        + ("S248" if absolute else "US250")
        + ("-B" if brake else "")
        + ("-L" if sensor_set else "")
    )
    return {
        "actuator": {
            "model_code": code,
            "frame": "25C",
            "frame_name": "FHA-25C",
            "ratio": 50,
            "encoder": "absolute" if absolute else "incremental",
            "supply_voltage": 200,
            "output_resolution_ppr": 500000,
        },
        "flags": {
            "brake": brake,
            "absolute": absolute,
            "incremental": not absolute,
            "sensor_set": sensor_set,
        },
        "drivers": ["HA-655-2A-200", "HA-675-2A-200"] if absolute else ["HA-655-2-200", "HA-675-2-200"],
        "drivers_text": "HA-655-2-200, HA-675-2-200",
        "tightening": {
            "output_flange": {
                "screws": "8-M6 depth: 10",
                "torque_nm": 12,
                "torque_kgf_cm": 120,
                "torque_min_nm": 10.8,
                "torque_max_nm": 13.2,
            },
            "flange": {
                "screws": "8-M6",
                "torque_nm": 7,
                "torque_kgf_cm": 70,
                "torque_min_nm": 6.3,
                "torque_max_nm": 7.7,
            },
        },
        "brake": {
            "supply_v": 24,
            "supply_tolerance_pct": 10,
            "supply_min_v": 21.6,
            "supply_max_v": 26.4,
            "activating_current_a": 1.1,
            "holding_current_a": 0.15,
            "holding_torque_nm": 49,
        },
        "cables": {
            "motor_column": "brake option" if brake else "standard",
            "motor": MOTOR_BRAKE,
            "encoder_incremental_14": [
                {"color": c, "signal": s} for c, s in [("Red", "Vcc"), ("Black", "GND"), ("Green", "A")]
            ],
            "encoder_incremental_4": [
                {"color": "Red", "signal": "+5V", "reference": "Power Supply"},
                {"color": "Yellow", "signal": "SD", "reference": "Serial"},
            ],
            "encoder_absolute": [
                {"color": "Orange", "signal": "BAT+", "reference": "Battery+"},
                {"color": "Green", "signal": "CLR", "reference": "Clear Signal"},
            ],
        },
        "environment": {
            "temperature_min_c": 0.0,
            "temperature_max_c": 40.0,
            "humidity_min_pct": 20.0,
            "humidity_max_pct": 80.0,
            "vibration_max_m_s2": 24.5,
            "altitude_max_m": 1000.0,
            "cable_bending_radius_min_mm": 40.0,
            "protection": "IP44",
        },
        "sensor_set": {"ccw_limit_deg": -175.0, "cw_limit_deg": 175.0, "test_tolerance_deg": 2.0},
    }


@pytest.fixture
def context():
    return _context()


@pytest.fixture
def make_context():
    return _context
