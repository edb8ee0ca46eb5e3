"""Four-node corotational shell, one in-plane point (Belytschko–Lin–Tsay family).

docs/theory.md §2; thesis ch. 4.4; docs/model.md §2. Per element and step, given the
positions x^n and the half-step velocities v^{n−1/2}, ω^{n−1/2}:

1. corotational frame: e3 along d13 × d24 (diagonals), e1 along side 1→2
   projected on the element plane, e2 = e3 × e1; local coordinates of the nodes;
2. membrane: in-plane deformation gradient F = Σ_I x̂_I ⊗ ∂N_I/∂X (X the reference
   material frame with the warp along x), the material gives the resultant N (fabric
   kernel, or an elastic St Venant–Kirchhoff membrane) and the nodal forces are
   f̂_I = Σ_g w_g P_g ∂N_I/∂X|_g with P = J N F⁻ᵀ — a total-Lagrangian membrane,
   work-conjugate to the material's stored energy — at the 2×2 Gauss points
   (``full_membrane``, theory §4.5) or at the centre alone (w = A0; reduced); on a
   warped element, normal corner forces for the frame's tilt make them the exact
   gradient of the membrane energy (``warp_forces``, theory §4 "Warped elements");
3. bending and transverse shear in rate form (Belytschko–Lin–Tsay 1984):
   κ̇_x = b1·θ̇_y, κ̇_y = −b2·θ̇_x, 2κ̇_xy = b2·θ̇_y − b1·θ̇_x,
   γ̇_xz = b1·v_z + ¼Σθ̇_y, γ̇_yz = b2·v_z − ¼Σθ̇_x (zero for any rigid
   rotation), M += D Δκ, Q += k G t Δγ;
4. hourglass control, Flanagan–Belytschko stiffness form, for the in-plane modes
   (reduced membranes only), the transverse and the rotational modes, with its
   energy; generalized stiffnesses r C_m A Σb², r 16 D Σb² and r D A Σb² (membrane,
   w, θ), each the order of the physical energy of a smooth field with the same
   nodal values;
5. the element's stable step L_e / c_e, L_e = A / max edge (eq. 4.9–4.11), c_e from
   the current membrane tangent and the transverse-shear wave speed, and no more than
   the rotational bound 2 √(I/k_θ) of its corners' spins; with ``run.stable_step =
   "yarn"`` a fabric's yarn families instead each over the element's reference length
   along them, and a kinematic limit (``family_stable_step``, ``kinematic_step``).

``shell_force`` is one element; ``internal_force_for_shells`` loops over all of them
in parallel, each writing only its own rows, so results do not depend on threads.
Per-element functions take the whole tables and the element's row index (no
per-element array views: each view costs reference counting at every call) and
the small geometric helpers work on scalars and tuples. Row indices are passed
as unsigned integers (``np.uint64``): a signed index makes Numba check every
access for a negative index to wrap around, ~20 % of the element's time. The helpers
of ``shell_force`` are inlined into it at Numba IR level (``inline_kernel``): one
function for LLVM to allocate registers in, 2 764 → 2 471 instructions per elastic
element and 10 324 → 9 064 per fabric 2×2 element (callgrind; results bitwise the same).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from wovenimpact.jit import inline_kernel, kernel, loop_kernel
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import j2_layout as JL
from wovenimpact.kernels.bundles import ElementTables
from wovenimpact.kernels.fabric import fabric_point
from wovenimpact.kernels.j2 import fold_amplification, j2_point
from wovenimpact.kernels.vecmath import sqrt as vsqrt
from wovenimpact.kernels.shell_layout import (
    C_AREAL_MASS,
    C_BEND_E,
    C_BEND_NU,
    C_HOURGLASS,
    C_INPLANE,
    C_MAT,
    C_POINTS,
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
    EL_INVERTED,
    EL_MATERIAL,
    EL_NAN,
    EL_OK,
    ELASTIC_MODULUS,
    ELASTIC_POISSON,
    MAT_FABRIC,
    MAT_J2,
    MEMBRANE_FULL,
    N_ELEM_STATE,
    STEP_YARN,
)


@inline_kernel
def elastic_membrane(f11, f12, f21, f22, modulus, poisson, thick):
    """St Venant–Kirchhoff plane-stress membrane from the in-plane F.

    E = ½(FᵀF − I), S = C E with C = E t/(1 − ν²) [[1, ν, 0], [ν, 1, 0], [0, 0, 1 − ν]]
    (tensor shear), N = F S Fᵀ / J (force per current length).

    Returns (W, C_m, N_xx, N_yy, N_xy): stored energy per reference area ½ S:E
    (J/m²), the membrane stiffness E t/(1 − ν²) (N/m) for the stable step, and N.
    """
    c = modulus * thick / (1.0 - poisson * poisson)
    e11 = 0.5 * (f11 * f11 + f21 * f21 - 1.0)
    e22 = 0.5 * (f12 * f12 + f22 * f22 - 1.0)
    e12 = 0.5 * (f11 * f12 + f21 * f22)
    s11 = c * (e11 + poisson * e22)
    s22 = c * (e22 + poisson * e11)
    s12 = c * (1.0 - poisson) * e12
    det = f11 * f22 - f12 * f21
    # N = F S Fᵀ / J
    a11 = f11 * s11 + f12 * s12
    a12 = f11 * s12 + f12 * s22
    a21 = f21 * s11 + f22 * s12
    a22 = f21 * s12 + f22 * s22
    inv_det = 1.0 / det
    n_xx = (a11 * f11 + a12 * f12) * inv_det
    n_yy = (a21 * f21 + a22 * f22) * inv_det
    n_xy = (a11 * f21 + a12 * f22) * inv_det
    return 0.5 * (s11 * e11 + s22 * e22 + 2.0 * s12 * e12), c, n_xx, n_yy, n_xy


@inline_kernel
def local_components(ax, ay, az, ex, ey, ez):
    """(a_I · e) for the four corners: a nodal vector field (components ax, ay, az,
    4-tuples) seen along axis e."""
    return (
        ax[0] * ex + ay[0] * ey + az[0] * ez,
        ax[1] * ex + ay[1] * ey + az[1] * ez,
        ax[2] * ex + ay[2] * ey + az[2] * ez,
        ax[3] * ex + ay[3] * ey + az[3] * ez,
    )


@inline_kernel
def corotational_frame(px, py, pz):
    """Corotational frame and one-point gradients of a quad (BLT; theory §2.1).

    e3 ∥ d13 × d24 (diagonals), e1 = side 1→2 projected on the plane, e2 = e3 × e1;
    local coordinates about the centroid; area A = ½ (x̂31 ŷ42 − x̂42 ŷ31);
    b1 = ∂N/∂x̂ = (ŷ24, ŷ31, ŷ42, ŷ13)/2A, b2 = ∂N/∂ŷ = (x̂42, x̂13, x̂24, x̂31)/2A.

    Returns ((e1), (e2), (e3), (x̂, ŷ), A, (b1, b2), ẑ), ẑ the corners' warp off the
    plane; A is 0 or NaN if degenerate.
    """
    d13x, d13y, d13z = px[2] - px[0], py[2] - py[0], pz[2] - pz[0]
    d24x, d24y, d24z = px[3] - px[1], py[3] - py[1], pz[3] - pz[1]
    nx = d13y * d24z - d13z * d24y
    ny = d13z * d24x - d13x * d24z
    nz = d13x * d24y - d13y * d24x
    inv_nn = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
    e3x, e3y, e3z = nx * inv_nn, ny * inv_nn, nz * inv_nn
    s12x, s12y, s12z = px[1] - px[0], py[1] - py[0], pz[1] - pz[0]
    p = s12x * e3x + s12y * e3y + s12z * e3z
    e1x, e1y, e1z = s12x - p * e3x, s12y - p * e3y, s12z - p * e3z
    inv_n1 = 1.0 / math.sqrt(e1x * e1x + e1y * e1y + e1z * e1z)
    e1x, e1y, e1z = e1x * inv_n1, e1y * inv_n1, e1z * inv_n1
    e2x = e3y * e1z - e3z * e1y
    e2y = e3z * e1x - e3x * e1z
    e2z = e3x * e1y - e3y * e1x
    cx = 0.25 * (px[0] + px[1] + px[2] + px[3])
    cy = 0.25 * (py[0] + py[1] + py[2] + py[3])
    cz = 0.25 * (pz[0] + pz[1] + pz[2] + pz[3])
    x0 = (px[0] - cx) * e1x + (py[0] - cy) * e1y + (pz[0] - cz) * e1z
    x1 = (px[1] - cx) * e1x + (py[1] - cy) * e1y + (pz[1] - cz) * e1z
    x2 = (px[2] - cx) * e1x + (py[2] - cy) * e1y + (pz[2] - cz) * e1z
    x3 = (px[3] - cx) * e1x + (py[3] - cy) * e1y + (pz[3] - cz) * e1z
    y0 = (px[0] - cx) * e2x + (py[0] - cy) * e2y + (pz[0] - cz) * e2z
    y1 = (px[1] - cx) * e2x + (py[1] - cy) * e2y + (pz[1] - cz) * e2z
    y2 = (px[2] - cx) * e2x + (py[2] - cy) * e2y + (pz[2] - cz) * e2z
    y3 = (px[3] - cx) * e2x + (py[3] - cy) * e2y + (pz[3] - cz) * e2z
    area = 0.5 * ((x2 - x0) * (y3 - y1) - (x3 - x1) * (y2 - y0))
    inv2a = 0.5 / area
    b1 = ((y1 - y3) * inv2a, (y2 - y0) * inv2a, (y3 - y1) * inv2a, (y0 - y2) * inv2a)
    b2 = ((x3 - x1) * inv2a, (x0 - x2) * inv2a, (x1 - x3) * inv2a, (x2 - x0) * inv2a)
    z = ((px[0] - cx) * e3x + (py[0] - cy) * e3y + (pz[0] - cz) * e3z,
         (px[1] - cx) * e3x + (py[1] - cy) * e3y + (pz[1] - cz) * e3z,
         (px[2] - cx) * e3x + (py[2] - cy) * e3y + (pz[2] - cz) * e3z,
         (px[3] - cx) * e3x + (py[3] - cy) * e3y + (pz[3] - cz) * e3z)
    return (
        (e1x, e1y, e1z), (e2x, e2y, e2z), (e3x, e3y, e3z),
        ((x0, x1, x2, x3), (y0, y1, y2, y3)), area, (b1, b2), z,
    )


@inline_kernel
def hourglass_vectors(lx, ly, b1, b2):
    """Flanagan–Belytschko γ_I = ¼ (h_I − (h·x̂) b1_I − (h·ŷ) b2_I), h = (1, −1, 1, −1),
    orthogonal to every linear field; and Σ_I (b1_I² + b2_I²)."""
    hx = lx[0] - lx[1] + lx[2] - lx[3]
    hy = ly[0] - ly[1] + ly[2] - ly[3]
    gam = (
        0.25 * (1.0 - hx * b1[0] - hy * b2[0]),
        0.25 * (-1.0 - hx * b1[1] - hy * b2[1]),
        0.25 * (1.0 - hx * b1[2] - hy * b2[2]),
        0.25 * (-1.0 - hx * b1[3] - hy * b2[3]),
    )
    bb = 0.0
    for i in range(4):
        bb += b1[i] * b1[i] + b2[i] * b2[i]
    return gam, bb


@inline_kernel
def hourglass_mode(q_old, k, gam_mid, rates, dt):
    """One hourglass mode (stiffness form): Q_new = Q_old + k (γ_mid · rates) Δt.

    Returns (Q_new, energy increment ½ (Q_old + Q_new) (γ_mid · rates) Δt); the
    corner forces are γ_I Q_new with the current γ.
    """
    rate = gam_mid[0] * rates[0] + gam_mid[1] * rates[1] + gam_mid[2] * rates[2] + (
        gam_mid[3] * rates[3]
    )
    new = q_old + k * rate * dt
    return new, 0.5 * (q_old + new) * rate * dt


@inline_kernel
def hourglass_stiffnesses(r, c_memb, area, bb, d_b, full):
    """The generalised hourglass stiffnesses (k_m, k_w, k_θ) = (r C_m A Σb², r 16 D Σb²,
    r D A Σb²) (theory §4, hourglass control); k_m = 0 for a 2×2 membrane, which has no
    in-plane modes. The w mode's 16 D Σb² is the twist energy of a square element's
    bilinear w at r = 1."""
    k_m = 0.0 if full else r * c_memb * area * bb
    return k_m, r * 16.0 * d_b * bb, r * d_b * area * bb


@inline_kernel
def hourglass_update(q_old, k_m, k_w, k_t, gam_mid, rates, dt):
    """The five hourglass resultants (in-plane x, y; w; θ_x, θ_y) from their old values
    q_old (5-tuple) and the midpoint rates (v_x, v_y, v_z, θ_x, θ_y of the corners), each
    :func:`hourglass_mode`. Returns ((Q_0 … Q_4), their energy increment)."""
    hg0, e_hg = hourglass_mode(q_old[0], k_m, gam_mid, rates[0], dt)
    hg1, de = hourglass_mode(q_old[1], k_m, gam_mid, rates[1], dt)
    e_hg += de
    hg2, de = hourglass_mode(q_old[2], k_w, gam_mid, rates[2], dt)
    e_hg += de
    hg3, de = hourglass_mode(q_old[3], k_t, gam_mid, rates[3], dt)
    e_hg += de
    hg4, de = hourglass_mode(q_old[4], k_t, gam_mid, rates[4], dt)
    e_hg += de
    return (hg0, hg1, hg2, hg3, hg4), e_hg


@inline_kernel
def plate_stiffness(e_b, thick, nu_b):
    """Bending stiffness of the plate law, D = E_b t³ / 12(1 − ν_b²)."""
    return e_b * thick * thick * thick / (12.0 * (1.0 - nu_b * nu_b))


@inline_kernel
def plate_moments(m_old, d_b, nu_b, dk):
    """M += D Δκ (plate law, rate form) from M_old = (M_xx, M_yy, M_xy) and
    Δκ = (Δκ_x, Δκ_y, 2Δκ_xy)."""
    return (m_old[0] + d_b * (dk[0] + nu_b * dk[1]), m_old[1] + d_b * (dk[1] + nu_b * dk[0]),
            m_old[2] + d_b * 0.5 * (1.0 - nu_b) * dk[2])


@inline_kernel
def shear_forces(q_old, kgt, dg):
    """Q += k G t Δγ from Q_old = (Q_x, Q_y) and Δγ = (Δγ_xz, Δγ_yz)."""
    return q_old[0] + kgt * dg[0], q_old[1] + kgt * dg[1]


@inline_kernel
def bending_work(area, w_bend, m_old, m_new, q_old, q_new, dk, dg):
    """The step's bending and transverse-shear work, trapezoid rule on the increments:
    A [w ½(M_old + M)·Δκ + ½(Q_old + Q)·Δγ] (w = 0 where the points book the bending)."""
    return area * (
        w_bend * (0.5 * (m_old[0] + m_new[0]) * dk[0] + 0.5 * (m_old[1] + m_new[1]) * dk[1]
                  + 0.5 * (m_old[2] + m_new[2]) * dk[2])
        + 0.5 * (q_old[0] + q_new[0]) * dg[0] + 0.5 * (q_old[1] + q_new[1]) * dg[1]
    )


@inline_kernel
def point_gradient(lx, ly, q1, q2):
    """F = Σ_I x̂_I ⊗ G_I at a Gauss point with reference gradients G = (q1, q2)
    (``full_membrane``): (F11, F12, F21, F22)."""
    f11 = lx[0] * q1[0] + lx[1] * q1[1] + lx[2] * q1[2] + lx[3] * q1[3]
    f12 = lx[0] * q2[0] + lx[1] * q2[1] + lx[2] * q2[2] + lx[3] * q2[3]
    f21 = ly[0] * q1[0] + ly[1] * q1[1] + ly[2] * q1[2] + ly[3] * q1[3]
    f22 = ly[0] * q2[0] + ly[1] * q2[1] + ly[2] * q2[2] + ly[3] * q2[3]
    return f11, f12, f21, f22


@inline_kernel
def point_corner_forces(wg, p11, p12, p21, p22, q1, q2):
    """A Gauss point's share of the membrane's corner forces, w_g P G_I: ((f̂x_I), (f̂y_I))."""
    return ((wg * (p11 * q1[0] + p12 * q2[0]), wg * (p11 * q1[1] + p12 * q2[1]),
             wg * (p11 * q1[2] + p12 * q2[2]), wg * (p11 * q1[3] + p12 * q2[3])),
            (wg * (p21 * q1[0] + p22 * q2[0]), wg * (p21 * q1[1] + p22 * q2[1]),
             wg * (p21 * q1[2] + p22 * q2[2]), wg * (p21 * q1[3] + p22 * q2[3])))


@inline_kernel
def clear_block(blocks, e):
    """No force or moment at any corner of element e."""
    for i in range(4):
        for j in range(6):
            blocks[e, i, j] = 0.0


@inline_kernel
def through_thickness_f(z, kx, ky, kxy2, f11, f12, f21, f22):
    """In-plane F at height z: (I + z κ̂) F, κ̂ = [[κ_x, κ_xy], [κ_xy, κ_y]]; the strain
    at z is then the mid-surface strain plus z κ (BLT curvature convention)."""
    kxy = 0.5 * kxy2
    return (
        f11 + z * (kx * f11 + kxy * f21), f12 + z * (kx * f12 + kxy * f22),
        f21 + z * (kxy * f11 + ky * f21), f22 + z * (kxy * f12 + ky * f22),
    )


# keeps its long signature: a stage inlined into ``section_response``, its arguments that loop's
# locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@inline_kernel
def point_response(kind, mat_params, m, o11, o12, o21, o22, g11, g12, g21, g22, dt, thick,
                   rows_in, rows_out, row, amp=1.0):
    """The material at one point: F_old → F_new (o.., g..) over Δt, dispatched on its kind.

    Fabric and J2 points keep their state in row ``row`` of the material rows (the
    crossover kernel, kernels.j2; both have their alive flag and stored energy in the
    same columns); elastic points have none.

    Returns:
        (status, alive, C_m, W, N_xx, N_yy, N_xy, C_s, k_w, k_f): 0 if the point
        updated; False once the point has eroded; its membrane tangent bound (N/m);
        stored energy per reference area (J/m²); the resultant N (force per current
        length of the whole section); the stable step's stiffnesses (theory §4,
        "Stable step"): C_s the isotropic part (C_m itself, or a fabric's trellis shear
        alone) and k_w, k_f a fabric's yarn families per reference width and length
        (zero for other materials). ``amp``: a J2 point's fold amplification (J17).
    """
    if kind == MAT_FABRIC:
        st, c, a, b, c12, c_s, k_w, k_f = fabric_point(
            mat_params, m, o11, o12, o21, o22, g11, g12, g21, g22, rows_in, rows_out, row
        )
        if st != 0:
            return st, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        return (0, rows_out[row, FL.S_ALIVE] != 0.0, c, rows_out[row, FL.S_ENERGY], a, b, c12,
                c_s, k_w, k_f)
    if kind == MAT_J2:
        st, c, a, b, c12 = j2_point(
            mat_params, m, o11, o12, o21, o22, g11, g12, g21, g22, dt, thick, rows_in,
            rows_out, row, amp,
        )
        if st != 0:
            return st, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        return (0, rows_out[row, FL.S_ALIVE] != 0.0, c, rows_out[row, FL.S_ENERGY], a, b, c12,
                c, 0.0, 0.0)
    energy, c, a, b, c12 = elastic_membrane(
        g11, g12, g21, g22, mat_params[m, ELASTIC_MODULUS], mat_params[m, ELASTIC_POISSON],
        thick
    )
    return 0, True, c, energy, a, b, c12, c, 0.0, 0.0


# keeps its long signature: a stage inlined into ``full_membrane`` and ``shell_force``, its
# arguments that loop's locals (a bundle written through in a parallel loop's body can lose its
# writes: kernels/bundles.py)
@inline_kernel
def section_response(
    n_pts, thick, kind, mat_params, m, fo11, fo12, fo21, fo22, f11, f12, f21, f22,
    ko_x, ko_y, ko_xy2, k_x, k_y, k_xy2, dt, rows_in, rows_out, row0,
):
    """The section at one in-plane point: its n through-thickness points (theory §4).

    n = 1: the mid-surface point alone (resultant section; the caller adds M = D κ).
    n ≥ 3 (odd): Simpson points z_k; point k sees F_k = (I + z_k κ̂) F and its resultant
    N_k (force per length of the whole section) is weighted by the Simpson weights w_k
    (Σ w_k = 1): N = Σ w_k N_k, M = Σ w_k z_k N_k (exact for the bending of a linear
    material). Point k's state is row ``row0 + k`` of the material rows.

    Returns:
        (status, n_alive, C_m, W, N_xx, N_yy, N_xy, M_xx, M_yy, M_xy, C_s, k_w, k_f):
        status 0 if every point updated (else the first failure's code); the points not
        eroded; the largest membrane tangent; stored energy per reference area
        Σ w_k W_k; the largest of each stable-step stiffness (:func:`point_response`).
    """
    n_xx = n_yy = n_xy = 0.0
    mxx = myy = mxy = 0.0
    w_sum = 0.0
    c_max = 0.0
    cs_max = kw_max = kf_max = 0.0
    alive = 0
    h = thick / (n_pts - 1) if n_pts > 1 else 0.0
    for k in range(n_pts):
        if n_pts == 1:
            z = 0.0
            w = 1.0
        else:
            z = -0.5 * thick + k * h
            w = (1.0 if k == 0 or k == n_pts - 1 else (4.0 if k % 2 == 1 else 2.0)) / (
                3.0 * (n_pts - 1))
        g11, g12, g21, g22 = through_thickness_f(z, k_x, k_y, k_xy2, f11, f12, f21, f22)
        if g11 * g22 - g12 * g21 <= 0.0:
            return EL_INVERTED, 0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        o11, o12, o21, o22 = through_thickness_f(z, ko_x, ko_y, ko_xy2, fo11, fo12, fo21, fo22)
        amp = 1.0
        if kind == MAT_J2 and n_pts > 1:  # (J17): a fold's strain, judged at its width
            amp = fold_amplification(rows_in[row0 + np.uint64(k), JL.S_HINGE],
                                     o11, o12, o21, o22, g11, g12, g21, g22,
                                     fo11, fo12, fo21, fo22, f11, f12, f21, f22)
        st, live, c, energy, a, b, c12, c_s, k_w, k_f = point_response(
            kind, mat_params, m, o11, o12, o21, o22, g11, g12, g21, g22, dt, thick,
            rows_in, rows_out, row0 + np.uint64(k), amp,
        )
        if st != 0:
            return EL_MATERIAL, 0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        if live:
            alive += 1
        n_xx += w * a
        n_yy += w * b
        n_xy += w * c12
        mxx += w * z * a
        myy += w * z * b
        mxy += w * z * c12
        w_sum += w * energy
        c_max = max(c_max, c)
        cs_max = max(cs_max, c_s)
        kw_max = max(kw_max, k_w)
        kf_max = max(kf_max, k_f)
    return 0, alive, c_max, w_sum, n_xx, n_yy, n_xy, mxx, myy, mxy, cs_max, kw_max, kf_max


@inline_kernel
def first_piola(n11, n22, n12, f11, f12, f21, f22):
    """P = J N F⁻ᵀ (force per reference length) from the Cauchy resultant N and F;
    F⁻ᵀ = [[f22, −f21], [−f12, f11]] / J. Returns (P11, P12, P21, P22)."""
    return (n11 * f22 - n12 * f12, -n11 * f21 + n12 * f11,
            n12 * f22 - n22 * f12, -n12 * f21 + n22 * f11)


@inline_kernel
def sync_yarn_damage(rows_out, row0, n_pts):
    """Yarn failure is an element's, not a Gauss point's (theory §4.5): the element is
    about one crossover cell, so a family broken at one of its 2×2 points is broken
    in all of them (d_i = max over the points, per through-thickness level)."""
    for k in range(n_pts):
        for fam in range(2):
            d = 0.0
            for g in range(4):
                d = max(d, rows_out[row0 + np.uint64(g * n_pts + k), FL.S_DAMAGE + fam])
            for g in range(4):
                rows_out[row0 + np.uint64(g * n_pts + k), FL.S_DAMAGE + fam] = d


# keeps its long signature: a stage inlined into ``shell_force``, its arguments that loop's locals
# (a bundle written through in a parallel loop's body can lose its writes: kernels/bundles.py)
@inline_kernel
def full_membrane(
    e, lx, ly, gauss_grad, gauss_weight, a0, n_pts, thick, kind, mat_params, m, el_in, el_out,
    ko_x, ko_y, ko_xy2, k_x, k_y, k_xy2, dt, rows_in, rows_out, row0,
):
    """Fully integrated membrane: the section at the 2×2 Gauss points (theory §4.5).

    At point g (reference gradients G_g = ∂N/∂X, weight w_g = det J, Σ w_g = A0):
    F_g = Σ_I x̂_I ⊗ G_gI in the corotational frame, the section's response N_g, M_g
    (:func:`section_response`, its state rows ``row0 + g n_pts + k``), and the corner
    forces f̂_I = Σ_g w_g P_g G_gI with P_g = J_g N_g F_g⁻ᵀ; stored energy Σ_g w_g W_g.
    F_g of the step is kept in the element state (``E_FG``) for the next one. Fabric
    yarn damage is shared by the element's points (:func:`sync_yarn_damage`).

    Returns:
        (status, eroded, C_m, U, N̄_xx, N̄_yy, N̄_xy, M̄_xx, M̄_yy, M̄_xy, (f̂x_I), (f̂y_I),
        C_s, k_w, k_f): eroded once a point's whole section has eroded; C_m the largest
        tangent; U the stored energy (J); N̄, M̄ the area averages; the in-plane corner
        forces; the largest of each stable-step stiffness (:func:`point_response`).
    """
    fx = (0.0, 0.0, 0.0, 0.0)
    fy = (0.0, 0.0, 0.0, 0.0)
    u = c_max = 0.0
    cs_max = kw_max = kf_max = 0.0
    n_xx = n_yy = n_xy = m_xx = m_yy = m_xy = 0.0
    eroded = False
    for g in range(4):
        q1 = (gauss_grad[e, g, 0, 0], gauss_grad[e, g, 0, 1], gauss_grad[e, g, 0, 2],
              gauss_grad[e, g, 0, 3])
        q2 = (gauss_grad[e, g, 1, 0], gauss_grad[e, g, 1, 1], gauss_grad[e, g, 1, 2],
              gauss_grad[e, g, 1, 3])
        f11, f12, f21, f22 = point_gradient(lx, ly, q1, q2)
        det = f11 * f22 - f12 * f21
        if not (det > 0.0):
            st = EL_NAN if not math.isfinite(det) else EL_INVERTED
            return st, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, fx, fy, 0.0, 0.0, 0.0
        col = E_FG + 4 * g
        st, n_alive, c, w, a, b, c12, ma, mb, mc, c_s, k_w, k_f = section_response(
            n_pts, thick, kind, mat_params, m,
            el_in[e, col], el_in[e, col + 1], el_in[e, col + 2], el_in[e, col + 3],
            f11, f12, f21, f22, ko_x, ko_y, ko_xy2, k_x, k_y, k_xy2, dt,
            rows_in, rows_out, row0 + np.uint64(g * n_pts),
        )
        if st != 0:
            return st, False, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, fx, fy, 0.0, 0.0, 0.0
        el_out[e, col] = f11
        el_out[e, col + 1] = f12
        el_out[e, col + 2] = f21
        el_out[e, col + 3] = f22
        if n_alive == 0:
            eroded = True
        wg = gauss_weight[e, g]
        u += wg * w
        c_max = max(c_max, c)
        cs_max = max(cs_max, c_s)
        kw_max = max(kw_max, k_w)
        kf_max = max(kf_max, k_f)
        n_xx += wg * a
        n_yy += wg * b
        n_xy += wg * c12
        m_xx += wg * ma
        m_yy += wg * mb
        m_xy += wg * mc
        p11, p12, p21, p22 = first_piola(a, b, c12, f11, f12, f21, f22)
        tx, ty = point_corner_forces(wg, p11, p12, p21, p22, q1, q2)
        fx = (fx[0] + tx[0], fx[1] + tx[1], fx[2] + tx[2], fx[3] + tx[3])
        fy = (fy[0] + ty[0], fy[1] + ty[1], fy[2] + ty[2], fy[3] + ty[3])
    if kind == MAT_FABRIC:
        sync_yarn_damage(rows_out, row0, n_pts)
    inv = 1.0 / a0
    return (0, eroded, c_max, u, n_xx * inv, n_yy * inv, n_xy * inv, m_xx * inv, m_yy * inv,
            m_xy * inv, fx, fy, cs_max, kw_max, kf_max)


@inline_kernel
def warp_forces(fx, fy, lx, ly, lz, area):
    """Normal corner forces that make the membrane corner forces (fx, fy) of a warped
    element the gradient of its membrane energy (theory §4, "Warped elements").

    The membrane energy U depends on the corners' coordinates in the element's frame
    (x̂_I, ŷ_I), and the frame turns with the nodes: its normal e3 ∥ d13 × d24. So
    δU = Σ_I f_I · δx_I − δθ · M, with f_I = f_x,I e1 + f_y,I e2 the in-plane forces,
    M = Σ_I d_I × f_I their moment about the centroid (d_I = (x̂_I, ŷ_I, z_I), z_I the
    warp) and δθ the frame's rotation. The diagonals lie in the element's plane, so the
    tilt δθ_1 = −e2·δe3, δθ_2 = e1·δe3 with δe3 = (1 − e3 e3ᵀ)(δd13 × d24 + d13 ×
    δd24)/|n| depends on the corners' normal motions alone:
        ∂θ_1/∂z = (a_1, −b_1, −a_1, b_1)/2A,   ∂θ_2/∂z = (a_2, −b_2, −a_2, b_2)/2A
    at corners 1…4, a = d24, b = d13 in the frame, |n| = 2A. The corner forces of U are
    then f_I − (M_1 ∂θ_1/∂z_I + M_2 ∂θ_2/∂z_I) e3, with M_1 = −Σ z_I f_y,I and
    M_2 = Σ z_I f_x,I (the in-plane turn's M_3 = Σ x̂ f_y − ŷ f_x is zero: the membrane
    stress is symmetric). A flat element (z = 0) gets none. The rate-form hourglass
    forces, booked in the frame, are left as they are. Returns the four normal forces."""
    m1 = m2 = 0.0
    for i in range(4):
        m1 -= lz[i] * fy[i]
        m2 += lz[i] * fx[i]
    inv = 0.5 / area
    a1, a2 = (lx[3] - lx[1]) * inv, (ly[3] - ly[1]) * inv
    b1, b2 = (lx[2] - lx[0]) * inv, (ly[2] - ly[0]) * inv
    return (-(m1 * a1 + m2 * a2), m1 * b1 + m2 * b2, m1 * a1 + m2 * a2, -(m1 * b1 + m2 * b2))


@inline_kernel
def corner_values(a, c0, c1, c2, c3):
    """The x, y and z components of rows c0…c3 of a (n, ≥3) table, as three 4-tuples."""
    return (
        (a[c0, 0], a[c1, 0], a[c2, 0], a[c3, 0]),
        (a[c0, 1], a[c1, 1], a[c2, 1], a[c3, 1]),
        (a[c0, 2], a[c1, 2], a[c2, 2], a[c3, 2]),
    )


@inline_kernel
def element_failed(e, el_out, blocks, measure):
    """Element e has a degenerate geometry (``measure``: an area or a Jacobian ≤ 0 or
    not finite): no force, no stable step; returns (EL_NAN or EL_INVERTED, 0, ∞)."""
    el_out[e, E_DT] = 0.0
    el_out[e, E_DT_KIN] = math.inf
    clear_block(blocks, e)
    return (EL_NAN if not math.isfinite(measure) else EL_INVERTED), 0, math.inf


@inline_kernel
def midpoint_frame(px, py, pz, vx, vy, vz, dt):
    """The corotational frame (``corotational_frame``) at x^{n−1/2} = x^n − ½Δt v^{n−1/2}:
    the configuration the step's velocities belong to."""
    h = 0.5 * dt
    return corotational_frame(
        (px[0] - h * vx[0], px[1] - h * vx[1], px[2] - h * vx[2], px[3] - h * vx[3]),
        (py[0] - h * vy[0], py[1] - h * vy[1], py[2] - h * vy[2], py[3] - h * vy[3]),
        (pz[0] - h * vz[0], pz[1] - h * vz[1], pz[2] - h * vz[2], pz[3] - h * vz[3]),
    )


@inline_kernel
def midpoint_rates(mid, vx_, vy_, vz_, wx_, wy_, wz_, dt):
    """Corner velocities and spins in the midpoint frame ``mid`` and the step's
    increments of curvature and transverse shear (BLT, module docstring item 3):
    Δκ_x = Σ b1·θ̇_y Δt, Δκ_y = −Σ b2·θ̇_x Δt, 2Δκ_xy = Σ (b2·θ̇_y − b1·θ̇_x) Δt,
    Δγ_xz = Σ (b1·v_z + ¼θ̇_y) Δt, Δγ_yz = Σ (b2·v_z − ¼θ̇_x) Δt — zero for any rigid motion.

    Returns (v̂_x, v̂_y, v̂_z, θ̇_x, θ̇_y) as 4-tuples, then Δκ_x, Δκ_y, 2Δκ_xy, Δγ_xz, Δγ_yz.
    """
    (m1x, m1y, m1z), (m2x, m2y, m2z), (m3x, m3y, m3z) = mid[0], mid[1], mid[2]
    mb1, mb2 = mid[5]
    vx = local_components(vx_, vy_, vz_, m1x, m1y, m1z)
    vy = local_components(vx_, vy_, vz_, m2x, m2y, m2z)
    vz = local_components(vx_, vy_, vz_, m3x, m3y, m3z)
    tx = local_components(wx_, wy_, wz_, m1x, m1y, m1z)
    ty = local_components(wx_, wy_, wz_, m2x, m2y, m2z)
    kx = ky = kxy2 = gxz = gyz = 0.0
    for i in range(4):
        kx += mb1[i] * ty[i]
        ky -= mb2[i] * tx[i]
        kxy2 += mb2[i] * ty[i] - mb1[i] * tx[i]
        gxz += mb1[i] * vz[i] + 0.25 * ty[i]
        gyz += mb2[i] * vz[i] - 0.25 * tx[i]
    return vx, vy, vz, tx, ty, kx * dt, ky * dt, kxy2 * dt, gxz * dt, gyz * dt


@inline_kernel
def centre_gradient(lx, ly, g1, g2):
    """In-plane deformation gradient at the centre, F = Σ_I x̂_I ⊗ ∂N_I/∂X:
    (F11, F12, F21, F22) from the local corner coordinates and the reference gradients."""
    f11 = f12 = f21 = f22 = 0.0
    for i in range(4):
        f11 += lx[i] * g1[i]
        f12 += lx[i] * g2[i]
        f21 += ly[i] * g1[i]
        f22 += ly[i] * g2[i]
    return f11, f12, f21, f22


@inline_kernel
def centre_membrane_forces(a0, n11, n22, n12, f11, f12, f21, f22, g1, g2):
    """One-point membrane corner forces f̂_I = A0 P ∂N_I/∂X, P = J N F⁻ᵀ (first Piola):
    (x components, y components) as 4-tuples in the local frame."""
    p11, p12, p21, p22 = first_piola(n11, n22, n12, f11, f12, f21, f22)
    mf_x = (a0 * (p11 * g1[0] + p12 * g2[0]), a0 * (p11 * g1[1] + p12 * g2[1]),
            a0 * (p11 * g1[2] + p12 * g2[2]), a0 * (p11 * g1[3] + p12 * g2[3]))
    mf_y = (a0 * (p21 * g1[0] + p22 * g2[0]), a0 * (p21 * g1[1] + p22 * g2[1]),
            a0 * (p21 * g1[2] + p22 * g2[2]), a0 * (p21 * g1[3] + p22 * g2[3]))
    return mf_x, mf_y


# keeps its long signature: a stage inlined into ``shell_force``, its arguments that loop's locals
# (a bundle written through in a parallel loop's body can lose its writes: kernels/bundles.py)
@inline_kernel
def bending_and_shear(e, el_in, el_out, area, integrated, c_memb, thick, e_b, nu_b, kgt,
                      mi_xx, mi_yy, mi_xy, dkx, dky, dkxy2, dgxz, dgyz):
    """Bending moments and transverse shear forces of element e at the end of the step,
    written to el_out with the bending energy (trapezoid rule on the increments).

    Resultant section: M += D Δκ, D = E_b t³/12(1 − ν_b²) (plate law); integrated
    section: M from its points (mi_*; their energy is in the membrane term, and the
    plate stiffness C_m t²/12 serves the hourglass only). Always Q += k G t Δγ.

    Returns (D, M_xx, M_yy, M_xy, Q_x, Q_y, w) with w = 1 when M is the plate law's.
    """
    m_old = (el_in[e, E_M], el_in[e, E_M + 1], el_in[e, E_M + 2])
    q_old = (el_in[e, E_Q], el_in[e, E_Q + 1])
    dk = (dkx, dky, dkxy2)
    dg = (dgxz, dgyz)
    if integrated:
        d_b = c_memb * thick * thick / 12.0  # for the hourglass stiffness only
        mxx, myy, mxy = mi_xx, mi_yy, mi_xy
        w_bend = 0.0
    else:
        d_b = plate_stiffness(e_b, thick, nu_b)
        mxx, myy, mxy = plate_moments(m_old, d_b, nu_b, dk)
        w_bend = 1.0
    qx, qy = shear_forces(q_old, kgt, dg)
    el_out[e, E_M] = mxx
    el_out[e, E_M + 1] = myy
    el_out[e, E_M + 2] = mxy
    el_out[e, E_Q] = qx
    el_out[e, E_Q + 1] = qy
    el_out[e, E_U_BEND] = el_in[e, E_U_BEND] + bending_work(
        area, w_bend, m_old, (mxx, myy, mxy), q_old, (qx, qy), dk, dg)
    return d_b, mxx, myy, mxy, qx, qy, w_bend


# keeps its long signature: a stage inlined into ``shell_force``, its arguments that loop's locals
# (a bundle written through in a parallel loop's body can lose its writes: kernels/bundles.py)
@inline_kernel
def hourglass_resultants(e, el_in, el_out, k_m, k_w, k_t, gam_mid, vx, vy, vz, tx, ty, dt):
    """The five hourglass resultants of element e (in-plane x, y; w; θ_x, θ_y), each
    Q += k (γ_mid · rates) Δt (``hourglass_mode``), written to el_out with their
    energy; returns them."""
    (hg0, hg1, hg2, hg3, hg4), e_hg = hourglass_update(
        (el_in[e, E_HG], el_in[e, E_HG + 1], el_in[e, E_HG + 2], el_in[e, E_HG + 3],
         el_in[e, E_HG + 4]), k_m, k_w, k_t, gam_mid, (vx, vy, vz, tx, ty), dt)
    el_out[e, E_HG] = hg0
    el_out[e, E_HG + 1] = hg1
    el_out[e, E_HG + 2] = hg2
    el_out[e, E_HG + 3] = hg3
    el_out[e, E_HG + 4] = hg4
    el_out[e, E_U_HG] = el_in[e, E_U_HG] + e_hg
    return hg0, hg1, hg2, hg3, hg4


# keeps its long signature: a stage inlined into ``shell_force``, its arguments that loop's locals
# (a bundle written through in a parallel loop's body can lose its writes: kernels/bundles.py)
@inline_kernel
def corner_forces(e, blocks, frame, mf_x, mf_y, fzs, gam, hg0, hg1, hg2, hg3, hg4,
                  mxx, myy, mxy, qx, qy):
    """Element e's corner forces and moments into blocks[e] (global axes; the internal,
    resisting forces), from the local ones: membrane (mf), warp (fzs), transverse shear
    (A b·Q), bending (A b·M with the shear's ¼A Q moment) and hourglass (γ_I Q_hg).
    Returns Σ_I f_x (a finiteness probe)."""
    area = frame[4]
    b1, b2 = frame[5]
    fsum = 0.0
    for i in range(4):
        gx, gy, gz, mx, my, mz = corner_global(
            frame, area, b1[i], b2[i], mf_x[i], mf_y[i], gam[i], fzs[i], hg0, hg1, hg2, hg3,
            hg4, mxx, myy, mxy, qx, qy)
        blocks[e, i, 0] = gx
        blocks[e, i, 1] = gy
        blocks[e, i, 2] = gz
        blocks[e, i, 3] = mx
        blocks[e, i, 4] = my
        blocks[e, i, 5] = mz
        fsum += gx
    return fsum


# keeps its long signature: a stage inlined into ``corner_forces`` and ``element_tail``, its
# arguments that loop's locals (a bundle written through in a parallel loop's body can lose its
# writes: kernels/bundles.py)
@inline_kernel
def corner_global(frame, area, b1i, b2i, mfx, mfy, gam, fzs, hg0, hg1, hg2, hg3, hg4, mxx, myy,
                  mxy, qx, qy):
    """One corner's force and moment in global axes (:func:`corner_forces`' terms, and
    the element stage in blocks'): membrane, warp, transverse shear, bending and
    hourglass in the local frame, turned to global axes."""
    e1x, e1y, e1z = frame[0]
    e2x, e2y, e2z = frame[1]
    e3x, e3y, e3z = frame[2]
    fx = mfx + gam * hg0
    fy = mfy + gam * hg1
    fz = area * (b1i * qx + b2i * qy) + gam * hg2 + fzs
    mx = area * (-b2i * myy - b1i * mxy - 0.25 * qy) + gam * hg3
    my = area * (b1i * mxx + b2i * mxy + 0.25 * qx) + gam * hg4
    return (fx * e1x + fy * e2x + fz * e3x, fx * e1y + fy * e2y + fz * e3y,
            fx * e1z + fy * e2z + fz * e3z, mx * e1x + my * e2x, mx * e1y + my * e2y,
            mx * e1z + my * e2z)


@inline_kernel
def element_stable_step(px, py, pz, area, c_memb, kgt, mu, inertia, d_b, bb):
    """The element's stable step (eq. 4.9–4.11): L_e/c_e with L_e = A / longest edge and
    c_e² = max(C_m, k G t)/μ, and no more than the rotational bound 2 √(I/k_θ).

    Rotations: a corner's spin against this element's transverse-shear and bending
    stiffness, k_θ = A (k G t/4 + D Σb²), with ``inertia`` I the rotary inertia the
    element lumped on it (``model.rotary_inertia``: at the reference geometry the bound
    is no shorter than the membrane's); ω Δt ≤ 2 needs Δt ≤ 2 √(I/k_θ). In an element
    that has stretched far beyond its reference size (a broken yarn family) this, not
    the membrane, governs.
    """
    edge2 = 0.0
    for i in range(4):
        j = (i + 1) % 4
        dx = px[j] - px[i]
        dy = py[j] - py[i]
        dz = pz[j] - pz[i]
        edge2 = max(edge2, dx * dx + dy * dy + dz * dz)
    c2 = max(c_memb, kgt) / mu
    dt_e = area / vsqrt(edge2 * c2)
    k_rot = area * (0.25 * kgt + d_b * bb)
    return min(dt_e, 2.0 * vsqrt(inertia / k_rot))


@inline_kernel
def family_stable_step(k, k_shear, mu, g):
    """A fabric yarn family's stable step in the total-Lagrangian membrane (theory §4,
    "Stable step"): the family's wave crosses the element's reference length along it,
    L0 = 1/√(Σ_I (∂N_I/∂X_i)²) at the centre (the side of a square along the yarns), at
    √((k + k_s)/μ) with k its stiffness per reference width and length (N/m), k_s the
    trellis shear's (added, as the single bound of the undeformed element adds it),
    μ the areal mass: Δt = √(μ/((k + k_s) Σ_I (∂N_I/∂X_i)²)). Infinite for k = 0 (a
    slack family, or not a fabric): it does not limit the step."""
    s = g[0] * g[0] + g[1] * g[1] + g[2] * g[2] + g[3] * g[3]
    step = vsqrt(mu / ((k + k_shear) * s))  # outside the select: a guarded sqrt is a
    return step if k > 0.0 else math.inf  # libm call, which stops the vectoriser


@inline_kernel
def kinematic_step(px, py, pz, vx, vy, vz, fraction):
    """The step in which no two corners of the element (sides and diagonals) close or
    open by more than ``fraction`` η of their distance: Δt ≤ η |Δx|²/|Δx·Δv|
    (theory §4, "Stable step"; η is ``run.kinematic_fraction``, default
    shell_layout.KINEMATIC_FRACTION). A wave-speed bound comes from the state at the step's
    start, and an element crushed within a few steps (a fabric cell under a punch's
    edge, its yarns slack, from 0.3 to 0.04 of its size in 1 µs) outruns it; so does a
    slack family (left out of the wave bound) pulled taut within one step. Corners
    moving across their line (a struck node leaving its neighbours normal to the
    plate) do not limit the step."""
    rate = 0.0
    for i in range(4):
        for j in range(i + 1, 4):
            dx = px[j] - px[i]
            dy = py[j] - py[i]
            dz = pz[j] - pz[i]
            change = abs(dx * (vx[j] - vx[i]) + dy * (vy[j] - vy[i]) + dz * (vz[j] - vz[i]))
            d2 = dx * dx + dy * dy + dz * dz
            rate = change / d2 if change > rate * d2 else rate  # a select: vectorises
    return fraction / rate if rate > 0.0 else math.inf


@inline_kernel
def carry_state(e, el_in, el_out, rows_in, rows_out, row0, n_rows):
    """Copy element e's state and its section's n_rows material point rows (from row0)
    from the start-of-step tables to the end-of-step ones; the step then updates the
    copy. Rows past n_rows belong to no point of this section and are never written."""
    for j in range(N_ELEM_STATE):
        el_out[e, j] = el_in[e, j]
    for r in range(row0, row0 + n_rows):
        for j in range(rows_in.shape[1]):
            rows_out[r, j] = rows_in[r, j]


@kernel
def shell_force(e, mesh, motion, dt, tables, blocks):
    """Internal forces of shell element e at x^n (see the module docstring).

    Args:
        e: the element (row of every per-element table below), unsigned.
        mesh: :class:`~wovenimpact.kernels.bundles.ShellMesh` (Model tables).
        motion: :class:`~wovenimpact.kernels.bundles.Motion`: x^n, v^{n−1/2}, ω^{n−1/2}.
        dt: Δt^{n−1/2}, the step the rates act over (0 at the start).
        tables: :class:`~wovenimpact.kernels.bundles.ElementTables` (el_in, el_out,
            rows_in, rows_out below).
        el_in, el_out: element state tables (shell_layout), start / end of step.
        rows_in, rows_out: material point states, start / end of step, one row per
            point: element e owns rows mesh.mat_row[e] … mat_row[e + 1] − 1
            (``Model.mat_row``).
            An eroded element's rows are carried only while the out tables still
            hold it alive (the first step after its erosion): both tables then hold
            the same rows for good, provided they did when the run started.
        blocks: (n_elems, 4, 6), row e written: forces (global, N) and moments
            (global, N·m) per corner, the internal (resisting) forces.

    Returns:
        (status, eroded_now, dt_erosion): an EL_* code, 1 if the element eroded this
        step, and the step the caller's erosion test (``dt_erode``) reads: the
        element's isotropic bound L_e/c_e (``element_stable_step``), also when the run's
        step is the yarn families' — erosion is a model decision, and must not change
        with the step's option (theory §4, stable step) — ∞ where it does not apply.
    """
    x, v, omega = motion.x, motion.v, motion.omega
    quads, area0, ref_grad = mesh.quads, mesh.area0, mesh.ref_grad
    gauss_grad, gauss_weight = mesh.gauss_grad, mesh.gauss_weight
    sections, mat_kind, mat_params = mesh.sections, mesh.mat_kind, mesh.mat_params
    el_in, el_out, rows_in, rows_out = tables.el_in, tables.el_out, tables.mat_in, tables.mat_out
    sec = np.uint64(mesh.elem_section[e])
    row0 = np.uint64(mesh.mat_row[e])
    n_rows = np.uint64(mesh.mat_row[e + np.uint64(1)]) - row0
    if el_in[e, E_ALIVE] == 0.0:
        # eroded: its state no longer changes; the other buffer needs it once more
        if el_out[e, E_ALIVE] != 0.0:
            carry_state(e, el_in, el_out, rows_in, rows_out, row0, n_rows)
        el_out[e, E_DT] = math.inf
        el_out[e, E_DT_KIN] = math.inf
        clear_block(blocks, e)
        return EL_OK, 0, math.inf
    carry_state(e, el_in, el_out, rows_in, rows_out, row0, n_rows)

    # 1. corotational frames at x^n (forces) and at x^{n−1/2} = x^n − ½Δt v (rates:
    # the velocities of the step belong to the midpoint configuration)
    c0, c1, c2_, c3 = (
        np.uint64(quads[e, 0]), np.uint64(quads[e, 1]), np.uint64(quads[e, 2]),
        np.uint64(quads[e, 3]),
    )
    px, py, pz = corner_values(x, c0, c1, c2_, c3)
    vx_, vy_, vz_ = corner_values(v, c0, c1, c2_, c3)
    frame = corotational_frame(px, py, pz)
    area = frame[4]
    if not (area > 0.0):
        return element_failed(e, el_out, blocks, area)
    mid = midpoint_frame(px, py, pz, vx_, vy_, vz_, dt)
    if not (mid[4] > 0.0):
        return element_failed(e, el_out, blocks, mid[4])
    lx, ly = frame[3]
    b1, b2 = frame[5]

    # 2. rates in the midpoint frame: curvature and transverse-shear increments
    wx_, wy_, wz_ = corner_values(omega, c0, c1, c2_, c3)
    vx, vy, vz, tx, ty, dkx, dky, dkxy2, dgxz, dgyz = midpoint_rates(
        mid, vx_, vy_, vz_, wx_, wy_, wz_, dt)
    kap_x = el_in[e, E_KAPPA] + dkx
    kap_y = el_in[e, E_KAPPA + 1] + dky
    kap_xy2 = el_in[e, E_KAPPA + 2] + dkxy2
    el_out[e, E_KAPPA] = kap_x
    el_out[e, E_KAPPA + 1] = kap_y
    el_out[e, E_KAPPA + 2] = kap_xy2

    # 3. membrane: F = Σ x̂_I ⊗ ∂N_I/∂X at the centre (one-point membrane, outputs),
    # the section's resultants and the membrane's corner forces
    g1 = (ref_grad[e, 0, 0], ref_grad[e, 0, 1], ref_grad[e, 0, 2], ref_grad[e, 0, 3])
    g2 = (ref_grad[e, 1, 0], ref_grad[e, 1, 1], ref_grad[e, 1, 2], ref_grad[e, 1, 3])
    f11, f12, f21, f22 = centre_gradient(lx, ly, g1, g2)
    det = f11 * f22 - f12 * f21
    if not (det > 0.0):
        return element_failed(e, el_out, blocks, det)
    el_out[e, E_F] = f11
    el_out[e, E_F + 1] = f12
    el_out[e, E_F + 2] = f21
    el_out[e, E_F + 3] = f22
    thick = sections[sec, C_THICK]
    mu = sections[sec, C_AREAL_MASS]
    m = np.uint64(sections[sec, C_MAT])
    kind = mat_kind[m]
    a0 = area0[e]
    n_pts = int(sections[sec, C_POINTS])
    integrated = n_pts > 1
    if int(sections[sec, C_INPLANE]) == MEMBRANE_FULL:
        (status, eroded, c_memb, w_memb, n11, n22, n12, mi_xx, mi_yy, mi_xy, mf_x, mf_y,
         c_step, k_warp, k_fill) = (
            full_membrane(
                e, lx, ly, gauss_grad, gauss_weight, a0, n_pts, thick, kind, mat_params, m,
                el_in, el_out, el_in[e, E_KAPPA], el_in[e, E_KAPPA + 1], el_in[e, E_KAPPA + 2],
                kap_x, kap_y, kap_xy2, dt, rows_in, rows_out, row0,
            )
        )
        full = True
    else:
        (status, n_alive, c_memb, w_memb, n11, n22, n12, mi_xx, mi_yy, mi_xy, c_step, k_warp,
         k_fill) = section_response(
            n_pts, thick, kind, mat_params, m,
            el_in[e, E_F], el_in[e, E_F + 1], el_in[e, E_F + 2], el_in[e, E_F + 3],
            f11, f12, f21, f22, el_in[e, E_KAPPA], el_in[e, E_KAPPA + 1],
            el_in[e, E_KAPPA + 2], kap_x, kap_y, kap_xy2, dt, rows_in, rows_out, row0,
        )
        eroded = status == 0 and n_alive == 0
        w_memb *= a0
        mf_x, mf_y = centre_membrane_forces(a0, n11, n22, n12, f11, f12, f21, f22, g1, g2)
        full = False
    if status != 0:
        el_out[e, E_N] = 0.0
        el_out[e, E_N + 1] = 0.0
        el_out[e, E_N + 2] = 0.0
        el_out[e, E_DT] = 0.0
        el_out[e, E_DT_KIN] = math.inf
        clear_block(blocks, e)
        return status, 0, math.inf
    if eroded:
        # no force from now on; its stored energy is booked by the caller
        el_out[e, E_U_MEMB] = w_memb
        el_out[e, E_ALIVE] = 0.0
        el_out[e, E_DT] = math.inf
        el_out[e, E_DT_KIN] = math.inf
        for j in range(3):
            el_out[e, E_N + j] = 0.0
        clear_block(blocks, e)
        return EL_OK, 1, math.inf
    el_out[e, E_N] = n11
    el_out[e, E_N + 1] = n22
    el_out[e, E_N + 2] = n12
    el_out[e, E_U_MEMB] = w_memb

    # 4. bending and transverse shear: M = D Δκ accumulated (resultant section) or
    # from the points (integrated section, bending energy then in the membrane term)
    kgt = sections[sec, C_SHEAR_K] * sections[sec, C_SHEAR_G] * thick
    d_b, mxx, myy, mxy, qx, qy, w_bend = bending_and_shear(
        e, el_in, el_out, area, integrated, c_memb, thick, sections[sec, C_BEND_E],
        sections[sec, C_BEND_NU], kgt, mi_xx, mi_yy, mi_xy, dkx, dky, dkxy2, dgxz, dgyz)

    # 5. hourglass (Flanagan–Belytschko): γ_I = ¼ (h_I − (h·x̂) b1_I − (h·ŷ) b2_I),
    # rates with the midpoint γ, forces with the current one
    gam, bb = hourglass_vectors(lx, ly, b1, b2)
    gam_mid = hourglass_vectors(mid[3][0], mid[3][1], mid[5][0], mid[5][1])[0]
    k_m, k_w, k_t = hourglass_stiffnesses(sections[sec, C_HOURGLASS], c_memb, area, bb, d_b,
                                          full)
    hg0, hg1, hg2, hg3, hg4 = hourglass_resultants(
        e, el_in, el_out, k_m, k_w, k_t, gam_mid, vx, vy, vz, tx, ty, dt)

    # 6. corner forces (membrane, shear, hourglass) and moments in the local frame,
    # turned to global axes
    fzs = warp_forces(mf_x, mf_y, lx, ly, frame[6], area)
    fsum = corner_forces(e, blocks, frame, mf_x, mf_y, fzs, gam, hg0, hg1, hg2, hg3, hg4,
                         mxx, myy, mxy, qx, qy)

    # 7. stable step; the isotropic bound is also the erosion test's
    inertia = mesh.rot_inertia[e]
    dt_iso = element_stable_step(px, py, pz, area, c_memb, kgt, mu, inertia, d_b, bb)
    if mesh.step_mode == STEP_YARN:
        # (k_warp, k_fill: the yarn families' stiffnesses; k_w above is the w hourglass
        # mode's); the kinematic bound is kept apart: mass scaling cannot raise it
        dt_e = min(element_stable_step(px, py, pz, area, c_step, kgt, mu, inertia, d_b, bb),
                   family_stable_step(k_warp, c_step, mu, g1),
                   family_stable_step(k_fill, c_step, mu, g2))
        dt_kin = kinematic_step(px, py, pz, vx_, vy_, vz_, mesh.kinematic_fraction)
    else:
        dt_e = dt_iso
        dt_kin = math.inf
    el_out[e, E_DT] = dt_e
    el_out[e, E_DT_KIN] = dt_kin
    if not math.isfinite(fsum + dt_e):
        return EL_NAN, 0, math.inf
    return EL_OK, 0, dt_iso


@kernel
def finish_element(e, st, er, dt_check, el_out, blocks, status, eroded_now, alive, dt_erode,
                   erode_inverted):
    """After ``shell_force`` of element e (status st, er = 1 if it eroded, dt_check its
    isotropic step): the erosion tests of the element stage (``internal_force_for_shells``'
    dt_erode and erode_inverted), then e's status, eroded and alive bytes.

    Returns (1 if e failed else 0, er, e's own step: the smaller of E_DT and E_DT_KIN)."""
    if st == EL_INVERTED and erode_inverted:
        # crushed through itself (LS-DYNA's erosion on a negative Jacobian): it goes,
        # with the energies it held at the start of the step
        el_out[e, E_ALIVE] = 0.0
        el_out[e, E_DT] = math.inf
        el_out[e, E_DT_KIN] = math.inf
        clear_block(blocks, e)
        st = EL_OK
        er = 1
    elif st == EL_OK and er == 0 and dt_check < dt_erode:
        el_out[e, E_ALIVE] = 0.0
        el_out[e, E_DT] = math.inf
        el_out[e, E_DT_KIN] = math.inf
        clear_block(blocks, e)
        er = 1
    status[e] = st
    eroded_now[e] = er
    alive[e] = 1 if el_out[e, E_ALIVE] != 0.0 else 0
    return (0 if st == EL_OK else 1), er, min(el_out[e, E_DT], el_out[e, E_DT_KIN])


@kernel
def scalar_element(e, mesh, motion, dt, tables, blocks, status, eroded_now, alive, dt_erode,
                   erode_inverted):
    """``shell_force`` of element e, then :func:`finish_element`; returns the latter's
    (failed, eroded, own step)."""
    st, er, dt_check = shell_force(e, mesh, motion, dt, tables, blocks)
    return finish_element(e, st, er, dt_check, tables.el_out, blocks, status, eroded_now,
                          alive, dt_erode, erode_inverted)


@loop_kernel
def internal_force_for_shells(mesh, motion, dt, tables, results, dt_erode, erode_inverted):
    """``shell_force`` for every element (prange; each element writes its own rows).

    Args: mesh (``bundles.ShellMesh``); motion (``bundles.Motion``); dt; tables
    (``bundles.ElementTables``: mat_in, mat_out one row per material point, element e's
    from ``mesh.mat_row[e]``); results
    (``bundles.ElementResults``, written: blocks (n_elems, 4, 6); status, eroded_now
    (n_elems,); alive (n_elems,) uint8: 1 for an element alive at the end of the step, a
    compact copy of ``el_out[:, E_ALIVE]`` for the node kernels); dt_erode: an element
    whose own stable step L_e/c_e falls below it is eroded (crushed or collapsed
    elements, e.g. fabric with one yarn family broken; 0 disables; the isotropic
    step L_e/c_e also under the yarn step option); erode_inverted: an
    element inverted (non-positive area or Jacobian) is eroded instead of stopping the
    run.

    Returns:
        (n_failed, n_eroded, dt_min): elements with a non-OK status, elements
        eroded this step (integer counts: exact, so the same for any thread count),
        and min_e of ``el_out[e, E_DT]`` and ``el_out[e, E_DT_KIN]`` (inf if every
        element is eroded; a minimum is
        exact in any order, so also the same for any thread count; meaningful only
        when n_failed is 0).
    """
    # one bundle member per statement, read before the parallel loop: a prange body
    # that writes through a bundle, or through arrays unpacked from a tuple in one
    # statement, loses its writes (Numba issues 5872, 7135: open in 0.68)
    ne = mesh.quads.shape[0]
    el_out = tables.el_out
    blocks = results.blocks
    status = results.status
    eroded_now = results.eroded_now
    alive = results.alive
    n_failed = 0
    n_eroded = 0
    dt_min = math.inf
    rows = ElementTables(tables.el_in, el_out, tables.mat_in, tables.mat_out)
    for e in prange(ne):
        failed, er, dt_own = scalar_element(np.uint64(e), mesh, motion, dt, rows, blocks,
                                            status, eroded_now, alive, dt_erode,
                                            erode_inverted)
        dt_min = min(dt_min, dt_own)
        n_failed += failed
        n_eroded += er
    return n_failed, n_eroded, dt_min
