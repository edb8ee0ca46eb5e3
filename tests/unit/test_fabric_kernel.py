"""Unit tests of the crossover kernel (kernels/fabric.py): oracles, invariants, properties.

The exact height solve is the subject here (crossover = "exact", the default; the
tabulated option is tested against it in test_fabric_table.py); the invariants that hold for
both run with both.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import brentq

from tests.conftest import reference_fabric
from wovenimpact.errors import MaterialPointError
from wovenimpact.kernels import fabric_layout as L
from wovenimpact.kernels.fabric import (
    compaction_closure,
    MAX_ITER,
    compaction_energy,
    shear_modulus_true,
)
from wovenimpact.materials.fabric import initial_state, update_points

RESIDUAL_TOL = 1e-9  # issue acceptance: equilibrium and compatibility residuals
EXACT = {"crossover": "exact"}


@pytest.fixture
def kevlar():
    """The reference fabric with the exact crossover solve (this module's subject)."""
    return reference_fabric(**EXACT)


def stretch_shear(lam_w: float, lam_f: float, gamma: float) -> np.ndarray:
    """F with yarn stretches λ_w, λ_f and the fill turned by γ towards the warp."""
    return np.array([[lam_w, lam_f * math.sin(gamma)], [0.0, lam_f * math.cos(gamma)]])


def one_step(params, f_new, f_old=None, state=None):
    f_old = np.eye(2) if f_old is None else f_old
    state = initial_state(params)[0] if state is None else state
    return update_points(params.to_array(), f_old, f_new, state)


# --- pieces against closed forms -------------------------------------------------
def test_compaction_closure_inverts_the_compaction_law():
    a, b = 0.12389e-3, 0.98432
    for force in (1e-6, 0.1, 1.0, 50.0, 1e4):
        delta, ddelta = compaction_closure(force, a, b)
        # evaluating b δ/(a − δ) back loses (1 + F/b) ulps to the cancellation in a − δ
        assert b * delta / (a - delta) == pytest.approx(force, rel=1e-14 * (1 + force / b))
        h = 1e-7 * force
        fd = (compaction_closure(force + h, a, b)[0] - compaction_closure(force - h, a, b)[0]) / (
            2 * h
        )
        assert ddelta == pytest.approx(fd, rel=1e-6)


def test_compaction_energy_is_the_integral_of_the_law():
    a, b = 0.12389e-3, 0.98432
    delta = 0.8 * a
    x = np.linspace(0.0, delta, 200001)
    numeric = np.trapezoid(b * x / (a - x), x)
    assert compaction_energy(delta, a, b) == pytest.approx(numeric, rel=1e-8)


def test_shear_energy_is_the_integral_of_the_secant_law():
    g1, g2, gam1, gam2 = 0.0824e9, 8.24e9, math.radians(5.0), math.radians(49.5)
    for gam in (math.radians(3.0), math.radians(30.0), math.radians(60.0)):
        x = np.linspace(0.0, gam, 400001)
        tau = np.array([shear_modulus_true(v, g1, g2, gam1, gam2)[0] * v for v in x])
        assert shear_modulus_true(gam, g1, g2, gam1, gam2)[2] == pytest.approx(
            np.trapezoid(tau, x), rel=1e-9
        )


# --- the height solve ---------------------------------------------------------------
def contact_force_oracle(params, lam_w, lam_f):
    """Independent formulation: unknown F_c, H_i(F_c) by inverting F_i(H) = F_c
    (scipy brentq), then compatibility H_w + H_f + δ(F_c) = S (eq. 6.25)."""
    w, f = params.warp, params.fill
    a, b = params.compaction_a, params.compaction_b
    s_total = w.h0 + f.h0

    def force(y, ell, h):
        length = math.hypot(ell, h)
        t = y.modulus * y.area * max(length - y.truss_length, 0.0) / y.truss_length
        return 2 * t * h / length

    def height(y, ell, fc):
        return brentq(lambda h: force(y, ell, h) - fc, 0.0, 1e-2, xtol=1e-20, rtol=1e-15)

    ell_w, ell_f = lam_w * w.half_length, lam_f * f.half_length

    def compat(fc):
        return height(w, ell_w, fc) + height(f, ell_f, fc) + a * fc / (b + fc) - s_total

    fc = brentq(compat, 1e-12, 1e4, xtol=1e-18, rtol=1e-15)
    return height(w, ell_w, fc), height(f, ell_f, fc)


@pytest.mark.parametrize(
    "lam_w, lam_f", [(1.02, 1.0), (1.04, 1.01), (1.03, 1.03), (1.01, 1.035), (1.045, 0.99)]
)
def test_heights_match_an_independent_contact_force_solve(lam_w, lam_f):
    params = reference_fabric(**EXACT)
    out = one_step(params, np.diag([lam_w, lam_f]))
    hw, hf = contact_force_oracle(params, lam_w, lam_f)
    assert out.state[0, L.S_H] == pytest.approx(hw, rel=1e-8)
    assert out.state[0, L.S_H + 1] == pytest.approx(hf, rel=1e-8)


def scaled_parameters(scale):
    """Reference parameters with each constant scaled by a factor in [1/√10, √10]."""
    import dataclasses

    p = reference_fabric(**EXACT)
    yarn = dataclasses.replace(p.warp, modulus=p.warp.modulus * scale[0], area=p.warp.area * scale[1])
    fill = dataclasses.replace(p.fill, modulus=p.fill.modulus * scale[2], area=p.fill.area * scale[3])
    from wovenimpact.materials.crimp import crimp_amplitude

    yarn = dataclasses.replace(
        yarn, crimp=p.warp.crimp * scale[4], h0=crimp_amplitude(yarn.half_length, p.warp.crimp * scale[4])
    )
    fill = dataclasses.replace(
        fill, crimp=p.fill.crimp * scale[5], h0=crimp_amplitude(fill.half_length, p.fill.crimp * scale[5])
    )
    return dataclasses.replace(
        p,
        warp=yarn,
        fill=fill,
        compaction_a=p.compaction_a * scale[6] * (yarn.h0 + fill.h0) / (p.warp.h0 + p.fill.h0),
        compaction_b=p.compaction_b * scale[7],
    )


SOLVER_STATS: list[int] = []
RESIDUALS: list[float] = []


@settings(max_examples=1500, deadline=None)
@given(
    lam_w=st.floats(0.9, 1.1),
    lam_f=st.floats(0.9, 1.1),
    gamma=st.floats(-math.radians(60), math.radians(60)),
    scale=st.lists(st.floats(10**-0.5, 10**0.5), min_size=8, max_size=8),
    damage=st.sampled_from([(0.0, 0.0), (0.3, 0.0), (0.0, 0.7)]),
    h_prev=st.floats(0.0, 1.0),
)
def test_height_solver_converges_with_small_residuals(lam_w, lam_f, gamma, scale, damage, h_prev):
    """Property: any admissible state converges; equilibrium and compatibility hold.

    Failure is switched off (T_u → ∞) so that every state exercises the solve.
    """
    import dataclasses

    params = scaled_parameters(scale)
    params = dataclasses.replace(
        params,
        warp=dataclasses.replace(params.warp, ultimate_tension=1e30),
        fill=dataclasses.replace(params.fill, ultimate_tension=1e30),
    )
    w, f = params.warp, params.fill
    s_total = w.h0 + f.h0
    a, b = params.compaction_a, params.compaction_b
    state = initial_state(params)[0]
    state[L.S_DAMAGE], state[L.S_DAMAGE + 1] = damage
    state[L.S_H] = h_prev * s_total
    state[L.S_H + 1] = s_total - state[L.S_H]
    upd = update_points(params.to_array(), np.eye(2), stretch_shear(lam_w, lam_f, gamma), state)
    assert np.all(np.isfinite(upd.resultant))
    out = upd.state[0]
    SOLVER_STATS.append(int(out[L.S_ITER]))
    hw, hf = out[L.S_H], out[L.S_H + 1]
    assert 0.0 <= hw <= s_total and 0.0 <= hf <= s_total
    # independent evaluation of the residuals: plain formulas in extended precision
    # (x87 long double, 64-bit mantissa), so the oracle's own round-off near the
    # slack point (L − L0 ≪ L) stays far below the tolerance
    q = np.longdouble
    lt0_w, lt0_f = np.hypot(q(w.half_length), q(w.h0)), np.hypot(q(f.half_length), q(f.h0))
    k_w = (1 - q(damage[0])) * q(w.modulus) * q(w.area) / lt0_w
    k_f = (1 - q(damage[1])) * q(f.modulus) * q(f.area) / lt0_f
    ell_w, ell_f = q(lam_w) * q(w.half_length), q(lam_f) * q(f.half_length)

    def forces(h_w, h_f):
        lw, lf = np.hypot(ell_w, h_w), np.hypot(ell_f, h_f)
        tw, tf = k_w * max(lw - lt0_w, q(0)), k_f * max(lf - lt0_f, q(0))
        return 2 * tw * h_w / lw, 2 * tf * h_f / lf, tw, tf

    fw, ff, tw, tf = forces(q(hw), q(hf))
    fc = max(fw, ff)
    # absolute floor: the force of a yarn stretched by a few ulps of its length, the
    # round-off of L − L0 in the kernel's double precision (≈ 1e-11 N; ulps of the
    # heights, which are shorter, missed a falsifying case: T = 3.5e-12 N vs 0)
    floor = 4 * float(max(k_w, k_f)) * np.spacing(float(max(lt0_w, lt0_f)))
    if fc > floor:  # yarns in contact (not both slack)
        RESIDUALS.append(float(abs(fw - ff) / fc))
    assert abs(fw - ff) <= RESIDUAL_TOL * fc + floor, "equilibrium residual"
    if fc > floor:  # closed with the force of whichever yarn carried the unknown
        gaps = [
            abs(q(hw) + q(hf) + q(a) * fx / (q(b) + fx) - q(s_total)) for fx in (fw, ff)
        ]
        assert min(gaps) <= RESIDUAL_TOL * s_total
    else:  # both slack: touching, no force
        assert abs(hw + hf - s_total) <= RESIDUAL_TOL * s_total
    # the kernel's tensions at its own heights match the extended-precision formula
    assert out[L.S_TENSION] == pytest.approx(float(tw), rel=1e-9, abs=floor)
    assert out[L.S_TENSION + 1] == pytest.approx(float(tf), rel=1e-9, abs=floor)


def test_zz_report_solver_iterations():
    """Prints the iteration statistics gathered by the property test (closing-note figure)."""
    if SOLVER_STATS:
        print(
            f"\nheight solve over {len(SOLVER_STATS)} random states: "
            f"mean {np.mean(SOLVER_STATS):.2f}, max {max(SOLVER_STATS)} iterations; "
            f"relative equilibrium residual over the {len(RESIDUALS)} states in contact: "
            f"median {np.median(RESIDUALS):.1e}, max {max(RESIDUALS):.1e}"
        )
        assert max(SOLVER_STATS) <= 2 * MAX_ITER  # solve + re-solve after a failure


# --- invariants --------------------------------------------------------------------------
@pytest.mark.parametrize("crossover", ["exact", "table"])
@pytest.mark.parametrize("angle", [0.3, math.pi / 2, 2.5, -1.0])
def test_superposed_rigid_rotation_changes_no_invariant(angle, crossover):
    params = reference_fabric(crossover=crossover)
    f = stretch_shear(1.03, 1.01, math.radians(20))
    rot = np.array([[math.cos(angle), -math.sin(angle)], [math.sin(angle), math.cos(angle)]])
    plain = one_step(params, f)
    rotated = one_step(params, rot @ f)
    for idx in (L.S_H, L.S_H + 1, L.S_TENSION, L.S_TENSION + 1, L.S_ENERGY, L.S_GAMMA):
        assert rotated.state[0, idx] == pytest.approx(plain.state[0, idx], rel=1e-12, abs=1e-300)
    n, nr = plain.resultant[0], rotated.resultant[0]
    nm = np.array([[n[0], n[2]], [n[2], n[1]]])
    nrm = np.array([[nr[0], nr[2]], [nr[2], nr[1]]])
    assert np.allclose(rot @ nm @ rot.T, nrm, rtol=0, atol=1e-12 * np.abs(nm).max())


def test_undeformed_point_is_stress_free_at_its_reference_heights(kevlar):
    out = one_step(kevlar, np.eye(2))
    assert np.all(out.resultant == 0.0)
    assert out.state[0, L.S_H] == kevlar.warp.h0
    assert out.state[0, L.S_H + 1] == kevlar.fill.h0
    assert out.state[0, L.S_ENERGY] == 0.0


def test_reference_resultant_is_tension_over_pitch_for_a_straight_yarn(kevlar):
    """§1.5: N_ww = T cosψ / (2ℓ_f); with the fill slack the warp is straight, cosψ = 1."""
    w = kevlar.warp
    lam = 1.015 * w.truss_length / w.half_length  # yarn strain 1.5 % < ε_u = 2.19 %
    out = one_step(kevlar, np.diag([lam, 0.85]))  # fill slack even at H_f = 2 h0
    t_w = out.state[0, L.S_TENSION]
    assert out.state[0, L.S_H] == 0.0  # unsupported by the slack fill
    assert t_w == pytest.approx(0.015 * w.modulus * w.area, rel=1e-12)
    ell_f = 0.85 * kevlar.fill.half_length  # current pitch: force per unit current width
    assert out.resultant[0, 0] == pytest.approx(t_w / (2 * ell_f), rel=1e-12)


def test_virial_resultant_in_reference_state_small_strain(kevlar):
    lam = 1.045
    out = one_step(kevlar, np.diag([lam, 1.0]))
    st_ = out.state[0]
    ell_w = lam * kevlar.warp.half_length
    length = math.hypot(ell_w, st_[L.S_H])
    expected = st_[L.S_TENSION] * (ell_w / length) / (2 * kevlar.fill.half_length)
    assert out.resultant[0, 0] == pytest.approx(expected, rel=1e-12)


def test_thesis_homogenisation_is_stiffer_by_the_section_ratio():
    """Eq. (6.38) vs virial: ratio t·2ℓ0/(2A)·/cosψ ≈ 1.57 for the reference fabric (§1.5)."""
    virial = reference_fabric(**EXACT)
    thesis = reference_fabric(homogenisation="thesis", **EXACT)
    f = np.diag([1.045, 1.0])
    nv = one_step(virial, f)
    nt = one_step(thesis, f)
    st_ = nv.state[0]
    ell_w = 1.045 * virial.warp.half_length
    cos_psi = ell_w / math.hypot(ell_w, st_[L.S_H])
    predicted = virial.shell_thickness * 2 * virial.fill.half_length / (2 * virial.warp.area * cos_psi)
    assert nt.resultant[0, 0] / nv.resultant[0, 0] == pytest.approx(predicted, rel=1e-12)
    assert 1.5 < predicted < 1.7


# --- failure and erosion ------------------------------------------------------------------
def test_broken_fill_lets_the_warp_decrimp_and_unload(kevlar):
    p = kevlar.to_array()
    state = initial_state(kevlar)[0]
    state[L.S_DAMAGE + 1] = 1.0  # fill broken
    out = update_points(p, np.eye(2), np.diag([1.01, 1.0]), state)
    st_ = out.state[0]
    ell = 1.01 * kevlar.warp.half_length
    assert st_[L.S_H] == pytest.approx(math.sqrt(kevlar.warp.truss_length**2 - ell**2), rel=1e-12)
    assert st_[L.S_TENSION] == 0.0 and st_[L.S_ALIVE] == 1.0


@pytest.mark.parametrize("fill_stretch, eroded", [(1.5, False), (1.99, False), (2.01, True)])
def test_broken_family_stretched_past_the_limit_erodes_the_point(kevlar, fill_stretch, eroded):
    """Nothing holds a point together across broken yarns: once the broken family is
    stretched past erode_broken_stretch (2 by default) the point erodes."""
    p = kevlar.to_array()
    state = initial_state(kevlar)[0]
    state[L.S_DAMAGE + 1] = 1.0  # fill broken
    out = update_points(p, np.eye(2), np.diag([1.0, fill_stretch]), state).state[0]
    assert (out[L.S_ALIVE] == 0.0) == eroded
    if eroded:
        assert out[L.S_DAMAGE] == 1.0 and out[L.S_DAMAGE + 1] == 1.0


@pytest.mark.parametrize("broken", [0, 1])
@pytest.mark.parametrize("crushed", [0, 1])
@pytest.mark.parametrize("stretch, eroded", [(0.9, False), (0.51, False), (0.49, True)])
def test_a_family_crushed_below_the_limit_erodes_a_broken_point(
    kevlar, broken, crushed, stretch, eroded
):
    """With one family broken, a point crushed below erode_broken_crush (0.5 by default)
    along either family is a sliver: slack intact yarns across broken ones, or intact
    yarns bunched with nothing holding them apart. It erodes before its step collapses
    (theory §1.4; the 8-ply 175 m/s blow-up of §4)."""
    p = kevlar.to_array()
    state = initial_state(kevlar)[0]
    state[L.S_DAMAGE + broken] = 1.0
    stretches = [1.01, 1.01]
    stretches[crushed] = stretch
    out = update_points(p, np.eye(2), np.diag(stretches), state).state[0]
    assert (out[L.S_ALIVE] == 0.0) == eroded
    if eroded:
        assert out[L.S_DAMAGE] == 1.0 and out[L.S_DAMAGE + 1] == 1.0


def test_crushing_an_intact_point_or_with_the_limit_off_does_not_erode():
    """The crush limit is about broken families only; 0 switches it off."""
    intact = reference_fabric(**EXACT)
    out = update_points(intact.to_array(), np.eye(2), np.diag([0.3, 1.0]),
                        initial_state(intact)[0]).state[0]
    assert out[L.S_ALIVE] == 1.0
    off = reference_fabric(erode_broken_crush=0.0, **EXACT)
    state = initial_state(off)[0]
    state[L.S_DAMAGE] = 1.0
    out = update_points(off.to_array(), np.eye(2), np.diag([0.3, 1.0]), state).state[0]
    assert out[L.S_ALIVE] == 1.0


def test_both_yarns_broken_erodes_the_point(kevlar):
    p = kevlar.to_array()
    state = initial_state(kevlar)[0]
    out = update_points(p, np.eye(2), np.diag([1.08, 1.08]), state)
    st_ = out.state[0]
    assert st_[L.S_DAMAGE] == 1.0 and st_[L.S_DAMAGE + 1] == 1.0
    assert st_[L.S_ALIVE] == 0.0
    assert np.all(out.resultant == 0.0) and out.stiffness[0] == 0.0
    again = update_points(p, np.diag([1.08, 1.08]), np.diag([1.0, 1.0]), st_)
    assert again.state[0, L.S_ALIVE] == 0.0  # erosion is for good


def test_progressive_failure_follows_the_linear_softening_envelope():
    soft = 0.01
    params = reference_fabric(failure="progressive", softening_strain=soft, **EXACT)
    w = params.warp
    ea = w.modulus * w.area
    eps_u = w.ultimate_tension / ea
    p = params.to_array()
    state = initial_state(params)[0]
    f_old = np.eye(2)
    lam_f = 0.85  # fill slack: the warp is straight, ε = ℓ/L0 − 1 exactly
    for eps in np.linspace(0.0, eps_u + 1.2 * soft, 400)[1:]:
        lam = (1 + eps) * w.truss_length / w.half_length
        f_new = np.diag([lam, lam_f])
        out = update_points(p, f_old, f_new, state)
        state, f_old = out.state[0], f_new
        t = state[L.S_TENSION]
        if eps <= eps_u:
            assert t == pytest.approx(ea * eps, rel=1e-9)
        elif eps < eps_u + soft:
            assert t == pytest.approx(w.ultimate_tension * (1 - (eps - eps_u) / soft), rel=1e-9)
        else:
            assert t == 0.0 and state[L.S_DAMAGE] == 1.0
    # irreversible: unloading follows the damaged secant, no healing
    d_before = state[L.S_DAMAGE]
    out = update_points(p, f_old, np.diag([1.0, lam_f]), state)
    assert out.state[0, L.S_DAMAGE] == d_before


def test_inadmissible_kinematics_raise_with_the_state(kevlar):
    with pytest.raises(MaterialPointError, match="inadmissible"):
        one_step(kevlar, np.array([[1.0, 1.0], [0.0, 0.0]]))  # yarns parallel
    with pytest.raises(MaterialPointError, match="point 0"):
        one_step(kevlar, np.array([[np.nan, 0.0], [0.0, 1.0]]))


# --- stiffness bound and many points ---------------------------------------------------------
@settings(max_examples=200, deadline=None)
@given(lam_w=st.floats(0.95, 1.04), lam_f=st.floats(0.95, 1.04), gamma=st.floats(-0.8, 0.8),
       crossover=st.sampled_from(["exact", "table"]))
def test_stiffness_bounds_the_membrane_tangent(lam_w, lam_f, gamma, crossover):
    """The time-step stiffness bounds the tangent dN_ii/dε along each yarn and in shear."""
    params = reference_fabric(crossover=crossover)
    f = stretch_shear(lam_w, lam_f, gamma)
    base = one_step(params, f)
    if base.state[0, L.S_ALIVE] == 0.0 or np.any(base.state[0, L.S_DAMAGE : L.S_DAMAGE + 2] > 0):
        return
    h = 1e-7
    for col in (0, 1):
        fp = f.copy()
        fp[:, col] *= 1 + h
        pert = one_step(params, fp)
        if np.any(pert.state[0, L.S_DAMAGE : L.S_DAMAGE + 2] > 0):
            continue
        e = fp[:, col] / np.linalg.norm(fp[:, col])
        n0 = np.array([[base.resultant[0, 0], base.resultant[0, 2]], [base.resultant[0, 2], base.resultant[0, 1]]])
        n1 = np.array([[pert.resultant[0, 0], pert.resultant[0, 2]], [pert.resultant[0, 2], pert.resultant[0, 1]]])
        tangent = (e @ n1 @ e - e @ n0 @ e) / h
        assert tangent <= base.stiffness[0] * (1 + 1e-6)
    # in shear: the fill turned by h more towards the warp (engineering shear strain h)
    sheared = one_step(params, stretch_shear(lam_w, lam_f, gamma + h))
    if np.all(sheared.state[0, L.S_DAMAGE : L.S_DAMAGE + 2] == 0):
        tangent = abs(sheared.resultant[0, 2] - base.resultant[0, 2]) / h
        assert tangent <= base.stiffness[0] * (1 + 1e-6)


@pytest.mark.parametrize("crossover", ["exact", "table"])
def test_many_points_equal_single_points_bitwise_and_any_thread_count(crossover):
    import numba

    from wovenimpact.jit import set_threads
    from wovenimpact.kernels.fabric import fabric_update_for_points

    params = reference_fabric(crossover=crossover)
    p = params.to_array()
    rng = np.random.default_rng(7)
    n = 2000
    f_new = np.array(
        [stretch_shear(*rng.uniform(0.97, 1.05, 2), rng.uniform(-0.9, 0.9)) for _ in range(n)]
    )
    f_old = np.repeat(np.eye(2)[None], n, axis=0)
    state = initial_state(params, n)

    def run():
        out_s = np.full_like(state, np.nan)  # poisoned outputs must all be written
        out_n = np.full((n, 3), np.nan)
        out_k = np.full(n, np.nan)
        status = np.full(n, -1, dtype=np.int32)
        fabric_update_for_points(p, f_old, f_new, state, out_s, out_n, out_k, status)
        return out_s, out_n, out_k, status

    top = numba.config.NUMBA_NUM_THREADS
    set_threads(1)
    one = run()
    set_threads(top)
    many = run()
    for a, b in zip(one, many):
        assert np.array_equal(a, b)
    assert np.all(one[3] == L.STATUS_OK) and np.all(np.isfinite(one[1]))
    for i in (0, 17, n - 1):
        single = update_points(p, f_old[i], f_new[i], state[i])
        assert np.array_equal(single.resultant[0], one[1][i])
        assert np.array_equal(single.state[0], one[0][i])
