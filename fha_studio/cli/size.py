"""``fha-studio size``: the selection calculator of FHA-C manual Chapter 2 for one duty cycle."""

from __future__ import annotations

import argparse
import json
import math

from fha_studio import plausible
from fha_studio.cli import CliError
from fha_studio.cli._values import NUMBER_SHAPE
from fha_studio.logic.sizing import (
    BearingLoads,
    DutyCycle,
    SizingError,
    SizingResult,
    actuator_ratings,
    evaluate,
    suggest_actuators,
)

ORDER = 20

# plausible range of each number (fha_studio.plausible says why)
_RANGES = {
    "load_inertia": plausible.LOAD_INERTIA_KGM2,
    "speed": plausible.SPEED_RPM,
    "angle": plausible.MOVE_ANGLE_DEG,
    "cycle": plausible.CYCLE_TIME_S,
    "load_torque": plausible.LOAD_TORQUE_NM,
    "accel_time": plausible.ACCEL_TIME_S,
    "radial_load_n": plausible.BEARING_LOAD_N,
    "axial_load_n": plausible.BEARING_LOAD_N,
    "radial_offset_mm": plausible.LOAD_OFFSET_MM,
    "axial_offset_mm": plausible.LOAD_OFFSET_MM,
    "load_factor": plausible.LOAD_FACTOR,
    "required_life_h": plausible.REQUIRED_LIFE_H,
}

# (option, attribute, unit) of the numbers; parsed here so that a bad one is one clear line
_REQUIRED = (
    ("--load-inertia", "load_inertia", "kg m^2"),
    ("--speed", "speed", "r/min"),
    ("--angle", "angle", "deg"),
    ("--cycle", "cycle", "s"),
)
_BEARING = (
    ("--radial-load-n", "radial_load_n", "N"),
    ("--axial-load-n", "axial_load_n", "N"),
    ("--radial-offset-mm", "radial_offset_mm", "mm"),
    ("--axial-offset-mm", "axial_offset_mm", "mm"),
    ("--load-factor", "load_factor", ""),
    ("--required-life-h", "required_life_h", "h"),
)


def register(subparsers: argparse._SubParsersAction) -> None:
    p = subparsers.add_parser(
        "size",
        help="check a duty cycle against an actuator (Chapter 2 selection guidelines)",
        description="Size an axis by the FHA-C manual's Chapter 2: acceleration and deceleration times, "
        "run time, %%ED, effective torque, average speed, minimum cycle time, regeneration and, with "
        "bearing loads, the cross-roller bearing checks. The duty is one move of --angle degrees at "
        "--speed every --cycle seconds, accelerated and braked at the maximum torque (the manual's "
        "method) or, with --accel-time, in the time the machine needs.",
    )
    p.add_argument("--actuator", metavar="CODE", help="model code, e.g. FHA-25C-50-US250")
    p.add_argument("--load-inertia", metavar="KGM2", help="load inertia JL in kg m^2 (output side)")
    p.add_argument("--speed", metavar="RPM", help="actuator (output) speed N in r/min")
    p.add_argument("--angle", metavar="DEG", help="move angle per cycle in degrees")
    p.add_argument("--cycle", metavar="S", help="cycle time t in s")
    p.add_argument(
        "--load-torque",
        metavar="NM",
        default="0",
        help="load torque TL in N m, + against the rotation (default 0)",
    )
    p.add_argument(
        "--duty-factors", metavar="KLA,KLR,KLD", help="duty factors from the manual's graphs (2-4-5)"
    )
    p.add_argument(
        "--accel-time",
        metavar="S",
        help="acceleration (and braking) time the machine needs, in s (default: at the maximum torque)",
    )
    g = p.add_argument_group("cross-roller bearing (2-3), checked when a load is given")
    g.add_argument("--radial-load-n", metavar="N", help="maximum radial load Frmax in N")
    g.add_argument("--axial-load-n", metavar="N", help="maximum axial load Famax in N")
    g.add_argument("--radial-offset-mm", metavar="MM", help="radial loading point Lr in mm (default 0)")
    g.add_argument("--axial-offset-mm", metavar="MM", help="axial loading point La in mm (default 0)")
    g.add_argument(
        "--load-factor", metavar="FW", help="load factor fw (1-1.2 smooth, 1.2-1.5 normal, 1.5-3 shock; 1.5)"
    )
    g.add_argument(
        "--use",
        choices=("precise", "normal", "shock"),
        default="normal",
        help="operation for the static safety limit: precise 3, shock 2, normal 1.5 (default normal)",
    )
    g.add_argument(
        "--sway", action="store_true", help="the axis sways back and forth over --angle (sway life, fretting)"
    )
    g.add_argument("--required-life-h", metavar="H", help="the bearing life needed, in hours")
    p.add_argument(
        "--suggest", action="store_true", help="list the actuators the duty passes on (no --actuator)"
    )
    p.add_argument("--strict", action="store_true", help="exit 1 when a check fails")
    p.add_argument("--json", action="store_true", help="print JSON")
    p.set_defaults(func=run)


def _number(args: argparse.Namespace, option: str, attr: str, unit: str) -> float | None:
    text = getattr(args, attr)
    if text is None:
        return None
    if not NUMBER_SHAPE.fullmatch(text.strip()):
        raise CliError(f"{option}: '{text[:40]}' is not a number" + (f" (in {unit})" if unit else ""))
    value = float(text)
    allowed = _RANGES.get(attr)
    if allowed is not None and not allowed.contains(value):
        raise CliError(f"{option}: {text.strip()[:40]} is outside {allowed.allowed()} ({allowed.reason})")
    if not math.isfinite(value):
        raise CliError(f"{option}: '{text[:40]}' is too large")
    return value


def _duty_factors(text: str | None) -> tuple[float, float, float] | None:
    if text is None:
        return None
    parts = [p.strip() for p in text.split(",")]
    values = tuple(float(p) for p in parts) if all(NUMBER_SHAPE.fullmatch(p) for p in parts) else ()
    if len(values) != 3 or not all(plausible.DUTY_FACTOR.contains(v) for v in values):
        raise CliError(f"--duty-factors: '{text[:40]}' must be three numbers "
                       f"{plausible.DUTY_FACTOR.allowed()} as KLA,KLR,KLD (e.g. 7,1,7)")
    return values[0], values[1], values[2]


def _duty(args: argparse.Namespace) -> DutyCycle:
    numbers = {}
    for option, attr, unit in _REQUIRED:
        value = _number(args, option, attr, unit)
        if value is None:
            raise CliError(f"{option} is required")
        numbers[attr] = value
    load_torque = _number(args, "--load-torque", "load_torque", "N m")
    accel_time = _number(args, "--accel-time", "accel_time", "s")
    bearing = {attr: _number(args, option, attr, unit) for option, attr, unit in _BEARING}
    for option, attr, _unit in _BEARING:
        given = bearing[attr]
        if given is not None and given < 0:
            raise CliError(f"{option} must be >= 0, got {getattr(args, attr)}")
    loads = None
    if bearing["radial_load_n"] is not None or bearing["axial_load_n"] is not None:
        try:
            loads = BearingLoads(
                max_radial_load_n=bearing["radial_load_n"] or 0.0,
                max_axial_load_n=bearing["axial_load_n"] or 0.0,
                radial_offset_m=(bearing["radial_offset_mm"] or 0.0) / 1000,
                axial_offset_m=(bearing["axial_offset_mm"] or 0.0) / 1000,
                load_factor_fw=1.5 if bearing["load_factor"] is None else bearing["load_factor"],
                use=args.use,
                sway_angle_deg=numbers["angle"] if args.sway else None,
                required_life_h=bearing["required_life_h"],
            )
        except ValueError as exc:
            raise CliError(f"bearing loads: {exc}") from None
    elif args.sway or any(v is not None for v in bearing.values()):
        raise CliError("bearing options need --radial-load-n or --axial-load-n")
    try:
        return DutyCycle(
            load_inertia_kgm2=numbers["load_inertia"],
            speed_rpm=numbers["speed"],
            angle_deg=numbers["angle"],
            cycle_time_s=numbers["cycle"],
            load_torque_nm=load_torque or 0.0,
            duty_factors=_duty_factors(args.duty_factors),
            bearing_loads=loads,
            accel_time_s=accel_time,
        )
    except SizingError as exc:
        raise CliError(_option_message(exc)) from None


_OPTION_OF_FIELD = {
    "load_inertia_kgm2": "--load-inertia",
    "speed_rpm": "--speed",
    "angle_deg": "--angle",
    "cycle_time_s": "--cycle",
    "load_torque_nm": "--load-torque",
    "duty_factors": "--duty-factors",
    "accel_time_s": "--accel-time",
}


def _option_message(exc: Exception) -> str:
    text = str(exc)
    field, _, rest = text.partition(" ")
    return f"{_OPTION_OF_FIELD[field]} {rest}" if field in _OPTION_OF_FIELD else text


def run(args: argparse.Namespace) -> int:
    duty = _duty(args)
    if args.suggest:
        if args.actuator:
            raise CliError("--suggest lists the actuators for the duty: leave out --actuator")
        return _suggest(args, duty)
    if not args.actuator:
        raise CliError("--actuator is required (or --suggest)")
    try:
        ratings = actuator_ratings(args.actuator)
    except SizingError as exc:
        raise CliError(str(exc)) from None
    if duty.speed_rpm > ratings.max_speed_rpm:
        raise CliError(
            f"--speed {duty.speed_rpm:g} r/min is above the maximum speed of {ratings.code} "
            f"({ratings.max_speed_rpm:g} r/min)"
        )
    try:
        result = evaluate(ratings, duty)
    except SizingError as exc:
        raise CliError(str(exc)) from None
    if args.json:
        print(json.dumps(result.as_dict(), indent=2, ensure_ascii=False))
    else:
        print(format_result(result))
    return 1 if args.strict and not result.ok else 0


def _suggest(args: argparse.Namespace, duty: DutyCycle) -> int:
    try:
        passing = suggest_actuators(duty)
    except SizingError as exc:
        raise CliError(str(exc)) from None
    if args.json:
        print(json.dumps([r.as_dict() for r in passing], indent=2, ensure_ascii=False))
    elif passing:
        print("actuators on which every check passes (smallest first):")
        for r in passing:
            tm, cont = r.effective_torque_nm, r.ratings.continuous_torque_nm
            print(f"  {r.actuator_code:<20} effective torque {tm:.3g} of {cont:g} N m")
    else:
        print("no actuator passes every check for this duty")
    return 1 if args.strict and not passing else 0


def _g(value: float | None, digits: int = 4) -> str:
    if value is None:
        return "-"
    if not math.isfinite(value):
        return "inf"
    return f"{value:.{digits}g}"


def format_result(r: SizingResult) -> str:
    """A readable report: the figures, then every check with PASS/FAIL."""
    d = r.duty
    lines = [
        f"{r.actuator_code}: load {d.load_inertia_kgm2:g} kg m^2, {d.speed_rpm:g} r/min, "
        f"{d.angle_deg:g} deg every {d.cycle_time_s:g} s, load torque {d.load_torque_nm:g} N m",
        f"  {r.assumption}",
        "",
    ]
    figures: list[tuple[str, float | None, str]] = [
        ("acceleration time ta", r.accel_time_s, "s"),
        ("deceleration time td", r.decel_time_s, "s"),
        ("friction torque TF", r.friction_torque_nm, "N m"),
        ("run time tr", r.run_time_s, "s"),
    ]
    if r.percent_ed is not None:
        figures.append(("%ED", r.percent_ed, "%"))
    figures += [
        ("effective torque Tm", r.effective_torque_nm, "N m"),
        ("minimum cycle time", r.min_cycle_time_s, "s"),
        ("average speed Nav", r.average_speed_rpm, "r/min"),
        ("regeneration", r.regeneration_power_w, f"W ({_g(r.regeneration_energy_j)} J per cycle)"),
    ]
    if r.bearing is not None:
        b = r.bearing
        figures += [
            ("bearing moment Mmax", b.max_moment_nm, "N m"),
            ("bearing X, Y", None, f"{b.x:g}, {b.y:g}"),
            ("equivalent dynamic load Pc", b.dynamic_load_n, "N"),
            ("bearing life L10", b.life_h, "h"),
        ]
        if b.sway_life_h is not None:
            figures.append(("bearing sway life", b.sway_life_h, "h"))
        figures.append(("static safety factor fs", b.static_safety_factor, ""))
    for label, value, unit in figures:
        shown = "" if value is None and label == "bearing X, Y" else _g(value)
        lines.append(f"  {label:<28} {shown} {unit}".rstrip())
    lines += ["", f"  {'check':<26} {'value':>10}    {'limit':<18} {'section':<9} result"]
    for c in r.checks:
        limit = f"{c.comparison} {_g(c.limit)} {c.unit}".strip()
        lines.append(
            f"  {c.name:<26} {_g(c.value):>10}    {limit:<18} {c.section:<9} {'PASS' if c.ok else 'FAIL'}"
        )
    failed = r.failed
    lines.append("")
    if failed:
        lines.append(
            f"FAIL: {len(failed)} of {len(r.checks)} checks fail ({', '.join(c.name for c in failed)})"
        )
        lines += [f"  - {c.name}: {c.note}" for c in failed if c.note]
    else:
        lines.append(f"PASS: all {len(r.checks)} checks pass")
    lines.append(
        "(--json gives every check with its note, including where the manual's formula was corrected)"
    )
    return "\n".join(lines)
