"""Tabulated crossover: the stored energy W(λ_w, λ_f) as a C¹ bicubic Hermite interpolant.

docs/theory.md §1.9. Before any yarn is damaged, the crossover equilibrium depends on
the two projected half-lengths ℓ_i = λ_i ℓ_i0 alone and is hyperelastic: the stored
energy per unit reference area (two half trusses per family plus the compaction spring,
eq. 6.20–6.25; shear is a separate law),

    W(λ_w, λ_f) = min over the heights of [Σ_i k_i ⟨L_i − L_i0⟩² + ∫ F dδ] / (4 ℓ_w0 ℓ_f0),

has the exact gradient ∂W/∂λ_i = 2 T_i cos ψ_i ℓ_i0 / (4 ℓ_w0 ℓ_f0) (envelope theorem:
∂U/∂H_i = F_i − F_c = 0 at equilibrium). ``materials/fabric_table.py`` tabulates W, its
gradient and ∂²W/∂λ_w∂λ_f, and the heights H_w, H_f with the same derivatives, on a
non-uniform tensor grid; this module evaluates the interpolant. The membrane resultant
is built from the interpolant's own gradient, so the tabulated material is exactly
hyperelastic (closed cycles return no work beyond round-off and quadrature).

Layout of the table in the parameter row: ``fabric_layout`` (P_TAB_*, T_*, TAB_STRIDE).
"""

from __future__ import annotations

from wovenimpact.jit import kernel
from wovenimpact.kernels.fabric_layout import (
    P_TAB_NF,
    P_TAB_NW,
    P_TAB_START,
    T_HF,
    T_EXACT,
    T_HW,
    T_W,
    TAB_STRIDE,
)


@kernel
def knot_interval(p, m, start, n, x):
    """Index i (0 ≤ i ≤ n − 2) of the knot interval [k_i, k_i+1] of p[m, start : start + n]
    holding x, by bisection; −1 if x lies outside the knots (or is NaN)."""
    if not (p[m, start] <= x <= p[m, start + n - 1]):
        return -1
    lo = 0
    hi = n - 1
    while hi - lo > 1:
        mid = (lo + hi) >> 1
        if p[m, start + mid] <= x:
            lo = mid
        else:
            hi = mid
    return lo


@kernel
def hermite_basis(t, h):
    """Cubic Hermite basis on [0, 1] scaled to an interval of length h.

    Returns (a0, a1, b0, b1, da0, da1, db0, db1): value weights a0 = (1 + 2t)(1 − t)²,
    a1 = t²(3 − 2t), slope weights b0 = h t(1 − t)², b1 = h t²(t − 1), and their
    derivatives with respect to x = x0 + t h.
    """
    t2 = t * t
    u = 1.0 - t
    a0 = (1.0 + 2.0 * t) * u * u
    a1 = t2 * (3.0 - 2.0 * t)
    b0 = h * t * u * u
    b1 = h * t2 * (t - 1.0)
    inv = 1.0 / h
    da0 = 6.0 * (t2 - t) * inv
    da1 = -da0
    db0 = 3.0 * t2 - 4.0 * t + 1.0
    db1 = 3.0 * t2 - 2.0 * t
    return a0, a1, b0, b1, da0, da1, db0, db1


@kernel
def crossover_from_table(p, m, lam_w, lam_f):
    """Evaluate the tabulated crossover of material row m at (λ_w, λ_f) (theory §1.9).

    Bicubic Hermite interpolation (C¹) of W, and of H_w, H_f, on the knot cell holding
    the point; the gradient is the interpolant's exact derivative.

    Returns:
        (inside, W, ∂W/∂λ_w, ∂W/∂λ_f, H_w, H_f): inside is False (and the rest 0) when
        the point lies outside the table or in a cell marked T_EXACT (then the caller
        solves exactly).
    """
    nw = int(p[m, P_TAB_NW])
    nf = int(p[m, P_TAB_NF])
    start = int(p[m, P_TAB_START])
    if nw < 2 or nf < 2:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    i = knot_interval(p, m, start, nw, lam_w)
    j = knot_interval(p, m, start + nw, nf, lam_f)
    if i < 0 or j < 0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    base = start + nw + nf
    if p[m, base + TAB_STRIDE * (i * nf + j) + T_EXACT] != 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    x0 = p[m, start + i]
    hx = p[m, start + i + 1] - x0
    y0 = p[m, start + nw + j]
    hy = p[m, start + nw + j + 1] - y0
    ax0, ax1, bx0, bx1, dax0, dax1, dbx0, dbx1 = hermite_basis((lam_w - x0) / hx, hx)
    ay0, ay1, by0, by1, day0, day1, dby0, dby1 = hermite_basis((lam_f - y0) / hy, hy)
    w = 0.0
    gw = 0.0
    gf = 0.0
    hw = 0.0
    hf = 0.0
    for c in range(4):
        ci = c >> 1  # corner (ci, cj) of the cell
        cj = c & 1
        k = base + TAB_STRIDE * ((i + ci) * nf + (j + cj))
        if ci == 0:
            ax, bx, dax, dbx = ax0, bx0, dax0, dbx0
        else:
            ax, bx, dax, dbx = ax1, bx1, dax1, dbx1
        if cj == 0:
            ay, by, day, dby = ay0, by0, day0, dby0
        else:
            ay, by, day, dby = ay1, by1, day1, dby1
        f = p[m, k + T_W]
        fx = p[m, k + T_W + 1]
        fy = p[m, k + T_W + 2]
        fxy = p[m, k + T_W + 3]
        # W = Σ f a a + f_x b a + f_y a b + f_xy b b, and its two partial derivatives
        w += (f * ax + fx * bx) * ay + (fy * ax + fxy * bx) * by
        gw += (f * dax + fx * dbx) * ay + (fy * dax + fxy * dbx) * by
        gf += (f * ax + fx * bx) * day + (fy * ax + fxy * bx) * dby
        hw += (p[m, k + T_HW] * ax + p[m, k + T_HW + 1] * bx) * ay + (
            p[m, k + T_HW + 2] * ax + p[m, k + T_HW + 3] * bx
        ) * by
        hf += (p[m, k + T_HF] * ax + p[m, k + T_HF + 1] * bx) * ay + (
            p[m, k + T_HF + 2] * ax + p[m, k + T_HF + 3] * bx
        ) * by
    return True, w, gw, gf, hw, hf


@kernel
def crossover_from_table_for_points(p, lam_w, lam_f, out):
    """:func:`crossover_from_table` on many points (tests, measurements).

    Args:
        p: (length,) parameter row with its table.
        lam_w, lam_f: (n,) stretches.
        out: (n, 6) written: inside (1/0), W, ∂W/∂λ_w, ∂W/∂λ_f, H_w, H_f.
    """
    table = p.reshape((1, p.shape[0]))
    for i in range(lam_w.shape[0]):
        inside, w, gw, gf, hw, hf = crossover_from_table(table, 0, lam_w[i], lam_f[i])
        out[i, 0] = 1.0 if inside else 0.0
        out[i, 1] = w
        out[i, 2] = gw
        out[i, 3] = gf
        out[i, 4] = hw
        out[i, 5] = hf
