"""Eight-node hexahedron for explicit dynamics: one-point (uniform strain) integration with
Flanagan–Belytschko hourglass control in stiffness form.

docs/solid.md states the element; the reference is Flanagan & Belytschko (1981), "A
uniform strain hexahedron and quadrilateral with orthogonal hourglass control", Int. J.
Numer. Meth. Engng 17, 679–706, doi:10.1002/nme.1620170504 (FB below), and Belytschko,
Liu, Moran & Elkhodary, "Nonlinear finite elements for continua and structures" (2nd ed.
2014), §8.7 (BLM below).

Why one point with hourglass control, and why the stiffness form
-----------------------------------------------------------------
- One point, not selectively reduced: one stress update and one polar decomposition per
  element instead of eight; no shear locking of the thin, bent yarns; and it is the
  thesis's own element (Abaqus C3D8R, §5.1), so that the cell's numbers compare. A
  selectively reduced element splits the stress into volumetric and deviatoric parts,
  which a strongly anisotropic yarn (E11/E22 ≈ 29) couples: the split has no clean form.
- Stiffness, not viscous: the crossover's virtual tests are quasi-static (slow ramps,
  dynamic relaxation). A viscous hourglass force is proportional to the hourglass
  velocity and vanishes as the loading slows, so the modes drift freely in the very tests
  the element is for; a stiffness form resists at any rate. Its energy is stored
  (½ Q̂²/k, recoverable) and booked like the shells' (kernels/shell.py, step 4, the same
  form), which is what the acceptance bound "hourglass energy < 5 % of internal work"
  is measured on. The thesis, too, used the stiffness hourglass contribution (§5.1).

Per element and step, given positions x^n, half-step velocities v^{n−1/2} and the step Δt
that led to x^n:

1. geometry (FB §3): the position modes a_k = ⅛ Σ_I s_kI x_I for the sign patterns ξ, η,
   ζ, ηζ, ξζ, ξη, ξηζ at the corners (solid_layout ``HEX_*``); the exact volume of the
   trilinear hexahedron
   V = 8 a1·(a2 × a3) + (8/3) [a1·(a6 × a5) + a5·(a4 × a3) + a6·(a2 × a4)]
   (∫ det J over the parent cube, term by term); and FB's uniform-strain gradients
   B_I = ∫_V ∇N_I dV = ∂V/∂x_I = ⅛ Σ_k s_kI ∂V/∂a_k, b_I = B_I / V. They satisfy
   Σ_I b_I = 0 and Σ_I x_I ⊗ b_I = I exactly, so a linear field has the exact gradient;
2. F = Σ_I x_I ⊗ b⁰_I with the reference gradients b⁰ (Model), and the material update
   (kernels/transverse_isotropic.py: Green–Naghdi rotated Kirchhoff stress τ);
3. internal forces f_I = V σ b_I = V0 τ b_I (σ = τ V0/V the Cauchy stress);
4. hourglass control (FB §4, stiffness form): γ_αI = ⅛ h_αI − a_{3+α}·b_I for the four base
   vectors h_α = ηζ, ξζ, ξη, ξηζ; γ_α is orthogonal to every linear field
   (Σ_I γ_αI (c + L x_I) = 0). Hourglass displacement increment in the rotated frame
   Δq̂_α = Rᵀ Σ_I γ_αI Δx_I (Δx = Δt v^{n−1/2}), generalised force Q̂_α ← Q̂_α + k Δq̂_α,
   corner forces f_I += Σ_α γ_αI R Q̂_α and energy ΔE_hg = Σ_α ½ (Q̂_α^old + Q̂_α^new)·Δq̂_α
   (the work of the hourglass forces: their rate is Σ_α Q̂_α · dq̂_α/dt = Σ_I f_hg,I · v_I).
   k = r G_hg V0 Σ_I b⁰_I·b⁰_I per element (``reference_geometry_for_hexes``), r the
   hourglass coefficient, G_hg the material's hourglass modulus. On a cube of edge h the
   γ_α are h_α/8, a corner pattern u_I = q h_αI e_i has hourglass displacement q and
   k = 3/2 r G_hg h;
5. the stable step Δt_e = l_e / c_e (``hex_stable_step``): with the lumped mass ρ0 V0/8 per
   corner, the Rayleigh quotient of the element bounds its highest frequency by
   ω² ≤ 8 (S + k Λ_γ / V0)/ρ0, where Λ_γ bounds λ_max of the hourglass Gram matrix
   Σ_I γ_αI γ_βI by its largest row sum and S bounds ε:C:ε/|u|² two ways, the smaller kept:
   (a) λ_C Λ_b, with Λ_b = λ_max(Σ_I b_I ⊗ b_I) (|sym ∇u|² ≤ Λ_b |u|²) and λ_C the largest
   eigenvalue of C in Mandel form (ρ c² ≤ λ_C for every plane wave);
   (b) max_i β_i in the current material axes a_i, β_i = D_i Λ_i + 2 Σ_{j≠i} G_ij Λ_j with
   Λ_i = Σ_I (a_i·b_I)², D_i = Σ_j |C_ij| the normal block's row sums and G_ij the shear
   moduli — (a) ignores the direction of the stiff fibre, (b) does not: a yarn element
   long along its fibre gets about twice (a)'s step.
   So l_e = 1/√(2 Λ_b) and c_e² = (S + k Λ_γ / V0)/(Λ_b ρ0) give 2/ω ≥ l_e / c_e. On a box
   l_e is its shortest edge (= V / largest face area, the usual rule) and (a) is exact for
   a single cube; FB's form 1/√(2 Σ_I b_I·b_I) (Λ_b bounded by the trace) is a factor √3
   smaller on a cube.

``hex_force`` is one element; ``internal_force_for_hexes`` loops over all of them in
parallel, each writing only its own rows (element state and the (n_elems, 8, 3) force
block), so results do not depend on the thread count; ``gather_hex_forces`` sums the
blocks into nodal forces through the node → (element, corner) CSR map, in a fixed order.
The blocks are internal forces (the node update subtracts them, as the shells' blocks).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from wovenimpact.jit import inline_kernel, kernel, loop_kernel
from wovenimpact.kernels.bundles import HexTables
from wovenimpact.kernels.shell_layout import EL_INVERTED, EL_MATERIAL, EL_NAN, EL_OK
from wovenimpact.kernels.solid_layout import (
    H_DT,
    H_HG,
    H_SIG,
    H_VOL,
    H_W_HG,
    HEX_ETA,
    HEX_H1,
    HEX_H2,
    HEX_H3,
    HEX_H4,
    HEX_XI,
    HEX_ZETA,
    POINT_BAD_KINEMATICS,
    TI_C11,
    TI_C12,
    TI_C22,
    TI_C23,
    TI_C44,
    TI_C66,
    TI_RHO,
    TI_WAVE_MODULUS,
)
from wovenimpact.kernels.polar3 import matmul3, transpose3
from wovenimpact.kernels.transverse_isotropic import frame_matrix, ti_point

THIRD8 = 8.0 / 3.0


# --- small vector helpers (3-tuples) ---------------------------------------------
@inline_kernel
def cross(u, v):
    return (u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0])


@inline_kernel
def dot(u, v):
    return u[0] * v[0] + u[1] * v[1] + u[2] * v[2]


@inline_kernel
def combine(a, u, b, v):
    """a u + b v."""
    return (a * u[0] + b * v[0], a * u[1] + b * v[1], a * u[2] + b * v[2])


@inline_kernel
def pattern_mode(s, px, py, pz):
    """⅛ Σ_I s_I x_I for a corner sign pattern s (8-tuple)."""
    ax = ay = az = 0.0
    for i in range(8):
        ax += s[i] * px[i]
        ay += s[i] * py[i]
        az += s[i] * pz[i]
    return (0.125 * ax, 0.125 * ay, 0.125 * az)


@inline_kernel
def corner_gradient(i, g1, g2, g3, g4, g5, g6):
    """B_I = ⅛ Σ_k s_kI g_k for corner i (step 1)."""
    s1, s2, s3 = HEX_XI[i], HEX_ETA[i], HEX_ZETA[i]
    s4, s5, s6 = HEX_H1[i], HEX_H2[i], HEX_H3[i]
    return (
        0.125 * (s1 * g1[0] + s2 * g2[0] + s3 * g3[0] + s4 * g4[0] + s5 * g5[0] + s6 * g6[0]),
        0.125 * (s1 * g1[1] + s2 * g2[1] + s3 * g3[1] + s4 * g4[1] + s5 * g5[1] + s6 * g6[1]),
        0.125 * (s1 * g1[2] + s2 * g2[2] + s3 * g3[2] + s4 * g4[2] + s5 * g5[2] + s6 * g6[2]),
    )


# --- step 1: geometry ------------------------------------------------------------
@inline_kernel
def hex_geometry(px, py, pz):
    """Volume, uniform-strain gradients and hourglass position modes of a hexahedron.

    Args:
        px, py, pz: corner coordinates (8-tuples, solid_layout node order).

    Returns:
        (V, bx, by, bz, modes): the exact volume (m³); b_I = B_I / V = (1/V) ∫ ∇N_I dV
        by component (8-tuples, 1/m); the modes (a4, a5, a6, a7) of the step-1 formula.
        V ≤ 0 (or NaN) for an inverted or degenerate element; b is then meaningless.
    """
    a1 = pattern_mode(HEX_XI, px, py, pz)
    a2 = pattern_mode(HEX_ETA, px, py, pz)
    a3 = pattern_mode(HEX_ZETA, px, py, pz)
    a4 = pattern_mode(HEX_H1, px, py, pz)
    a5 = pattern_mode(HEX_H2, px, py, pz)
    a6 = pattern_mode(HEX_H3, px, py, pz)
    a7 = pattern_mode(HEX_H4, px, py, pz)
    # ∂V/∂a_k
    g1 = combine(8.0, cross(a2, a3), THIRD8, cross(a6, a5))
    g2 = combine(8.0, cross(a3, a1), THIRD8, cross(a4, a6))
    g3 = combine(8.0, cross(a1, a2), THIRD8, cross(a5, a4))
    g4 = combine(THIRD8, cross(a3, a5), THIRD8, cross(a6, a2))
    g5 = combine(THIRD8, cross(a1, a6), THIRD8, cross(a4, a3))
    g6 = combine(THIRD8, cross(a5, a1), THIRD8, cross(a2, a4))
    vol = 8.0 * dot(a1, cross(a2, a3)) + THIRD8 * (
        dot(a1, cross(a6, a5)) + dot(a5, cross(a4, a3)) + dot(a6, cross(a2, a4)))
    c0 = corner_gradient(0, g1, g2, g3, g4, g5, g6)
    c1 = corner_gradient(1, g1, g2, g3, g4, g5, g6)
    c2 = corner_gradient(2, g1, g2, g3, g4, g5, g6)
    c3 = corner_gradient(3, g1, g2, g3, g4, g5, g6)
    c4 = corner_gradient(4, g1, g2, g3, g4, g5, g6)
    c5 = corner_gradient(5, g1, g2, g3, g4, g5, g6)
    c6 = corner_gradient(6, g1, g2, g3, g4, g5, g6)
    c7 = corner_gradient(7, g1, g2, g3, g4, g5, g6)
    iv = 1.0 / vol
    bx = (c0[0] * iv, c1[0] * iv, c2[0] * iv, c3[0] * iv,
          c4[0] * iv, c5[0] * iv, c6[0] * iv, c7[0] * iv)
    by = (c0[1] * iv, c1[1] * iv, c2[1] * iv, c3[1] * iv,
          c4[1] * iv, c5[1] * iv, c6[1] * iv, c7[1] * iv)
    bz = (c0[2] * iv, c1[2] * iv, c2[2] * iv, c3[2] * iv,
          c4[2] * iv, c5[2] * iv, c6[2] * iv, c7[2] * iv)
    return vol, bx, by, bz, (a4, a5, a6, a7)


@inline_kernel
def mode_vector(h, a, bx, by, bz):
    """γ_I = ⅛ h_I − a·b_I for one hourglass base vector h and its position mode a."""
    return (
        0.125 * h[0] - (a[0] * bx[0] + a[1] * by[0] + a[2] * bz[0]),
        0.125 * h[1] - (a[0] * bx[1] + a[1] * by[1] + a[2] * bz[1]),
        0.125 * h[2] - (a[0] * bx[2] + a[1] * by[2] + a[2] * bz[2]),
        0.125 * h[3] - (a[0] * bx[3] + a[1] * by[3] + a[2] * bz[3]),
        0.125 * h[4] - (a[0] * bx[4] + a[1] * by[4] + a[2] * bz[4]),
        0.125 * h[5] - (a[0] * bx[5] + a[1] * by[5] + a[2] * bz[5]),
        0.125 * h[6] - (a[0] * bx[6] + a[1] * by[6] + a[2] * bz[6]),
        0.125 * h[7] - (a[0] * bx[7] + a[1] * by[7] + a[2] * bz[7]),
    )


@inline_kernel
def hourglass_vectors(bx, by, bz, modes):
    """FB's hourglass shape vectors γ_α (α = 1 … 4, 8-tuples each; step 4)."""
    return (mode_vector(HEX_H1, modes[0], bx, by, bz),
            mode_vector(HEX_H2, modes[1], bx, by, bz),
            mode_vector(HEX_H3, modes[2], bx, by, bz),
            mode_vector(HEX_H4, modes[3], bx, by, bz))


@inline_kernel
def corners(hexes, e, x):
    """Corner coordinates (or velocities) of element e from a nodal (n_nodes, 3) array."""
    n0, n1, n2, n3 = hexes[e, 0], hexes[e, 1], hexes[e, 2], hexes[e, 3]
    n4, n5, n6, n7 = hexes[e, 4], hexes[e, 5], hexes[e, 6], hexes[e, 7]
    return (
        (x[n0, 0], x[n1, 0], x[n2, 0], x[n3, 0], x[n4, 0], x[n5, 0], x[n6, 0], x[n7, 0]),
        (x[n0, 1], x[n1, 1], x[n2, 1], x[n3, 1], x[n4, 1], x[n5, 1], x[n6, 1], x[n7, 1]),
        (x[n0, 2], x[n1, 2], x[n2, 2], x[n3, 2], x[n4, 2], x[n5, 2], x[n6, 2], x[n7, 2]),
    )


@inline_kernel
def deformation_gradient(px, py, pz, ref_grad, e):
    """F = Σ_I x_I ⊗ b⁰_I (9-tuple, row-major), b⁰ = ref_grad[e] (3, 8)."""
    f11 = f12 = f13 = f21 = f22 = f23 = f31 = f32 = f33 = 0.0
    for i in range(8):
        g1 = ref_grad[e, 0, i]
        g2 = ref_grad[e, 1, i]
        g3 = ref_grad[e, 2, i]
        f11 += px[i] * g1
        f12 += px[i] * g2
        f13 += px[i] * g3
        f21 += py[i] * g1
        f22 += py[i] * g2
        f23 += py[i] * g3
        f31 += pz[i] * g1
        f32 += pz[i] * g2
        f33 += pz[i] * g3
    return (f11, f12, f13, f21, f22, f23, f31, f32, f33)


# --- step 3: internal forces -----------------------------------------------------
@inline_kernel
def stress_forces(e, blocks, s, scale, bx, by, bz):
    """blocks[e, I] = scale · S b_I for a symmetric S (Voigt): f_I = V σ b_I with S = σ,
    scale = V, or V0 τ b_I with S = τ, scale = V0 (step 3). Overwrites the block."""
    for i in range(8):
        b1, b2, b3 = bx[i], by[i], bz[i]
        blocks[e, i, 0] = scale * (s[0] * b1 + s[5] * b2 + s[4] * b3)
        blocks[e, i, 1] = scale * (s[5] * b1 + s[1] * b2 + s[3] * b3)
        blocks[e, i, 2] = scale * (s[4] * b1 + s[3] * b2 + s[2] * b3)


# --- step 4: hourglass -------------------------------------------------------------
@inline_kernel
def hourglass_forces(e, el_in, el_out, blocks, gam, r, k, dx, dy, dz):
    """Stiffness-form hourglass update of element e (step 4): Q̂ ← Q̂ + k Rᵀ Σ γ Δx, its
    work, and the corner forces Σ_α γ_αI R Q̂_α added to blocks[e].

    Args:
        el_in, el_out: element tables (Q̂ read from ``el_in[e, H_HG:]``, written to el_out).
        gam: the four γ_α (8-tuples). r: R (9-tuple). k: hourglass stiffness (N/m).
        dx, dy, dz: corner displacement increments Δx_I = Δt v_I (8-tuples).

    Returns:
        ΔE_hg, the work of the hourglass forces over the step (J).
    """
    work = 0.0
    for a in range(4):
        g = gam[a]
        qx = qy = qz = 0.0
        for i in range(8):
            qx += g[i] * dx[i]
            qy += g[i] * dy[i]
            qz += g[i] * dz[i]
        # Δq̂ = Rᵀ Δq
        hx = r[0] * qx + r[3] * qy + r[6] * qz
        hy = r[1] * qx + r[4] * qy + r[7] * qz
        hz = r[2] * qx + r[5] * qy + r[8] * qz
        c = H_HG + 3 * a
        ox, oy, oz = el_in[e, c], el_in[e, c + 1], el_in[e, c + 2]
        nx, ny, nz = ox + k * hx, oy + k * hy, oz + k * hz
        el_out[e, c] = nx
        el_out[e, c + 1] = ny
        el_out[e, c + 2] = nz
        work += 0.5 * ((ox + nx) * hx + (oy + ny) * hy + (oz + nz) * hz)
        # global Q = R Q̂
        gx = r[0] * nx + r[1] * ny + r[2] * nz
        gy = r[3] * nx + r[4] * ny + r[5] * nz
        gz = r[6] * nx + r[7] * ny + r[8] * nz
        for i in range(8):
            blocks[e, i, 0] += g[i] * gx
            blocks[e, i, 1] += g[i] * gy
            blocks[e, i, 2] += g[i] * gz
    return work


# --- step 5: stable step -----------------------------------------------------------
@inline_kernel
def sym3_max_eigenvalue(a11, a22, a33, a23, a13, a12):
    """Largest eigenvalue of a symmetric 3×3 (trigonometric form, Smith 1961,
    doi:10.1145/355578.366316)."""
    p1 = a12 * a12 + a13 * a13 + a23 * a23
    q = (a11 + a22 + a33) / 3.0
    if p1 == 0.0:
        return max(a11, max(a22, a33))
    d1, d2, d3 = a11 - q, a22 - q, a33 - q
    p = math.sqrt((d1 * d1 + d2 * d2 + d3 * d3 + 2.0 * p1) / 6.0)
    inv = 1.0 / p
    b11, b22, b33 = d1 * inv, d2 * inv, d3 * inv
    b23, b13, b12 = a23 * inv, a13 * inv, a12 * inv
    det_b = (b11 * (b22 * b33 - b23 * b23) - b12 * (b12 * b33 - b23 * b13)
             + b13 * (b12 * b23 - b22 * b13))
    half = max(-1.0, min(1.0, 0.5 * det_b))
    return q + 2.0 * p * math.cos(math.acos(half) / 3.0)


@inline_kernel
def hex_stable_step(bx, by, bz, gam, k, vol0, axes, mat_params, m):
    """Δt_e = l_e / c_e of step 5.

    Args:
        bx, by, bz: current b_I. gam: the γ_α. k: hourglass stiffness. vol0: V0.
        axes: Q = R M0ᵀ, the current material axes as columns (9-tuple).
        mat_params, m: the material's row (solid_layout ``TI_*``).

    Returns:
        (Δt_e, l_e): the step (s) and the characteristic length 1/√(2 Λ_b) (m).
    """
    s11 = s22 = s33 = s23 = s13 = s12 = 0.0
    l1 = l2 = l3 = 0.0  # Λ_i = Σ_I (a_i · b_I)², a_i the current material axes
    for i in range(8):
        s11 += bx[i] * bx[i]
        s22 += by[i] * by[i]
        s33 += bz[i] * bz[i]
        s23 += by[i] * bz[i]
        s13 += bx[i] * bz[i]
        s12 += bx[i] * by[i]
        m1 = axes[0] * bx[i] + axes[3] * by[i] + axes[6] * bz[i]
        m2 = axes[1] * bx[i] + axes[4] * by[i] + axes[7] * bz[i]
        m3 = axes[2] * bx[i] + axes[5] * by[i] + axes[8] * bz[i]
        l1 += m1 * m1
        l2 += m2 * m2
        l3 += m3 * m3
    lam_b = sym3_max_eigenvalue(s11, s22, s33, s23, s13, s12)
    # isotropic bound λ_C Λ_b, and the material-axis bound max_i β_i (docstring, step 5)
    c12 = abs(mat_params[m, TI_C12])
    d1 = mat_params[m, TI_C11] + 2.0 * c12
    d2 = c12 + mat_params[m, TI_C22] + abs(mat_params[m, TI_C23])
    g12 = mat_params[m, TI_C66]
    g23 = mat_params[m, TI_C44]
    beta = max(d1 * l1 + 2.0 * g12 * (l2 + l3),
               max(d2 * l2 + 2.0 * (g12 * l1 + g23 * l3), d2 * l3 + 2.0 * (g12 * l1 + g23 * l2)))
    stiff = min(mat_params[m, TI_WAVE_MODULUS] * lam_b, beta)
    lam_g = 0.0
    for a in range(4):
        row = 0.0
        for c in range(4):
            gg = 0.0
            for i in range(8):
                gg += gam[a][i] * gam[c][i]
            row += abs(gg)
        lam_g = max(lam_g, row)
    length = 1.0 / math.sqrt(2.0 * lam_b)
    c2 = (stiff + k * lam_g / vol0) / (lam_b * mat_params[m, TI_RHO])
    return length / math.sqrt(c2), length


# --- the element -------------------------------------------------------------------
@inline_kernel
def clear_hex_block(blocks, e):
    """No force at any corner of element e."""
    for i in range(8):
        for j in range(3):
            blocks[e, i, j] = 0.0


@kernel
def hex_force(e, mesh, motion, dt, tables, blocks):
    """Steps 1–5 for element e: writes ``tables.el_out[e]`` and ``blocks[e]`` (8, 3).

    Args:
        e: element index (unsigned).
        mesh: ``bundles.HexMesh``. motion: ``bundles.Motion`` (x^n, v^{n−1/2}; ω unused).
        dt: the step Δt that led from x^{n−1} to x^n (s).
        tables: ``bundles.HexTables`` (el_in read, el_out written).
        blocks: (n_elems, 8, 3) internal corner forces, written.

    Returns:
        (status, Δt_e): shell_layout ``EL_*`` code and the element's stable step (s; inf
        unless the status is EL_OK).
    """
    el_in = tables.el_in
    el_out = tables.el_out
    px, py, pz = corners(mesh.hexes, e, motion.x)
    vol, bx, by, bz, modes = hex_geometry(px, py, pz)
    if not vol > 0.0:
        clear_hex_block(blocks, e)
        return EL_INVERTED if vol <= 0.0 else EL_NAN, math.inf
    m = np.uint64(mesh.elem_mat[e])
    vol0 = mesh.vol0[e]
    f = deformation_gradient(px, py, pz, mesh.ref_grad, e)
    st, tau, r = ti_point(mesh.mat_params, m, mesh.frame, e, f, el_in, el_out, e, vol0)
    if st != 0:
        clear_hex_block(blocks, e)
        return (EL_INVERTED if st == POINT_BAD_KINEMATICS else EL_MATERIAL), math.inf
    stress_forces(e, blocks, tau, vol0, bx, by, bz)
    gam = hourglass_vectors(bx, by, bz, modes)
    vx, vy, vz = corners(mesh.hexes, e, motion.v)
    dx = (vx[0] * dt, vx[1] * dt, vx[2] * dt, vx[3] * dt,
          vx[4] * dt, vx[5] * dt, vx[6] * dt, vx[7] * dt)
    dy = (vy[0] * dt, vy[1] * dt, vy[2] * dt, vy[3] * dt,
          vy[4] * dt, vy[5] * dt, vy[6] * dt, vy[7] * dt)
    dz = (vz[0] * dt, vz[1] * dt, vz[2] * dt, vz[3] * dt,
          vz[4] * dt, vz[5] * dt, vz[6] * dt, vz[7] * dt)
    k = mesh.hg_stiffness[e]
    el_out[e, H_W_HG] = el_in[e, H_W_HG] + hourglass_forces(
        e, el_in, el_out, blocks, gam, r, k, dx, dy, dz)
    inv_j = vol0 / vol
    for c in range(6):
        el_out[e, H_SIG + c] = tau[c] * inv_j
    el_out[e, H_VOL] = vol
    axes = matmul3(r, transpose3(frame_matrix(mesh.frame, e)))
    dt_e, _ = hex_stable_step(bx, by, bz, gam, k, vol0, axes, mesh.mat_params, m)
    el_out[e, H_DT] = dt_e
    fsum = 0.0
    for i in range(8):
        fsum += blocks[e, i, 0] + blocks[e, i, 1] + blocks[e, i, 2]
    if not math.isfinite(fsum + dt_e):
        return EL_NAN, math.inf
    return EL_OK, dt_e


@loop_kernel
def internal_force_for_hexes(mesh, motion, dt, tables, results):
    """``hex_force`` for every element (prange; each element writes its own rows).

    Args: mesh (``bundles.HexMesh``); motion (``bundles.Motion``); dt (s); tables
    (``bundles.HexTables``); results (``bundles.HexResults``, written: blocks
    (n_elems, 8, 3) internal corner forces, status (n_elems,) int32 ``EL_*``).

    Returns:
        (n_failed, dt_min): elements with a non-OK status (an exact count) and the
        smallest element step (a minimum: the same in any order, so for any thread count).
    """
    # one bundle member per statement, read before the parallel loop (kernels/shell.py,
    # internal_force_for_shells: a prange body writing through a bundle loses writes)
    ne = mesh.hexes.shape[0]
    el_out = tables.el_out
    blocks = results.blocks
    status = results.status
    rows = HexTables(tables.el_in, el_out)
    n_failed = 0
    dt_min = math.inf
    for e in prange(ne):
        st, dt_e = hex_force(np.uint64(e), mesh, motion, dt, rows, blocks)
        status[e] = st
        n_failed += 0 if st == EL_OK else 1
        dt_min = min(dt_min, dt_e)
    return n_failed, dt_min


@loop_kernel
def gather_hex_forces(node_ptr, node_elem, node_corner, blocks, out):
    """out[n] = Σ blocks[e, c] over the (e, c) of node n, in CSR order (deterministic).

    Args:
        node_ptr, node_elem, node_corner: CSR map node → (element, corner) (Model).
        blocks: (n_elems, 8, 3) corner forces.
        out: (n_nodes, 3) written.
    """
    nn = node_ptr.shape[0] - 1
    for n in prange(nn):
        f0 = f1 = f2 = 0.0
        for k in range(node_ptr[n], node_ptr[n + 1]):
            e = np.uint64(node_elem[k])
            c = np.uint64(node_corner[k])
            f0 += blocks[e, c, 0]
            f1 += blocks[e, c, 1]
            f2 += blocks[e, c, 2]
        out[n, 0] = f0
        out[n, 1] = f1
        out[n, 2] = f2


@kernel
def hex_reference(e, hexes, x0, hg_scale, ref_grad, vol0, hg_stiffness):
    """Element e's row of ``reference_geometry_for_hexes``."""
    px, py, pz = corners(hexes, e, x0)
    vol, bx, by, bz, _ = hex_geometry(px, py, pz)
    bb = 0.0
    for i in range(8):
        ref_grad[e, 0, i] = bx[i]
        ref_grad[e, 1, i] = by[i]
        ref_grad[e, 2, i] = bz[i]
        bb += bx[i] * bx[i] + by[i] * by[i] + bz[i] * bz[i]
    vol0[e] = vol
    hg_stiffness[e] = hg_scale[e] * vol * bb


@loop_kernel
def reference_geometry_for_hexes(hexes, x0, hg_scale, ref_grad, vol0, hg_stiffness):
    """The Model's per-element reference data (prange over elements).

    Args:
        hexes: (n_elems, 8) corner nodes. x0: (n_nodes, 3) reference positions.
        hg_scale: (n_elems,) r G_hg (Pa): hourglass coefficient times hourglass modulus.
        ref_grad: (n_elems, 3, 8) written: b⁰_I by component.
        vol0: (n_elems,) written: V0 (≤ 0 for an inverted element: the caller checks).
        hg_stiffness: (n_elems,) written: k = r G_hg V0 Σ_I b⁰_I·b⁰_I (N/m).
    """
    ne = hexes.shape[0]
    for e in prange(ne):
        hex_reference(np.uint64(e), hexes, x0, hg_scale, ref_grad, vol0, hg_stiffness)
