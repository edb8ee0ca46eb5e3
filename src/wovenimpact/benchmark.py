"""Cost of the explicit step: ns per element-cycle for elastic and fabric shell plates
(``wovenimpact bench``; ``make bench`` runs it between the fabric-kernel and the contact
benchmarks of ``benchmarks/``). The first line printed is :func:`machine_line`.

A clamped square plate, pre-stretched 2 % in-plane (so fabric yarns carry tension and
the crossover solve does real work) and set moving with a smooth transverse velocity
field, is stepped with one thread and with two. Prints one line per case with the
share of time per stage; ``--json`` prints {"cases": [{"name", "elements", "threads",
"ns_per_element_cycle", "shares"}]}. ``--sizes=10000,100000`` chooses plate sizes,
``--kinds=metal,fabric,fabric_reduced`` the plates (``metal``: a J2 aluminium plate at 5
points through the thickness; ``fabric_reduced``: the one-point membrane with hourglass
springs, for the cost of the 2×2 one), ``--threads=2`` the thread counts and ``--steps=N`` the
timed steps per case (20). The threading layer is printed first (``NUMBA_THREADING_LAYER``
overrides the default of :mod:`wovenimpact.jit`).
"""

from __future__ import annotations

import math
import time

import numba
import numpy as np

from pathlib import Path

from wovenimpact.errors import InputError
from wovenimpact.jit import set_threads
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.solver import Workspace, step
from wovenimpact.spec import load_material
from wovenimpact.state import initial_state

DEFAULT_SIZES = (10_000, 100_000, 400_000)
MATERIALS = Path(__file__).resolve().parents[2] / "examples" / "materials"
REFERENCE_FABRIC = MATERIALS / "kevlar_thesis.toml"
REFERENCE_METAL = MATERIALS / "aluminium.toml"
# elastic: 1 mm steel, resultant section; metal: 1 mm of the thesis aluminium, J2 at 5
# Simpson points, one-point membrane (its defaults); fabric(_reduced): the thesis Kevlar
KINDS = ("elastic", "metal", "fabric", "fabric_reduced")


def plate_model(kind: str, n_elements: int):
    """The benchmark plate of ``kind`` (one of :data:`KINDS`) with about ``n_elements``;
    the 2 % pre-stretch yields a metal plate, so its points do plastic returns."""
    if kind not in KINDS:
        raise InputError(f"bench kind {kind!r}; valid: {', '.join(KINDS)}")
    per_edge = int(round(math.sqrt(n_elements)))
    size = 0.94e-3
    mesh = plate_mesh(per_edge * size, size)
    if kind in ("fabric", "fabric_reduced"):  # 2×2 membrane (default) or one point + springs
        fabric = load_material(REFERENCE_FABRIC)
        sec = Section(fabric, bending_modulus=1e9, transverse_shear_modulus=3.28e9,
                      membrane="reduced" if kind == "fabric_reduced" else "full")
    elif kind == "metal":
        sec = Section(load_material(REFERENCE_METAL), thickness=1e-3)
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


def run_cases(kinds, sizes, thread_counts, steps: int = 20, report=None) -> list[dict]:
    """Measure every (kind, size, threads) case; ``report(case)`` after each one."""
    cases = []
    for kind in kinds:
        for n in sizes:
            for threads in thread_counts:
                cases.append(measure(kind, n, threads, steps))
                if report is not None:
                    report(cases[-1])
    return cases


def machine() -> dict:
    """What a timing depends on: CPU model, cores, threads Numba may use, OS, versions, date."""
    import os
    import platform
    from datetime import date

    from wovenimpact import __version__

    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "numba_threads": numba.config.NUMBA_NUM_THREADS,
            "system": platform.system(), "python": platform.python_version(),
            "numba": numba.__version__, "wovenimpact": __version__,
            "date": date.today().isoformat()}


def machine_line(m: dict | None = None) -> str:
    """The first line of ``wovenimpact bench`` / ``make bench``: where the numbers were taken
    (the README quotes times with this line)."""
    m = m or machine()
    return (f"machine: {m['cpu']}, {m['cores']} cores ({m['numba_threads']} Numba threads), "
            f"{m['system']}, Python {m['python']}, numba {m['numba']}, wovenimpact "
            f"{m['wovenimpact']}, {m['date']}")


def case_line(c: dict) -> str:
    shares = ", ".join(f"{k} {v:.0%}" for k, v in c["shares"].items())
    return (f"{c['name']:>14} {c['elements']:>7} elements, {c['threads']} thread(s): "
            f"{c['ns_per_element_cycle']:7.1f} ns per element-cycle  ({shares})")
