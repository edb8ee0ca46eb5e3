"""Eroded nodes that stay in the model (``run.eroded_nodes = "keep"``, LS-DYNA's ENMASS = 2;
theory §5, "Eroded nodes").

A node that loses its last live element either leaves the model with its kinetic energy
(``"remove"``, the default) or flies on as a free node with its mass and momentum, taking
contact against impactors and, as a slave node, against other surfaces' live segments.
Checked here by conservation laws: with "keep" nothing leaves the model, so the momentum
of nodes and bodies is conserved to round-off where "remove" loses the eroded nodes'
momentum; debris hitting an intact plate hands it momentum through contact and stops at
its contact offset; the energy balance of a perforation stays closed; and the option
changes nothing until a node is freed.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.verification.meshes import elastic, rect_grid
from tests.verification.test_mixed_contact import hybrid_model, momentum_z
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.model import Section, build_model
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver import Workspace, step
from wovenimpact.state import initial_state


def free_nodes(model, st) -> np.ndarray:
    """Mask of the nodes still in the model (node_active) without a live element."""
    live = np.zeros(model.n_nodes, dtype=bool)
    live[model.quads[st.elem[:, SL.E_ALIVE] != 0.0].ravel()] = True
    return ~live & (st.node_active != 0)


def perforation(mode: str, end: float = 12e-6) -> dict:
    """The FSP at 600 m/s through 0.5 mm of aluminium into two Kevlar plies (the model of
    test_mixed_contact on 1 mm elements; free shells, symmetry planes only: nothing
    outside takes momentum along z), run to ``end`` with ``run.eroded_nodes = mode``."""
    model, mesh = hybrid_model(size=1e-3)
    model = dataclasses.replace(model, eroded_nodes=mode)
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    p0 = momentum_z(model, st)
    worst = 0.0
    free_contact = 0.0  # largest contact force on a free node (N)
    while st.t < end:
        step(model, st, ws)
        worst = max(worst, energy_balance(model, st)["error_fraction"])
        free = free_nodes(model, st)
        if free.any():
            free_contact = max(free_contact, float(np.abs(ws.contact.f_con[free]).max()))
    return {"model": model, "state": st, "p0": p0, "p": momentum_z(model, st),
            "worst": worst, "balance": energy_balance(model, st), "free": free_nodes(model, st),
            "free_contact": free_contact,
            "eroded": int(np.sum(st.elem[:, SL.E_ALIVE] == 0.0))}


@pytest.fixture(scope="module")
def runs():
    return {mode: perforation(mode) for mode in ("remove", "keep")}


def test_kept_eroded_nodes_conserve_momentum_where_removed_ones_carry_it_away(runs):
    """Momentum along z (nodes + projectile) after the FSP has eroded a ring of the
    aluminium: conserved to round-off (1e-12 of the projectile's) with "keep"; with
    "remove" short by the eroded nodes' momentum, far beyond that (the test can tell the
    two apart). With "keep" no node leaves (node_active all 1, no eroded kinetic energy)
    and the freed ones take contact forces."""
    keep, remove = runs["keep"], runs["remove"]
    print(f"\nremove: Δp/p0 = {(remove['p'] - remove['p0']) / remove['p0']:.3e}, "
          f"{remove['eroded']} eroded, eroded kinetic {remove['balance']['eroded_kinetic_J']:.4f} J; "
          f"keep: Δp/p0 = {(keep['p'] - keep['p0']) / keep['p0']:.3e}, {keep['eroded']} eroded, "
          f"{int(keep['free'].sum())} free nodes, largest contact force on one "
          f"{keep['free_contact']:.1f} N")
    assert keep["eroded"] > 0 and remove["eroded"] > 0
    assert keep["free"].sum() > 0
    assert np.all(keep["state"].node_active == 1)
    assert keep["balance"]["eroded_kinetic_J"] == 0.0
    assert keep["free_contact"] > 0.0
    assert keep["p"] == pytest.approx(keep["p0"], rel=1e-12)
    assert abs(remove["p"] - remove["p0"]) > 1e-3 * abs(remove["p0"])
    assert remove["balance"]["eroded_kinetic_J"] > 0.0


def test_a_perforation_with_kept_eroded_nodes_keeps_its_energy_balance(runs):
    """The same perforation: the energy balance holds to 1e-3 (the tolerance of
    test_mixed_contact's run with "remove") with the freed nodes' kinetic energy counted
    as kinetic energy, and the projectile still gets through the aluminium (slowed)."""
    keep = runs["keep"]
    eb = keep["balance"]
    print(f"\nkeep: worst energy error {keep['worst']:.2e} (remove {runs['remove']['worst']:.2e}), "
          f"kinetic {eb['kinetic_J']:.4f} J, eroded internal {eb['eroded_internal_J']:.4f} J")
    assert keep["worst"] < 1e-3
    assert runs["remove"]["worst"] < 1e-3
    free = keep["free"]
    st, model = keep["state"], keep["model"]
    ke_free = 0.5 * float(np.sum(model.node_mass[free] * np.sum(st.v[free] ** 2, axis=1)))
    assert 0.0 < ke_free < eb["kinetic_J"]


def test_keep_changes_nothing_until_a_node_is_freed():
    """"keep" and "remove" step bitwise alike (the whole State) until the first step in
    which a node loses its last element; in that step "remove" takes it out of the model
    (node_active 0, velocity 0) and "keep" does not."""
    model, _ = hybrid_model(size=1e-3)
    models = {m: dataclasses.replace(model, eroded_nodes=m) for m in ("remove", "keep")}
    states = {m: initial_state(models[m]) for m in models}
    spaces = {m: Workspace.for_model(models[m], states[m]) for m in models}
    steps = 0
    while states["remove"].equals(states["keep"]):
        assert steps < 400, "no node was freed"
        for m in models:
            step(models[m], states[m], spaces[m])
        steps += 1
    gone = states["remove"].node_active == 0
    print(f"\nfirst difference after step {steps}: {int(gone.sum())} nodes removed")
    assert gone.any() and np.all(states["keep"].node_active == 1)
    assert np.all(free_nodes(models["keep"], states["keep"]) == gone)
    assert np.all(states["remove"].v[gone] == 0.0) and np.any(states["keep"].v[gone] != 0.0)


def debris_on_plate(mode: str, speed: float = 50.0, end: float = 80e-6):
    """A free steel plate 30 mm square, 1 mm thick (ply 1, 6 × 6 elements, z = 0), and
    above it one 2 mm square steel element 1 mm thick (ply 0, at z = 3 mm, its corners
    inside a plate element, away from the plate's nodes) moving down at ``speed``. The
    debris element erodes at t = 0 (a release at 0: ``Model.release_elems``); with
    "keep" its four nodes fly on as free nodes."""
    nodes, quads = rect_grid(6, 6, 0.03, 0.03)
    d = np.array([[0.011, 0.011, 3e-3], [0.013, 0.011, 3e-3], [0.013, 0.013, 3e-3],
                  [0.011, 0.013, 3e-3]])
    n_plate = len(nodes)
    nodes = np.vstack([nodes, d])
    quads = np.vstack([quads, n_plate + np.arange(4)[None, :]])
    ply = np.zeros(len(quads), dtype=np.int64)
    ply[:-1] = 1
    model = build_model(nodes, quads, {"s": Section(elastic(), thickness=1e-3)},
                        np.zeros(len(quads), int), ply=ply, release_elems=[len(quads) - 1],
                        release_time=0.0, eroded_nodes=mode)
    v0 = np.zeros((len(nodes), 3))
    v0[n_plate:, 2] = -speed
    st = initial_state(model, velocity=v0)
    ws = Workspace.for_model(model, st)
    debris = np.arange(n_plate, n_plate + 4)
    plate = np.arange(n_plate)
    gap = np.inf  # closest approach of a debris node to the plate's mid-surface (m)
    worst = 0.0
    while st.t < end:
        step(model, st, ws)
        gap = min(gap, float(np.min(st.x[debris, 2]) - np.max(st.x[plate, 2])))
        worst = max(worst, energy_balance(model, st)["error_fraction"])
    return model, st, ws, debris, plate, gap, worst


def test_free_debris_hands_its_momentum_to_an_intact_plate_through_contact():
    """With "keep" the four freed debris nodes strike the plate's segments (node to
    segment: no plate node under them) and bounce: the plate takes momentum
    Δp = (1 + e) m v M/(M + m), 0 ≤ e ≤ 1 the restitution, so between M/(M + m) and
    2 M/(M + m) of the debris's m v; nodes + plate conserve it to round-off; the debris
    never comes closer to the plate's mid-surface than half the offsets h_p + h_s = 1 mm
    (the free node keeps the offset of its shell) and ends moving away; the energy balance
    holds to 1e-3. With "remove" the debris leaves the model at t = 0 and the plate takes
    nothing."""
    model, st, ws, debris, plate, gap, worst = debris_on_plate("keep")
    m = model.node_mass
    p_debris0 = -50.0 * float(m[debris].sum())
    p_plate = float(np.sum(m[plate] * st.v[plate, 2]))
    p_debris = float(np.sum(m[debris] * st.v[debris, 2]))
    ratio = m[plate].sum() / (m[plate].sum() + m[debris].sum())
    print(f"\nkeep: plate took {p_plate / p_debris0:.4f} of the debris's momentum (bounds "
          f"{ratio:.4f}–{2 * ratio:.4f}); debris now {st.v[debris, 2].mean():.2f} m/s; closest "
          f"approach {gap * 1e3:.3f} mm; energy error {worst:.1e}")
    assert np.all(st.node_active[debris] == 1) and st.elem[-1, SL.E_ALIVE] == 0.0
    assert p_plate + p_debris == pytest.approx(p_debris0, rel=1e-12)
    assert ratio <= p_plate / p_debris0 <= 2.0 * ratio
    assert np.all(st.v[debris, 2] > st.v[plate, 2].mean())  # separating
    assert gap > 0.5e-3
    assert worst < 1e-3
    assert energy_balance(model, st)["eroded_kinetic_J"] == 0.0
    model, st, ws, debris, plate, gap, worst = debris_on_plate("remove")
    assert np.all(st.node_active[debris] == 0)
    assert np.all(st.v[plate, 2] == 0.0)  # (in-plane: round-off of the unloaded plate)
    assert energy_balance(model, st)["eroded_kinetic_J"] == pytest.approx(
        0.5 * float(m[debris].sum()) * 50.0**2, rel=1e-12)
