"""The energy balance of a run: energies of the modelled part at the last whole step and
the balance error (docs/theory.md §5), functions of a Model and a State that step nothing.

Read by the run loop's history rows and summary (:mod:`wovenimpact.results.history_rows`,
:mod:`wovenimpact.results.summary`), the verification problems and the tests.
"""

from __future__ import annotations

import numpy as np

from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels import solid_layout as HL
from wovenimpact.state import (
    BODY_KINETIC,
    CONTACT_PENALTY,
    CONTACT_WORK,
    ERODED_INTERNAL,
    ERODED_KINETIC,
    KINETIC,
    KINETIC0,
    MASS_SCALING,
    NODE_CONTACT_WORK,
    W_EXT,
    W_INT,
    State,
)


def solid_energies(state) -> tuple[float, float]:
    """(stored, hourglass) energy of the hexahedra (J): Σ V0 W and Σ E_hg of their rows."""
    if not state.hex.shape[0]:
        return 0.0, 0.0
    return float(np.sum(state.hex[:, HL.H_W])), float(np.sum(state.hex[:, HL.H_W_HG]))


def body_force_work(model, state: State) -> float:
    """Work of the body forces (gravity) up to the last whole step t^n, like every work of
    :func:`energy_balance`: Σ_a m_a g_a · (x_a^n − X_a), exact for the constant loads
    m_a g_a that the trapezoid rule integrates; x^n = x^{n+1} − Δt^{n+1/2} v^{n+1/2}
    (the State already holds x^{n+1}). A node that leaves the model stops moving, and its
    body force working (its velocity is then zero); a free node (``run.eroded_nodes =
    "keep"``) keeps both."""
    g = model.body_accel[:, :3]
    if not np.any(g):
        return 0.0
    x_n = state.x - state.dt * state.v
    return float(np.sum(model.node_mass[:, None] * g * (x_n - model.x0)))


def energy_balance(model, state: State) -> dict[str, float]:
    """Energies (J) of the modelled part at the last whole step and the balance error.

    total = kinetic (nodes + impactors) + internal work + eroded kinetic − external
    work − work of the contact forces (= + contact energy, the penalty springs' energy
    and what sliding dissipated), which the exact solution keeps at the initial kinetic
    energy; ``drift`` is total minus its initial value. The external work is split into
    ``body_force_work_J`` (gravity) and ``reaction_work_J``, the work of the supports'
    and prescribed motions' reactions (prescribed-motion work).

    ``scale_J`` is the energy put into the model so far: max(KE0, |W_ext|, |body-force
    work|, |reaction work|). A run's error is |drift| over the largest ``scale_J`` of its
    history (results.history_rows.history_row), so round-off on energies near zero (a
    plate at rest under gravity) is not a large fraction. The kinetic energy, internal work and contact
    energy are left out on purpose: in a run that keeps its balance each is at most the
    energy put in (W_int, contact energy ≥ 0), and in one that does not they are what
    blows up — normalising by them let a section 1 m thick whose internal work went to
    −9e10 J from 5 mJ report 0.12 instead of 2e12 (docs/theory.md §5).
    ``error_fraction`` here is |drift| / ``scale_J`` of this state alone
    (:func:`error_fraction`: 0 while no energy has been put in).

    The internal work is split, each joule once: ``stored_J`` and ``hourglass_J`` are
    held by live elements (shells and hexahedra); an eroded element keeps its energies at erosion frozen in its
    state and they count only in ``eroded_internal_J`` (booked by ``step``), of which
    ``eroded_hourglass_J`` was hourglass energy. The rest of W_int was dissipated
    (broken yarns, damping of the contact's or the material's).
    """
    en = state.energy
    live = state.elem[:, SL.E_ALIVE] != 0.0
    u_memb, u_bend, u_hg = (state.elem[:, SL.E_U_MEMB], state.elem[:, SL.E_U_BEND],
                            state.elem[:, SL.E_U_HG])
    stored = float(np.sum(np.where(live, u_memb + u_bend, 0.0)))
    hourglass = float(np.sum(np.where(live, u_hg, 0.0)))
    if model.n_hexes:  # the hexahedra's, booked alike (docs/solid.md §4)
        solid_stored, solid_hourglass = solid_energies(state)
        stored += solid_stored
        hourglass += solid_hourglass
    eroded_hg = float(np.sum(np.where(live, 0.0, u_hg)))
    external = en[W_EXT] - en[NODE_CONTACT_WORK]
    body = body_force_work(model, state)
    reaction = external - body
    contact = -en[CONTACT_WORK]
    kinetic = en[KINETIC] + en[BODY_KINETIC]
    total = kinetic + en[W_INT] + en[ERODED_KINETIC] - external + contact - en[MASS_SCALING]
    drift = total - en[KINETIC0]
    scale = max(en[KINETIC0], abs(external), abs(body), abs(reaction), en[MASS_SCALING])
    return {
        "kinetic_J": float(en[KINETIC]),
        "impactor_kinetic_J": float(en[BODY_KINETIC]),
        "initial_kinetic_J": float(en[KINETIC0]),
        "internal_work_J": float(en[W_INT]),
        "stored_J": stored,
        "hourglass_J": hourglass,
        "external_work_J": float(external),
        "body_force_work_J": body,
        "reaction_work_J": float(reaction),
        "contact_energy_J": float(contact),
        "contact_penalty_J": float(en[CONTACT_PENALTY]),
        "contact_dissipated_J": float(contact - en[CONTACT_PENALTY]),
        "eroded_kinetic_J": float(en[ERODED_KINETIC]),
        "eroded_internal_J": float(en[ERODED_INTERNAL]),
        "eroded_hourglass_J": eroded_hg,
        "total_J": float(total),
        "drift_J": float(drift),
        "scale_J": float(scale),
        "error_fraction": error_fraction(drift, scale),
    }


def error_fraction(drift: float, scale: float) -> float:
    """|drift| / scale; 0 when scale is 0: with no energy put into the model there is
    nothing for round-off to be a fraction of (a mesh at rest without loads)."""
    return float(abs(drift) / scale) if scale > 0.0 else 0.0
