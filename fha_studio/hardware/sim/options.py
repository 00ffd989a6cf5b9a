"""How a simulated drive is chosen: :class:`SimConfig`, built from keywords, a ``sim://`` URL or the CLI.

URL form (docs/protocol.md, transports)::

    sim://FHA-25C-50-US250?load_inertia=1.5&brake=1&sensors=1&paced=0&eeprom=PATH
        &effects=coulomb_friction:torque_nm=8;viscous_friction:coefficient_nm_s_per_rad=2
    sim://FHA-25C-50-US250?catalogue_friction=1

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
``catalogue_friction``
                   1: the actuator's friction as the catalogue gives it: TF = Kt x Im - TM, the
                   friction torque at maximum speed (FHA-C manual 2-4-4), half Coulomb and half
                   viscous (``physics.catalogue_effects``; the split is an assumption), merged
                   with ``effects`` (an effect given there wins over the catalogue's of the same
                   id). 0 (default): frictionless, the model check's nominal axis: after an
                   alarm it coasts on for ever, and a steady jog draws no current
``eeprom``         EEPROM file; ``user`` = the user data directory; default: a temporary file
                   removed when the drive closes
``paced``          1 (default): replies paced like a 19200 baud line; 0: at memory speed
``stepped``        0 (default): the drive runs in real time in its own thread; 1: its time
                   stands still until the port's holder advances it
                   (``port.sim_drive.advance(seconds)``), so a test holds a motion for exactly
                   that much drive time however loaded the machine is
``quantised``      1 (default): the servo loops see whole encoder pulses (a real drive's current
                   noise); 0: ideal feedback
``oww_clear_s``    how long OWW takes to clear the multi-turn data [s] (default 5)
``packed_trace``   1 (default): trace blocks also in the packed encoding (TRP, listed in CAP);
                   0: text blocks (TRB) only, as a drive from before the packed encoding
``profile``        ``full`` (default): every command of docs/protocol.md; ``documented``: only
                   what the public HA-655 manual documents (DGR, OWW; ``x`` to the rest, ``s`` to
                   everything while the servo is on). Servo-ON then comes from the simulated CN2
                   input (``SimDrive.set_servo``), as on a real drive from the controller
``wiring``         a wiring fault (training): ``ok`` (default), ``motor_swapped``,
                   ``motor_open``, ``encoder_swapped``, ``encoder_open`` (docs/sim.md says what each
                   does)
``brake_supply``   1 (default) / 0: the brake's 24 V supply is missing, the brake never releases
``battery``        the absolute encoder's backup battery: ``ok`` (default), ``low`` (alarm 56 at
                   power-on), ``lost`` (alarm 56 and the multi-turn data lost)
``preset``         items as the drive is delivered, ``MODE.NUMBER=VALUE,...`` (e.g.
                   ``system.8=1,system.6=1``); stored into a new EEPROM only
``training``       a token from :func:`register_training`: hidden options of a training drive,
                   merged in (they never appear in the address a person sees)
=================  ==========================================================================
"""

from __future__ import annotations

import difflib
import math
import re
import secrets
import threading
from dataclasses import dataclass, field, replace
from enum import StrEnum
from typing import Any
from urllib.parse import parse_qs, unquote, urlsplit

from fha_studio import plausible
from fha_studio.catalog import DEFAULT_ACTUATOR
from fha_studio.hardware.sim.journal import Journal


class Profile(StrEnum):
    """The command set a simulated drive speaks (see ``profile`` above)."""

    FULL = "full"
    DOCUMENTED = "documented"


class Wiring(StrEnum):
    """A wiring fault a simulated drive can carry (see ``wiring`` above and docs/sim.md)."""

    OK = "ok"
    MOTOR_SWAPPED = "motor_swapped"
    MOTOR_OPEN = "motor_open"
    ENCODER_SWAPPED = "encoder_swapped"
    ENCODER_OPEN = "encoder_open"


class Battery(StrEnum):
    """The state of the absolute encoder's backup battery (see ``battery`` above)."""

    OK = "ok"
    LOW = "low"
    LOST = "lost"


PROFILES = tuple(Profile)
WIRING_FAULTS = tuple(Wiring)
BATTERY_STATES = tuple(Battery)


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
    #: the catalogue's friction (TF of 2-4-4) under the explicit effects (see the table above)
    catalogue_friction: bool = False
    eeprom: str | None = None
    paced: bool = True
    #: the drive's time advances only by SimDrive.advance (no real-time thread)
    stepped: bool = False
    quantised: bool = True
    oww_clear_s: float | None = None
    packed_trace: bool = True
    profile: Profile = Profile.FULL
    wiring: Wiring = Wiring.OK
    brake_supply: bool = True
    battery: Battery = Battery.OK
    #: items stored into a new EEPROM, as delivered: ((mode, number, value), ...)
    preset: tuple[tuple[str, int, int], ...] = ()
    #: the training registration this drive belongs to (its journal), or None
    training: str | None = None

    def __post_init__(self) -> None:
        kinds: tuple[tuple[str, type[StrEnum]], ...] = (
            ("profile", Profile), ("wiring", Wiring), ("battery", Battery)
        )
        for name, kind in kinds:  # the text of a URL or a keyword becomes its kind
            value = getattr(self, name)
            try:
                object.__setattr__(self, name, kind(value))
            except ValueError:
                raise SimConfigError(
                    f"simulated drive option {name}: {value!r} is not one of {', '.join(kind)}"
                ) from None
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


def parse_preset(text: str) -> tuple[tuple[str, int, int], ...]:
    """``"system.8=1,system.6=1"`` -> ``(("system", 8, 1), ("system", 6, 1))``. Whether an item
    and its value exist is checked by the drive's parameter model when it stores them."""
    items: list[tuple[str, int, int]] = []
    for part in filter(None, (p.strip() for p in text.split(","))):
        m = re.fullmatch(r"(monitor|tune|system|test)\.([0-9]+)\s*=\s*([+-]?[0-9]+)", part)
        if m is None:
            raise SimConfigError(f"simulated drive option preset: {part!r} is not MODE.NUMBER=VALUE "
                                 "(MODE: tune, system or test), e.g. system.8=1")
        items.append((m.group(1), int(m.group(2)), int(m.group(3))))
    return tuple(items)


@dataclass
class TrainingRegistration:
    """A training drive's hidden options and its journal (what the trainee did to the drive)."""

    token: str
    options: str  # a URL query string: the hidden faults
    journal: Journal


_TRAINING: dict[str, TrainingRegistration] = {}
_TRAINING_LOCK = threading.Lock()


def register_training(options: str) -> TrainingRegistration:
    """Registers hidden options (a URL query string, checked now) for a training drive; its
    address is then ``sim://ACTUATOR?training=TOKEN``, which says nothing of the faults.
    Raises SimConfigError for a bad option."""
    config_from_url(f"sim://{DEFAULT_ACTUATOR}?{options}")  # check them before anything uses them
    registration = TrainingRegistration(secrets.token_hex(6), options, Journal())
    with _TRAINING_LOCK:
        _TRAINING[registration.token] = registration
    return registration


def training_registration(token: str) -> TrainingRegistration | None:
    with _TRAINING_LOCK:
        return _TRAINING.get(token)


def forget_training(token: str) -> None:
    with _TRAINING_LOCK:
        _TRAINING.pop(token, None)


def public_url(url: str) -> str:
    """The address a person may see: a training drive's address without its options (they
    could name the hidden faults); any other address as it is."""
    parts = urlsplit(url)
    if parts.scheme.lower() != "sim" or "training" not in parse_qs(parts.query):
        return url
    return f"sim://{parts.netloc or parts.path.lstrip('/')} (training)"


#: What the status bar, the machine window's banner and the Connection page call a sim:// drive.
EMBEDDED_DRIVE = "embedded simulated drive"


def drive_words(url: str, *, detail: bool = False) -> str:
    """A drive's address as a person reads it: an embedded simulated drive in words, not by its
    address full of options (an EEPROM file's path among them); any other address as it is.

    ``detail`` adds its actuator and whether it has the friction the catalogue gives (TF, FHA-C
    manual 2-4-4), which decides how it moves. A training drive says only that it is one: its
    options could name the hidden faults."""
    parts = urlsplit(url)
    if parts.scheme.lower() != "sim":
        return url
    if not detail:
        return EMBEDDED_DRIVE
    actuator = unquote(parts.netloc or parts.path.lstrip("/")).split(" ")[0].strip()
    named = f"{EMBEDDED_DRIVE} {actuator}" if actuator else EMBEDDED_DRIVE
    query = parse_qs(parts.query)
    if "training" in query or url.endswith("(training)"):  # public_url's form of a training drive
        return f"{named} (training)"
    try:
        friction = _flag("catalogue_friction", query.get("catalogue_friction", ["0"])[-1])
    except SimConfigError:  # not a drive that connected: nothing to say of its friction
        return named
    return f"{named}, {'with' if friction else 'without'} the catalogue's friction (TF, 2-4-4)"


_URL_KEYS = {
    "driver", "load_inertia", "load_inertia_kgm2", "brake", "sensors", "origin_deg", "ls1_deg",
    "ls2_deg", "effects", "effect", "catalogue_friction", "eeprom", "paced", "stepped", "quantised",
    "oww_clear_s", "packed_trace", "profile", "wiring", "brake_supply", "battery", "preset", "training",
}


#: Where a person reads what each option means (the options are too many for one message line).
OPTIONS_DOCUMENTED_IN = "docs/sim.md"


def unknown_options_words(unknown: set[str]) -> str:
    """One line naming the options no simulated drive knows, a close known name where there is
    one, and where the options are documented. The address is not repeated: whoever shows the
    line names the port it could not open."""
    words = []
    for name in sorted(unknown):
        near = difflib.get_close_matches(name, sorted(_URL_KEYS), n=1)
        words.append(f"{name!r}" + (f" (did you mean {near[0]!r}?)" if near else ""))
    option = "option" if len(words) == 1 else "options"
    return (f"the simulated drive has no {option} {', '.join(words)}; "
            f"its options are listed in {OPTIONS_DOCUMENTED_IN}")


def config_from_url(url: str) -> SimConfig:
    """A SimConfig from ``sim://ACTUATOR?options``; SimConfigError names a bad option."""
    parts = urlsplit(url)
    if parts.scheme.lower() != "sim":
        raise SimConfigError(f"{url!r} is not a sim:// URL")
    actuator = unquote(parts.netloc or parts.path.lstrip("/")).strip()
    if not actuator:
        raise SimConfigError("the actuator model code is missing, e.g. sim://FHA-25C-50-US250")
    query = parse_qs(parts.query, keep_blank_values=True)
    unknown = set(query) - _URL_KEYS
    if unknown:
        raise SimConfigError(unknown_options_words(unknown))
    token = query["training"][-1] if "training" in query else None
    if token is not None:
        registration = training_registration(token)
        if registration is None:
            raise SimConfigError(f"{public_url(url)}: this training drive is no longer registered")
        hidden = parse_qs(registration.options, keep_blank_values=True)
        # the hidden options decide; the visible ones (paced, eeprom) add to them
        query = {**query, **hidden}

    def last(key: str) -> str | None:
        return query[key][-1] if key in query else None

    values: dict[str, Any] = {"actuator": actuator}
    if last("driver") is not None:
        values["driver"] = last("driver")
    inertia = last("load_inertia_kgm2") if last("load_inertia_kgm2") is not None else last("load_inertia")
    if inertia is not None:
        values["load_inertia_kgm2"] = _ranged("load_inertia", inertia, plausible.LOAD_INERTIA_KGM2)
    for key in ("brake", "sensors", "paced", "stepped", "quantised", "packed_trace", "catalogue_friction"):
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
    for key in ("wiring", "battery"):
        if last(key) is not None:
            values[key] = last(key).strip().lower()  # type: ignore[union-attr]
    if last("brake_supply") is not None:
        values["brake_supply"] = _flag("brake_supply", last("brake_supply"))  # type: ignore[arg-type]
    presets = query.get("preset", [])
    if presets:
        values["preset"] = sum((parse_preset(p) for p in presets), ())
    if token is not None:
        values["training"] = token
    return SimConfig(**values)
