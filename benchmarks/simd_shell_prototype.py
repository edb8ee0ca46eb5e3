"""Prototype of the SIMD element pass (issue 13): the 2×2-membrane elastic shell element
(resultant section) written so that LLVM vectorises it across elements, timed against
``shell_force`` on the same state. A measurement, not solver code.

    python benchmarks/simd_shell_prototype.py [N_ELEMENTS [THREADS]]   (100 000, 1)

Checks the outputs (corner forces and moments, resultants, energies, F at the points,
curvatures, stable step) against ``shell_force`` (bit for bit: the same formulas in the
same order; exit 1 otherwise), then prints ns per element of each: the pass on tables
of blocks (``element_pass``), and the same pass on the solver's row tables of element
state and corner forces, copied in and out per block (``element_pass_rows``).

What Numba's loops need to vectorise (found with LLVM's
``--pass-remarks-missed=loop-vectorize``; docs/theory.md §4.6, "SIMD element pass"):

1. Blocks of LANES = 8 elements with each value's 8 lanes side by side (one AVX-512
   register), all of a block's values contiguous, and the loop over a block's lanes
   innermost; indices unsigned (:func:`lane`), so that they are affine.
2. The corner gathers ``x[quads[e, i]]`` do not vectorise (LLVM's cost model declines
   gathers here): a scalar loop copies the block's corners into a small table first.
3. No run-time alias checks: LLVM must know that no output overlaps an input, and for a
   loop of 8 lanes the checks cost more than vectorising gains. Numba marks the array
   arguments of the function it generates for a ``prange`` body ``noalias``; the block
   kernel (``block_pass``) is compiled with ``forceinline=True``, so that LLVM inlines it
   there and its loads and stores are of those arguments. (Numba's own inlining,
   ``inline="always"``, would run the parfor array analysis over the helpers' tuples,
   which fails with "Dimension mismatch".)
4. No inner loops with long bodies (the vectoriser takes innermost loops only): the four
   Gauss points and corners are written out (``gauss_point``, ``corner_out``).
5. No early exits and no calls: ``sqrt`` and division vectorise; ``atan2`` and ``exp``
   have no vector form without SVML (not installed here).
"""

import math
import sys
import time

import numpy as np
import numba
from numba import get_thread_id, njit, prange

from wovenimpact.jit import set_threads
from wovenimpact.kernels.shell import (
    corotational_frame,
    elastic_membrane,
    element_stable_step,
    first_piola,
    hourglass_vectors,
    midpoint_frame,
    midpoint_rates,
    warp_forces,
)
from wovenimpact.kernels.shell_layout import (
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
    N_ELEM_STATE,
)

FAST = dict(boundscheck=False, error_model="numpy")
STEEL_E, STEEL_NU = 210e9, 0.3  # the benchmark's elastic plate (wovenimpact.benchmark)


LANES = 8  # elements per block: one AVX-512 register of doubles
_U = np.uint64


@njit(inline="always", **FAST)
def lane(b, width, c, lu):
    """Index of value c of lane lu of block b in a table of blocks of ``width`` values
    (unsigned, so that Numba adds no negative-index test and LLVM sees an affine
    index)."""
    return (b * _U(width) + _U(c)) * _U(LANES) + lu


@njit(inline="always", **FAST)
def col(b, c, lu):
    """Element-state column c of lane lu of block b."""
    return lane(b, N_ELEM_STATE, c, lu)


@njit(inline="always", **FAST)
def slot(c, lu):
    """Value c (corner·9 + x, y, z, v_x, v_y, v_z, ω_x, ω_y, ω_z) of the corner block."""
    return _U(c) * _U(LANES) + lu


@njit(inline="always", **FAST)
def corner_values(cn, tid, v, lu):
    """Value v (0…8: x, y, z, v_x, v_y, v_z, ω_x, ω_y, ω_z) of the four corners of lane lu
    in thread tid's corner block."""
    return (cn[tid, slot(v, lu)], cn[tid, slot(v + 9, lu)], cn[tid, slot(v + 18, lu)],
            cn[tid, slot(v + 27, lu)])


@njit(inline="always", **FAST)
def gauss_gradients(gg, bu, g, lu):
    """Gauss point g's ∂N_I/∂X (4) and ∂N_I/∂Y (4)."""
    return (gg[lane(bu, 32, 8 * g, lu)], gg[lane(bu, 32, 8 * g + 1, lu)],
            gg[lane(bu, 32, 8 * g + 2, lu)], gg[lane(bu, 32, 8 * g + 3, lu)],
            gg[lane(bu, 32, 8 * g + 4, lu)], gg[lane(bu, 32, 8 * g + 5, lu)],
            gg[lane(bu, 32, 8 * g + 6, lu)], gg[lane(bu, 32, 8 * g + 7, lu)])


@njit(inline="always", **FAST)
def gauss_point(el_out, su, gg, gw, bu, g, lu, lx, ly, e_mod, nu, thick):
    """2×2 point g of lane lu: F = Σ x̂_I ⊗ ∂N_I/∂X (into block su of the element state,
    E_FG; the gradients are block bu's), the elastic
    membrane, and its weighted energy, resultant and corner forces w_g P G_gI
    (shell.full_membrane's terms)."""
    a1, a2, a3, a4, c1, c2, c3, c4 = gauss_gradients(gg, bu, g, lu)
    wg = gw[lane(bu, 4, g, lu)]
    f11 = lx[0] * a1 + lx[1] * a2 + lx[2] * a3 + lx[3] * a4
    f12 = lx[0] * c1 + lx[1] * c2 + lx[2] * c3 + lx[3] * c4
    f21 = ly[0] * a1 + ly[1] * a2 + ly[2] * a3 + ly[3] * a4
    f22 = ly[0] * c1 + ly[1] * c2 + ly[2] * c3 + ly[3] * c4
    el_out[col(su, E_FG + 4 * g, lu)] = f11
    el_out[col(su, E_FG + 4 * g + 1, lu)] = f12
    el_out[col(su, E_FG + 4 * g + 2, lu)] = f21
    el_out[col(su, E_FG + 4 * g + 3, lu)] = f22
    w, c, a, b, c12 = elastic_membrane(f11, f12, f21, f22, e_mod, nu, thick)
    p11, p12, p21, p22 = first_piola(a, b, c12, f11, f12, f21, f22)
    return (wg * w, (wg * a, wg * b, wg * c12),
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


@njit(inline="always", **FAST)
def store_corner(blk, bu, i, lu, values):
    """Corner i's force and moment (6 values) into the block table of corner forces."""
    for k in range(6):
        blk[lane(bu, 24, 6 * i + k, lu)] = values[k]


@njit(forceinline=True, **FAST)
def block_pass(b, bs, tid, x, v, omega, quads, cn, gg, gw, a0s, inertia, dt, thick, mu, e_mod,
               nu, e_b, nu_b, kgt, r_hg, el_in, el_out, blk):
    """Block b of :func:`element_pass` (inlined by LLVM into the parallel loop, so that
    its arrays are the loop's noalias arguments; Numba's own inlining would run the
    parfor array analysis over the helpers' tuples, which fails). The block's state and
    corner forces are block bs of el_in, el_out and blk: b itself (tables of blocks), or
    the thread's block of scratch tables (:func:`element_pass_rows`)."""
    c_m = e_mod * thick / (1.0 - nu * nu)
    d_b = e_b * thick * thick * thick / (12.0 * (1.0 - nu_b * nu_b))
    bu = np.uint64(b)
    su = np.uint64(bs)
    # the block's corners (scalar: gathers) into cn[(corner·9 + value)·8 + lane]
    for l in range(LANES):
        for i in range(4):
            node = np.uint64(quads[b * LANES + l, i])
            for d in range(3):
                cn[tid, (i * 9 + d) * LANES + l] = x[node, d]
                cn[tid, (i * 9 + 3 + d) * LANES + l] = v[node, d]
                cn[tid, (i * 9 + 6 + d) * LANES + l] = omega[node, d]
    # the element arithmetic, vectorised across the block's lanes
    for l in range(LANES):
        lu = np.uint64(l)
        px = corner_values(cn, tid, 0, lu)
        py = corner_values(cn, tid, 1, lu)
        pz = corner_values(cn, tid, 2, lu)
        vx_ = corner_values(cn, tid, 3, lu)
        vy_ = corner_values(cn, tid, 4, lu)
        vz_ = corner_values(cn, tid, 5, lu)
        wx_ = corner_values(cn, tid, 6, lu)
        wy_ = corner_values(cn, tid, 7, lu)
        wz_ = corner_values(cn, tid, 8, lu)
        frame = corotational_frame(px, py, pz)
        area = frame[4]
        mid = midpoint_frame(px, py, pz, vx_, vy_, vz_, dt)
        lx, ly = frame[3]
        b1, b2 = frame[5]
        vx, vy, vz, tx, ty, dkx, dky, dkxy2, dgxz, dgyz = midpoint_rates(
            mid, vx_, vy_, vz_, wx_, wy_, wz_, dt)
        el_out[col(su, E_KAPPA, lu)] = el_in[col(su, E_KAPPA, lu)] + dkx
        el_out[col(su, E_KAPPA + 1, lu)] = el_in[col(su, E_KAPPA + 1, lu)] + dky
        el_out[col(su, E_KAPPA + 2, lu)] = el_in[col(su, E_KAPPA + 2, lu)] + dkxy2
        # membrane at the 2x2 points
        u0, n0, m0_, f0 = gauss_point(el_out, su, gg, gw, bu, 0, lu, lx, ly, e_mod, nu, thick)
        u1, n1, m1_, f1 = gauss_point(el_out, su, gg, gw, bu, 1, lu, lx, ly, e_mod, nu, thick)
        u2, n2, m2_, f2 = gauss_point(el_out, su, gg, gw, bu, 2, lu, lx, ly, e_mod, nu, thick)
        u3, n3, m3_, f3 = gauss_point(el_out, su, gg, gw, bu, 3, lu, lx, ly, e_mod, nu, thick)
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
        a0 = a0s[lane(bu, 1, 0, lu)]
        inv = 1.0 / a0
        el_out[col(su, E_N, lu)] = n_xx * inv
        el_out[col(su, E_N + 1, lu)] = n_yy * inv
        el_out[col(su, E_N + 2, lu)] = n_xy * inv
        el_out[col(su, E_U_MEMB, lu)] = u
        mf_x = (fx0, fx1, fx2, fx3)
        mf_y = (fy0, fy1, fy2, fy3)
        # bending and shear (resultant section)
        m0 = el_in[col(su, E_M, lu)]
        m1 = el_in[col(su, E_M + 1, lu)]
        m2 = el_in[col(su, E_M + 2, lu)]
        qo0, qo1 = el_in[col(su, E_Q, lu)], el_in[col(su, E_Q + 1, lu)]
        mxx = m0 + d_b * (dkx + nu_b * dky)
        myy = m1 + d_b * (dky + nu_b * dkx)
        mxy = m2 + d_b * 0.5 * (1.0 - nu_b) * dkxy2
        qx = qo0 + kgt * dgxz
        qy = qo1 + kgt * dgyz
        el_out[col(su, E_M, lu)] = mxx
        el_out[col(su, E_M + 1, lu)] = myy
        el_out[col(su, E_M + 2, lu)] = mxy
        el_out[col(su, E_Q, lu)] = qx
        el_out[col(su, E_Q + 1, lu)] = qy
        el_out[col(su, E_U_BEND, lu)] = el_in[col(su, E_U_BEND, lu)] + area * (
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
        h0o = el_in[col(su, E_HG + 0, lu)]
        h1o = el_in[col(su, E_HG + 1, lu)]
        h2o = el_in[col(su, E_HG + 2, lu)]
        h3o = el_in[col(su, E_HG + 3, lu)]
        h4o = el_in[col(su, E_HG + 4, lu)]
        hg2 = h2o + k_w * rz * dt
        hg3 = h3o + k_t * rtx * dt
        hg4 = h4o + k_t * rty * dt
        e_hg = (0.5 * (h2o + hg2) * rz * dt + 0.5 * (h3o + hg3) * rtx * dt
                + 0.5 * (h4o + hg4) * rty * dt)
        el_out[col(su, E_HG, lu)] = h0o
        el_out[col(su, E_HG + 1, lu)] = h1o
        el_out[col(su, E_HG + 2, lu)] = hg2
        el_out[col(su, E_HG + 3, lu)] = hg3
        el_out[col(su, E_HG + 4, lu)] = hg4
        el_out[col(su, E_U_HG, lu)] = el_in[col(su, E_U_HG, lu)] + e_hg
        fzs = warp_forces(mf_x, mf_y, lx, ly, frame[6], area)
        store_corner(blk, su, 0, lu, corner_out(
            mf_x[0], mf_y[0], gam[0], b1[0], b2[0], fzs[0], area, h0o, h1o, hg2, hg3, hg4,
            mxx, myy, mxy, qx, qy, frame))
        store_corner(blk, su, 1, lu, corner_out(
            mf_x[1], mf_y[1], gam[1], b1[1], b2[1], fzs[1], area, h0o, h1o, hg2, hg3, hg4,
            mxx, myy, mxy, qx, qy, frame))
        store_corner(blk, su, 2, lu, corner_out(
            mf_x[2], mf_y[2], gam[2], b1[2], b2[2], fzs[2], area, h0o, h1o, hg2, hg3, hg4,
            mxx, myy, mxy, qx, qy, frame))
        store_corner(blk, su, 3, lu, corner_out(
            mf_x[3], mf_y[3], gam[3], b1[3], b2[3], fzs[3], area, h0o, h1o, hg2, hg3, hg4,
            mxx, myy, mxy, qx, qy, frame))
        el_out[col(su, E_DT, lu)] = element_stable_step(
            px, py, pz, area, c_m, kgt, mu, inertia[lane(bu, 1, 0, lu)], d_b, bb)


@njit(parallel=True, **FAST)
def element_pass(nb, x, v, omega, quads, cn, gg, gw, a0s, inertia, dt, thick, mu, e_mod, nu,
                 e_b, nu_b, kgt, r_hg, el_in, el_out, blk):
    """``shell_force`` of a 2×2-membrane elastic element with a resultant section, for
    the nb blocks of LANES elements (element e = LANES·b + l; quads padded to whole
    blocks), on tables of blocks: value c of element e at [lane(b, width, c, l)]
    (:func:`lane`): gg (the 32 Gauss gradients, [g, ∂/∂X or ∂/∂Y, corner]), gw (4),
    a0s and inertia (1), el_in and el_out (the element state), blk (written: corner
    forces and moments, [corner, component]). cn (threads, 36·LANES) is a scratch block
    of corners per thread. No failure checks (every element of the plate is sound)."""
    for b in prange(nb):
        block_pass(b, b, get_thread_id(), x, v, omega, quads, cn, gg, gw, a0s, inertia, dt,
                   thick, mu, e_mod, nu, e_b, nu_b, kgt, r_hg, el_in, el_out, blk)


@njit(parallel=True, **FAST)
def element_pass_rows(nb, x, v, omega, quads, cn, gg, gw, a0s, inertia, dt, thick, mu, e_mod,
                      nu, e_b, nu_b, kgt, r_hg, rows_in, rows_out, blocks, s_in, s_out, s_blk):
    """:func:`element_pass` with the element state and corner forces in the solver's row
    tables, as they are today (rows_in, rows_out (n, N_ELEM_STATE); blocks (n, 4, 6)):
    each block's rows are copied into the thread's block of the scratch tables s_in,
    s_out, s_blk and back (scalar loops), the geometry staying in blocks."""
    for b in prange(nb):
        tid = get_thread_id()
        t = np.uint64(tid)
        for l in range(LANES):
            e = b * LANES + l
            for c in range(N_ELEM_STATE):
                s_in[col(t, c, np.uint64(l))] = rows_in[e, c]
                s_out[col(t, c, np.uint64(l))] = rows_in[e, c]
        block_pass(b, tid, tid, x, v, omega, quads, cn, gg, gw, a0s, inertia, dt, thick, mu,
                   e_mod, nu, e_b, nu_b, kgt, r_hg, s_in, s_out, s_blk)
        for l in range(LANES):
            e = b * LANES + l
            for c in range(N_ELEM_STATE):
                rows_out[e, c] = s_out[col(t, c, np.uint64(l))]
            for i in range(4):
                for j in range(6):
                    blocks[e, i, j] = s_blk[lane(t, 24, 6 * i + j, np.uint64(l))]


def to_blocks(a: np.ndarray, nb: int) -> np.ndarray:
    """(values, n) → the flat table of blocks [(b, value, lane)], the last element
    repeated into the padding lanes."""
    nv, n = a.shape
    padded = np.concatenate([a, np.repeat(a[:, -1:], nb * LANES - n, axis=1)], axis=1)
    return np.ascontiguousarray(padded.reshape(nv, nb, LANES).transpose(1, 0, 2)).ravel()


def from_blocks(flat: np.ndarray, nv: int, n: int) -> np.ndarray:
    """The inverse of :func:`to_blocks`: (values, n)."""
    nb = flat.size // (nv * LANES)
    return flat.reshape(nb, nv, LANES).transpose(1, 0, 2).reshape(nv, nb * LANES)[:, :n]


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
    )
    from wovenimpact.solver import explicit as X

    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    threads = int(sys.argv[2]) if len(sys.argv) > 2 else 1
    set_threads(threads)
    model, st, ws = elastic_full_plate(n)
    ne = model.n_elems
    X.shell_forces(model, st, ws)  # the reference
    ref_blocks, ref_el = ws.blocks.copy(), ws.elem.copy()
    mesh = ws.mesh
    sec = mesh.sections[0]
    thick = sec[C_THICK]
    nb = (ne + LANES - 1) // LANES
    quads = np.concatenate([mesh.quads, np.repeat(mesh.quads[-1:], nb * LANES - ne, axis=0)])
    el_in = to_blocks(st.elem.T, nb)
    el_out = np.zeros_like(el_in)
    blk = np.zeros(nb * 24 * LANES)
    args = (nb, st.x, st.v, st.omega, quads,
            np.zeros((numba.config.NUMBA_NUM_THREADS, 36 * LANES)),
            to_blocks(np.transpose(mesh.gauss_grad, (1, 2, 3, 0)).reshape(32, ne), nb),
            to_blocks(mesh.gauss_weight.T, nb), to_blocks(mesh.area0[None, :], nb),
            to_blocks(mesh.rot_inertia[None, :], nb), st.dt, thick, sec[C_AREAL_MASS],
            STEEL_E, STEEL_NU, sec[C_BEND_E], sec[C_BEND_NU],
            sec[C_SHEAR_K] * sec[C_SHEAR_G] * thick, sec[C_HOURGLASS], el_in, el_out, blk)
    element_pass(*args)
    state = from_blocks(el_out, N_ELEM_STATE, ne)
    written = [E_N, E_N + 1, E_N + 2, E_M, E_M + 1, E_M + 2, E_Q, E_Q + 1, E_HG + 2, E_HG + 3,
               E_HG + 4, E_U_MEMB, E_U_BEND, E_U_HG, E_DT, E_KAPPA, E_KAPPA + 1, E_KAPPA + 2,
               *range(E_FG, E_FG + 16)]
    same = (np.array_equal(from_blocks(blk, 24, ne).T.reshape(ne, 4, 6), ref_blocks)
            and all(np.array_equal(state[c], ref_el[:, c]) for c in written))
    # the same pass on the solver's row tables (padded to whole blocks)
    threads_max = numba.config.NUMBA_NUM_THREADS
    pad = nb * LANES - ne
    rows_in = np.concatenate([st.elem, np.repeat(st.elem[-1:], pad, axis=0)])
    rows_out = np.zeros_like(rows_in)
    blocks_rows = np.zeros((nb * LANES, 4, 6))
    rows_args = args[:-3] + (rows_in, rows_out, blocks_rows,
                             np.zeros(threads_max * N_ELEM_STATE * LANES),
                             np.zeros(threads_max * N_ELEM_STATE * LANES),
                             np.zeros(threads_max * 24 * LANES))
    element_pass_rows(*rows_args)
    same_rows = (np.array_equal(blocks_rows[:ne], ref_blocks)
                 and all(np.array_equal(rows_out[:ne, c], ref_el[:, c]) for c in written))
    print(f"outputs bitwise equal to shell_force's: {same} (blocks), {same_rows} (rows)")
    t_ref = best_seconds(lambda: X.shell_forces(model, st, ws))
    t_new = best_seconds(lambda: element_pass(*args))
    t_rows = best_seconds(lambda: element_pass_rows(*rows_args))
    for name, f in (("element_pass", element_pass), ("element_pass_rows", element_pass_rows)):
        asm = next(iter(f.inspect_asm().values()))
        packed = sum(line.split()[0].endswith("pd") for line in asm.splitlines()
                     if line.strip() and ("%zmm" in line or "%ymm" in line))
        print(f"{name}: {packed} packed-double instructions (0: not vectorised)")
    print(f"{ne} elements, {threads} thread(s), ns per element: shell_force "
          f"{t_ref / ne * 1e9:.0f}; blocks {t_new / ne * 1e9:.0f} ({t_ref / t_new:.2f}x); "
          f"state in rows {t_rows / ne * 1e9:.0f} ({t_ref / t_rows:.2f}x)")
    return 0 if same and same_rows else 1


if __name__ == "__main__":
    sys.exit(main())
