"""The energy of the contact forces booked per interface and per part of the pair force
(docs/theory.md §6, "Contact energy per interface"): a flat face strikes a stack of
three free plies; the plies strike each other."""

from __future__ import annotations

import numpy as np
import pytest

from wovenimpact.impactor import Impactor
from wovenimpact.interfaces import booked_totals, interface_energies, part_names
from wovenimpact.kernels.contact_energy import DAMPING, FRICTION, SPRING
from wovenimpact.model import Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.model.model import RigidBody, ShellContactParams
from wovenimpact.results.energy import energy_balance
from wovenimpact.results.summary import contact_damping_summary
from wovenimpact.solver import Workspace, step
from wovenimpact.state import CONTACT_PENALTY, CONTACT_WORK, KINETIC0, initial_state
from tests.verification.meshes import elastic

T = 0.5e-3


def struck_stack(friction=0.0, body_friction=0.0, mode="always", end=4e-6):
    """Three free 6 mm plies 0.55 mm apart (1 mm elements), struck at 100 m/s by a flat
    face of radius 2 mm and ten times their mass; returns (model, state)."""
    mesh = plate_mesh(6e-3, 1e-3, plies=3, spacing=T + 0.05e-3)
    mat = elastic(poisson=0.3)
    m_plies = 3 * mat.density * T * 36e-6
    body = RigidBody(Impactor("cylinder", 2e-3, 4e-3), tip=(0.0, 0.0, 2 * (T + 0.05e-3)
                                                           + 0.5 * T + 0.01e-3),
                     direction=(0, 0, -1), speed=100.0, mass=10 * m_plies,
                     friction=body_friction)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(mat, thickness=T)},
                        np.zeros(mesh.n_elems, int), ply=mesh.ply, bodies=[body],
                        elem_sets=mesh.elem_sets, node_sets=mesh.node_sets,
                        shell_contact=ShellContactParams(damping=0.3, friction=friction,
                                                         damping_mode=mode))
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    while st.t < end:
        step(model, st, ws)
    return model, st


@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_the_books_hold_the_contact_work_by_interface(friction):
    """Spring + dashpot + friction of every pair, booked against the velocities of the
    solver's own trapezoid rule, sum to −W_contact (nodes and body) to round-off
    (10⁻¹⁰ of the impact energy over ~1000 steps); without friction its books are
    exactly zero (with it, an interface's friction book may be negative: a node in
    several pairs can have its relative tangential velocity reversed by their capped
    forces together within a step, and the explicit kinetic friction then does positive
    work — −3.6 mJ at ply1-ply2 here, against 0.19 J of its dashpots; the single pair of
    tests/unit/test_contact_damping.py dissipates exactly the energy it takes); the
    dashpots dissipated energy at every interface;
    the interfaces are named as the user knows the parts (ply0-ply1, ply1-ply2,
    ply2-impactor) and their energies sum to the totals. The springs' book differs from
    their energy Σ ½ k g² by the penalty's discretisation (k follows Δt; the trapezoid
    does not integrate a pair's onset and release exactly): printed, and below 1 % of
    the impact energy."""
    model, st = struck_stack(friction=friction, body_friction=friction)
    books = st.contact_books[0]
    en = st.energy
    ke0 = float(en[KINETIC0])
    totals = booked_totals(books)
    booked = totals["spring"] + totals["damping"] + totals["friction"]
    print(f"\nμ = {friction}: −W_contact {-en[CONTACT_WORK]:.6e} J, booked {booked:.6e} J "
          f"(spring {totals['spring']:.4e}, damping {totals['damping']:.4e}, friction "
          f"{totals['friction']:.4e}); penalty energy {en[CONTACT_PENALTY]:.4e} J; spring "
          f"book − penalty energy {totals['spring'] - en[CONTACT_PENALTY]:+.3e} J; impact "
          f"energy {ke0:.4e} J")
    # the pending half of the last step's forces is not yet in the solver's work either
    assert booked == pytest.approx(-en[CONTACT_WORK], rel=0.0, abs=1e-10 * ke0)
    if friction == 0.0:
        assert np.all(books[FRICTION] == 0.0)
    else:
        assert np.any(books[FRICTION] != 0.0)
    assert abs(totals["spring"] - en[CONTACT_PENALTY]) < 0.01 * ke0
    assert part_names(model) == ["ply0", "ply1", "ply2", "impactor"]
    damping = interface_energies(model, books, DAMPING)
    assert list(damping) == ["ply0-ply1", "ply1-ply2", "ply2-impactor"]
    assert all(d > 0.0 for d in damping.values())
    assert sum(damping.values()) == pytest.approx(totals["damping"], rel=1e-12)
    assert sum(interface_energies(model, books, FRICTION).values()) == pytest.approx(
        totals["friction"], rel=1e-12, abs=0.0)
    assert sum(interface_energies(model, books, SPRING).values()) == pytest.approx(
        totals["spring"], rel=1e-12)
    summary = contact_damping_summary(model, st, 1.0)
    assert summary["contact_damping_energy_J"] == totals["damping"]
    assert summary["contact_damping_energy_by_interface_J"] == damping
    eb = energy_balance(model, st)
    assert eb["error_fraction"] < 2e-3


def test_the_approach_law_dissipates_less_at_the_ply_interfaces():
    """The same impact with the approach-only dashpot between the plies: the plies part
    undamped after each collision, so the ply interfaces' dashpots take less than with
    the dashpot that also acts while they separate (the impactor's contact keeps its own
    law), and the books still close on the contact work."""
    out = {}
    for mode in ("always", "approach"):
        model, st = struck_stack(mode=mode)
        out[mode] = interface_energies(model, st.contact_books[0], DAMPING)
        total = st.contact_books[0].sum()
        assert total == pytest.approx(-st.energy[CONTACT_WORK], rel=0.0,
                                      abs=1e-10 * st.energy[KINETIC0])
    print(f"\ndamping energy by interface: always {out['always']}, approach "
          f"{out['approach']}")
    for iface in ("ply0-ply1", "ply1-ply2"):
        assert out["approach"][iface] < out["always"][iface]
