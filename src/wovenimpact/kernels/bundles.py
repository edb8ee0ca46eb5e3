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
