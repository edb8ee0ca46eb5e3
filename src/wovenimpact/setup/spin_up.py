"""The spin-up of a containment case: the blade's steady spin state, relaxed before the
run starts (theory §8.1).

:func:`~wovenimpact.setup.compile.compile_case` calls :func:`spin_blade` as a step of its
own, after the pre-run checks of the unspun case and before the containment checks of
the spun blade; the relaxation itself is the solver's
(:func:`wovenimpact.solver.relaxation.spin_state`).
"""

from __future__ import annotations

import numpy as np

from wovenimpact.model.mesh import Mesh
from wovenimpact.model.model import BoundaryConditions, Model, Section, build_model
from wovenimpact.solver.relaxation import centrifugal_acceleration, spin_state
from wovenimpact.state import BODY_KINETIC, KINETIC, KINETIC0, State


def spin_blade(model: Model, state: State, mesh: Mesh, section: Section, omega, tol,
               warp) -> None:
    """The blade's steady spin state (solver.relaxation) written into ``state``: the
    blade alone, clamped at its root and loaded by ω² r⊥, relaxed; its configuration,
    element and material state copied in, with v = ω × x and spins ω."""
    elems = mesh.elem_sets["blade.blade"]
    nodes = np.unique(mesh.quads[elems])
    local = np.searchsorted(nodes, mesh.quads[elems])
    x = mesh.nodes[nodes]
    root = np.searchsorted(nodes, mesh.node_sets["blade.root"])
    es = np.zeros(len(elems), dtype=np.int64)
    bc = BoundaryConditions(len(x)).fix(root)
    free = build_model(x, local, {"blade": section}, es, bcs=bc, alpha=model.alpha,
                       warp_direction=warp[elems])
    held = build_model(x, local, {"blade": section}, es, bcs=bc, alpha=model.alpha,
                       warp_direction=warp[elems], body_accel=centrifugal_acceleration(x, omega))
    spun, _ = spin_state(held, free, omega, tol=tol)
    state.x[nodes] = spun.x
    state.v[nodes] = spun.v
    state.omega[nodes] = spun.omega
    state.elem[elems] = spun.elem
    width = min(free.point_width, model.point_width)
    if width:  # the blade's points' rows (the same section, so as many rows per element)
        n_rows = np.diff(free.mat_row)
        src = np.arange(free.mat_row[-1])  # the blade model's rows, element by element
        dst = src + np.repeat(model.mat_row[elems] - free.mat_row[:-1], n_rows)
        state.mat[dst, :width] = spun.mat[src, :width]
    ke = 0.5 * float(np.sum(model.node_mass[:, None] * state.v**2)
                     + np.sum(model.node_inertia[:, None] * state.omega**2))
    state.energy[KINETIC] = ke
    state.energy[KINETIC0] = ke + state.energy[BODY_KINETIC]
