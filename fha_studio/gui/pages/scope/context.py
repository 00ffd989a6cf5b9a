"""What the scope must know of the axis it shows: :class:`ScopeContext`."""

from __future__ import annotations

from dataclasses import dataclass

from fha_studio.catalog import DEFAULT_ACTUATOR, Actuator, get_actuator


@dataclass(frozen=True)
class ScopeContext:
    """What the scope must know of the axis: the actuator (resolution, ratio) and the load.

    ``actuator_declared`` is False when nobody said which actuator is on the axis and
    ``actuator`` is only assumed (the view says so)."""

    actuator: str = DEFAULT_ACTUATOR
    load_inertia_kgm2: float = 0.0
    supply_voltage: int = 200
    driver: str = "HA-655"
    actuator_declared: bool = True

    def actuator_data(self) -> Actuator:
        return get_actuator(self.actuator)


def actuator_text(context: ScopeContext) -> str:
    """The actuator as the scope names it (saying so when it is only assumed)."""
    if context.actuator_declared:
        return context.actuator
    return f"{context.actuator} (assumed: no actuator given on the Connection page)"
