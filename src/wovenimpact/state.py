"""State: everything that evolves during a run, as plain NumPy arrays.

A checkpoint is a State (plus the Model digest); a restart loads it. The
central-difference scheme keeps positions at whole steps and velocities at half
steps: after ``n`` steps ``x`` is x^n and ``v``/``omega`` are v^{n−1/2}/ω^{n−1/2};
``dt`` is the last step Δt^{n−1/2}. Energy accumulators are in ``energy``
(indices below). docs/theory.md §3.
"""

from __future__ import annotations

from dataclasses import MISSING, dataclass, field, fields

import numpy as np

from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import j2_layout as JL
from wovenimpact.kernels import rigid_body as RB
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels import solid_layout as HL
from wovenimpact.kernels.contact_plane import N_PLANE_STATE, PL_X

# indices of State.energy (J)
W_INT = 0  # work of the internal forces (membrane, bending, shear, hourglass)
W_EXT = 1  # work of external forces, body forces, support reactions and contact on nodes
KINETIC = 2  # kinetic energy at the last whole step (translational + rotational)
ERODED_KINETIC = 3  # kinetic energy of nodes that left the model (lost their last element;
#                     with run.eroded_nodes = "keep" such nodes stay, and this stays 0)
ERODED_INTERNAL = 4  # stored energy of elements at their erosion
KINETIC0 = 5  # kinetic energy at t = 0 (nodes and rigid bodies)
BODY_KINETIC = 6  # kinetic energy of the rigid bodies at the last whole step
CONTACT_WORK = 7  # work of the contact forces on nodes and bodies (−penalty energy)
NODE_CONTACT_WORK = 8  # the part of W_EXT done by contact forces on the nodes
CONTACT_PENALTY = 9  # energy of the contact springs at the last whole step; the rest
#                      of −CONTACT_WORK was dissipated by contact dashpots and friction
MASS_SCALING = 10  # kinetic energy added with the mass of mass scaling (an input)
N_ENERGY = 11
ENERGY_NAMES = ("internal_work", "external_work", "kinetic", "eroded_kinetic",
                "eroded_internal", "initial_kinetic", "body_kinetic", "contact_work",
                "node_contact_work", "contact_penalty", "mass_scaling")


@dataclass
class State:
    """Evolving arrays of a run (SI).

    Attributes:
        t: time of ``x`` (s).
        step: number of steps taken.
        dt: last step Δt^{n−1/2} (s); 0 before the first step.
        x: (n_nodes, 3) positions x^n.
        v: (n_nodes, 3) velocities v^{n−1/2}.
        omega: (n_nodes, 3) angular velocities ω^{n−1/2} (global axes).
        elem: (n_elems, N_ELEM_STATE) element state (shell_layout).
        mat: (n_rows, max(1, Model.point_width)) material state, one row per point:
            element e's points in rows Model.mat_row[e] … mat_row[e + 1] − 1.
        f_int: (n_nodes, 6) internal forces and moments at x^n.
        f_ext: (n_nodes, 6) external forces, body forces and reactions at x^n.
        node_active: (n_nodes,) 1 while a node is in the model: it belongs to at least
            one live element, or (``run.eroded_nodes = "keep"``) it lost its last one
            and flies on as a free node.
        energy: (N_ENERGY,) accumulators (indices in this module).
        dt_first: the first stable step (s), reference of the Δt-collapse check.
        bodies: (n_bodies, N_BODY_STATE) rigid impactors (kernels.rigid_body layout).
        f_contact: (n_nodes, 3) contact forces on the nodes at x^n (for their work).
        mass_ratio: (n_elems,) added-mass ratio r_e of mass scaling (kernels.mass_scaling).
        added_mass: (n_nodes,) mass added to each node by mass scaling (kg).
        contact_work: (n_nodes,) work the contact forces did on each node so far (J,
            the trapezoid rule of ``force_pair_power``): the energy a node's part took
            from contact, which it holds, dissipated or carried away when it eroded.
        contact_books: (2, 3, P, P) the work of the contact forces split by interface
            and by part of the pair force (J; wovenimpact.interfaces, theory §6,
            "Contact energy per interface"): [0][kind, a, b] the energy the springs
            (kind 0), dashpots (1) and friction (2) of the pairs of a node of part a and
            a segment or body of part b took out of the structure up to the last whole
            step, [1] the same of the last step's forces against the velocities after it,
            moved into [0] at the next step.
        hex: (n_hexes, N_HEX_STATE) state of the hexahedra (solid_layout ``H_*``: the
            rotated Kirchhoff stress, the stretch U, the hourglass forces, the Cauchy
            stress, the stored and hourglass energies, the last element step, the volume).
        planes: (n_planes, N_PLANE_STATE) the rigid plates (kernels.contact_plane
            ``PL_*``: position of the plane's point, its velocity of the last step, the
            force of the nodes on it at x^n).
    """

    t: float
    step: int
    dt: float
    x: np.ndarray
    v: np.ndarray
    omega: np.ndarray
    elem: np.ndarray
    mat: np.ndarray
    f_int: np.ndarray
    f_ext: np.ndarray
    node_active: np.ndarray
    energy: np.ndarray
    dt_first: float = 0.0
    bodies: np.ndarray = field(default_factory=lambda: np.zeros((0, RB.N_BODY_STATE)))
    f_contact: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    mass_ratio: np.ndarray = field(default_factory=lambda: np.zeros(0))
    added_mass: np.ndarray = field(default_factory=lambda: np.zeros(0))
    contact_work: np.ndarray = field(default_factory=lambda: np.zeros(0))
    contact_books: np.ndarray = field(default_factory=lambda: np.zeros((2, 3, 0, 0)))
    hex: np.ndarray = field(default_factory=lambda: np.zeros((0, HL.N_HEX_STATE)))
    planes: np.ndarray = field(default_factory=lambda: np.zeros((0, N_PLANE_STATE)))

    def copy(self) -> State:
        return State(**{f.name: (getattr(self, f.name).copy() if isinstance(
            getattr(self, f.name), np.ndarray) else getattr(self, f.name)) for f in fields(self)})

    def arrays(self) -> dict[str, np.ndarray]:
        """All fields as arrays (scalars as 0-d arrays): what a checkpoint stores."""
        return {f.name: np.asarray(getattr(self, f.name)) for f in fields(self)}

    @classmethod
    def from_arrays(cls, data) -> State:
        kw = {}
        for f in fields(cls):
            if f.name not in data and f.default_factory is not MISSING:
                continue  # an array added since the file was written: its default
            a = np.asarray(data[f.name])
            kw[f.name] = a.item() if a.ndim == 0 else a.copy()
        kw["step"] = int(kw["step"])
        return cls(**kw)

    def equals(self, other: State) -> bool:
        """Bitwise equality of every field (determinism and restart checks)."""
        for f in fields(self):
            a, b = np.asarray(getattr(self, f.name)), np.asarray(getattr(other, f.name))
            if a.shape != b.shape or a.tobytes() != b.tobytes():
                return False
        return True


def initial_material_rows(model) -> np.ndarray:
    """``State.mat`` at the start: each element's rows (``Model.mat_row``) from its
    section's initial point blocks (``Model.section_state0``)."""
    width = max(1, model.point_width)
    counts = np.diff(model.mat_row)
    section = np.repeat(model.elem_section, counts)  # of each row
    point = np.arange(model.mat_row[-1]) - np.repeat(model.mat_row[:-1], counts)
    blocks = model.section_state0.shape[1] // width
    per_point = model.section_state0[:, :blocks * width].reshape(-1, blocks, width)
    rows = np.ascontiguousarray(per_point[section, point])
    if model.elem_failure.shape[0] == model.n_elems:
        # each point's failure columns from its element's lengths (theory §1.4, §7.3)
        elem = np.repeat(np.arange(model.n_elems), counts)
        kind = model.mat_kind[model.sections[section, SL.C_MAT].astype(np.int64)]
        fab = np.flatnonzero(kind == SL.MAT_FABRIC)
        if fab.size:
            rows[fab, FL.S_TU_SCALE:FL.S_TU_SCALE + 6] = model.elem_failure[elem[fab]]
        j2 = np.flatnonzero(kind == SL.MAT_J2)
        if j2.size:
            rows[j2, JL.S_FRAC_SCALE:JL.S_FRAC_SCALE + 2] = model.elem_failure[elem[j2], :2]
            rows[j2, JL.S_HINGE] = model.elem_failure[elem[j2], 2]
    return rows


def initial_state(model, velocity=None, angular_velocity=None) -> State:
    """State at t = 0: reference positions, the given velocity field, materials at rest.

    Args:
        model: the Model.
        velocity: (3,) or (n_nodes, 3) initial velocities (m/s).
        angular_velocity: (3,) or (n_nodes, 3) initial nodal spins (rad/s).
    """
    from wovenimpact.interfaces import empty_books

    n, ne = model.n_nodes, model.n_elems
    v = np.zeros((n, 3)) if velocity is None else np.broadcast_to(
        np.asarray(velocity, dtype=float), (n, 3)).copy()
    w = np.zeros((n, 3)) if angular_velocity is None else np.broadcast_to(
        np.asarray(angular_velocity, dtype=float), (n, 3)).copy()
    elem = np.zeros((ne, SL.N_ELEM_STATE))
    for col in (SL.E_F, *range(SL.E_FG, SL.E_FG + 16, 4)):  # F = I at the centre and Gauss points
        elem[:, col] = 1.0
        elem[:, col + 3] = 1.0
    elem[:, SL.E_ALIVE] = 1.0
    mat = initial_material_rows(model)
    energy = np.zeros(N_ENERGY)
    ke = 0.5 * (np.sum(model.node_mass[:, None] * v * v) + np.sum(model.node_inertia[:, None] * w * w))
    bodies = model.body_state0.copy()
    ke_b = 0.0
    for b, p in zip(bodies, model.body_params):
        spin = b[RB.B_W:RB.B_W + 3]
        inertia = np.array([p[RB.BP_I_AXIAL], p[RB.BP_I_TRANS], p[RB.BP_I_TRANS]])
        ke_b += 0.5 * p[RB.BP_MASS] * float(b[RB.B_V:RB.B_V + 3] @ b[RB.B_V:RB.B_V + 3])
        ke_b += 0.5 * float(spin @ (inertia * spin))
    energy[KINETIC] = ke
    energy[BODY_KINETIC] = ke_b
    energy[KINETIC0] = ke + ke_b
    return State(t=0.0, step=0, dt=0.0, x=model.x0.copy(), v=v, omega=w, elem=elem, mat=mat,
                 f_int=np.zeros((n, 6)), f_ext=np.zeros((n, 6)),
                 node_active=np.ones(n, dtype=np.int8), energy=energy, bodies=bodies,
                 f_contact=np.zeros((n, 3)), mass_ratio=np.zeros(ne), added_mass=np.zeros(n),
                 contact_work=np.zeros(n), contact_books=empty_books(model),
                 hex=initial_hex_rows(getattr(model, "n_hexes", 0)),
                 planes=initial_plane_rows(model))


def initial_plane_rows(model) -> np.ndarray:
    """``State.planes`` at the start: each rigid plate at its point, at rest."""
    planes = getattr(model, "rigid_planes", ())
    rows = np.zeros((len(planes), N_PLANE_STATE))
    for row, plane in zip(rows, planes):
        row[PL_X:PL_X + 3] = plane.point
    return rows


def initial_hex_rows(n: int) -> np.ndarray:
    """``State.hex`` at the start: n unstrained hexahedra (U = I, the rest zero)."""
    rows = np.zeros((n, HL.N_HEX_STATE))
    rows[:, HL.H_U:HL.H_U + 3] = 1.0
    return rows


def rigid_rotation_velocity(x: np.ndarray, omega, centre=(0.0, 0.0, 0.0)) -> np.ndarray:
    """v = ω × (x − c): the velocity field of a rigid rotation (rad/s about ``centre``)."""
    return np.cross(np.asarray(omega, dtype=float), x - np.asarray(centre, dtype=float))
