"""Prototype of the SIMD element pass (issue 13): the 2x2-membrane elastic shell element
(resultant section) as one loop over elements that LLVM vectorises, timed against
``shell_force`` on the same state. A measurement, not solver code.

    python benchmarks/simd_shell_prototype.py [N_ELEMENTS]   (default 100 000)

Checks the outputs (corner forces and moments, resultants, energies, F at the points,
curvatures, stable step) against ``shell_force`` (bit for bit: the same formulas in the
same order; exit 1 otherwise), then prints ns per element of each, one thread.

What Numba's loops need to vectorise (found here with LLVM's
``--pass-remarks-missed=loop-vectorize``; docs/theory.md §4, "SIMD element pass"):

1. Structure-of-arrays tables, one row per value, indexed ``[value, e]``; the corner
   gathers ``x[quads[e, i]]`` do not vectorise (LLVM's cost model declines gathers on
   this CPU), so a scalar pass copies each element's corners into such a table first
   (``gather_corners``).
2. No alias checks: LLVM must prove that no output overlaps an input. Numba marks array
   arguments ``noalias`` only in parfor bodies; here every function is compiled with
   the flag set (``_with_noalias``, Numba's internal ``Flags.noalias``, set only after
   the solver's own kernels are compiled), and each output
   row is a separate array (a tuple of rows): rows of one 2-D table written at
   different indices need a run-time check per pair ("too many memory checks needed").
3. No inner loops with long bodies: the vectoriser takes innermost loops only, and a
   loop over the four Gauss points or corners that LLVM does not unroll itself is one;
   they are written out (``gauss_point``, ``corner_out`` called four times).
4. No early exits and no calls (``sqrt`` and division vectorise; ``atan2``, ``exp``
   have no vector version without SVML, absent here).
"""

import math
import sys
import time

import numba.core.cpu as _cpu
import numpy as np
from numba import njit

_finalize = _cpu.CPUTargetOptions.finalize


def _with_noalias(self, flags, options):
    """Numba's internal noalias flag on every function compiled from now on (main()
    sets it once the solver's kernels are compiled or loaded, so that only the
    prototype's functions get it; they compile at their first call)."""
    _finalize(self, flags, options)
    flags.noalias = True

from wovenimpact.jit import set_threads  # noqa: E402
from wovenimpact.kernels.shell import (  # noqa: E402
    corotational_frame,
    elastic_membrane,
    first_piola,
    hourglass_vectors,
    midpoint_frame,
    midpoint_rates,
    warp_forces,
)
from wovenimpact.kernels.shell_layout import (  # noqa: E402
    E_DT,
    E_FG,
    E_HG,
    E_KAPPA,
    E_M,
    E_N,
    E_Q,
    E_U_BEND,
    E_U_HG,
    E_U_MEMB,
)

FAST = dict(boundscheck=False, error_model="numpy")
STEEL_E, STEEL_NU = 210e9, 0.3  # the benchmark's elastic plate (wovenimpact.benchmark)


@njit(inline="always", **FAST)
def gauss_point(lx, ly, a1, a2, a3, a4, c1, c2, c3, c4, wg, e_mod, nu, thick):
    """One 2x2 point: F = sum x_I (x) dN_I/dX, the elastic membrane, and its weighted
    energy, resultant and corner forces w_g P G_gI (shell.full_membrane's terms)."""
    f11 = lx[0] * a1 + lx[1] * a2 + lx[2] * a3 + lx[3] * a4
    f12 = lx[0] * c1 + lx[1] * c2 + lx[2] * c3 + lx[3] * c4
    f21 = ly[0] * a1 + ly[1] * a2 + ly[2] * a3 + ly[3] * a4
    f22 = ly[0] * c1 + ly[1] * c2 + ly[2] * c3 + ly[3] * c4
    w, c, a, b, c12 = elastic_membrane(f11, f12, f21, f22, e_mod, nu, thick)
    p11, p12, p21, p22 = first_piola(a, b, c12, f11, f12, f21, f22)
    return ((f11, f12, f21, f22), wg * w, (wg * a, wg * b, wg * c12),
            (wg * (p11 * a1 + p12 * c1), wg * (p11 * a2 + p12 * c2),
             wg * (p11 * a3 + p12 * c3), wg * (p11 * a4 + p12 * c4)),
            (wg * (p21 * a1 + p22 * c1), wg * (p21 * a2 + p22 * c2),
             wg * (p21 * a3 + p22 * c3), wg * (p21 * a4 + p22 * c4)))


@njit(inline="always", **FAST)
def corner_out(mfx, mfy, gam, b1, b2, fzs, area, h0, h1, hg2, hg3, hg4, mxx, myy, mxy,
               qx, qy, frame):
    """One corner's force and moment in global axes (shell.corner_forces' terms)."""
    e1x, e1y, e1z = frame[0]
    e2x, e2y, e2z = frame[1]
    e3x, e3y, e3z = frame[2]
    fx = mfx + gam * h0
    fy = mfy + gam * h1
    fz = area * (b1 * qx + b2 * qy) + gam * hg2 + fzs
    mx = area * (-b2 * myy - b1 * mxy - 0.25 * qy) + gam * hg3
    my = area * (b1 * mxx + b2 * mxy + 0.25 * qx) + gam * hg4
    return (fx * e1x + fy * e2x + fz * e3x, fx * e1y + fy * e2y + fz * e3y,
            fx * e1z + fy * e2z + fz * e3z, mx * e1x + my * e2x, mx * e1y + my * e2y,
            mx * e1z + my * e2z)


@njit(**FAST)
def element_pass(n, cn, gg, gw, a0s, inertia, dt, thick, mu, e_mod, nu, e_b, nu_b, kgt, r_hg,
                 el_in, el_out, blk):
    """``shell_force`` of a 2×2-membrane elastic element with a resultant section, for
    elements 0 … n − 1, on structure-of-arrays tables: cn[corner, value, e]
    (gather_corners), gg[g, ∂/∂X or ∂/∂Y, corner, e], gw[g, e], el_in[column, e]; el_out
    and blk are tuples of rows (an element-state column; a corner's force or moment
    component), written. No failure checks (every element of the plate is sound)."""
    c_m = e_mod * thick / (1.0 - nu * nu)
    d_b = e_b * thick * thick * thick / (12.0 * (1.0 - nu_b * nu_b))
    for e in range(n):
        px = (cn[0, 0, e], cn[1, 0, e], cn[2, 0, e], cn[3, 0, e])
        py = (cn[0, 1, e], cn[1, 1, e], cn[2, 1, e], cn[3, 1, e])
        pz = (cn[0, 2, e], cn[1, 2, e], cn[2, 2, e], cn[3, 2, e])
        vx_ = (cn[0, 3, e], cn[1, 3, e], cn[2, 3, e], cn[3, 3, e])
        vy_ = (cn[0, 4, e], cn[1, 4, e], cn[2, 4, e], cn[3, 4, e])
        vz_ = (cn[0, 5, e], cn[1, 5, e], cn[2, 5, e], cn[3, 5, e])
        wx_ = (cn[0, 6, e], cn[1, 6, e], cn[2, 6, e], cn[3, 6, e])
        wy_ = (cn[0, 7, e], cn[1, 7, e], cn[2, 7, e], cn[3, 7, e])
        wz_ = (cn[0, 8, e], cn[1, 8, e], cn[2, 8, e], cn[3, 8, e])
        frame = corotational_frame(px, py, pz)
        area = frame[4]
        mid = midpoint_frame(px, py, pz, vx_, vy_, vz_, dt)
        lx, ly = frame[3]
        b1, b2 = frame[5]
        vx, vy, vz, tx, ty, dkx, dky, dkxy2, dgxz, dgyz = midpoint_rates(
            mid, vx_, vy_, vz_, wx_, wy_, wz_, dt)
        el_out[E_KAPPA][e] = el_in[E_KAPPA, e] + dkx
        el_out[E_KAPPA + 1][e] = el_in[E_KAPPA + 1, e] + dky
        el_out[E_KAPPA + 2][e] = el_in[E_KAPPA + 2, e] + dkxy2
        # membrane at the 2x2 points
        F0, u0, n0, m0_, f0 = gauss_point(
            lx, ly, gg[0, 0, 0, e], gg[0, 0, 1, e], gg[0, 0, 2, e], gg[0, 0, 3, e],
            gg[0, 1, 0, e], gg[0, 1, 1, e], gg[0, 1, 2, e], gg[0, 1, 3, e], gw[0, e],
            e_mod, nu, thick)
        el_out[E_FG + 0][e] = F0[0]
        el_out[E_FG + 1][e] = F0[1]
        el_out[E_FG + 2][e] = F0[2]
        el_out[E_FG + 3][e] = F0[3]
        F1, u1, n1, m1_, f1 = gauss_point(
            lx, ly, gg[1, 0, 0, e], gg[1, 0, 1, e], gg[1, 0, 2, e], gg[1, 0, 3, e],
            gg[1, 1, 0, e], gg[1, 1, 1, e], gg[1, 1, 2, e], gg[1, 1, 3, e], gw[1, e],
            e_mod, nu, thick)
        el_out[E_FG + 4][e] = F1[0]
        el_out[E_FG + 5][e] = F1[1]
        el_out[E_FG + 6][e] = F1[2]
        el_out[E_FG + 7][e] = F1[3]
        F2, u2, n2, m2_, f2 = gauss_point(
            lx, ly, gg[2, 0, 0, e], gg[2, 0, 1, e], gg[2, 0, 2, e], gg[2, 0, 3, e],
            gg[2, 1, 0, e], gg[2, 1, 1, e], gg[2, 1, 2, e], gg[2, 1, 3, e], gw[2, e],
            e_mod, nu, thick)
        el_out[E_FG + 8][e] = F2[0]
        el_out[E_FG + 9][e] = F2[1]
        el_out[E_FG + 10][e] = F2[2]
        el_out[E_FG + 11][e] = F2[3]
        F3, u3, n3, m3_, f3 = gauss_point(
            lx, ly, gg[3, 0, 0, e], gg[3, 0, 1, e], gg[3, 0, 2, e], gg[3, 0, 3, e],
            gg[3, 1, 0, e], gg[3, 1, 1, e], gg[3, 1, 2, e], gg[3, 1, 3, e], gw[3, e],
            e_mod, nu, thick)
        el_out[E_FG + 12][e] = F3[0]
        el_out[E_FG + 13][e] = F3[1]
        el_out[E_FG + 14][e] = F3[2]
        el_out[E_FG + 15][e] = F3[3]
        u = u0 + u1 + u2 + u3
        n_xx = n0[0] + n1[0] + n2[0] + n3[0]
        n_yy = n0[1] + n1[1] + n2[1] + n3[1]
        n_xy = n0[2] + n1[2] + n2[2] + n3[2]
        fx0 = m0_[0] + m1_[0] + m2_[0] + m3_[0]
        fx1 = m0_[1] + m1_[1] + m2_[1] + m3_[1]
        fx2 = m0_[2] + m1_[2] + m2_[2] + m3_[2]
        fx3 = m0_[3] + m1_[3] + m2_[3] + m3_[3]
        fy0 = f0[0] + f1[0] + f2[0] + f3[0]
        fy1 = f0[1] + f1[1] + f2[1] + f3[1]
        fy2 = f0[2] + f1[2] + f2[2] + f3[2]
        fy3 = f0[3] + f1[3] + f2[3] + f3[3]
        a0 = a0s[e]
        inv = 1.0 / a0
        el_out[E_N][e] = n_xx * inv
        el_out[E_N + 1][e] = n_yy * inv
        el_out[E_N + 2][e] = n_xy * inv
        el_out[E_U_MEMB][e] = u
        mf_x = (fx0, fx1, fx2, fx3)
        mf_y = (fy0, fy1, fy2, fy3)
        # bending and shear (resultant section)
        m0, m1, m2 = el_in[E_M, e], el_in[E_M + 1, e], el_in[E_M + 2, e]
        qo0, qo1 = el_in[E_Q, e], el_in[E_Q + 1, e]
        mxx = m0 + d_b * (dkx + nu_b * dky)
        myy = m1 + d_b * (dky + nu_b * dkx)
        mxy = m2 + d_b * 0.5 * (1.0 - nu_b) * dkxy2
        qx = qo0 + kgt * dgxz
        qy = qo1 + kgt * dgyz
        el_out[E_M][e] = mxx
        el_out[E_M + 1][e] = myy
        el_out[E_M + 2][e] = mxy
        el_out[E_Q][e] = qx
        el_out[E_Q + 1][e] = qy
        el_out[E_U_BEND][e] = el_in[E_U_BEND, e] + area * (
            (0.5 * (m0 + mxx) * dkx + 0.5 * (m1 + myy) * dky + 0.5 * (m2 + mxy) * dkxy2)
            + 0.5 * (qo0 + qx) * dgxz + 0.5 * (qo1 + qy) * dgyz)
        # hourglass (w, theta modes; a 2x2 membrane has no in-plane ones)
        gam, bb = hourglass_vectors(lx, ly, b1, b2)
        gam_mid = hourglass_vectors(mid[3][0], mid[3][1], mid[5][0], mid[5][1])[0]
        k_w = r_hg * 16.0 * d_b * bb
        k_t = r_hg * d_b * area * bb
        rz = gam_mid[0] * vz[0] + gam_mid[1] * vz[1] + gam_mid[2] * vz[2] + gam_mid[3] * vz[3]
        rtx = gam_mid[0] * tx[0] + gam_mid[1] * tx[1] + gam_mid[2] * tx[2] + gam_mid[3] * tx[3]
        rty = gam_mid[0] * ty[0] + gam_mid[1] * ty[1] + gam_mid[2] * ty[2] + gam_mid[3] * ty[3]
        h0o, h1o, h2o, h3o, h4o = (el_in[E_HG, e], el_in[E_HG + 1, e], el_in[E_HG + 2, e],
                                   el_in[E_HG + 3, e], el_in[E_HG + 4, e])
        hg2 = h2o + k_w * rz * dt
        hg3 = h3o + k_t * rtx * dt
        hg4 = h4o + k_t * rty * dt
        e_hg = (0.5 * (h2o + hg2) * rz * dt + 0.5 * (h3o + hg3) * rtx * dt
                + 0.5 * (h4o + hg4) * rty * dt)
        el_out[E_HG][e] = h0o
        el_out[E_HG + 1][e] = h1o
        el_out[E_HG + 2][e] = hg2
        el_out[E_HG + 3][e] = hg3
        el_out[E_HG + 4][e] = hg4
        el_out[E_U_HG][e] = el_in[E_U_HG, e] + e_hg
        fzs = warp_forces(mf_x, mf_y, lx, ly, frame[6], area)
        c0 = corner_out(mf_x[0], mf_y[0], gam[0], b1[0], b2[0], fzs[0], area, h0o, h1o,
                        hg2, hg3, hg4, mxx, myy, mxy, qx, qy, frame)
        blk[0][e] = c0[0]
        blk[1][e] = c0[1]
        blk[2][e] = c0[2]
        blk[3][e] = c0[3]
        blk[4][e] = c0[4]
        blk[5][e] = c0[5]
        c1 = corner_out(mf_x[1], mf_y[1], gam[1], b1[1], b2[1], fzs[1], area, h0o, h1o,
                        hg2, hg3, hg4, mxx, myy, mxy, qx, qy, frame)
        blk[6][e] = c1[0]
        blk[7][e] = c1[1]
        blk[8][e] = c1[2]
        blk[9][e] = c1[3]
        blk[10][e] = c1[4]
        blk[11][e] = c1[5]
        c2 = corner_out(mf_x[2], mf_y[2], gam[2], b1[2], b2[2], fzs[2], area, h0o, h1o,
                        hg2, hg3, hg4, mxx, myy, mxy, qx, qy, frame)
        blk[12][e] = c2[0]
        blk[13][e] = c2[1]
        blk[14][e] = c2[2]
        blk[15][e] = c2[3]
        blk[16][e] = c2[4]
        blk[17][e] = c2[5]
        c3 = corner_out(mf_x[3], mf_y[3], gam[3], b1[3], b2[3], fzs[3], area, h0o, h1o,
                        hg2, hg3, hg4, mxx, myy, mxy, qx, qy, frame)
        blk[18][e] = c3[0]
        blk[19][e] = c3[1]
        blk[20][e] = c3[2]
        blk[21][e] = c3[3]
        blk[22][e] = c3[4]
        blk[23][e] = c3[5]
        # stable step
        edge2 = 0.0
        for i in range(4):
            j = (i + 1) % 4
            dx = px[j] - px[i]
            dy = py[j] - py[i]
            dz = pz[j] - pz[i]
            edge2 = max(edge2, dx * dx + dy * dy + dz * dz)
        c2 = max(c_m, kgt) / mu
        dt_e = area / math.sqrt(edge2 * c2)
        k_rot = area * (0.25 * kgt + d_b * bb)
        el_out[E_DT][e] = min(dt_e, 2.0 * math.sqrt(inertia[e] / k_rot))


@njit(**FAST)
def gather_corners(x, v, omega, quads, cn):
    """Each element's corner positions, velocities and spins into cn[corner, value, e]
    (scalar: the gathers)."""
    for e in range(quads.shape[0]):
        for i in range(4):
            n = np.uint64(quads[e, i])
            for d in range(3):
                cn[i, d, e] = x[n, d]
                cn[i, 3 + d, e] = v[n, d]
                cn[i, 6 + d, e] = omega[n, d]


@njit(**FAST)
def prototype_step(x, v, omega, quads, cn, *tables):
    gather_corners(x, v, omega, quads, cn)
    element_pass(quads.shape[0], cn, *tables)


def elastic_full_plate(n: int):
    """The benchmark plate (wovenimpact.benchmark) with the elastic steel section on the
    2×2 membrane, stepped 5 times, spins set so that every term is non-zero."""
    from wovenimpact.materials.metal import MetalParameters
    from wovenimpact.model import BoundaryConditions, Section, build_model
    from wovenimpact.model.mesh import plate_mesh
    from wovenimpact.solver import Workspace, step
    from wovenimpact.state import initial_state

    per_edge = int(round(math.sqrt(n)))
    size = 0.94e-3
    mesh = plate_mesh(per_edge * size, size)
    steel = MetalParameters(name="steel", kind="elastic", density=7850.0, modulus=STEEL_E,
                            poisson=STEEL_NU)
    sec = Section(steel, thickness=1e-3, membrane="full")
    bc = BoundaryConditions(mesh.n_nodes).fix(mesh.node_sets["edge_outer"])
    model = build_model(mesh.nodes, mesh.quads, {"s": sec}, np.zeros(mesh.n_elems, int), bcs=bc)
    r = np.linalg.norm(mesh.nodes[:, :2], axis=1) / (0.5 * per_edge * size)
    v0 = np.zeros((mesh.n_nodes, 3))
    v0[:, 2] = -50.0 * np.clip(1.0 - r, 0.0, None) ** 2
    st = initial_state(model, velocity=v0)
    st.x[:, :2] *= 1.02
    ws = Workspace.for_model(model, st)
    for _ in range(5):
        step(model, st, ws)
    st.omega[:] = 1e3 * np.sin(np.arange(st.omega.size).reshape(st.omega.shape))
    return model, st, ws


def best_seconds(f, repeats=7, inner=10):
    """Best of ``repeats`` means over ``inner`` calls."""
    best = math.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(inner):
            f()
        best = min(best, (time.perf_counter() - t0) / inner)
    return best


def main() -> int:
    from wovenimpact.kernels.shell_layout import (
        C_AREAL_MASS,
        C_BEND_E,
        C_BEND_NU,
        C_HOURGLASS,
        C_SHEAR_G,
        C_SHEAR_K,
        C_THICK,
        N_ELEM_STATE,
    )
    from wovenimpact.solver import explicit as X

    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    set_threads(1)
    model, st, ws = elastic_full_plate(n)
    ne = model.n_elems
    X.shell_forces(model, st, ws)  # the reference, compiled (or loaded) without noalias
    _cpu.CPUTargetOptions.finalize = _with_noalias
    ref_blocks, ref_el = ws.blocks.copy(), ws.elem.copy()
    mesh = ws.mesh
    sec = mesh.sections[0]
    thick = sec[C_THICK]
    gg = np.ascontiguousarray(np.transpose(mesh.gauss_grad, (1, 2, 3, 0)))
    gw = np.ascontiguousarray(mesh.gauss_weight.T)
    el_in = np.ascontiguousarray(st.elem.T)
    el_out = np.zeros((N_ELEM_STATE, ne))
    blocks = np.zeros((4, 6, ne))
    cn = np.zeros((4, 9, ne))
    args = (st.x, st.v, st.omega, mesh.quads, cn, gg, gw, mesh.area0, mesh.rot_inertia,
            st.dt, thick, sec[C_AREAL_MASS], STEEL_E, STEEL_NU, sec[C_BEND_E], sec[C_BEND_NU],
            sec[C_SHEAR_K] * sec[C_SHEAR_G] * thick, sec[C_HOURGLASS], el_in,
            tuple(el_out[j] for j in range(N_ELEM_STATE)),
            tuple(blocks[i, j] for i in range(4) for j in range(6)))
    prototype_step(*args)
    written = [E_N, E_N + 1, E_N + 2, E_M, E_M + 1, E_M + 2, E_Q, E_Q + 1, E_HG + 2, E_HG + 3,
               E_HG + 4, E_U_MEMB, E_U_BEND, E_U_HG, E_DT, E_KAPPA, E_KAPPA + 1, E_KAPPA + 2,
               *range(E_FG, E_FG + 16)]
    same = (np.array_equal(np.transpose(blocks, (2, 0, 1)), ref_blocks)
            and all(np.array_equal(el_out[c], ref_el[:, c]) for c in written))
    print(f"outputs bitwise equal to shell_force's: {same}")
    t_ref = best_seconds(lambda: X.shell_forces(model, st, ws))
    t_new = best_seconds(lambda: prototype_step(*args))
    t_gather = best_seconds(lambda: gather_corners(st.x, st.v, st.omega, mesh.quads, cn))
    asm = next(iter(element_pass.inspect_asm().values()))
    packed = sum(line.split()[0].endswith("pd") for line in asm.splitlines()
                 if line.strip() and ("%zmm" in line or "%ymm" in line))
    print(f"element_pass: {packed} packed-double instructions (0: not vectorised)")
    print(f"{ne} elements, 1 thread: shell_force {t_ref / ne * 1e9:.0f} ns, prototype "
          f"{t_new / ne * 1e9:.0f} ns per element ({t_ref / t_new:.2f}x; its corner gather "
          f"{t_gather / ne * 1e9:.0f} ns)")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
