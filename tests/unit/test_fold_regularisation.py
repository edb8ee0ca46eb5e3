"""The fold law of metal fracture (docs/theory.md §7.3, "Folds"; J17) on one shell section.

An element of length l_e bends over its whole length what a sheet folded over an edge
bends over its hinge length l_h, so with a hinge length the bending part of a point's
plastic strain counts x_b = max(1, l_e/l_h) times when fracture is judged. Driven here on
the five Simpson points of one in-plane point (kernels.shell.section_response), each test
one that the law without the hinge fails:

- pure bending: the surface point fails at ε̄p = ε_f/x_b, so the curvature at failure
  times l_e — the fold's rotation over the element — is nearly the same for l_e = 2, 4
  and 8 l_h (without the hinge it grows with l_e);
- pure stretch: the fracture strain is ε_f whatever x_b (the tension test's calibration
  stands);
- an element no longer than l_h is judged bitwise as without the hinge.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from wovenimpact.kernels import j2_layout as JL
from wovenimpact.kernels.j2 import fold_amplification
from wovenimpact.kernels.shell import section_response
from wovenimpact.kernels.shell_layout import MAT_J2
from wovenimpact.materials.metal import FractureRegularisation, initial_state, j2_parameter_row
from wovenimpact.spec.material import load_material

ALUMINIUM = Path(__file__).resolve().parents[2] / "examples" / "materials" / "aluminium.toml"
THICK = 1e-3
POINTS = 5
HINGE = 1.0  # l_h/t: the fold is one thickness wide


def aluminium(hinge: float | None):
    """The thesis aluminium (ε_f = 0.18, perfectly plastic), with a hinge length or none."""
    mat = load_material(ALUMINIUM)
    if hinge is None:
        return replace(mat, regularisation=None)
    return replace(mat, regularisation=FractureRegularisation(reference_length=1e-3,
                                                              hinge_ratio=hinge))


def drive(mat, element_length: float, curvature: float, stretch: float, steps: int = 4000):
    """Load one section from rest to (κ_x, λ_x) in ``steps`` equal steps (λ_y free of
    stress is not modelled: F = diag(λ_x, 1), κ = diag(κ_x, 0)); returns the per-step
    states (steps + 1, POINTS, N_STATE) and the curvature and stretch of each step."""
    p = j2_parameter_row(mat)[None, :]
    rows = initial_state(mat, POINTS, lengths=np.full(POINTS, element_length), thickness=THICK)
    width = rows.shape[1]
    kappas = np.linspace(0.0, curvature, steps + 1)
    lams = np.linspace(1.0, stretch, steps + 1)
    states = np.empty((steps + 1, POINTS, width))
    states[0] = rows
    dt = 1e-7
    for n in range(1, steps + 1):
        out = np.empty_like(rows)
        section_response(np.int64(POINTS), THICK, np.int64(MAT_J2), p, np.uint64(0),
                         lams[n - 1], 0.0, 0.0, 1.0, lams[n], 0.0, 0.0, 1.0,
                         kappas[n - 1], 0.0, 0.0, kappas[n], 0.0, 0.0, dt, rows, out,
                         np.uint64(0))
        rows = out
        states[n] = rows
    return states, kappas, lams


def first_failure(states):
    """The first step at which a point has failed (S_ALIVE 0), and that point."""
    dead = states[:, :, JL.S_ALIVE] == 0.0
    step = int(np.flatnonzero(dead.any(axis=1))[0])
    return step, int(np.flatnonzero(dead[step])[0])


def test_the_amplification_is_x_b_in_pure_bending_1_in_pure_stretch_and_1_without_a_hinge():
    eye = (1.0, 0.0, 0.0, 1.0)
    bent_old, bent_new = (1.0, 0.0, 0.0, 1.0), (1.001, 0.0, 0.0, 1.0)
    assert fold_amplification(4.0, *bent_old, *bent_new, *eye, *eye) == 4.0
    assert fold_amplification(4.0, *eye, 1.001, 0.0, 0.0, 1.0, *eye, 1.001, 0.0, 0.0, 1.0) == 1.0
    assert fold_amplification(1.0, *bent_old, *bent_new, *eye, *eye) == 1.0
    # a rigid rotation of the mid-surface is no stretch: bending alone still counts x_b
    c, s = np.cos(0.3), np.sin(0.3)
    assert fold_amplification(4.0, 1.0, 0.0, 0.0, 1.0, 1.001 * c, -s, 1.001 * s, c,
                              *eye, c, -s, s, c) == pytest.approx(4.0, rel=1e-9)


def test_a_bent_section_fails_at_the_same_fold_rotation_whatever_its_element_length():
    """Pure bending to κ = 0.3/t: the surface point fails at ε̄p = ε_f/x_b (to one step's
    increment), and κ_f l_e — the fold's rotation over the element — agrees within 10 %
    for l_e = 2, 4, 8 mm with l_h = t = 1 mm; without the hinge it grows 4-fold."""
    with_hinge, without = [], []
    for le in (2e-3, 4e-3, 8e-3):
        states, kappas, _ = drive(aluminium(HINGE), le, 0.3 / THICK, 1.0)
        step, point = first_failure(states)
        assert point in (0, POINTS - 1)  # a surface point fails first
        x_b = le / (HINGE * THICK)
        eps = states[step - 1, point, JL.S_EPS_P]
        step_increment = eps - states[step - 2, point, JL.S_EPS_P]
        assert eps * x_b == pytest.approx(0.18, abs=x_b * step_increment)
        with_hinge.append(kappas[step] * le)
        states, kappas, _ = drive(aluminium(None), le, 0.3 / THICK, 1.0)
        without.append(kappas[first_failure(states)[0]] * le)
    assert max(with_hinge) / min(with_hinge) < 1.1
    assert without[-1] / without[0] == pytest.approx(4.0, rel=0.02)


def test_a_stretched_section_fails_at_the_fracture_strain_whatever_its_element_length():
    """Pure stretch (λ_x to 1.4, κ = 0): every point fails at ε̄p = ε_f = 0.18, with the
    hinge and an 8 mm element as without it."""
    for mat in (aluminium(HINGE), aluminium(None)):
        states, _, _ = drive(mat, 8e-3, 0.0, 1.4, steps=2000)
        step, point = first_failure(states)
        assert states[step - 1, point, JL.S_EPS_P] < 0.18 <= (
            states[step - 1, point, JL.S_EPS_P]
            + 2 * (states[step - 1, point, JL.S_EPS_P] - states[step - 2, point, JL.S_EPS_P]))


def test_an_element_no_longer_than_the_hinge_is_judged_bitwise_as_without_it():
    """l_e ≤ l_h: x_b = 1, and every state column but S_HINGE matches the run without a
    hinge length bit for bit, through bending and stretch to failure."""
    a, _, _ = drive(aluminium(HINGE), 1e-3, 0.3 / THICK, 1.1, steps=1500)
    b, _, _ = drive(aluminium(None), 1e-3, 0.3 / THICK, 1.1, steps=1500)
    assert np.all(a[:, :, JL.S_HINGE] == 1.0)
    assert np.array_equal(a, b)


def test_a_hinge_ratio_with_two_fracture_criteria_is_refused(tmp_path):
    from wovenimpact.errors import InputError

    text = ALUMINIUM.read_text() + (
        '\n[material.damage]\nd1 = 0.1\nd2 = 0.2\nd3 = -0.5\nd4 = 0\n'
        '\n[material.regularisation]\nreference_length = "1 mm"\nhinge_ratio = 1\n')
    path = tmp_path / "al.toml"
    path.write_text(text)
    with pytest.raises(InputError, match="hinge_ratio.*two"):
        load_material(path)


def test_a_hinge_ratio_needs_no_reference_length_but_a_scale_table_does(tmp_path):
    from wovenimpact.errors import InputError

    path = tmp_path / "al.toml"
    path.write_text(ALUMINIUM.read_text() + "\n[material.regularisation]\nhinge_ratio = 1\n")
    assert load_material(path).regularisation.hinge_ratio == 1.0
    path.write_text(ALUMINIUM.read_text()
                    + "\n[material.regularisation]\nfracture_scale = [[1, 1], [2, 0.9]]\n")
    with pytest.raises(InputError, match="reference_length: is missing"):
        load_material(path)
