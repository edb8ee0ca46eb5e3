"""Per-element energy audit: the work the nodes do on each element against the energy it books.

A diagnostic (not a test, not a benchmark): from a run's checkpoint, step the model N
steps and accumulate for every element the work of its own nodal forces over the nodes'
displacements (trapezoid on the element's force blocks, translations and rotations),

    W_e = Σ_n ½ (b_e^n + b_e^{n+1}) · Δu^{n+1/2},

and compare it with the change of the energy it books, ΔU_e (membrane + bending and
transverse shear + hourglass, ``E_U_MEMB + E_U_BEND + E_U_HG``). For a consistent element
the gap W_e − ΔU_e is the quadrature error, or positive where the material dissipates
without booking it (yarn failure, the trellis shear's path dependence); a negative gap is
energy the element gives its nodes that it never had. The run's energy balance cannot see
it (it balances the nodes' kinetic energy against W_int = Σ_e W_e), so this audit is
where to look when the internal work falls while the booked energies grow.

Usage: ``python benchmarks/element_work_audit.py CASE CHECKPOINT STEPS [KEY=VALUE ...]``
(the overrides the run had, e.g. ``'run.mass_scaling_fraction=0.08'``). Prints the gap
per section and the elements that created the most energy, with their fabric state.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from wovenimpact.io.checkpoint import _read_arrays
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.setup.compile import compile_case
from wovenimpact.solver.explicit import W_INT, Workspace, step
from wovenimpact.spec.case import load_case
from wovenimpact.state import State


def booked(state) -> np.ndarray:
    """(n_elems,) the energy each element books (J)."""
    return state.elem[:, SL.E_U_MEMB] + state.elem[:, SL.E_U_BEND] + state.elem[:, SL.E_U_HG]


def audit(case: str, checkpoint: str, steps: int, overrides=()) -> dict:
    """Step ``steps`` steps from ``checkpoint``; per-element work W, ΔU and the model."""
    spec, base = load_case(case, overrides)
    model = compile_case(spec, base).model
    state = State.from_arrays(_read_arrays(Path(checkpoint)))
    ws = Workspace.for_model(model, state)
    alive0 = state.elem[:, SL.E_ALIVE] != 0
    u0, w_int0, t0 = booked(state).copy(), float(state.energy[W_INT]), float(state.t)
    work = np.zeros(model.n_elems)
    quads = model.quads
    blocks_old = du_old = None
    for _ in range(steps):
        x_old = state.x.copy()
        step(model, state, ws)
        blocks = ws.blocks.copy()  # forces at the step's start configuration
        if blocks_old is not None:
            work += 0.5 * np.einsum("ecd,ecd->e", blocks_old + blocks, du_old[quads])
        du = np.zeros((model.n_nodes, 6))
        du[:, :3] = state.x - x_old
        du[:, 3:] = state.omega * state.dt
        blocks_old, du_old = blocks, du
    both = alive0 & (state.elem[:, SL.E_ALIVE] != 0)
    return {"model": model, "state": state, "work": work, "delta_u": booked(state) - u0,
            "alive": both, "t0": t0, "w_int_change": float(state.energy[W_INT]) - w_int0}


def main(argv: list[str]) -> None:
    case, checkpoint, steps, *overrides = argv
    a = audit(case, checkpoint, int(steps), overrides)
    model, state, both = a["model"], a["state"], a["alive"]
    gap = a["work"] - a["delta_u"]
    names = np.array(model.section_names)[model.elem_section]
    print(f"t {a['t0']:.4e} → {state.t:.4e} s: W_int changed by {a['w_int_change']:.2f} J")
    print(f"{'section':>10} {'elements':>8} {'W (J)':>10} {'ΔU (J)':>10} {'gap (J)':>10} "
          f"{'created (J)':>12}")
    for sec in np.unique(names):
        s = both & (names == sec)
        g = gap[s]
        print(f"{sec:>10} {s.sum():>8} {a['work'][s].sum():>10.2f} {a['delta_u'][s].sum():>10.2f} "
              f"{g.sum():>10.2f} {g[g < 0].sum():>12.2f}")
    width = model.point_width
    for e in np.argsort(np.where(both, gap, np.inf))[:12]:
        line = (f"element {e} ({names[e]}, ply {model.ply[e]}): W {a['work'][e]:.3f} J, "
                f"ΔU {a['delta_u'][e]:.3f} J, gap {gap[e]:.3f} J")
        kind = model.mat_kind[int(model.sections[model.elem_section[e], SL.C_MAT])]
        section = model.sections[model.elem_section[e]]
        n_in = 4 if int(section[SL.C_INPLANE]) == SL.MEMBRANE_FULL else 1
        if kind == SL.MAT_FABRIC:
            pts = state.mat[model.mat_row[e]:model.mat_row[e] + n_in, :width]
            line += (f"; λ_w,f {np.round(pts[:, FL.S_LAMBDA:FL.S_LAMBDA + 2], 2).tolist()}, "
                     f"broken {pts[:, FL.S_DAMAGE:FL.S_DAMAGE + 2].max(axis=0).tolist()}")
        print(line)


if __name__ == "__main__":
    main(sys.argv[1:])
