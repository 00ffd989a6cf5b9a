"""Whether a fitted shape parameter lies within what the recording spans (Candidate.shape_check).

The joint refinement of all parameters (selection.final_fit) is not bounded, so a shape can run
off to where the recording holds nothing of it; these checks say so in a person's words.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np


def stribeck_within(shape: tuple[float, ...], ctx: Any) -> str:
    """A fading speed must lie well within the speeds the axis slid at: far above every recorded
    speed the term is Coulomb (and viscous) friction, not breakaway."""
    v_s = abs(float(shape[0]))
    top = float(np.percentile(np.abs(ctx.sig.speed_rad_s), 99.0))
    if v_s > 0.5 * top:
        return (f"its fading speed {v_s * 30.0 / math.pi:.3g} r/min is not well below the fastest "
                f"recorded speed ({top * 30.0 / math.pi:.3g} r/min): at these speeds it is Coulomb friction")
    return ""


def cycles_within(grid: Sequence[float]) -> Callable[[tuple[float, ...], Any], str]:
    """A refined frequency must stay next to the grid value it was refined from."""

    def check(shape: tuple[float, ...], ctx: Any) -> str:
        c = float(shape[0])
        nearest = min(grid, key=lambda g: abs(g - c))
        if abs(c - nearest) > 0.3:
            return f"its frequency ran off to {c:.3g} cycles per motor turn in the joint fit"
        return ""

    return check
