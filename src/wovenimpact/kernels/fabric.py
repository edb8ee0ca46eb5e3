"""Yarn-crossover model of a dry plain-weave fabric: one material-point update.

docs/theory.md §1 states the model; thesis ch. 3.5–3.6 and 6.2 are its source,
docs/model.md §1 the corrections. Per point, given the in-plane deformation gradient
F (2×2, mapping the reference yarn frame — warp along x, fill along y — to the
current corotational frame), the kernel

1. finds the stretches λ_i and yarn directions e_i (fibre frame, §1.7) or
   accumulates them incrementally (Green–Naghdi option, eq. 6.13–6.16);
2. solves the crossover for the crimp heights H_w, H_f (eq. 6.19–6.25) with a
   bracketed Newton iteration on one unknown (theory §1.3) — or, with the material's
   crossover table (P_CROSSOVER, default), interpolates the stored energy W(λ_w, λ_f), its
   gradient and the heights while both families are intact (theory §1.9,
   ``kernels/fabric_table.py``);
3. applies yarn failure (eq. 6.29, or progressive softening) and erosion;
4. returns the membrane stress resultant N (force per unit current length,
   virial homogenisation §1.5 or the thesis's eq. 6.38), the trellis shear
   resultant (§1.6), the stored energy per unit reference area and an upper
   bound of the membrane tangent stiffness for the stable time step.

``fabric_point`` is these steps as named stages — ``yarn_frame``,
``green_naghdi_stretches``, ``crossover_equilibrium``, ``sliver_erodes``,
``yarn_resultant``, ``trellis_shear``, ``stored_energy`` — inlined into it at Numba IR
level (the same operations in the same order) and tested alone
(tests/unit/test_fabric_stages.py).

Everything is a pure function of flat arrays; ``fabric_update_point`` handles
one point and ``fabric_update_for_points`` loops over many in parallel (each
point independent, so results are bitwise identical for any thread count).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from wovenimpact.jit import inline_kernel, kernel, loop_kernel
from wovenimpact.kernels.fabric_table import crossover_from_table
from wovenimpact.kernels.vecmath import atan2_upper
from wovenimpact.kernels.fabric_layout import (
    CROSSOVER_TABLE,
    FAILURE_PROGRESSIVE,
    FRAME_GREEN_NAGHDI,
    HOMOG_THESIS,
    N_STATE,
    P_AREA,
    P_BETA1,
    P_BETA2,
    P_COMP_A,
    P_COMP_B,
    P_CROSSOVER,
    P_E,
    P_ELL0,
    P_ERODE_CRUSH,
    P_ERODE_INTACT,
    P_FAILURE,
    P_FRAME,
    P_G1,
    P_G2,
    P_GAMMA1,
    P_GAMMA2,
    P_H0,
    P_HOMOG,
    P_LT0,
    P_SHEAR,
    P_THICK,
    P_TU,
    S_ALIVE,
    S_DAMAGE,
    S_ENERGY,
    S_ERODE_LIMIT,
    S_GAMMA,
    S_H,
    S_ITER,
    S_LAMBDA,
    S_SHEAR_ENERGY,
    S_SOFT,
    S_TAU,
    S_TENSION,
    S_TU_SCALE,
    SHEAR_THESIS,
    STATUS_BAD_KINEMATICS,
    STATUS_NOT_CONVERGED,
    STATUS_OK,
)

MAX_ITER = 100  # bisection alone halves [0, 2h0] to round-off in < 60 steps
REL_TOL = 1e-12  # equilibrium |F_w − F_f| ≤ REL_TOL (F_w + F_f)
EPS = 2.220446049250313e-16  # machine epsilon of float64
FINAL_STEP_TOL = 1e-8  # |g| below which one last Newton step is taken unchecked
SWAP_RATIO = 0.25  # re-solve with the roles swapped if u_b < SWAP_RATIO u_a
# a yarn family whose truss is shorter than (1 − SLACK_MARGIN) L0 is slack by more than
# its strain can change in a few steps: its tangent is zero, and it does not count in
# the stable step (theory §1.8, "Slack families")
SLACK_MARGIN = 0.1


# --- constitutive pieces -------------------------------------------------------
@kernel
def yarn_extension(ell, ell0, h, h0, ell_truss0):
    """L − L0 of a half truss, L = √(ℓ² + H²), L0 = √(ℓ0² + h0²) (eq. 6.19, 6.28).

    Evaluated as [(ℓ − ℓ0)(ℓ + ℓ0) + (H − h0)(H + h0)] / (L + L0): near the
    slack point L ≈ L0 the plain difference of two square roots loses all but
    a few digits, and those digits are the yarn tension.
    """
    length = math.sqrt(ell * ell + h * h)
    return ((ell - ell0) * (ell + ell0) + (h - h0) * (h + h0)) / (length + ell_truss0), length


@kernel
def compaction_closure(force, a, b):
    """Overclosure δ(F) = a F / (b + F), inverse of F = b δ / (a − δ) (eq. 5.8), and dδ/dF."""
    if force <= 0.0:
        return 0.0, a / b
    inv = 1.0 / (b + force)
    return a * force * inv, a * b * (inv * inv)


@kernel
def compaction_energy(delta, a, b):
    """∫₀^δ F dδ = b (−a ln(1 − δ/a) − δ) (J), energy of the compaction spring."""
    if delta <= 0.0:
        return 0.0
    return b * (-a * math.log1p(-delta / a) - delta)


@kernel
def slack_height(ell, ell0, h0):
    """Largest H at which a yarn of half-length ℓ is slack, √(L0² − ℓ²) = √(h0² − (ℓ − ℓ0)(ℓ + ℓ0)),
    or 0 if it is taut even when straight."""
    q = h0 * h0 - (ell - ell0) * (ell + ell0)
    if q <= 0.0:
        return 0.0
    return math.sqrt(q)


@kernel
def slack_offset(ell, ell0, h0):
    """Slack geometry of one yarn of half-length ℓ (theory §1.3).

    Returns (Hs, h0 − Hs, c): the largest height at which the yarn is slack,
    Hs = √(L0² − ℓ²) (0 if the yarn is taut even when straight), the distance
    h0 − Hs = (ℓ − ℓ0)(ℓ + ℓ0)/(h0 + Hs) computed without cancellation, and
    c = max(ℓ² − L0², 0), the squared excess length of a taut straight yarn.
    """
    dq = (ell - ell0) * (ell + ell0)  # ℓ² − ℓ0², exact to a few ulps
    q = h0 * h0 - dq  # L0² − ℓ²
    if q <= 0.0:
        return 0.0, h0, -q
    hs = math.sqrt(q)
    return hs, dq / (h0 + hs), 0.0


@kernel
def yarn_force_offset(k, ell, hs, c, u, ell_truss0):
    """Vertical force of one yarn at height H = Hs + u above its slack height.

    The extension is written in the offset u so that it keeps its relative
    accuracy near the slack point (eq. 6.19, 6.21–6.22):
    L − L0 = (L² − L0²)/(L + L0) = [u (u + 2 Hs) + c]/(L + L0), F = 2 T H / L.

    Returns (F, dF/du, T, H); no force for u ≤ 0 (slack) or k = 0.
    """
    h = hs + u
    if u <= 0.0 or k == 0.0:
        return 0.0, 0.0, 0.0, h
    length = math.sqrt(ell * ell + h * h)
    inv_len = 1.0 / length  # one division for F and dF/du (the Newton loop's latency)
    ext = (u * (u + 2.0 * hs) + c) / (length + ell_truss0)
    tension = k * ext
    force = 2.0 * tension * h * inv_len
    dforce = 2.0 * k * (1.0 - ell_truss0 * ell * ell * (inv_len * inv_len * inv_len))
    return force, dforce, tension, h


@kernel
def yarn_vertical_stiffness(k, ell, h, ell_truss0):
    """dF/dH = 2 k (1 − L0 ℓ²/L³) of a taut yarn at height H (eq. 6.22), ≥ 0."""
    length = math.sqrt(ell * ell + h * h)
    return max(2.0 * k * (1.0 - ell_truss0 * ell * ell / (length * length * length)), 0.0)


@kernel
def tension_predictor(tension, k, ell_truss0, ell, h_prev):
    """Height at which a yarn of half-length ℓ keeps the tension T it had:
    H = √((L0 + T/k)² − ℓ²); the previous height if it was slack or cannot."""
    if tension <= 0.0 or k <= 0.0:
        return h_prev
    length = ell_truss0 + tension / k
    q = length * length - ell * ell
    return math.sqrt(q) if q > 0.0 else h_prev


# keeps its long signature: a stage called in the loop of ``intact_crimp_heights``, its arguments
# that loop's locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@kernel
def solve_crimp_heights(k_a, ell_a, ell0_a, h0_a, lt0_a, k_b, ell_b, ell0_b, h0_b, lt0_b, a, b, h_a_prev):
    """Crimp heights of two intact yarns in contact (eq. 6.21–6.25; theory §1.3).

    Unknown: u_a = H_a − Hs_a, the height of yarn "a" above its slack height
    Hs_a. Compatibility H_a + H_b + δ(F) = h0_a + h0_b gives
    u_b = D − δ(F_a(u_a)) − u_a with the overlap D = (h0_a − Hs_a) + (h0_b − Hs_b),
    computed without cancellation, so near-slack states (small F, small D)
    keep full relative accuracy. The residual g(u_a) = F_a − F_b is increasing;
    if D ≤ 0 both yarns are slack while touching (g ≡ 0 on an interval: the
    previous height is kept, projected onto it), otherwise the root is unique
    in (0, D) with g(0) < 0 < g(D). Newton steps stay in the shrinking bracket,
    bisection otherwise. Stops when |g| ≤ REL_TOL (F_a + F_b) or when |g| is
    at the round-off level of its own evaluation.

    Returns:
        (H_a, H_b, F_c, |F_a − F_b|, iterations, converged, swap): swap says the
        derived yarn ended much closer to slack than the unknown one
        (u_b < SWAP_RATIO u_a), so the other role would be better conditioned.
    """
    s_total = h0_a + h0_b
    hs_a, off_a, c_a = slack_offset(ell_a, ell0_a, h0_a)
    hs_b, off_b, c_b = slack_offset(ell_b, ell0_b, h0_b)
    overlap = off_a + off_b
    if overlap <= 0.0:
        lo = max(0.0, s_total - hs_b)
        hi = min(s_total, hs_a)
        h_a = min(max(h_a_prev, lo), hi)
        return h_a, s_total - h_a, 0.0, 0.0, 0, True, False
    lo = 0.0
    hi = overlap
    x = min(max(h_a_prev - hs_a, lo), hi)
    if x == lo or x == hi:
        x = 0.5 * (lo + hi)
    for it in range(1, MAX_ITER + 1):
        f_a, df_a, t_a, h_a = yarn_force_offset(k_a, ell_a, hs_a, c_a, x, lt0_a)
        delta, ddelta = compaction_closure(f_a, a, b)
        u_b = overlap - delta - x
        f_b, df_b, t_b, h_b = yarn_force_offset(k_b, ell_b, hs_b, c_b, u_b, lt0_b)
        g = f_a - f_b
        slope = df_a + df_b * (1.0 + ddelta * df_a)
        # round-off level of g: the forces, and one ulp of the overlap seen through F_b
        noise = EPS * (4.0 * (f_a + f_b) + 2.0 * df_b * overlap)
        if f_a > 0.0 and (abs(g) <= REL_TOL * (f_a + f_b) or abs(g) <= noise):
            return h_a, h_b, 0.5 * (f_a + f_b), abs(g), it, True, u_b < SWAP_RATIO * x
        if f_a > 0.0 and f_b > 0.0 and slope > 0.0 and abs(g) <= FINAL_STEP_TOL * (f_a + f_b):
            # Last Newton step taken without a new evaluation: the residual left
            # is O(step²), ~1e-14 of F here; heights and force follow linearly.
            step = g / slope
            du_b = (1.0 + ddelta * df_a) * step
            if u_b + du_b > 0.0 and lo <= x - step <= hi:
                f_c = f_a - df_a * step
                u_b += du_b
                x -= step
                res = abs(g) * FINAL_STEP_TOL
                return hs_a + x, hs_b + u_b, f_c, res, it, True, u_b < SWAP_RATIO * x
        if g < 0.0:
            lo = x
        else:
            hi = x
        if hi - lo <= 4.0 * EPS * hi:  # bracket collapsed to a few ulps
            return h_a, h_b, 0.5 * (f_a + f_b), abs(g), it, f_a > 0.0, u_b < SWAP_RATIO * x
        x_new = x - g / slope if slope > 0.0 else lo - 1.0
        if not (lo < x_new < hi):
            x_new = 0.5 * (lo + hi)
        x = x_new
    return hs_a + x, s_total - hs_a - x, 0.0, 0.0, MAX_ITER, False, False


@inline_kernel
def shear_modulus_true(gamma_abs, g1, g2, gamma1, gamma2):
    """Secant modulus G(|γ|) of the trellis law (eq. 3.16 on the true angle; theory §1.6).

    Returns (G, dτ/dγ, e) with τ = G γ and e(|γ|) = ∫₀^|γ| τ dγ (J/m³): G = G1 up to γ1,
    rising linearly to G2 at γ2 (when γ2 > γ1), G2 beyond. Every branch is computed and
    one selected, so that a loop over points vectorises (``kernels.shell_blocks``).
    """
    lo = gamma_abs <= gamma1
    ramp = gamma2 > gamma1
    mid = (gamma_abs <= gamma2) & ramp
    e1 = 0.5 * g1 * gamma1 * gamma1
    m = (g2 - g1) / (gamma2 - gamma1) if ramp else 0.0
    a2, a3 = gamma_abs * gamma_abs, gamma_abs * gamma_abs * gamma_abs
    c2, c3 = gamma1 * gamma1, gamma1 * gamma1 * gamma1
    r2, r3 = gamma2 * gamma2, gamma2 * gamma2 * gamma2
    g_mid = g1 + m * (gamma_abs - gamma1)
    e_mid = e1 + 0.5 * g1 * (a2 - c2) + m * ((a3 - c3) / 3.0 - 0.5 * gamma1 * (a2 - c2))
    e2 = (e1 + 0.5 * g1 * (r2 - c2) + m * ((r3 - c3) / 3.0 - 0.5 * gamma1 * (r2 - c2))
          if ramp else e1)
    e_high = e2 + 0.5 * g2 * (a2 - r2)
    g = g1 if lo else (g_mid if mid else g2)
    g_tan = g1 if lo else (g_mid + m * gamma_abs if mid else g2)
    e = 0.5 * g1 * gamma_abs * gamma_abs if lo else (e_mid if mid else e_high)
    return g, g_tan, e


@kernel
def shear_modulus_thesis(sin_beta, g1, g2, beta1, beta2):
    """G(β) of the thesis's VUMAT, eq. (6.35)–(6.36): β from the crimp heights."""
    beta = math.asin(min(sin_beta, 1.0))
    if beta <= beta1:
        return g1
    if beta >= beta2:
        return g2
    return g1 + (g2 - g1) * (beta - beta1) / (beta2 - beta1)


@kernel
def softening_damage(strain, d_old, e_a, t_u, soft):
    """Damage after progressive failure (theory §1.4): tension falls linearly to 0 over Δε_s.

    Envelope T_env(ε) = T_u (1 − (ε − ε_u)/Δε_s) for ε ≥ ε_u = T_u/(E A);
    d = max(d_old, 1 − T_env/(E A ε)) when (1 − d_old) E A ε exceeds it.
    """
    eps_u = t_u / e_a
    if strain < eps_u:
        return d_old
    if strain >= eps_u + soft:
        return 1.0
    t_env = t_u * (1.0 - (strain - eps_u) / soft)
    if (1.0 - d_old) * e_a * strain <= t_env:
        return d_old
    return max(d_old, 1.0 - t_env / (e_a * strain))


# --- one material point --------------------------------------------------------
@kernel
def clear_eroded_point(s_out, i):
    """An eroded point (theory §1.4) carries nothing: alive 0, no tension, stress or energy
    (row i of the state table s_out)."""
    s_out[i, S_ALIVE] = 0.0
    s_out[i, S_TENSION] = 0.0
    s_out[i, S_TENSION + 1] = 0.0
    s_out[i, S_TAU] = 0.0
    s_out[i, S_ENERGY] = 0.0
    s_out[i, S_SHEAR_ENERGY] = 0.0


@inline_kernel
def yarn_constants(p, m):
    """The material's crossover constants the stages share: ℓ_w0, ℓ_f0 (half-lengths),
    h_w0, h_f0 (crimp amplitudes), L_w0, L_f0 (truss lengths), E A per family and the
    compaction law's a, b (m, m, m, N)."""
    return (p[m, P_ELL0], p[m, P_ELL0 + 1], p[m, P_H0], p[m, P_H0 + 1], p[m, P_LT0],
            p[m, P_LT0 + 1], p[m, P_E] * p[m, P_AREA], p[m, P_E + 1] * p[m, P_AREA + 1],
            p[m, P_COMP_A], p[m, P_COMP_B])


@inline_kernel
def yarn_frame(f11, f12, f21, f22):
    """Step 1 (eq. 6.5, fibre frame): the yarns' current stretches λ_w = |F e_x|,
    λ_f = |F e_y|, unit directions e_w, e_f, cos θ and sin θ of the angle between them,
    and the trellis angle γ = π/2 − θ.

    Returns (ok, λ_w, λ_f, e_wx, e_wy, e_fx, e_fy, cos θ, sin θ, γ); ok is False for a
    zero, non-finite or inverted pair of yarn directions.
    """
    lam_w, lam_f = yarn_stretches(f11, f12, f21, f22)
    if not (lam_w > 0.0 and lam_f > 0.0):  # also catches NaN
        return False, lam_w, lam_f, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    ewx, ewy, efx, efy, cos_t, sin_t = yarn_directions(f11, f21, f12, f22, lam_w, lam_f)
    if not (sin_t > 0.0) or not math.isfinite(cos_t):
        return False, lam_w, lam_f, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    return True, lam_w, lam_f, ewx, ewy, efx, efy, cos_t, sin_t, trellis_angle(sin_t, cos_t)


@inline_kernel
def yarn_stretches(f11, f12, f21, f22):
    """The yarns' current stretches λ_w = |F e_x|, λ_f = |F e_y| (fibre frame)."""
    return math.sqrt(f11 * f11 + f21 * f21), math.sqrt(f12 * f12 + f22 * f22)


@inline_kernel
def yarn_directions(gwx, gwy, gfx, gfy, lam_w, lam_f):
    """The yarns' unit directions e_w = F e_x/λ_w, e_f = F e_y/λ_f and cos θ, sin θ of the
    angle between them (eq. 6.5): (e_wx, e_wy, e_fx, e_fy, cos θ, sin θ)."""
    ewx, ewy = gwx / lam_w, gwy / lam_w
    efx, efy = gfx / lam_f, gfy / lam_f
    return ewx, ewy, efx, efy, ewx * efx + ewy * efy, ewx * efy - ewy * efx


@inline_kernel
def trellis_angle(sin_t, cos_t):
    """γ = π/2 − θ (θ in (0, π) from sin θ > 0 and cos θ; libm's atan2 to 1 ulp, and
    vectorises: kernels.vecmath)."""
    return 0.5 * math.pi - atan2_upper(sin_t, cos_t)


@inline_kernel
def virial_components(c_w, c_f, ewx, ewy, efx, efy):
    """The yarns' membrane resultant c_w e_w⊗e_w + c_f e_f⊗e_f (theory §1.5):
    (N_xx, N_yy, N_xy)."""
    return (c_w * ewx * ewx + c_f * efx * efx, c_w * ewy * ewy + c_f * efy * efy,
            c_w * ewx * ewy + c_f * efx * efy)


@inline_kernel
def shear_step_stiffness(thick, g_tan, cs):
    """The stable step's isotropic stiffness of a fabric point (theory §1.8): the shear
    tangent t dτ/dγ and the shear resultant's own (geometric) stiffness |N_s| = t|τ|/(J
    sinθ), counted twice — a shear strain takes both in-plane gradients, Σ_I |∇N_I|² =
    2/L² on a square where a yarn family's takes one, and the step pairs it with the
    element's L_e."""
    return 2.0 * (thick * g_tan + abs(cs))


@inline_kernel
def green_naghdi_stretches(fo11, fo12, fo21, fo22, f11, f12, f21, f22, lam_w_old, lam_f_old,
                           gamma_old):
    """The thesis's incremental frame (option FRAME_GREEN_NAGHDI): the yarn stretches
    and trellis angle advanced from their values at the start of the step.

    Returns (ok, λ_w, λ_f, γ); ok is False if the midpoint F or a stretch is inadmissible.
    """
    # Incremental stretches (eq. 6.13–6.16) from the midpoint strain increment
    # Δε = sym(ΔF F_mid⁻¹), and the shear increment of eq. (6.34).
    a11 = 0.5 * (fo11 + f11)
    a12 = 0.5 * (fo12 + f12)
    a21 = 0.5 * (fo21 + f21)
    a22 = 0.5 * (fo22 + f22)
    det = a11 * a22 - a12 * a21
    if not (det > 0.0):
        return False, 0.0, 0.0, 0.0
    i11, i12, i21, i22 = a22 / det, -a12 / det, -a21 / det, a11 / det
    d11 = f11 - fo11
    d12 = f12 - fo12
    d21 = f21 - fo21
    d22 = f22 - fo22
    l11 = d11 * i11 + d12 * i21
    l12 = d11 * i12 + d12 * i22
    l21 = d21 * i11 + d22 * i21
    l22 = d21 * i12 + d22 * i22
    e11, e22, e12 = l11, l22, 0.5 * (l12 + l21)
    # project on the yarn directions of the midpoint configuration, where Δε
    # lives (second-order accurate; a rigid rotation gives Δε = 0 exactly,
    # ΔF F_mid⁻¹ being the Cayley form of the rotation increment)
    nw = math.sqrt(a11 * a11 + a21 * a21)
    nf = math.sqrt(a12 * a12 + a22 * a22)
    pwx, pwy = a11 / nw, a21 / nw
    pfx, pfy = a12 / nf, a22 / nf
    de_w = pwx * pwx * e11 + 2.0 * pwx * pwy * e12 + pwy * pwy * e22
    de_f = pfx * pfx * e11 + 2.0 * pfx * pfy * e12 + pfy * pfy * e22
    if not (1.0 + 2.0 * de_w > 0.0 and 1.0 + 2.0 * de_f > 0.0):
        return False, 0.0, 0.0, 0.0
    lam_w = lam_w_old * math.sqrt(1.0 + 2.0 * de_w)
    lam_f = lam_f_old * math.sqrt(1.0 + 2.0 * de_f)
    # e_w · Δε · (e_w turned +90°) + (e_f turned −90°) · Δε · e_f  (eq. 6.34)
    nwx, nwy = -pwy, pwx
    mfx, mfy = pfy, -pfx
    dgam = (pwx * nwx * e11 + (pwx * nwy + pwy * nwx) * e12 + pwy * nwy * e22) + (
        mfx * pfx * e11 + (mfx * pfy + mfy * pfx) * e12 + mfy * pfy * e22
    )
    return True, lam_w, lam_f, gamma_old + dgam


@inline_kernel
def yarn_damage(p, m, s_in, i, strain_w, strain_f, t_w, t_f, d_w, d_f, ea_w, ea_f):
    """Step 3, the failure check, for yarn strains ε and tensions T at point i: the
    damages after it. Progressive softening (theory §1.4) of each family not yet
    broken, or eq. (6.29): a yarn breaks for good when T ≥ T_u. A broken family
    (d = 1) stays broken. T_u is the point's regularised strength s_i T_u and Δε_s its
    own softening strain (columns S_TU_SCALE, S_SOFT, set from its element's lengths;
    s = 1 and Δε_s = the material's for an unregularised point). Returns (d_w, d_f)."""
    d_w_new = d_w
    d_f_new = d_f
    tu_w = s_in[i, S_TU_SCALE] * p[m, P_TU]
    tu_f = s_in[i, S_TU_SCALE + 1] * p[m, P_TU + 1]
    if p[m, P_FAILURE] == FAILURE_PROGRESSIVE:
        if d_w < 1.0:
            d_w_new = softening_damage(strain_w, d_w, ea_w, tu_w, s_in[i, S_SOFT])
        if d_f < 1.0:
            d_f_new = softening_damage(strain_f, d_f, ea_f, tu_f, s_in[i, S_SOFT + 1])
    else:
        if d_w < 1.0 and t_w >= tu_w:
            d_w_new = 1.0
        if d_f < 1.0 and t_f >= tu_f:
            d_f_new = 1.0
    return d_w_new, d_f_new


@inline_kernel
def tabulated_crossover(p, m, lam_w, lam_f, yc):
    """Step 2′ (theory §1.9), both families intact: W, its gradient and the crimp
    heights from the C¹ interpolant of the material's table, the tensions from
    ∂W/∂λ_i = 2 T_i cos ψ_i ℓ_i0 / A0 (yc: :func:`yarn_constants`).

    Returns (inside, H_w, H_f, T_w, T_f, L_w, L_f, W, ∂W/∂λ_w, ∂W/∂λ_f); inside is
    False for stretches outside the tabulated cells (the exact solve takes over).
    """
    ell0_w, ell0_f = yc[0], yc[1]
    inside, w_tab, gw_tab, gf_tab, hw_tab, hf_tab = crossover_from_table(p, m, lam_w, lam_f)
    if not inside:
        return False, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0
    _, _, h_w, h_f, l_w, l_f, t_w, t_f = table_tensions(lam_w, lam_f, ell0_w, ell0_f, hw_tab,
                                                        hf_tab, gw_tab, gf_tab)
    return True, h_w, h_f, t_w, t_f, l_w, l_f, w_tab, gw_tab, gf_tab


@inline_kernel
def table_tensions(lam_w, lam_f, ell0_w, ell0_f, hw_tab, hf_tab, gw_tab, gf_tab):
    """The table's heights (clipped at 0), truss lengths and tensions from ∂W/∂λ_i =
    2 T_i cos ψ_i ℓ_i0 / A0 (:func:`tabulated_crossover`; the element stage in blocks
    too). Returns (ℓ_w, ℓ_f, H_w, H_f, L_w, L_f, T_w, T_f)."""
    ell_w = lam_w * ell0_w
    ell_f = lam_f * ell0_f
    area0 = 4.0 * ell0_w * ell0_f
    h_w = max(hw_tab, 0.0)
    h_f = max(hf_tab, 0.0)
    l_w = math.sqrt(ell_w * ell_w + h_w * h_w)
    l_f = math.sqrt(ell_f * ell_f + h_f * h_f)
    t_w = max(gw_tab * area0 * l_w / (2.0 * ell0_w * ell_w), 0.0)
    t_f = max(gf_tab * area0 * l_f / (2.0 * ell0_f * ell_f), 0.0)
    return ell_w, ell_f, h_w, h_f, l_w, l_f, t_w, t_f


@inline_kernel
def intact_crimp_heights(s_in, i, k_w, k_f, ell_w, ell_f, yc):
    """Step 2 with both families intact: the crimp heights and compaction force of eq.
    6.21–6.25 (yarn stiffnesses k = (1 − d) E A / L0, half-lengths ℓ; yc:
    :func:`yarn_constants`), from point i's heights and tensions at the start of the
    step.

    The yarn that is vertically stiffer (dF/dH of eq. 6.22 at the previous heights)
    carries the unknown ("a"): the other yarn's height above slack, u = D − δ − u_a, is
    then the larger one and keeps its relative accuracy. If the converged offsets say
    otherwise, the roles swap and the solve restarts from the solution (rare: cold
    starts, role changes).

    Returns (ok, iterations, H_w, H_f, compaction force).
    """
    ell0_w, ell0_f, h0_w, h0_f, lt0_w, lt0_f, ea_w, ea_f, a, b = yc
    warp_unknown = yarn_vertical_stiffness(k_w, ell_w, s_in[i, S_H], lt0_w) >= (
        yarn_vertical_stiffness(k_f, ell_f, s_in[i, S_H + 1], lt0_f)
    )
    ok = False
    iters = 0
    h_w = 0.0
    h_f = 0.0
    f_c = 0.0
    for role in range(2):
        if warp_unknown:
            k_a, ell_a, ell0_a, h0_a, lt0_a = k_w, ell_w, ell0_w, h0_w, lt0_w
            k_b, ell_b, ell0_b, h0_b, lt0_b = k_f, ell_f, ell0_f, h0_f, lt0_f
            t_prev, h_prev, h_last = s_in[i, S_TENSION], s_in[i, S_H], h_w
        else:
            k_a, ell_a, ell0_a, h0_a, lt0_a = k_f, ell_f, ell0_f, h0_f, lt0_f
            k_b, ell_b, ell0_b, h0_b, lt0_b = k_w, ell_w, ell0_w, h0_w, lt0_w
            t_prev, h_prev, h_last = s_in[i, S_TENSION + 1], s_in[i, S_H + 1], h_f
        if role == 0:
            h_guess = tension_predictor(t_prev, k_a, lt0_a, ell_a, h_prev)
        else:
            h_guess = h_last
        h_a, h_b, f_c, res, it, ok, swap = solve_crimp_heights(
            k_a, ell_a, ell0_a, h0_a, lt0_a, k_b, ell_b, ell0_b, h0_b, lt0_b, a, b,
            h_guess,
        )
        if warp_unknown:
            h_w, h_f = h_a, h_b
        else:
            h_f, h_w = h_a, h_b
        iters += it
        if not (ok and swap):
            break
        warp_unknown = not warp_unknown
    return ok, iters, h_w, h_f, f_c


@inline_kernel
def crossover_equilibrium(p, m, s_in, i, lam_w, lam_f):
    """Steps 2–3 of the module docstring for point i at the yarn stretches λ_w, λ_f:
    the crossover's crimp heights and yarn tensions, the failure check (eq. 6.29, or
    progressive softening) and one re-solve with the new damage if a yarn failed.

    From the table (:func:`tabulated_crossover`, theory §1.9) while both families are
    intact and the point lies in a tabulated cell, else by the exact solve of eq.
    6.21–6.25 (:func:`intact_crimp_heights`), a broken family's partner decrimping.

    Returns (converged, iterations, H_w, H_f, d_w, d_f, T_w, T_f, L_w − L0_w, L_f − L0_f,
    L_w, L_f, compaction force, from_table, W, ∂W/∂λ_w, ∂W/∂λ_f); the last three are the
    table's (0 when the exact solve ran).
    """
    yc = yarn_constants(p, m)
    ell0_w, ell0_f, h0_w, h0_f, lt0_w, lt0_f, ea_w, ea_f, a, b = yc
    ell_w = lam_w * ell0_w
    ell_f = lam_f * ell0_f
    d_w = s_in[i, S_DAMAGE]
    d_f = s_in[i, S_DAMAGE + 1]
    h_w = s_in[i, S_H]
    h_f = s_in[i, S_H + 1]
    if p[m, P_CROSSOVER] == CROSSOVER_TABLE and d_w == 0.0 and d_f == 0.0:
        inside, hw_t, hf_t, tw_t, tf_t, lw_t, lf_t, w_t, gw_t, gf_t = tabulated_crossover(
            p, m, lam_w, lam_f, yc)
        if inside:
            d_w_new, d_f_new = yarn_damage(p, m, s_in, i, tw_t / ea_w, tf_t / ea_f, tw_t, tf_t,
                                           d_w, d_f, ea_w, ea_f)
            if d_w_new == d_w and d_f_new == d_f:
                return (True, 0, hw_t, hf_t, d_w, d_f, tw_t, tf_t, 0.0, 0.0, lw_t, lf_t, 0.0,
                        True, w_t, gw_t, gf_t)
            # a yarn failed: the exact solve takes over with the new damage
            d_w = d_w_new
            d_f = d_f_new
            h_w = hw_t  # a broken family's height stays the table's
            h_f = hf_t
    f_c = 0.0
    t_w = 0.0
    t_f = 0.0
    ext_w = 0.0
    ext_f = 0.0
    l_w = 1.0
    l_f = 1.0
    iters = 0
    for attempt in range(2):
        k_w = (1.0 - d_w) * ea_w / lt0_w
        k_f = (1.0 - d_f) * ea_f / lt0_f
        if d_w < 1.0 and d_f < 1.0:
            ok, it, h_w, h_f, f_c = intact_crimp_heights(s_in, i, k_w, k_f, ell_w, ell_f, yc)
            iters += it
            if not ok:
                return (False, iters, h_w, h_f, d_w, d_f, t_w, t_f, ext_w, ext_f, l_w, l_f,
                        f_c, False, 0.0, 0.0, 0.0)
        elif d_w < 1.0:  # fill broken: the warp loses its support and decrimps
            h_w = min(s_in[i, S_H], slack_height(ell_w, ell0_w, h0_w))
            f_c = 0.0
        elif d_f < 1.0:  # warp broken
            h_f = min(s_in[i, S_H + 1], slack_height(ell_f, ell0_f, h0_f))
            f_c = 0.0
        ext_w, l_w = yarn_extension(ell_w, ell0_w, h_w, h0_w, lt0_w)
        ext_f, l_f = yarn_extension(ell_f, ell0_f, h_f, h0_f, lt0_f)
        t_w = k_w * max(ext_w, 0.0)
        t_f = k_f * max(ext_f, 0.0)
        if attempt == 1:
            break
        d_w_new, d_f_new = yarn_damage(p, m, s_in, i, ext_w / lt0_w, ext_f / lt0_f, t_w, t_f,
                                       d_w, d_f, ea_w, ea_f)
        if d_w_new == d_w and d_f_new == d_f:
            break
        d_w = d_w_new
        d_f = d_f_new

    return (True, iters, h_w, h_f, d_w, d_f, t_w, t_f, ext_w, ext_f, l_w, l_f, f_c,
            False, 0.0, 0.0, 0.0)


@inline_kernel
def sliver_erodes(p, m, s_in, i, d_w, d_f, lam_w, lam_f):
    """Theory §1.4: point i with a family broken erodes once it is a sliver — the broken
    family stretched beyond its limit S_ERODE_LIMIT (held by nothing across the break: the
    material's P_ERODE_STRETCH, or 1 + δ_e/h_i, an opening δ_e across an element h_i long),
    or either family crushed below P_ERODE_CRUSH (slack intact yarns, or intact yarns
    bunched with nothing holding them apart); any point, intact or not, once crushed both
    ways to λ_w λ_f below P_ERODE_INTACT (off by default); 0 disables each test."""
    lim_w = s_in[i, S_ERODE_LIMIT]
    lim_f = s_in[i, S_ERODE_LIMIT + 1]
    crush = p[m, P_ERODE_CRUSH]
    intact = p[m, P_ERODE_INTACT]
    return ((lim_w > 0.0 and d_w >= 1.0 and lam_w > lim_w)
            or (lim_f > 0.0 and d_f >= 1.0 and lam_f > lim_f)) or (
        crush > 0.0 and (d_w >= 1.0 or d_f >= 1.0) and min(lam_w, lam_f) < crush
    ) or (intact > 0.0 and lam_w * lam_f < intact)


# keeps its long signature: a stage inlined into ``fabric_point``, its arguments that loop's
# locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@inline_kernel
def yarn_resultant(p, m, use_table, lam_w, lam_f, sin_t, d_w, d_f, t_w, t_f, l_w, l_f,
                   gw_cross, gf_cross):
    """Step 4a (theory §1.5): the yarn families' membrane resultants c_w, c_f (N/m, along
    e_w ⊗ e_w and e_f ⊗ e_f) and the bound of the membrane tangent stiffness (§1.8).

    Virial N = Σ 2 T_i ℓ_i cosψ_i e_i⊗e_i / A_cell (default); from the table's
    gradient, c_i = λ_i ∂W/∂λ_i / J; or the thesis's σ = ½ Σ T_i/A_i e_i⊗e_i (eq. 6.30).

    The stiffness bound is max_i s_i with s_i the family's term (per current length);
    for the stable step each family's term also comes per *reference* width and length,
    k_i = s_i λ_j sin θ / λ_i — the membrane is total-Lagrangian, so a family's wave
    crosses the element's reference length along it at √(k_i/μ) however the element is
    crushed across it — and counts only while the family is taut or within
    SLACK_MARGIN of taut (a slack yarn has no tangent; theory §1.8).
    Returns (c_w, c_f, stiffness, k_w, k_f).
    """
    thick = p[m, P_THICK]
    ell0_w, ell0_f, _, _, lt0_w, lt0_f, ea_w, ea_f, _, _ = yarn_constants(p, m)
    ell_w = lam_w * ell0_w
    ell_f = lam_f * ell0_f
    if p[m, P_HOMOG] == HOMOG_THESIS:  # eq. (6.30), (6.38): σ = ½ Σ T_i/A_i e_i⊗e_i, × t
        c_w = 0.5 * thick * t_w / p[m, P_AREA]
        c_f = 0.5 * thick * t_f / p[m, P_AREA + 1]
        yarn_w = (1.0 - d_w) * ea_w * ell_w / lt0_w
        yarn_f = (1.0 - d_f) * ea_f * ell_f / lt0_f
        den_w = p[m, P_AREA]
        den_f = p[m, P_AREA + 1]
        scale = 0.5 * thick
    elif use_table:  # virial from the table: c_i = λ_i ∂W/∂λ_i / J, J = λ_w λ_f sinθ
        c_w, c_f, yarn_w, yarn_f, den_w, den_f = table_virial(
            gw_cross, gf_cross, lam_w, lam_f, sin_t, ell_w, ell_f, ea_w, ea_f, lt0_w, lt0_f)
        scale = 1.0
    else:  # virial: N = Σ 2 T_i ℓ_i cosψ_i e_i⊗e_i / A_cell
        a_cell = 4.0 * ell_w * ell_f * sin_t
        c_w = 2.0 * t_w * ell_w * (ell_w / l_w) / a_cell
        c_f = 2.0 * t_f * ell_f * (ell_f / l_f) / a_cell
        # ℓ_i ∂N_ii/∂ℓ_i ≤ [E A ℓ_i / L0 + T_i] / (2 ℓ_j sin θ): yarn stretch plus
        # the turning of the truss towards the plane
        yarn_w = (1.0 - d_w) * ea_w * ell_w / lt0_w
        yarn_f = (1.0 - d_f) * ea_f * ell_f / lt0_f
        den_w = 2.0 * ell_f * sin_t
        den_f = 2.0 * ell_w * sin_t
        scale = 1.0
    stiff, k_w, k_f = family_stiffness(scale, yarn_w, yarn_f, t_w, t_f, den_w, den_f, l_w,
                                       l_f, lt0_w, lt0_f, lam_w, lam_f, sin_t)
    return c_w, c_f, stiff, k_w, k_f


@inline_kernel
def table_virial(gw, gf, lam_w, lam_f, sin_t, ell_w, ell_f, ea_w, ea_f, lt0_w, lt0_f):
    """:func:`yarn_resultant`'s table branch: the families' resultants c_i = λ_i ∂W/∂λ_i / J
    from the table's gradient (∂W/∂λ_w, ∂W/∂λ_f), and their yarn stiffness terms and
    denominators for :func:`family_stiffness`. Returns (c_w, c_f, yarn_w, yarn_f, den_w,
    den_f)."""
    c_w = gw / (lam_f * sin_t)
    c_f = gf / (lam_w * sin_t)
    yarn_w = ea_w * ell_w / lt0_w
    yarn_f = ea_f * ell_f / lt0_f
    den_w = 2.0 * ell_f * sin_t
    den_f = 2.0 * ell_w * sin_t
    return c_w, c_f, yarn_w, yarn_f, den_w, den_f


# keeps its long signature: a stage inlined into ``crossover_points`` and ``yarn_resultant``, its
# arguments that loop's locals (a bundle written through in a parallel loop's body can lose its
# writes: kernels/bundles.py)
@inline_kernel
def family_stiffness(scale, yarn_w, yarn_f, t_w, t_f, den_w, den_f, l_w, l_f, lt0_w, lt0_f,
                     lam_w, lam_f, sin_t):
    """:func:`yarn_resultant`'s stiffnesses from each family's yarn term and its
    denominator: the membrane tangent bound and k_w, k_f per reference width and length
    (a family slack by more than SLACK_MARGIN keeps its tension term alone)."""
    stiff = scale * max((yarn_w + t_w) / den_w, (yarn_f + t_f) / den_f)
    taut_w = 1.0 if l_w >= (1.0 - SLACK_MARGIN) * lt0_w else 0.0
    taut_f = 1.0 if l_f >= (1.0 - SLACK_MARGIN) * lt0_f else 0.0
    k_w = scale * (taut_w * yarn_w + t_w) / den_w * (lam_f * sin_t / lam_w)
    k_f = scale * (taut_f * yarn_f + t_f) / den_f * (lam_w * sin_t / lam_f)
    return stiff, k_w, k_f


# keeps its long signature: a stage inlined into ``crossover_points`` and ``fabric_point``, its
# arguments that loop's locals (a bundle written through in a parallel loop's body can lose its
# writes: kernels/bundles.py)
@inline_kernel
def shear_resultant(n_xx, n_yy, n_xy, thick, tau, lam_w, lam_f, ewx, ewy, efx, efy, cos_t,
                    sin_t):
    """Step 4b's resultant: the trellis shear stress τ added to the yarns' N through its
    work conjugate (theory §1.6), c_s = t τ / (J sin θ), J = λ_w λ_f sin θ. Returns
    (N_xx, N_yy, N_xy, c_s)."""
    jac = lam_w * lam_f * sin_t
    cs = thick * tau / (jac * sin_t)
    n_xx += cs * (2.0 * ewx * efx - cos_t * (ewx * ewx + efx * efx))
    n_yy += cs * (2.0 * ewy * efy - cos_t * (ewy * ewy + efy * efy))
    n_xy += cs * (ewx * efy + ewy * efx - cos_t * (ewx * ewy + efx * efy))
    return n_xx, n_yy, n_xy, cs


@inline_kernel
def trellis_shear(p, m, s_in, i, gamma, dgamma, h_w, h_f, lam_w, lam_f):
    """Step 4b (theory §1.6): the trellis shear stress τ(γ), its tangent and the shear
    energy per unit reference area — the true law G(γ) with locking (default), or the
    thesis's G(β) integrated incrementally (eq. 6.35–6.37).

    Returns (τ, tangent modulus, shear energy).
    """
    thick = p[m, P_THICK]
    ell_w = lam_w * p[m, P_ELL0]
    ell_f = lam_f * p[m, P_ELL0 + 1]
    if p[m, P_SHEAR] == SHEAR_THESIS:  # eq. (6.35)–(6.37): G(β), τ integrated incrementally
        sin_beta = 0.5 * (h_w / ell_w + h_f / ell_f)
        g = shear_modulus_thesis(sin_beta, p[m, P_G1], p[m, P_G2], p[m, P_BETA1], p[m, P_BETA2])
        tau = s_in[i, S_TAU] + g * dgamma
        g_tan = g
        e_shear = s_in[i, S_SHEAR_ENERGY] + thick * 0.5 * (s_in[i, S_TAU] + tau) * dgamma
    else:
        g, g_tan, e_dens = shear_modulus_true(
            abs(gamma), p[m, P_G1], p[m, P_G2], p[m, P_GAMMA1], p[m, P_GAMMA2]
        )
        tau = g * gamma
        e_shear = thick * e_dens
    return tau, g_tan, e_shear


@inline_kernel
def stored_energy(p, m, use_table, w_cross, e_shear, d_w, d_f, ext_w, ext_f, h_w, h_f, f_c):
    """Step 5: stored energy per unit reference area — two half trusses per family, the
    compaction spring and the shear energy (the table's W in place of the first two)."""
    if use_table:
        return w_cross + e_shear
    ell0_w, ell0_f, h0_w, h0_f, lt0_w, lt0_f, ea_w, ea_f, a, b = yarn_constants(p, m)
    k_w = (1.0 - d_w) * ea_w / lt0_w
    k_f = (1.0 - d_f) * ea_f / lt0_f
    u_yarn = k_w * max(ext_w, 0.0) ** 2 + k_f * max(ext_f, 0.0) ** 2
    delta = h0_w + h0_f - h_w - h_f if f_c > 0.0 else 0.0
    return (u_yarn + compaction_energy(delta, a, b)) / (4.0 * ell0_w * ell0_f) + e_shear


# keeps its long signature: a stage called in the loop of ``exact_points`` and
# ``fabric_update_for_points`` and ``fabric_update_point`` and ``point_response``, its arguments
# that loop's locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@kernel
def fabric_point(p, m, fo11, fo12, fo21, fo22, f11, f12, f21, f22, s_in, s_out, i):
    """Update crossover material point i from F_old to F_new (the module's steps 1–5).

    The core of :func:`fabric_update_point`, for loop kernels: whole tables and row
    indices instead of per-point views, F as scalars and N returned, so that a call
    costs no array views or reference counting.

    Args:
        p, m: parameter table (n_materials, N_PARAM) and the material's row.
        fo11, fo12, fo21, fo22: F_old (row-major); f11, f12, f21, f22: F_new.
        s_in, s_out: state tables (n, N_STATE): row i at the start of the step, and
            row i at the end (written; the tables may not alias). Pass the rows m and
            i as unsigned integers (np.uint64) in loops: signed indices cost a
            negative-index check at every access.

    Returns:
        (status, stiffness, N_xx, N_yy, N_xy, k_shear, k_w, k_f): a STATUS_* code, an
        upper bound of the membrane tangent stiffness dN/dε (N/m; the hourglass
        stiffness of a reduced membrane scales with it), the membrane resultant in N/m
        (0 unless the status is OK), and the stable step's stiffnesses (theory §1.8):
        the trellis shear's t dτ/dγ, and each yarn family's per reference width and
        length, zero while it is slack (:func:`yarn_resultant`).
    """
    for j in range(N_STATE):
        s_out[i, j] = s_in[i, j]
    thick = p[m, P_THICK]

    # 1. kinematics: current yarn directions and angle (eq. 6.5, fibre frame), or the
    # thesis's incremental stretches (eq. 6.13–6.16)
    ok, lam_w, lam_f, ewx, ewy, efx, efy, cos_t, sin_t, gamma = yarn_frame(f11, f12, f21, f22)
    if not ok:
        return STATUS_BAD_KINEMATICS, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if p[m, P_FRAME] == FRAME_GREEN_NAGHDI:
        ok, lam_w, lam_f, gamma = green_naghdi_stretches(
            fo11, fo12, fo21, fo22, f11, f12, f21, f22, s_in[i, S_LAMBDA],
            s_in[i, S_LAMBDA + 1], s_in[i, S_GAMMA])
        if not ok:
            return STATUS_BAD_KINEMATICS, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    dgamma = gamma - s_in[i, S_GAMMA]
    s_out[i, S_LAMBDA] = lam_w
    s_out[i, S_LAMBDA + 1] = lam_f
    s_out[i, S_GAMMA] = gamma

    if s_in[i, S_ALIVE] == 0.0:
        clear_eroded_point(s_out, i)
        return STATUS_OK, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0

    # 2–3. crossover solve, failure check, and one re-solve if a yarn failed
    (ok, iters, h_w, h_f, d_w, d_f, t_w, t_f, ext_w, ext_f, l_w, l_f, f_c, use_table,
     w_cross, gw_cross, gf_cross) = crossover_equilibrium(p, m, s_in, i, lam_w, lam_f)
    s_out[i, S_ITER] = iters
    if not ok:
        return STATUS_NOT_CONVERGED, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    s_out[i, S_H] = h_w
    s_out[i, S_H + 1] = h_f
    s_out[i, S_DAMAGE] = d_w
    s_out[i, S_DAMAGE + 1] = d_f
    s_out[i, S_TENSION] = t_w
    s_out[i, S_TENSION + 1] = t_f
    # eroded (theory §1.4): both families broken, or one broken and the point a sliver
    if sliver_erodes(p, m, s_in, i, d_w, d_f, lam_w, lam_f):
        d_w = 1.0
        d_f = 1.0
        s_out[i, S_DAMAGE] = 1.0
        s_out[i, S_DAMAGE + 1] = 1.0
    if d_w >= 1.0 and d_f >= 1.0:
        clear_eroded_point(s_out, i)
        return STATUS_OK, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0

    # 4a. yarn membrane resultant (theory §1.5), with the extensions L − L0 and
    # lengths L of the final heights from the solve above
    c_w, c_f, stiff, k_w, k_f = yarn_resultant(p, m, use_table, lam_w, lam_f, sin_t, d_w, d_f,
                                               t_w, t_f, l_w, l_f, gw_cross, gf_cross)
    n_xx, n_yy, n_xy = virial_components(c_w, c_f, ewx, ewy, efx, efy)

    # 4b. trellis shear (theory §1.6): τ(γ), applied through its work conjugate
    tau, g_tan, e_shear = trellis_shear(p, m, s_in, i, gamma, dgamma, h_w, h_f, lam_w, lam_f)
    s_out[i, S_TAU] = tau
    s_out[i, S_SHEAR_ENERGY] = e_shear
    n_xx, n_yy, n_xy, cs = shear_resultant(n_xx, n_yy, n_xy, thick, tau, lam_w, lam_f, ewx,
                                           ewy, efx, efy, cos_t, sin_t)
    k_shear = shear_step_stiffness(thick, g_tan, cs)
    stiff += thick * g_tan

    # 5. stored energy per unit reference area
    s_out[i, S_ENERGY] = stored_energy(p, m, use_table, w_cross, e_shear, d_w, d_f, ext_w,
                                       ext_f, h_w, h_f, f_c)
    return STATUS_OK, stiff, n_xx, n_yy, n_xy, k_shear, k_w, k_f


@kernel
def fabric_update_point(p, f_old, f_new, s_in, s_out, n_out):
    """Update one crossover material point from F_old to F_new (single-point callers).

    Args:
        p: (N_PARAM,) parameters (layout in fabric_layout).
        f_old, f_new: (2, 2) deformation gradients at the start and end of the step.
        s_in: (N_STATE,) state at the start of the step.
        s_out: (N_STATE,) state at the end (written; may not alias s_in).
        n_out: (3,) membrane resultant (N_xx, N_yy, N_xy) in N/m (written).

    Returns:
        (status, stiffness): a STATUS_* code and an upper bound of the membrane
        tangent stiffness dN/dε (N/m) for the stable time step (theory §1.8).

    A thin wrapper of :func:`fabric_point` (which loop kernels call directly).
    """
    # views, not copies: a kernel allocates nothing (jit.kernel), and the parameter row
    # may carry a 1.6 MB table
    p_table = p.reshape((1, p.shape[0]))
    row_in = s_in.reshape((1, s_in.shape[0]))
    row_out = s_out.reshape((1, s_out.shape[0]))
    status, stiff, n_xx, n_yy, n_xy, _, _, _ = fabric_point(
        p_table, 0, f_old[0, 0], f_old[0, 1], f_old[1, 0], f_old[1, 1],
        f_new[0, 0], f_new[0, 1], f_new[1, 0], f_new[1, 1], row_in, row_out, 0,
    )
    n_out[0] = n_xx
    n_out[1] = n_yy
    n_out[2] = n_xy
    return status, stiff


# --- many points ----------------------------------------------------------------
@loop_kernel
def fabric_update_for_points(p, f_old, f_new, state_in, state_out, n_out, stiff_out, status_out):
    """Run :func:`fabric_point` on every point (independent, ``prange``).

    Args:
        p: (N_PARAM,) parameters shared by all points.
        f_old, f_new: (n, 2, 2) deformation gradients.
        state_in: (n, N_STATE) states at the start of the step.
        state_out: (n, N_STATE) states at the end (written).
        n_out: (n, 3) membrane resultants (written).
        stiff_out: (n,) tangent stiffness bounds (written).
        status_out: (n,) int32 status codes (written).
    """
    p_table = p.reshape((1, p.shape[0]))  # a view: the row may carry a 1.6 MB table
    for i in prange(f_new.shape[0]):
        status, stiff, n_xx, n_yy, n_xy, _, _, _ = fabric_point(
            p_table, 0, f_old[i, 0, 0], f_old[i, 0, 1], f_old[i, 1, 0], f_old[i, 1, 1],
            f_new[i, 0, 0], f_new[i, 0, 1], f_new[i, 1, 0], f_new[i, 1, 1],
            state_in, state_out, np.uint64(i),
        )
        n_out[i, 0] = n_xx
        n_out[i, 1] = n_yy
        n_out[i, 2] = n_xy
        status_out[i] = status
        stiff_out[i] = stiff
