"""Engineering quantities of a run: impactor kinematics, residual velocity, energies by ply.

Models with symmetry planes carry a share of the impactor (a quarter in a quarter
model, ``kernels.rigid_body.BP_FRACTION``); forces and energies returned here as
"full" are the whole-problem values (divided by that share), velocities are the same.
"""

from __future__ import annotations

import math
import weakref

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.kernels import integrate as IN
from wovenimpact.kernels import rigid_body as RB
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels.mass_scaling import node_masses
from wovenimpact.model.model import flies_sideways, sideways_shadow, travel_of_row

QUIET_TIME = 10e-6  # contact must have been light this long to call a perforation
LIGHT_CONTACT = 0.01  # "light": below this fraction of the peak contact force
STEADY_VELOCITY = 1e-3  # a change between history rows above this fraction of the initial
# speed is an engagement too (a contact that fell between the rows of a coarse history)
REST_FRACTION = 0.01  # "at rest": speed along the travel below this fraction of the initial
OUTCOMES = ("perforated", "stopped", "undecided", "no contact")
OUTCOME_COLUMNS = ("time_s", "impactor_velocity_m_per_s", "contact_force_full_N",
                   "intact_material_ahead")


def symmetry_factor(model) -> float:
    """1 / (share of the first impactor in the model): 4 in a quarter model, else 1."""
    if model.body_params.shape[0] == 0:
        return 1.0
    return 1.0 / model.body_params[0, RB.BP_FRACTION]


def travel_direction(model, state, b: int = 0) -> np.ndarray:
    """Unit vector of the body's direction of travel: −(body axis), tip leading, or,
    for a body flying sideways, its rotation times its travel in its own frame
    (model.model.travel_of_row)."""
    return travel_of_row(model, state.bodies[b], b)


def impactor_row(model, state, b: int = 0) -> dict:
    """Velocity and displacement along the initial travel direction, and the contact
    force resisting it (full-problem value), of impactor b."""
    d0 = travel_of_row(model, model.body_state0[b], b)
    row = state.bodies[b]
    x0 = model.body_state0[b, RB.B_X:RB.B_X + 3]
    factor = 1.0 / model.body_params[b, RB.BP_FRACTION]
    return {
        "impactor_velocity_m_per_s": float(row[RB.B_V:RB.B_V + 3] @ d0),
        "impactor_displacement_m": float((row[RB.B_X:RB.B_X + 3] - x0) @ d0),
        "contact_force_full_N": float(-(row[RB.B_F:RB.B_F + 3] @ d0) * factor),
    }


def impactor_radius(model, b: int = 0) -> float:
    """Largest radius of impactor b's profile (its shank, or a sphere's radius; m)."""
    n = int(model.body_params[b, RB.BP_NPTS])
    return float(np.max(model.body_profiles[b, :n, 1]))


def nose_tip(model, state, b: int = 0) -> np.ndarray:
    """Position of impactor b's nose tip: the centre of mass plus ``BP_TIP`` along the
    travel direction."""
    return state.bodies[b, RB.B_X:RB.B_X + 3] + model.body_params[b, RB.BP_TIP] * travel_direction(
        model, state, b)


_ATTACHED_CACHE: dict = {}


def attached_nodes(model, state) -> np.ndarray:
    """(n_nodes,) bool: nodes of live elements connected, through live elements, to a
    support — a node whose three translations are constrained (clamped, pinned or
    driven; a symmetry plane constrains one and is no support). What is torn free (a
    plug punched out, a fragment) is not attached. A model without any support (a free
    target) counts all its live material as attached.

    The components are recomputed only when the set of live elements changes (one
    entry is kept: the model, held by a weak reference, and its alive flags)."""
    alive = state.elem[:, SL.E_ALIVE] != 0.0
    ref = _ATTACHED_CACHE.get("model")
    if (ref is not None and ref() is model
            and np.array_equal(_ATTACHED_CACHE["alive"], alive)):
        return _ATTACHED_CACHE["value"]
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    quads = model.quads[alive]
    n = model.n_nodes
    used = np.zeros(n, dtype=bool)
    used[quads.ravel()] = True
    support = np.all(model.bc_code[:, :3] != 0, axis=1)
    if not np.any(support):
        attached = used
    else:
        a = quads.ravel()
        b = np.roll(quads, -1, axis=1).ravel()
        graph = coo_matrix((np.ones(a.size, dtype=np.int8), (a, b)), shape=(n, n))
        _, label = connected_components(graph, directed=False)
        held = np.unique(label[support & used])
        attached = used & np.isin(label, held)
    _ATTACHED_CACHE.clear()
    _ATTACHED_CACHE.update(model=weakref.ref(model), alive=alive, value=attached)
    return attached


def intact_material_ahead(model, state, b: int = 0) -> dict:
    """Where the intact material is, seen from impactor b's nose (docs/theory.md §6).

    Intact material: the nodes of live elements still attached to a support
    (:func:`attached_nodes`: a plug carried ahead of the nose is not intact material),
    each with its contact offset h (half the shell thickness), whose distance from the
    impactor's axis is at most R + h (R its largest radius: what the body can touch).
    With s the coordinate of a node along the travel direction measured from the nose
    tip, the far surface of its shell is at s + h; the nose has passed the material
    when every such surface lies behind it.

    Returns:
        ``impactor_nose_ahead_of_intact_m``: −max(s + h) over that material: positive
        once the nose is past all of it, negative while material is ahead of the nose
        (+inf when there is no intact material within the radius at all);
        ``intact_material_ahead``: 1 if some of it is ahead of the nose (max(s + h) ≥ 0),
        else 0.
    """
    live, s, h, near = _material_near(model, state, b)
    if not np.any(near):
        return {"impactor_nose_ahead_of_intact_m": math.inf, "intact_material_ahead": 0}
    lead = float(np.max(s[near] + h[near]))
    return {"impactor_nose_ahead_of_intact_m": -lead, "intact_material_ahead": int(lead >= 0.0)}


def _material_near(model, state, b: int = 0):
    """The intact nodes (:func:`intact_material_ahead`), their coordinate s along the
    travel from the nose tip, their offset h and whether each is within the body's reach."""
    d = travel_direction(model, state, b)
    live = np.flatnonzero(attached_nodes(model, state) & (state.node_active != 0))
    h = model.node_offset[live]
    if flies_sideways(model, b):
        s, outside = sideways_shadow(model, state.bodies[b], b, state.x[live])
        near = outside <= h
    else:
        tip = nose_tip(model, state, b)
        rel = state.x[live] - tip
        s = rel @ d
        rho = np.sqrt(np.maximum(np.sum(rel * rel, axis=1) - s * s, 0.0))
        near = rho <= impactor_radius(model, b) + h
    return live, s, h, near


_PLY_CACHE: dict = {}


def plies(model) -> tuple[np.ndarray, list[np.ndarray], np.ndarray]:
    """The model's ply numbers (``np.unique(model.ply)``), each ply's nodes and each
    node's ply (−1 for a node of no element), computed once per model (one entry is
    kept, the model held by a weak reference)."""
    ref = _PLY_CACHE.get("model")
    if ref is not None and ref() is model:
        return _PLY_CACHE["value"]
    numbers = np.unique(model.ply)
    nodes = [np.unique(model.quads[model.ply == p]) for p in numbers]
    node_ply = np.full(model.n_nodes, -1, dtype=np.int64)
    for p, n in zip(numbers, nodes):
        node_ply[n] = p
    _PLY_CACHE.clear()
    _PLY_CACHE.update(model=weakref.ref(model), value=(numbers, nodes, node_ply))
    return numbers, nodes, node_ply


def ply_columns(model) -> tuple[str, ...]:
    """The per-ply history columns of a plate impact (:func:`ply_row`): every ply's
    contact work, then every ply's intact-ahead flag, in ply order."""
    numbers = plies(model)[0]
    return (tuple(f"ply{p}_contact_work_part_J" for p in numbers)
            + tuple(f"ply{p}_intact_ahead" for p in numbers))


def ply_row(model, state, b: int = 0) -> dict:
    """Each ply's share of a plate impact's history row (:func:`ply_columns`):

    - ``ply{p}_contact_work_part_J``: the work the contact forces did on ply p's nodes so
      far (J, modelled part): :func:`ply_contact_work` of the row (× the symmetry factor
      at the end: the summary's ``contact_work_per_ply_J``);
    - ``ply{p}_intact_ahead``: 1 if some of ply p's intact material within the impactor's
      reach lies ahead of its nose — ``intact_material_ahead`` of
      :func:`intact_material_ahead` asked of that ply alone. A ply is *perforated* from
      the first row it reads 0 (:func:`ply_perforation_times`).
    """
    numbers, nodes, node_ply = plies(model)
    row = {f"ply{p}_contact_work_part_J": float(np.sum(state.contact_work[n]))
           for p, n in zip(numbers, nodes)}
    live, s, h, near = _material_near(model, state, b)
    ahead = np.unique(node_ply[live[near & (s + h >= 0.0)]])
    row.update({f"ply{p}_intact_ahead": int(p in ahead) for p in numbers})
    return row


def ply_perforation_times(h: dict) -> list[float | None]:
    """The time each ply was first perforated (s, in ply order; None for a ply never
    perforated): the first history row at which none of its intact material within the
    impactor's reach lies ahead of the nose (``ply{p}_intact_ahead`` = 0, :func:`ply_row`),
    the geometric test of the outcome rule asked of each ply. A history without the
    per-ply columns gives []."""
    t = np.asarray(h["time_s"], dtype=float)
    names = sorted((c for c in h if c.startswith("ply") and c.endswith("_intact_ahead")),
                   key=lambda c: int(c[3:-len("_intact_ahead")]))
    out: list[float | None] = []
    for c in names:
        rows = np.flatnonzero(np.asarray(h[c]) == 0)
        out.append(float(t[rows[0]]) if rows.size else None)
    return out


def outcome_decided_at(h: dict) -> float | None:
    """The time from which :func:`residual_velocity` of the history up to every row has
    read the run's final outcome (None when it ends undecided or without contact)."""
    final = residual_velocity(h)["outcome"]
    if final in ("undecided", "no contact"):
        return None
    t = np.asarray(h["time_s"], dtype=float)
    since = t.size - 1
    for i in range(t.size - 2, -1, -1):
        prefix = {c: np.asarray(h[c])[:i + 1] for c in OUTCOME_COLUMNS}
        if residual_velocity(prefix)["outcome"] != final:
            break
        since = i
    return float(t[since])


def _outcome(outcome: str, v_res: float, v_reb: float) -> dict:
    return {"outcome": outcome, "perforated": outcome == "perforated",
            "residual_velocity_m_per_s": float(v_res), "rebound_velocity_m_per_s": float(v_reb)}


def residual_velocity(h: dict, quiet_time: float = QUIET_TIME) -> dict:
    """Outcome of an impact from the impactor columns of a history (docs/theory.md §6).

    Exactly one of:

    - ``no contact``: the impactor never touched anything (no contact force in any row
      and its velocity never changed); not perforated; residual = its velocity;
    - ``stopped``: it turned back (its velocity along the travel reached zero) or came
      to rest (below ``REST_FRACTION`` of its initial speed) with intact material ahead
      of it; residual 0, and the speed it bounced back with as
      ``rebound_velocity_m_per_s``;
    - ``perforated``: at the end its nose is past every intact surface within its radius
      (history column ``intact_material_ahead`` = 0, see :func:`intact_material_ahead`)
      *and* contact has ended: every row for at least ``quiet_time`` (counted from the
      first light row after the last engaged one, so a coarse history interval can only
      make the call later) had a contact force below ``LIGHT_CONTACT`` of its peak and a
      velocity within ``STEADY_VELOCITY`` × v0 of the row before (a contact shorter than
      the history interval shows only there). Torn yarns rubbing the shank below that
      are not an engagement, nor is debris striking it from behind (a force along the
      travel). Residual = its final velocity;
    - ``undecided``: anything else — still in contact or pushing intact material at the
      end time (however little it has slowed): run longer. Residual = its velocity at
      the end, for information only.

    Args:
        h: history columns (arrays) ``OUTCOME_COLUMNS``; the force is of the whole
            problem but only its ratio to the peak matters.
        quiet_time: how long contact must have been light (s).

    Returns:
        dict with ``outcome`` (one of ``OUTCOMES``), ``perforated`` (bool),
        ``residual_velocity_m_per_s``, ``rebound_velocity_m_per_s``.
    """
    missing = [c for c in OUTCOME_COLUMNS if c not in h]
    if missing:
        raise InputError(f"history lacks the columns {missing} that the outcome rule needs "
                         "(a history written by an older wovenimpact: run the case again)")
    t = np.asarray(h["time_s"], dtype=float)
    v = np.asarray(h["impactor_velocity_m_per_s"], dtype=float)
    f = np.asarray(h["contact_force_full_N"], dtype=float)
    ahead = np.asarray(h["intact_material_ahead"])
    v0, v_end = float(v[0]), float(v[-1])
    touched = np.any(f != 0.0) or np.ptp(v) > 1e-12 * abs(v0)
    if not touched:
        return _outcome("no contact", v_end, 0.0)
    if np.min(v) <= 0.0:
        return _outcome("stopped", 0.0, max(0.0, -v_end))
    if ahead[-1] and v_end <= REST_FRACTION * abs(v0):
        return _outcome("stopped", 0.0, 0.0)
    jump = np.abs(np.diff(v, prepend=v0)) > STEADY_VELOCITY * abs(v0)
    engaged = np.flatnonzero((f > LIGHT_CONTACT * np.max(np.abs(f))) | jump)
    first_light = 0 if not engaged.size else int(engaged[-1]) + 1
    quiet = t[-1] - t[first_light] if first_light < t.size else -math.inf
    if not ahead[-1] and quiet >= quiet_time:
        return _outcome("perforated", v_end, 0.0)
    return _outcome("undecided", v_end, 0.0)


def ply_energies(model, state) -> list[float]:
    """Energy each ply absorbed (full-problem values, J): kinetic energy of its nodes,
    the stored energy of its elements (for eroded elements, the energy at erosion) and
    a metal ply's plastic work. Energy dissipated by yarns that broke in elements that
    did not erode is not in it (:func:`ply_contact_work` counts it)."""
    from wovenimpact.results.metal_state import element_plastic_work

    factor = symmetry_factor(model)
    plastic = element_plastic_work(model, state)
    return [float(factor * (held_energy(model, state, sel) + np.sum(plastic[sel])))
            for sel in (np.flatnonzero(model.ply == p) for p in np.unique(model.ply))]


def ply_contact_work(model, state) -> list[float]:
    """Energy each ply took through contact (full-problem values, J): the work the
    contact forces — the impactor's and the neighbouring plies' — did on its nodes
    (``State.contact_work``), as containment.layer_absorbed_energies for a casing. Unlike
    :func:`ply_energies` it counts what the ply dissipated (a metal's plastic work, the
    work of yarns that broke) and what its eroded pieces carried away; a ply that passes
    energy on to the next through contact counts only what it kept."""
    factor = symmetry_factor(model)
    return [float(factor * np.sum(state.contact_work[np.unique(model.quads[model.ply == p])]))
            for p in np.unique(model.ply)]


def held_energy(model, state, elems) -> float:
    """Energy the elements ``elems`` and their nodes hold (J, modelled part): the kinetic
    energy of their nodes plus the energy in their element state (stored, hourglass; an
    eroded element's as it held it at erosion)."""
    nodes = np.unique(model.quads[elems])
    ke = 0.5 * float(np.sum(model.node_mass[nodes] * np.sum(state.v[nodes] ** 2, axis=1)))
    return ke + float(np.sum(state.elem[elems, SL.E_U_MEMB] + state.elem[elems, SL.E_U_BEND]
                             + state.elem[elems, SL.E_U_HG]))


def ply_deflections(model, state) -> list[float]:
    """Largest displacement of each ply's nodes (m)."""
    out = []
    for p in np.unique(model.ply):
        nodes = np.unique(model.quads[model.ply == p])
        out.append(float(np.sqrt(np.max(np.sum((state.x[nodes] - model.x0[nodes]) ** 2, axis=1)))))
    return out


REACTION_COLUMNS = ("reaction_force_x_part_N", "reaction_force_y_part_N",
                    "reaction_force_z_part_N")


def supported_nodes(model) -> np.ndarray:
    """Indices of the nodes held by a support: all three translations fixed (a clamped or
    pinned edge, a casing's clamped ends). A symmetry plane's nodes (one translation fixed)
    and nodes in prescribed or rotating motion are not supports."""
    return np.flatnonzero(np.all(model.bc_code[:, :3] == IN.FIXED, axis=1))


def support_reaction(model, state) -> np.ndarray:
    """(3,) the sum of the reaction forces of the supports (:func:`supported_nodes`) at the
    state's last whole step x^n, in global axes (N, modelled part).

    It is the force whose work is booked in ``reaction_work_J``: the integrator writes a
    constrained degree of freedom's ``State.f_ext`` as m (v_new − v_old)/Δt + f_int = load + R
    (kernels/integrate.py, ``update_node``), the load being m g + the contact force, so
    R = f_ext − m g − f_contact with m the node's mass with any added by mass scaling. It is
    the force the supports exert on the structure (the structure pulls on them with −R)."""
    nodes = supported_nodes(model)
    if nodes.size == 0:
        return np.zeros(3)
    added = state.added_mass if state.added_mass.shape == (model.n_nodes,) else 0.0
    mass, _ = node_masses(model.node_mass, model.node_inertia, added)
    load = mass[nodes, None] * model.body_accel[nodes, :3] + state.f_contact[nodes]
    active = (state.node_active[nodes] != 0)[:, None]
    return np.sum(np.where(active, state.f_ext[nodes, :3] - load, 0.0), axis=0)


def reaction_row(model, state) -> dict:
    """The :data:`REACTION_COLUMNS` of a history row (:func:`support_reaction`)."""
    return dict(zip(REACTION_COLUMNS, (float(r) for r in support_reaction(model, state))))
