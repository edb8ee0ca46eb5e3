"""Prototype (issue 13): the crossover table's evaluation split for SIMD — a scalar knot
look-up that copies each point's cell coefficients into lane-major scratch, then a
vectorised bicubic Hermite evaluation — against the scalar ``crossover_from_table``
on the same random points (docs/theory.md §4.6, "SIMD element pass"). A measurement,
not solver code.

    python benchmarks/simd_table_prototype.py [N_POINTS]   (4 000: in cache)

Prints whether the split gives bitwise the same flags and values (exit 1 if not) and ns
per point of each part, one thread.
"""

import dataclasses
import math
import re
import sys
import time

import numpy as np
from numba import njit, prange

from wovenimpact.benchmark import REFERENCE_FABRIC
from wovenimpact.jit import set_threads
from wovenimpact.kernels import fabric_layout as L
from wovenimpact.kernels.fabric_table import (
    EXACT,
    STRIDE,
    _U,
    crossover_from_table_for_points,
    hermite_basis,
    knot_interval,
)
from wovenimpact.spec import load_material

FAST = dict(boundscheck=False, error_model="numpy")
LANES = 8
N_COEF = 48  # 4 corners × (W, H_w, H_f) × (f, f_x, f_y, f_xy)


@njit(inline="always", **FAST)
def at(b, width, k, lu):
    """Index of value k of lane lu of block b in a table of blocks of ``width`` values."""
    return (b * _U(width) + _U(k)) * _U(LANES) + lu


@njit(**FAST)
def lookup_gather(row, lam_w, lam_f, coef, geo, flag):
    """Scalar part, per point e = 8 b + l: the knot cell holding (λ_w, λ_f)
    (``knot_interval``, as ``crossover_from_table``), its 4 corners' 12 coefficients into
    coef[at(b, 48, 12 corner + 3 q + (0: W, 1: H_w, 2: H_f), l)] and (x0, hx, y0, hy) into
    geo[at(b, 4, ·, l)]; flag 1 where the table defers to the exact solve (outside the
    knots, or an exact cell)."""
    p = row.reshape((1, row.shape[0]))
    m = 0
    nw = int(p[m, L.P_TAB_NW])
    nf = int(p[m, L.P_TAB_NF])
    nbw = int(p[m, L.P_TAB_NBW])
    kw = _U(int(p[m, L.P_TAB_START]))
    kf = kw + _U(nw)
    for e in range(lam_w.shape[0]):
        b = _U(e // LANES)
        lu = _U(e % LANES)
        i = knot_interval(p, m, kw, nw, kf + _U(nf), nbw, p[m, L.P_TAB_IBW], lam_w[e])
        j = knot_interval(p, m, kf, nf, kf + _U(nf + nbw), int(p[m, L.P_TAB_NBF]),
                          p[m, L.P_TAB_IBF], lam_f[e])
        bad = i < 0 or j < 0
        if bad:
            i = 0
            j = 0
        u00 = _U(int(p[m, L.P_TAB_DATA]) + L.TAB_STRIDE * (i * nf + j))
        flag[e] = 1 if bad or p[m, u00 + EXACT] != 0.0 else 0
        geo[at(b, 4, 0, lu)] = p[m, kw + _U(i)]
        geo[at(b, 4, 1, lu)] = p[m, kw + _U(i + 1)] - p[m, kw + _U(i)]
        geo[at(b, 4, 2, lu)] = p[m, kf + _U(j)]
        geo[at(b, 4, 3, lu)] = p[m, kf + _U(j + 1)] - p[m, kf + _U(j)]
        u10 = u00 + _U(L.TAB_STRIDE * nf)
        c = 0
        for u in (u00, u00 + STRIDE, u10, u10 + STRIDE):
            for q in range(4):
                coef[at(b, N_COEF, c, lu)] = p[m, u + _U(L.T_W + q)]
                coef[at(b, N_COEF, c + 1, lu)] = p[m, u + _U(L.T_HW + q)]
                coef[at(b, N_COEF, c + 2, lu)] = p[m, u + _U(L.T_HF + q)]
                c += 3


@njit(inline="always", **FAST)
def corner(cf, b, k, ax, bx, dax, dbx, ay, by, day, dby, lu):
    """``hermite_corner`` on corner k's copied coefficients."""
    c = 12 * k
    f, h0, k0 = cf[at(b, N_COEF, c, lu)], cf[at(b, N_COEF, c + 1, lu)], cf[at(b, N_COEF, c + 2, lu)]
    fx, h1, k1 = (cf[at(b, N_COEF, c + 3, lu)], cf[at(b, N_COEF, c + 4, lu)],
                  cf[at(b, N_COEF, c + 5, lu)])
    fy, h2, k2 = (cf[at(b, N_COEF, c + 6, lu)], cf[at(b, N_COEF, c + 7, lu)],
                  cf[at(b, N_COEF, c + 8, lu)])
    fxy, h3, k3 = (cf[at(b, N_COEF, c + 9, lu)], cf[at(b, N_COEF, c + 10, lu)],
                   cf[at(b, N_COEF, c + 11, lu)])
    u = f * ax + fx * bx
    v = fy * ax + fxy * bx
    w = u * ay + v * by
    gw = (f * dax + fx * dbx) * ay + (fy * dax + fxy * dbx) * by
    gf = u * day + v * dby
    hw = (h0 * ax + h1 * bx) * ay + (h2 * ax + h3 * bx) * by
    hf = (k0 * ax + k1 * bx) * ay + (k2 * ax + k3 * bx) * by
    return w, gw, gf, hw, hf


@njit(forceinline=True, **FAST)
def hermite_block(b, lam_w, lam_f, coef, geo, out):
    """Block b of :func:`hermite_blocks` (inlined by LLVM into the parallel loop, whose
    arguments are noalias: docs/theory.md §4.6)."""
    for ll in range(LANES):
        lu = _U(ll)
        e = b * _U(LANES) + lu
        x0, hx = geo[at(b, 4, 0, lu)], geo[at(b, 4, 1, lu)]
        y0, hy = geo[at(b, 4, 2, lu)], geo[at(b, 4, 3, lu)]
        ax0, ax1, bx0, bx1, dax0, dax1, dbx0, dbx1 = hermite_basis((lam_w[e] - x0) / hx, hx)
        ay0, ay1, by0, by1, day0, day1, dby0, dby1 = hermite_basis((lam_f[e] - y0) / hy, hy)
        c0 = corner(coef, b, 0, ax0, bx0, dax0, dbx0, ay0, by0, day0, dby0, lu)
        c1 = corner(coef, b, 1, ax0, bx0, dax0, dbx0, ay1, by1, day1, dby1, lu)
        c2 = corner(coef, b, 2, ax1, bx1, dax1, dbx1, ay0, by0, day0, dby0, lu)
        c3 = corner(coef, b, 3, ax1, bx1, dax1, dbx1, ay1, by1, day1, dby1, lu)
        out[at(b, 5, 0, lu)] = (c0[0] + c1[0]) + (c2[0] + c3[0])
        out[at(b, 5, 1, lu)] = (c0[1] + c1[1]) + (c2[1] + c3[1])
        out[at(b, 5, 2, lu)] = (c0[2] + c1[2]) + (c2[2] + c3[2])
        out[at(b, 5, 3, lu)] = (c0[3] + c1[3]) + (c2[3] + c3[3])
        out[at(b, 5, 4, lu)] = (c0[4] + c1[4]) + (c2[4] + c3[4])


@njit(parallel=True, **FAST)
def hermite_blocks(nb, lam_w, lam_f, coef, geo, out):
    """Vectorised part: the bicubic Hermite W, ∂W/∂λ_w, ∂W/∂λ_f, H_w, H_f of every point
    from the copied coefficients, into out[at(b, 5, ·, l)]."""
    for b in prange(nb):
        hermite_block(_U(b), lam_w, lam_f, coef, geo, out)


def best(f, repeats=200):
    """Best of ``repeats`` calls (s)."""
    t = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        t = min(t, time.perf_counter() - t0)
    return t


def main() -> int:
    n = LANES * (int(sys.argv[1]) // LANES) if len(sys.argv) > 1 else 4000
    set_threads(1)
    fabric = load_material(REFERENCE_FABRIC)
    row = dataclasses.replace(fabric, options=dataclasses.replace(fabric.options,
                                                                  crossover="table")).to_array()
    rng = np.random.default_rng(0)
    lw = rng.uniform(0.9, 1.05, n)
    lf = rng.uniform(0.9, 1.05, n)
    ref = np.empty((n, 6))
    crossover_from_table_for_points(row, lw, lf, ref)
    t_ref = best(lambda: crossover_from_table_for_points(row, lw, lf, ref))
    nb = n // LANES
    coef = np.zeros(nb * N_COEF * LANES)
    geo = np.zeros(nb * 4 * LANES)
    flag = np.zeros(n, np.int8)
    out = np.zeros(nb * 5 * LANES)
    lookup_gather(row, lw, lf, coef, geo, flag)
    hermite_blocks(nb, lw, lf, coef, geo, out)
    got = out.reshape(nb, 5, LANES).transpose(1, 0, 2).reshape(5, n)
    ok = ref[:, 0] == 1.0
    same = np.array_equal(flag == 0, ok) and all(
        np.array_equal(got[c][ok], ref[ok, c + 1]) for c in range(5))
    print(f"{ok.mean():.1%} of the points tabulated; flags and values bitwise equal to "
          f"crossover_from_table's: {same}")
    t_g = best(lambda: lookup_gather(row, lw, lf, coef, geo, flag))
    t_h = best(lambda: hermite_blocks(nb, lw, lf, coef, geo, out))
    asm = next(iter(hermite_blocks.inspect_asm().values()))
    packed = len(re.findall(r"pd\s+%zmm", asm))
    print(f"hermite_blocks: {packed} packed-double instructions")
    print(f"{n} points, 1 thread: crossover_from_table {t_ref / n * 1e9:.1f} ns per point; "
          f"split: look-up and copy {t_g / n * 1e9:.1f} ns, Hermite {t_h / n * 1e9:.1f} ns")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
