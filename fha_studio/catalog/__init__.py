"""The actuator catalogue of the FHA-C manual (Chapters 1, 2, 3 and 4), loaded from resources/catalog.

Public API: :func:`parse_model_code` -> :class:`ModelCode` (raises :class:`ModelCodeError`),
:func:`get_actuator` -> :class:`Actuator`, :func:`compatible_drivers`, :func:`all_model_codes`,
:func:`frames`, :func:`ratios`, :func:`options_allowed`, :func:`environment`; the raw tables (incl.
4-1 as printed, 1-7, 1-8, 1-14 cables, 4-7-1 sensors, 1-10 rotary direction) are in
:mod:`fha_studio.catalog.tables`, the manual's contradictions in :func:`discrepancies`.
"""

from fha_studio.catalog.actuator import (
    Actuator,
    Bearing,
    Brake,
    CableLeads,
    MechanicalAccuracy,
    ScrewTightening,
    TighteningTorques,
    TorsionalStiffness,
    all_model_codes,
    compatible_drivers,
    frames,
    get_actuator,
    options_allowed,
    ratios,
)
from fha_studio.catalog.model_code import (
    DEFAULT_ACTUATOR,
    OPTION_ORDER,
    ModelCode,
    ModelCodeError,
    parse_model_code,
)
from fha_studio.catalog.tables import Discrepancy, Environment, Lead, discrepancies, environment

__all__ = [
    "DEFAULT_ACTUATOR",
    "OPTION_ORDER",
    "Actuator",
    "Bearing",
    "Brake",
    "CableLeads",
    "Discrepancy",
    "Environment",
    "Lead",
    "MechanicalAccuracy",
    "ModelCode",
    "ModelCodeError",
    "ScrewTightening",
    "TighteningTorques",
    "TorsionalStiffness",
    "all_model_codes",
    "compatible_drivers",
    "discrepancies",
    "environment",
    "frames",
    "get_actuator",
    "options_allowed",
    "parse_model_code",
    "ratios",
]
