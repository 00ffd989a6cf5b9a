"""Size one axis: the whole of Chapter 2 for one actuator and the user's duty cycle.

:func:`evaluate` is pure (explicit ratings in SI); :func:`size_axis` looks the actuator up in
the catalogue first; :func:`suggest_actuators` lists the catalogue actuators a duty passes
on. The duty cycle is the manual's: one move of ``angle_deg`` per cycle of
``cycle_time_s``, accelerated at maximum torque to ``speed_rpm``, run, braked at maximum torque.

Accelerating at each actuator's maximum torque (2-4-4) makes a larger actuator accelerate harder
and so raises its effective torque: a larger frame can fail a check that a smaller one passes.
When the machine needs a given acceleration time, ``DutyCycle.accel_time_s`` sizes for that move
instead (accelerating and braking in that time, at the torque it takes); the result's
``assumption`` says which method decided.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from fha_studio import catalog
from fha_studio.logic.sizing import duty as f
from fha_studio.logic.sizing._data import limits
from fha_studio.logic.sizing.bearing import BearingLoads, BearingRatings, BearingResult, check_bearing
from fha_studio.logic.sizing.checks import Check, at_least, at_most


class SizingError(ValueError):
    """The duty cycle or the actuator cannot be sized (bad input, unknown actuator)."""


@dataclass(frozen=True)
class ActuatorRatings:
    """The catalogue figures Chapter 2 needs, output side, SI (see fha_studio.catalog.Actuator)."""

    code: str
    max_torque_nm: float
    max_speed_rpm: float
    friction_torque_nm: float
    inertia_kgm2: float
    continuous_torque_nm: float
    continuous_speed_rpm: float
    allowable_inertia_kgm2: float
    bearing: BearingRatings | None = None


@dataclass(frozen=True)
class DutyCycle:
    """The user's duty: load inertia JL, speed N, move angle θ, cycle time t, load torque TL.

    ``load_torque_nm`` is positive when it opposes the rotation (2-4-4). ``duty_factors``:
    (KLa, KLr, KLd) read from the manual's duty-factor graphs (2-4-5), or None. ``bearing_loads``:
    the loads on the output flange for the checks of 2-3, or None.
    """

    load_inertia_kgm2: float
    speed_rpm: float
    angle_deg: float
    cycle_time_s: float
    load_torque_nm: float = 0.0
    duty_factors: tuple[float, float, float] | None = None
    bearing_loads: BearingLoads | None = None
    #: Acceleration (and braking) time the machine needs [s]; None: at the maximum torque (2-4-4).
    accel_time_s: float | None = None

    def __post_init__(self) -> None:
        def need(name: str, ok: bool, what: str) -> None:
            if not ok:
                raise SizingError(f"{name} must be {what}, got {getattr(self, name)!r}")

        def finite(v: object) -> bool:
            return isinstance(v, int | float) and math.isfinite(v)

        need(
            "load_inertia_kgm2",
            finite(self.load_inertia_kgm2) and self.load_inertia_kgm2 >= 0,
            "a number >= 0",
        )
        need("speed_rpm", finite(self.speed_rpm) and self.speed_rpm > 0, "a number > 0")
        need("angle_deg", finite(self.angle_deg) and self.angle_deg > 0, "a number > 0")
        need("cycle_time_s", finite(self.cycle_time_s) and self.cycle_time_s > 0, "a number > 0")
        need("load_torque_nm", finite(self.load_torque_nm), "a number")
        if self.accel_time_s is not None:
            need("accel_time_s", finite(self.accel_time_s) and self.accel_time_s > 0, "a number > 0 (s)")
        if self.duty_factors is not None:
            k = self.duty_factors
            need(
                "duty_factors",
                len(k) == 3 and all(finite(x) and x >= 0 for x in k),
                "three numbers >= 0 (KLa, KLr, KLd)",
            )


@dataclass(frozen=True)
class OperatingPoint:
    """One point of the duty on the torque-speed plane (output side): phase, speed, torque."""

    phase: str
    speed_rpm: float
    torque_nm: float


@dataclass(frozen=True)
class SizingResult:
    """Every figure of Chapter 2 for one actuator and duty, and the checks.

    Times in s, torques in N m, speeds in r/min, energy in J, power in W. ``percent_ed`` is None
    without duty factors; ``bearing`` is None without bearing loads. ``run_time_s`` is never
    negative: a move too short to reach the speed gives 0 and a failed check.
    """

    actuator_code: str
    duty: DutyCycle
    ratings: ActuatorRatings
    friction_torque_nm: float
    accel_time_s: float
    decel_time_s: float
    run_time_s: float
    percent_ed: float | None
    effective_torque_nm: float
    average_speed_rpm: float
    min_cycle_time_s: float
    regeneration_energy_j: float
    regeneration_power_w: float
    external_resistor_w: float
    bearing: BearingResult | None
    checks: tuple[Check, ...] = field(default=())
    #: How the move was accelerated, in words: the assumption that decides the torque checks.
    assumption: str = ""

    @property
    def ok(self) -> bool:
        """True when every check passes."""
        return all(c.ok for c in self.checks)

    @property
    def failed(self) -> tuple[Check, ...]:
        """The checks that fail."""
        return tuple(c for c in self.checks if not c.ok)

    def as_dict(self) -> dict[str, Any]:
        """The JSON form (the ``fha-studio size --json`` contract); non-finite numbers become None."""
        out: dict[str, Any] = {
            "actuator": self.actuator_code,
            "accel_time_s": self.accel_time_s,
            "decel_time_s": self.decel_time_s,
            "friction_torque_nm": self.friction_torque_nm,
            "run_time_s": self.run_time_s,
            "effective_torque_nm": self.effective_torque_nm,
            "min_cycle_time_s": self.min_cycle_time_s,
            "average_speed_rpm": self.average_speed_rpm,
        }
        if self.percent_ed is not None:
            out["percent_ed"] = self.percent_ed
        out["regeneration_energy_j"] = self.regeneration_energy_j
        out["regeneration_power_w"] = self.regeneration_power_w
        out["external_resistor_w"] = max(0.0, self.external_resistor_w)
        if self.bearing is not None:
            b = self.bearing
            out["bearing"] = {
                "max_moment_nm": b.max_moment_nm,
                "average_radial_load_n": b.average_radial_load_n,
                "average_axial_load_n": b.average_axial_load_n,
                "load_factor_ratio": b.load_factor_ratio,
                "x": b.x,
                "y": b.y,
                "dynamic_load_n": b.dynamic_load_n,
                "life_h": b.life_h,
                "sway_life_h": b.sway_life_h,
                "static_load_n": b.static_load_n,
                "static_safety_factor": b.static_safety_factor,
            }
        out["assumption"] = self.assumption
        out["ok"] = self.ok
        out["checks"] = [c.as_dict() for c in self.checks]
        finite: dict[str, Any] = _finite(out)
        return finite

    def operating_points(self) -> list[OperatingPoint]:
        """The duty on the torque-speed plane (output side), for a plot.

        Acceleration runs at TM (or, with a given acceleration time, at the torque it takes) from
        0 to N, the constant-speed part at TL, braking at minus that torque from N to 0 (the
        motor's share; friction brakes too); the last point is the effective torque at the average
        speed, to compare with the continuous rating.
        """
        n, tl = self.duty.speed_rpm, self.duty.load_torque_nm
        tm = self.ratings.max_torque_nm
        if self.duty.accel_time_s is not None:
            tm = accel_torque_for(self.ratings, self.duty)
        return [
            OperatingPoint("acceleration", 0.0, tm),
            OperatingPoint("acceleration", n, tm),
            OperatingPoint("constant speed", n, tl),
            OperatingPoint("deceleration", n, -tm),
            OperatingPoint("deceleration", 0.0, -tm),
            OperatingPoint("effective", self.average_speed_rpm, self.effective_torque_nm),
        ]

    def envelope(self) -> dict[str, float]:
        """The actuator's limits for the same plot: maximum and continuous torque and speed."""
        r = self.ratings
        return {
            "max_torque_nm": r.max_torque_nm,
            "max_speed_rpm": r.max_speed_rpm,
            "continuous_torque_nm": r.continuous_torque_nm,
            "continuous_speed_rpm": r.continuous_speed_rpm,
        }


def _finite(obj: Any) -> Any:
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: _finite(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_finite(v) for v in obj]
    return obj


def accel_torque_for(ratings: ActuatorRatings, duty: DutyCycle) -> float:
    """The torque that accelerates ``duty``'s load to its speed in its ``accel_time_s`` [N m]."""
    assert duty.accel_time_s is not None
    return f.accel_torque_nm(
        ratings.inertia_kgm2, duty.load_inertia_kgm2, duty.speed_rpm, duty.accel_time_s, duty.load_torque_nm
    )


def evaluate(ratings: ActuatorRatings, duty: DutyCycle) -> SizingResult:
    """Chapter 2 for ``duty`` on an actuator with ``ratings``: figures and checks."""
    r, d = ratings, duty
    jl, n, tl, t = d.load_inertia_kgm2, d.speed_rpm, d.load_torque_nm, d.cycle_time_s
    checks: list[Check] = [
        at_most(
            "load inertia",
            jl,
            r.allowable_inertia_kgm2,
            "2-1",
            "kg m^2",
            "the allowable load inertia (reference value) for high accuracy",
        ),
        at_most("speed", n, r.max_speed_rpm, "2-1", "r/min", "the actuator's maximum speed"),
    ]
    tf = r.friction_torque_nm
    if d.accel_time_s is None:
        ta = f.accel_time_s(r.inertia_kgm2, jl, n, r.max_torque_nm, tl)
        td = f.decel_time_s(r.inertia_kgm2, jl, n, r.max_torque_nm, tf, tl)
        accel_torque = r.max_torque_nm  # the manual accelerates and brakes at the maximum torque
        assumption = (
            f"accelerated and braked at the maximum torque TM = {r.max_torque_nm:g} N·m (the manual's "
            "method, 2-4-4): a larger actuator accelerates harder and its effective torque is higher; "
            "give the acceleration time the machine needs to size for that move instead"
        )
    else:
        ta = td = d.accel_time_s
        accel_torque = accel_torque_for(r, d)
        assumption = (
            f"accelerated and braked in the given {ta:g} s, at the torque that takes "
            f"(Ta = {accel_torque:.3g} N·m, 2-4-4 solved for the torque)"
        )
        checks.append(
            at_most(
                "acceleration torque",
                accel_torque,
                r.max_torque_nm,
                "2-4-4",
                "N m",
                f"Ta = (JA + JL) 2π/60 N / ta + TL must not exceed the maximum torque "
                f"to accelerate in {ta:g} s",
            )
        )
    checks.append(
        Check(
            "load torque",
            float(tl),
            float(r.max_torque_nm),
            tl < r.max_torque_nm,
            "2-4-4",
            "N m",
            "the maximum torque must exceed the load torque to accelerate; " + f.DECEL_LOAD_TORQUE_NOTE,
            "<",
        )
    )
    if tl < 0:  # a load turning with the rotation (a falling mass) works against braking
        braking = r.max_torque_nm + 2 * tf
        checks.append(
            Check(
                "load torque while braking",
                float(-tl),
                float(braking),
                -tl < braking,
                "2-4-4",
                "N m",
                "a load torque turning with the rotation must stay below the braking torque TM + 2 TF",
                "<",
            )
        )
    accelerates = math.isfinite(ta) and math.isfinite(td)
    if accelerates:
        tr_raw = f.run_time_s(d.angle_deg, n, ta, td)
        min_angle = f.min_angle_to_reach_speed_deg(n, ta, td)
        note = "θ >= 6 N (ta + td) / 2 for a trapezoidal move"
        if tr_raw < 0:
            note = (
                f"the move is too short to reach {n:g} r/min (tr = θ/6N - (ta+td)/2 = {tr_raw:.3f} s); "
                "the figures take tr = 0: lower the speed or lengthen the move"
            )
        checks.append(at_least("move reaches speed", d.angle_deg, min_angle, "2-4-5", "deg", note))
        tr = max(tr_raw, 0.0)
        checks.append(
            at_most(
                "move time within cycle", ta + tr + td, t, "2-4-5", "s", "ta + tr + td must fit in the cycle"
            )
        )
    else:
        tr = 0.0
    ta_f, td_f = (ta, td) if accelerates else (0.0, 0.0)

    ed = None
    if d.duty_factors is not None:
        kla, klr, kld = d.duty_factors
        ed = f.percent_ed(kla, klr, kld, ta_f, tr, td_f, t) if accelerates else math.inf
        checks.append(
            at_most(
                "%ED",
                ed,
                100.0,
                "2-4-5",
                "%",
                f"duty factors KLa = {kla:g}, KLr = {klr:g}, KLd = {kld:g} as entered (manual's graphs)",
            )
        )

    tm_torque = accel_torque
    if accelerates:
        tm = f.effective_torque_nm(tm_torque, tl, ta, tr, td, t)
        nav = f.average_speed_rpm(n, ta, tr, td, t)
        t_min = f.min_cycle_time_s(tm_torque, tl, ta, tr, td, r.continuous_torque_nm)
    else:
        tm = nav = t_min = math.inf
    checks += [
        at_most(
            "effective torque",
            tm,
            r.continuous_torque_nm,
            "2-4-6",
            "N m",
            f"Tm against the continuous torque; it falls to the continuous torque at a {t_min:.3g} s cycle",
        ),
        at_least(
            "cycle time",
            t,
            t_min,
            "2-4-6",
            "s",
            "the shortest cycle at which Tm equals the continuous torque: lengthen the cycle, lower the "
            "load inertia or choose a larger frame",
        ),
        at_most(
            "average speed", nav, r.continuous_speed_rpm, "2-4-6", "r/min", "Nav against the continuous speed"
        ),
    ]

    builtin_w = float(limits()["regeneration"]["builtin_resistor_w"])
    jt = r.inertia_kgm2 + jl
    energy = f.regeneration_energy_j(jt, n)
    power = f.regeneration_power_w(jt, n, t)
    external = power - builtin_w
    regen_note = f.REGENERATION_NOTE
    if external > 0:
        regen_note = (
            f"an external regeneration resistor of at least {external:.1f} W is needed; " + regen_note
        )
    checks.append(at_most("regeneration power", power, builtin_w, "2-4-8", "W", regen_note))

    bearing_result = None
    if d.bearing_loads is not None:
        if r.bearing is None:
            raise SizingError(f"no cross-roller bearing data for {r.code}: cannot check the bearing loads")
        # an oscillation (there and back over the sway angle) covers 2 x sway / 360 rev; with the
        # sway angle equal to the move angle this is one oscillation every two cycles
        sway = d.bearing_loads.sway_angle_deg
        oscillations = None
        if sway is not None:
            oscillations = nav * 360 / (2 * sway) if math.isfinite(nav) else 0.0
        bearing_result = check_bearing(
            r.bearing, d.bearing_loads, nav if math.isfinite(nav) else 0.0, oscillations
        )
        checks += bearing_result.checks

    return SizingResult(
        r.code,
        d,
        r,
        tf,
        ta,
        td,
        tr,
        ed,
        tm,
        nav,
        t_min,
        energy,
        power,
        external,
        bearing_result,
        tuple(checks),
        assumption,
    )


# -- the catalogue glue --------------------------------------------------------------------------
def ratings_from_actuator(actuator: catalog.Actuator) -> ActuatorRatings:
    """The figures Chapter 2 needs from a catalogue :class:`fha_studio.catalog.Actuator`."""
    b = actuator.bearing
    return ActuatorRatings(
        code=actuator.model_code,
        max_torque_nm=actuator.max_torque_nm,
        max_speed_rpm=actuator.max_speed_rpm,
        friction_torque_nm=actuator.friction_torque_nm,
        inertia_kgm2=actuator.inertia_kgm2,
        continuous_torque_nm=actuator.continuous_torque_nm,
        continuous_speed_rpm=actuator.continuous_speed_rpm,
        allowable_inertia_kgm2=actuator.allowable_inertia_kgm2,
        bearing=BearingRatings(
            pitch_circle_m=b.circular_pitch_of_roller_m,
            offset_m=b.offset_m,
            dynamic_load_rating_n=b.basic_dynamic_load_rating_n,
            static_load_rating_n=b.basic_static_load_rating_n,
            allowable_radial_load_n=b.allowable_radial_load_n,
            allowable_axial_load_n=b.allowable_axial_load_n,
            allowable_moment_nm=b.allowable_torsional_moment_nm,
        ),
    )


def actuator_ratings(actuator_code: str) -> ActuatorRatings:
    """The ratings of a catalogue model code; SizingError (one line) for a code the catalogue lacks."""
    try:
        return ratings_from_actuator(catalog.get_actuator(actuator_code))
    except (ValueError, KeyError) as exc:
        raise SizingError(f"unknown actuator {actuator_code!r}: {exc}") from None


def size_axis(actuator_code: str, duty: DutyCycle) -> SizingResult:
    """Chapter 2 for ``duty`` on the catalogue actuator ``actuator_code`` (e.g. ``"FHA-25C-50-US250"``)."""
    return evaluate(actuator_ratings(actuator_code), duty)


def size_all(
    duty: DutyCycle, codes: list[str] | None = None, encoder_code: str = "US250"
) -> list[SizingResult]:
    """``duty`` on every actuator of ``codes`` (default: the catalogue's 200 V actuators with
    ``encoder_code``, smallest frame and ratio first)."""
    if codes is None:
        codes = [c for c in catalog.all_model_codes(include_ac100v=False) if c.endswith(encoder_code)]
    return [size_axis(code, duty) for code in codes]


def suggest_actuators(
    duty: DutyCycle, codes: list[str] | None = None, encoder_code: str = "US250"
) -> list[SizingResult]:
    """The actuators on which ``duty`` passes every check, in the order of :func:`size_all`."""
    return [r for r in size_all(duty, codes, encoder_code) if r.ok]
