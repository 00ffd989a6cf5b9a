"""The selection calculator of FHA-C manual Chapter 2 and its appendices. No Qt.

- :mod:`.duty` (2-4), :mod:`.bearing` (2-3), :mod:`.inertia` (Appendix 2), :mod:`.units`
  (Appendix 1): pure functions of SI numbers.
- :func:`evaluate` (explicit ratings) and :func:`size_axis` (a catalogue code): every figure and
  check of Chapter 2 for one duty cycle, as a :class:`SizingResult` of :class:`Check` items;
  :func:`suggest_actuators`: the catalogue actuators a duty passes on.
"""

from fha_studio.logic.sizing.axis import (
    ActuatorRatings,
    DutyCycle,
    OperatingPoint,
    SizingError,
    SizingResult,
    actuator_ratings,
    evaluate,
    ratings_from_actuator,
    size_all,
    size_axis,
    suggest_actuators,
)
from fha_studio.logic.sizing.bearing import BearingLoads, BearingRatings, BearingResult, LoadSegment
from fha_studio.logic.sizing.checks import Check

__all__ = [
    "ActuatorRatings",
    "BearingLoads",
    "BearingRatings",
    "BearingResult",
    "Check",
    "DutyCycle",
    "LoadSegment",
    "OperatingPoint",
    "SizingError",
    "SizingResult",
    "actuator_ratings",
    "evaluate",
    "ratings_from_actuator",
    "size_all",
    "size_axis",
    "suggest_actuators",
]
