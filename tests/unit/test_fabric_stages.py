"""The named stages of the crossover point update (kernels/fabric.py ``fabric_point``),
each checked alone: kinematics against the definition of the stretches and the angle,
the incremental frame against a rigid rotation, the exact and tabulated crossover
against each other (envelope theorem), failure, the sliver rule, and the shear energy
against its stress."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.conftest import reference_fabric, with_options
from wovenimpact.kernels import fabric_layout as L
from wovenimpact.kernels.fabric import (
    crossover_equilibrium,
    green_naghdi_stretches,
    sliver_erodes,
    stored_energy,
    trellis_shear,
    yarn_frame,
    yarn_resultant,
)
from wovenimpact.materials.fabric import initial_state
from wovenimpact.materials.fabric_table import TOLERANCE

U0 = np.uint64(0)


@pytest.fixture(scope="module")
def rows():
    """(exact, tabulated) parameter tables of the thesis Kevlar, one material each."""
    params = reference_fabric()
    exact = with_options(params, crossover="exact").to_array()[None, :]
    table = with_options(params, crossover="table").to_array()[None, :]
    return params, exact, table


def test_yarn_frame_gives_the_stretches_and_the_trellis_angle():
    lam_w, lam_f, a, b = 1.03, 0.98, 0.2, 0.2 + 1.3  # yarns 1.3 rad apart
    f11, f21 = lam_w * math.cos(a), lam_w * math.sin(a)
    f12, f22 = lam_f * math.cos(b), lam_f * math.sin(b)
    ok, lw, lf, ewx, ewy, efx, efy, cos_t, sin_t, gamma = yarn_frame(f11, f12, f21, f22)
    assert ok
    assert (lw, lf) == pytest.approx((lam_w, lam_f), rel=1e-15)
    assert (ewx, ewy, efx, efy) == pytest.approx(
        (math.cos(a), math.sin(a), math.cos(b), math.sin(b)), abs=1e-15)
    assert (cos_t, sin_t) == pytest.approx((math.cos(1.3), math.sin(1.3)), abs=1e-15)
    assert gamma == pytest.approx(0.5 * math.pi - 1.3, abs=1e-15)
    # the fill turned past the warp (an inverted cell) or a collapsed yarn: not admissible
    assert not yarn_frame(1.0, -0.2, 0.0, -0.9)[0]
    assert not yarn_frame(0.0, 0.0, 0.0, 1.0)[0]
    assert not yarn_frame(math.nan, 0.0, 0.0, 1.0)[0]


def test_the_incremental_frame_keeps_the_stretches_in_a_rigid_rotation():
    """ΔF F_mid⁻¹ of a rotation increment is skew (its Cayley form): Δε = 0, so the
    stretches and the angle carried from the start of the step do not change."""
    theta = 0.3
    r = np.array([[math.cos(theta), -math.sin(theta)], [math.sin(theta), math.cos(theta)]])
    f_old = np.array([[1.02, 0.1], [0.0, 0.97]])
    f_new = r @ f_old
    ok, lw, lf, gamma = green_naghdi_stretches(*f_old.ravel(), *f_new.ravel(), 1.02, 0.975,
                                               0.1)
    assert ok
    assert (lw, lf, gamma) == pytest.approx((1.02, 0.975, 0.1), abs=1e-15)
    # a stretch along the warp: λ grows by √(1 + 2Δε), Δε = ΔF F_mid⁻¹ = 0.02/1.01
    ok, lw, lf, gamma = green_naghdi_stretches(1.0, 0.0, 0.0, 1.0, 1.02, 0.0, 0.0, 1.0,
                                               1.0, 1.0, 0.0)
    assert ok and lw == pytest.approx(math.sqrt(1.0 + 2.0 * 0.02 / 1.01), rel=1e-14)
    assert lf == 1.0 and gamma == 0.0


@pytest.mark.parametrize("lam_w, lam_f", [(1.01, 1.0), (1.03, 1.02), (1.045, 0.99)])
def test_table_and_exact_crossover_agree_and_the_resultant_is_the_energy_gradient(
        rows, lam_w, lam_f):
    params, exact, table = rows
    s = initial_state(params)
    ex = crossover_equilibrium(exact, U0, s, U0, lam_w, lam_f)
    tb = crossover_equilibrium(table, U0, s, U0, lam_w, lam_f)
    assert ex[0] and tb[0] and not ex[13] and tb[13]  # converged; exact / table
    t_u = params.warp.ultimate_tension
    assert max(ex[6], ex[7]) > 0.0  # the yarns carry load here
    np.testing.assert_allclose(tb[6:8], ex[6:8], rtol=0, atol=TOLERANCE * t_u)  # tensions
    np.testing.assert_allclose(tb[2:4], ex[2:4], rtol=0,
                               atol=TOLERANCE * params.warp.h0)  # heights
    # the virial resultant of the exact tensions is the table's λ_i ∂W/∂λ_i / J
    sin_t = 1.0
    c_ex = yarn_resultant(exact, U0, False, lam_w, lam_f, sin_t, *ex[4:8], *ex[10:12], 0.0, 0.0)
    c_tb = yarn_resultant(table, U0, True, lam_w, lam_f, sin_t, *tb[4:8], *tb[10:12], *tb[15:17])
    ell0 = params.warp.half_length
    a0 = 4.0 * ell0 * params.fill.half_length
    c_u = t_u / (2.0 * ell0)  # the resultant of yarns at T_u
    np.testing.assert_allclose(c_tb[:2], c_ex[:2], rtol=1e-3, atol=TOLERANCE * c_u)
    # and the stored energies agree (yarns + compaction, no shear here)
    w_ex = stored_energy(exact, U0, False, 0.0, 0.0, *ex[4:6], *ex[8:10], *ex[2:4], ex[12])
    w_tb = stored_energy(table, U0, True, tb[14], 0.0, *tb[4:6], *tb[8:10], *tb[2:4], tb[12])
    lt0 = exact[0, L.P_LT0]
    w_u = t_u**2 * lt0 / (params.warp.modulus * params.warp.area) / a0  # yarns at T_u
    assert w_ex > 0.0 and w_tb == pytest.approx(w_ex, rel=1e-3, abs=TOLERANCE * w_u)


def test_a_yarn_past_its_ultimate_tension_breaks_and_its_partner_decrimps(rows):
    params, exact, _ = rows
    s = initial_state(params)
    stretch = 1.0572 * 1.01  # beyond a straight yarn's failure stretch (theory §1.9)
    out = crossover_equilibrium(exact, U0, s, U0, 1.0, stretch)
    ok, _, h_w, h_f, d_w, d_f, t_w, t_f = out[:8]
    assert ok and d_f == 1.0 and d_w == 0.0
    assert t_f == 0.0  # re-solved with the fill broken
    assert h_w <= params.warp.h0 * (1.0 + 1e-12)  # the warp lost its support


def test_the_sliver_rule_needs_a_broken_family():
    p = np.zeros((1, L.N_PARAM))
    s = np.zeros((1, L.N_STATE))
    s[0, L.S_ERODE_LIMIT:L.S_ERODE_LIMIT + 2] = 1.5  # the point's stretch limits
    p[0, L.P_ERODE_CRUSH] = 0.5
    assert not sliver_erodes(p, U0, s, U0, 0.0, 0.0, 1.8, 0.4)  # intact: never
    assert sliver_erodes(p, U0, s, U0, 1.0, 0.0, 1.6, 1.0)  # broken warp stretched past 1.5
    assert not sliver_erodes(p, U0, s, U0, 1.0, 0.0, 1.4, 1.0)
    assert sliver_erodes(p, U0, s, U0, 0.0, 1.0, 1.0, 0.45)  # crushed below 0.5
    s[0, L.S_ERODE_LIMIT + 1] = 1.2  # a limit of its own per family (an element's lengths)
    assert sliver_erodes(p, U0, s, U0, 0.0, 1.0, 1.0, 1.3)
    assert not sliver_erodes(p, U0, s, U0, 1.0, 0.0, 1.3, 1.0)
    s[0, L.S_ERODE_LIMIT:L.S_ERODE_LIMIT + 2] = 0.0
    p[0, L.P_ERODE_CRUSH] = 0.0
    assert not sliver_erodes(p, U0, s, U0, 1.0, 0.0, 5.0, 0.01)  # both tests disabled


def test_the_intact_crush_rule_erodes_a_cell_crushed_both_ways_only_when_asked():
    """erode_intact_crush (off by default): any point erodes once λ_w λ_f < the limit —
    a cell crushed both ways — but not one crushed across one family only, nor any
    point with the option off (the default, and the shipped Kevlar)."""
    p = np.zeros((1, L.N_PARAM))
    s = np.zeros((1, L.N_STATE))
    assert not sliver_erodes(p, U0, s, U0, 0.0, 0.0, 0.2, 0.2)  # off: never
    p[0, L.P_ERODE_INTACT] = 0.1
    assert sliver_erodes(p, U0, s, U0, 0.0, 0.0, 0.3, 0.3)  # 0.09 < 0.1
    assert not sliver_erodes(p, U0, s, U0, 0.0, 0.0, 0.35, 0.35)  # 0.1225
    assert not sliver_erodes(p, U0, s, U0, 0.0, 0.0, 1.04, 0.12)  # one way (a casing fold): 0.125
    assert reference_fabric().to_array()[L.P_ERODE_INTACT] == 0.0


@pytest.mark.parametrize("gamma", [0.05, 0.4, 0.7])
def test_the_shear_energy_is_the_integral_of_the_shear_stress(rows, gamma):
    """True law: d(e_shear)/dγ = t τ (central differences), and τ is odd in γ."""
    params, exact, _ = rows
    s = initial_state(params)
    thick = exact[0, L.P_THICK]
    h = 1e-6

    def shear(g):
        return trellis_shear(exact, U0, s, U0, g, 0.0, params.warp.h0, params.fill.h0, 1.0, 1.0)

    tau, g_tan, _ = shear(gamma)
    de = (shear(gamma + h)[2] - shear(gamma - h)[2]) / (2 * h)
    assert de == pytest.approx(thick * tau, rel=1e-6)
    assert shear(-gamma)[0] == pytest.approx(-tau, rel=1e-15)
    assert g_tan > 0.0


@pytest.mark.parametrize("crossover", ["exact", "table"])
def test_the_stable_step_stiffness_of_a_family_is_per_reference_width_and_zero_when_slack(
        rows, crossover):
    """yarn_resultant's k_w, k_f (theory §1.8): at rest they are the bound's own family
    terms; the warp's stays within 1 % when the element is crushed across it (λ_f = 0.5:
    the bound per current width doubles, the yarns per reference width do not change);
    a family shorter than (1 − SLACK_MARGIN) of its rest truss has none, one within the
    margin keeps its taut term."""
    from wovenimpact.kernels.fabric import SLACK_MARGIN

    params, exact, table = rows
    p = exact if crossover == "exact" else table
    s = initial_state(params)

    def terms(lam_w, lam_f):
        ex = crossover_equilibrium(p, U0, s, U0, lam_w, lam_f)
        assert ex[0]
        out = yarn_resultant(p, U0, ex[13], lam_w, lam_f, 1.0, *ex[4:8], *ex[10:12],
                             *ex[15:17])
        return out, np.array(ex[10:12]) / p[0, L.P_LT0]

    (_, _, stiff, k_w, k_f), _ = terms(1.0, 1.0)
    assert k_w == pytest.approx(stiff, rel=1e-12) and k_f == pytest.approx(stiff, rel=1e-12)
    (_, _, stiff_t, k_taut, _), _ = terms(1.045, 1.0)
    (_, _, stiff_c, k_crushed, k_slack), (l_w, l_f) = terms(1.045, 0.5)
    assert stiff_c > 1.9 * stiff_t  # the bound per current width doubles
    assert k_crushed == pytest.approx(k_taut, rel=0.01)
    assert l_f < 1.0 - SLACK_MARGIN and k_slack == 0.0
    # the fill just inside the margin still counts at its taut term
    (_, _, _, _, k_near), (_, l_near) = terms(1.0, 0.95)
    assert 1.0 - SLACK_MARGIN <= l_near < 1.0 and k_near > 0.5 * stiff
