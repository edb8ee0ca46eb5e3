"""Solid stage of the step: the hexahedra's corner forces at x^n (docs/solid.md §4).

Called beside the shells' element stage. ``internal_force_for_hexes`` (kernels/hex8.py)
updates every hexahedron from x^n and the step's corner increments Δt^{n−1/2} v^{n−1/2}
(Green–Naghdi stress of the transversely isotropic material, stiffness-form hourglass
forces, stored and hourglass energies, the element's stable step l_e/c_e), each element
writing only its own rows: the (n_hexes, 8, 3) force blocks and the next state table.
The node pass (kernels/integrate.py, ``gather_and_update``) then adds the blocks to the
shells' through the Model's node → (hexahedron, corner) map, in a fixed order, so no
force is scattered and the result is the same for any thread count.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wovenimpact.errors import SimulationError
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels import solid_layout as HL
from wovenimpact.kernels.bundles import HexGather, HexMesh, HexResults, HexTables, Motion
from wovenimpact.kernels.hex8 import internal_force_for_hexes
from wovenimpact.model.solid import solid_node_map

STATUS_TEXT = {
    SL.EL_INVERTED: "inverted or degenerate (non-positive volume)",
    SL.EL_MATERIAL: "material point failed (the polar decomposition did not converge)",
    SL.EL_NAN: "non-finite force or time step (NaN/inf)",
}


@dataclass
class SolidBuffers:
    """The hexahedron kernel's view of a Model and its preallocated outputs."""

    mesh: HexMesh | None  # None in a model without solids
    results: HexResults
    gather: HexGather  # what the node pass adds (empty map without solids)
    dt_min: float = math.inf  # min_e l_e/c_e of the last solid stage (s)

    @classmethod
    def for_model(cls, model) -> SolidBuffers:
        s = model.solid
        ne = s.n_hexes
        results = HexResults(blocks=np.zeros((ne, 8, 3)), status=np.zeros(ne, dtype=np.int32))
        ptr, elem, corner = solid_node_map(model)
        gather = HexGather(node_ptr=ptr, node_elem=elem, node_corner=corner,
                           blocks=results.blocks)
        mesh = None
        if ne:
            mesh = HexMesh(hexes=s.hexes, elem_mat=s.mat, mat_params=s.params, frame=s.frame,
                           ref_grad=s.ref_grad, vol0=s.vol0, hg_stiffness=s.hg_stiffness)
        return cls(mesh=mesh, results=results, gather=gather)


def solid_forces(model, state, hex_out: np.ndarray, sb: SolidBuffers) -> None:
    """Corner forces of every hexahedron at x^n into ``sb.results.blocks``, their next
    state into ``hex_out`` and the smallest element step into ``sb.dt_min``; stops
    naming the first element that failed."""
    if sb.mesh is None:
        sb.dt_min = math.inf
        return
    motion = Motion(x=state.x, v=state.v, omega=state.omega)
    n_failed, sb.dt_min = internal_force_for_hexes(
        sb.mesh, motion, state.dt, HexTables(el_in=state.hex, el_out=hex_out), sb.results)
    if n_failed:
        bad = np.flatnonzero(sb.results.status)
        e = int(bad[0])
        raise SimulationError(
            f"hexahedron {e} (nodes {model.solid.hexes[e].tolist()}) at t = {state.t:.6e} s, "
            f"step {state.step}: "
            f"{STATUS_TEXT.get(int(sb.results.status[e]), 'unknown failure')}"
            + (f"; {bad.size} hexahedra in this state" if bad.size > 1 else ""))


def governing_hexahedron(model, hex_state: np.ndarray) -> str:
    """Words naming the hexahedron of the smallest step in ``hex_state`` (for messages)."""
    e = int(np.argmin(hex_state[:, HL.H_DT]))
    return (f"hexahedron {e} (nodes {model.solid.hexes[e].tolist()}, step "
            f"{hex_state[e, HL.H_DT]!r} s)")
