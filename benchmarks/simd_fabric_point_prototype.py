"""Prototype (issue 13): the crossover point's fast path — intact yarns, a tabulated cell,
the fibre frame, the true trellis law (the defaults) — in blocks of 8 points, against
``fabric_point`` on the same states (docs/theory.md §4.6, "SIMD element pass"). A
measurement, not solver code: it does not write the point's state (heights, tensions,
stretches, angle, stress, energy), which the solver's would.

    python benchmarks/simd_fabric_point_prototype.py [N_POINTS]   (4 000)

Stages: the stretches; the table's scalar look-up and copy
(``simd_table_prototype.lookup_gather``); then per lane the fibre frame with a
vectorisable atan2 (``simd_atan2_prototype``), the Hermite W, ∇W and heights, the
tensions (a yarn at T_u flags the lane for the scalar kernel), the virial resultant, the
trellis shear law written as selects, the stored energy. Prints the differences from
``fabric_point`` (round-off) and ns per point of each stage, one thread.
"""
import dataclasses
import math
import re
import sys
from pathlib import Path

import numpy as np
from numba import njit, prange
sys.path.insert(0, str(Path(__file__).resolve().parent))
from simd_table_prototype import lookup_gather, corner, at, LANES, N_COEF, _U, best
from simd_atan2_prototype import atan2_upper
from wovenimpact.benchmark import REFERENCE_FABRIC
from wovenimpact.jit import set_threads
from wovenimpact.spec import load_material
from wovenimpact.kernels import fabric_layout as L
from wovenimpact.kernels.fabric import fabric_update_for_points, yarn_constants
from wovenimpact.kernels.fabric_table import hermite_basis
from wovenimpact.materials.fabric import initial_state
FAST = dict(boundscheck=False, error_model="numpy")

@njit(**FAST)
def stretches(f, lam_w, lam_f):
    """λ_w = |F e_x|, λ_f = |F e_y| of every point."""
    for e in range(f.shape[0]):
        gwx, gwy, gfx, gfy = f[e, 0, 0], f[e, 1, 0], f[e, 0, 1], f[e, 1, 1]
        lw = math.sqrt(gwx * gwx + gwy * gwy)
        lf = math.sqrt(gfx * gfx + gfy * gfy)
        lam_w[e] = lw
        lam_f[e] = lf

@njit(forceinline=True, **FAST)
def point_block(b, p, f, lam_w, lam_f, coef, geo, flag, out):
    """Block b's lanes (``fabric_point``'s fast path, the same formulas): out[at(b, 5, k, l)]
    = N_xx, N_yy, N_xy, the stiffness bound, the stored energy; flag[e] |= 1 for a lane
    the scalar kernel must redo."""
    m = 0
    ell0_w, ell0_f, h0_w, h0_f, lt0_w, lt0_f, ea_w, ea_f, a, bb = yarn_constants(p, m)
    thick = p[m, L.P_THICK]
    tu_w, tu_f = p[m, L.P_TU], p[m, L.P_TU + 1]
    g1, g2, gam1, gam2 = p[m, L.P_G1], p[m, L.P_G2], p[m, L.P_GAMMA1], p[m, L.P_GAMMA2]
    area0 = 4.0 * ell0_w * ell0_f
    for ll in range(LANES):
        lu = _U(ll)
        e = b * _U(LANES) + lu
        gwx, gwy, gfx, gfy = f[e, 0, 0], f[e, 1, 0], f[e, 0, 1], f[e, 1, 1]
        lw = lam_w[e]
        lf = lam_f[e]
        ewx, ewy = gwx / lw, gwy / lw
        efx, efy = gfx / lf, gfy / lf
        cos_t = ewx * efx + ewy * efy
        sin_t = ewx * efy - ewy * efx
        gamma = 0.5 * math.pi - atan2_upper(sin_t, cos_t)
        x0, hx = geo[at(b, 4, 0, lu)], geo[at(b, 4, 1, lu)]
        y0, hy = geo[at(b, 4, 2, lu)], geo[at(b, 4, 3, lu)]
        ax0, ax1, bx0, bx1, dax0, dax1, dbx0, dbx1 = hermite_basis((lw - x0) / hx, hx)
        ay0, ay1, by0, by1, day0, day1, dby0, dby1 = hermite_basis((lf - y0) / hy, hy)
        c0 = corner(coef, b, 0, ax0, bx0, dax0, dbx0, ay0, by0, day0, dby0, lu)
        c1 = corner(coef, b, 1, ax0, bx0, dax0, dbx0, ay1, by1, day1, dby1, lu)
        c2 = corner(coef, b, 2, ax1, bx1, dax1, dbx1, ay0, by0, day0, dby0, lu)
        c3 = corner(coef, b, 3, ax1, bx1, dax1, dbx1, ay1, by1, day1, dby1, lu)
        w = (c0[0] + c1[0]) + (c2[0] + c3[0])
        gw = (c0[1] + c1[1]) + (c2[1] + c3[1])
        gf = (c0[2] + c1[2]) + (c2[2] + c3[2])
        h_w = max((c0[3] + c1[3]) + (c2[3] + c3[3]), 0.0)
        h_f = max((c0[4] + c1[4]) + (c2[4] + c3[4]), 0.0)
        ell_w = lw * ell0_w
        ell_f = lf * ell0_f
        l_w = math.sqrt(ell_w * ell_w + h_w * h_w)
        l_f = math.sqrt(ell_f * ell_f + h_f * h_f)
        t_w = max(gw * area0 * l_w / (2.0 * ell0_w * ell_w), 0.0)
        t_f = max(gf * area0 * l_f / (2.0 * ell0_f * ell_f), 0.0)
        # a yarn reaching T_u, or a look-up outside the table: the scalar kernel redoes it
        bad = (t_w >= tu_w) | (t_f >= tu_f) | (not (sin_t > 0.0))
        flag[e] = flag[e] | np.int8(1 if bad else 0)
        c_w = gw / (lf * sin_t)
        c_f = gf / (lw * sin_t)
        yarn_w = ea_w * ell_w / lt0_w
        yarn_f = ea_f * ell_f / lt0_f
        den_w = 2.0 * ell_f * sin_t
        den_f = 2.0 * ell_w * sin_t
        stiff = max((yarn_w + t_w) / den_w, (yarn_f + t_f) / den_f)
        n_xx = c_w * ewx * ewx + c_f * efx * efx
        n_yy = c_w * ewy * ewy + c_f * efy * efy
        n_xy = c_w * ewx * ewy + c_f * efx * efy
        ga = abs(gamma)
        # the true trellis law, written as selects (shear_modulus_true's branches)
        mm = (g2 - g1) / (gam2 - gam1)
        e1 = 0.5 * g1 * gam1 * gam1
        g_mid = g1 + mm * (ga - gam1)
        e_mid = e1 + 0.5 * g1 * (ga * ga - gam1 * gam1) + mm * (
            (ga * ga * ga - gam1 * gam1 * gam1) / 3.0 - 0.5 * gam1 * (ga * ga - gam1 * gam1))
        e2 = e1 + 0.5 * g1 * (gam2 * gam2 - gam1 * gam1) + mm * (
            (gam2 * gam2 * gam2 - gam1 * gam1 * gam1) / 3.0
            - 0.5 * gam1 * (gam2 * gam2 - gam1 * gam1))
        lo = ga <= gam1
        hi = ga > gam2
        g = g1 if lo else (g2 if hi else g_mid)
        g_tan = g1 if lo else (g2 if hi else g_mid + mm * ga)
        e_high = e2 + 0.5 * g2 * (ga * ga - gam2 * gam2)
        e_dens = 0.5 * g1 * ga * ga if lo else (e_high if hi else e_mid)
        tau = g * gamma
        jac = lw * lf * sin_t
        cs = thick * tau / (jac * sin_t)
        n_xx += cs * (2.0 * ewx * efx - cos_t * (ewx * ewx + efx * efx))
        n_yy += cs * (2.0 * ewy * efy - cos_t * (ewy * ewy + efy * efy))
        n_xy += cs * (ewx * efy + ewy * efx - cos_t * (ewx * ewy + efx * efy))
        out[at(b, 5, 0, lu)] = n_xx
        out[at(b, 5, 1, lu)] = n_yy
        out[at(b, 5, 2, lu)] = n_xy
        out[at(b, 5, 3, lu)] = stiff + thick * g_tan
        out[at(b, 5, 4, lu)] = w + thick * e_dens

@njit(parallel=True, **FAST)
def points_blocks(nb, p, f, lam_w, lam_f, coef, geo, flag, out):
    """:func:`point_block` for every block (a prange: noalias arguments)."""
    for b in prange(nb):
        point_block(_U(b), p, f, lam_w, lam_f, coef, geo, flag, out)

def main() -> int:
    set_threads(1)
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 4000
    fabric = load_material(REFERENCE_FABRIC)
    row = dataclasses.replace(fabric, options=dataclasses.replace(fabric.options,
                                                                  crossover="table")).to_array()
    rng = np.random.default_rng(2)
    lw = rng.uniform(0.97, 1.03, n); lf = rng.uniform(0.97, 1.03, n); sh = rng.uniform(-0.3, 0.3, n)
    f = np.zeros((n, 2, 2))
    f[:, 0, 0] = lw; f[:, 1, 0] = 0.0
    f[:, 0, 1] = lf * np.sin(sh); f[:, 1, 1] = lf * np.cos(sh)
    s_in = initial_state(fabric, n); s_out = np.empty_like(s_in)
    n_ref = np.empty((n, 3)); st_ref = np.empty(n); status = np.empty(n, np.int32)
    fabric_update_for_points(row, f.copy(), f, s_in, s_out, n_ref, st_ref, status)
    p2 = row.reshape(1, -1)
    nb = n // LANES
    lam_w = np.empty(n); lam_f = np.empty(n)
    coef = np.zeros(nb * N_COEF * LANES)
    geo = np.zeros(nb * 4 * LANES)
    flag = np.zeros(n, np.int8)
    out = np.zeros(n * 5)
    def fast():
        stretches(f, lam_w, lam_f)
        lookup_gather(row, lam_w, lam_f, coef, geo, flag)
        points_blocks(nb, p2, f, lam_w, lam_f, coef, geo, flag, out)
    fast()
    got = out.reshape(nb, 5, LANES).transpose(0, 2, 1).reshape(n, 5)
    ok = (flag == 0) & (status == 0)
    scale = np.abs(n_ref[ok]).max()
    err = np.abs(got[ok, :3] - n_ref[ok]).max() / scale
    e_ref = s_out[ok, L.S_ENERGY]
    e_err = np.abs(got[ok, 4] - e_ref).max() / np.abs(e_ref).max()
    k_err = np.abs(got[ok, 3] - st_ref[ok]).max() / st_ref[ok].max()
    print(f"fast path taken by {ok.mean():.1%}; against fabric_point: resultant {err:.1e} of "
          f"the largest, energy {e_err:.1e}, stiffness {k_err:.1e}")
    asm = next(iter(points_blocks.inspect_asm().values()))
    packed = len(re.findall(r"pd\s+%zmm", asm))
    print(f"points_blocks: {packed} packed-double instructions (0: not vectorised)")
    f_old = f.copy()
    t_ref = best(lambda: fabric_update_for_points(row, f_old, f, s_in, s_out, n_ref, st_ref,
                                                  status))
    t_k = best(lambda: stretches(f, lam_w, lam_f))
    t_l = best(lambda: lookup_gather(row, lam_w, lam_f, coef, geo, flag))
    t_p = best(lambda: points_blocks(nb, p2, f, lam_w, lam_f, coef, geo, flag, out))
    print(f"{n} points, 1 thread: fabric_point {t_ref / n * 1e9:.1f} ns; fast path: stretches "
          f"{t_k / n * 1e9:.1f} + look-up and copy {t_l / n * 1e9:.1f} + the rest "
          f"{t_p / n * 1e9:.1f} ns")
    return 0 if err < 1e-12 else 1

if __name__ == "__main__":
    sys.exit(main())
