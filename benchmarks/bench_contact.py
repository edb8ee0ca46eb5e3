"""Cost of the shell–shell contact: ns per node and call for 1, 2, 4 and 6 stacked plies.

Quarter model of the 97 mm plate, 0.94 mm elements, plies 0.5 mm apart (0.4998 mm
shells, the thesis's casing plies nest: initial overlap removed), the stack pressed
together under a dome of transverse displacement (as under an impactor: up to 0.1 mm
at the centre for the top ply, so that part of the pairs is in contact) and set
sliding (the top ply at 5 m/s along x and 20 m/s down, the others in proportion to
their height, for any number of plies), with Coulomb friction μ = 0.2.
``ShellContact.forces`` is timed twice: with a search at every call (skin 0: broad +
narrow phase + assembly) and reusing its candidates (the default skin, positions fixed:
narrow phase + assembly, what most steps cost); the broad phase with the skin alone is
also reported, and 'book': the energy books of a step's pairs (``ShellContact.book``,
as the solver calls it once a step: the spring, dashpot and friction work per interface). The
cost per
node must stay about constant as plies multiply (linear scaling).
``--threads=1,2`` chooses the thread counts, ``--plies=1,2,4,6`` the stacks,
``--calls=N`` the timed calls per batch (50, best of 5 batches), ``--json`` prints
{"cases": [...]}, ``--save=PATH`` also writes it to PATH.
"""

from __future__ import annotations

import json
import sys
import time

import numba
import numpy as np

from wovenimpact.solver.shell_contact import ShellContact
from wovenimpact.interfaces import empty_books, part_arrays
from wovenimpact.jit import set_threads
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.model import Section, build_model
from wovenimpact.model.mesh import plate_mesh
from performance_page import save_json  # benchmarks/ is the script's folder

SIDE, SIZE, SPACING, THICK = 97e-3, 0.94e-3, 0.5e-3, 0.4998e-3


def stack(n_plies: int):
    mesh = plate_mesh(SIDE, SIZE, plies=n_plies, spacing=SPACING, quarter=True)
    steel = MetalParameters(name="steel", kind="elastic", density=7850.0, modulus=210e9,
                            poisson=0.3)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(steel, thickness=THICK)},
                        np.zeros(mesh.n_elems, int), ply=mesh.ply)
    r = np.linalg.norm(mesh.nodes[:, :2], axis=1) / (0.25 * SIDE)
    level = (mesh.nodes[:, 2] - mesh.nodes[:, 2].min()) / SPACING  # ply index 0 … n−1
    x = model.x0.copy()
    x[:, 2] -= 0.1e-3 * np.clip(1.0 - r, 0.0, None) ** 2 * level / max(n_plies - 1, 1) * 2.0
    v = np.zeros_like(x)
    # plies sliding on each other, the top one at 5 m/s along x and 20 m/s down, the
    # others in proportion to their height: the same speeds for any number of plies (a
    # speed growing with the ply index gave the 30-ply stack's top ply 600 m/s, and
    # skins, 8 |v| Δt, that listed plies far beyond the next)
    frac = level / max(n_plies - 1, 1)
    v[:, 0] = 5.0 * frac
    v[:, 2] = -20.0 * frac
    return mesh, model, x, v


def best_time(call, calls: int, repeats: int = 5) -> float:
    """Seconds per call: the best of ``repeats`` batches (a shared machine adds noise)."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        for _ in range(calls):
            call()
        best = min(best, (time.perf_counter() - t0) / calls)
    return best


def run_case(n_plies: int, threads: int, calls: int) -> dict:
    set_threads(threads)
    mesh, model, x, v = stack(n_plies)
    every_call = ShellContact(model, friction=0.2, skin=0.0)
    contact = ShellContact(model, friction=0.2)
    out = np.zeros((model.n_nodes, 3))
    alive = np.ones(model.n_elems)
    active = np.ones(model.n_nodes, dtype=np.int8)
    dt = 1e-7
    every_call.forces(x, v, dt, alive, active, out)  # compile, size buffers
    energy, n_active = contact.forces(x, v, dt, alive, active, out)
    searched = best_time(lambda: every_call.forces(x, v, dt, alive, active, out), calls)
    reused = best_time(lambda: contact.forces(x, v, dt, alive, active, out), calls)
    pairs = contact.n_pairs
    node_part, elem_part, _ = part_arrays(model)
    books = empty_books(model)[0]

    def book():  # both halves of a step (the second at the velocities after it: here v)
        contact.book(v, 0.5 * dt, books, 0.5 * dt, books, node_part, elem_part)

    booking = best_time(book, calls)
    broad = best_time(lambda: contact._search(x, contact.sigma), calls)
    n = model.n_nodes
    return {
        "plies": n_plies, "threads": threads, "nodes": n, "segments": model.n_elems,
        "pairs": every_call.n_pairs, "pairs_with_skin": pairs, "active": n_active,
        "energy_J": energy, "ns_per_node": 1e9 * searched / n,
        "reused_ns_per_node": 1e9 * reused / n, "broad_ns_per_node": 1e9 * broad / n,
        "book_ns_per_node": 1e9 * booking / n,
        "ms_per_call": 1e3 * searched,
    }


def main(argv: list[str]) -> None:
    opts = dict(a.lstrip("-").split("=", 1) if "=" in a else (a.lstrip("-"), "1") for a in argv)
    threads = [int(t) for t in opts.get("threads", "1,2").split(",")]
    threads = [t for t in threads if t <= numba.config.NUMBA_NUM_THREADS]
    calls = int(opts.get("calls", "50"))
    plies = [int(p) for p in opts.get("plies", "1,2,4,6").split(",")]
    cases = [run_case(p, t, calls) for t in threads for p in plies]
    save_json({"cases": cases}, argv)
    if "json" in opts:
        print(json.dumps({"cases": cases}))
        return
    print(f"threading layer: {numba.threading_layer()}; best of 5 × {calls} calls")
    print("ns per node and call: 'search' with a search every call, 'reuse' with the "
          "candidates of the skin kept, 'broad' the search with the skin alone, 'book' the "
          "energy books of a step's pairs")
    print(f"{'plies':>5} {'thr':>3} {'nodes':>7} {'pairs':>7} {'+skin':>7} {'active':>7} "
          f"{'search':>7} {'reuse':>7} {'broad':>7} {'book':>7} {'ratio':>6}")
    for c in cases:
        print(f"{c['plies']:>5} {c['threads']:>3} {c['nodes']:>7} {c['pairs']:>7} "
              f"{c['pairs_with_skin']:>7} {c['active']:>7} {c['ns_per_node']:>7.1f} "
              f"{c['reused_ns_per_node']:>7.1f} {c['broad_ns_per_node']:>7.1f} "
              f"{c['book_ns_per_node']:>7.1f} "
              f"{c['ns_per_node'] / c['reused_ns_per_node']:>6.2f}")



if __name__ == "__main__":
    main(sys.argv[1:])
