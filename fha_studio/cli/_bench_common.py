"""What ``bench import`` and ``bench record`` share: the drive's parameter file read for the
decoding, and a summary made fit for JSON."""

from __future__ import annotations

import math
from typing import Any


def parameter_values(path: str) -> dict[tuple[str, int], int]:
    from fha_studio.hardware.parameters import load_parameter_model
    from fha_studio.logic.bench.importer import BenchImportError
    from fha_studio.logic.paramfile import ParameterFileError, load_parameter_file

    try:
        loaded = load_parameter_file(path, load_parameter_model("HA-655"))
        if loaded.driver == "HA-675":
            loaded = load_parameter_file(path, load_parameter_model("HA-675"))
    except ParameterFileError as exc:
        raise BenchImportError(str(exc)) from None
    return dict(loaded.values)


def finite(obj: Any) -> Any:
    if isinstance(obj, float) and not math.isfinite(obj):
        return None
    if isinstance(obj, dict):
        return {k: finite(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [finite(v) for v in obj]
    return obj
