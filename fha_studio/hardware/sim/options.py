"""How a simulated drive is chosen: :class:`SimConfig`, built from keywords, a ``sim://`` URL or the CLI.

URL form (docs/protocol.md, transports)::

    sim://FHA-25C-50-US250?load_inertia=1.5&brake=1&sensors=1&paced=0&eeprom=PATH
        &effects=coulomb_friction:torque_nm=8;viscous_friction:coefficient_nm_s_per_rad=2

Options (all optional):

=================  ==========================================================================
``driver``         driver model, e.g. ``HA-655-2-200``; default: the first HA-655 of the
                   combination table (FHA-C manual 1-3) for the actuator and supply voltage
``load_inertia``   load inertia on the output [kg m^2] (``load_inertia_kgm2`` also accepted)
``brake``          1/0: fit or leave out the motor brake (default: option B of the model code)
``sensors``        1/0: fit or leave out the option-L sensor set (default: option L of the code)
``origin_deg``,    angles of the origin slit and of the dogs of limit switch 1 (CCW end) and
``ls1_deg``,       limit switch 2 (CW end), output flange, CW positive seen from the flange
``ls2_deg``
``effects``        physical effects, ``ID:NAME=VALUE,NAME=VALUE;ID...``; ``effect=`` may repeat
``eeprom``         EEPROM file; ``user`` = the user data directory; default: a temporary file
                   removed when the drive closes
``paced``          1 (default): replies paced like a 19200 baud line; 0: at memory speed
``quantised``      1 (default): the servo loops see whole encoder pulses (a real drive's current
                   noise); 0: ideal feedback
``oww_clear_s``    how long OWW takes to clear the multi-turn data [s] (default 5)
``packed_trace``   1 (default): trace blocks also in the packed encoding (TRP, listed in CAP);
                   0: text blocks (TRB) only, as a drive from before the packed encoding
``profile``        ``full`` (default): every command of docs/protocol.md; ``documented``: only
                   what the public HA-655 manual documents (DGR, OWW; ``x`` to the rest, ``s`` to
                   everything while the servo is on). Servo-ON then comes from the simulated CN2
                   input (``SimDrive.set_servo``), as on a real drive from the controller
=================  ==========================================================================
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field, replace
from typing import Any
from urllib.parse import parse_qs, unquote, urlsplit

from fha_studio import plausible
from fha_studio.catalog import DEFAULT_ACTUATOR

#: The command sets a simulated drive can speak (see ``profile`` above).
PROFILES = ("full", "documented")


class SimConfigError(ValueError):
    """A simulated-drive option is wrong; the message names the option and what is allowed."""


@dataclass(frozen=True)
class SimConfig:
    """Everything that chooses one simulated drive. Units in the names."""

    actuator: str = DEFAULT_ACTUATOR
    driver: str | None = None
    load_inertia_kgm2: float = 0.0
    brake: bool | None = None
    sensors: bool | None = None
    origin_deg: float | None = None
    ls1_deg: float | None = None
    ls2_deg: float | None = None
    effects: dict[str, dict[str, float]] = field(default_factory=dict)
    eeprom: str | None = None
    paced: bool = True
    quantised: bool = True
    oww_clear_s: float | None = None
    packed_trace: bool = True
    profile: str = "full"

    def __post_init__(self) -> None:
        if self.profile not in PROFILES:
            raise SimConfigError(
                f"simulated drive option profile: {self.profile!r} is not one of {', '.join(PROFILES)}"
            )
        if not isinstance(self.actuator, str) or not self.actuator.strip():
            raise SimConfigError("simulated drive: an actuator model code is needed, e.g. FHA-25C-50-US250")
        _ranged("load_inertia_kgm2", self.load_inertia_kgm2, plausible.LOAD_INERTIA_KGM2)
        for name in ("origin_deg", "ls1_deg", "ls2_deg"):
            if getattr(self, name) is not None:
                _ranged(name, getattr(self, name), plausible.SENSOR_ANGLE_DEG)
        if self.oww_clear_s is not None:
            _ranged("oww_clear_s", self.oww_clear_s, plausible.OWW_CLEAR_S)
        for effect_id, params in self.effects.items():
            for name, value in params.items():
                allowed = plausible.EFFECT_PARAMETER_RANGES.get(name)
                if allowed is not None:
                    _ranged(f"{effect_id}.{name}", value, allowed)

    def replace(self, **changes: Any) -> SimConfig:
        return replace(self, **changes)


_DECIMAL = re.compile(r"\s*[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?\s*")


def _finite(name: str, value: Any, minimum: float | None = None) -> float:
    if isinstance(value, str) and not _DECIMAL.fullmatch(value):  # float() takes "1_0", "inf"
        raise SimConfigError(f"simulated drive option {name}: '{value[:40]}' is not a number")
    if isinstance(value, bool):
        raise SimConfigError(f"simulated drive option {name}: {value} is not a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise SimConfigError(f"simulated drive option {name}: {value!r} is not a number") from None
    if not math.isfinite(number) or (minimum is not None and number < minimum):
        bound = f" >= {minimum:g}" if minimum is not None else ""
        raise SimConfigError(f"simulated drive option {name}: {value!r} must be a finite number{bound}")
    return number


def _ranged(name: str, value: Any, allowed: plausible.Range) -> float:
    number = _finite(name, value)
    if not allowed.contains(number):
        raise SimConfigError(f"simulated drive option {name}: {number:g} is outside {allowed.allowed()} "
                             f"({allowed.reason})")
    return number


def _flag(name: str, text: str) -> bool:
    lowered = text.strip().lower()
    if lowered in ("1", "true", "yes", "on"):
        return True
    if lowered in ("0", "false", "no", "off"):
        return False
    raise SimConfigError(f"simulated drive option {name}: {text!r} is not 1/0 (or true/false)")


def parse_effect(spec: str) -> tuple[str, dict[str, float]]:
    """``"coulomb_friction:torque_nm=8"`` -> ``("coulomb_friction", {"torque_nm": 8.0})``.

    Whether the id and names exist is checked by the physics (Effects.from_dict), which names them.
    """
    effect_id, _, rest = spec.strip().partition(":")
    effect_id = effect_id.strip()
    if not effect_id:
        raise SimConfigError(f"effect '{spec.strip()}': expected ID or ID:NAME=VALUE,NAME=VALUE, "
                             "e.g. coulomb_friction:torque_nm=8")
    params: dict[str, float] = {}
    for part in filter(None, (p.strip() for p in rest.split(","))):
        name, eq, value = part.partition("=")
        if not eq or not name.strip():
            raise SimConfigError(f"effect {spec!r}: parameter {part!r} is not NAME=VALUE")
        name = name.strip()
        allowed = plausible.EFFECT_PARAMETER_RANGES.get(name)
        where = f"{effect_id}.{name}"
        params[name] = _ranged(where, value, allowed) if allowed else _finite(where, value)
    return effect_id, params


def parse_effects(specs: list[str]) -> dict[str, dict[str, float]]:
    """Several effect specs (each may hold several, separated by ``;``) -> {id: params}."""
    effects: dict[str, dict[str, float]] = {}
    for spec in specs:
        if not spec.strip():
            raise SimConfigError("effect '': empty; expected ID or ID:NAME=VALUE,NAME=VALUE, "
                                 "e.g. coulomb_friction:torque_nm=8")
        ones = [s.strip() for s in spec.split(";") if s.strip()]
        if not ones:
            raise SimConfigError(f"effect '{spec.strip()}': no effect in it; expected ID or "
                                 "ID:NAME=VALUE,NAME=VALUE, e.g. coulomb_friction:torque_nm=8")
        for one in ones:
            effect_id, params = parse_effect(one)
            effects[effect_id] = params
    return effects


_URL_KEYS = {
    "driver", "load_inertia", "load_inertia_kgm2", "brake", "sensors", "origin_deg", "ls1_deg",
    "ls2_deg", "effects", "effect", "eeprom", "paced", "quantised", "oww_clear_s",
    "packed_trace", "profile",
}


def config_from_url(url: str) -> SimConfig:
    """A SimConfig from ``sim://ACTUATOR?options``; SimConfigError names a bad option."""
    parts = urlsplit(url)
    if parts.scheme.lower() != "sim":
        raise SimConfigError(f"{url!r} is not a sim:// URL")
    actuator = unquote(parts.netloc or parts.path.lstrip("/")).strip()
    if not actuator:
        raise SimConfigError(f"{url!r}: the actuator model code is missing, e.g. sim://FHA-25C-50-US250")
    query = parse_qs(parts.query, keep_blank_values=True)
    unknown = set(query) - _URL_KEYS
    if unknown:
        raise SimConfigError(
            f"{url!r}: unknown option(s) {', '.join(sorted(unknown))}; known: {', '.join(sorted(_URL_KEYS))}"
        )

    def last(key: str) -> str | None:
        return query[key][-1] if key in query else None

    values: dict[str, Any] = {"actuator": actuator}
    if last("driver") is not None:
        values["driver"] = last("driver")
    inertia = last("load_inertia_kgm2") if last("load_inertia_kgm2") is not None else last("load_inertia")
    if inertia is not None:
        values["load_inertia_kgm2"] = _ranged("load_inertia", inertia, plausible.LOAD_INERTIA_KGM2)
    for key in ("brake", "sensors", "paced", "quantised", "packed_trace"):
        flag = last(key)
        if flag is not None:
            values[key] = _flag(key, flag)
    for key in ("origin_deg", "ls1_deg", "ls2_deg", "oww_clear_s"):
        if last(key) is not None:
            values[key] = _finite(key, last(key))
    specs = query.get("effects", []) + query.get("effect", [])
    if specs:
        values["effects"] = parse_effects(specs)
    if last("eeprom") is not None:
        values["eeprom"] = last("eeprom")
    profile = last("profile")
    if profile is not None:
        values["profile"] = profile.strip().lower()
    return SimConfig(**values)
