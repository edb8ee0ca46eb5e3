"""Transversely isotropic linear elastic solid point, objective (Green–Naghdi) update.

docs/solid.md "Material"; thesis §5.2.2 (Table 5-2: the yarn's engineering constants,
E11 along the yarn). Per point and step, given the one-point deformation gradient F^n
(reference → current), the stretch U^{n−1} and the stress of the last step, and the
element's material axes M0 (rows a1, a2, a3 in global components, a1 the fibre axis),

1. polar decomposition F = R U (``polar3.polar_decomposition``);
2. rotated strain increment Δd = sym(ΔU U_mid⁻¹) (``polar3.stretch_increment``), in the
   material axes Δd_m = M0 Δd M0ᵀ;
3. rotated Kirchhoff stress in the material axes τ_m ← τ_m + C : Δd_m, C the
   stiffness of the engineering constants (solid_layout ``TI_C*``):
   Δτ11 = C11 Δd11 + C12 (Δd22 + Δd33), Δτ22 = C12 Δd11 + C22 Δd22 + C23 Δd33,
   Δτ33 = C12 Δd11 + C23 Δd22 + C22 Δd33, Δτ23 = 2 G23 Δd23, Δτ13 = 2 G12 Δd13,
   Δτ12 = 2 G12 Δd12;
4. stored energy per unit reference volume ΔW = ½ (τ_old + τ_new) : Δd_m (trapezoid:
   exact for a linear law, W = ½ ε : C : ε with ε = Σ Δd);
5. the Kirchhoff stress in global axes τ = Q τ_m Qᵀ, Q = R M0ᵀ (the material axes carried
   by the element's rotation R: the Green–Naghdi frame, as Abaqus/Explicit orients the
   materials of its solid elements). The Cauchy stress is σ = τ / J.

Objectivity: a superposed rotation of any size changes R alone (U is unchanged), so τ_m is
unchanged and τ rotates with it exactly; a rigid rotation from the unstressed state
leaves the stress zero to round-off (tests/unit/test_hex8.py).

The point's state is a row of the solid element table (solid_layout ``H_*``): τ_m at
``H_TAU``, U at ``H_U``, the energy at ``H_W``.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from wovenimpact.jit import inline_kernel, kernel, loop_kernel
from wovenimpact.kernels.polar3 import (
    det3,
    matmul3,
    polar_decomposition,
    rotate_sym,
    stretch_increment,
    transpose3,
)
from wovenimpact.kernels.solid_layout import (
    H_SIG,
    H_TAU,
    H_U,
    H_W,
    POINT_BAD_KINEMATICS,
    POINT_NOT_CONVERGED,
    POINT_OK,
    TI_C11,
    TI_C12,
    TI_C22,
    TI_C23,
    TI_C44,
    TI_C66,
)


@inline_kernel
def ti_stress_increment(mat_params, m, d):
    """Δτ_m = C : Δd_m (step 3) for the parameter row m; d in Voigt order (tensor shears)."""
    c11 = mat_params[m, TI_C11]
    c12 = mat_params[m, TI_C12]
    c22 = mat_params[m, TI_C22]
    c23 = mat_params[m, TI_C23]
    g23 = mat_params[m, TI_C44]
    g12 = mat_params[m, TI_C66]
    return (
        c11 * d[0] + c12 * (d[1] + d[2]),
        c12 * d[0] + c22 * d[1] + c23 * d[2],
        c12 * d[0] + c23 * d[1] + c22 * d[2],
        2.0 * g23 * d[3],
        2.0 * g12 * d[4],
        2.0 * g12 * d[5],
    )


@inline_kernel
def frame_matrix(frame, fr):
    """M0 of frame row fr (9-tuple, row-major: rows a1, a2, a3)."""
    return (frame[fr, 0, 0], frame[fr, 0, 1], frame[fr, 0, 2],
            frame[fr, 1, 0], frame[fr, 1, 1], frame[fr, 1, 2],
            frame[fr, 2, 0], frame[fr, 2, 1], frame[fr, 2, 2])


@inline_kernel
def ti_point(mat_params, m, frame, fr, f, el_in, el_out, row, vol0):
    """One point from row ``row`` of ``el_in`` to the same row of ``el_out`` (steps 1–5).

    Args:
        mat_params, m: parameter table and the material's row (solid_layout ``TI_*``).
        frame, fr: material axes table (n, 3, 3) and the point's row.
        f: F^n, 9-tuple row-major.
        el_in, el_out: state tables (solid_layout ``H_*``); writes ``H_TAU``, ``H_U`` and
            ``H_W`` of ``el_out[row]``.
        vol0: the reference volume the energy is booked for (1: per unit volume).

    Returns:
        (status, τ, R): solid_layout ``POINT_*`` code; the Kirchhoff stress J σ in global
        axes (Voigt); the rotation R (9-tuple). On a status other than ``POINT_OK`` the
        row is not written and τ = 0.
    """
    zero6 = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    ok, r, u = polar_decomposition(f)
    if not ok:
        det = det3(f)
        bad = not (det > 0.0 and math.isfinite(det))
        return (POINT_BAD_KINEMATICS if bad else POINT_NOT_CONVERGED), zero6, r
    u_old = (el_in[row, H_U], el_in[row, H_U + 1], el_in[row, H_U + 2],
             el_in[row, H_U + 3], el_in[row, H_U + 4], el_in[row, H_U + 5])
    m0 = frame_matrix(frame, fr)
    d = rotate_sym(m0, stretch_increment(u_old, u))
    dtau = ti_stress_increment(mat_params, m, d)
    t_old = (el_in[row, H_TAU], el_in[row, H_TAU + 1], el_in[row, H_TAU + 2],
             el_in[row, H_TAU + 3], el_in[row, H_TAU + 4], el_in[row, H_TAU + 5])
    t_new = (t_old[0] + dtau[0], t_old[1] + dtau[1], t_old[2] + dtau[2],
             t_old[3] + dtau[3], t_old[4] + dtau[4], t_old[5] + dtau[5])
    dw = 0.0
    for k in range(6):
        w = 1.0 if k < 3 else 2.0  # τ : d with tensor shears
        dw += w * 0.5 * (t_old[k] + t_new[k]) * d[k]
    for k in range(6):
        el_out[row, H_TAU + k] = t_new[k]
        el_out[row, H_U + k] = u[k]
    el_out[row, H_W] = el_in[row, H_W] + vol0 * dw
    tau = rotate_sym(matmul3(r, transpose3(m0)), t_new)
    return POINT_OK, tau, r


@kernel
def ti_driven_point(mat_params, m, frame, f, el_in, el_out, i):
    """Point i of ``ti_update_for_points``; returns its status."""
    fi = (f[i, 0, 0], f[i, 0, 1], f[i, 0, 2], f[i, 1, 0], f[i, 1, 1], f[i, 1, 2],
          f[i, 2, 0], f[i, 2, 1], f[i, 2, 2])
    st, tau, _ = ti_point(mat_params, m, frame, i, fi, el_in, el_out, i, 1.0)
    if st == POINT_OK:
        inv_j = 1.0 / det3(fi)
        for k in range(6):
            el_out[i, H_SIG + k] = tau[k] * inv_j
    return st


@loop_kernel
def ti_update_for_points(mat_params, m, frame, f, el_in, el_out, status):
    """``ti_point`` for every point i (prange; each point writes its own row): F^n of
    point i is f[i] (n, 3, 3), its axes frame[i]; el_out[i, H_SIG] gets σ = τ / det F.

    Args: mat_params, m (parameter table and row); frame (n, 3, 3); f (n, 3, 3); el_in,
    el_out (n, N_HEX_STATE), el_out written; status (n,) int32 written (``POINT_*``).
    """
    n = f.shape[0]
    for i in prange(n):
        status[i] = ti_driven_point(mat_params, m, frame, f, el_in, el_out, np.uint64(i))
