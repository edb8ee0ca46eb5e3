"""The contact force per interface (results.contact_forces; LS-DYNA's RCFORC): checked
against the nodal contact forces the solver applied and against the momentum a free
ply takes from the ply that strikes it."""

from __future__ import annotations

import numpy as np
import pytest

from wovenimpact.impactor import Impactor
from wovenimpact.interfaces import n_parts, part_names
from wovenimpact.model import Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.model.model import RigidBody, ShellContactParams
from wovenimpact.results.contact_forces import (
    contact_force_columns,
    contact_force_row,
    interface_forces,
)
from wovenimpact.results.history_rows import history_columns, history_row
from wovenimpact.solver import Workspace, step
from wovenimpact.state import initial_state
from tests.verification.meshes import elastic

T = 0.5e-3


def two_free_plies(damping: float = 0.3):
    """Two free 6 mm elastic plies 0.55 mm apart (1 mm elements, no support, no
    symmetry); the upper one (ply1) thrown at the lower (ply0) at 50 m/s. Returns
    (model, state, workspace)."""
    mesh = plate_mesh(6e-3, 1e-3, plies=2, spacing=T + 0.05e-3)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(elastic(poisson=0.3), thickness=T)},
                        np.zeros(mesh.n_elems, int), ply=mesh.ply, elem_sets=mesh.elem_sets,
                        node_sets=mesh.node_sets,
                        shell_contact=ShellContactParams(damping=damping))
    st = initial_state(model)
    st.v[mesh.node_sets["ply1"], 2] = -50.0
    return model, st, Workspace.for_model(model, st)


def test_interface_forces_are_the_applied_nodal_forces_and_the_struck_plys_momentum():
    """Over the plies' meeting (about 120 steps): (1) each ply's share of the interface
    forces, Σ_b F[a, b], is the sum of the nodal contact forces the solver applied to its
    nodes (``State.f_contact``, gathered through the segments' corners) to 1e-9 of the
    largest; (2) the lower ply, free, gains in each step the momentum Δt_mid F[ply0,
    ply1] (central differences: v^{n+1/2} = v^{n−1/2} + Δt_mid f^n / m) to 1e-9 of the
    largest change — a force with the wrong sign, a missing pass of the two-sided
    contact or a pair counted twice fails both; (3) the plies touched: the force was
    compressive (on ply0 along −z) and its impulse took a measurable share of ply1's
    momentum."""
    model, st, ws = two_free_plies()
    names = part_names(model)
    p0, p1 = names.index("ply0"), names.index("ply1")
    ply0 = np.flatnonzero(np.isin(np.arange(model.n_nodes), model.node_sets["ply0"]))
    mass = model.node_mass[ply0]
    impulse, p_start = np.zeros(3), mass @ st.v[ply0]
    worst_share = worst_momentum = largest = 0.0
    steps = 0
    while st.t < 20e-6:
        dt_old = st.dt
        before = mass @ st.v[ply0]
        step(model, st, ws)
        dt_mid = 0.5 * (dt_old + st.dt)
        F = interface_forces(ws.contact, n_parts(model))
        for a in (p0, p1):
            nodes = model.node_sets[names[a]]
            applied = st.f_contact[nodes, :3].sum(axis=0)
            worst_share = max(worst_share, float(np.max(np.abs(applied - F[a].sum(axis=0)))))
        change = mass @ st.v[ply0] - before
        worst_momentum = max(worst_momentum,
                             float(np.max(np.abs(change - dt_mid * F[p0, p1]))))
        largest = max(largest, float(np.max(np.abs(F))))
        impulse += dt_mid * F[p0, p1]
        steps += 1
    gained = mass @ st.v[ply0] - p_start
    p1_initial = 50.0 * float(np.sum(model.node_mass[model.node_sets["ply1"]]))
    print(f"\n{steps} steps; largest interface force {largest:.4g} N; worst share error "
          f"{worst_share:.3g} N; worst momentum error {worst_momentum * 1e9:.3g} nN s; "
          f"impulse on ply0 {impulse} N s against ply1's initial {p1_initial:.4g} N s")
    assert largest > 0.0
    assert worst_share <= 1e-9 * largest
    assert worst_momentum <= 1e-9 * np.max(np.abs(gained))
    assert impulse[2] < -0.05 * p1_initial
    assert gained == pytest.approx(impulse, rel=1e-9, abs=1e-12 * p1_initial)


def test_a_plate_impacts_history_has_the_ply_interface_force_along_the_travel():
    """A struck stack of three free plies (the impactor comes down on ply2 along −z; no
    symmetry: factor 1): the history names the interfaces in the order the impactor
    meets the plies, ply2_ply1 and ply1_ply0, and gives the force of the front ply on
    the one behind along the impactor's travel (−z): the row's value is −F[q, p]_z,
    positive while the front ply pushes; zero on the first row (no step yet)."""
    mesh = plate_mesh(6e-3, 1e-3, plies=3, spacing=T + 0.05e-3)
    mat = elastic(poisson=0.3)
    body = RigidBody(Impactor("cylinder", 2e-3, 4e-3),
                     tip=(0.0, 0.0, 2 * (T + 0.05e-3) + 0.5 * T + 0.01e-3),
                     direction=(0, 0, -1), speed=100.0, mass=10 * 3 * mat.density * T * 36e-6)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(mat, thickness=T)},
                        np.zeros(mesh.n_elems, int), ply=mesh.ply, bodies=[body],
                        elem_sets=mesh.elem_sets, node_sets=mesh.node_sets,
                        shell_contact=ShellContactParams(damping=0.3))
    st = initial_state(model)
    cols = contact_force_columns(model)
    assert cols == ("contact_force_ply2_ply1_full_N", "contact_force_ply1_ply0_full_N")
    assert history_columns(model)[-2:] == cols
    assert all(v == 0.0 for v in contact_force_row(model, None).values())
    ws = Workspace.for_model(model, st)
    seen = dict.fromkeys(cols, 0.0)
    names = part_names(model)
    while st.t < 4e-6:
        step(model, st, ws)
        row = history_row(model, st, contact=ws.contact)
        F = interface_forces(ws.contact, n_parts(model))
        for c in cols:
            p, q = c.split("_")[2:4]
            assert row[c] == pytest.approx(-F[names.index(q), names.index(p), 2], abs=1e-12)
            seen[c] = max(seen[c], row[c])
    print(f"\nlargest ply-on-ply forces along the travel: {seen}")
    assert all(v > 0.0 for v in seen.values())  # each front ply pushed the one behind it
