"""What a tuning did, for the commissioning report: before and after, figures, who, when."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from fha_studio.hardware.parameters import ParameterModel, load_parameter_model
from fha_studio.logic.wording import NO_BREAK_SPACE, with_unit

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


def figure_words(key: str, value: float | None, unit: str, manual_units: bool = False) -> str:
    """A figure in words: the value and unit, or why there is none. ``manual_units``: units as
    the FHA-C manual prints them ("°", not "deg"), for what a person reads."""
    if value is None:
        if key != "gain_margin_db":
            return "none found"
        return NO_PHASE_CROSSING.replace("-180 deg", "−180°") if manual_units else NO_PHASE_CROSSING
    return with_unit(f"{value:.3g}", unit, on_page=True) if manual_units else f"{value:.3g} {unit}"


def result_figure_words(result: Mapping[str, Any], key: str, unit: str, manual_units: bool = False) -> str:
    """A measurement's figure in words. A measured gain margin is taken over the measured band
    alone: where the phase stays above -180 deg there, the crossing (if any) lies beyond it and
    the margin is the model's, said as such (not "none", beside the model's figure in dB)."""
    value, top_hz = result.get(key), result.get("measured_to_hz")
    if key != "gain_margin_db" or value is not None or not top_hz:
        return figure_words(key, value, unit, manual_units)
    predicted = (result.get("predicted") or {}).get("gain_margin_db")
    minus_180 = "−180°" if manual_units else "-180 deg"
    space = NO_BREAK_SPACE if manual_units else " "  # a page's label may wrap: never between figure and unit
    model = f"{predicted:.3g}{space}dB by the model" if predicted is not None else "none by the model either"
    return f"{model} (the measured phase stays above {minus_180} up to {top_hz:.0f}{space}Hz)"


def _figures(result: Mapping[str, Any]) -> str:
    return ", ".join(f"{words} {result_figure_words(result, key, unit)}" for key, words, unit in FIGURES)


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
