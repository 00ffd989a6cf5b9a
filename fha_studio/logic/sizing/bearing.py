"""Cross-roller bearing checks of FHA-C manual section 2-3, as pure functions of SI numbers.

Loads in N, moments in N m, lengths in m (the manual writes mm: only the unit differs, every
ratio is the same), speeds in r/min, life in hours. The bearing's ratings (Table 1 of 2-3) come
from the catalogue through :class:`BearingRatings`.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

from fha_studio.logic.sizing._data import limits
from fha_studio.logic.sizing.checks import Check, at_least, at_most

_LIFE_EXPONENT = 10 / 3

LOAD_FACTOR_NOTE = (
    "the printed (5) reads Frav / (Frav + 2 (Frav (Lr + R) + Frav La) / dp); the axial ratio "
    "Faav / (Frav + 2 (Frav (Lr + R) + Faav La) / dp) is used, as in (6) and ISO 76/281 practice"
)
SWAY_SPEED_NOTE = (
    "n1 is taken as oscillations per minute (one oscillation: there and back), as in Harmonic Drive's "
    "bearing data; the manual's text calls it the average speed of (4), which would overstate the life "
    "by 90/θ"
)


@dataclass(frozen=True)
class BearingRatings:
    """Table 1 of 2-3 for one frame: pitch circle dp, offset R, ratings C/Co, allowable loads."""

    pitch_circle_m: float
    offset_m: float
    dynamic_load_rating_n: float
    static_load_rating_n: float
    allowable_radial_load_n: float
    allowable_axial_load_n: float
    allowable_moment_nm: float


@dataclass(frozen=True)
class LoadSegment:
    """One part of a cycle for the averages (2)-(4): output speed n, duration t, loads Fr and Fa."""

    speed_rpm: float
    time_s: float
    radial_load_n: float
    axial_load_n: float


# (1) ------------------------------------------------------------------------------------------
def max_moment_nm(
    max_radial_load_n: float,
    max_axial_load_n: float,
    radial_offset_m: float,
    axial_offset_m: float,
    offset_m: float,
) -> float:
    """Mmax = Frmax (Lr + R) + Famax La (2-3 (1)); Lr, La: loading points, R: the bearing's offset."""
    return max_radial_load_n * (radial_offset_m + offset_m) + max_axial_load_n * axial_offset_m


# (2) (3) (4) ----------------------------------------------------------------------------------
def average_load_n(loads_n: Sequence[float], speeds_rpm: Sequence[float], times_s: Sequence[float]) -> float:
    """(Σ n t |F|^(10/3) / Σ n t)^(3/10): the average radial (2) or axial (3) load."""
    if not (len(loads_n) == len(speeds_rpm) == len(times_s)) or not loads_n:
        raise ValueError("loads_n, speeds_rpm and times_s must be equally long and not empty")
    weights = [abs(n) * t for n, t in zip(speeds_rpm, times_s, strict=True)]
    total = sum(weights)
    if total <= 0:
        raise ValueError("the segments contain no motion (Σ n t = 0): no average load")
    mean = sum(w * abs(f) ** _LIFE_EXPONENT for w, f in zip(weights, loads_n, strict=True)) / total
    return float(mean ** (1 / _LIFE_EXPONENT))


def average_output_speed_rpm(speeds_rpm: Sequence[float], times_s: Sequence[float]) -> float:
    """Nav = Σ n t / Σ t (2-3 (4))."""
    total = sum(times_s)
    if total <= 0:
        raise ValueError("the segments last no time (Σ t = 0)")
    return sum(abs(n) * t for n, t in zip(speeds_rpm, times_s, strict=True)) / total


def average_loads(segments: Sequence[LoadSegment]) -> tuple[float, float, float]:
    """(Frav, Faav, Nav) of a cycle's segments by (2), (3) and (4)."""
    n = [s.speed_rpm for s in segments]
    t = [s.time_s for s in segments]
    return (
        average_load_n([s.radial_load_n for s in segments], n, t),
        average_load_n([s.axial_load_n for s in segments], n, t),
        average_output_speed_rpm(n, t),
    )


# (5) (6) --------------------------------------------------------------------------------------
def load_factor_ratio(
    average_radial_load_n: float,
    average_axial_load_n: float,
    radial_offset_m: float,
    axial_offset_m: float,
    offset_m: float,
    pitch_circle_m: float,
) -> float:
    """Faav / (Frav + 2 (Frav (Lr + R) + Faav La) / dp), the ratio of 2-3 (5) (see LOAD_FACTOR_NOTE)."""
    fr, fa = average_radial_load_n, average_axial_load_n
    denominator = fr + 2 * (fr * (radial_offset_m + offset_m) + fa * axial_offset_m) / pitch_circle_m
    if denominator <= 0:
        return math.inf if fa > 0 else 0.0
    return fa / denominator


def load_factors(ratio: float) -> tuple[float, float]:
    """(X, Y) for the ratio of (5): X = 1, Y = 0.45 up to 1.5, else X = Y = 0.67 (limits.toml)."""
    f = limits()["bearing_load_factors"]
    if ratio <= f["ratio_limit"]:
        return f["x_low_ratio"], f["y_low_ratio"]
    return f["x_high_ratio"], f["y_high_ratio"]


def equivalent_dynamic_load_n(
    average_radial_load_n: float,
    average_axial_load_n: float,
    radial_offset_m: float,
    axial_offset_m: float,
    offset_m: float,
    pitch_circle_m: float,
    x: float,
    y: float,
) -> float:
    """Pc = X (Frav + 2 (Frav (Lr + R) + Faav La) / dp) + Y Faav (2-3 (6))."""
    fr, fa = average_radial_load_n, average_axial_load_n
    return x * (fr + 2 * (fr * (radial_offset_m + offset_m) + fa * axial_offset_m) / pitch_circle_m) + y * fa


# (7) (8) --------------------------------------------------------------------------------------
def life_h(
    average_speed_rpm: float, dynamic_load_rating_n: float, load_factor_fw: float, dynamic_load_n: float
) -> float:
    """L10 = 10^6 / (60 Nav) (C / (fw Pc))^(10/3) hours (2-3 (7)); inf when nothing turns or loads."""
    if average_speed_rpm <= 0 or dynamic_load_n <= 0:
        return math.inf
    return float(
        1e6
        / (60 * average_speed_rpm)
        * (dynamic_load_rating_n / (load_factor_fw * dynamic_load_n)) ** _LIFE_EXPONENT
    )


def sway_life_h(
    oscillations_per_min: float,
    half_sway_angle_deg: float,
    dynamic_load_rating_n: float,
    load_factor_fw: float,
    dynamic_load_n: float,
) -> float:
    """L = 10^6 / (60 n1) x 90 / θ x (C / (fw Pc))^(10/3) hours (2-3 (8)); θ is half the sway angle.

    n1 in oscillations per minute (see :data:`SWAY_SPEED_NOTE`).
    """
    if oscillations_per_min <= 0 or dynamic_load_n <= 0:
        return math.inf
    if half_sway_angle_deg <= 0:
        raise ValueError(f"half_sway_angle_deg must be > 0, got {half_sway_angle_deg!r}")
    return float(
        1e6
        / (60 * oscillations_per_min)
        * 90
        / half_sway_angle_deg
        * (dynamic_load_rating_n / (load_factor_fw * dynamic_load_n)) ** _LIFE_EXPONENT
    )


# (9) (10) -------------------------------------------------------------------------------------
def equivalent_static_load_n(
    max_radial_load_n: float, max_moment_nm: float, max_axial_load_n: float, pitch_circle_m: float
) -> float:
    """Po = Frmax + 2 Mmax / dp + 0.44 Famax (2-3 (9))."""
    return max_radial_load_n + 2 * max_moment_nm / pitch_circle_m + 0.44 * max_axial_load_n


def static_safety_factor(static_load_rating_n: float, static_load_n: float) -> float:
    """fs = Co / Po (2-3 (10)); inf without load."""
    return math.inf if static_load_n <= 0 else static_load_rating_n / static_load_n


def static_safety_limit(use: str) -> float:
    """The least fs for ``use``: ``"precise"`` 3, ``"shock"`` 2, ``"normal"`` 1.5 (2-3 (10))."""
    table = {k: v for k, v in limits()["bearing_static_safety"].items() if k != "section"}
    try:
        return float(table[use])
    except KeyError:
        raise ValueError(f"unknown use {use!r}; expected one of {', '.join(table)}") from None


def load_factor_range(operation: str) -> tuple[float, float]:
    """The manual's fw range for ``"smooth"``, ``"normal"`` or ``"shock"`` operation (2-3 (7))."""
    table = limits()["bearing_load_factor_fw"]
    if operation not in table or operation == "section":
        raise ValueError(f"unknown operation {operation!r}; expected smooth, normal or shock")
    low, high = table[operation]
    return float(low), float(high)


# the whole of 2-3 -----------------------------------------------------------------------------
@dataclass(frozen=True)
class BearingLoads:
    """The user's loads on the output flange (2-3, Fig. 1).

    Maximum loads for (1), (9), (10); average loads for (2), (3), (6) default to the maximum ones
    (a constant load while moving). ``radial_offset_m`` (Lr) and ``axial_offset_m`` (La) are the
    loading points. ``load_factor_fw``: 1-1.2 smooth, 1.2-1.5 normal, 1.5-3 with shock (the
    default is the top of "normal"). ``use`` picks the static safety limit. ``sway_angle_deg``:
    the full sway angle for a swaying motion (None: rotation). ``required_life_h``: the life the
    user needs (None: the life is reported, not checked).
    """

    max_radial_load_n: float = 0.0
    max_axial_load_n: float = 0.0
    radial_offset_m: float = 0.0
    axial_offset_m: float = 0.0
    average_radial_load_n: float | None = None
    average_axial_load_n: float | None = None
    load_factor_fw: float = 1.5
    use: str = "normal"
    sway_angle_deg: float | None = None
    required_life_h: float | None = None

    def __post_init__(self) -> None:
        for name in ("max_radial_load_n", "max_axial_load_n", "radial_offset_m", "axial_offset_m"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value >= 0):
                raise ValueError(f"{name} must be a number >= 0, got {value!r}")
        if not self.load_factor_fw >= 1.0:
            raise ValueError(f"load_factor_fw must be >= 1, got {self.load_factor_fw!r}")
        static_safety_limit(self.use)
        if self.sway_angle_deg is not None and not self.sway_angle_deg > 0:
            raise ValueError(f"sway_angle_deg must be > 0, got {self.sway_angle_deg!r}")


@dataclass(frozen=True)
class BearingResult:
    """The figures of 2-3 and its checks."""

    max_moment_nm: float
    average_radial_load_n: float
    average_axial_load_n: float
    load_factor_ratio: float
    x: float
    y: float
    dynamic_load_n: float
    life_h: float
    sway_life_h: float | None
    static_load_n: float
    static_safety_factor: float
    checks: tuple[Check, ...]


def check_bearing(
    ratings: BearingRatings,
    loads: BearingLoads,
    average_speed_rpm: float,
    oscillations_per_min: float | None = None,
) -> BearingResult:
    """Every check of 2-3 for ``loads`` on a bearing of ``ratings`` turning at ``average_speed_rpm``.

    ``oscillations_per_min`` is needed for the sway life when ``loads.sway_angle_deg`` is set.
    """
    r, ld = ratings, loads
    mmax = max_moment_nm(
        ld.max_radial_load_n, ld.max_axial_load_n, ld.radial_offset_m, ld.axial_offset_m, r.offset_m
    )
    frav = ld.max_radial_load_n if ld.average_radial_load_n is None else ld.average_radial_load_n
    faav = ld.max_axial_load_n if ld.average_axial_load_n is None else ld.average_axial_load_n
    ratio = load_factor_ratio(frav, faav, ld.radial_offset_m, ld.axial_offset_m, r.offset_m, r.pitch_circle_m)
    x, y = load_factors(ratio)
    pc = equivalent_dynamic_load_n(
        frav, faav, ld.radial_offset_m, ld.axial_offset_m, r.offset_m, r.pitch_circle_m, x, y
    )
    life = life_h(average_speed_rpm, r.dynamic_load_rating_n, ld.load_factor_fw, pc)
    po = equivalent_static_load_n(ld.max_radial_load_n, mmax, ld.max_axial_load_n, r.pitch_circle_m)
    fs = static_safety_factor(r.static_load_rating_n, po)

    checks = [
        at_most("maximum radial load", ld.max_radial_load_n, r.allowable_radial_load_n, "2-3", "N"),
        at_most("maximum axial load", ld.max_axial_load_n, r.allowable_axial_load_n, "2-3", "N"),
        at_most("maximum torsional moment", mmax, r.allowable_moment_nm, "2-3 (1)", "N m"),
    ]
    sway_life = None
    if ld.sway_angle_deg is not None:
        if oscillations_per_min is None:
            raise ValueError("oscillations_per_min is needed for the sway life (sway_angle_deg is set)")
        sway_life = sway_life_h(
            oscillations_per_min, ld.sway_angle_deg / 2, r.dynamic_load_rating_n, ld.load_factor_fw, pc
        )
        fretting = limits()["bearing_sway"]["fretting_angle_deg"]
        checks.append(
            at_least(
                "sway angle (fretting)",
                ld.sway_angle_deg,
                fretting,
                "2-3 (8)",
                "deg",
                "below 5 degrees fretting wear may occur (no oil film): consult Harmonic Drive Systems",
            )
        )
    if ld.required_life_h is not None:
        used = life if sway_life is None else sway_life
        name, section = (
            ("bearing life L10", "2-3 (7)") if sway_life is None else ("bearing sway life", "2-3 (8)")
        )
        note = f"X = {x}, Y = {y}; " + LOAD_FACTOR_NOTE
        if sway_life is not None:
            note += "; " + SWAY_SPEED_NOTE
        checks.append(at_least(name, used, ld.required_life_h, section, "h", note))
    checks.append(
        at_least(
            "static safety factor",
            fs,
            static_safety_limit(ld.use),
            "2-3 (10)",
            "",
            f"fs = Co / Po for {ld.use} operation (precise >= 3, shock >= 2, normal >= 1.5)",
        )
    )
    return BearingResult(mmax, frav, faav, ratio, x, y, pc, life, sway_life, po, fs, tuple(checks))
