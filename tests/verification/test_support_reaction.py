"""The support reaction of the history (results.quantities.support_reaction) and the metal
stress of the VTU frames (results.metal_state.largest_von_mises) on a strip pulled slowly."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from wovenimpact.kernels import integrate as IN
from wovenimpact.kernels import j2_layout as J
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.results.metal_state import largest_von_mises
from wovenimpact.results.quantities import support_reaction, supported_nodes
from wovenimpact.solver import Workspace, step
from wovenimpact.spec import load_material
from wovenimpact.state import initial_state
from tests.verification.meshes import rect_grid

ALUMINIUM = Path(__file__).resolve().parents[2] / "examples" / "materials" / "aluminium.toml"


def strip(clamped: bool):
    """A 2 mm aluminium strip of four 5 mm elements (5-point section), out-of-plane motion
    and rotations held; its left end clamped (all translations: a support) or held in x
    only (one node also in y, uniaxial stress), its right end pulled at 5 m/s after a 40 µs
    ramp, run to 340 µs (8 %, quasi-static). Returns (material, thickness, model, state,
    right-end nodes)."""
    al = load_material(ALUMINIUM)
    t, cell, n = 2e-3, 5e-3, 4
    nodes, quads = rect_grid(n, 1, n * cell, cell)
    left = np.flatnonzero(nodes[:, 0] == 0.0)
    right = np.flatnonzero(np.isclose(nodes[:, 0], n * cell))
    bc = BoundaryConditions(len(nodes), ramp_time=40e-6)
    bc.fix(np.arange(len(nodes)), (2, 3, 4, 5)).fix(left, (0, 1) if clamped else (0,))
    bc.fix(left[:1], (1,))
    bc.prescribe(right, 0, 5.0)
    model = build_model(nodes, quads, {"al": Section(al, thickness=t)}, np.zeros(n, int), bcs=bc)
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    while st.t < 340e-6:
        step(model, st, ws)
    return al, t, model, st, right


def test_reaction_of_a_clamped_end_balances_the_pull_of_the_other():
    """Quasi-static: the clamped end's summed reaction (supports only: the pulled nodes,
    in prescribed motion, are not supports) is the opposite of the force that pulls the
    other end (the prescribed nodes' f_ext, their reaction) within 1 % (the rest is
    the strip's m·a), and it equals the membrane force N_xx × current width of each element
    not at the clamp (there the element narrows from the clamp's width) within 1 %; the y component (the two clamped nodes' opposite Poisson reactions; the only y force on the
    strip, so its sum is the strip's y inertia) is below 1e-5 of the x one, z is 0."""
    al, t, model, st, right = strip(clamped=True)
    assert supported_nodes(model).tolist() == np.flatnonzero(model.x0[:, 0] == 0.0).tolist()
    assert np.all(model.bc_code[right, 0] == IN.PRESCRIBED)
    r = support_reaction(model, st)
    pull = float(np.sum(st.f_ext[right, 0]))
    print(f"\nreaction {r} N, pull {pull:.6g} N")
    assert pull > 1e3
    assert r[0] == pytest.approx(-pull, rel=0.01)
    # N_xx is per unit current width: the force through each element is N_xx × its width
    y = st.x[model.quads][:, :, 1]
    width = y.max(axis=1) - y.min(axis=1)  # of a straight 4-node strip element, to 1e-3
    force = st.elem[:, SL.E_N] * width
    print("N_xx × width per element", force)
    away = model.x0[model.quads].min(axis=1)[:, 0] > 0.0  # the clamped element is a trapezoid
    assert away.sum() == 3
    assert np.allclose(-r[0], force[away], rtol=0.01)
    assert abs(r[1]) < 1e-5 * abs(r[0]) and r[2] == 0.0


def test_reaction_is_zero_without_supports_and_its_history_columns_come_last():
    """A strip held only in x at one end (one node also in y) has one support (the node
    with x, y and z held); the history row's last three columns are the reaction's."""
    from wovenimpact.results.history_rows import history_columns, history_row

    _, _, model, st, _ = strip(clamped=False)
    assert supported_nodes(model).size == 1
    cols = history_columns(model)
    assert cols[-3:] == ("reaction_force_x_part_N", "reaction_force_y_part_N",
                         "reaction_force_z_part_N")
    row = history_row(model, st)
    assert [row[c] for c in cols[-3:]] == support_reaction(model, st).tolist()


def test_stress_of_a_uniaxially_pulled_strip_is_the_j2_kernels():
    """Uniaxial stress (left end held in x only): each element's VTU ``stress`` σ_xx is the
    membrane force over the current thickness, N_xx / (t0 t/t0) (the shell's integration of
    its points' stresses) to 1e-6, and the hardening table's at its plastic strain to 1 %
    (the J2 kernel's flow stress, as test_metal_shell checks of N/t); σ_yy, σ_xy are below
    0.5 % of it and the von Mises stress is σ_xx within 0.5 %."""
    al, t, model, st, _ = strip(clamped=False)
    vm, sig = largest_von_mises(model, st)
    pts = st.mat.reshape(model.n_elems, -1, model.point_width)
    lam = (pts[..., J.S_THICK] @ (np.array([1, 4, 2, 4, 1]) / 12.0))
    assert np.allclose(sig[:, 0], st.elem[:, SL.E_N] / (t * lam), rtol=1e-6)
    eps_p = pts[..., J.S_EPS_P].max(axis=1)
    assert eps_p.min() > 0.04
    table = np.interp(eps_p, *np.array(al.hardening).T)
    assert np.allclose(sig[:, 0], table, rtol=0.01)
    assert np.all(np.abs(sig[:, 1:]) < 5e-3 * sig[:, :1])
    assert np.allclose(vm, sig[:, 0], rtol=5e-3)
