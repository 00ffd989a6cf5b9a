"""Which axis a recording declares, and whether the recording can be that axis (refusals)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from fha_studio.physics import AxisModel
from fha_studio.recording import Recording

# A current monitor's noise above this share of the actuator's maximum current is not a monitor.
GARBAGE_CURRENT_NOISE_FRACTION = 0.05


class ModelCheckError(ValueError):
    """The recording cannot be checked (wrong declared actuator, garbage columns, no motion)."""


@dataclass(frozen=True)
class DeclaredAxis:
    """The nominal model the recording declares: catalogue (or custom) actuator + declared load."""

    code: str
    model: AxisModel  # nominal: no effects
    actuator: object | None  # the catalogue entry (None for custom)

    @property
    def kt_nm_per_a(self) -> float:
        return self.model.torque_constant_nm_per_a

    @property
    def nominal_inertia_kgm2(self) -> float:
        """J_actuator + J_load_declared (kg m^2)."""
        return self.model.total_inertia_kgm2

    @property
    def ratio(self) -> float | None:
        return self.model.ratio


def declared_axis(rec: Recording) -> DeclaredAxis:
    """The nominal model of a recording; ModelCheckError when the declaration is inconsistent."""
    meta = rec.metadata
    if meta.load_inertia_kgm2 is None:
        raise ModelCheckError("the recording declares no load inertia (load_inertia_kgm2): the model "
                              "check needs the declared load")
    load_inertia_kgm2 = float(meta.load_inertia_kgm2)
    if meta.is_custom:
        # without a current the peak is unknown: no torque limit to refuse an effect by
        peak = float(np.max(np.abs(rec.current_a))) if rec.has_current else 1e6
        ppr = _guess_ppr(rec.pos_deg)
        kt, inertia = meta.torque_constant_nm_per_a, meta.actuator_inertia_kgm2
        if kt is None or inertia is None:  # the recording reader refuses such a file already
            raise ModelCheckError("a custom axis needs torque_constant_nm_per_a and actuator_inertia_kgm2")
        model = AxisModel(
            torque_constant_nm_per_a=float(kt),
            max_current_a=max(1.5 * peak, 1e-3),
            actuator_inertia_kgm2=float(inertia),
            load_inertia_kgm2=load_inertia_kgm2,
            ratio=meta.motor_turns_per_output_rev,
            output_resolution_ppr=ppr,
        )
        return DeclaredAxis("custom", model, None)
    from fha_studio.catalog import get_actuator

    try:
        actuator = get_actuator(meta.actuator)
    except ValueError as exc:
        raise ModelCheckError(f"unknown actuator '{meta.actuator}': {exc}") from None
    if int(actuator.supply_voltage) != int(meta.supply_voltage):
        raise ModelCheckError(
            f"the recording says supply_voltage {meta.supply_voltage} V but {meta.actuator} is a "
            f"{actuator.supply_voltage} V actuator (100 V models carry option A): wrong actuator declared?"
        )
    model = AxisModel.from_actuator(actuator, load_inertia_kgm2=load_inertia_kgm2)
    return DeclaredAxis(meta.actuator, model, actuator)


def _guess_ppr(pos_deg: np.ndarray) -> int:
    """Encoder pulses per output turn of a custom axis, from the position's quantisation step."""
    d = np.abs(np.diff(pos_deg))
    d = d[d > 0]
    if d.size < 20:
        return 1_000_000
    q = float(np.percentile(d, 1))
    ratio = d / q
    if np.mean(np.abs(ratio - np.round(ratio)) < 0.02) > 0.9:
        return max(1, round(360.0 / q))
    return 1_000_000


def check_plausible(rec: Recording, axis: DeclaredAxis) -> list[str]:
    """Refuse a recording that cannot come from the declared axis; returns notes (warnings)."""
    notes: list[str] = []
    code = axis.code
    t = rec.t_s
    pos = rec.pos_deg
    span = float(np.ptp(pos))
    q_deg = 360.0 / axis.model.output_resolution_ppr
    if span < 50 * q_deg or span < 0.01:
        raise ModelCheckError(
            f"column 'pos' hardly moves ({span:.4g} deg over the recording): "
            "nothing to check; record a motion"
        )
    if len(t) < 200:
        raise ModelCheckError(f"{len(t)} samples: the model check needs at least 200 (record longer)")
    dt = np.diff(t)
    speed_rpm = np.abs(np.diff(pos)) / dt / 6.0  # deg/s -> r/min
    fast = np.percentile(speed_rpm, 99.5)
    model = axis.model
    if model.max_speed_rpm is not None and fast > 1.5 * model.max_speed_rpm:
        i = int(np.argmax(speed_rpm))
        raise ModelCheckError(
            f"column 'pos' moves at {fast:.3g} r/min (jump of {pos[i + 1] - pos[i]:.4g} deg "
            f"at t = {t[i + 1]:.4g} s), "
            f"more than {code}'s maximum {model.max_speed_rpm:g} r/min: wrong actuator declared, "
            "or 'pos' is not the output position in degrees"
        )
    _check_resolution(pos, q_deg, code, axis.model.output_resolution_ppr, rec.metadata.is_custom)
    if rec.has_current:
        _check_current(rec, axis)
    _check_other_columns(rec, axis, span)
    return notes


def _check_current(rec: Recording, axis: DeclaredAxis) -> None:
    """The current column must be the motor current of the declared actuator."""
    code, model = axis.code, axis.model
    cur = rec.current_a
    peak = float(np.max(np.abs(cur)))
    if not rec.metadata.is_custom and peak > 1.5 * model.max_current_a:
        raise ModelCheckError(
            f"column 'current' reaches {peak:.3g} A but {code} allows at most {model.max_current_a:g} A: "
            "wrong actuator declared, or 'current' is not the motor current in A"
        )
    # Garbage, not a weak signal: a current whose sample-to-sample scatter dominates its spread AND
    # is large against the actuator's current range. A real monitor's noise is a few steps of a
    # 10-bit converter (under 1 % of Imax); a weak but real current (a slow move, a heavy load on a
    # 160:1 gear) is judged per channel later, at the analysis bandwidth, never refused here.
    from fha_studio.logic.modelcheck.signals import noise_sigma

    spread = float(np.std(cur))
    if spread == 0:
        raise ModelCheckError("column 'current' is constant: no torque information")
    scatter = noise_sigma(cur)
    if (
        not rec.metadata.is_custom
        and scatter > 0.5 * spread
        and scatter > GARBAGE_CURRENT_NOISE_FRACTION * model.max_current_a
    ):
        raise ModelCheckError(
            f"column 'current' looks like noise (sample-to-sample scatter {scatter:.3g} A against a "
            f"spread of {spread:.3g} A, {100 * scatter / model.max_current_a:.0f} % of {code}'s "
            f"{model.max_current_a:g} A): is it the driver's current monitor?"
        )


def _check_other_columns(rec: Recording, axis: DeclaredAxis, span: float) -> None:
    """load_pos, vel and cmd_pos must be what the format says."""
    t, pos, model = rec.t_s, rec.pos_deg, axis.model
    load = rec.load_pos_deg
    if load is not None:
        diff = load - pos
        off = float(np.median(diff))
        worst = float(np.max(np.abs(diff - off)))
        if worst > 0.5:
            i = int(np.argmax(np.abs(diff - off)))
            raise ModelCheckError(
                f"column 'load_pos' differs from 'pos' by {worst:.3g} deg (at t = {t[i]:.4g} s) "
                "beyond its offset; "
                "gear wind-up and errors are arcseconds: is it the same axis, in degrees?"
            )
    vel = rec.vel_rpm
    if vel is not None:
        v_est = np.gradient(pos, t) / 6.0
        err = float(np.sqrt(np.mean((vel - v_est) ** 2)))
        scale = float(np.sqrt(np.mean(v_est**2)))
        if err > 0.5 * scale + 0.05 * (model.max_speed_rpm or scale):
            raise ModelCheckError(
                f"column 'vel' does not match the derivative of 'pos' "
                f"(rms difference {err:.3g} r/min against "
                f"{scale:.3g} r/min): is it the output speed in r/min?"
            )
    cmd = rec.cmd_pos_deg
    alarm = rec.channels.get("alarm")
    if cmd is not None and alarm is not None and np.any(alarm > 0.5):
        # from the first alarm on the command does not hold the axis: it coasts away, and a
        # controller resumes from its own count, the coast's travel off (the closed loop is read
        # before it)
        first = int(np.argmax(alarm > 0.5))
        cmd, pos = cmd[:first], pos[:first]
    if cmd is not None and len(cmd):
        err = float(np.sqrt(np.mean((cmd - pos) ** 2)))
        if err > max(0.5 * span, 5.0):
            raise ModelCheckError(
                f"column 'cmd_pos' is far from 'pos' (rms {err:.3g} deg over a {span:.3g} deg motion): "
                "is it the position command in degrees?"
            )


def _check_resolution(pos: np.ndarray, q_deg: float, code: str, ppr: int, custom: bool) -> None:
    """Quantised positions must step in whole pulses of the declared encoder."""
    if custom:
        return
    d = np.abs(np.diff(pos))
    d = d[d > 1e-12]
    if d.size < 50:
        return
    r = d / q_deg
    whole = np.abs(r - np.round(r)) < 0.02
    if np.mean(whole) > 0.9:
        # with the declared encoder about half of the steps would be an odd number of pulses
        odd = np.mean(np.round(r[whole]) % 2 == 1)
        if odd < 0.02:
            raise ModelCheckError(
                f"column 'pos' always steps by an even number of {code}'s encoder pulses ({q_deg:.4g} deg, "
                f"{ppr} per turn): the encoder is coarser than declared; wrong actuator declared?"
            )
        return
    # not whole pulses of the declared encoder: is it quantised to another one?
    q = float(np.percentile(d, 1))
    rq = d / q
    if q > 0 and np.mean(np.abs(rq - np.round(rq)) < 0.02) > 0.9:
        raise ModelCheckError(
            f"column 'pos' moves in steps of {q:.4g} deg ({360.0 / q:.0f} pulses per turn) "
            f"but {code}'s encoder "
            f"resolves {q_deg:.4g} deg ({ppr} per turn): wrong actuator declared?"
        )


def rms(x: np.ndarray | None) -> float:
    """Root mean square (0 for no signal)."""
    return float(math.sqrt(np.mean(np.square(x)))) if x is not None and len(x) else 0.0
