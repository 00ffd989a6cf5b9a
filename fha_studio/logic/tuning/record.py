"""What a tuning did, for the commissioning report: before and after, figures, who, when."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from fha_studio.hardware.parameters import ParameterModel, load_parameter_model

FIGURES = (("resonance_hz", "resonance", "Hz"), ("antiresonance_hz", "anti-resonance", "Hz"),
           ("load_inertia_estimate_kgm2", "load inertia estimate", "kg·m²"),
           ("gain_margin_db", "gain margin", "dB"), ("phase_margin_deg", "phase margin", "deg"),
           ("crossover_hz", "crossover", "Hz"), ("bandwidth_hz", "bandwidth", "Hz"))


@dataclass(frozen=True)
class TuningRecord:
    """One measurement (``before``), the proposal applied (``items``, its ``aim``), and the
    measurement after writing them (``after``, None when nothing was applied)."""

    at: str
    who: str
    before: Mapping[str, Any]
    items: Mapping[str, int] = field(default_factory=dict)
    aim: str = ""
    warning: str | None = None
    after: Mapping[str, Any] | None = None


#: a gain margin python-control cannot give: the loop's phase never reaches -180 deg
NO_PHASE_CROSSING = "none (the phase never reaches -180 deg)"


def figure_words(key: str, value: float | None, unit: str) -> str:
    """A figure in words: the value and unit, or why there is none."""
    if value is None:
        return NO_PHASE_CROSSING if key == "gain_margin_db" else "none found"
    return f"{value:.3g} {unit}"


def _figures(result: Mapping[str, Any]) -> str:
    return ", ".join(f"{words} {figure_words(key, result.get(key), unit)}" for key, words, unit in FIGURES)


def items_words(items: Mapping[str, int], parameters: ParameterModel) -> str:
    """Tune items as the front panel knows them: "tune 0 Speed loop gain (Kv) 60 Hz, ..."."""
    words = []
    for key, value in items.items():
        try:
            item = parameters.by_key(key)
        except KeyError:
            words.append(f"{key} {value}")
            continue
        unit = f" {item.unit}" if item.unit else ""
        words.append(f"{item.mode} {item.number} {item.name} {value}{unit}")
    return ", ".join(words)


def tuning_notes(records: Sequence[TuningRecord],
                 parameters: ParameterModel | None = None) -> list[tuple[str, str]]:
    """The records as the report's notes: (text, who); the items in the front panel's words
    (``parameters``: the drive's parameter model, the HA-655's when not given)."""
    model = parameters or load_parameter_model("HA-655")
    notes = []
    for r in records:
        items = items_words(dict(r.before.get("items", {})), model)
        text = f"Tuning ({r.at}): measured with {items}: {_figures(r.before)}"
        if r.after is not None:
            text += (f". Applied ({r.aim}) {items_words(dict(r.items), model)}, measured again: "
                     f"{_figures(r.after)}")
        if r.warning:
            text += f". Warning: {r.warning}"
        notes.append((text, r.who))
    return notes
