"""Contact stage of the step: impactors and rigid plates on shells and solids, and shells
and solids on each other (docs/model.md §4, docs/solid.md §6).

Called between the element stage and the node update. It fills ``ws.f_con`` (the
contact forces on the nodes at x^n, external loads of the shells) and the resultant
force and torque on each rigid body, then advances the bodies by central differences
(kernels.rigid_body). Penalty stiffnesses k = β m/Δt² use the step about to be taken,
so contact never limits the stable step (ω Δt ≤ √(2β) per contact spring); each pair
also has a dashpot (ζ of critical) and optional Coulomb friction.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from wovenimpact.interfaces import hex_parts, n_parts, part_arrays, solid_body_count
from wovenimpact.kernels import rigid_body as RB
from wovenimpact.kernels.bundles import BodyContact, BodyContactOut, ContactNodes, EnergyBooks
from wovenimpact.kernels.contact_energy import book_body_pairs
from wovenimpact.kernels.contact_plane import PL_F, PL_V, PL_X, plane_contact_forces, plane_resultant
from wovenimpact.kernels.integrate import smooth_step
from wovenimpact.kernels.contact_rigid import add_body_forces, rigid_contact_forces
from wovenimpact.kernels.gather import nodes_with_live_elements, node_sum
from wovenimpact.kernels.rigid_body import advance_body
from wovenimpact.model.model import flies_sideways
from wovenimpact.state import W_EXT


@dataclass
class ContactBuffers:
    """Preallocated arrays of the contact stage of one Model."""

    f_con: np.ndarray  # (n, 3) total contact force per node
    f_body: np.ndarray  # (n, 3) contact force of one body on each node
    e_body: np.ndarray  # (n,) penalty energy per node (one body)
    active: np.ndarray  # (n,) int8: nodes that take contact forces this step
    shells: object | None  # ShellContact driver, if surfaces can touch each other
    shell_energy: float = 0.0
    shell_pairs: int = 0
    penalty_energy: float = 0.0  # Σ ½ k g² of every body and shell pair at x^n (J)
    # the energy books per interface (wovenimpact.interfaces, kernels.contact_energy):
    # the part of each node, element and body, and of each body's pairs at x^n the
    # spring, dashpot, normal, force and powers of each node in contact (contact_rigid
    # ``parts``) and the list of those nodes
    node_part: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    elem_part: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    body_part: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    n_parts: int = 0
    body_parts: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 11)))
    body_list: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=np.int64))
    body_count: list = field(default_factory=list)
    # the part of each contact segment (the shells' elem_part, then the solids' faces')
    seg_part: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    # the rigid plates: which nodes each meets, the force on each at x^n (N), and as for
    # a body the parts of its pairs, the list and count of its nodes in contact
    plane_meets: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=np.int8))
    plane_force: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    plane_parts: np.ndarray = field(default_factory=lambda: np.zeros((0, 0, 11)))
    plane_list: np.ndarray = field(default_factory=lambda: np.zeros((0, 0), dtype=np.int64))
    plane_count: list = field(default_factory=list)

    @classmethod
    def for_model(cls, model) -> ContactBuffers:
        """Buffers and, when the model has two or more surfaces (``model.ply`` and the
        solid bodies) or self-contact, the contact of ``model.shell_contact`` between
        them (the solids' exterior faces as one-sided segments; docs/solid.md §6)."""
        n = model.n_nodes
        shells = None
        p = model.shell_contact
        n_surfaces = np.unique(model.ply).size + solid_body_count(model)
        if p.enabled and (n_surfaces > 1 or p.self_contact):
            from wovenimpact.solver.shell_contact import ShellContact

            shells = ShellContact(model, beta=p.beta, damping=p.damping, friction=p.friction,
                                  damping_mode=p.damping_mode, self_contact=p.self_contact)
        nb = model.body_params.shape[0]
        node_part, elem_part, body_part = part_arrays(model)
        seg_part = elem_part
        if shells is not None and shells.quads.shape[0] > shells.n_shells:
            seg_part = np.concatenate([elem_part, hex_parts(model)[model.solid.face_hex]])
        planes = getattr(model, "rigid_planes", ())
        npl = len(planes)
        return cls(np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n),
                   np.zeros(n, dtype=np.int8), shells, node_part=node_part,
                   elem_part=elem_part, body_part=body_part, n_parts=n_parts(model),
                   body_parts=np.zeros((nb, n, 11)),
                   body_list=np.zeros((nb, n), dtype=np.int64), body_count=[0] * nb,
                   seg_part=seg_part,
                   plane_meets=np.array([pl.node_mask(n) for pl in planes],
                                        dtype=np.int8).reshape(npl, n),
                   plane_force=np.zeros((npl, 3)), plane_parts=np.zeros((npl, n, 11)),
                   plane_list=np.zeros((npl, n), dtype=np.int64), plane_count=[0] * npl)


def body_frame(state_row, params):
    """(tip position, unit axis tip → tail) of a body at x^n."""
    axis = state_row[RB.B_R:RB.B_R + 9].reshape(3, 3)[:, 0]
    tip = state_row[RB.B_X:RB.B_X + 3] - params[RB.BP_TIP] * axis
    return tip, axis


def contact_forces(model, state, cb: ContactBuffers, dt: float, elem_alive,
                   eroded_now: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Contact forces on the nodes (into cb.f_con) and (force, torque) on every body.

    ``elem_alive`` (n_elems,) are the elements alive at the end of this step's element
    stage; when ``eroded_now`` of them eroded in it, the nodes they left without a live
    element take no contact force (they leave the model in this step's node update,
    so nothing could react to it: the body would be pushed by a node that is gone) —
    unless ``run.eroded_nodes = "keep"``: they then stay in the model as free nodes and
    take contact like any active node, against the bodies and, as slave nodes, the live
    segments of the other surfaces (with the offsets and penalty masses they had).

    Penalty stiffness k = β m / Δt_k² with Δt_k = max(Δt, Δt_first): it follows a step
    that grows (so that ω Δt stays below 2) but not one that falls. When a crushed
    element cut the step, every spring already compressed stiffened at once and gave
    its new energy back: 16 plies struck at 200 m/s, the step fell from 1.5e-7 to
    4.3e-8 s in 0.5 µs, the contact did +20 J of work, the FSP dropped from 144 to 66
    m/s and the energy error reached 2.7 % by 12 µs (6e-4 with this rule). The springs'
    energy goes to ``cb.penalty_energy``; the dashpots and friction (theory §6.2–6.3)
    dissipate the rest of the contact forces' work.
    """
    cb.f_con[:] = 0.0
    dt = max(dt, state.dt_first)
    active = state.node_active
    if eroded_now and model.eroded_nodes != "keep":
        nodes_with_live_elements(model.node_ptr, model.node_elem, elem_alive, state.node_active,
                                 cb.active)
        active = cb.active
    resultants = []
    cb.penalty_energy = 0.0
    for b in range(model.body_params.shape[0]):
        p = model.body_params[b]
        row = state.bodies[b]
        tip, axis = body_frame(row, p)
        rot = row[RB.B_R:RB.B_R + 9].reshape(3, 3)
        spin = rot @ row[RB.B_W:RB.B_W + 3]
        prof = model.body_profiles[b, : int(p[RB.BP_NPTS])]
        nodes = ContactNodes(x=state.x, v=state.v, active=active, mass=model.node_mass,
                             offset=model.node_offset)
        body = BodyContact(
            tip=tip, axis=axis, velocity=np.ascontiguousarray(row[RB.B_V:RB.B_V + 3]),
            spin=spin, centre=np.ascontiguousarray(row[RB.B_X:RB.B_X + 3]),
            prof_z=np.ascontiguousarray(prof[:, 0]), prof_r=np.ascontiguousarray(prof[:, 1]),
            reach=p[RB.BP_REACH] + float(model.node_offset.max()), mass=p[RB.BP_MASS],
            beta=p[RB.BP_BETA], zeta=p[RB.BP_DAMPING], mu=p[RB.BP_FRICTION])
        out = BodyContactOut(force=cb.f_body, energy=cb.e_body, parts=cb.body_parts[b],
                             contact_list=cb.body_list[b])
        cb.body_count[b] = rigid_contact_forces(nodes, body, dt, out)
        cb.penalty_energy += node_sum(cb.e_body)
        fx, fy, fz, tx, ty, tz = add_body_forces(state.x, row[RB.B_X:RB.B_X + 3], cb.f_body,
                                                 cb.f_con)
        force = np.array([fx, fy, fz])
        if p[RB.BP_AXIAL_ONLY]:  # symmetry planes through the travel: no torque, no drift
            if flies_sideways(model, b):  # the line of travel is across the axis
                d = rot @ model.body_travel[b]
                force = (force @ d) * d
            else:
                force = (force @ axis) * axis
            torque = np.zeros(3)
        else:
            torque = np.array([tx, ty, tz])
        resultants.append((force, torque))
    for j, plane in enumerate(getattr(model, "rigid_planes", ())):
        row = state.planes[j]
        nodes = ContactNodes(x=state.x, v=state.v, active=active, mass=model.node_mass,
                             offset=model.node_offset)
        out = BodyContactOut(force=cb.f_body, energy=cb.e_body, parts=cb.plane_parts[j],
                             contact_list=cb.plane_list[j])
        cb.plane_count[j] = plane_contact_forces(
            nodes, np.ascontiguousarray(row[PL_X:PL_X + 3]), plane.unit_normal,
            np.ascontiguousarray(row[PL_V:PL_V + 3]), cb.plane_meets[j], plane.beta,
            plane.damping, plane.friction, dt, out)
        cb.penalty_energy += node_sum(cb.e_body)
        cb.plane_force[j] = plane_resultant(cb.f_body, cb.plane_list[j], cb.plane_count[j],
                                            cb.f_con)
        resultants.append((cb.plane_force[j], None))
    if cb.shells is not None:
        cb.shell_energy, cb.shell_pairs = cb.shells.forces(
            state.x, state.v, dt, elem_alive, active, cb.f_con, accumulate=True)
        cb.penalty_energy += cb.shell_energy
    return resultants


def book_contact_work(model, state, cb: ContactBuffers, w_before: float, books_before,
                      w_after: float, books_after) -> None:
    """Book the work of this step's contact forces (the pairs of :func:`contact_forces`)
    by interface and kind (kernels.contact_energy) as the solver's trapezoid rule counts
    it: against the velocities they were computed with (v^{n−1/2}; the force kernels
    wrote those powers) times ``w_before`` = ½ Δt^{n−1/2} into ``books_before``, and
    against the State's velocities after the node update (the nodes' v^{n+1/2}, the
    bodies' translation) times ``w_after`` = ½ Δt^{n+1/2} into ``books_after`` (N_KINDS,
    P, P each). Called once per step, after the bodies moved."""
    if cb.shells is not None:
        cb.shells.book(state.v, w_before, books_before, w_after, books_after, cb.node_part,
                       cb.seg_part)
    books = EnergyBooks(w_before=float(w_before), before=books_before, w_after=float(w_after),
                        after=books_after)
    for b, count in enumerate(cb.body_count):
        if count == 0:
            continue
        row = state.bodies[b]
        book_body_pairs(state.v, np.ascontiguousarray(row[RB.B_V:RB.B_V + 3]),
                        cb.body_parts[b], cb.body_list[b], count,
                        model.body_params[b, RB.BP_FRICTION] > 0.0, cb.node_part,
                        int(cb.body_part[b]), books)
    nb = model.body_params.shape[0]
    for j, plane in enumerate(getattr(model, "rigid_planes", ())):
        if cb.plane_count[j] == 0:
            continue
        # the plane's velocity after the node update (advance_bodies moved it on)
        book_body_pairs(state.v, np.ascontiguousarray(state.planes[j, PL_V:PL_V + 3]),
                        cb.plane_parts[j], cb.plane_list[j], cb.plane_count[j],
                        plane.friction > 0.0, cb.node_part, int(cb.body_part[nb + j]), books)


def advance_bodies(model, state, resultants, dt_old: float, dt_new: float) -> tuple[float, float]:
    """Advance every body, then every rigid plate; returns (the bodies' kinetic energy at
    t^n, the work of the contact forces on bodies and plates over [t^{n−1}, t^n],
    trapezoid rule). ``resultants``: the bodies' (force, torque), then the plates'
    (force, None), of :func:`contact_forces`.

    A plate moves at its prescribed velocity V^{n+1/2} = a(t^n + ½ Δt^{n+1/2}) V (a the
    case's smooth-step amplitude, as a prescribed nodal velocity), c^{n+1} = c^n +
    Δt^{n+1/2} V^{n+1/2}. What its driver puts in is the opposite of the work of the
    contact forces on it: it is booked as external work (``W_EXT``, the reaction work of
    a prescribed motion) beside the contact work, so the balance counts it as an input
    and the contact energy holds the springs, dashpots and friction only."""
    ke = 0.0
    work = 0.0
    nb = model.body_params.shape[0]
    for j, plane in enumerate(getattr(model, "rigid_planes", ())):
        row = state.planes[j]
        force = resultants[nb + j][0]
        w = 0.5 * float((row[PL_F:PL_F + 3] + force) @ (dt_old * row[PL_V:PL_V + 3]))
        work += w
        state.energy[W_EXT] -= w
        row[PL_F:PL_F + 3] = force
        amplitude = smooth_step(state.t + 0.5 * dt_new, model.ramp_time)
        row[PL_V:PL_V + 3] = amplitude * np.asarray(plane.velocity, dtype=float)
        row[PL_X:PL_X + 3] += dt_new * row[PL_V:PL_V + 3]
    for b, (force, torque) in enumerate(resultants[:nb]):
        p = model.body_params[b]
        row = state.bodies[b]
        du = dt_old * row[RB.B_V:RB.B_V + 3]
        work += 0.5 * float((row[RB.B_F:RB.B_F + 3] + force) @ du)
        row[RB.B_F:RB.B_F + 3] = force
        ke += advance_body(row, p[RB.BP_MASS], p[RB.BP_I_AXIAL], p[RB.BP_I_TRANS],
                           np.ascontiguousarray(force), np.ascontiguousarray(torque),
                           dt_old, dt_new)
    return ke, work
