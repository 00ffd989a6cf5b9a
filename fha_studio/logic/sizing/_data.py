"""The manual's sizing data from resources/sizing/*.toml, read once."""

from __future__ import annotations

import tomllib
from functools import cache
from typing import Any

from fha_studio.paths import resource


@cache
def load(name: str) -> dict[str, Any]:
    """The parsed ``resources/sizing/<name>.toml``."""
    with resource("sizing", f"{name}.toml").open("rb") as fh:
        return tomllib.load(fh)


def limits() -> dict[str, Any]:
    """resources/sizing/limits.toml: the limits and factors Chapter 2 states."""
    return load("limits")
