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

import numpy as np

from wovenimpact.jit import inline_kernel, kernel
from wovenimpact.kernels.fabric_layout import (
    P_TAB_DATA,
    P_TAB_IBF,
    P_TAB_IBW,
    P_TAB_NBF,
    P_TAB_NBW,
    P_TAB_NF,
    P_TAB_NW,
    P_TAB_START,
    T_HF,
    T_EXACT,
    T_HW,
    T_W,
    TAB_STRIDE,
)


# Row offsets are unsigned. Numba checks a signed index for wraparound (a negative one
# counts from the end) at every load; these offsets are computed from the row, so LLVM
# cannot prove them non-negative. As uint64 they need no check: 627 → 416 instructions
# per evaluation (docs/theory.md §4.6). uint64 and int64 mix to float64 in Numba, so
# every offset below is built from _U(...) values only.
_U = np.uint64
W0, W1, W2, W3 = _U(T_W), _U(T_W + 1), _U(T_W + 2), _U(T_W + 3)
HW0, HW1, HW2, HW3 = _U(T_HW), _U(T_HW + 1), _U(T_HW + 2), _U(T_HW + 3)
HF0, HF1, HF2, HF3 = _U(T_HF), _U(T_HF + 1), _U(T_HF + 2), _U(T_HF + 3)
STRIDE = _U(TAB_STRIDE)
EXACT = _U(T_EXACT)


@inline_kernel
def knot_interval(p, m, start, n, buckets, nb, inv_width, x):
    """Index i (0 ≤ i ≤ n − 2) of the knot interval [k_i, k_i+1] of p[m, start : start + n]
    holding x, or −1 if x lies outside the knots (or is NaN). ``start`` and ``buckets``
    are unsigned row offsets, ``n`` and ``nb`` counts.

    O(1): the bucket map p[m, buckets : buckets + nb] (uniform buckets of width
    1/inv_width from k_0) gives the interval of the bucket's left edge; a bucket is
    half the fine knot spacing, so at most one step forward remains, except in the
    cluster of knots around λ = 1 (materials/fabric_table.REST_STEPS), where a point steps
    through a few. (A bisection over 124 knots cost ~55 ns per axis here, its branches
    unpredictable.)
    """
    k0 = p[m, start]
    if not (k0 <= x <= p[m, start + _U(n - 1)]):
        return -1
    b = min(int((x - k0) * inv_width), nb - 1)
    i = int(p[m, buckets + _U(b)])
    while i < n - 2 and x >= p[m, start + _U(i + 1)]:
        i += 1
    return i


@inline_kernel
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


@inline_kernel
def hermite_corner(p, m, k, ax, bx, dax, dbx, ay, by, day, dby):
    """One cell corner's terms of the bicubic Hermite interpolant (knot data at p[m, k:]).

    With value weights a, slope weights b (including the interval length) and their
    x-derivatives da, db in λ_w (x) and λ_f (y): W = Σ (f a_x + f_x b_x) a_y +
    (f_y a_x + f_xy b_x) b_y over the corners, ∂W/∂λ_w the same with da_x, db_x, ∂W/∂λ_f
    with da_y, db_y; H_w and H_f likewise (values only).

    ``k`` is the knot's unsigned row offset. Returns the corner's (W, ∂W/∂λ_w, ∂W/∂λ_f,
    H_w, H_f) terms.
    """
    return hermite_terms(p[m, k + W0], p[m, k + W1], p[m, k + W2], p[m, k + W3],
                         p[m, k + HW0], p[m, k + HW1], p[m, k + HW2], p[m, k + HW3],
                         p[m, k + HF0], p[m, k + HF1], p[m, k + HF2], p[m, k + HF3],
                         ax, bx, dax, dbx, ay, by, day, dby)


# keeps its long signature: a stage inlined into ``cell_corner`` and ``hermite_corner``, its
# arguments that loop's locals (a bundle written through in a parallel loop's body can lose its
# writes: kernels/bundles.py)
@inline_kernel
def hermite_terms(f, fx, fy, fxy, h0, h1, h2, h3, k0, k1, k2, k3, ax, bx, dax, dbx, ay, by,
                  day, dby):
    """:func:`hermite_corner` on a corner's twelve coefficients (W, ∂W/∂λ_w, ∂W/∂λ_f,
    ∂²W/∂λ_w∂λ_f; the same four of H_w, then of H_f), wherever they were read from (the
    element stage in blocks copies them: ``kernels.shell_blocks``)."""
    u = f * ax + fx * bx
    v = fy * ax + fxy * bx
    w = u * ay + v * by
    gw = (f * dax + fx * dbx) * ay + (fy * dax + fxy * dbx) * by
    gf = u * day + v * dby
    hw = (h0 * ax + h1 * bx) * ay + (h2 * ax + h3 * bx) * by
    hf = (k0 * ax + k1 * bx) * ay + (k2 * ax + k3 * bx) * by
    return w, gw, gf, hw, hf


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
    if nw < 2 or nf < 2:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    nbw = int(p[m, P_TAB_NBW])
    kw = _U(int(p[m, P_TAB_START]))  # the knots along λ_w, then along λ_f, then the maps
    kf = kw + _U(nw)
    i = knot_interval(p, m, kw, nw, kf + _U(nf), nbw, p[m, P_TAB_IBW], lam_w)
    j = knot_interval(p, m, kf, nf, kf + _U(nf + nbw), int(p[m, P_TAB_NBF]),
                      p[m, P_TAB_IBF], lam_f)
    if i < 0 or j < 0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    u00 = _U(int(p[m, P_TAB_DATA]) + TAB_STRIDE * (i * nf + j))
    if p[m, u00 + EXACT] != 0.0:
        return False, 0.0, 0.0, 0.0, 0.0, 0.0
    x0 = p[m, kw + _U(i)]
    hx = p[m, kw + _U(i + 1)] - x0
    y0 = p[m, kf + _U(j)]
    hy = p[m, kf + _U(j + 1)] - y0
    ax0, ax1, bx0, bx1, dax0, dax1, dbx0, dbx1 = hermite_basis((lam_w - x0) / hx, hx)
    ay0, ay1, by0, by1, day0, day1, dby0, dby1 = hermite_basis((lam_f - y0) / hy, hy)
    u10 = u00 + _U(TAB_STRIDE * nf)
    w, gw, gf, hw, hf = cell_sum(
        hermite_corner(p, m, u00, ax0, bx0, dax0, dbx0, ay0, by0, day0, dby0),
        hermite_corner(p, m, u00 + STRIDE, ax0, bx0, dax0, dbx0, ay1, by1, day1, dby1),
        hermite_corner(p, m, u10, ax1, bx1, dax1, dbx1, ay0, by0, day0, dby0),
        hermite_corner(p, m, u10 + STRIDE, ax1, bx1, dax1, dbx1, ay1, by1, day1, dby1))
    return True, w, gw, gf, hw, hf


@inline_kernel
def cell_sum(c0, c1, c2, c3):
    """The interpolant on a knot cell: the sum of its four corners' terms (each (W,
    ∂W/∂λ_w, ∂W/∂λ_f, H_w, H_f), :func:`hermite_corner`), paired as (c0 + c1) + (c2 + c3)."""
    return ((c0[0] + c1[0]) + (c2[0] + c3[0]), (c0[1] + c1[1]) + (c2[1] + c3[1]),
            (c0[2] + c1[2]) + (c2[2] + c3[2]), (c0[3] + c1[3]) + (c2[3] + c3[3]),
            (c0[4] + c1[4]) + (c2[4] + c3[4]))


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
