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
overrides the default of :mod:`wovenimpact.jit`). Each case also reports the memory per
element (the model's, state's and workspace's arrays), its ratio to the elastic plate of
the same size and threads, and its ratio to the previous release's figure kept in
``benchmarks/release_figures.json`` (``--save-release`` writes this run's figures there,
at a release, on an idle machine).
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
        "bytes_per_element": array_bytes(model, st, ws) / model.n_elems,
        "shares": {k: v / total for k, v in ws.timings.items()},
    }


def array_bytes(*holders) -> int:
    """Bytes of the NumPy arrays the objects hold as attributes (model, state and
    workspace of a run: what the step reads and writes; a shared array counted once)."""
    seen: dict[int, int] = {}
    for h in holders:
        for value in vars(h).values():
            if isinstance(value, np.ndarray):
                base = value if value.base is None else value.base
                if isinstance(base, np.ndarray):
                    seen[id(base)] = base.nbytes
    return sum(seen.values())


RELEASE_FIGURES = Path(__file__).resolve().parents[2] / "benchmarks" / "release_figures.json"


def case_key(c: dict) -> str:
    """"fabric_plate/10000/1": the case's name, size and threads (the figure's key)."""
    return f"{c['name']}/{c['elements']}/{c['threads']}"


def compare(cases: list[dict], previous: dict | None = None) -> list[dict]:
    """Add to each case ``ratio_to_elastic`` (its ns per element-cycle over the elastic
    plate's of the same size and threads in this run, when that ran) and
    ``ratio_to_previous`` (over the previous release's figure in ``previous``, the
    content of benchmarks/release_figures.json, when it has the case)."""
    by_key = {case_key(c): c for c in cases}
    figures = (previous or {}).get("ns_per_element_cycle", {})
    for c in cases:
        elastic = by_key.get(f"elastic_plate/{c['elements']}/{c['threads']}")
        c["ratio_to_elastic"] = (c["ns_per_element_cycle"] / elastic["ns_per_element_cycle"]
                                 if elastic else None)
        before = figures.get(case_key(c))
        c["ratio_to_previous"] = c["ns_per_element_cycle"] / before if before else None
    return cases


def release_figures(cases: list[dict], m: dict | None = None) -> dict:
    """What benchmarks/release_figures.json keeps of a bench run: the machine and each
    case's ns per element-cycle (``make bench`` compares the next release with it)."""
    return {"machine": machine_line(m),
            "ns_per_element_cycle": {case_key(c): round(c["ns_per_element_cycle"], 1)
                                     for c in cases}}


def run_cases(kinds, sizes, thread_counts, steps: int = 20, report=None,
              previous: dict | None = None) -> list[dict]:
    """Measure every (kind, size, threads) case; ``report(case)`` after each one, with
    its ratios (:func:`compare`: run the elastic plate first for ``ratio_to_elastic``)
    to this run's elastic plate and to ``previous`` (default: the figures stored in
    benchmarks/release_figures.json, if any)."""
    if previous is None:
        previous = load_release_figures()
    cases = []
    for kind in kinds:
        for n in sizes:
            for threads in thread_counts:
                cases.append(measure(kind, n, threads, steps))
                compare(cases, previous)
                if report is not None:
                    report(cases[-1])
    return cases


def load_release_figures(path: Path = None) -> dict:
    """The previous release's figures (benchmarks/release_figures.json; {} if absent)."""
    import json

    path = path or RELEASE_FIGURES
    return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else {}


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
    ratios = "".join(f", {label} {c[key]:.2f}×" for key, label in
                     (("ratio_to_elastic", "elastic"), ("ratio_to_previous", "previous release"))
                     if c.get(key) is not None)
    memory = f", {c['bytes_per_element']:.0f} B/element" if "bytes_per_element" in c else ""
    return (f"{c['name']:>14} {c['elements']:>7} elements, {c['threads']} thread(s): "
            f"{c['ns_per_element_cycle']:7.1f} ns per element-cycle{memory}{ratios}  "
            f"({shares})")
