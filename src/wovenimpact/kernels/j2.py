"""Plane-stress J2 plasticity of a metal shell point: one material-point update.

docs/theory.md "Metal shells (kernels/j2.py)" states the model and numbers the
equations (J1)–(J14) cited below; docs/model.md §5 and thesis 8.2.3 / 8.3.1 are its
source. Per point, given the in-plane deformation gradients F_old, F_new (2×2,
reference material frame → current corotational frame) and the step Δt, the kernel

1. kinematics in the Green–Naghdi rotated frame (J1–J2): F = R U (closed-form 2×2
   polar decomposition); strain increment Δd = sym(ΔU U_mid⁻¹), U_mid = ½(U_old + U_new),
   which is Rᵀ D R Δt at the midpoint — the rotated rate of deformation — and
   depends on U alone, so any superposed rotation history Q(t) F(t) leaves it
   unchanged to round-off;
2. elastic predictor on the rotated Kirchhoff stress τ = J σ (J = det F · λ3 the
   volume ratio): τ_trial = τ_old + C Δd, C the plane-stress elastic matrix (J3);
3. plane-stress return (Simo & Taylor 1986, doi:10.1002/nme.1620220310): in the
   eigenbasis shared by C and the projection P of the plane-stress von Mises
   norm, τ(Δγ) is explicit (J5) and the consistency condition is one scalar
   equation g(Δγ) = σ_eq(Δγ) − σ_y(ε̄p + Δε̄p(Δγ), Δε̄p/Δt) = 0 (J6–J8), strictly
   decreasing with a known bracket, solved by Newton safeguarded by bisection
   to |g| ≤ RETURN_TOL σ_y (status STATUS_NOT_CONVERGED if it ends above
   RETURN_TOL_FAIL σ_y, which bisection on a bracket does not allow in practice);
   σ_y is the piecewise-linear table (flat beyond its last row) times the
   optional Johnson–Cook rate factor 1 + C ln(ε̇p/ε̇0) for ε̇p > ε̇0 (J9);
4. thickness stretch λ3 from plastic incompressibility plus the elastic
   plane-stress ε33 (J10); energies per unit reference area: elastic stored
   W_e = t0 ½ τ·C⁻¹τ and plastic work ΔW_p = t0 ½(τ_old + τ_new)·Δε_p (J11),
   so that W_e + W_p grows by exactly t0 ½(τ_old + τ_new)·Δd, the work of the
   step (to round-off);
5. failure (J12–J13): ε̄p ≥ ε_f (the thesis's constant fracture strain) or the
   Johnson–Cook damage D = Σ Δε̄p / ε_f(η, ε̇*) ≥ 1; a failed point carries no
   stress from then on and its alive flag is 0 for good. With a hinge ratio
   (J17, :func:`fold_amplification`) each step's Δε̄p counts amp ≥ 1 times.

What the caller (the shell section) must do
-------------------------------------------
- Call ``j2_point(p, m, F_old, F_new, Δt, t0, s_in, s_out, i)`` with F of the
  point (for a through-thickness point, F_k = (I + z_k κ̂) F) and t0 the section's
  REFERENCE thickness; Δt the step the increment F_old → F_new happens over (rate
  terms; 0 is allowed and switches them off for the call).
- The returned N (N/m) is the Cauchy resultant σ t of the whole section at that
  point, per unit CURRENT length, in the corotational frame — the fabric's
  convention; weight it like fabric_point's N (N = Σ w_k N_k, M = Σ w_k z_k N_k).
  The first Piola resultant the shell uses is then P = J N F⁻ᵀ = t0 τ F⁻ᵀ.
- Energy balance per point (J/m² of reference area, multiply by A0 and weights):
  internal energy = s_out[i, S_ENERGY] (elastic, stored, recoverable)
  + s_out[i, S_PLASTIC_WORK] (dissipated, cumulative)
  + s_out[i, S_FAIL_ENERGY] (elastic energy released when the point failed: book
  it as eroded/failure energy). The three together grow by the step's work.
- Current thickness of the point t = t0 · s_out[i, S_THICK]; of an integrated section
  t0 Σ_k w_k λ3,k with the through-thickness weights (contact offsets, output).
- The parameter table may be wider than N_PARAM and hold other kinds' rows: only the
  columns of j2_layout in row m are read.
- A status other than STATUS_OK (j2_layout: inverted or non-finite F, a return that did
  not converge) leaves s_out[i] partly written and N = 0: treat it as fabric_point's
  (the element reports EL_MATERIAL). A failed point is STATUS_OK with N = 0.
- Erosion: s_out[i, S_ALIVE] == 0 for a failed point; the element erodes when all
  (or a configured count of) its points have S_ALIVE 0.
- Stable step: the returned stiffness E t0 max(1, J)/(1 − ν²) bounds the membrane
  tangent per unit current length times J (J = det F λ3), i.e. the plate wave
  speed √(stiffness/μ) with μ the mass per REFERENCE area, as the shell uses it.

Everything is a pure function of flat arrays; ``j2_point`` handles one point
(tables and row index, no views, no allocation) and ``j2_update_for_points``
loops over many in parallel (each point independent, so results are bitwise
identical for any thread count).
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from wovenimpact.jit import kernel, loop_kernel
from wovenimpact.kernels.j2_layout import (
    N_STATE,
    P_D,
    P_DAMAGE,
    P_DAMAGE_REF,
    P_FRACTURE,
    P_HARD,
    P_N_HARD,
    P_NU,
    P_RATE_C,
    P_RATE_REF,
    P_YOUNG,
    S_ALIVE,
    S_ENERGY,
    S_EPS_P,
    S_EVOLUTION,
    S_FAIL_ENERGY,
    S_FRAC_SCALE,
    S_HINGE,
    S_JC_DAMAGE,
    S_KIRCHHOFF,
    S_PLASTIC_WORK,
    S_RATE,
    S_RETURN_ITER,
    S_SIG,
    S_SOFT_DAMAGE,
    S_THICK,
    S_YIELD,
    STATUS_BAD_KINEMATICS,
    STATUS_NOT_CONVERGED,
    STATUS_OK,
)

MAX_ITER = 200  # bisection alone shrinks the bracket to round-off in < 64 steps
RETURN_TOL = 1e-13  # converged when |σ_eq − σ_y| ≤ RETURN_TOL σ_y
RETURN_TOL_FAIL = 1e-10  # a return that ends above this is reported, never used
EPS = 2.220446049250313e-16  # machine epsilon of float64


# --- kinematics ------------------------------------------------------------------
@kernel
def polar_rotation(f11, f12, f21, f22):
    """cos θ, sin θ of R in F = R U (2×2, det F > 0), eq. (J1).

    tan θ = (F21 − F12)/(F11 + F22): for F = R U, F11 + F22 = cos θ tr U and
    F21 − F12 = sin θ tr U with tr U > 0.
    """
    a = f11 + f22
    b = f21 - f12
    r = math.sqrt(a * a + b * b)
    return a / r, b / r


@kernel
def right_stretch(f11, f12, f21, f22, c, s):
    """U = Rᵀ F (symmetric part; the skew part is round-off): (U11, U22, U12)."""
    u11 = c * f11 + s * f21
    u22 = -s * f12 + c * f22
    u12 = 0.5 * ((c * f12 + s * f22) + (-s * f11 + c * f21))
    return u11, u22, u12


@kernel
def rotated_increment(uo11, uo22, uo12, un11, un22, un12):
    """Δd = sym(ΔU U_mid⁻¹), U_mid = ½(U_old + U_new), eq. (J2).

    Returns (Δd11, Δd22, Δγ12) with Δγ12 = 2 Δd12 (engineering shear), and det U_mid.
    """
    m11 = 0.5 * (uo11 + un11)
    m22 = 0.5 * (uo22 + un22)
    m12 = 0.5 * (uo12 + un12)
    det = m11 * m22 - m12 * m12
    d11 = un11 - uo11
    d22 = un22 - uo22
    d12 = un12 - uo12
    l11 = (d11 * m22 - d12 * m12) / det
    l12 = (-d11 * m12 + d12 * m11) / det
    l21 = (d12 * m22 - d22 * m12) / det
    l22 = (-d12 * m12 + d22 * m11) / det
    return l11, l22, l12 + l21, det


@kernel
def rotate_to_corotational(t11, t22, t12, c, s):
    """R t Rᵀ for a symmetric 2×2 tensor (t11, t22, t12) in the rotated frame."""
    cc = c * c
    ss = s * s
    cs = c * s
    return (
        cc * t11 - 2.0 * cs * t12 + ss * t22,
        ss * t11 + 2.0 * cs * t12 + cc * t22,
        cs * (t11 - t22) + (cc - ss) * t12,
    )


# --- material functions ----------------------------------------------------------
@kernel
def hardening(p, m, eps_p):
    """Table flow stress σ_h(ε̄p) and slope H = dσ_h/dε̄p, piecewise linear, flat
    beyond the last row (J9). Binary search over the rows."""
    n = int(p[m, P_N_HARD])
    last = n - 1
    if n == 1 or eps_p >= p[m, P_HARD + 2 * last]:
        return p[m, P_HARD + 2 * last + 1], 0.0
    lo = 0
    hi = last  # invariant: ε_lo ≤ ε̄p < ε_hi
    while hi - lo > 1:
        mid = (lo + hi) // 2
        if p[m, P_HARD + 2 * mid] <= eps_p:
            lo = mid
        else:
            hi = mid
    e0 = p[m, P_HARD + 2 * lo]
    s0 = p[m, P_HARD + 2 * lo + 1]
    e1 = p[m, P_HARD + 2 * hi]
    s1 = p[m, P_HARD + 2 * hi + 1]
    slope = (s1 - s0) / (e1 - e0)
    return s0 + slope * (max(eps_p, e0) - e0), slope


@kernel
def rate_factor(p, m, deps, dt):
    """Johnson–Cook rate factor R = 1 + C ln(ε̇p/ε̇0) for ε̇p = Δε̄p/Δt > ε̇0, else 1,
    and dR/dΔε̄p (J9). Off (R = 1) without a reference rate or with Δt ≤ 0."""
    ref = p[m, P_RATE_REF]
    if ref <= 0.0 or dt <= 0.0:
        return 1.0, 0.0
    rate = deps / dt
    if not rate > ref:
        return 1.0, 0.0
    c = p[m, P_RATE_C]
    return 1.0 + c * math.log(rate / ref), c / deps


@kernel
def flow_stress(p, m, eps_p_old, deps, dt):
    """σ_y = σ_h(ε̄p_old + Δε̄p) R(Δε̄p/Δt) and dσ_y/dΔε̄p (J9)."""
    sig_h, slope = hardening(p, m, eps_p_old + deps)
    r, dr = rate_factor(p, m, deps, dt)
    return sig_h * r, slope * r + sig_h * dr


@kernel
def fracture_strain_jc(p, m, eta, rate):
    """Johnson–Cook fracture strain ε_f = (D1 + D2 exp(D3 η))(1 + D4 ln ε̇*), ε̇* =
    max(ε̇p/ε̇0, 1); the temperature factor (1 + D5 T*) is 1 (T* = 0, isothermal) (J13)."""
    ef = p[m, P_D] + p[m, P_D + 1] * math.exp(p[m, P_D + 2] * eta)
    ref = p[m, P_DAMAGE_REF]
    if ref > 0.0 and rate > ref:
        ef *= 1.0 + p[m, P_D + 3] * math.log(rate / ref)
    return ef


# --- the plane-stress return -----------------------------------------------------
@kernel
def equivalent_stress(a_sq, b_sq, a, b, dgam):
    """σ_eq(Δγ) and dσ_eq/dΔγ of the returned stress (J6): σ_eq² = A/(1 + aΔγ)² +
    B/(1 + bΔγ)², A = ¼(τ11 + τ22)²_trial, B = 3(¼(τ11 − τ22)² + τ12²)_trial."""
    xa = 1.0 / (1.0 + a * dgam)
    xb = 1.0 / (1.0 + b * dgam)
    q = a_sq * xa * xa + b_sq * xb * xb
    seq = math.sqrt(q)
    dq = -2.0 * (a * a_sq * xa * xa * xa + b * b_sq * xb * xb * xb)
    dseq = 0.5 * dq / seq if seq > 0.0 else 0.0
    return seq, dseq


@kernel
def plane_stress_return(p, m, e_mod, nu, tt11, tt22, tt12, eps_p_old, dt):
    """Simo–Taylor consistent plane-stress return of the trial stress (J4–J8).

    Args:
        p, m: parameter table and material row.
        e_mod, nu: E, ν.
        tt11, tt22, tt12: trial rotated Kirchhoff stress (Pa), beyond the yield surface.
        eps_p_old: ε̄p at the start of the step; dt: the step (rate factor).

    Returns:
        (τ11, τ22, τ12, Δγ, Δε̄p, σ_y, iterations, |g|/σ_y): the stress on the
        yield surface, the plastic multiplier, the equivalent plastic strain
        increment Δε̄p = ⅔ Δγ σ_eq, the flow stress, and the final residual.
    """
    a = e_mod / (3.0 * (1.0 - nu))  # eigenvalue of C P on (1, 1, 0)
    b = e_mod / (1.0 + nu)  # on (1, −1, 0) and (0, 0, 1): 2G
    s_tr = tt11 + tt22
    d_tr = tt11 - tt22
    a_sq = 0.25 * s_tr * s_tr
    b_sq = 3.0 * (0.25 * d_tr * d_tr + tt12 * tt12)
    seq_tr = math.sqrt(a_sq + b_sq)
    sig_y0, _ = flow_stress(p, m, eps_p_old, 0.0, dt)
    lo = 0.0
    hi = (seq_tr / sig_y0 - 1.0) / min(a, b)  # σ_eq(hi) ≤ σ_y(ε̄p_old) ≤ σ_y: g(hi) ≤ 0
    x = 0.0
    it = 0
    deps = 0.0
    sig_y = sig_y0
    res = math.inf
    for it in range(1, MAX_ITER + 1):
        seq, dseq = equivalent_stress(a_sq, b_sq, a, b, x)
        deps = 2.0 / 3.0 * x * seq
        sig_y, dsig = flow_stress(p, m, eps_p_old, deps, dt)
        g = seq - sig_y
        res = abs(g) / sig_y
        if res <= RETURN_TOL or it == MAX_ITER:
            break
        if g > 0.0:
            lo = x
        else:
            hi = x
        if hi - lo <= 4.0 * EPS * hi:
            break  # the bracket is two floats wide: x is as good as it gets
        dg = dseq - dsig * 2.0 / 3.0 * (seq + x * dseq)
        x_new = x - g / dg if dg < 0.0 else 0.5 * (lo + hi)
        if not (lo < x_new < hi):
            x_new = 0.5 * (lo + hi)  # Newton left the bracket: bisect
        x = x_new
    s = s_tr / (1.0 + a * x)
    d = d_tr / (1.0 + b * x)
    t12 = tt12 / (1.0 + b * x)
    return 0.5 * (s + d), 0.5 * (s - d), t12, x, deps, sig_y, it, res


@kernel
def elastic_energy(t11, t22, t12, e_mod, nu, thick):
    """W_e = t0 ½ τ·C⁻¹τ per unit reference area (J11), plane stress."""
    return 0.5 * thick / e_mod * (
        t11 * t11 + t22 * t22 - 2.0 * nu * t11 * t22 + 2.0 * (1.0 + nu) * t12 * t12
    )


@kernel
def clear_failed_point(s_out, i):
    """A failed point carries nothing: alive 0, no stress, no stored energy (row i)."""
    s_out[i, S_ALIVE] = 0.0
    for j in range(3):
        s_out[i, S_SIG + j] = 0.0
        s_out[i, S_KIRCHHOFF + j] = 0.0
    s_out[i, S_ENERGY] = 0.0


# --- one material point ------------------------------------------------------------
# keeps its long signature: a stage called in the loop of ``j2_update_for_points`` and
# ``point_response``, its arguments that loop's locals (a bundle written through in a parallel
# loop's body can lose its writes: kernels/bundles.py)
@kernel
def j2_point(p, m, fo11, fo12, fo21, fo22, f11, f12, f21, f22, dt, thick, s_in, s_out, i,
             amp=1.0):
    """Update J2 material point i from F_old to F_new over Δt (the module's steps 1–5).

    Args:
        p, m: parameter table (n_materials, N_PARAM) and the material's row.
        fo11, fo12, fo21, fo22: F_old (row-major); f11, f12, f21, f22: F_new; both map
            the reference material frame to the current corotational frame.
        dt: Δt of the increment (1/s rates); ≤ 0 switches the rate terms off.
        thick: t0, the section's reference thickness (m).
        s_in, s_out: state tables (n, N_STATE): row i at the start of the step, and
            row i at the end (written; the tables may not alias). Pass m and i as
            unsigned integers (np.uint64) in loops.
        amp: the factor ≥ 1 on the step's Δε̄p when fracture is judged (J17: the
            section's fold amplification, :func:`fold_amplification`); 1 for a point
            with no hinge ratio (S_HINGE = 1), which is then judged as before.

    Returns:
        (status, stiffness, N_xx, N_yy, N_xy): a STATUS_* code, an upper bound
        E t0 max(1, J)/(1 − ν²) of the membrane tangent (N/m) for the stable step,
        and the Cauchy resultant σ t of the whole section in N per unit current
        length, corotational frame (0 unless the status is OK and the point alive).
    """
    for j in range(N_STATE):
        s_out[i, j] = s_in[i, j]
    e_mod = p[m, P_YOUNG]
    nu = p[m, P_NU]
    det_o = fo11 * fo22 - fo12 * fo21
    det_n = f11 * f22 - f12 * f21
    if not (det_o > 0.0 and det_n > 0.0) or not math.isfinite(det_o + det_n + dt):
        return STATUS_BAD_KINEMATICS, 0.0, 0.0, 0.0, 0.0
    stiff = e_mod * thick / (1.0 - nu * nu)
    if s_in[i, S_ALIVE] == 0.0:
        clear_failed_point(s_out, i)
        s_out[i, S_RATE] = 0.0
        s_out[i, S_RETURN_ITER] = 0.0
        return STATUS_OK, 0.0, 0.0, 0.0, 0.0

    # 1. kinematics (J1–J2)
    co, so = polar_rotation(fo11, fo12, fo21, fo22)
    cn, sn = polar_rotation(f11, f12, f21, f22)
    uo11, uo22, uo12 = right_stretch(fo11, fo12, fo21, fo22, co, so)
    un11, un22, un12 = right_stretch(f11, f12, f21, f22, cn, sn)
    dd11, dd22, dg12, det_mid = rotated_increment(uo11, uo22, uo12, un11, un22, un12)
    if not (det_mid > 0.0):
        return STATUS_BAD_KINEMATICS, 0.0, 0.0, 0.0, 0.0

    # 2. elastic predictor (J3)
    to11 = s_in[i, S_KIRCHHOFF]
    to22 = s_in[i, S_KIRCHHOFF + 1]
    to12 = s_in[i, S_KIRCHHOFF + 2]
    c = e_mod / (1.0 - nu * nu)
    g_mod = 0.5 * e_mod / (1.0 + nu)
    tt11 = to11 + c * (dd11 + nu * dd22)
    tt22 = to22 + c * (dd22 + nu * dd11)
    tt12 = to12 + g_mod * dg12
    eps_p = s_in[i, S_EPS_P]
    seq_tr = math.sqrt(tt11 * tt11 - tt11 * tt22 + tt22 * tt22 + 3.0 * tt12 * tt12)
    sig_y, _ = flow_stress(p, m, eps_p, 0.0, dt)

    # 3. plastic corrector (J4–J9)
    dgam = 0.0
    deps = 0.0
    iters = 0
    if seq_tr > sig_y:
        t11, t22, t12, dgam, deps, sig_y, iters, res = plane_stress_return(
            p, m, e_mod, nu, tt11, tt22, tt12, eps_p, dt
        )
        s_out[i, S_RETURN_ITER] = iters
        if not (res <= RETURN_TOL_FAIL):
            return STATUS_NOT_CONVERGED, 0.0, 0.0, 0.0, 0.0
    else:
        t11, t22, t12 = tt11, tt22, tt12
        s_out[i, S_RETURN_ITER] = 0.0

    # 4. plastic strain increment (J7), thickness (J10), energies (J11)
    dep11 = dgam * (2.0 * t11 - t22) / 3.0
    dep22 = dgam * (2.0 * t22 - t11) / 3.0
    dgp12 = 2.0 * dgam * t12
    dep33 = -dgam * (t11 + t22) / 3.0
    de33 = -nu / e_mod * (t11 + t22 - to11 - to22) + dep33
    lam3 = s_in[i, S_THICK] * math.exp(de33)
    w_p = 0.5 * thick * ((to11 + t11) * dep11 + (to22 + t22) * dep22 + (to12 + t12) * dgp12)
    s_out[i, S_PLASTIC_WORK] = s_in[i, S_PLASTIC_WORK] + w_p
    w_e = elastic_energy(t11, t22, t12, e_mod, nu, thick)
    s_out[i, S_ENERGY] = w_e
    s_out[i, S_THICK] = lam3
    eps_p_new = eps_p + deps
    s_out[i, S_EPS_P] = eps_p_new
    rate = deps / dt if dt > 0.0 else 0.0
    s_out[i, S_RATE] = rate
    s_out[i, S_YIELD] = sig_y if deps > 0.0 else hardening(p, m, eps_p_new)[0]
    jac = det_n * lam3  # volume ratio J (J10)
    s_out[i, S_KIRCHHOFF] = t11
    s_out[i, S_KIRCHHOFF + 1] = t22
    s_out[i, S_KIRCHHOFF + 2] = t12
    s_out[i, S_SIG] = t11 / jac
    s_out[i, S_SIG + 1] = t22 / jac
    s_out[i, S_SIG + 2] = t12 / jac

    # 5. damage and failure (J12–J13) at the point's regularised fracture strain s ε_f,
    # then the softening after onset (J15–J16)
    onset = False
    after = 0.0  # the part of Δε̄p past the onset of failure
    if deps > 0.0:
        s_frac = s_in[i, S_FRAC_SCALE]
        counted = deps * amp  # (J17): Δε̄p as fracture counts it
        if p[m, P_DAMAGE] != 0.0:
            seq = math.sqrt(t11 * t11 - t11 * t22 + t22 * t22 + 3.0 * t12 * t12)
            eta = (t11 + t22) / (3.0 * seq) if seq > 0.0 else 0.0
            ef = s_frac * fracture_strain_jc(p, m, eta, rate)
            d_old = s_in[i, S_JC_DAMAGE]
            dmg = d_old + counted / ef if ef > 0.0 else 1.0
            s_out[i, S_JC_DAMAGE] = dmg
            if dmg >= 1.0:
                onset = True
                after = deps if d_old >= 1.0 else deps * (dmg - 1.0) / (dmg - d_old)
        ef_const = s_frac * p[m, P_FRACTURE]
        if ef_const > 0.0 and s_in[i, S_HINGE] > 1.0:
            # (J17) with a constant ε_f (no Johnson–Cook damage: the material file refuses
            # both with a hinge ratio): D = Σ amp Δε̄p / (s ε_f) in the damage column
            d_old = s_in[i, S_JC_DAMAGE]
            dmg = d_old + counted / ef_const
            s_out[i, S_JC_DAMAGE] = dmg
            if dmg >= 1.0:
                onset = True
                after = deps if d_old >= 1.0 else deps * (dmg - 1.0) / (dmg - d_old)
        elif ef_const > 0.0 and eps_p_new >= ef_const:
            onset = True
            after = max(after, eps_p_new - max(eps_p, ef_const))
    d_e_old = s_in[i, S_SOFT_DAMAGE]
    d_e = d_e_old
    failed = onset
    if onset and s_in[i, S_EVOLUTION] > 0.0:
        d_e = min(1.0, d_e_old + s_in[i, S_EVOLUTION] * after)  # (J15)
        failed = d_e >= 1.0
    if d_e > 0.0 and not failed:
        # (J16): the stress is (1 − D_e) τ̃; what the step's work does not store is
        # dissipated — plastic work and the work of softening together
        a_o = 1.0 - d_e_old
        a_n = 1.0 - d_e
        work = 0.5 * thick * ((a_o * to11 + a_n * t11) * dd11 + (a_o * to22 + a_n * t22) * dd22
                              + (a_o * to12 + a_n * t12) * dg12)
        stored_old = s_in[i, S_ENERGY]
        w_e = a_n * w_e
        s_out[i, S_ENERGY] = w_e
        s_out[i, S_PLASTIC_WORK] = s_in[i, S_PLASTIC_WORK] + work - (w_e - stored_old)
        s_out[i, S_SOFT_DAMAGE] = d_e
        s_out[i, S_SIG] = a_n * t11 / jac
        s_out[i, S_SIG + 1] = a_n * t22 / jac
        s_out[i, S_SIG + 2] = a_n * t12 / jac
        t11 = a_n * t11
        t22 = a_n * t22
        t12 = a_n * t12
    if failed:
        if d_e > d_e_old:  # softened to the end: the rest of its work was dissipated
            a_o = 1.0 - d_e_old
            work = 0.5 * thick * a_o * (to11 * dd11 + to22 * dd22 + to12 * dg12)
            s_out[i, S_PLASTIC_WORK] = (s_in[i, S_PLASTIC_WORK] + work
                                        + s_in[i, S_ENERGY])
            s_out[i, S_SOFT_DAMAGE] = 1.0
            w_e = 0.0
        s_out[i, S_FAIL_ENERGY] = s_in[i, S_FAIL_ENERGY] + w_e
        clear_failed_point(s_out, i)
        return STATUS_OK, 0.0, 0.0, 0.0, 0.0

    # output: N = σ t = τ t0 / det F, turned to the corotational frame (J14)
    scale = thick / det_n
    n_xx, n_yy, n_xy = rotate_to_corotational(t11 * scale, t22 * scale, t12 * scale, cn, sn)
    return STATUS_OK, stiff * max(1.0, jac), n_xx, n_yy, n_xy


# keeps its long signature: a stage called in the loop of ``section_response``, its arguments that
# loop's locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@kernel
def fold_amplification(x_b, ko11, ko12, ko21, ko22, kn11, kn12, kn21, kn22,
                       fo11, fo12, fo21, fo22, f11, f12, f21, f22):
    """(J17) The factor on a section point's Δε̄p when fracture is judged: 1 + (x_b − 1) r.

    x_b = max(1, l_e/l_h) (S_HINGE): an element of length l_e bends over its whole length
    what a fold of the sheet bends over l_h, so the bending part of its surface strain
    is x_b times too small. r ∈ [0, 1] is the bending share of the point's strain
    increment, measured rotation-free by the Green–Lagrange increments ΔE = ½ΔC:

        r = |ΔE_k − ΔE_0| / (|ΔE_0| + |ΔE_k − ΔE_0|),

    ΔE_k the point's (F_k = (I + z κ̂) F, old ko.., new kn..), ΔE_0 the mid-surface's
    (fo.., f..), |·| the Frobenius norm. A membrane step (r = 0) counts as it is, a pure
    bending step x_b times; x_b = 1 gives exactly 1."""
    if x_b <= 1.0:
        return 1.0
    dk11 = 0.5 * ((kn11 * kn11 + kn21 * kn21) - (ko11 * ko11 + ko21 * ko21))
    dk22 = 0.5 * ((kn12 * kn12 + kn22 * kn22) - (ko12 * ko12 + ko22 * ko22))
    dk12 = 0.5 * ((kn11 * kn12 + kn21 * kn22) - (ko11 * ko12 + ko21 * ko22))
    d011 = 0.5 * ((f11 * f11 + f21 * f21) - (fo11 * fo11 + fo21 * fo21))
    d022 = 0.5 * ((f12 * f12 + f22 * f22) - (fo12 * fo12 + fo22 * fo22))
    d012 = 0.5 * ((f11 * f12 + f21 * f22) - (fo11 * fo12 + fo21 * fo22))
    bend = math.sqrt((dk11 - d011) ** 2 + (dk22 - d022) ** 2 + 2.0 * (dk12 - d012) ** 2)
    memb = math.sqrt(d011 * d011 + d022 * d022 + 2.0 * d012 * d012)
    if bend + memb <= 0.0:
        return 1.0
    return 1.0 + (x_b - 1.0) * bend / (bend + memb)


# --- many points ----------------------------------------------------------------
@loop_kernel
def j2_update_for_points(
    p, f_old, f_new, dt, thick, state_in, state_out, n_out, stiff_out, status_out
):
    """Run :func:`j2_point` on every point (independent, ``prange``).

    Args:
        p: (N_PARAM,) parameters shared by all points.
        f_old, f_new: (n, 2, 2) deformation gradients.
        dt: Δt of the increment (s); thick: reference thickness t0 (m).
        state_in: (n, N_STATE) states at the start of the step.
        state_out: (n, N_STATE) states at the end (written).
        n_out: (n, 3) resultants N_xx, N_yy, N_xy (N/m) (written).
        stiff_out: (n,) tangent stiffness bounds (written).
        status_out: (n,) int32 status codes (written).
    """
    p_table = np.empty((1, p.shape[0]))
    p_table[0, :] = p
    for i in prange(f_new.shape[0]):
        status, stiff, n_xx, n_yy, n_xy = j2_point(
            p_table, np.uint64(0), f_old[i, 0, 0], f_old[i, 0, 1], f_old[i, 1, 0],
            f_old[i, 1, 1], f_new[i, 0, 0], f_new[i, 0, 1], f_new[i, 1, 0], f_new[i, 1, 1],
            dt, thick, state_in, state_out, np.uint64(i),
        )
        n_out[i, 0] = n_xx
        n_out[i, 1] = n_yy
        n_out[i, 2] = n_xy
        status_out[i] = status
        stiff_out[i] = stiff
