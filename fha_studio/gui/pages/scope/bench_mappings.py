"""The Bench tab's channel mapping, saved per instrument and offered again for the same one.

What the technician typed for an instrument (its channels, the rate, and which channels are the
encoder, the command lines, IN-POS, ALARM and ALM-A ... D: the *roles*) is kept in the user's
settings under the instrument's spec (``fx2lafw:conn=1.5``, ``demo``, ``sim-cn2``) once a stream
with it started, so the next session with the same analyzer on the same drive starts with the
same wiring.
"""

from __future__ import annotations

import json

from PySide6.QtCore import QSettings

#: The settings key: one JSON object, instrument spec -> fields.
SETTINGS_KEY = "bench/mappings"
#: The fields of a mapping (the Bench tab's line edits).
FIELDS = ("channels", "rate", "encoder", "command", "in_position", "alarm", "alm_a", "alm_b", "alm_c",
          "alm_d")
#: Fields kept only when given (a mapping of an older version has none).
OPTIONAL = ("alarm", "alm_a", "alm_b", "alm_c", "alm_d")
#: Instruments remembered at most (the least recently used go first).
MAX_INSTRUMENTS = 50


def _all() -> dict[str, dict[str, str]]:
    raw = QSettings().value(SETTINGS_KEY, "")
    try:
        data = json.loads(raw) if isinstance(raw, str) and raw else {}
    except ValueError:
        return {}  # a damaged entry is forgotten, not fatal
    if not isinstance(data, dict):
        return {}
    return {str(spec): {k: str(v) for k, v in fields.items() if k in FIELDS}
            for spec, fields in data.items() if isinstance(fields, dict)}


def saved(spec: str) -> dict[str, str] | None:
    """The fields last used with the instrument ``spec``, or None."""
    return _all().get(spec) if spec else None


def save(spec: str, fields: dict[str, str]) -> None:
    """Keep ``fields`` for the instrument ``spec`` (the newest last)."""
    if not spec:
        return
    data = _all()
    data.pop(spec, None)
    data[spec] = {k: fields.get(k, "") for k in FIELDS if k not in OPTIONAL or fields.get(k)}
    while len(data) > MAX_INSTRUMENTS:
        data.pop(next(iter(data)))
    QSettings().setValue(SETTINGS_KEY, json.dumps(data))
