"""J2 metal sections in the shell (kernels/shell.py with kernels/j2.py; theory §7)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from wovenimpact.kernels import j2_layout as J
from wovenimpact.kernels import shell_layout as S
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.solver import Workspace, energy_balance, step
from wovenimpact.spec import load_material
from wovenimpact.state import initial_state
from tests.verification.meshes import rect_grid

ALUMINIUM = Path(__file__).resolve().parents[2] / "examples" / "materials" / "aluminium.toml"


@pytest.mark.parametrize("membrane", ["reduced", "full"])
def test_aluminium_strip_pulled_follows_the_hardening_table_and_books_its_plastic_work(membrane):
    """A 2 mm aluminium strip (four elements, 5-point section) pulled slowly to 8 %:
    every element's membrane stress σ = N/t is the hardening table's at its plastic
    strain (1 %: the table is of the Kirchhoff stress), the points through the
    thickness yield alike (no bending), and the internal work is the elastic stored
    energy plus the plastic work of the points (1 %), the energy balance holding."""
    al = load_material(ALUMINIUM)
    t, cell, n = 2e-3, 5e-3, 4
    nodes, quads = rect_grid(n, 1, n * cell, cell)
    left = np.flatnonzero(nodes[:, 0] == 0.0)
    right = np.flatnonzero(np.isclose(nodes[:, 0], n * cell))
    bc = BoundaryConditions(len(nodes), ramp_time=40e-6)
    bc.fix(np.arange(len(nodes)), (2, 3, 4, 5)).fix(left, (0,)).fix(left[:1], (1,))
    bc.prescribe(right, 0, 5.0)
    model = build_model(nodes, quads, {"al": Section(al, thickness=t, membrane=membrane)},
                        np.zeros(n, int), bcs=bc)
    assert model.sections[0, S.C_POINTS] == 5
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    while st.t < 340e-6:  # 5 m/s × 320 µs ≈ 1.6 mm of 20 mm: 8 %, quasi-static
        step(model, st, ws)
    width = model.point_width
    pts = st.mat.reshape(n, -1, 5, width)  # (element, in-plane point, level, column)
    eps_p = pts[..., J.S_EPS_P]
    assert eps_p.min() > 0.04
    assert np.allclose(eps_p, eps_p[..., :1], rtol=1e-9)
    sigma = st.elem[:, S.E_N] / (t * pts[..., J.S_THICK].mean(axis=(1, 2)))
    table = np.interp(eps_p.mean(axis=(1, 2)), *np.array(al.hardening).T)
    print(f"\n{membrane}: ε_p {eps_p.mean():.4f}, σ {sigma.mean() / 1e6:.2f} MPa vs table "
          f"{table.mean() / 1e6:.2f} MPa")
    assert np.allclose(sigma, table, rtol=0.01)
    a0 = model.area0[:, None]
    weights = np.array([1, 4, 2, 4, 1]) / 12.0
    per_elem = pts
    gw = (model.gauss_weight / model.area0[:, None]) if membrane == "full" else np.ones((n, 1))
    plastic = float(np.sum(a0 * gw * np.einsum("egk,k->eg", per_elem[..., J.S_PLASTIC_WORK],
                                                weights)))
    eb = energy_balance(model, st)
    assert eb["stored_J"] + plastic == pytest.approx(eb["internal_work_J"], rel=0.01)
    assert eb["error_fraction"] < 1e-3
