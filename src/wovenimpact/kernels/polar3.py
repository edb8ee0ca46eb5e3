"""3×3 kinematics of a solid material point: polar decomposition and the rotated
strain increment (docs/solid.md, "Objective stress update").

Tensors travel as tuples: a general 3×3 as 9 values row by row (A11 A12 A13 A21 …),
a symmetric one as 6 in Voigt order 11, 22, 33, 23, 13, 12 (tensor components).

- ``polar_decomposition``: F = R U (det F > 0) by Newton's iteration on the orthogonal
  factor with determinant scaling (Higham 1986, "Computing the polar decomposition — with
  applications", SIAM J. Sci. Stat. Comput. 7, 1160, doi:10.1137/0907079):
  X_{k+1} = ½ (ζ_k X_k + ζ_k⁻¹ X_k⁻ᵀ), ζ_k = |det X_k|^(−1/3), X_0 = F. It converges
  quadratically for any non-singular F; it stops once a step changes X by less than
  ``POLAR_STEP_TOL`` (Frobenius norm), after which the next error is below round-off. Then
  U = sym(Rᵀ F).
- ``stretch_increment``: Δd = sym(ΔU U_mid⁻¹), U_mid = ½ (U_old + U_new) — the rotated
  rate of deformation Rᵀ D R Δt at the midpoint (the same increment as the shells' J2
  kernel, eq. (J2) of theory.md, in 3-D). It depends on U alone, so any superposed
  rotation history leaves it unchanged to round-off: a rigid rotation of any size gives
  Δd = 0.

All functions are per-point (no allocation) and inline into their callers.
"""

from __future__ import annotations

import math

from wovenimpact.jit import inline_kernel

POLAR_MAX_ITER = 40  # Newton from a stretch of 10⁶ reaches round-off in ~12 steps
POLAR_STEP_TOL = 1e-10  # ‖X_{k+1} − X_k‖_F below this: X_{k+1} is R to round-off


@inline_kernel
def det3(a):
    """det A of a 3×3 (9-tuple, row-major)."""
    return (a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
            + a[2] * (a[3] * a[7] - a[4] * a[6]))


@inline_kernel
def cofactor3(a):
    """cof A = det A · A⁻ᵀ (9-tuple, row-major)."""
    return (
        a[4] * a[8] - a[5] * a[7], a[5] * a[6] - a[3] * a[8], a[3] * a[7] - a[4] * a[6],
        a[2] * a[7] - a[1] * a[8], a[0] * a[8] - a[2] * a[6], a[1] * a[6] - a[0] * a[7],
        a[1] * a[5] - a[2] * a[4], a[2] * a[3] - a[0] * a[5], a[0] * a[4] - a[1] * a[3],
    )


@inline_kernel
def matmul3(a, b):
    """A B (9-tuples, row-major)."""
    return (
        a[0] * b[0] + a[1] * b[3] + a[2] * b[6],
        a[0] * b[1] + a[1] * b[4] + a[2] * b[7],
        a[0] * b[2] + a[1] * b[5] + a[2] * b[8],
        a[3] * b[0] + a[4] * b[3] + a[5] * b[6],
        a[3] * b[1] + a[4] * b[4] + a[5] * b[7],
        a[3] * b[2] + a[4] * b[5] + a[5] * b[8],
        a[6] * b[0] + a[7] * b[3] + a[8] * b[6],
        a[6] * b[1] + a[7] * b[4] + a[8] * b[7],
        a[6] * b[2] + a[7] * b[5] + a[8] * b[8],
    )


@inline_kernel
def transpose3(a):
    """Aᵀ (9-tuple, row-major)."""
    return (a[0], a[3], a[6], a[1], a[4], a[7], a[2], a[5], a[8])


@inline_kernel
def sym_to_full(s):
    """The 9-tuple of a symmetric tensor given in Voigt order (11, 22, 33, 23, 13, 12)."""
    return (s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2])


@inline_kernel
def sym_part(a):
    """sym A = ½ (A + Aᵀ) in Voigt order (11, 22, 33, 23, 13, 12)."""
    return (a[0], a[4], a[8], 0.5 * (a[5] + a[7]), 0.5 * (a[2] + a[6]), 0.5 * (a[1] + a[3]))


@inline_kernel
def rotate_sym(q, s):
    """Q S Qᵀ (S symmetric, Voigt in and out; Q a 9-tuple)."""
    a = matmul3(matmul3(q, sym_to_full(s)), transpose3(q))
    return sym_part(a)


@inline_kernel
def rotate_sym_back(q, s):
    """Qᵀ S Q (S symmetric, Voigt in and out; Q a 9-tuple)."""
    a = matmul3(matmul3(transpose3(q), sym_to_full(s)), q)
    return sym_part(a)


@inline_kernel
def polar_decomposition(f):
    """F = R U (docstring of the module).

    Returns:
        (ok, R, U): ok False for det F ≤ 0, a non-finite F or no convergence within
        ``POLAR_MAX_ITER`` steps (R, U then meaningless); R a 9-tuple, U Voigt 6-tuple.
    """
    x = f
    det = det3(x)
    if not (det > 0.0 and math.isfinite(det)):
        return False, x, (0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    ok = False
    for _ in range(POLAR_MAX_ITER):
        det = det3(x)
        zeta = abs(det) ** (-1.0 / 3.0)
        c = cofactor3(x)
        s1 = 0.5 * zeta
        s2 = 0.5 / (zeta * det)  # ½ ζ⁻¹ X⁻ᵀ = ½ ζ⁻¹ cof X / det X
        xn = (
            s1 * x[0] + s2 * c[0], s1 * x[1] + s2 * c[1], s1 * x[2] + s2 * c[2],
            s1 * x[3] + s2 * c[3], s1 * x[4] + s2 * c[4], s1 * x[5] + s2 * c[5],
            s1 * x[6] + s2 * c[6], s1 * x[7] + s2 * c[7], s1 * x[8] + s2 * c[8],
        )
        step = 0.0
        for i in range(9):
            step += (xn[i] - x[i]) * (xn[i] - x[i])
        x = xn
        if step <= POLAR_STEP_TOL * POLAR_STEP_TOL:
            ok = True
            break
    u = sym_part(matmul3(transpose3(x), f))
    return ok, x, u


@inline_kernel
def sym_inverse(s):
    """S⁻¹ of a symmetric 3×3 (Voigt in and out); inf/NaN if singular."""
    c11 = s[1] * s[2] - s[3] * s[3]
    c22 = s[0] * s[2] - s[4] * s[4]
    c33 = s[0] * s[1] - s[5] * s[5]
    c23 = s[4] * s[5] - s[0] * s[3]
    c13 = s[5] * s[3] - s[1] * s[4]
    c12 = s[3] * s[4] - s[2] * s[5]
    inv = 1.0 / (s[0] * c11 + s[5] * c12 + s[4] * c13)
    return (c11 * inv, c22 * inv, c33 * inv, c23 * inv, c13 * inv, c12 * inv)


@inline_kernel
def stretch_increment(u_old, u_new):
    """Δd = sym(ΔU U_mid⁻¹), U_mid = ½ (U_old + U_new) (Voigt in and out)."""
    du = (u_new[0] - u_old[0], u_new[1] - u_old[1], u_new[2] - u_old[2],
          u_new[3] - u_old[3], u_new[4] - u_old[4], u_new[5] - u_old[5])
    mid = (0.5 * (u_new[0] + u_old[0]), 0.5 * (u_new[1] + u_old[1]),
           0.5 * (u_new[2] + u_old[2]), 0.5 * (u_new[3] + u_old[3]),
           0.5 * (u_new[4] + u_old[4]), 0.5 * (u_new[5] + u_old[5]))
    return sym_part(matmul3(sym_to_full(du), sym_to_full(sym_inverse(mid))))
