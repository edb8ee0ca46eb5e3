"""Model: the immutable arrays a run is made of (geometry, sections, BCs, masses).

``build_model`` turns a mesh (nodes, quads), section assignments and boundary
conditions into a :class:`Model`: it packs the material tables, precomputes each
element's reference shape-function gradients in its material frame (warp along
the projected ``warp_direction``), lumps the masses and builds the node → element
map through which nodal forces are gathered (CSR; deterministic, no scatter).
docs/theory.md §2 (element) and §3 (integration).
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.impactor import BODY_PENALTY_SCALE, SIDEWAYS_COS, Impactor
from wovenimpact.kernels.integrate import FIXED, PRESCRIBED, ROTATING
from wovenimpact.kernels import fabric_layout as FP
from wovenimpact.kernels import rigid_body as RB
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.materials.fabric import FabricParameters
from wovenimpact.materials.fabric import initial_state as fabric_initial_state
from wovenimpact.materials.fabric import regularised_columns as fabric_regularised_columns
from wovenimpact.materials.metal import MetalParameters, j2_parameter_row
from wovenimpact.materials.metal import initial_state as j2_initial_state
from wovenimpact.materials.metal import regularised_columns as j2_regularised_columns
from wovenimpact.model.solid import NO_SOLIDS, SolidPart, section_indices

DOF_NAMES = ("ux", "uy", "uz", "rx", "ry", "rz")


def is_plastic(material) -> bool:
    """A J2 plastic metal (kernels.j2)."""
    return isinstance(material, MetalParameters) and material.kind == "j2_plastic"
MEMBRANE_POINTS = {"full": SL.MEMBRANE_FULL, "reduced": SL.MEMBRANE_REDUCED}
# what becomes of a node that loses its last live element (Model.eroded_nodes)
ERODED_NODES = ("remove", "keep")
# a rigid body's direction of travel in its own frame (Model.body_travel): nose first,
# along −(axis of revolution), or sideways, along the second body axis
DEFAULT_TRAVEL = (-1.0, 0.0, 0.0)
SIDEWAYS_TRAVEL = (0.0, 1.0, 0.0)
GAUSS = 1.0 / np.sqrt(3.0)  # 2×2 Gauss points at (±1/√3, ±1/√3), weights 1
GAUSS_XI = np.array([-GAUSS, GAUSS, GAUSS, -GAUSS])  # point g next to corner g
GAUSS_ETA = np.array([-GAUSS, -GAUSS, GAUSS, GAUSS])
CORNER_XI = np.array([-1.0, 1.0, 1.0, -1.0])
CORNER_ETA = np.array([-1.0, -1.0, 1.0, 1.0])


@dataclass(frozen=True)
class Section:
    """A shell section: thickness, material and the stiffnesses the material lacks.

    Attributes:
        material: fabric (crossover kernel) or an elastic metal.
        thickness: t (m); default for a fabric: 4 h0 (its shell thickness).
        bending_modulus: E_b of M = E_b t³/(12(1 − ν_b²)) κ (Pa); default the
            metal's E; for a fabric it must be given (docs/model.md §1.8).
        bending_poisson: ν_b (—); default the metal's ν, 0 for a fabric.
        transverse_shear_modulus: G of Q = k G t γ (Pa); default the metal's G; for
            a fabric it must be given (thesis: 3.28 GPa).
        shear_factor: k (—), 5/6.
        hourglass: r, hourglass stiffness coefficient (—), 0.05.
        areal_mass: μ (kg/m²); default ρ t (metal) or the fabric's areal mass.
        points: 1 = resultant section (membrane from the material at the mid-surface,
            elastic bending M = D κ with the bending modulus); an odd n ≥ 3 = the
            material evaluated at n Simpson points through the thickness (the
            thesis's S4R + VUMAT section), its bending stiffness then comes from the
            material itself. Default 5 for plastic metals (which need it), else 1.
        membrane: ``"full"`` = 2×2 Gauss points in the plane (no in-plane hourglass
            modes, theory §4.5), ``"reduced"`` = one point and hourglass springs;
            default full for fabric sections, reduced for metals.
    """

    material: FabricParameters | MetalParameters
    thickness: float | None = None
    bending_modulus: float | None = None
    bending_poisson: float | None = None
    transverse_shear_modulus: float | None = None
    shear_factor: float = 5.0 / 6.0
    hourglass: float = 0.05
    areal_mass: float | None = None
    points: int | None = None
    membrane: str | None = None

    def points_for(self, m) -> int:
        """Through-thickness points: as given, else 5 for a plastic metal (docs/model.md §2)
        and 1 (resultant section) otherwise."""
        if self.points is not None:
            return self.points
        return 5 if is_plastic(m) else 1

    def row(self, mat_index: int, name: str) -> np.ndarray:
        """The section's row of ``Model.sections`` (layout in shell_layout)."""
        m = self.material
        r = np.zeros(SL.N_SECTION)
        if isinstance(m, FabricParameters):
            t = m.shell_thickness if self.thickness is None else self.thickness
            mu = m.areal_mass if self.areal_mass is None else self.areal_mass
            if self.transverse_shear_modulus is None or (
                self.bending_modulus is None and self.points_for(m) == 1
            ):
                raise InputError(
                    f"section {name!r}: a fabric section needs transverse_shear_modulus "
                    "(e.g. '3.28 GPa') and, unless it is integrated through the thickness "
                    "(points ≥ 3), bending_modulus (the small elastic bending stiffness of "
                    "docs/model.md §1.8, e.g. '1 GPa')"
                )
            e_b = 1.0 if self.bending_modulus is None else self.bending_modulus  # unused if points > 1
            nu_b = self.bending_poisson or 0.0
            g = self.transverse_shear_modulus
        else:
            if self.thickness is None:
                raise InputError(f"section {name!r}: a metal section needs a thickness")
            t = self.thickness
            mu = m.density * t if self.areal_mass is None else self.areal_mass
            e_b = m.modulus if self.bending_modulus is None else self.bending_modulus
            nu_b = m.poisson if self.bending_poisson is None else self.bending_poisson
            g = m.shear_modulus if self.transverse_shear_modulus is None else (
                self.transverse_shear_modulus
            )
        for label, value in (("thickness", t), ("areal_mass", mu), ("bending_modulus", e_b),
                             ("transverse_shear_modulus", g), ("shear_factor", self.shear_factor)):
            if not value > 0.0:
                raise InputError(f"section {name!r}: {label} = {value!r} must be > 0")
        points = self.points_for(m)
        if not (points == 1 or (points >= 3 and points % 2 == 1)):
            raise InputError(f"section {name!r}: points = {points!r}; valid: 1 (resultant "
                             "section) or an odd number ≥ 3 (Simpson integration)")
        if points == 1 and is_plastic(m):
            raise InputError(f"section {name!r}: material {m.name!r} is plastic; its section "
                             "is integrated through the thickness: points must be an odd "
                             "number ≥ 3 (default 5)")
        if not 0.0 <= self.hourglass < 1.0:
            raise InputError(f"section {name!r}: hourglass = {self.hourglass!r}; valid: 0 ≤ r < 1")
        membrane = self.membrane or ("full" if isinstance(m, FabricParameters) else "reduced")
        if membrane not in MEMBRANE_POINTS:
            raise InputError(f"section {name!r}: membrane = {membrane!r}; valid: "
                             f"{' or '.join(repr(k) for k in MEMBRANE_POINTS)}")
        r[SL.C_THICK] = t
        r[SL.C_MAT] = mat_index
        r[SL.C_AREAL_MASS] = mu
        r[SL.C_BEND_E] = e_b
        r[SL.C_BEND_NU] = nu_b
        r[SL.C_SHEAR_G] = g
        r[SL.C_SHEAR_K] = self.shear_factor
        r[SL.C_HOURGLASS] = self.hourglass
        r[SL.C_POINTS] = points
        r[SL.C_INPLANE] = MEMBRANE_POINTS[membrane]
        return r


@dataclass
class BoundaryConditions:
    """Per-node, per-DOF constraints: free, fixed (v = 0) or prescribed velocity.

    A prescribed velocity follows the smooth-step amplitude of thesis Fig. 8-3,
    A(t) = ξ³(10 − 15ξ + 6ξ²), ξ = min(t / ramp_time, 1) (A = 1 if ramp_time = 0).
    """

    n_nodes: int
    ramp_time: float = 0.0
    code: np.ndarray = field(init=False)
    velocity: np.ndarray = field(init=False)

    def __post_init__(self) -> None:
        self.code = np.zeros((self.n_nodes, 6), dtype=np.int8)
        self.velocity = np.zeros((self.n_nodes, 6))

    def fix(self, nodes, dofs=(0, 1, 2, 3, 4, 5)) -> BoundaryConditions:
        """Hold ``dofs`` (0–2 translations, 3–5 rotations) of ``nodes`` at rest."""
        idx = np.asarray(nodes, dtype=np.int64)
        for d in dofs:
            self.code[idx, d] = FIXED
            self.velocity[idx, d] = 0.0
        return self

    def symmetry(self, nodes, normal_axis: int) -> BoundaryConditions:
        """Symmetry plane with normal along axis 0/1/2: u_n = 0 and the two in-plane rotations."""
        rot = [3 + a for a in range(3) if a != normal_axis]
        return self.fix(nodes, (normal_axis, *rot))

    def rotate(self, nodes, omega, centre=(0.0, 0.0, 0.0)) -> BoundaryConditions:
        """Turn ``nodes`` rigidly at ``omega`` (rad/s vector) about the axis through
        ``centre`` (all six DOFs; times the amplitude): a driven hub, a blade root."""
        idx = np.asarray(nodes, dtype=np.int64)
        self.code[idx, :] = ROTATING
        self.velocity[idx, :3] = np.asarray(omega, dtype=float)
        self.velocity[idx, 3:] = np.asarray(centre, dtype=float)
        return self

    def prescribe(self, nodes, dof: int, velocity: float) -> BoundaryConditions:
        """Drive ``dof`` of ``nodes`` at ``velocity`` (m/s or rad/s) times the amplitude."""
        idx = np.asarray(nodes, dtype=np.int64)
        self.code[idx, dof] = PRESCRIBED
        self.velocity[idx, dof] = velocity
        return self


@dataclass(frozen=True)
class RigidBody:
    """A rigid impactor placed in the model.

    Attributes:
        impactor: its geometry and density.
        tip: nose-tip position at t = 0 (m).
        direction: direction of travel (the nose leads); normalised here.
        speed: initial speed along ``direction`` (m/s).
        mass: if given, the mass (kg) the density is scaled to.
        beta: penalty factor of the node contact stiffness k = β m_node/Δt².
        damping: contact damping ζ, a fraction of critical (2 √(k m_node)) per node.
        friction: Coulomb coefficient μ between the body and the nodes.
        fraction: the share of the body in the model (0.25 in a quarter model: mass
            and inertia are scaled by it).
        axial_only: the body translates along its line of travel only, without
            rotating (a body cut by symmetry planes through its line of travel).
        axis: the body's axis of revolution (tip → tail), perpendicular to
            ``direction``: the body flies sideways (a cylinder lying across a strip
            strikes it with its side); ``tip`` is then the point of the axis where the
            profile starts. None (default): the axis is −direction, nose first.
    """

    impactor: Impactor
    tip: tuple[float, float, float]
    direction: tuple[float, float, float] = (0.0, 0.0, -1.0)
    speed: float = 0.0
    mass: float | None = None
    beta: float = BODY_PENALTY_SCALE
    damping: float = 1.0
    friction: float = 0.0
    fraction: float = 1.0
    axial_only: bool = False
    axis: tuple[float, float, float] | None = None

    @property
    def travel_in_body(self) -> tuple[float, float, float]:
        """The direction of travel in the body's frame (first axis: the axis of
        revolution): (−1, 0, 0) nose first, (0, 1, 0) sideways (:meth:`pack`)."""
        return DEFAULT_TRAVEL if self.axis is None else SIDEWAYS_TRAVEL

    def pack(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(parameter row, profile polyline, initial state row) for the Model/State."""
        imp = self.impactor
        m, zc, i_a, i_t = imp.mass_properties()
        scale = (1.0 if self.mass is None else self.mass / m) * self.fraction
        m, i_a, i_t = m * scale, i_a * scale, i_t * scale
        travel = np.asarray(self.direction, dtype=float)
        travel = travel / np.linalg.norm(travel)
        if self.axis is None:
            axis = -travel  # body axis: tip → tail
            helper = (np.array([1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9
                      else np.array([0.0, 1.0, 0.0]))
            e2 = np.cross(axis, helper)
            e2 /= np.linalg.norm(e2)
        else:  # sideways: the second body axis is the travel (travel_in_body)
            axis = np.asarray(self.axis, dtype=float)
            axis = axis / np.linalg.norm(axis)
            if abs(float(axis @ travel)) > SIDEWAYS_COS:
                raise InputError(f"rigid body: axis {axis.tolist()} is not perpendicular to "
                                 f"the direction of travel {travel.tolist()}")
            e2 = travel
        e3 = np.cross(axis, e2)
        rot = np.stack([axis, e2, e3], axis=1)  # columns: body axes in global coordinates
        profile = imp.profile()
        reach = float(np.max(np.hypot(profile[:, 0], profile[:, 1])))
        params = np.zeros(RB.N_BODY_PARAM)
        params[[RB.BP_MASS, RB.BP_I_AXIAL, RB.BP_I_TRANS, RB.BP_TIP, RB.BP_BETA, RB.BP_REACH,
                RB.BP_NPTS, RB.BP_AXIAL_ONLY, RB.BP_FRACTION, RB.BP_DAMPING, RB.BP_FRICTION]] = (
            m, i_a, i_t, zc, self.beta, reach, len(profile), float(self.axial_only),
            self.fraction, self.damping, self.friction)
        state = np.zeros(RB.N_BODY_STATE)
        state[RB.B_X:RB.B_X + 3] = np.asarray(self.tip, dtype=float) + zc * axis
        state[RB.B_V:RB.B_V + 3] = self.speed * travel
        state[RB.B_R:RB.B_R + 9] = rot.ravel()
        return params, profile, state


@dataclass(frozen=True)
class ShellContactParams:
    """Shell–shell contact of a model (plies on plies, layers on layers; theory §6.3).

    Attributes:
        enabled: build the contact (False: surfaces pass through each other).
        beta: penalty scale β of k = β min(m_node, m̄_segment)/Δt², 0 < β ≤ 0.5.
        damping: ζ, fraction of critical damping 2 √(k m_red) of each node–segment pair.
        friction: Coulomb coefficient μ ≥ 0.
        self_contact: a surface also meets its own non-adjacent segments (a folding
            ply or a single imported surface).
        damping_mode: "always" (the dashpot acts while the pair overlaps) or "approach"
            (only while it closes; theory §6). Not in the repr, which the digest hashes:
            Model.digest adds it when it is not the default, so older digests hold.
    """

    enabled: bool = True
    beta: float = 0.1
    damping: float = 0.3
    friction: float = 0.0
    self_contact: bool = False
    damping_mode: str = field(default="always", repr=False)


@dataclass(frozen=True, eq=False)
class Model:
    """Static arrays of a run (SI). Never mutated; the solver reads them.

    Attributes:
        x0: (n_nodes, 3) reference coordinates.
        quads: (n_elems, 4) node indices, counter-clockwise about the normal.
        elem_section: (n_elems,) section row of each element.
        sections: (n_sections, N_SECTION) section table (shell_layout).
        mat_kind: (n_mats,) MAT_ELASTIC or MAT_FABRIC.
        mat_params: (n_mats, n_params) parameter vectors, zero-padded.
        section_state0: (n_sections, n_mat_state) initial material state of an element
            of each section (its points' state blocks side by side).
        point_width: length of one point's state block (the longest state vector of
            the model's material kinds; 0 if none has a state).
        mat_row: (n_elems + 1,) the material rows of ``State.mat`` element e owns,
            mat_row[e] … mat_row[e + 1] − 1: one per point of its section (in-plane
            point g, level k at g · levels + k) for a material with a state, one (unused)
            for an elastic one.
        gauss_grad, gauss_weight: (n_elems, 4, 2, 4) ∂N_I/∂X at the 2×2 Gauss points
            and (n_elems, 4) their weights det J (fully integrated membranes).
        ref_grad: (n_elems, 2, 4) ∂N_I/∂X at the element centre in its reference
            material frame (warp along x).
        area0: (n_elems,) reference areas.
        node_mass: (n_nodes,) lumped translational mass (kg).
        node_inertia: (n_nodes,) lumped rotary inertia (kg m²).
        bc_code, bc_velocity: (n_nodes, 6) constraint codes and prescribed velocities.
        ramp_time: rise time of the smooth-step amplitude (s).
        body_accel: (n_nodes, 3) body-force acceleration field (m/s²).
        node_ptr, node_elem, node_corner: CSR map node → (element, corner).
        alpha: stable-step factor (eq. 4.8, 0.9).
        erode_dt_fraction: an element whose stable step α L_e/c_e falls below this
            fraction of the first step of the run is eroded (LS-DYNA's DTMIN idea;
            0 disables). Fabric with one yarn family broken has no stiffness
            across it and crushes; without this the step would collapse.
        ply: (n_elems,) ply (or part) index of each element, for per-ply outputs.
        node_offset: (n_nodes,) contact offset of each node: half the thickness of the
            thickest section it belongs to (m).
        body_params: (n_bodies, N_BODY_PARAM) rigid impactors (kernels.rigid_body).
        body_profiles: (n_bodies, n_points, 2) their meridian polylines (ζ, ρ), padded.
        body_state0: (n_bodies, N_BODY_STATE) their state at t = 0.
        body_travel: (n_bodies, 3) each body's direction of travel in its own frame
            (constant): DEFAULT_TRAVEL (−1, 0, 0), nose first, or SIDEWAYS_TRAVEL
            (0, 1, 0), a body whose axis lies across its travel (RigidBody.axis). A
            Model built without it (empty) has every body nose first
            (:func:`flies_sideways`, :func:`travel_of_row`).
        solid: the hexahedra (model.solid.SolidPart; ``NO_SOLIDS`` in a model of shells
            only). Their lumped masses are in ``node_mass``; a node of solids only has no
            rotations (its rotational degrees of freedom are held, ``bc_code`` FIXED).
        node_sets, elem_sets: named index arrays (outputs, BCs).
        shell_contact: parameters of the shell–shell contact between the surfaces
            (``ply`` labels the surfaces: plies, element sets or connected parts).
        erode_inverted: an inverted element (non-positive area or Jacobian) is eroded
            instead of stopping the run (LS-DYNA's erosion on negative volume).
        release_elems, release_time: elements eroded at ``release_time`` (s) — the
            tie between a blade's hub part and its fragment (theory §8.2); none by default.
        section_names, material_names: labels for reports.
        mass_scaling_fraction: elements whose step α L_e/c_e falls below this fraction
            of the first step get mass so that it is that fraction again
            (kernels.mass_scaling; 0: off).
        max_added_mass_fraction: a run whose added mass exceeds this fraction of the
            model's mass stops (mass scaling is then no longer a small perturbation).
        stable_step: "isotropic" or "yarn", the fabric elements' stable step (theory
            §4, "Stable step"; the shell kernel reads it as ``STEP_*``).
        kinematic_fraction: η of the kinematic bound under ``stable_step = "yarn"``:
            the fraction of its distance a corner pair may close or open in one step.
        elem_mass: (n_elems,) mass of each element, μ A0 (kg).
        elem_length: (n_elems, 2) each element's lengths for the regularisation of
            failure: along warp and fill for fabric, √A0 twice otherwise
            (:func:`characteristic_lengths`).
        elem_failure: (n_elems, 6) the failure columns of each element's points, from
            its lengths (:func:`failure_columns`): fabric S_TU_SCALE … S_ERODE_LIMIT + 1,
            J2 S_FRAC_SCALE, S_EVOLUTION, S_HINGE in the first three.
        eroded_nodes: "remove" (this class's default, for models built in code): a node
            left without a live element leaves the model with its kinetic energy; "keep"
            (LS-DYNA's ENMASS = 2; a case's default, ``run.eroded_nodes``): it flies on as
            a free node with its mass and momentum, contact-active (theory §5, "Eroded
            nodes").
    """

    x0: np.ndarray
    quads: np.ndarray
    elem_section: np.ndarray
    sections: np.ndarray
    mat_kind: np.ndarray
    mat_params: np.ndarray
    section_state0: np.ndarray
    point_width: int
    mat_row: np.ndarray
    ref_grad: np.ndarray
    area0: np.ndarray
    gauss_grad: np.ndarray
    gauss_weight: np.ndarray
    node_mass: np.ndarray
    node_inertia: np.ndarray
    bc_code: np.ndarray
    bc_velocity: np.ndarray
    ramp_time: float
    body_accel: np.ndarray
    node_ptr: np.ndarray
    node_elem: np.ndarray
    node_corner: np.ndarray
    alpha: float
    erode_dt_fraction: float
    ply: np.ndarray
    node_offset: np.ndarray
    body_params: np.ndarray
    body_profiles: np.ndarray
    body_state0: np.ndarray
    node_sets: dict = field(default_factory=dict)
    elem_sets: dict = field(default_factory=dict)
    shell_contact: ShellContactParams = ShellContactParams()
    erode_inverted: bool = False
    release_elems: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    release_time: float = math.inf
    section_names: tuple = ()
    material_names: tuple = ()
    mass_scaling_fraction: float = 0.0
    max_added_mass_fraction: float = 0.02
    stable_step: str = "isotropic"
    kinematic_fraction: float = SL.KINEMATIC_FRACTION
    elem_mass: np.ndarray = field(default_factory=lambda: np.zeros(0))
    # the rotary inertia each element lumps on each of its corners (kg m²; node_inertia
    # is their sum, so the digest covers it)
    elem_rot_inertia: np.ndarray = field(default_factory=lambda: np.zeros(0))
    # each element's lengths for the regularisation of failure (characteristic_lengths;
    # derived from x0, quads and the warp direction): the initial material rows take
    # their failure columns from them (state.initial_material_rows)
    elem_length: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))
    elem_failure: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))
    eroded_nodes: str = "remove"
    body_travel: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    # the smallest edge radius of what strikes the structure (m; inf: nothing does): the
    # rigid bodies' (Impactor.edge_radius) and a released blade's half thickness — read by
    # the mesh verdict only, so not in the digest
    striking_radius: float = math.inf
    solid: SolidPart = NO_SOLIDS
    # rigid plates (model.rigid_plane.RigidPlane) that press or hold (docs/solid.md §6)
    rigid_planes: tuple = ()

    @property
    def n_nodes(self) -> int:
        return self.x0.shape[0]

    @property
    def n_elems(self) -> int:
        """The shell elements (the hexahedra are ``n_hexes``)."""
        return self.quads.shape[0]

    @property
    def n_hexes(self) -> int:
        return self.solid.n_hexes

    def digest(self) -> str:
        """SHA-256 of every array: a checkpoint is only resumed on the same Model."""
        h = hashlib.sha256()
        for name in ("x0", "quads", "elem_section", "sections", "mat_kind", "mat_params",
                     "bc_code", "bc_velocity", "body_accel", "node_mass", "node_inertia",
                     "body_params", "body_profiles", "body_state0"):
            a = np.ascontiguousarray(getattr(self, name))
            h.update(name.encode())
            h.update(str(a.dtype).encode() + str(a.shape).encode())
            h.update(a.tobytes())
        # not max_added_mass_fraction: a stop rule, which a restart may change
        # (provenance.RESTART_FREE); it changes no step the run replays
        h.update(repr((self.ramp_time, self.alpha, self.erode_dt_fraction,
                       self.shell_contact, self.release_time, self.erode_inverted,
                       self.mass_scaling_fraction)).encode())
        if self.stable_step != "isotropic":  # (the default leaves older digests as they were)
            h.update(self.stable_step.encode())
        if self.kinematic_fraction != SL.KINEMATIC_FRACTION:  # (likewise)
            h.update(repr(self.kinematic_fraction).encode())
        if self.eroded_nodes != "remove":  # (likewise)
            h.update(self.eroded_nodes.encode())
        if self.shell_contact.damping_mode != "always":  # (likewise)
            h.update(self.shell_contact.damping_mode.encode())
        if any(flies_sideways(self, b) for b in range(self.body_params.shape[0])):
            h.update(b"body_travel" + np.ascontiguousarray(self.body_travel).tobytes())
        h.update(np.ascontiguousarray(self.release_elems).tobytes())
        if self.solid.n_hexes:  # (a model of shells only keeps its digest)
            self.solid.digest_into(h)
        for plane in self.rigid_planes:  # (likewise, a model without planes)
            h.update(b"rigid_plane" + plane.digest_bytes(self.n_nodes))
        return h.hexdigest()


def flies_sideways(model, b: int = 0) -> bool:
    """Whether body b's axis lies across its travel (RigidBody.axis given)."""
    t = model.body_travel
    return t.shape[0] > b and tuple(t[b]) != DEFAULT_TRAVEL


def travel_of_row(model, row, b: int = 0) -> np.ndarray:
    """The unit direction of travel of body b whose state row is ``row``: −(its axis)
    for a body flying nose first (the expression used before sideways bodies existed),
    its rotation times ``body_travel[b]`` for one flying sideways."""
    rot = row[RB.B_R:RB.B_R + 9].reshape(3, 3)
    if not flies_sideways(model, b):
        return -rot[:, 0]
    return rot @ model.body_travel[b]


def sideways_shadow(model, row, b: int, x) -> tuple[np.ndarray, np.ndarray]:
    """Points ``x`` (m, 3) seen from body b flying sideways (state row ``row``): s,
    their distance ahead of its leading line along the travel d (the line of the body's
    surface farthest along d, R ahead of its axis, R the profile's largest radius), and
    how far each lies outside the body's shadow — the rectangle the body sweeps, its
    length L along the axis a by 2R across (e = d × a) — ≤ 0 inside:
    max(|(x − tip)·e| − R, −(x − tip)·a, (x − tip)·a − L). For a cylinder the shadow
    is exact; for another profile it is the bounding rectangle."""
    p = model.body_params[b]
    rot = row[RB.B_R:RB.B_R + 9].reshape(3, 3)
    a = rot[:, 0]
    d = travel_of_row(model, row, b)
    e = np.cross(d, a)
    tip = row[RB.B_X:RB.B_X + 3] - p[RB.BP_TIP] * a
    n = int(p[RB.BP_NPTS])
    radius = float(np.max(model.body_profiles[b, :n, 1]))
    length = float(model.body_profiles[b, n - 1, 0])
    rel = np.asarray(x, dtype=float) - tip
    along = rel @ a
    outside = np.maximum(np.abs(rel @ e) - radius, np.maximum(-along, along - length))
    return rel @ d - radius, outside


def rotary_inertia(x0, quads, sec_table, elem_section, mat_kind, mat_params, area0, ref_grad):
    """The rotary inertia I_e each element lumps on each of its corners (kg m²):

        I_e = ¼ m_e ρ_e,   ρ_e = max(t²/12, A0/8, ρ_θ),

    m_e = μ A0 the element's mass. t²/12 is the physical value, A0/8 the usual scaling
    that keeps a thin shell's spins slower than its membrane (theory §4, "Stable step").
    ρ_θ (metal sections only) makes the element's rotational bound 2 √(I_e/k_θ) no shorter
    than its membrane bound L_e/c_e at the reference geometry, with
    k_θ = A0 (k G t/4 + D Σb²) and c_e² = max(C_m, k G t)/μ, C_m = E t/(1 − ν²):

        ρ_θ = k_θ (L_e/c_e)² / m_e.

    A thick shell needs it: the titanium blade, 4.98 mm on ~5 mm elements, has
    k_θ/I about twice the membrane's (2/Δt)² with A0/8 (its spins 1.4× faster), and they
    set the model's step (6.6e-7 against 9.1e-7 s). Translational mass is unchanged; only spins
    faster than the membrane's fastest mode are slowed. Fabric sections keep
    max(t²/12, A0/8): their bending and transverse-shear stiffnesses are far below the
    yarns' tension stiffness, whose wave bound the element kernel computes from the
    current state (none of the 51 800 fabric elements of the 10-ply casing is governed
    by its spins)."""
    t = sec_table[elem_section, SL.C_THICK]
    mu = sec_table[elem_section, SL.C_AREAL_MASS]
    m_el = mu * area0
    rho = np.maximum(t**2 / 12.0, area0 / 8.0)
    mat = sec_table[elem_section, SL.C_MAT].astype(np.int64)
    metal = np.flatnonzero((mat_kind[mat] == SL.MAT_ELASTIC) | (mat_kind[mat] == SL.MAT_J2))
    if metal.size:  # (the fabric rows' parameters are not E, ν: left out)
        sec = sec_table[elem_section[metal]]
        tm, mu_m, a0 = t[metal], mu[metal], area0[metal]
        e_mod, nu = mat_params[mat[metal], 0], mat_params[mat[metal], 1]
        c_m = e_mod * tm / (1.0 - nu**2)
        kgt = sec[:, SL.C_SHEAR_K] * sec[:, SL.C_SHEAR_G] * tm
        e_b, nu_b = sec[:, SL.C_BEND_E], sec[:, SL.C_BEND_NU]
        integrated = sec[:, SL.C_POINTS] > 1  # bending from the points (as the kernel)
        d_b = np.where(integrated, c_m * tm**2 / 12.0, e_b * tm**3 / (12.0 * (1.0 - nu_b**2)))
        p = x0[quads[metal]]
        edge = np.linalg.norm(np.roll(p, -1, axis=1) - p, axis=2).max(axis=1)
        bb = np.sum(ref_grad[metal] ** 2, axis=(1, 2))
        dt_m = a0 / (edge * np.sqrt(np.maximum(c_m, kgt) / mu_m))
        k_rot = a0 * (0.25 * kgt + d_b * bb)
        rho[metal] = np.maximum(rho[metal], k_rot * dt_m**2 / m_el[metal])
    return 0.25 * m_el * rho


def material_frame_gradients(x0, quads, warp_direction):
    """Reference gradients and areas in each element's material frame: e3 the element
    normal, e1 the warp direction projected on the element plane, e2 = e3 × e1 (the fill
    direction of an unsheared fabric).

    Returns (grad (n, 2, 4), area (n,), gauss_grad (n, 4, 2, 4), gauss_weight (n, 4)):
    the one-point (centre, BLT) gradients ∂N_I/∂X, the reference areas, and ∂N_I/∂X at
    the 2×2 Gauss points with their weights det J(ξ_g, η_g) (Σ_g = area for a planar
    quad) — see :func:`gauss_gradients`.
    """
    X, Y, area = material_frame_coordinates(x0, quads, warp_direction)
    grad = np.empty((len(quads), 2, 4))
    # one-point gradients of the bilinear quad (Belytschko–Lin–Tsay B matrix)
    a2 = 2.0 * area
    grad[:, 0] = np.stack([Y[:, 1] - Y[:, 3], Y[:, 2] - Y[:, 0], Y[:, 3] - Y[:, 1],
                           Y[:, 0] - Y[:, 2]], axis=1) / a2[:, None]
    grad[:, 1] = np.stack([X[:, 3] - X[:, 1], X[:, 0] - X[:, 2], X[:, 1] - X[:, 3],
                           X[:, 2] - X[:, 0]], axis=1) / a2[:, None]
    g_grad, g_weight = gauss_gradients(X, Y)
    return grad, area, g_grad, g_weight


def characteristic_lengths(x0, quads, warp_direction, kinds) -> np.ndarray:
    """Each element's lengths for the regularisation of failure (theory §1.4, §7.3), (n, 2):
    for a fabric element (kinds[e] == MAT_FABRIC) its length along each yarn family,
    h_i = A0 / (its width across family i) — for a rectangle a × b with the warp along a,
    h_w = a and h_f = b, the width of the band a crack across family i opens in; for any
    other element l_e = √A0 in both columns (GISSMO's SIZFLG = 0 for shells)."""
    X, Y, area = material_frame_coordinates(x0, quads, warp_direction)
    out = np.empty((len(quads), 2))
    out[:, 0] = area / (Y.max(axis=1) - Y.min(axis=1))
    out[:, 1] = area / (X.max(axis=1) - X.min(axis=1))
    other = np.asarray(kinds) != SL.MAT_FABRIC
    out[other] = np.sqrt(area[other])[:, None]
    return out


def failure_columns(kinds, params, elem_mat, elem_length, elem_thickness=None) -> np.ndarray:
    """(n_elems, 6): the failure columns of each element's material points (theory §1.4,
    §7.3) from its lengths — a fabric's :func:`materials.fabric.regularised_columns`, a
    J2 metal's :func:`materials.metal.regularised_columns` in the first three, zeros for
    an elastic element. kinds, params: per material; elem_mat: each element's material;
    elem_thickness: each element's section thickness t0 (the metal's fold law; None: none)."""
    out = np.zeros((len(elem_mat), 6))
    for m, (kind, p) in enumerate(zip(kinds, params)):
        sel = np.flatnonzero(elem_mat == m)
        if kind == SL.MAT_FABRIC:
            out[sel] = fabric_regularised_columns(p, elem_length[sel])
        elif kind == SL.MAT_J2:
            t0 = 0.0 if elem_thickness is None else elem_thickness[sel]
            out[sel, :3] = j2_regularised_columns(p, elem_length[sel, 0], t0)
    return out


def material_frame_coordinates(x0, quads, warp_direction):
    """Corner coordinates (X, Y) (n, 4) of each element in its material frame (origin at
    the corners' mean; see :func:`material_frame_gradients`) and the reference areas (n,).
    """
    xe = x0[quads]  # (n, 4, 3)
    d13 = xe[:, 2] - xe[:, 0]
    d24 = xe[:, 3] - xe[:, 1]
    n = np.cross(d13, d24)
    area = 0.5 * np.linalg.norm(n, axis=1)
    bad = np.flatnonzero(~(area > 0.0))
    if bad.size:
        raise InputError(
            f"element {int(bad[0])} (nodes {quads[bad[0]].tolist()}) has zero area or "
            "reversed node order; quads must be convex and counter-clockwise"
        )
    e3 = n / (2.0 * area[:, None])
    w = np.broadcast_to(np.asarray(warp_direction, dtype=float), e3.shape)
    e1 = w - np.sum(w * e3, axis=1)[:, None] * e3
    norm1 = np.linalg.norm(e1, axis=1)
    bad = np.flatnonzero(norm1 < 1e-8)
    if bad.size:
        e = int(bad[0])
        raise InputError(
            f"warp_direction {w[e].tolist()} is normal to element {e} (nodes "
            f"{quads[e].tolist()}){f' and {bad.size - 1} more' if bad.size > 1 else ''}; "
            "give a direction lying in the fabric plane"
        )
    e1 /= norm1[:, None]
    e2 = np.cross(e3, e1)
    rel = xe - xe.mean(axis=1, keepdims=True)
    X = np.einsum("nij,nj->ni", rel, e1)
    Y = np.einsum("nij,nj->ni", rel, e2)
    return X, Y, area


def release_array(elems, n_elems: int) -> np.ndarray:
    """The released elements as a sorted int64 array, checked against the mesh."""
    idx = np.unique(np.asarray([] if elems is None else elems, dtype=np.int64))
    if idx.size and (idx[0] < 0 or idx[-1] >= n_elems):
        raise InputError(f"release elements refer to element {int(idx[-1])}; the mesh has "
                         f"{n_elems}")
    return idx


def gauss_gradients(X, Y):
    """∂N_I/∂X at the 2×2 Gauss points of bilinear quads with corner coordinates X, Y
    (n, 4) in the element plane, and the weights det J (Gauss weights 1).

    N_I = ¼ (1 + ξ_I ξ)(1 + η_I η); J = [[∂X/∂ξ, ∂Y/∂ξ], [∂X/∂η, ∂Y/∂η]];
    [∂N/∂X, ∂N/∂Y]ᵀ = J⁻¹ [∂N/∂ξ, ∂N/∂η]ᵀ (theory §4.5).
    """
    n = X.shape[0]
    grad = np.empty((n, 4, 2, 4))
    weight = np.empty((n, 4))
    for g in range(4):
        dn_dxi = 0.25 * CORNER_XI * (1.0 + CORNER_ETA * GAUSS_ETA[g])
        dn_deta = 0.25 * CORNER_ETA * (1.0 + CORNER_XI * GAUSS_XI[g])
        j11, j12 = X @ dn_dxi, Y @ dn_dxi
        j21, j22 = X @ dn_deta, Y @ dn_deta
        det = j11 * j22 - j12 * j21
        bad = np.flatnonzero(~(det > 0.0))
        if bad.size:
            raise InputError(
                f"element {int(bad[0])} has a non-positive Jacobian at a Gauss point "
                "(a concave or folded quad); fix the mesh"
            )
        grad[:, g, 0] = (j22[:, None] * dn_dxi - j12[:, None] * dn_deta) / det[:, None]
        grad[:, g, 1] = (-j21[:, None] * dn_dxi + j11[:, None] * dn_deta) / det[:, None]
        weight[:, g] = det
    return grad, weight


def node_element_map(quads: np.ndarray, n_nodes: int):
    """CSR map node → (element, corner), elements in increasing order per node."""
    n_el = quads.shape[0]
    flat = quads.ravel()
    order = np.argsort(flat, kind="stable")
    counts = np.bincount(flat, minlength=n_nodes)
    ptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(counts, out=ptr[1:])
    elem = (order // 4).astype(np.int64)
    corner = (order % 4).astype(np.int64)
    assert elem.size == 4 * n_el
    return ptr, elem, corner


def check_build_arguments(x0, q, *, alpha, erode_dt_fraction, mass_scaling_fraction,
                          max_added_mass_fraction, stable_step, eroded_nodes,
                          kinematic_fraction=SL.KINEMATIC_FRACTION) -> None:
    """Checks :func:`build_model`'s mesh arrays (shapes, node indices) and run parameters
    (ranges, names), raising an :class:`InputError` that names the first one wrong."""
    if x0.ndim != 2 or x0.shape[1] != 3:
        raise InputError(f"nodes must be an (n, 3) array, got shape {x0.shape}")
    if q.ndim != 2 or q.shape[1] != 4:
        raise InputError(f"quads must be an (n, 4) array, got shape {q.shape}")
    if q.size and (q.min() < 0 or q.max() >= len(x0)):
        raise InputError(f"quads refer to node {int(q.max())}, but there are {len(x0)} nodes")
    if not 0.0 <= erode_dt_fraction < 1.0:
        raise InputError(
            f"erode_dt_fraction = {erode_dt_fraction!r}: valid 0 ≤ f < 1 (0 disables)"
        )
    if not 0.0 < alpha <= 1.0:
        raise InputError(f"alpha = {alpha!r}: the stable-step factor must be in (0, 1]")
    if mass_scaling_fraction != 0.0 and not erode_dt_fraction < mass_scaling_fraction < 1.0:
        raise InputError(
            f"mass_scaling_fraction = {mass_scaling_fraction!r}: valid 0 (off) or "
            f"erode_dt_fraction ({erode_dt_fraction!r}) < f < 1 — below the erosion "
            "fraction an element erodes before it would be scaled"
        )
    if not 0.0 < max_added_mass_fraction <= 1.0:
        raise InputError(
            f"max_added_mass_fraction = {max_added_mass_fraction!r}: valid 0 < f ≤ 1"
        )
    if stable_step not in SL.STABLE_STEPS:
        raise InputError(
            f"stable_step = {stable_step!r}: valid {' or '.join(SL.STABLE_STEPS)}")
    if not 0.0 < kinematic_fraction <= 0.5:
        raise InputError(f"kinematic_fraction = {kinematic_fraction!r}: valid 0 < η ≤ 0.5 "
                         "(a corner pair closing by more than half its distance in a step "
                         "could pass through itself)")
    if kinematic_fraction != SL.KINEMATIC_FRACTION and stable_step != "yarn":
        raise InputError(f"kinematic_fraction = {kinematic_fraction!r}: the kinematic bound "
                         f"belongs to stable_step = \"yarn\", not {stable_step!r}; set "
                         "stable_step = \"yarn\" or leave kinematic_fraction out")
    if eroded_nodes not in ERODED_NODES:
        raise InputError(
            f"eroded_nodes = {eroded_nodes!r}: valid {' or '.join(map(repr, ERODED_NODES))}")


def section_table(sections: dict[str, Section], elem_section, n_elems: int):
    """Builds the section table: (the section names, the distinct material objects in
    their order of first use, the (n_sections, N_SECTION) table of section rows, each
    element's section row (n_elems,)); ``elem_section`` gives names or row indices."""
    names = list(sections)
    # materials: one table row per distinct material object
    mats: list = []
    for sec in sections.values():
        if not any(sec.material is m for m in mats):
            mats.append(sec.material)
    rows = [sections[n].row(next(i for i, m in enumerate(mats) if m is sections[n].material), n)
            for n in names]
    sec_table = np.array(rows).reshape(-1, SL.N_SECTION)
    es = section_indices(elem_section, names, n_elems, "section", "elem_section", "element")
    return names, mats, sec_table, es


def material_table(mats: list):
    """Builds the material table: (each material's kind (SL.MAT_*), its parameter row,
    the (n_materials, widest row) table of those rows zero-padded, the initial state of
    one of its material points)."""
    kinds, params, states = [], [], []
    for m in mats:
        if isinstance(m, FabricParameters):
            kinds.append(SL.MAT_FABRIC)
            params.append(m.to_array())
            states.append(fabric_initial_state(m)[0])
        elif is_plastic(m):
            kinds.append(SL.MAT_J2)
            params.append(j2_parameter_row(m))
            states.append(j2_initial_state(m)[0])
        else:
            kinds.append(SL.MAT_ELASTIC)
            params.append(np.array([m.modulus, m.poisson, m.density]))
            states.append(np.zeros(0))
    n_par = max((len(p) for p in params), default=0)
    mat_params = np.zeros((len(mats), n_par))
    for i, p in enumerate(params):
        mat_params[i, : len(p)] = p
    return kinds, params, mat_params, states


def point_state_tables(sec_table, kinds, states, es):
    """Builds the material points' initial state: (the width of one point's state, each
    section's points' state blocks (``Model.section_state0``), the first row of
    ``State.mat`` each element owns (``Model.mat_row``, n_elems + 1))."""
    # per section: its points' state blocks side by side, each padded to the longest
    # state vector of the model's kinds (width of the table: the widest section)
    point_width = max((len(st) for st in states), default=0)
    padded = [np.pad(st, (0, point_width - len(st))) for st in states]
    blocks = [np.tile(padded[int(r[SL.C_MAT])], int(r[SL.C_POINTS]) * int(r[SL.C_INPLANE]))
              if point_width else np.zeros(0) for r in sec_table]
    section_state0 = np.zeros((len(blocks), max(1, max((len(b) for b in blocks), default=0))))
    for i, b in enumerate(blocks):
        section_state0[i, : len(b)] = b
    # the material rows each element owns (``State.mat``, one row per point): packed, so
    # that a fabric element beside 2×2×5-point metal owns 4 rows, not 20 (theory §4.6)
    sec_rows = np.array([int(r[SL.C_POINTS]) * int(r[SL.C_INPLANE])
                         if point_width and kinds[int(r[SL.C_MAT])] != SL.MAT_ELASTIC else 1
                         for r in sec_table], dtype=np.int64)
    mat_row = np.zeros(len(es) + 1, dtype=np.int64)
    np.cumsum(sec_rows[es], out=mat_row[1:])
    return point_width, section_state0, mat_row


def element_failure_tables(x0, q, warp_direction, sec_table, es, kinds, params, mat_params):
    """Builds each element's failure lengths and columns (:func:`characteristic_lengths`,
    :func:`failure_columns`), and writes each fabric's failure threshold of the vector
    stage (``P_TU_FLOOR``) into ``mat_params``; returns (elem_length, elem_failure)."""
    elem_mat = sec_table[es, SL.C_MAT].astype(np.int64)
    elem_length = characteristic_lengths(x0, q, warp_direction, np.array(kinds)[elem_mat])
    elem_failure = failure_columns(kinds, params, elem_mat, elem_length,
                                   sec_table[es, SL.C_THICK])
    for m, kind in enumerate(kinds):  # the vector stage's failure threshold (P_TU_FLOOR)
        sel = elem_mat == m
        if kind == SL.MAT_FABRIC and sel.any():
            mat_params[m, FP.P_TU_FLOOR:FP.P_TU_FLOOR + 2] = np.minimum(
                1.0, elem_failure[sel, 0:2].min(axis=0))
    return elem_length, elem_failure


def lumped_masses(x0, q, sec_table, es, kinds, mat_params, area0, ref_grad):
    """Builds the lumped masses of the shells: (each element's mass, the rotary inertia
    it lumps on each corner, each node's mass, each node's rotary inertia)."""
    # lumped masses: a quarter of each element's mass to each corner, and the rotary
    # inertia the element lumps on each corner (rotary_inertia: rotations never govern
    # the stable step at the reference geometry; theory §4, "Stable step")
    m_el = sec_table[es, SL.C_AREAL_MASS] * area0
    elem_rot_inertia = rotary_inertia(x0, q, sec_table, es, np.array(kinds), mat_params, area0,
                                      ref_grad)
    node_mass = np.zeros(len(x0))
    node_inertia = np.zeros(len(x0))
    for c in range(4):
        np.add.at(node_mass, q[:, c], 0.25 * m_el)
        np.add.at(node_inertia, q[:, c], elem_rot_inertia)
    return m_el, elem_rot_inertia, node_mass, node_inertia


def constraint_codes(bcs: BoundaryConditions | None, solid: SolidPart | None, x0, q,
                     node_mass):
    """Builds the constraint code of every degree of freedom: (the boundary conditions,
    none if not given; the solid part, NO_SOLIDS if none; their codes with the rotations
    of nodes of hexahedra only held); adds the hexahedra's masses to ``node_mass``."""
    if bcs is None:
        bcs = BoundaryConditions(len(x0))
    if bcs.code.shape != (len(x0), 6):
        raise InputError(f"boundary conditions are for {bcs.code.shape[0]} nodes, mesh has {len(x0)}")
    if bcs.ramp_time < 0.0:
        raise InputError(f"ramp_time = {bcs.ramp_time!r} s must be ≥ 0")
    solid = NO_SOLIDS if solid is None else solid
    bc_code = bcs.code.copy()
    if solid.n_hexes:
        if solid.node_ptr.shape != (len(x0) + 1,):
            raise InputError(f"the solid part is for {solid.node_ptr.shape[0] - 1} nodes, the "
                             f"mesh has {len(x0)}")
        node_mass += solid.node_masses(len(x0))
        # a node of solids only has no rotations: they are held (no rotary inertia)
        in_shell = np.zeros(len(x0), dtype=bool)
        in_shell[q.ravel()] = True
        solid_only = np.flatnonzero(~in_shell & (np.diff(solid.node_ptr) > 0))
        bc_code[solid_only, 3:] = FIXED
    return bcs, solid, bc_code


def node_offsets(q, thick, n_nodes: int) -> np.ndarray:
    """Builds each node's offset from its shells' mid-surface: half the thickest shell
    on it (0 on a node of no shell)."""
    node_offset = np.zeros(n_nodes)
    for c in range(4):
        np.maximum.at(node_offset, q[:, c], 0.5 * thick)
    return node_offset


def body_tables(bodies: list[RigidBody] | None):
    """Builds the rigid bodies' tables: (their parameters (n, N_BODY_PARAM), their
    profiles (n, most points, 2) zero-padded, their states at t = 0 (n, N_BODY_STATE),
    their travel directions in the body (n, 3))."""
    packed = [b.pack() for b in (bodies or [])]
    body_travel = np.array([b.travel_in_body for b in (bodies or [])],
                           dtype=float).reshape(-1, 3)
    n_pts = max((len(p[1]) for p in packed), default=0)
    body_params = np.zeros((len(packed), RB.N_BODY_PARAM))
    body_profiles = np.zeros((len(packed), n_pts, 2))
    body_state0 = np.zeros((len(packed), RB.N_BODY_STATE))
    for i, (bp, prof, st0) in enumerate(packed):
        body_params[i] = bp
        body_profiles[i, : len(prof)] = prof
        body_state0[i] = st0
    return body_params, body_profiles, body_state0, body_travel


def build_model(
    nodes,
    quads,
    sections: dict[str, Section],
    elem_section,
    bcs: BoundaryConditions | None = None,
    warp_direction=(1.0, 0.0, 0.0),
    body_accel=None,
    alpha: float = 0.9,
    erode_dt_fraction: float = 0.05,
    ply=None,
    bodies: list[RigidBody] | None = None,
    node_sets: dict | None = None,
    elem_sets: dict | None = None,
    shell_contact: ShellContactParams | None = None,
    release_elems=None,
    release_time: float = math.inf,
    erode_inverted: bool = False,
    mass_scaling_fraction: float = 0.0,
    max_added_mass_fraction: float = 0.02,
    stable_step: str = "isotropic",
    eroded_nodes: str = "remove",
    solid: SolidPart | None = None,
    kinematic_fraction: float = SL.KINEMATIC_FRACTION,
    rigid_planes=(),
) -> Model:
    """Assemble a :class:`Model` from a mesh, named sections and constraints.

    Args:
        nodes: (n_nodes, 3) coordinates (m).
        quads: (n_elems, 4) node indices; triangles as quads with a repeated last node.
        sections: name → Section.
        elem_section: (n_elems,) section name (str) or row index of each element.
        bcs: constraints; default none.
        warp_direction: global vector (or (n_elems, 3) array) projected on each
            element to give its warp (material x) direction.
        body_accel: (3,) or (n_nodes, 3) body-force acceleration (m/s²).
        alpha: stable-step factor, 0 < α ≤ 1.
        erode_dt_fraction: erode elements whose step falls below this fraction of
            the first one, 0 ≤ f < 1 (0: never); default 0.05.
        ply: (n_elems,) part index for per-ply outputs; default all 0.
        bodies: rigid impactors.
        shell_contact: shell–shell contact parameters (default ShellContactParams()).
        release_elems, release_time: elements eroded at that time (a blade's release).
        mass_scaling_fraction: add mass to elements whose step falls below this fraction
            of the first one, erode_dt_fraction < f < 1 (0: never, the default).
        max_added_mass_fraction: stop once the added mass exceeds this fraction of the
            model's mass, 0 < f ≤ 1; default 0.02.
        stable_step: "isotropic" (default) or "yarn" (theory §4, "Stable step").
        eroded_nodes: "remove" (default here; a case's ``run.eroded_nodes`` defaults to
            "keep") or "keep": what becomes of a node that loses its last live element
            (theory §5, "Eroded nodes").
        solid: the hexahedra on the same nodes (model.solid.solid_part); default none.
            ``quads`` may then be empty.
        rigid_planes: rigid plates (model.rigid_plane.RigidPlane); default none.
        kinematic_fraction: η of the kinematic bound under ``stable_step = "yarn"``,
            0 < η ≤ 0.5; default ``shell_layout.KINEMATIC_FRACTION`` (theory §4).
    """
    x0 = np.ascontiguousarray(nodes, dtype=float)
    q = np.ascontiguousarray(quads, dtype=np.int64)
    check_build_arguments(x0, q, alpha=alpha, erode_dt_fraction=erode_dt_fraction,
                          mass_scaling_fraction=mass_scaling_fraction,
                          max_added_mass_fraction=max_added_mass_fraction,
                          stable_step=stable_step, eroded_nodes=eroded_nodes,
                          kinematic_fraction=kinematic_fraction)
    names, mats, sec_table, es = section_table(sections, elem_section, len(q))
    kinds, params, mat_params, states = material_table(mats)
    point_width, section_state0, mat_row = point_state_tables(sec_table, kinds, states, es)
    ref_grad, area0, gauss_grad, gauss_weight = material_frame_gradients(x0, q, warp_direction)
    elem_length, elem_failure = element_failure_tables(x0, q, warp_direction, sec_table, es,
                                                       kinds, params, mat_params)
    thick = sec_table[es, SL.C_THICK]
    m_el, elem_rot_inertia, node_mass, node_inertia = lumped_masses(
        x0, q, sec_table, es, kinds, mat_params, area0, ref_grad)
    bcs, solid, bc_code = constraint_codes(bcs, solid, x0, q, node_mass)
    ba = np.zeros((len(x0), 3)) if body_accel is None else np.broadcast_to(
        np.asarray(body_accel, dtype=float), (len(x0), 3)).copy()
    ptr, n_elem, n_corner = node_element_map(q, len(x0))
    node_offset = node_offsets(q, thick, len(x0))
    body_params, body_profiles, body_state0, body_travel = body_tables(bodies)
    striking = [b.impactor.edge_radius(sideways=b.axis is not None) for b in bodies or ()]
    rel = release_array(release_elems, len(q))
    if rel.size:  # a blade strikes with its edge: half its shell's thickness
        striking.append(0.5 * float(sec_table[es[rel[0]], SL.C_THICK]))
    return Model(
        x0=x0, quads=q, elem_section=es, sections=sec_table,
        mat_kind=np.array(kinds, dtype=np.int64), mat_params=mat_params,
        section_state0=section_state0, point_width=int(point_width), mat_row=mat_row,
        ref_grad=ref_grad, area0=area0, gauss_grad=gauss_grad, gauss_weight=gauss_weight,
        node_mass=node_mass, node_inertia=node_inertia,
        bc_code=bc_code, bc_velocity=bcs.velocity.copy(), ramp_time=float(bcs.ramp_time),
        body_accel=ba, node_ptr=ptr, node_elem=n_elem, node_corner=n_corner, alpha=float(alpha),
        erode_dt_fraction=float(erode_dt_fraction),
        ply=np.zeros(len(q), dtype=np.int64) if ply is None else np.asarray(ply, dtype=np.int64),
        node_offset=node_offset, body_params=body_params, body_profiles=body_profiles,
        body_state0=body_state0, body_travel=body_travel,
        node_sets=dict(node_sets or {}), elem_sets=dict(elem_sets or {}),
        shell_contact=shell_contact or ShellContactParams(),
        release_elems=rel, release_time=float(release_time),
        striking_radius=min(striking, default=math.inf),
        erode_inverted=bool(erode_inverted),
        section_names=tuple(names), material_names=tuple(getattr(m, "name", "") for m in mats),
        mass_scaling_fraction=float(mass_scaling_fraction),
        max_added_mass_fraction=float(max_added_mass_fraction), elem_mass=m_el,
        elem_rot_inertia=elem_rot_inertia, elem_length=elem_length, elem_failure=elem_failure,
        stable_step=str(stable_step), eroded_nodes=str(eroded_nodes), solid=solid,
        rigid_planes=tuple(rigid_planes or ()), kinematic_fraction=float(kinematic_fraction),
    )
