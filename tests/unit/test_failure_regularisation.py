"""Element-size regularisation of failure at the point level (docs/theory.md §1.4, §7.3).

Each law is driven on one material point standing for elements of several lengths h, and
each test is one that a law without the regularisation fails:

- fabric: the softening given as an opening δ_s dissipates ½ T_u δ_s per yarn crossing
  the crack, the same for every h (a fixed softening strain gives h times as much); a
  point fails at its own strength s(h) T_u; a broken family erodes once its element has
  opened by δ_e (a fixed stretch limit lets a 7 mm element open 7 mm);
- metal: the fracture strain is s(l_e) ε_f; after onset the damage grows with the plastic
  displacement l_e Δε̄p, so the work of the softening per unit crack area, t0 σ_y ū_f / 2,
  does not depend on l_e;
- the model: each element's lengths along the yarns (√A0 for a metal), and the failure
  columns its points start with.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tests.conftest import with_options
from wovenimpact.calibration.metal_element import run_metal_element_test
from wovenimpact.kernels import fabric_layout as L
from wovenimpact.kernels import j2_layout as JL
from wovenimpact.materials.fabric import (
    FailureRegularisation,
    initial_state,
    regularised_columns,
    update_points,
)
from wovenimpact.materials.metal import FractureRegularisation
from wovenimpact.model.model import characteristic_lengths
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.spec.material import load_material

LENGTHS_MM = (0.94, 1.88, 3.76, 7.0)
SCALE = ((1.0, 1.0), (2.0, 0.9), (4.0, 0.8), (8.0, 0.7))  # an example table (h/h_ref, s)
OPENING = 0.3e-3  # δ_s (m)


def regularised(params, **kw):
    from dataclasses import replace

    return replace(with_options(params, crossover="exact", failure=kw.pop("failure", "instant")),
                   regularisation=FailureRegularisation(**kw))


def pull_warp(params, h, stretch_end=1.2, n=4000):
    """One point of an element h long along the warp (and across the fill), pulled along
    the warp with the fill held at λ_f = 1: the stretches, the work per unit reference
    area (trapezoid on P = J N F⁻ᵀ, here N_xx λ_f) and the states."""
    p = params.to_array()
    state = initial_state(params, lengths=np.array([[h, h]]))
    lam = np.linspace(1.0, stretch_end, n + 1)
    work = np.zeros(n + 1)
    states = np.empty((n + 1, L.N_STATE))
    states[0] = state[0]
    n_prev = 0.0
    for k in range(1, n + 1):
        upd = update_points(p, np.diag([lam[k - 1], 1.0]), np.diag([lam[k], 1.0]), state)
        n_xx = upd.resultant[0, 0]
        work[k] = work[k - 1] + 0.5 * (n_prev + n_xx) * (lam[k] - lam[k - 1])
        n_prev = n_xx
        state = upd.state
        states[k] = state[0]
    return lam, work, states


def softening_work(params, st, h):
    """The work the warp yarns take from their peak tension to zero, per unit crack length
    across an element h long: h × 2 ∫ T dL / (4 ℓ_w0 ℓ_f0) (two half trusses per cell,
    L = √((λ ℓ_w0)² + H_w²) their length, trapezoid over the load steps)."""
    ell_w, ell_f = params.warp.half_length, params.fill.half_length
    t = st[:, L.S_TENSION]
    length = np.hypot(st[:, L.S_LAMBDA] * ell_w, st[:, L.S_H])
    k_peak = int(np.argmax(t))
    k_end = int(np.flatnonzero(st[:, L.S_DAMAGE] >= 1.0)[0])
    seg = slice(k_peak, k_end + 1)
    work = np.sum(0.5 * (t[seg][1:] + t[seg][:-1]) * np.diff(length[seg]))
    return h * 2.0 * work / (4.0 * ell_w * ell_f), k_peak, k_end


def test_the_softening_opening_dissipates_the_same_work_per_crack_whatever_the_element(kevlar):
    """The warp's work from its peak to zero tension, per unit crack length: ½ T_u δ_s per
    yarn crossing the crack (yarns 2ℓ_f0 apart) to 0.5 % for h = 0.94 … 7 mm, whatever
    the strength scale s(h); with the fixed softening strain it grows like h (7 mm > 5×
    0.94 mm). The external work from the peak to the break differs from the yarn's by the
    energy the crossing fill gives back as the warp decrimps (crimp interchange): within
    3 % of it."""
    params = regularised(kevlar, failure="progressive", strength_scale=SCALE,
                         softening_opening=OPENING)
    expected = 0.5 * kevlar.warp.ultimate_tension * OPENING / (2.0 * kevlar.fill.half_length)
    for h_mm in LENGTHS_MM:
        h = h_mm * 1e-3
        lam, work, st = pull_warp(params, h, stretch_end=1.1 + 2.0 * OPENING / h, n=6000)
        g, k_peak, k_end = softening_work(params, st, h)
        assert g == pytest.approx(expected, rel=0.005), h_mm
        assert h * (work[k_end] - work[k_peak]) == pytest.approx(g, rel=0.03), h_mm
    fixed = with_options(kevlar, crossover="exact", failure="progressive",
                         softening_strain=0.01)
    g = [softening_work(fixed, pull_warp(fixed, h_mm * 1e-3, stretch_end=1.1)[2],
                        h_mm * 1e-3)[0] for h_mm in (0.94, 7.0)]
    assert g[1] > 5.0 * g[0]


def test_a_point_fails_at_its_own_regularised_strength(kevlar):
    """Instant failure at s(h/h_ref) T_u: the largest tension before the break is that
    strength within one load step, for every h (the table, flat beyond its ends)."""
    params = regularised(kevlar, strength_scale=SCALE)
    h_ref = 2.0 * kevlar.warp.half_length
    for h_mm in LENGTHS_MM:
        h = h_mm * 1e-3
        s = float(np.interp(h / h_ref, [r[0] for r in SCALE], [r[1] for r in SCALE]))
        lam, work, st = pull_warp(params, h, stretch_end=1.1, n=2000)
        k_break = int(np.flatnonzero(st[:, L.S_DAMAGE] >= 1.0)[0])
        t_peak = st[k_break - 1, L.S_TENSION]
        step = t_peak - st[k_break - 2, L.S_TENSION]
        target = s * kevlar.warp.ultimate_tension
        assert target - step <= t_peak < target, (h_mm, t_peak, target)


def test_a_broken_family_erodes_once_its_element_has_opened_by_the_erosion_opening(kevlar):
    """λ at erosion = 1 + δ_e/h for each h (with a fixed stretch limit of 2 a 7 mm element
    would stay until it had opened by 7 mm)."""
    delta = 0.94e-3
    params = regularised(kevlar, erosion_opening=delta)
    for h_mm in (0.94, 3.76, 7.0):
        h = h_mm * 1e-3
        lam, work, st = pull_warp(params, h, stretch_end=2.2, n=6000)
        k = int(np.flatnonzero(st[:, L.S_ALIVE] == 0.0)[0])
        limit = 1.0 + delta / h
        assert lam[k - 1] <= limit < lam[k], (h_mm, lam[k], limit)


def test_without_regularisation_every_point_keeps_the_material_s_own_failure(kevlar):
    """The default (no [material.regularisation]): s = 1 and the material's softening
    strain whatever the element; a broken family erodes at the opening at which a
    crossover-size element reaches the material's erode_broken_stretch λ_e (λ_lim = 1 +
    (λ_e − 1) h_ref/h: λ_e itself at h_ref, 1.5 on an element twice as long); a stretch
    limit of 0 still means never."""
    p = with_options(kevlar, failure="progressive", softening_strain=0.01).to_array(table=False)
    h_ref = p[L.P_REG_LENGTH:L.P_REG_LENGTH + 2]
    lengths = np.array([[0.5e-3, 7e-3], [2.0 * h_ref[0], 0.0]])
    cols = regularised_columns(p, lengths)
    assert np.array_equal(cols[:, 0:2], np.ones((2, 2)))
    assert np.array_equal(cols[:, 2:4], np.full((2, 2), 0.01))
    lam_e = p[L.P_ERODE_STRETCH]
    assert lam_e == 2.0
    h = np.where(lengths > 0.0, lengths, h_ref)
    assert cols[:, 4:6] == pytest.approx(1.0 + (lam_e - 1.0) * h_ref / h, rel=1e-15)
    assert cols[1, 4] == pytest.approx(1.5) and cols[1, 5] == 2.0
    never = with_options(kevlar, erode_broken_stretch=0.0).to_array(table=False)
    assert np.array_equal(regularised_columns(never, lengths)[:, 4:6], np.zeros((2, 2)))


def test_the_element_lengths_follow_the_yarns():
    """A 3 × 2 rectangle, warp along its 3 side: h_w = 3, h_f = 2; warp along the other
    side: swapped; a metal element: √A0 both."""
    x0 = np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [3.0, 2.0, 0.0], [0.0, 2.0, 0.0]])
    q = np.array([[0, 1, 2, 3]])
    fab = np.array([SL.MAT_FABRIC])
    assert characteristic_lengths(x0, q, (1.0, 0.0, 0.0), fab)[0] == pytest.approx([3.0, 2.0])
    assert characteristic_lengths(x0, q, (0.0, 1.0, 0.0), fab)[0] == pytest.approx([2.0, 3.0])
    metal = np.array([SL.MAT_J2])
    assert characteristic_lengths(x0, q, (1.0, 0.0, 0.0), metal)[0] == pytest.approx(
        [math.sqrt(6.0)] * 2)


# --- metal ------------------------------------------------------------------------------
TITANIUM = "examples/materials/titanium.toml"
U_F = 0.05e-3  # ū_f (m)


def titanium(**kw):
    from dataclasses import replace

    return replace(load_material(TITANIUM), regularisation=FractureRegularisation(**kw))


def test_the_fracture_strain_scales_with_the_element_length():
    """Uniaxial tension to failure: ε̄p at failure = s(l_e/l_ref) × 0.25 (the table)."""
    table = ((0.25, 1.6), (1.0, 1.0), (4.0, 0.6))
    mat = titanium(reference_length=1e-3, fracture_scale=table)
    for le, s in ((0.25e-3, 1.6), (0.5e-3, 1.6 - 0.6 * (0.25 / 0.75)), (1e-3, 1.0),
                  (2e-3, 1.0 - 0.4 / 3.0), (8e-3, 0.6)):
        res = run_metal_element_test(mat, "uniaxial", strain=0.6, n_steps=300,
                                     element_length=le)
        assert res.failure_plastic_strain == pytest.approx(s * 0.25, rel=1e-9), le


def test_the_softening_after_onset_dissipates_the_same_work_per_crack_whatever_the_element():
    """Perfectly plastic titanium (σ_y = 827.37 MPa) with ū_f = 0.05 mm: the external work
    from the onset of failure to failure, times l_e, is t0 σ_y ū_f / 2 to 1 % for
    l_e = 0.25 … 2 mm; the energy check of the element test (work = stored + plastic +
    released) holds through the softening."""
    mat = titanium(reference_length=1e-3, failure_displacement=U_F)
    t0 = 1e-3
    sig_y = mat.hardening[0][1]
    per_crack = []
    for le in (0.25e-3, 0.5e-3, 1e-3, 2e-3):
        res = run_metal_element_test(mat, "uniaxial", strain=0.5, n_steps=4000, thickness=t0,
                                     element_length=le)
        h = res.history
        onset = int(np.flatnonzero(h["plastic_strain"] >= 0.25)[0])
        end = int(np.flatnonzero(h["alive"] == 0.0)[0])
        assert h["softening_damage"][end - 1] > 0.9  # it softened before it failed
        per_crack.append(le * (h["external_work_J_per_m2"][end]
                               - h["external_work_J_per_m2"][onset]))
        assert res.energy_error_fraction < 1e-3
    expected = t0 * sig_y * U_F / 2.0
    assert np.array(per_crack) == pytest.approx(expected, rel=0.01)


def test_a_metal_point_without_regularisation_fails_at_onset_as_before():
    """No [material.regularisation]: s = 1, no softening (S_EVOLUTION 0): the point fails
    at ε̄p = ε_f with no softening damage."""
    mat = load_material(TITANIUM)
    res = run_metal_element_test(mat, "uniaxial", strain=0.4, n_steps=200)
    assert res.failure_plastic_strain == pytest.approx(0.25, rel=1e-12)
    assert np.all(res.history["softening_damage"] == 0.0)
    from wovenimpact.materials.metal import initial_state as j2_state

    row = j2_state(mat)[0]
    assert row[JL.S_FRAC_SCALE] == 1.0 and row[JL.S_EVOLUTION] == 0.0


def test_a_case_can_add_a_regularisation_to_a_material_file_that_has_none(tmp_path):
    """``materials.NAME.set.regularisation…`` (a study's ``--set``) adds the table the shipped
    file does not have; a table the material schema does not know is refused by name."""
    from wovenimpact.errors import InputError
    from wovenimpact.setup.compile import load_case_material
    from wovenimpact.spec.case import MaterialRef

    base = Path(__file__).resolve().parents[2] / "examples" / "materials"
    ref = MaterialRef(file="kevlar_thesis.toml",
                      set={"regularisation": {"erosion_opening": "0.94 mm"}})
    kevlar = load_case_material(base, "kevlar", ref)
    assert kevlar.regularisation.erosion_opening == pytest.approx(0.94e-3)
    bad = MaterialRef(file="kevlar_thesis.toml", set={"regularization": {"x": "1 mm"}})
    with pytest.raises(InputError, match="regularization"):
        load_case_material(base, "kevlar", bad)
