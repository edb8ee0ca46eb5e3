"""Named bundles of arrays for the two widest kernels (issue 13).

``shell.internal_force_for_shells`` and ``integrate.gather_and_update`` read and write
some twenty arrays each, most of them float64: passed one by one, two swapped arguments
compile and run. They take these bundles instead, so that a call site names what it
passes (``ElementStates(elem_in=state.elem, elem_out=ws.elem, …)``) and a kernel reads
``motion.x``, not its eleventh positional argument.

A bundle is a ``typing.NamedTuple`` of references to existing arrays (nothing is
copied). Numba takes a named tuple as an argument — fields of different dtypes
included — types it by its class and its fields' types, and caches the compiled kernel
(``cache=True``) like any other signature; the kernels unpack the fields into locals
before their ``prange`` loop, so the loops compile as they did with positional arrays.

Unpack one field per statement (``alive = out.alive``), never several in one tuple
assignment (``blocks, alive = out.blocks, out.alive``): Numba's alias analysis links
``a = t.a`` to the argument ``t`` but not the locals of a tuple built and unpacked, so
with ``parallel=True`` its dead-code pass may drop every write to such an array that the
kernel does not read again (Numba 0.68: the shell kernel's ``alive`` stayed 0 and every
node was eroded in the first step). tests/verification/test_kernel_bundles.py checks
that the kernels write every output field.

What is built when:

- ``NodeArrays``, ``ShellArrays``: fixed for a Model (``Model.node_arrays``,
  ``Model.shell_arrays``, built on first use and kept);
- ``ElementOutput``, ``NodeEnergy``: the Workspace's own scratch, built once in
  ``Workspace.for_model``;
- ``NodeMotion``, ``NodeForces``, ``ElementStates``: assembled at each call from the
  State's current arrays and the Workspace's buffers (a tuple of references; no array
  is allocated). The step swaps the State's and the Workspace's element, material and
  force arrays each step, and a caller may give the State new arrays (``state.x =
  …``), so a bundle of these built once would go stale.

Modules of the Python side may import this one: it holds no compiled code.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class NodeArrays(NamedTuple):
    """What the node update reads of the Model: the node → (element, corner) map and the
    nodes' masses, constraints and body forces (SI)."""

    node_ptr: np.ndarray  # (n_nodes + 1,) CSR offsets: node n's entries are ptr[n] … ptr[n+1]−1
    node_elem: np.ndarray  # (n_entries,) element of each entry
    node_corner: np.ndarray  # (n_entries,) its corner 0–3 (a row of the element's force block)
    mass: np.ndarray  # (n_nodes,) lumped translational mass m (kg)
    inertia: np.ndarray  # (n_nodes,) lumped isotropic rotary inertia I (kg m²)
    bc_code: np.ndarray  # (n_nodes, 6) per dof: 0 free, FIXED, PRESCRIBED, ROTATING (integrate)
    bc_velocity: np.ndarray  # (n_nodes, 6) prescribed velocity (ROTATING: ω 0–2, centre 3–5)
    body_accel: np.ndarray  # (n_nodes, 3) body-force acceleration g (m/s²)


class ShellArrays(NamedTuple):
    """What the shell force kernel reads of the Model: connectivity, sections, materials
    and reference geometry (tables laid out in ``shell_layout``)."""

    quads: np.ndarray  # (n_elems, 4) node indices, counter-clockwise about the normal
    elem_section: np.ndarray  # (n_elems,) row of ``sections`` of each element
    sections: np.ndarray  # (n_sections, N_SECTION) section table (C_* columns)
    mat_kind: np.ndarray  # (n_mats,) MAT_ELASTIC, MAT_FABRIC or MAT_J2
    mat_params: np.ndarray  # (n_mats, n_params) parameter rows, zero-padded
    area0: np.ndarray  # (n_elems,) reference areas A0 (m²)
    ref_grad: np.ndarray  # (n_elems, 2, 4) ∂N_I/∂X at the centre, reference material frame
    gauss_grad: np.ndarray  # (n_elems, 4, 2, 4) ∂N_I/∂X at the 2×2 Gauss points
    gauss_weight: np.ndarray  # (n_elems, 4) their weights det J
    point_width: int  # values in one material point's state block (0: no point state)


class NodeMotion(NamedTuple):
    """The nodes' kinematic state: the State's own arrays. The shell kernel reads x, v,
    ω; the node update advances all four in place."""

    x: np.ndarray  # (n_nodes, 3) positions x^n (x^{n+1} after the node update)
    v: np.ndarray  # (n_nodes, 3) velocities v^{n−1/2} (then v^{n+1/2})
    omega: np.ndarray  # (n_nodes, 3) angular velocities ω^{n−1/2} (then ω^{n+1/2}), global
    node_active: np.ndarray  # (n_nodes,) 1 while the node has a live element, else 0


class ElementStates(NamedTuple):
    """Element and material state at the start of the step (read) and at its end
    (written by the shell kernel): the State's and the Workspace's arrays, which swap
    after each step."""

    elem_in: np.ndarray  # (n_elems, N_ELEM_STATE) element state at the start (E_* columns)
    elem_out: np.ndarray  # (n_elems, N_ELEM_STATE) written: at the end
    mat_in: np.ndarray  # (n_elems, width) an element's points' state blocks side by side
    mat_out: np.ndarray  # (n_elems, width) written: at the end


class ElementOutput(NamedTuple):
    """What the shell kernel writes per element besides its state (Workspace scratch);
    the node update gathers ``blocks`` of the elements that are ``alive``."""

    blocks: np.ndarray  # (n_elems, 4, 6) corner forces (N) and moments (N·m), global axes
    alive: np.ndarray  # (n_elems,) uint8: 1 for an element alive at the end of the step
    status: np.ndarray  # (n_elems,) int32: EL_* code of the element's force evaluation
    eroded_now: np.ndarray  # (n_elems,) int32: 1 for an element eroded in this step


class NodeForces(NamedTuple):
    """Nodal forces of the node update: the new ones (written) are the Workspace's, the
    old ones the State's; the two swap after each step."""

    f_int: np.ndarray  # (n_nodes, 6) written: internal forces and moments at x^n
    f_ext: np.ndarray  # (n_nodes, 6) written: body forces plus reactions at x^n
    f_int_old: np.ndarray  # (n_nodes, 6) internal forces at x^{n−1}
    f_ext_old: np.ndarray  # (n_nodes, 6) external forces at x^{n−1}
    f_con: np.ndarray  # (n_nodes, 3) contact forces at x^n (external loads of the shells)


class NodeEnergy(NamedTuple):
    """Per-node energy terms written by the node update (Workspace scratch), summed by
    the caller in node order (a deterministic reduction)."""

    w_int: np.ndarray  # (n_nodes,) internal work over [x^{n−1}, x^n] (J)
    w_ext: np.ndarray  # (n_nodes,) external work over [x^{n−1}, x^n] (J)
    ke: np.ndarray  # (n_nodes,) kinetic energy at t^n, ½ m v^{n−1/2}·v^{n+1/2} (J)
    ke_eroded: np.ndarray  # (n_nodes,) kinetic energy of nodes that left the model now (J)
