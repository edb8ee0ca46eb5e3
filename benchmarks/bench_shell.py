"""Cost of the explicit step: ns per element-cycle for elastic and fabric shell plates.

A clamped square plate, pre-stretched 2 % in-plane (so fabric yarns carry tension and
the crossover solve does real work) and set moving with a smooth transverse velocity
field, is stepped with one thread and with two. Prints one line per case with the
share of time per stage; ``--json`` prints {"cases": [{"name", "elements", "threads",
"ns_per_element_cycle", "shares"}]}. ``--sizes=10000,100000`` chooses plate sizes,
``--kinds=fabric`` the plates, ``--threads=2`` the thread counts and ``--steps=N`` the
timed steps per case (20). The threading layer is printed first (``NUMBA_THREADING_LAYER``
overrides the default of :mod:`wovenimpact.jit`).
"""

from __future__ import annotations

import json
import math
import sys
import time

import numba
import numpy as np

from wovenimpact.jit import set_threads
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.solver import Workspace, step
from wovenimpact.spec import load_material
from wovenimpact.state import initial_state

DEFAULT_SIZES = (10_000, 100_000, 400_000)


def plate_model(kind: str, n_elements: int):
    per_edge = int(round(math.sqrt(n_elements)))
    size = 0.94e-3
    mesh = plate_mesh(per_edge * size, size)
    if kind == "fabric":
        fabric = load_material("examples/materials/kevlar_thesis.toml")
        sec = Section(fabric, bending_modulus=1e9, transverse_shear_modulus=3.28e9)
    else:
        steel = MetalParameters(name="steel", kind="elastic", density=7850.0, modulus=210e9,
                                poisson=0.3)
        sec = Section(steel, thickness=1e-3)
    bc = BoundaryConditions(mesh.n_nodes).fix(mesh.node_sets["edge_outer"])
    model = build_model(mesh.nodes, mesh.quads, {"s": sec}, np.zeros(mesh.n_elems, int), bcs=bc)
    half = 0.5 * per_edge * size
    r = np.linalg.norm(mesh.nodes[:, :2], axis=1) / half
    v0 = np.zeros((mesh.n_nodes, 3))
    v0[:, 2] = -50.0 * np.clip(1.0 - r, 0.0, None) ** 2
    st = initial_state(model, velocity=v0)
    st.x[:, :2] *= 1.02
    return model, st


def measure(kind: str, n_elements: int, threads: int, steps: int = 20) -> dict:
    set_threads(threads)
    model, st = plate_model(kind, n_elements)
    ws = Workspace.for_model(model, st)
    for _ in range(3):  # compile and warm up
        step(model, st, ws)
    ws.profile = True
    ws.timings.clear()
    t0 = time.perf_counter()
    for _ in range(steps):
        step(model, st, ws)
    wall = time.perf_counter() - t0
    total = sum(ws.timings.values())
    return {
        "name": f"{kind}_plate",
        "elements": model.n_elems,
        "threads": threads,
        "ns_per_element_cycle": wall / (steps * model.n_elems) * 1e9,
        "shares": {k: v / total for k, v in ws.timings.items()},
    }


def main() -> None:
    sizes = DEFAULT_SIZES
    kinds = ("elastic", "fabric")
    thread_counts = sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)})
    steps = 20
    for arg in sys.argv[1:]:
        if arg.startswith("--sizes="):
            sizes = tuple(int(s) for s in arg.split("=", 1)[1].split(","))
        elif arg.startswith("--kinds="):
            kinds = tuple(arg.split("=", 1)[1].split(","))
        elif arg.startswith("--threads="):
            thread_counts = [int(s) for s in arg.split("=", 1)[1].split(",")]
        elif arg.startswith("--steps="):
            steps = int(arg.split("=", 1)[1])
    cases = []
    for kind in kinds:
        for n in sizes:
            for threads in thread_counts:
                cases.append(measure(kind, n, threads, steps))
                if len(cases) == 1 and "--json" not in sys.argv:
                    print(f"threading layer: {numba.threading_layer()}", flush=True)
                if "--json" not in sys.argv:
                    c = cases[-1]
                    shares = ", ".join(f"{k} {v:.0%}" for k, v in c["shares"].items())
                    print(f"{c['name']:>14} {c['elements']:>7} elements, {threads} thread(s): "
                          f"{c['ns_per_element_cycle']:7.1f} ns per element-cycle  ({shares})",
                          flush=True)
    if "--json" in sys.argv:
        print(json.dumps({"cases": cases}))


if __name__ == "__main__":
    main()
