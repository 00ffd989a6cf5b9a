"""Helpers for the catalogue tests: 'within printed rounding' comparisons (a unique module name)."""

from __future__ import annotations

import math

KGF_N = 9.80665  # N per kgf
RAD_PER_ARCMIN = math.pi / (180 * 60)


def half_unit(value: float) -> float:
    """Half a unit in the last printed digit of a table value.

    Decimals come from the shortest repr of the float (0.17 -> 0.005); an integral value counts its
    trailing zeros as not significant (510 -> 5, 24 -> 0.5), so the check errs towards lenient.
    """
    if value == 0:
        return 0.5
    if float(value).is_integer():
        n = int(abs(value))
        unit = 1
        while n % 10 == 0:
            n //= 10
            unit *= 10
        return unit / 2
    text = repr(float(value))
    if "e" in text:
        mantissa, exponent = text.split("e")
        decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
        return 0.5 * 10.0 ** (int(exponent) - decimals)
    return 0.5 * 10.0 ** -len(text.split(".")[1])


def agree_within_rounding(si: float, other: float, factor: float) -> bool:
    """True when ``si`` and ``other`` x ``factor`` overlap once each is widened by its printed rounding."""
    lo_a, hi_a = si - half_unit(si), si + half_unit(si)
    conv = [(other - half_unit(other)) * factor, (other + half_unit(other)) * factor]
    lo_b, hi_b = min(conv), max(conv)
    return lo_a <= hi_b + 1e-12 and lo_b <= hi_a + 1e-12
