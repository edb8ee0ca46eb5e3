"""Discretisation error of a mesh study: observed order, extrapolated value and the grid
convergence index (GCI) of one answer computed on three or more element sizes.

The procedure is Celik et al.'s (I. B. Celik, U. Ghia, P. J. Roache, C. J. Freitas,
H. Coleman, P. E. Raad, "Procedure for estimation and reporting of uncertainty due to
discretization in CFD applications", J. Fluids Eng. 130 (2008) 078001), after Roache's
GCI, for meshes whose refinement ratios need not be equal. With h1 < h2 < h3 the element
sizes of three consecutive meshes, φ1, φ2, φ3 the answers, r21 = h2/h1, r32 = h3/h2,
ε21 = φ2 − φ1, ε32 = φ3 − φ2 and s = sign(ε32/ε21), the observed order p solves

    p = |ln|ε32/ε21| + q(p)| / ln r21,   q(p) = ln((r21^p − s)/(r32^p − s))      (C2)

(solved here as the root of the power law it stands for; q = 0 when the ratios are equal), and

    φ_ext = (r21^p φ1 − φ2)/(r21^p − 1)                                         (C4)
    GCI_fine = 1.25 |(φ1 − φ2)/φ1| / (r21^p − 1)                                (C5)

GCI_fine is a band that contains the mesh-converged answer with about 95 % confidence
when the three meshes are in the asymptotic range (the error ∝ h^p). That is judged,
not assumed: the triple is reported *oscillatory* when ε32/ε21 < 0 (the answer goes up
then down, no order exists), and *not asymptotic* when the observed order lies outside
[0.5, 4] (an element of first or second order, with an unresolved feature, converges
at an order between; outside it the "order" fits noise). Only a monotone, asymptotic
triple gets an extrapolated value and a GCI; a triple whose finer step is larger than
any positive order allows is *diverging*.

A single explicit run carries its own scatter (a contact that catches one node more,
an element that erodes one step earlier): when the differences between meshes are no
larger than that scatter, the observed order means nothing. Three runs per mesh (e.g.
the release angle moved by ±0.1°) measure it; this module takes one answer per mesh.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from wovenimpact.errors import InputError

SAFETY_FACTOR = 1.25  # Celik et al.'s Fs for three meshes
ORDER_RANGE = (0.5, 4.0)  # observed orders taken as asymptotic
MAX_ITERATIONS = 200  # bisection steps of the observed order


@dataclass(frozen=True)
class Triple:
    """The convergence of one answer on three consecutive meshes (h1 finest)."""

    sizes: tuple[float, float, float]
    values: tuple[float, float, float]
    verdict: str  # "monotone", "oscillatory", "diverging", "not asymptotic" or "converged"
    order: float | None
    extrapolated: float | None
    gci_fine: float | None  # fraction of φ1

    def row(self) -> dict:
        """The triple as a flat, printable record."""
        return {"h1": self.sizes[0], "h2": self.sizes[1], "h3": self.sizes[2],
                "phi1": self.values[0], "phi2": self.values[1], "phi3": self.values[2],
                "verdict": self.verdict, "order": self.order,
                "extrapolated": self.extrapolated, "gci_fine": self.gci_fine}


def observed_order(h1: float, h2: float, h3: float, e21: float, e32: float) -> float | None:
    """The observed order p: the root of (h3^p − h2^p)/(h2^p − h1^p) = ε32/ε21, the
    error model φ = φ_ext + C h^p of eq. (C2) written without its fixed-point form (the
    same root when s = +1; found by bracketing, so a root is not missed where the
    iteration would start at p = 0). Negative when the finer step is larger than any
    positive order allows (the answer diverges); None when ε32/ε21 ≤ 0 or no root lies
    in [−20, 20]."""
    ratio = e32 / e21
    if not ratio > 0.0:
        return None

    def steps(p: float) -> float:
        if abs(p) < 1e-9:  # the limit p → 0
            return math.log(h3 / h2) / math.log(h2 / h1)
        return (h3 ** p - h2 ** p) / (h2 ** p - h1 ** p)

    lo, hi = -20.0, 20.0
    f_lo, f_hi = steps(lo) - ratio, steps(hi) - ratio
    if f_lo * f_hi > 0.0:
        return None
    for _ in range(MAX_ITERATIONS):  # bisection: steps(p) rises with p
        mid = 0.5 * (lo + hi)
        f_mid = steps(mid) - ratio
        if (f_mid > 0.0) == (f_hi > 0.0):
            hi, f_hi = mid, f_mid
        else:
            lo, f_lo = mid, f_mid
        if hi - lo < 1e-12:
            break
    return 0.5 * (lo + hi)


def triple(sizes, values) -> Triple:
    """Celik et al.'s estimate on three meshes; ``sizes`` and ``values`` in any order of
    the same three meshes (they are sorted finest first).

    Raises:
        InputError: fewer or more than three meshes, two equal sizes, or a size ≤ 0.
    """
    if len(sizes) != 3 or len(values) != 3:
        raise InputError(f"a convergence triple needs three meshes, got {len(sizes)}")
    pairs = sorted(zip(map(float, sizes), map(float, values)))
    (h1, f1), (h2, f2), (h3, f3) = pairs
    if h1 <= 0.0 or not h1 < h2 < h3:
        raise InputError(f"element sizes must be positive and distinct, got {h1:g}, "
                         f"{h2:g}, {h3:g}")
    hs, fs = (h1, h2, h3), (f1, f2, f3)
    e21, e32 = f2 - f1, f3 - f2
    if e21 == 0.0 and e32 == 0.0:
        return Triple(hs, fs, "converged", None, f1, 0.0)
    if e21 == 0.0 or e32 == 0.0 or e32 / e21 < 0.0:
        return Triple(hs, fs, "oscillatory", None, None, None)
    p = observed_order(h1, h2, h3, e21, e32)
    if p is not None and p < 0.0:
        return Triple(hs, fs, "diverging", p, None, None)
    if p is None or not ORDER_RANGE[0] <= p <= ORDER_RANGE[1]:
        return Triple(hs, fs, "not asymptotic", p, None, None)
    rp = (h2 / h1) ** p
    ext = (rp * f1 - f2) / (rp - 1.0)
    gci = SAFETY_FACTOR * abs((f1 - f2) / f1) / (rp - 1.0) if f1 != 0.0 else None
    return Triple(hs, fs, "monotone", p, ext, gci)


def mesh_convergence(sizes, values) -> list[Triple]:
    """Every consecutive triple of a mesh study (sorted finest first), finest triple
    first: the finest one is the estimate; the others show whether the order holds as
    the mesh is refined.

    Raises:
        InputError: fewer than three meshes, or two runs of the same size (average
            repeated runs first: one answer per mesh).
    """
    pairs = sorted(zip(map(float, sizes), map(float, values)))
    if len(pairs) < 3:
        raise InputError(f"a mesh convergence estimate needs at least three element "
                         f"sizes, got {len(pairs)}")
    hs = [h for h, _ in pairs]
    if len(set(hs)) != len(hs):
        raise InputError(f"two runs share an element size ({hs}): give one answer per "
                         "mesh (average repeated runs first)")
    return [triple(*zip(*pairs[i:i + 3])) for i in range(len(pairs) - 2)]
