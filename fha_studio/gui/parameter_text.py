"""How the parameter editor and the parameter-file comparison show a driver item's value and read
back what was typed: in the item's unit, or as a choice with its meaning."""

from __future__ import annotations

from fha_studio.hardware.parameters import MODE_WORDS  # the manual's word for each mode

__all__ = ["MODE_WORDS", "parse_value", "range_text", "value_text"]


def parse_value(item, text: str) -> int:
    """The wire integer for what was typed: a choice number, or a value in the item's unit.
    Raises ValueError saying the allowed range."""
    text = text.strip()
    if item.choices:
        head = text.split(":", 1)[0].strip()
        try:
            wire = int(head)
        except ValueError:
            raise ValueError(f"{item.name}: choose one of {_choices(item)}") from None
        if wire not in item.choices:
            raise ValueError(f"{item.name}: {wire} is not allowed; choose one of {_choices(item)}")
        return wire
    try:
        value = float(text.replace(",", "."))
    except ValueError:
        raise ValueError(f"{item.name}: '{text}' is not a number; allowed {range_text(item)}") from None
    wire = round(value / item.scale)
    if not item.minimum <= wire <= item.maximum or abs(wire * item.scale - value) > item.scale * 0.5 + 1e-9:
        raise ValueError(f"{item.name}: {text} is outside the allowed range {range_text(item)}")
    return wire


def _choices(item) -> str:
    return ", ".join(f"{k} ({v})" for k, v in item.choices.items())


def _num(value: float) -> str:
    return f"{value:g}"


def range_text(item) -> str:
    if item.choices:
        return " / ".join(str(k) for k in item.choices)
    return f"{_num(item.to_unit(item.minimum))} … {_num(item.to_unit(item.maximum))}"


def value_text(item, wire: int | None) -> str:
    if wire is None:
        return ""
    if item.choices:
        return f"{wire}: {item.choices.get(wire, '?')}"
    return _num(item.to_unit(wire))
