"""Named bundles of arrays handed to the step's kernels (issue 13).

The element loop (``shell.internal_force_for_shells``) and the node pass
(``integrate.gather_and_update``) took 24 and 26 positional arrays, most of one dtype:
two swapped arguments compiled and ran. They now take named tuples, built
with keywords, the way MuJoCo Warp hands ``Model`` and ``Data`` to every kernel; Numba
passes a named tuple of arrays as its members (a field read is resolved at compile
time), so a bundle costs nothing in the compiled loop (theory §4.6: instruction counts
before and after). In a ``prange`` loop, read each member into a local, one per
statement, before the loop: writes through a bundle in the loop body can be lost
(theory §4.6; a sentinel test of each loop guards it).

:class:`ShellMesh`, :class:`ElementResults`, :class:`NodeMap` and :class:`NodeEnergies`
are built once per Workspace, the others per step from the arrays the step swaps; none
is stored in a checkpoint.

The contact kernels take bundles too (issue 37): the shell–shell contact's
:class:`ContactSurfaces` and :class:`ContactLaw` are built once per ``ShellContact``, its
search, bins, candidate lists and pair tables (:class:`ContactSearch`,
:class:`SegmentBinTables`, :class:`Candidates`, :class:`PairTables`) at each call from the
buffers of the moment (they grow and swap); the rigid bodies' :class:`ContactNodes`,
:class:`BodyContact` and :class:`BodyContactOut` per body and step
(``solver.contact_stage``); :class:`EnergyBooks` per step. A kernel called from outside
``kernels/`` takes at most 12 arguments (tests/docs/test_kernel_calls.py); the inner
stages of a loop keep their long signatures where they say so.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class ShellMesh(NamedTuple):
    """What the element kernel reads of a Model (never written)."""

    quads: np.ndarray  # (n_elems, 4) node indices
    elem_section: np.ndarray  # (n_elems,) row of ``sections``
    sections: np.ndarray  # (n_sections, N_SECTION) shell_layout C_* columns
    mat_kind: np.ndarray  # (n_materials,) MAT_* codes
    mat_params: np.ndarray  # (n_materials, n_par) parameter rows
    area0: np.ndarray  # (n_elems,) reference areas A0
    ref_grad: np.ndarray  # (n_elems, 2, 4) ∂N_I/∂X at the centre, material frame
    gauss_grad: np.ndarray  # (n_elems, 4, 2, 4) the same at the 2×2 Gauss points
    gauss_weight: np.ndarray  # (n_elems, 4) their weights (det J)
    rot_inertia: np.ndarray  # (n_elems,) rotary inertia lumped on each corner (kg m²)
    mat_row: np.ndarray  # (n_elems + 1,) element e's material rows mat_row[e] … [e + 1] − 1
    step_mode: int  # shell_layout STEP_*: the fabric elements' stable step
    kinematic_fraction: float  # η of the kinematic bound under STEP_YARN (run.kinematic_fraction)


class Motion(NamedTuple):
    """Nodal positions x^n, velocities v^{n−1/2} and spins ω^{n−1/2}, (n_nodes, 3) each."""

    x: np.ndarray
    v: np.ndarray
    omega: np.ndarray


class ElementTables(NamedTuple):
    """Element and material-point state at the start (``*_in``) and end (``*_out``) of
    the step; the out tables are written (shell_layout E_*, and the materials' S_*)."""

    el_in: np.ndarray  # (n_elems, N_ELEM_STATE)
    el_out: np.ndarray
    mat_in: np.ndarray  # (n_rows, width): one row per material point (ShellMesh.mat_row)
    mat_out: np.ndarray


class ElementResults(NamedTuple):
    """What the element stage writes beside the state tables."""

    blocks: np.ndarray  # (n_elems, 4, 6) corner forces and moments (global)
    status: np.ndarray  # (n_elems,) int32 EL_* codes
    eroded_now: np.ndarray  # (n_elems,) int32, 1 where an element eroded this step
    alive: np.ndarray  # (n_elems,) uint8, 1 for an element alive at the end of the step


class NodeMap(NamedTuple):
    """The node → (element, corner) map in CSR form (Model)."""

    node_ptr: np.ndarray
    node_elem: np.ndarray
    node_corner: np.ndarray


class NodeModel(NamedTuple):
    """Nodal masses (with any added by mass scaling), constraints and body loads, and
    what becomes of a node that loses its last element."""

    mass: np.ndarray  # (n_nodes,) kg
    inertia: np.ndarray  # (n_nodes,) rotary inertia, kg m²
    bc_code: np.ndarray  # (n_nodes, 6) integrate FREE / FIXED / PRESCRIBED / ROTATING
    bc_velocity: np.ndarray  # (n_nodes, 6) prescribed velocities (or ω and the centre)
    body_accel: np.ndarray  # (n_nodes, 3) body-force acceleration, m/s²
    # False: it leaves the model with its kinetic energy; True: it flies on as a free
    # node with its mass and momentum (run.eroded_nodes = "keep"; integrate.update_node)
    keep_free: bool = False


class NodeForces(NamedTuple):
    """Nodal forces, (n_nodes, 6) each: internal at x^n (written by the gather), internal
    and external at x^{n−1}, external (body forces plus reactions) at x^n (written)."""

    f_int: np.ndarray
    f_int_old: np.ndarray
    f_ext_old: np.ndarray
    f_ext: np.ndarray


class NodeEnergies(NamedTuple):
    """Per-node energy figures of the step (written), (n_nodes,) each: internal and
    external work over [x^{n−1}, x^n], kinetic energy at t^n, kinetic energy of nodes
    eroded now."""

    w_int: np.ndarray
    w_ext: np.ndarray
    ke: np.ndarray
    ke_eroded: np.ndarray


class BlockPlan(NamedTuple):
    """Which elements the element stage takes in blocks of ``LANES`` (kernels.shell_blocks)
    and their static geometry in block layout — value k of lane l of block b at
    (b · width + k) · LANES + l — built once per Workspace (solver.element_blocks)."""
    elems: np.ndarray  # (n_blocks · LANES,) int64 element of each lane (the last repeated)
    lanes: np.ndarray  # (n_blocks,) int64 lanes in use
    section: np.ndarray  # (n_blocks,) int64 the block's section (one per block)
    others: np.ndarray  # (n,) int64 the elements left to ``shell_force`` alone
    gauss_grad: np.ndarray  # width 32: [g, ∂/∂X or ∂/∂Y, corner]
    gauss_weight: np.ndarray  # width 4
    ref_grad: np.ndarray  # width 8: [∂/∂X or ∂/∂Y, corner]
    area0: np.ndarray  # width 1
    rot_inertia: np.ndarray  # width 1


class BlockScratch(NamedTuple):
    """Per-thread scratch rows of the block stages (kernels.shell_blocks), (threads, n)."""
    corners: np.ndarray  # the block's corners (x, v, ω)
    old: np.ndarray  # the element state the step reads
    kin: np.ndarray  # each point's F and stretches
    coef: np.ndarray  # each point's table cell
    geo: np.ndarray
    flag: np.ndarray  # > 0: the lane goes to shell_force
    exact: np.ndarray  # 1.0: the point is solved by fabric_point (outside the table's cells)
    res: np.ndarray  # each point's crossover results
    out_el: np.ndarray  # the element state and the isotropic step
    out_blk: np.ndarray  # corner forces
    pending: np.ndarray  # (n_blocks · LANES,) int8: 1 where shell_force takes the lane


class HexMesh(NamedTuple):
    """What the hexahedron kernel reads of a Model (never written; kernels.hex8)."""

    hexes: np.ndarray  # (n_elems, 8) corner nodes, solid_layout node order
    elem_mat: np.ndarray  # (n_elems,) row of ``mat_params``
    mat_params: np.ndarray  # (n_materials, n_par) parameter rows (solid_layout TI_*)
    frame: np.ndarray  # (n_elems, 3, 3) material axes a1, a2, a3 (rows, global components)
    ref_grad: np.ndarray  # (n_elems, 3, 8) b⁰_I = (1/V0) ∫ ∇N_I dV in the reference
    vol0: np.ndarray  # (n_elems,) reference volumes V0
    hg_stiffness: np.ndarray  # (n_elems,) hourglass stiffness k (N/m)


class HexTables(NamedTuple):
    """Hexahedron state at the start (``el_in``) and end (``el_out``, written) of the
    step, (n_elems, N_HEX_STATE) each (solid_layout H_*)."""

    el_in: np.ndarray
    el_out: np.ndarray


class HexResults(NamedTuple):
    """What the hexahedron stage writes beside the state tables."""

    blocks: np.ndarray  # (n_elems, 8, 3) internal corner forces (global)
    status: np.ndarray  # (n_elems,) int32 EL_* codes


class HexGather(NamedTuple):
    """The hexahedra's corner forces as the node pass adds them to the shells'
    (``integrate.gather_and_update``): the node → (hexahedron, corner) map in CSR form
    (Model; all-zero ``node_ptr`` in a model without solids) and the force blocks."""

    node_ptr: np.ndarray  # (n_nodes + 1,) int64
    node_elem: np.ndarray  # int64 the hexahedron of each entry
    node_corner: np.ndarray  # int64 its corner
    blocks: np.ndarray  # (n_hexes, 8, 3) internal corner forces at x^n (HexResults.blocks)


# Contact (issue 37): the bundles of the shell–shell contact (contact_broad, contact_update,
# contact_narrow, contact_energy), built by its driver (``contact.ShellContact``), and of
# the rigid bodies (contact_rigid, built by ``solver.contact_stage``). The contact kernels
# read each member into a local, one per statement, at their top.


class ContactSurfaces(NamedTuple):
    """The shell surfaces of a contact as its kernels read them: fixed for a
    ``ShellContact`` (never written)."""

    quads: np.ndarray  # (n_elems, 4) int64 the segments' nodes
    ply: np.ndarray  # (n_elems,) int64 each segment's ply
    node_ply: np.ndarray  # (n_nodes,) int64 the ply of all of a node's elements, −1 if several
    node_ptr: np.ndarray  # (n_nodes + 1,) node → element CSR (Model)
    node_elem: np.ndarray
    node_mass: np.ndarray  # (n_nodes,) lumped masses (kg)
    h_node: np.ndarray  # (n_nodes,) node offsets h_p (m)
    h_seg: np.ndarray  # (n_elems,) segment offsets h_s (m); a solid's face: its reach D_s
    margin: float  # the search margin m (m)
    self_contact: bool  # pairs within a ply (unless the node's element shares a node)
    one_sided: np.ndarray  # (n_segments,) int8: 1 for a solid's face (outward normal, no offset)


class ContactSearch(NamedTuple):
    """Where a search looks: the positions it is made at, the nodes' skins, the
    segments' planes (contact_broad.segment_boxes) and the cell edge of its bins."""

    x: np.ndarray  # (n_nodes, 3) positions of the search (m)
    sigma: np.ndarray  # (n_nodes,) node skins σ_p (m)
    seg_plane: np.ndarray  # (n_elems, N_SEG_PLANE)
    edge: float  # the cell edge L (m)


class SegmentBinTables(NamedTuple):
    """The hashed-grid bins of segments (contact_broad.bin_segments): a bucket CSR over
    entries, one entry per (segment, cell) its padded box overlaps."""

    bucket_ptr: np.ndarray  # (n_buckets + 1,) int64
    entry_seg: np.ndarray  # (capacity,) int64 the entry's segment
    entry_cell: np.ndarray  # (capacity, 3) int64 its cell
    entry_box: np.ndarray  # (capacity, N_SEG_BOX) its segment's padded box
    entry_ply: np.ndarray  # (capacity,) int64 its segment's ply


class Candidates(NamedTuple):
    """Candidate (node, segment) pairs, node-major: node p's segments are
    seg[ptr[p]:ptr[p + 1]] in increasing order (written by the searches)."""

    ptr: np.ndarray  # (n_nodes + 1,) int64
    seg: np.ndarray  # (capacity,) int64


class ContactLaw(NamedTuple):
    """The penalty law of the shell pairs (contact_narrow.penalty_forces)."""

    beta: float  # penalty scale β of k = β min(m_p, m̄_s) / Δt²
    zeta: float  # pair dashpot, fraction ζ of critical
    mu: float  # Coulomb friction coefficient μ (0: frictionless)
    approach: bool  # the dashpot acts only while the pair closes (damping_mode "approach")


class PairTables(NamedTuple):
    """What the narrow phase writes of each candidate pair, (capacity, …) each
    (contact_narrow.penalty_forces: rows of the acting pairs, ``on`` ≠ 0)."""

    geo: np.ndarray  # (capacity, N_GEO) the projection (ξ, η, d, n, side)
    on: np.ndarray  # (capacity,) int8 1 for an acting pair
    force: np.ndarray  # (capacity, 3) force on the node (N)
    weights: np.ndarray  # (capacity, 4) N_I(ξ, η) of the contact point
    energy: np.ndarray  # (capacity,) ½ k g² (J)
    spring_damper: np.ndarray  # (capacity, 2) normal forces of the spring and the dashpot (N)
    power: np.ndarray  # (capacity, N_KINDS) powers of spring, dashpot, friction (W)


class EnergyBooks(NamedTuple):
    """Both halves of a step's contact work (kernels.contact_energy): ``before[kind, a,
    b] −= w_before · P`` with the powers at the velocities of the forces, ``after`` with
    those at the velocities after the node update (both written)."""

    w_before: float  # ½ Δt^{n−1/2} (s)
    before: np.ndarray  # (N_KINDS, P, P)
    w_after: float  # ½ Δt^{n+1/2} (s)
    after: np.ndarray  # (N_KINDS, P, P)


class ContactNodes(NamedTuple):
    """The nodes as the rigid-body contact reads them (contact_rigid; never written)."""

    x: np.ndarray  # (n, 3) positions x^n
    v: np.ndarray  # (n, 3) velocities v^{n−1/2}
    active: np.ndarray  # (n,) 0 for a node that takes no contact (eroded)
    mass: np.ndarray  # (n,) lumped masses (kg)
    offset: np.ndarray  # (n,) contact offsets h (m)


class BodyContact(NamedTuple):
    """A rigid body of revolution as the contact kernel sees it at x^n, with its
    penalty law (contact_rigid.rigid_contact_forces)."""

    tip: np.ndarray  # (3,) nose-tip position
    axis: np.ndarray  # (3,) unit axis, tip → tail
    velocity: np.ndarray  # (3,) the body's velocity V
    spin: np.ndarray  # (3,) its global spin ω
    centre: np.ndarray  # (3,) its centre of mass c
    prof_z: np.ndarray  # meridian profile polyline (ζ_i, ρ_i), tip to tail
    prof_r: np.ndarray
    reach: float  # bounding radius about the tip plus the largest offset (m)
    mass: float  # the body's mass in the model M (kg; its share in a symmetry model)
    beta: float  # penalty scale β of k = β m / Δt²
    zeta: float  # dashpot, fraction ζ of critical
    mu: float  # Coulomb friction coefficient μ


class BodyContactOut(NamedTuple):
    """What the rigid-body contact writes (contact_rigid.rigid_contact_forces)."""

    force: np.ndarray  # (n, 3) contact force on each node (N)
    energy: np.ndarray  # (n,) penalty energy ½ k g² of each node (J)
    parts: np.ndarray  # (n, 11) the pair's spring, dashpot, normal, force and powers
    contact_list: np.ndarray  # (n,) int64 the nodes in contact, in node order
