"""Where a case's step goes: the solver's stage timers over N steps from a given time.

A diagnostic (not a test): compiles CASE (with ``KEY=VALUE`` overrides), steps it to
T_START, then times N steps with ``Workspace.profile`` on and prints ms per step and
ns per element-cycle, each stage's share, and the shell contact's candidate count; then,
at the final state, the shell contact's parts timed alone (best of 10): the search's
binning and query, and the narrow phase with how many candidates it projected and how
many act, and the rest of a step's shell contact (masks, the reuse test, the segment
geometry, the assembly and the contact power) (docs/theory.md §6, "Where the contact
time goes").

Usage: ``python benchmarks/stage_profile.py CASE T_START N [KEY=VALUE ...]``, e.g.
``NUMBA_NUM_THREADS=1 python benchmarks/stage_profile.py
examples/containment/hybrid_10.toml 1.5e-4 100``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

from wovenimpact.jit import configure_threading
from wovenimpact.setup.compile import compile_case
from wovenimpact.solver.explicit import Workspace, step
from wovenimpact.spec.case import load_case


def main(argv: list[str]) -> None:
    configure_threading()  # the CLI's threading layer and wait policy (wovenimpact.jit)
    case, t_start, n_steps, *overrides = argv
    spec, base = load_case(case, overrides)
    compiled = compile_case(spec, base)
    model, state = compiled.model, compiled.state
    ws = Workspace.for_model(model, state)
    print(f"{model.n_elems} elements, {model.n_nodes} nodes", flush=True)
    t0 = time.perf_counter()
    while state.t < float(t_start):
        step(model, state, ws)
    print(f"to t = {state.t:.3e} s: {state.step} steps in {time.perf_counter() - t0:.1f} s")
    ws.profile, ws.timings = True, {}
    n = int(n_steps)
    t0 = time.perf_counter()
    for _ in range(n):
        step(model, state, ws)
    wall = time.perf_counter() - t0
    print(f"{n} steps: {wall / n * 1e3:.2f} ms per step, "
          f"{wall / n / model.n_elems * 1e9:.0f} ns per element-cycle (Δt {state.dt:.3e} s)")
    total = sum(ws.timings.values())
    for stage, seconds in sorted(ws.timings.items(), key=lambda kv: -kv[1]):
        print(f"  {stage:24s} {seconds / n * 1e3:8.3f} ms  {100 * seconds / total:5.1f} %")
    shells = ws.contact.shells
    if shells is not None:
        print(f"shell contact: {shells.n_pairs} candidates, {shells.searches} searches, "
              f"{shells.updates} incremental updates")
        contact_parts(shells, state)


# the assembly adds the contact forces to ``out`` (as the solver calls it, into f_ext)
ACCUMULATE = True


def best_ms(f, repeats: int = 10):
    """Best wall time of ``repeats`` calls of f (ms) and its last result."""
    best, out = float("inf"), None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best * 1e3, out


def contact_parts(sc, state) -> None:
    """The shell contact's search and narrow phase at ``state``, each timed alone."""
    from wovenimpact.kernels import contact_broad as B
    from wovenimpact.kernels import contact_update as U
    from wovenimpact.kernels.bundles import ContactSearch
    from wovenimpact.kernels.contact_narrow import (
        GEO_SIDE,
        assemble_contact_forces,
        penalty_forces,
        segment_geometry,
    )
    from wovenimpact.kernels.integrate import force_pair_power
    from wovenimpact.kernels.shell_layout import E_ALIVE

    x = np.ascontiguousarray(state.x)
    sigma = sc.sigma.copy()
    t_all, n = best_ms(lambda: sc._search(x, sigma))
    t_box, _ = best_ms(lambda: B.segment_boxes(x, sc.quads, sc.seg_on, sc.h_seg, sigma,
                                                sc.margin, sc.seg_box, sc.seg_plane))
    edge = B.cell_edge(sc.seg_on, sc.seg_box)
    t_bin, entries = best_ms(lambda: B.bin_segments(
        sc.seg_on, sc.seg_box, sc.ply, 1.0 / edge, sc.bucket_ptr, sc.entry_seg, sc.entry_cell,
        sc.entry_box, sc.entry_ply))
    search = ContactSearch(x=x, sigma=sigma, seg_plane=sc.seg_plane, edge=edge)
    t_query, _ = best_ms(lambda: B.query_candidates(
        sc.surfaces, search, sc.node_on, sc.bins, sc.no_skip, sc.slots, sc.candidates_now))
    nodes = int((sc.node_on != 0).sum())
    print(f"  one search {t_all:.2f} ms: boxes {t_box:.2f}, binning {t_bin:.2f} ({entries} "
          f"entries, cell {edge * 1e3:.2f} mm), query {t_query:.2f} ({n} candidates, "
          f"{t_query / max(nodes, 1) * 1e6:.0f} ns per node)")
    segment_geometry(x, sc.quads, sc.seg_on, sc.seg_geo)
    args = (x, state.v, float(state.dt), sc.surfaces, sc.law, sc.overlap, sc.seg_geo, sc.seg_on,
            sc.node_on, sc.candidates_now, sc.pair_tables, sc.node_f)
    sc.geo[:n, GEO_SIDE] = 0.0  # the narrow phase writes the rows of projected pairs only
    t_pen, _ = best_ms(lambda: penalty_forces(*args))
    projected = int((sc.geo[:n, GEO_SIDE] != 0).sum())
    acting = int((sc.pair_on[:n] != 0).sum())
    print(f"  narrow phase {t_pen:.2f} ms: {n} candidates ({t_pen / max(n, 1) * 1e6:.1f} ns "
          f"each), {projected} projected, {acting} acting")
    # the rest of a step's shell contact (ShellContact.forces), each timed alone
    alive = state.elem[:, E_ALIVE].copy()
    t_mask, _ = best_ms(lambda: B.contact_masks(alive, sc.elem_part, state.node_active,
                                                sc.node_part, sc.seg_on, sc.node_on))
    t_valid, _ = best_ms(lambda: (U.surfaces_joined(sc.node_on, sc.node_on_search, sc.seg_on,
                                                    sc.seg_on_search),
                                  U.nodes_beyond_skins(x, sc.x_search, sc.sigma, sc.node_on,
                                                       state.v, 4.0 * state.dt, sc.far)))
    t_geo, _ = best_ms(lambda: segment_geometry(x, sc.quads, sc.seg_on, sc.seg_geo))
    out = np.zeros((x.shape[0], 3))
    t_asm, _ = best_ms(lambda: assemble_contact_forces(
        sc.quads, sc.candidates_now, sc.pair_tables, sc.node_f, sc.seg_ptr, sc.seg_entry,
        sc.cursor, out, ACCUMULATE, sc.active))
    work = np.zeros(x.shape[0])
    t_pow, _ = best_ms(lambda: force_pair_power(out, out, state.v, float(state.dt), work))
    sc.n_active = int((sc.pair_on[:n] != 0).sum())  # the pairs the assembly listed
    books = np.zeros((3, int(sc.ply.max()) + 1, int(sc.ply.max()) + 1))
    node_part = np.maximum(sc.node_ply, 0)
    t_book, _ = best_ms(lambda: sc.book(state.v, 0.5 * state.dt, books, 0.5 * state.dt, books,
                                        node_part, sc.ply))
    print(f"  per step besides: masks {t_mask:.2f}, reuse test {t_valid:.2f}, segment "
          f"geometry {t_geo:.2f}, assembly {t_asm:.2f}, contact power {t_pow:.2f}, "
          f"energy books (both halves) {t_book:.2f} ms")


if __name__ == "__main__":
    main(sys.argv[1:])
