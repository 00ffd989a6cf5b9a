"""The one physics model of an FHA-C axis, used by the simulated drive and by the model check.

- `AxisModel`: output-referred plant parameters (SI) and the TOML model file (fha-axis-model/1).
- `Effects` and one dataclass per effect, with the model check's ids and parameter names.
- `GearStiffness`: the wind-up curve of manual 1-9-2.
- `ServoSettings`, `ServoAxis`: the HA-655-like cascade (P position, PI speed, current limit,
  feed-forward, electronic gear, rotary direction, in-position) at >= 5 kHz over the plant;
  `PanelGains`: the front panel's tune items 0-3 in SI (the one reading of them), and
  `servo_settings()`: the drive's items as `ServoSettings`.
- `MotionGenerator`: jog and trapezoidal move profiles.
- `simulate()`: a whole recorded command through the closed loop; `MonitorOptions` for the
  monitors' quantisation and noise.

Signs: positive angle/speed/torque/current = CW seen from the output flange.
"""

from fha_studio.physics.effects import (
    EFFECT_IDS,
    EFFECT_TYPES,
    AsymmetricFriction,
    CoulombFriction,
    Effects,
    GravityLoad,
    InertiaError,
    KinematicError,
    LoadTorqueOffset,
    LostMotion,
    StribeckFriction,
    TorqueConstantError,
    TorqueRipple,
    TorsionalCompliance,
    ViscousFriction,
)
from fha_studio.physics.model import MODEL_FORMAT, AxisModel, catalogue_effects
from fha_studio.physics.motion import MotionGenerator
from fha_studio.physics.servo import (
    RAD_S_PER_RPM,
    TRACE_CHANNELS,
    PanelGains,
    ServoAxis,
    ServoSettings,
    servo_settings,
)
from fha_studio.physics.simulate import SIMULATION_UNITS, MonitorOptions, apply_monitor, simulate
from fha_studio.physics.stiffness import ARCMIN_PER_RAD, ARCSEC_PER_RAD, GearStiffness

__all__ = [
    "ARCMIN_PER_RAD",
    "ARCSEC_PER_RAD",
    "EFFECT_IDS",
    "EFFECT_TYPES",
    "MODEL_FORMAT",
    "RAD_S_PER_RPM",
    "SIMULATION_UNITS",
    "TRACE_CHANNELS",
    "AsymmetricFriction",
    "AxisModel",
    "CoulombFriction",
    "Effects",
    "GearStiffness",
    "GravityLoad",
    "InertiaError",
    "KinematicError",
    "LoadTorqueOffset",
    "LostMotion",
    "MonitorOptions",
    "MotionGenerator",
    "PanelGains",
    "ServoAxis",
    "ServoSettings",
    "StribeckFriction",
    "TorqueConstantError",
    "TorqueRipple",
    "TorsionalCompliance",
    "ViscousFriction",
    "apply_monitor",
    "catalogue_effects",
    "servo_settings",
    "simulate",
]
