"""The model check: where simulation and measurement disagree, which effect is missing,
its parameters, the updated model, and the gap on held-out data. numpy/scipy only, no Qt.

Entry point: :func:`run_modelcheck(recording) <run_modelcheck>` -> :class:`ModelCheckResult`, whose
fields hold each step's arrays (see result.py): ``residual`` (step 1), ``where`` (step 2),
``channels``/``effects``/``ambiguities``/``structures``/``detection_limits`` (step 3),
``updated_model`` (step 4), ``gap`` and ``resimulation`` (step 5); ``summary_lines()`` and
``to_json()`` for the CLI.
"""

from fha_studio.logic.modelcheck.axis import ModelCheckError
from fha_studio.logic.modelcheck.entry import run_modelcheck
from fha_studio.logic.modelcheck.result import (
    Ambiguity,
    Binned,
    ChannelReport,
    ChannelWhere,
    DetectionLimit,
    Effect,
    Gap,
    ModelCheckResult,
    Resimulation,
    Structure,
)

__all__ = [
    "Ambiguity",
    "Binned",
    "ChannelReport",
    "ChannelWhere",
    "DetectionLimit",
    "Effect",
    "Gap",
    "ModelCheckError",
    "ModelCheckResult",
    "Resimulation",
    "Structure",
    "run_modelcheck",
]
