"""Crimp amplitude of a plain-weave yarn from thread count and crimp (the yarn's shape,
which the material schema and the crimp calibration both use).

Thesis eq. (5.1)–(5.5), docs/theory.md §1.1. The yarn centre line is
z = h cos(π x / (2ℓ)) on x ∈ [−ℓ, ℓ]; its length over a half cell is

    ∫₀^ℓ √(1 + (π h / 2ℓ)² sin²(π x / 2ℓ)) dx = (2ℓ/π) E(−(π h / 2ℓ)²),

with E(m) = ∫₀^{π/2} √(1 − m sin²φ) dφ the complete elliptic integral of the
second kind (scipy's ``ellipe``). Eq. (5.5) sets this equal to ℓ(1 + c), which
is solved for h by Brent's method (the left side is increasing in h).
"""

from __future__ import annotations

import math

from scipy.optimize import brentq
from scipy.special import ellipe


def half_length_from_thread_count(crossing_thread_count: float) -> float:
    """ℓ_i0 = 1 / (2 n_j): in-plane half-length of a yarn between crossings (m).

    Args:
        crossing_thread_count: n_j, threads per metre of the crossing family.
    """
    if not crossing_thread_count > 0.0:
        raise ValueError(
            f"thread count = {crossing_thread_count} 1/m is not valid: it must be > 0"
        )
    return 0.5 / crossing_thread_count


def crimp_of_amplitude(h: float, half_length: float) -> float:
    """Crimp c(h) = (2/π) E(−(π h / 2ℓ)²) − 1 of a cosine yarn (eq. 5.3–5.4)."""
    k = math.pi * h / (2.0 * half_length)
    return 2.0 / math.pi * float(ellipe(-k * k)) - 1.0


def crimp_amplitude(half_length: float, crimp: float) -> float:
    """Solve eq. (5.5) for the crimp amplitude h0 (m).

    Args:
        half_length: ℓ, in-plane half-length of the yarn between crossings (m).
        crimp: c = yarn length / fabric length − 1 (dimensionless, ≥ 0).

    Returns:
        h0 such that the cosine yarn of amplitude h0 over ±ℓ has length 2ℓ(1 + c).
    """
    if not half_length > 0.0:
        raise ValueError(f"half length = {half_length} m is not valid: it must be > 0")
    if not crimp >= 0.0:
        raise ValueError(f"crimp = {crimp} is not valid: it must be ≥ 0 (0.0421 for 4.21 %)")
    if crimp == 0.0:
        return 0.0
    # Solve for r = h/ℓ (scale-free): c(r) grows like (π r / 2)²/4 for small r and
    # like 2r for large r, so r = 2 + c bounds the root from above.
    r = brentq(
        lambda x: crimp_of_amplitude(x, 1.0) - crimp, 0.0, 2.0 + crimp, xtol=1e-15, rtol=8.9e-16
    )
    return half_length * r
