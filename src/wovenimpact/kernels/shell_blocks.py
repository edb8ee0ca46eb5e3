"""The element stage for fabric shells in blocks of 8, vectorised across the block (issue 13).

docs/theory.md §4.6 and docs/performance.md ("SIMD element pass"). ``shell.shell_force``
is one element: LLVM has no loop over elements to vectorise. Here the fabric elements of the default model — a 2×2
membrane (``full_membrane``), a resultant section, the tabulated crossover, the fibre
frame, the true trellis law, the virial resultant — go through the same arithmetic as
``shell_force`` and ``fabric.fabric_point``: every formula is one of their inlined helpers
(``plate_moments``, ``hourglass_update``, ``point_gradient``, ``yarn_directions``,
``virial_components``, ``cell_sum``, …), so the physics is written once; this module adds
the data layout, selects in place of branches, and the scalar kernel's sums over points
unrolled in its order, so that each value of a block of ``LANES`` elements is computed
for all lanes at once. Per block (one iteration of the parallel loop; every table below is
the thread's own scratch row):

1. *gather* (scalar): the corners' x, v, ω and the element state the step reads; a lane
   whose element or one of whose points is eroded is flagged, a point with a yarn
   damaged is marked for 4′;
2. *kinematics* (vector, :func:`kinematics_lanes`): frames, rates, curvature, F at the
   four Gauss points and the F the section's point sees, its yarn stretches; a
   degenerate or inverted element flags its lane;
3. *look-up* (scalar, :func:`table_lookup`): each point's knot cell in the crossover
   table and its 48 coefficients, copied point-major; a point outside the table or in
   an exactly-solved cell is marked for 4′;
4. *crossover* (vector over the block's 32 points, :func:`crossover_points`):
   ``fabric_point``'s default path — fibre frame, Hermite W, ∇W and heights, tensions,
   resultant, trellis shear, energy; a yarn at T_u (or at its strain ε_u) or a sliver
   marks the point bad;
   4′. *marked points* (scalar, :func:`exact_points`): ``fabric_point`` itself, which
   writes the point's row; a point that erodes or fails marks itself bad;
5. *element* (vector, :func:`element_lanes`): the rest of ``shell_force`` — the
   membrane's corner forces, bending and transverse shear, hourglass, corner forces,
   both stable steps; a bad point or a non-finite force or step flags the lane;
6. *scatter* (scalar): a lane's results into the solver's row tables. A flagged lane is
   left to ``shell_force`` in a second loop (its inputs, the start-of-step tables, are
   untouched), and the elements outside the blocks go through it in a third.

Elastic resultant sections with the one-point membrane take blocks of their own: the
same gather (with the Gauss-point F columns a one-point element carries), then
:func:`elastic_membrane_lanes` (stages 2–4: ``section_response`` on one point of
``elastic_membrane``, ``centre_membrane_forces``) and :func:`elastic_element_lanes`;
both kinds end in :func:`element_tail` (bending, hourglass, corner forces, steps).

The results are bitwise those of ``shell_force`` (tests/unit/test_shell_blocks.py), so a
run does not depend on which elements went through the blocks, nor on the thread count.
What LLVM needs to vectorise the three vector stages (found with
``--pass-remarks-missed=loop-vectorize``):
lane-major scratch with unsigned affine indices (:func:`at`), no gathers inside the
loop, no calls (``vecmath.atan2_upper``), selects instead of branches, and no alias
checks — each stage is compiled with ``forceinline=True`` so that LLVM inlines it into
the parallel loop's body, whose array arguments Numba marks ``noalias`` as long as it
finds no alias there (no bool assigned from another, no tuple of the same arrays:
theory §4.6, item 6).
"""

from __future__ import annotations

import math

import numpy as np
from numba import get_thread_id, prange

from wovenimpact.jit import block_kernel, inline_kernel, loop_kernel
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels.fabric import (
    fabric_point,
    family_stiffness,
    shear_modulus_true,
    shear_resultant,
    shear_step_stiffness,
    table_tensions,
    table_virial,
    trellis_angle,
    virial_components,
    yarn_directions,
    yarn_stretches,
)
from wovenimpact.kernels.fabric_table import (
    cell_sum,
    hermite_basis,
    hermite_terms,
    knot_interval,
)
from wovenimpact.kernels.shell import (
    centre_gradient,
    centre_membrane_forces,
    corner_global,
    corotational_frame,
    elastic_membrane,
    element_stable_step,
    family_stable_step,
    finish_element,
    bending_work,
    first_piola,
    hourglass_stiffnesses,
    hourglass_update,
    hourglass_vectors,
    kinematic_step,
    midpoint_frame,
    midpoint_rates,
    plate_moments,
    plate_stiffness,
    point_corner_forces,
    point_gradient,
    scalar_element,
    shear_forces,
    through_thickness_f,
    warp_forces,
)
from wovenimpact.kernels.bundles import ElementTables
from wovenimpact.kernels.shell_layout import (
    C_AREAL_MASS,
    C_BEND_E,
    C_BEND_NU,
    C_HOURGLASS,
    C_MAT,
    C_SHEAR_G,
    C_SHEAR_K,
    C_THICK,
    E_ALIVE,
    E_DT,
    E_DT_KIN,
    E_F,
    E_FG,
    E_HG,
    E_KAPPA,
    E_M,
    E_N,
    E_Q,
    E_U_BEND,
    E_U_HG,
    E_U_MEMB,
    ELASTIC_MODULUS,
    ELASTIC_POISSON,
    MAT_ELASTIC,
    N_ELEM_STATE,
    STEP_YARN,
)

LANES = 8  # elements per block: one AVX-512 register of doubles
POINTS = 4 * LANES  # the block's crossover points: Gauss point g of lane l is g·LANES + l
_U = np.uint64

# The thread's scratch rows. Per element, lane-major: value k of lane l at k·LANES + l
# (:func:`at`); per point, point-major: value k of point q = g·LANES + l at k·POINTS + q
# (:func:`atq`).
N_CORNER = 36  # corner I's x, y, z, v_x, v_y, v_z, ω_x, ω_y, ω_z at 9 I + 0…8
# the element state the step reads
V_KAPPA, V_M, V_Q, V_HG, V_U_BEND, V_U_HG = 0, 3, 6, 8, 13, 14
N_OLD = 15
N_OUT_EL = N_ELEM_STATE + 1  # the element state's columns, then the isotropic step
N_BLK = 24  # corner I's force and moment (global) at 6 I + 0…5
# per point: F seen by the material (4), then λ_w, λ_f
N_KIN = 6
Q_LAM = 4
N_COEF = 48  # per point: 4 corners × (W, H_w, H_f) × (f, f_x, f_y, f_xy), hermite_terms order
N_GEO = 4  # per point: the cell's λ_w0, h_w, λ_f0, h_f
# per point, crossover_point's results
(R_BAD, R_STIFF, R_NXX, R_NYY, R_NXY, R_KSHEAR, R_KW, R_KF, R_ENERGY, R_LAM_W, R_LAM_F,
 R_GAMMA, R_H_W, R_H_F, R_T_W, R_T_F, R_TAU, R_E_SHEAR) = range(18)
N_RES = 18
N_GG = 32  # static geometry per element: the Gauss gradients [g, ∂/∂X or ∂/∂Y, corner]
N_RG = 8  # the centre gradients [∂/∂X or ∂/∂Y, corner]


@inline_kernel
def at(k, lu):
    """Index of value k of lane lu in a lane-major scratch row (unsigned: affine)."""
    return _U(k) * _U(LANES) + lu


@inline_kernel
def atq(k, q):
    """Index of value k of point q (= g·LANES + lane) in a point-major scratch row."""
    return _U(k) * _U(POINTS) + q


@inline_kernel
def gb(b, width, k, lu):
    """Index of value k of lane lu of block b in a static table of ``width`` values per
    element, lane-major per block."""
    return (b * _U(width) + _U(k)) * _U(LANES) + lu


@inline_kernel
def corner_lane(cn, tid, v, lu):
    """Value v (0…8: x, y, z, v_x, v_y, v_z, ω_x, ω_y, ω_z) of the four corners of lane lu."""
    return (cn[tid, at(v, lu)], cn[tid, at(v + 9, lu)], cn[tid, at(v + 18, lu)],
            cn[tid, at(v + 27, lu)])


@inline_kernel
def gauss_f(gg, bu, g, lu, lx, ly):
    """F at Gauss point g of lane lu (``shell.full_membrane``'s formula) and the point's
    reference gradients q1 = ∂N/∂X, q2 = ∂N/∂Y."""
    q1 = (gg[gb(bu, N_GG, 8 * g, lu)], gg[gb(bu, N_GG, 8 * g + 1, lu)],
          gg[gb(bu, N_GG, 8 * g + 2, lu)], gg[gb(bu, N_GG, 8 * g + 3, lu)])
    q2 = (gg[gb(bu, N_GG, 8 * g + 4, lu)], gg[gb(bu, N_GG, 8 * g + 5, lu)],
          gg[gb(bu, N_GG, 8 * g + 6, lu)], gg[gb(bu, N_GG, 8 * g + 7, lu)])
    f11, f12, f21, f22 = point_gradient(lx, ly, q1, q2)
    return f11, f12, f21, f22, q1, q2


@inline_kernel
def ref_gradients(rg, bu, lu):
    """Lane lu's reference gradients at the centre, ∂N_I/∂X and ∂N_I/∂Y (4-tuples)."""
    return ((rg[gb(bu, N_RG, 0, lu)], rg[gb(bu, N_RG, 1, lu)], rg[gb(bu, N_RG, 2, lu)],
             rg[gb(bu, N_RG, 3, lu)]),
            (rg[gb(bu, N_RG, 4, lu)], rg[gb(bu, N_RG, 5, lu)], rg[gb(bu, N_RG, 6, lu)],
             rg[gb(bu, N_RG, 7, lu)]))


@inline_kernel
def lane_motion(cn, old, tid, lu, dt):
    """Lane lu's frames at x^n and x^{n−1/2}, corner velocities, the step's rates and the
    new curvature (``shell_force`` steps 1–2)."""
    px = corner_lane(cn, tid, 0, lu)
    py = corner_lane(cn, tid, 1, lu)
    pz = corner_lane(cn, tid, 2, lu)
    vx_ = corner_lane(cn, tid, 3, lu)
    vy_ = corner_lane(cn, tid, 4, lu)
    vz_ = corner_lane(cn, tid, 5, lu)
    frame = corotational_frame(px, py, pz)
    mid = midpoint_frame(px, py, pz, vx_, vy_, vz_, dt)
    rates = midpoint_rates(mid, vx_, vy_, vz_, corner_lane(cn, tid, 6, lu),
                           corner_lane(cn, tid, 7, lu), corner_lane(cn, tid, 8, lu), dt)
    kap = (old[tid, at(V_KAPPA, lu)] + rates[5], old[tid, at(V_KAPPA + 1, lu)] + rates[6],
           old[tid, at(V_KAPPA + 2, lu)] + rates[7])
    return px, py, pz, vx_, vy_, vz_, frame, mid, rates, kap


@inline_kernel
def point_kinematics(tid, bu, lu, g, gg, lx, ly, kap, kin):
    """Gauss point g of lane lu: F (``full_membrane``), the F its one-point section's
    material sees (``section_response``: z = 0), and that F's yarn stretches
    (``fabric.yarn_frame``), into kin. Returns whether either F is inverted."""
    f11, f12, f21, f22, _, _ = gauss_f(gg, bu, g, lu, lx, ly)
    h11, h12, h21, h22 = through_thickness_f(0.0, kap[0], kap[1], kap[2], f11, f12, f21, f22)
    q = _U(g * LANES) + lu
    kin[tid, atq(0, q)] = h11
    kin[tid, atq(1, q)] = h12
    kin[tid, atq(2, q)] = h21
    kin[tid, atq(3, q)] = h22
    lam_w, lam_f = yarn_stretches(h11, h12, h21, h22)
    kin[tid, atq(Q_LAM, q)] = lam_w
    kin[tid, atq(Q_LAM + 1, q)] = lam_f
    return (not (f11 * f22 - f12 * f21 > 0.0)) | (not (h11 * h22 - h12 * h21 > 0.0))


@block_kernel
def kinematics_lanes(tid, bu, cn, old, gg, rg, dt, kin, flag):
    """Stage 2: each lane's frames and rates, its points' F and stretches into kin; a
    degenerate or inverted element (area, midpoint area, F at the centre or at a point)
    adds to its lane's flag."""
    for ll in range(LANES):
        lu = _U(ll)
        px, py, pz, vx_, vy_, vz_, frame, mid, rates, kap = lane_motion(cn, old, tid, lu, dt)
        lx, ly = frame[3]
        g1, g2 = ref_gradients(rg, bu, lu)
        f11, f12, f21, f22 = centre_gradient(lx, ly, g1, g2)
        bad = not ((frame[4] > 0.0) & (mid[4] > 0.0) & (f11 * f22 - f12 * f21 > 0.0))
        bad = bad | point_kinematics(tid, bu, lu, 0, gg, lx, ly, kap, kin)
        bad = bad | point_kinematics(tid, bu, lu, 1, gg, lx, ly, kap, kin)
        bad = bad | point_kinematics(tid, bu, lu, 2, gg, lx, ly, kap, kin)
        bad = bad | point_kinematics(tid, bu, lu, 3, gg, lx, ly, kap, kin)
        flag[tid, lu] = flag[tid, lu] + (1.0 if bad else 0.0)


@block_kernel
def table_lookup(p, m, tid, kin, coef, geo, exact):
    """Stage 3 (scalar): each point's knot cell (``fabric_table.crossover_from_table``'s
    look-up) and its four corners' coefficients into coef, the cell into geo; a point
    outside the knots or in an exactly-solved cell is marked in exact (1.0; the gather
    marked those with a yarn damaged), for the scalar crossover (:func:`exact_points`)."""
    nw = int(p[m, FL.P_TAB_NW])
    nf = int(p[m, FL.P_TAB_NF])
    nbw = int(p[m, FL.P_TAB_NBW])
    kw = _U(int(p[m, FL.P_TAB_START]))
    kf = kw + _U(nw)
    stride = _U(FL.TAB_STRIDE)
    for qi in range(POINTS):
        q = _U(qi)
        i = knot_interval(p, m, kw, nw, kf + _U(nf), nbw, p[m, FL.P_TAB_IBW],
                          kin[tid, atq(Q_LAM, q)])
        j = knot_interval(p, m, kf, nf, kf + _U(nf + nbw), int(p[m, FL.P_TAB_NBF]),
                          p[m, FL.P_TAB_IBF], kin[tid, atq(Q_LAM + 1, q)])
        outside = i < 0 or j < 0
        if outside:
            i = 0
            j = 0
        u00 = _U(int(p[m, FL.P_TAB_DATA]) + FL.TAB_STRIDE * (i * nf + j))
        if outside or p[m, u00 + _U(FL.T_EXACT)] != 0.0:
            exact[tid, q] = 1.0
        geo[tid, atq(0, q)] = p[m, kw + _U(i)]
        geo[tid, atq(1, q)] = p[m, kw + _U(i + 1)] - p[m, kw + _U(i)]
        geo[tid, atq(2, q)] = p[m, kf + _U(j)]
        geo[tid, atq(3, q)] = p[m, kf + _U(j + 1)] - p[m, kf + _U(j)]
        u10 = u00 + stride * _U(nf)
        c = 0
        for u in (u00, u00 + stride, u10, u10 + stride):
            for k in range(4):
                coef[tid, atq(c + k, q)] = p[m, u + _U(FL.T_W + k)]
                coef[tid, atq(c + 4 + k, q)] = p[m, u + _U(FL.T_HW + k)]
                coef[tid, atq(c + 8 + k, q)] = p[m, u + _U(FL.T_HF + k)]
            c += 12


@inline_kernel
def cell_corner(coef, tid, c, q, ax, bx, dax, dbx, ay, by, day, dby):
    """``fabric_table.hermite_corner`` on the twelve coefficients copied at value c."""
    return hermite_terms(
        coef[tid, atq(c, q)], coef[tid, atq(c + 1, q)], coef[tid, atq(c + 2, q)],
        coef[tid, atq(c + 3, q)], coef[tid, atq(c + 4, q)], coef[tid, atq(c + 5, q)],
        coef[tid, atq(c + 6, q)], coef[tid, atq(c + 7, q)], coef[tid, atq(c + 8, q)],
        coef[tid, atq(c + 9, q)], coef[tid, atq(c + 10, q)], coef[tid, atq(c + 11, q)],
        ax, bx, dax, dbx, ay, by, day, dby)


@inline_kernel
def point_response_into(res, tid, q, bad, stiff, n_xx, n_yy, n_xy, k_shear, k_w, k_f, energy):
    """Point q's response — what ``shell.point_response`` returns of ``fabric_point`` — into
    res (R_BAD … R_ENERGY)."""
    res[tid, atq(R_BAD, q)] = bad
    res[tid, atq(R_STIFF, q)] = stiff
    res[tid, atq(R_NXX, q)] = n_xx
    res[tid, atq(R_NYY, q)] = n_yy
    res[tid, atq(R_NXY, q)] = n_xy
    res[tid, atq(R_KSHEAR, q)] = k_shear
    res[tid, atq(R_KW, q)] = k_w
    res[tid, atq(R_KF, q)] = k_f
    res[tid, atq(R_ENERGY, q)] = energy


@block_kernel
def crossover_points(tid, kin, coef, geo, res, mc):
    """Stage 4: ``fabric.fabric_point`` on its default path (fibre frame, both yarns
    intact, a tabulated cell, the virial resultant, the true trellis law) at every point
    of the block, into res (R_*); mc: the material's constants (:func:`material_lanes`).
    R_BAD is 1 where ``fabric_point`` would leave this path (inadmissible kinematics, a
    yarn at T_u or at ε_u, a sliver)."""
    (thick, ell0_w, ell0_f, lt0_w, lt0_f, ea_w, ea_f, tu_w, tu_f, g1, g2, gam1, gam2,
     intact) = mc
    for qi in range(POINTS):
        q = _U(qi)
        g11, g12 = kin[tid, atq(0, q)], kin[tid, atq(1, q)]
        g21, g22 = kin[tid, atq(2, q)], kin[tid, atq(3, q)]
        # 1. kinematics (fabric.yarn_frame)
        lam_w = kin[tid, atq(Q_LAM, q)]
        lam_f = kin[tid, atq(Q_LAM + 1, q)]
        ewx, ewy, efx, efy, cos_t, sin_t = yarn_directions(g11, g21, g12, g22, lam_w, lam_f)
        bad = not ((lam_w > 0.0) & (lam_f > 0.0) & (sin_t > 0.0) & (cos_t - cos_t == 0.0))
        gamma = trellis_angle(sin_t, cos_t)
        # 2. the table (fabric_table.crossover_from_table on the copied cell)
        x0, hx = geo[tid, atq(0, q)], geo[tid, atq(1, q)]
        y0, hy = geo[tid, atq(2, q)], geo[tid, atq(3, q)]
        ax0, ax1, bx0, bx1, dax0, dax1, dbx0, dbx1 = hermite_basis((lam_w - x0) / hx, hx)
        ay0, ay1, by0, by1, day0, day1, dby0, dby1 = hermite_basis((lam_f - y0) / hy, hy)
        w_tab, gw_tab, gf_tab, hw_tab, hf_tab = cell_sum(
            cell_corner(coef, tid, 0, q, ax0, bx0, dax0, dbx0, ay0, by0, day0, dby0),
            cell_corner(coef, tid, 12, q, ax0, bx0, dax0, dbx0, ay1, by1, day1, dby1),
            cell_corner(coef, tid, 24, q, ax1, bx1, dax1, dbx1, ay0, by0, day0, dby0),
            cell_corner(coef, tid, 36, q, ax1, bx1, dax1, dbx1, ay1, by1, day1, dby1))
        # fabric.tabulated_crossover
        ell_w, ell_f, h_w, h_f, l_w, l_f, t_w, t_f = table_tensions(
            lam_w, lam_f, ell0_w, ell0_f, hw_tab, hf_tab, gw_tab, gf_tab)
        # 3. failure (fabric.yarn_damage: instant at T_u, progressive from ε_u = T_u/EA)
        # and the intact sliver test (fabric.sliver_erodes): the scalar kernel's. T_u here is
        # the smallest regularised strength of the material's points (P_TU_FLOOR): a point
        # at or above it goes to fabric_point, which applies its own s T_u
        bad = bad | (t_w >= tu_w) | (t_f >= tu_f) | (t_w / ea_w >= tu_w / ea_w) | (
            t_f / ea_f >= tu_f / ea_f) | ((intact > 0.0) & (lam_w * lam_f < intact))
        # 4a. fabric.yarn_resultant, the table's virial branch
        c_w, c_f, yarn_w, yarn_f, den_w, den_f = table_virial(
            gw_tab, gf_tab, lam_w, lam_f, sin_t, ell_w, ell_f, ea_w, ea_f, lt0_w, lt0_f)
        scale = 1.0
        stiff, k_w, k_f = family_stiffness(scale, yarn_w, yarn_f, t_w, t_f, den_w, den_f, l_w,
                                           l_f, lt0_w, lt0_f, lam_w, lam_f, sin_t)
        n_xx, n_yy, n_xy = virial_components(c_w, c_f, ewx, ewy, efx, efy)
        # 4b. fabric.trellis_shear, the true law
        gs, g_tan, e_dens = shear_modulus_true(abs(gamma), g1, g2, gam1, gam2)
        tau = gs * gamma
        e_shear = thick * e_dens
        n_xx, n_yy, n_xy, cs = shear_resultant(n_xx, n_yy, n_xy, thick, tau, lam_w, lam_f, ewx,
                                               ewy, efx, efy, cos_t, sin_t)
        k_shear = shear_step_stiffness(thick, g_tan, cs)
        stiff += thick * g_tan
        # 5. fabric.stored_energy, the table's
        point_response_into(res, tid, q, 1.0 if bad else 0.0, stiff, n_xx, n_yy, n_xy, k_shear,
                            k_w, k_f, w_tab + e_shear)
        res[tid, atq(R_LAM_W, q)] = lam_w
        res[tid, atq(R_LAM_F, q)] = lam_f
        res[tid, atq(R_GAMMA, q)] = gamma
        res[tid, atq(R_H_W, q)] = h_w
        res[tid, atq(R_H_F, q)] = h_f
        res[tid, atq(R_T_W, q)] = t_w
        res[tid, atq(R_T_F, q)] = t_f
        res[tid, atq(R_TAU, q)] = tau
        res[tid, atq(R_E_SHEAR, q)] = e_shear


# keeps its long signature: a stage inlined into ``internal_force_blocks``, its arguments that
# loop's locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@block_kernel
def exact_points(p, m, tid, b, elems, mat_row, el_in, rows_in, rows_out, kin, exact, flag, res):
    """Stage 4′ (scalar): the points marked in exact (a yarn damaged, outside the table or
    in an exactly-solved cell) by ``fabric.fabric_point`` itself, as ``section_response``
    calls it — its row of rows_out written, its results into res in place of the
    vector stage's (lanes already flagged are left alone). A point whose yarns then both broke, or that failed, marks its lane
    bad (R_BAD): the element goes to ``shell_force``, which writes the row again."""
    for qi in range(POINTS):
        q = _U(qi)
        # (not in a lane already flagged: shell_force may not write an eroded element's
        # rows again, and would keep these)
        if exact[tid, q] == 0.0 or flag[tid, _U(qi % LANES)] != 0.0:
            continue
        g = qi // LANES
        e = _U(elems[b * _U(LANES) + _U(qi % LANES)])
        col = E_FG + 4 * g
        o11, o12, o21, o22 = through_thickness_f(
            0.0, el_in[e, E_KAPPA], el_in[e, E_KAPPA + 1], el_in[e, E_KAPPA + 2],
            el_in[e, col], el_in[e, col + 1], el_in[e, col + 2], el_in[e, col + 3])
        row = _U(mat_row[e]) + _U(g)
        st, stiff, n_xx, n_yy, n_xy, k_shear, k_w, k_f = fabric_point(
            p, m, o11, o12, o21, o22, kin[tid, atq(0, q)], kin[tid, atq(1, q)],
            kin[tid, atq(2, q)], kin[tid, atq(3, q)], rows_in, rows_out, row)
        point_response_into(
            res, tid, q, 0.0 if st == 0 and rows_out[row, FL.S_ALIVE] != 0.0 else 1.0, stiff,
            n_xx, n_yy, n_xy, k_shear, k_w, k_f, rows_out[row, FL.S_ENERGY])


@block_kernel
def material_lanes(p, m):
    """The crossover constants :func:`crossover_points` reads, as one tuple."""
    return (p[m, FL.P_THICK], p[m, FL.P_ELL0], p[m, FL.P_ELL0 + 1], p[m, FL.P_LT0],
            p[m, FL.P_LT0 + 1], p[m, FL.P_E] * p[m, FL.P_AREA],
            p[m, FL.P_E + 1] * p[m, FL.P_AREA + 1], p[m, FL.P_TU] * p[m, FL.P_TU_FLOOR],
            p[m, FL.P_TU + 1] * p[m, FL.P_TU_FLOOR + 1],
            p[m, FL.P_G1], p[m, FL.P_G2], p[m, FL.P_GAMMA1], p[m, FL.P_GAMMA2],
            p[m, FL.P_ERODE_INTACT])


@inline_kernel
def store_corner(out_blk, tid, i, lu, v):
    """Corner i's six values into the block's corner forces; returns its global f_x."""
    out_blk[tid, at(6 * i, lu)] = v[0]
    out_blk[tid, at(6 * i + 1, lu)] = v[1]
    out_blk[tid, at(6 * i + 2, lu)] = v[2]
    out_blk[tid, at(6 * i + 3, lu)] = v[3]
    out_blk[tid, at(6 * i + 4, lu)] = v[4]
    out_blk[tid, at(6 * i + 5, lu)] = v[5]
    return v[0]


@inline_kernel
def membrane_point(tid, bu, lu, g, gg, gw, res, lx, ly, out_el):
    """Gauss point g of lane lu in ``shell.full_membrane``: F (into out_el, E_FG) and
    the point's weighted terms from its one-point section (``section_response``: z = 0,
    weight 1) on the crossover's results in res.

    Returns (bad, w_g W, C_m, C_s, k_w, k_f, w_g N_xx, w_g N_yy, w_g N_xy, (w_g (P G)_xI),
    (w_g (P G)_yI)), each term as ``full_membrane`` adds it."""
    f11, f12, f21, f22, q1, q2 = gauss_f(gg, bu, g, lu, lx, ly)
    col = E_FG + 4 * g
    out_el[tid, at(col, lu)] = f11
    out_el[tid, at(col + 1, lu)] = f12
    out_el[tid, at(col + 2, lu)] = f21
    out_el[tid, at(col + 3, lu)] = f22
    q = _U(g * LANES) + lu
    c_pt = max(0.0, res[tid, atq(R_STIFF, q)])
    w_pt = 0.0 + 1.0 * res[tid, atq(R_ENERGY, q)]
    a = 0.0 + 1.0 * res[tid, atq(R_NXX, q)]
    b = 0.0 + 1.0 * res[tid, atq(R_NYY, q)]
    c12 = 0.0 + 1.0 * res[tid, atq(R_NXY, q)]
    c_s = max(0.0, res[tid, atq(R_KSHEAR, q)])
    k_w = max(0.0, res[tid, atq(R_KW, q)])
    k_f = max(0.0, res[tid, atq(R_KF, q)])
    wg = gw[gb(bu, 4, g, lu)]
    p11, p12, p21, p22 = first_piola(a, b, c12, f11, f12, f21, f22)
    fx, fy = point_corner_forces(wg, p11, p12, p21, p22, q1, q2)
    return (res[tid, atq(R_BAD, q)], wg * w_pt, c_pt, c_s, k_w, k_f, wg * a, wg * b, wg * c12,
            fx, fy)


# keeps its long signature: a stage inlined into ``elastic_element_lanes`` and ``element_lanes``,
# its arguments that loop's locals (a bundle written through in a parallel loop's body can lose
# its writes: kernels/bundles.py)
@block_kernel
def element_tail(tid, bu, lu, old, out_el, out_blk, inert, dt, px, py, pz, vx_, vy_, vz_,
                 frame, mid, rates, g1, g2, mf_x, mf_y, c_memb, cs_max, kw_max, kf_max,
                 full, thick, mu, e_b, nu_b, kgt, r_hg, step_yarn, kin_frac):
    """Steps 4–7 of ``shell_force`` for lane lu, on its membrane's results: bending and
    transverse shear of a resultant section, hourglass (in-plane modes too unless
    ``full``: a 2×2 membrane has none), the corner forces into out_blk, the element
    state's columns and both stable steps into out_el. Returns 1.0 if the corner forces
    and the step are finite, else 0.0."""
    area = frame[4]
    lx, ly = frame[3]
    b1, b2 = frame[5]
    vx, vy, vz, tx, ty, dkx, dky, dkxy2, dgxz, dgyz = rates
    # 4. bending and transverse shear (shell.bending_and_shear, resultant section)
    m_old = (old[tid, at(V_M, lu)], old[tid, at(V_M + 1, lu)], old[tid, at(V_M + 2, lu)])
    q_old = (old[tid, at(V_Q, lu)], old[tid, at(V_Q + 1, lu)])
    dk = (dkx, dky, dkxy2)
    dg = (dgxz, dgyz)
    d_b = plate_stiffness(e_b, thick, nu_b)
    mxx, myy, mxy = plate_moments(m_old, d_b, nu_b, dk)
    qx, qy = shear_forces(q_old, kgt, dg)
    out_el[tid, at(E_M, lu)] = mxx
    out_el[tid, at(E_M + 1, lu)] = myy
    out_el[tid, at(E_M + 2, lu)] = mxy
    out_el[tid, at(E_Q, lu)] = qx
    out_el[tid, at(E_Q + 1, lu)] = qy
    out_el[tid, at(E_U_BEND, lu)] = old[tid, at(V_U_BEND, lu)] + bending_work(
        area, 1.0, m_old, (mxx, myy, mxy), q_old, (qx, qy), dk, dg)
    # 5. hourglass (shell.hourglass_resultants)
    gam, bb = hourglass_vectors(lx, ly, b1, b2)
    gam_mid = hourglass_vectors(mid[3][0], mid[3][1], mid[5][0], mid[5][1])[0]
    k_m, k_wm, k_t = hourglass_stiffnesses(r_hg, c_memb, area, bb, d_b, full)
    (hg0, hg1, hg2, hg3, hg4), e_hg = hourglass_update(
        (old[tid, at(V_HG, lu)], old[tid, at(V_HG + 1, lu)], old[tid, at(V_HG + 2, lu)],
         old[tid, at(V_HG + 3, lu)], old[tid, at(V_HG + 4, lu)]), k_m, k_wm, k_t, gam_mid,
        (vx, vy, vz, tx, ty), dt)
    out_el[tid, at(E_HG, lu)] = hg0
    out_el[tid, at(E_HG + 1, lu)] = hg1
    out_el[tid, at(E_HG + 2, lu)] = hg2
    out_el[tid, at(E_HG + 3, lu)] = hg3
    out_el[tid, at(E_HG + 4, lu)] = hg4
    out_el[tid, at(E_U_HG, lu)] = old[tid, at(V_U_HG, lu)] + e_hg
    # 6. corner forces (shell.warp_forces, shell.corner_forces)
    fzs = warp_forces(mf_x, mf_y, lx, ly, frame[6], area)
    fsum = 0.0
    fsum += store_corner(out_blk, tid, 0, lu, corner_global(
        frame, area, b1[0], b2[0], mf_x[0], mf_y[0], gam[0], fzs[0], hg0, hg1, hg2, hg3,
        hg4, mxx, myy, mxy, qx, qy))
    fsum += store_corner(out_blk, tid, 1, lu, corner_global(
        frame, area, b1[1], b2[1], mf_x[1], mf_y[1], gam[1], fzs[1], hg0, hg1, hg2, hg3,
        hg4, mxx, myy, mxy, qx, qy))
    fsum += store_corner(out_blk, tid, 2, lu, corner_global(
        frame, area, b1[2], b2[2], mf_x[2], mf_y[2], gam[2], fzs[2], hg0, hg1, hg2, hg3,
        hg4, mxx, myy, mxy, qx, qy))
    fsum += store_corner(out_blk, tid, 3, lu, corner_global(
        frame, area, b1[3], b2[3], mf_x[3], mf_y[3], gam[3], fzs[3], hg0, hg1, hg2, hg3,
        hg4, mxx, myy, mxy, qx, qy))
    # 7. stable steps (both options computed, one selected: a select vectorises)
    inertia = inert[gb(bu, 1, 0, lu)]
    dt_iso = element_stable_step(px, py, pz, area, c_memb, kgt, mu, inertia, d_b, bb)
    dt_yarn = min(element_stable_step(px, py, pz, area, cs_max, kgt, mu, inertia, d_b, bb),
                  family_stable_step(kw_max, cs_max, mu, g1),
                  family_stable_step(kf_max, cs_max, mu, g2))
    dt_kin = kinematic_step(px, py, pz, vx_, vy_, vz_, kin_frac)
    dt_e = dt_yarn if step_yarn else dt_iso
    out_el[tid, at(E_DT, lu)] = dt_e
    out_el[tid, at(E_DT_KIN, lu)] = dt_kin if step_yarn else math.inf
    out_el[tid, at(N_ELEM_STATE, lu)] = dt_iso
    return 1.0 if fsum + dt_e - (fsum + dt_e) == 0.0 else 0.0


# keeps its long signature: a stage inlined into ``internal_force_blocks``, its arguments that
# loop's locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@block_kernel
def element_lanes(tid, bu, cn, old, res, flag, gg, gw, rg, a0s, inert, out_el, out_blk, dt,
                  thick, mu, e_b, nu_b, kgt, r_hg, step_yarn, kin_frac):
    """Stage 5: the rest of ``shell_force`` for every lane of the block (see the module
    docstring), on the points' results in res: the element state's columns and the
    isotropic step into out_el, the corner forces into out_blk; a lane with a point
    off the default path (res R_BAD) or a non-finite force or step adds to its flag."""
    for ll in range(LANES):
        lu = _U(ll)
        px, py, pz, vx_, vy_, vz_, frame, mid, rates, kap = lane_motion(cn, old, tid, lu, dt)
        lx, ly = frame[3]
        out_el[tid, at(E_KAPPA, lu)] = kap[0]
        out_el[tid, at(E_KAPPA + 1, lu)] = kap[1]
        out_el[tid, at(E_KAPPA + 2, lu)] = kap[2]
        # 3. the centre's F (outputs)
        g1, g2 = ref_gradients(rg, bu, lu)
        f11, f12, f21, f22 = centre_gradient(lx, ly, g1, g2)
        out_el[tid, at(E_F, lu)] = f11
        out_el[tid, at(E_F + 1, lu)] = f12
        out_el[tid, at(E_F + 2, lu)] = f21
        out_el[tid, at(E_F + 3, lu)] = f22
        # the 2×2 membrane (shell.full_membrane), its four points written out: the
        # vectoriser takes innermost loops only
        m0 = membrane_point(tid, bu, lu, 0, gg, gw, res, lx, ly, out_el)
        m1 = membrane_point(tid, bu, lu, 1, gg, gw, res, lx, ly, out_el)
        m2 = membrane_point(tid, bu, lu, 2, gg, gw, res, lx, ly, out_el)
        m3 = membrane_point(tid, bu, lu, 3, gg, gw, res, lx, ly, out_el)
        u = (((0.0 + m0[1]) + m1[1]) + m2[1]) + m3[1]
        c_memb = max(max(max(max(0.0, m0[2]), m1[2]), m2[2]), m3[2])
        cs_max = max(max(max(max(0.0, m0[3]), m1[3]), m2[3]), m3[3])
        kw_max = max(max(max(max(0.0, m0[4]), m1[4]), m2[4]), m3[4])
        kf_max = max(max(max(max(0.0, m0[5]), m1[5]), m2[5]), m3[5])
        n_xx = (((0.0 + m0[6]) + m1[6]) + m2[6]) + m3[6]
        n_yy = (((0.0 + m0[7]) + m1[7]) + m2[7]) + m3[7]
        n_xy = (((0.0 + m0[8]) + m1[8]) + m2[8]) + m3[8]
        fxa, fxb, fxc, fxd = m0[9], m1[9], m2[9], m3[9]
        fya, fyb, fyc, fyd = m0[10], m1[10], m2[10], m3[10]
        mf_x = ((((0.0 + fxa[0]) + fxb[0]) + fxc[0]) + fxd[0],
                (((0.0 + fxa[1]) + fxb[1]) + fxc[1]) + fxd[1],
                (((0.0 + fxa[2]) + fxb[2]) + fxc[2]) + fxd[2],
                (((0.0 + fxa[3]) + fxb[3]) + fxc[3]) + fxd[3])
        mf_y = ((((0.0 + fya[0]) + fyb[0]) + fyc[0]) + fyd[0],
                (((0.0 + fya[1]) + fyb[1]) + fyc[1]) + fyd[1],
                (((0.0 + fya[2]) + fyb[2]) + fyc[2]) + fyd[2],
                (((0.0 + fya[3]) + fyb[3]) + fyc[3]) + fyd[3])
        bad_points = m0[0] + m1[0] + m2[0] + m3[0]
        inv = 1.0 / a0s[gb(bu, 1, 0, lu)]
        out_el[tid, at(E_N, lu)] = n_xx * inv
        out_el[tid, at(E_N + 1, lu)] = n_yy * inv
        out_el[tid, at(E_N + 2, lu)] = n_xy * inv
        out_el[tid, at(E_U_MEMB, lu)] = u
        finite = element_tail(tid, bu, lu, old, out_el, out_blk, inert, dt, px, py, pz, vx_,
                              vy_, vz_, frame, mid, rates, g1, g2, mf_x, mf_y, c_memb, cs_max,
                              kw_max, kf_max, True, thick, mu, e_b, nu_b, kgt, r_hg, step_yarn,
                              kin_frac)
        # a count, not a conditional store (which LLVM would not vectorise): > 0 flags
        flag[tid, lu] = flag[tid, lu] + bad_points + (1.0 - finite)


# --- elastic sections: the one-point membrane of a resultant section ---------------------
# per lane, in res (lane-major, :func:`at`): what elastic_membrane_lanes hands on
(L_F, L_N, L_W, L_C, L_MFX, L_MFY) = (0, 4, 7, 8, 9, 13)
N_LANE_MEMB = 17
# they go into the res row, whose bounds the kernels do not check
assert N_LANE_MEMB <= 4 * N_RES


@block_kernel
def elastic_membrane_lanes(tid, bu, cn, old, rg, a0s, dt, res, flag, modulus, poisson, thick):
    """Stages 2–4 of an elastic block (``shell_force`` with a one-point membrane and a
    resultant section of ``MAT_ELASTIC``: ``section_response`` with n = 1 on
    ``elastic_membrane``, then ``centre_membrane_forces``): each lane's centre F, its
    resultant N, membrane energy and tangent and corner forces into res; a degenerate or
    inverted element adds to its lane's flag."""
    for ll in range(LANES):
        lu = _U(ll)
        px, py, pz, vx_, vy_, vz_, frame, mid, rates, kap = lane_motion(cn, old, tid, lu, dt)
        lx, ly = frame[3]
        g1, g2 = ref_gradients(rg, bu, lu)
        f11, f12, f21, f22 = centre_gradient(lx, ly, g1, g2)
        h11, h12, h21, h22 = through_thickness_f(0.0, kap[0], kap[1], kap[2], f11, f12, f21,
                                                 f22)
        bad = not ((frame[4] > 0.0) & (mid[4] > 0.0) & (f11 * f22 - f12 * f21 > 0.0)
                   & (h11 * h22 - h12 * h21 > 0.0))
        energy, c, a, b, c12 = elastic_membrane(h11, h12, h21, h22, modulus, poisson, thick)
        # section_response's sums over its one point (z = 0, weight 1)
        n_xx = 0.0 + 1.0 * a
        n_yy = 0.0 + 1.0 * b
        n_xy = 0.0 + 1.0 * c12
        a0 = a0s[gb(bu, 1, 0, lu)]
        mf_x, mf_y = centre_membrane_forces(a0, n_xx, n_yy, n_xy, f11, f12, f21, f22, g1, g2)
        res[tid, at(L_F, lu)] = f11
        res[tid, at(L_F + 1, lu)] = f12
        res[tid, at(L_F + 2, lu)] = f21
        res[tid, at(L_F + 3, lu)] = f22
        res[tid, at(L_N, lu)] = n_xx
        res[tid, at(L_N + 1, lu)] = n_yy
        res[tid, at(L_N + 2, lu)] = n_xy
        res[tid, at(L_W, lu)] = (0.0 + 1.0 * energy) * a0
        res[tid, at(L_C, lu)] = max(0.0, c)
        for i in range(4):
            res[tid, at(L_MFX + i, lu)] = mf_x[i]
            res[tid, at(L_MFY + i, lu)] = mf_y[i]
        flag[tid, lu] = flag[tid, lu] + (1.0 if bad else 0.0)


# keeps its long signature: a stage inlined into ``internal_force_blocks``, its arguments that
# loop's locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@block_kernel
def elastic_element_lanes(tid, bu, cn, old, res, flag, rg, inert, out_el, out_blk, dt, thick,
                          mu, e_b, nu_b, kgt, r_hg, step_yarn, kin_frac):
    """Stage 5 of an elastic block: the element state's membrane columns from res, then
    :func:`element_tail` with the in-plane hourglass modes."""
    for ll in range(LANES):
        lu = _U(ll)
        px, py, pz, vx_, vy_, vz_, frame, mid, rates, kap = lane_motion(cn, old, tid, lu, dt)
        out_el[tid, at(E_KAPPA, lu)] = kap[0]
        out_el[tid, at(E_KAPPA + 1, lu)] = kap[1]
        out_el[tid, at(E_KAPPA + 2, lu)] = kap[2]
        for k in range(4):
            out_el[tid, at(E_F + k, lu)] = res[tid, at(L_F + k, lu)]
        for k in range(3):
            out_el[tid, at(E_N + k, lu)] = res[tid, at(L_N + k, lu)]
        out_el[tid, at(E_U_MEMB, lu)] = res[tid, at(L_W, lu)]
        g1, g2 = ref_gradients(rg, bu, lu)
        mf_x = (res[tid, at(L_MFX, lu)], res[tid, at(L_MFX + 1, lu)],
                res[tid, at(L_MFX + 2, lu)], res[tid, at(L_MFX + 3, lu)])
        mf_y = (res[tid, at(L_MFY, lu)], res[tid, at(L_MFY + 1, lu)],
                res[tid, at(L_MFY + 2, lu)], res[tid, at(L_MFY + 3, lu)])
        c_memb = res[tid, at(L_C, lu)]
        finite = element_tail(tid, bu, lu, old, out_el, out_blk, inert, dt, px, py, pz, vx_,
                              vy_, vz_, frame, mid, rates, g1, g2, mf_x, mf_y, c_memb, c_memb,
                              0.0, 0.0, False, thick, mu, e_b, nu_b, kgt, r_hg, step_yarn,
                              kin_frac)
        flag[tid, lu] = flag[tid, lu] + (1.0 - finite)


@loop_kernel
def internal_force_blocks(mesh, motion, dt, tables, results, dt_erode, erode_inverted, plan,
                          scratch):
    """The element stage (``shell.internal_force_for_shells``' contract and returns) with
    the plan's fabric elements in blocks of LANES (the stages of the module docstring)
    and the rest, ``plan.others``, by ``shell_force``.

    plan: :class:`~wovenimpact.kernels.bundles.BlockPlan`; scratch:
    :class:`~wovenimpact.kernels.bundles.BlockScratch` (one row per thread).
    """
    # one bundle member per statement, read before the parallel loops (shell.py explains)
    quads = mesh.quads
    sections = mesh.sections
    mat_kind = mesh.mat_kind
    mat_params = mesh.mat_params
    step_yarn = mesh.step_mode == STEP_YARN
    kin_frac = mesh.kinematic_fraction
    x = motion.x
    v = motion.v
    omega = motion.omega
    el_in = tables.el_in
    el_out = tables.el_out
    blocks = results.blocks
    status = results.status
    eroded_now = results.eroded_now
    alive = results.alive
    elems = plan.elems
    lanes = plan.lanes
    block_sec = plan.section
    others = plan.others
    gg = plan.gauss_grad
    gw = plan.gauss_weight
    rg = plan.ref_grad
    a0s = plan.area0
    inert = plan.rot_inertia
    cn = scratch.corners
    old = scratch.old
    kin = scratch.kin
    coef = scratch.coef
    geo = scratch.geo
    flag = scratch.flag
    exact = scratch.exact
    res = scratch.res
    out_el = scratch.out_el
    out_blk = scratch.out_blk
    pending = scratch.pending
    m_in = tables.mat_in
    m_out = tables.mat_out
    mat_row = mesh.mat_row
    rows_in = m_in
    rows_out = m_out
    pw = rows_in.shape[1]
    rows = ElementTables(el_in, el_out, rows_in, rows_out)
    n_failed = 0
    n_eroded = 0
    dt_min = math.inf
    for bi in prange(lanes.shape[0]):
        b = _U(bi)
        tid_i = get_thread_id()
        if tid_i >= flag.shape[0]:  # no scratch row for this thread: shell_force takes it
            for ll in range(LANES):
                pending[b * _U(LANES) + _U(ll)] = 1
            continue
        tid = _U(tid_i)
        sec = _U(block_sec[b])
        thick = sections[sec, C_THICK]
        m = _U(sections[sec, C_MAT])
        kind = mat_kind[m]
        # 1. gather
        for ll in range(LANES):
            lu = _U(ll)
            e = _U(elems[b * _U(LANES) + lu])
            for i in range(4):
                node = _U(quads[e, i])
                for d in range(3):
                    cn[tid, at(9 * i + d, lu)] = x[node, d]
                    cn[tid, at(9 * i + 3 + d, lu)] = v[node, d]
                    cn[tid, at(9 * i + 6 + d, lu)] = omega[node, d]
            for k in range(3):
                old[tid, at(V_KAPPA + k, lu)] = el_in[e, E_KAPPA + k]
                old[tid, at(V_M + k, lu)] = el_in[e, E_M + k]
            old[tid, at(V_Q, lu)] = el_in[e, E_Q]
            old[tid, at(V_Q + 1, lu)] = el_in[e, E_Q + 1]
            for k in range(5):
                old[tid, at(V_HG + k, lu)] = el_in[e, E_HG + k]
            old[tid, at(V_U_BEND, lu)] = el_in[e, E_U_BEND]
            old[tid, at(V_U_HG, lu)] = el_in[e, E_U_HG]
            # (counted in floats: a bool assigned in a parallel loop's body counts as an
            # alias for Numba, which then gives the body's arrays no ``noalias``)
            # an eroded element or point: the lane goes to shell_force; a point with a
            # yarn damaged: to fabric_point (its exact solve), the rest of the lane stays
            worn = 0.0 if el_in[e, E_ALIVE] != 0.0 else 1.0
            if kind == MAT_ELASTIC:
                # the 2×2 membrane's Gauss-point F, which a one-point one carries
                for k in range(16):
                    out_el[tid, at(E_FG + k, lu)] = el_in[e, E_FG + k]
            else:
                row0 = _U(mat_row[e])
                for g in range(4):
                    r = row0 + _U(g)
                    worn += 0.0 if rows_in[r, FL.S_ALIVE] != 0.0 else 1.0
                    exact[tid, _U(g * LANES) + lu] = (
                        (0.0 if rows_in[r, FL.S_DAMAGE] == 0.0 else 1.0)
                        + (0.0 if rows_in[r, FL.S_DAMAGE + 1] == 0.0 else 1.0))
            flag[tid, lu] = worn
        # 2.–5.
        mu = sections[sec, C_AREAL_MASS]
        e_b = sections[sec, C_BEND_E]
        nu_b = sections[sec, C_BEND_NU]
        kgt = sections[sec, C_SHEAR_K] * sections[sec, C_SHEAR_G] * thick
        r_hg = sections[sec, C_HOURGLASS]
        if kind == MAT_ELASTIC:
            elastic_membrane_lanes(tid, b, cn, old, rg, a0s, dt, res, flag,
                                   mat_params[m, ELASTIC_MODULUS],
                                   mat_params[m, ELASTIC_POISSON], thick)
            elastic_element_lanes(tid, b, cn, old, res, flag, rg, inert, out_el, out_blk, dt,
                                  thick, mu, e_b, nu_b, kgt, r_hg, step_yarn, kin_frac)
        else:
            kinematics_lanes(tid, b, cn, old, gg, rg, dt, kin, flag)
            table_lookup(mat_params, m, tid, kin, coef, geo, exact)
            crossover_points(tid, kin, coef, geo, res, material_lanes(mat_params, m))
            exact_points(mat_params, m, tid, b, elems, mat_row, el_in, rows_in, rows_out,
                         kin, exact, flag, res)
            element_lanes(tid, b, cn, old, res, flag, gg, gw, rg, a0s, inert, out_el, out_blk,
                          dt, thick, mu, e_b, nu_b, kgt, r_hg, step_yarn, kin_frac)
        # 6. scatter; a flagged lane is left for the scalar kernel (the next loop)
        for ll in range(lanes[b]):
            lu = _U(ll)
            e = _U(elems[b * _U(LANES) + lu])
            if flag[tid, lu] != 0.0:
                pending[b * _U(LANES) + lu] = 1
                continue
            pending[b * _U(LANES) + lu] = 0
            keep = el_in[e, E_ALIVE]
            for c in range(N_ELEM_STATE):
                el_out[e, c] = out_el[tid, at(c, lu)]
            el_out[e, E_ALIVE] = keep
            for i in range(4):
                for k in range(6):
                    blocks[e, i, k] = out_blk[tid, at(6 * i + k, lu)]
            row0 = _U(mat_row[e])
            if kind == MAT_ELASTIC:  # shell.carry_state's one row (an elastic point has none)
                for j in range(pw):
                    rows_out[row0, j] = rows_in[row0, j]
            else:
                for g in range(4):
                    r = row0 + _U(g)
                    q = _U(g * LANES) + lu
                    if exact[tid, q] != 0.0:  # fabric_point wrote its state columns
                        for j in range(FL.N_STATE, pw):
                            rows_out[r, j] = rows_in[r, j]
                        continue
                    for j in range(pw):
                        rows_out[r, j] = rows_in[r, j]
                    rows_out[r, FL.S_LAMBDA] = res[tid, atq(R_LAM_W, q)]
                    rows_out[r, FL.S_LAMBDA + 1] = res[tid, atq(R_LAM_F, q)]
                    rows_out[r, FL.S_GAMMA] = res[tid, atq(R_GAMMA, q)]
                    rows_out[r, FL.S_ITER] = 0.0
                    rows_out[r, FL.S_H] = res[tid, atq(R_H_W, q)]
                    rows_out[r, FL.S_H + 1] = res[tid, atq(R_H_F, q)]
                    rows_out[r, FL.S_TENSION] = res[tid, atq(R_T_W, q)]
                    rows_out[r, FL.S_TENSION + 1] = res[tid, atq(R_T_F, q)]
                    rows_out[r, FL.S_TAU] = res[tid, atq(R_TAU, q)]
                    rows_out[r, FL.S_SHEAR_ENERGY] = res[tid, atq(R_E_SHEAR, q)]
                    rows_out[r, FL.S_ENERGY] = res[tid, atq(R_ENERGY, q)]
                # shell.sync_yarn_damage
                for fam in range(2):
                    d = 0.0
                    for g in range(4):
                        d = max(d, rows_out[row0 + _U(g), FL.S_DAMAGE + fam])
                    for g in range(4):
                        rows_out[row0 + _U(g), FL.S_DAMAGE + fam] = d
            failed, er, dt_own = finish_element(e, 0, 0, out_el[tid, at(N_ELEM_STATE, lu)],
                                                el_out, blocks, status, eroded_now, alive,
                                                dt_erode, erode_inverted)
            dt_min = min(dt_min, dt_own)
            n_failed += failed
            n_eroded += er
    # the scalar kernel: the lanes flagged above, then the elements outside the blocks.
    # (Apart from the block loop: it hands shell_force the tables in a tuple, which Numba
    # counts as aliases of the arrays the block loop writes, and would then not mark
    # that loop's arrays noalias, and LLVM would not vectorise its stages.)
    for bi in prange(lanes.shape[0]):
        for ll in range(lanes[bi]):
            k = bi * LANES + ll
            if pending[k] == 0:
                continue
            failed, er, dt_own = scalar_element(_U(elems[k]), mesh, motion, dt, rows,
                                                blocks, status, eroded_now,
                                                alive, dt_erode, erode_inverted)
            dt_min = min(dt_min, dt_own)
            n_failed += failed
            n_eroded += er
    for k in prange(others.shape[0]):
        failed, er, dt_own = scalar_element(_U(others[k]), mesh, motion, dt, rows,
                                            blocks, status, eroded_now, alive,
                                            dt_erode, erode_inverted)
        dt_min = min(dt_min, dt_own)
        n_failed += failed
        n_eroded += er
    return n_failed, n_eroded, dt_min
