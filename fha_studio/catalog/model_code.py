"""The FHA-C model code (1-2, 3-1): ``FHA-<frame>-<ratio>-<encoder>[-<options>]``.

Examples: ``FHA-25C-50-US250``, ``FHA-32C-100-S248-B``, ``FHA-17C-50-US250-B-L``.

Separator rule: the options follow the encoder code after a hyphen. Each option may stand in its
own hyphen-separated group (``-B-L``), or several may run together in one group (``-BL``); both
mean the same because the option codes are unambiguous (``F5`` is the only two-character code and
``5`` appears in no other). Case and surrounding blanks are ignored. The canonical form
(:attr:`ModelCode.code`, ``str(code)``) writes each option in its own group in the order of 1-2
(A B L C K W D F5 E).
"""

from __future__ import annotations

from dataclasses import dataclass

from fha_studio.catalog.tables import FRAMES, RATIOS, encoder_codes, option_table

OPTION_ORDER: tuple[str, ...] = ("A", "B", "L", "C", "K", "W", "D", "F5", "E")


class ModelCodeError(ValueError):
    """A model code the manual does not allow; the message says what is wrong and what is allowed."""

    def __init__(self, code: object, problem: str, allowed: str):
        self.code = code
        self.problem = problem
        self.allowed = allowed
        super().__init__(f"model code {code!r}: {problem}; {allowed}")


@dataclass(frozen=True)
class ModelCode:
    """A parsed model code.

    frame: "17C" | "25C" | "32C" | "40C"; ratio: 50 | 100 | 160; encoder: "incremental" | "absolute";
    encoder_code: "US250" | "S248"; options: frozenset of "A B L C K W D F5 E";
    supply_voltage: 100 (option A, AC100V) else 200 (V).
    """

    frame: str
    ratio: int
    encoder: str
    encoder_code: str
    options: frozenset[str] = frozenset()

    @property
    def supply_voltage(self) -> int:
        """Supply voltage in V: 100 with option A (4-1), else 200."""
        return 100 if "A" in self.options else 200

    @property
    def has_brake(self) -> bool:
        """Option B (4-2): brake for motor."""
        return "B" in self.options

    @property
    def code(self) -> str:
        """The canonical model code string, options in the order of 1-2, each in its own group."""
        parts = ["FHA", self.frame, str(self.ratio), self.encoder_code]
        parts += [o for o in OPTION_ORDER if o in self.options]
        return "-".join(parts)

    @property
    def base_code(self) -> str:
        """The code without options, e.g. ``FHA-25C-50-US250``."""
        return f"FHA-{self.frame}-{self.ratio}-{self.encoder_code}"

    def __str__(self) -> str:
        return self.code


def _split_options(text: object, groups: list[str]) -> list[str]:
    options: list[str] = []
    allowed = f"allowed options: {' '.join(OPTION_ORDER)}, e.g. -B-L or -BL"
    for group in groups:
        if not group:
            raise ModelCodeError(
                text, "empty option group (two hyphens in a row or a trailing hyphen)", allowed
            )
        i = 0
        while i < len(group):
            if group.startswith("F5", i):
                options.append("F5")
                i += 2
            elif group[i] in OPTION_ORDER:
                options.append(group[i])
                i += 1
            else:
                bad = "F (the 5 m cable option is F5)" if group[i] == "F" else repr(group[i])
                raise ModelCodeError(text, f"unknown option {bad} in '{group}'", allowed)
    return options


#: The actuator FHA Studio starts with until the user names one: the embedded simulated drive's
#: actuator, the sizing page's first choice, the scope's scaling before a model code is known.
DEFAULT_ACTUATOR = "FHA-25C-50-US250"


def parse_model_code(text: str) -> ModelCode:
    """Parse a model code such as ``FHA-32C-100-S248-B``; raises :class:`ModelCodeError`."""
    if not isinstance(text, str):
        raise ModelCodeError(text, f"expected a string, got {type(text).__name__}", "e.g. FHA-25C-50-US250")
    s = text.strip().upper()
    if any(ch.isspace() for ch in s):
        raise ModelCodeError(text, "contains a blank", "write the code without blanks, e.g. FHA-25C-50-US250")
    parts = s.split("-")
    shape = (
        "the form is FHA-<frame>-<ratio>-<encoder>[-<options>], e.g. FHA-25C-50-US250 or FHA-32C-100-S248-B"
    )
    if parts[0] != "FHA":
        if parts[0].startswith("FHA") and len(parts[0]) > 3:
            raise ModelCodeError(text, f"missing hyphen after FHA in '{parts[0]}'", shape)
        raise ModelCodeError(text, "does not start with FHA-", shape)
    if len(parts) < 4:
        raise ModelCodeError(text, "too few parts", shape)
    frame, ratio_text, encoder_code = parts[1], parts[2], parts[3]
    if frame not in FRAMES:
        hint = f" (did you mean {frame}C?)" if f"{frame}C" in FRAMES else ""
        raise ModelCodeError(text, f"unknown frame '{frame}'{hint}", f"allowed frames: {', '.join(FRAMES)}")
    if not (ratio_text.isascii() and ratio_text.isdigit()) or int(ratio_text) not in RATIOS:
        raise ModelCodeError(
            text, f"unknown reduction ratio '{ratio_text}'", f"allowed ratios: {', '.join(map(str, RATIOS))}"
        )
    encoders = encoder_codes()
    if encoder_code not in encoders:
        hint = " (1-4-2 prints US248, the absolute system is S248)" if encoder_code == "US248" else ""
        allowed = ", ".join(f"{c} ({e})" for c, e in encoders.items())
        raise ModelCodeError(text, f"unknown encoder '{encoder_code}'{hint}", f"allowed encoders: {allowed}")
    options = _split_options(text, parts[4:])
    seen: set[str] = set()
    for o in options:
        if o in seen:
            raise ModelCodeError(text, f"option {o} given twice", "give each option once")
        seen.add(o)
    for spec in option_table():
        if spec.code in seen and frame not in spec.frames:
            allowed_frames = ", ".join("FHA-" + f for f in spec.frames)
            raise ModelCodeError(
                text,
                f"option {spec.code} ({spec.name}) is not available for FHA-{frame}",
                f"{spec.section}: option {spec.code} is for {allowed_frames} only",
            )
    return ModelCode(
        frame=frame,
        ratio=int(ratio_text),
        encoder=encoders[encoder_code],
        encoder_code=encoder_code,
        options=frozenset(options),
    )
