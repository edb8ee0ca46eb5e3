"""The element stage with and without the blocks (kernels.shell_blocks) on a case's state.

A diagnostic (not a test): compiles CASE, steps it to T (seconds), then prints how many
lanes the block stage left to ``shell_force`` in the last step, how many crossover
points were solved exactly, and ns per element of ``shell_forces`` (best of 20) with the
blocks and without (docs/theory.md §4.6, "The element stage in blocks").

Usage: ``python benchmarks/bench_block_stage.py CASE T THREADS``, e.g.
``python benchmarks/bench_block_stage.py examples/plate_impact/plies4_120.toml 1e-4 1``;
CASE ``plate:N`` is ``make bench``'s fabric plate of about N elements.
"""

from __future__ import annotations

import sys
import time

from wovenimpact.jit import configure_threading, set_threads
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.setup.compile import compile_case
from wovenimpact.solver.explicit import Workspace, shell_forces, step
from wovenimpact.spec.case import load_case


def best_seconds(f, repeats: int = 20) -> float:
    t = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        f()
        t = min(t, time.perf_counter() - t0)
    return t


def case_state(case: str, t_end: float, threads: int):
    """CASE compiled and stepped to t_end on ``threads`` threads: (model, state, workspace),
    or None when no element of the case goes into blocks. CASE ``plate:N`` is ``make
    bench``'s fabric plate of about N elements (``wovenimpact.benchmark.plate_model``)."""
    configure_threading()
    set_threads(threads)
    if case.startswith("plate:"):
        from wovenimpact.benchmark import plate_model

        model, state = plate_model("fabric", int(case.removeprefix("plate:")))
    else:
        spec, base = load_case(case, [])
        compiled = compile_case(spec, base)
        model, state = compiled.model, compiled.state
    ws = Workspace.for_model(model, state)
    kinds = set() if ws.plan is None else {
        int(model.mat_kind[int(model.sections[s, SL.C_MAT])]) for s in ws.plan.section}
    if kinds != {SL.MAT_FABRIC}:  # the fabric stages are what is measured here
        print("the blocks of this case are not all fabric ones (or WOVENIMPACT_BLOCKS=0)")
        return None
    while state.t < t_end:
        step(model, state, ws)
    return model, state, ws


def main(argv: list[str]) -> None:
    case, t_end, threads = argv[0], float(argv[1]), int(argv[2])
    found = case_state(case, t_end, threads)
    if found is None:
        return
    model, state, ws = found
    rows = state.mat.reshape(-1, model.point_width)
    print(f"t = {state.t:.3e} s: {int(ws.scratch.pending.sum())} of {ws.plan.elems.size} block "
          f"lanes left to shell_force; {int((rows[:, FL.S_ITER] > 0).sum())} of {rows.shape[0]} "
          "points solved exactly")
    with_blocks = best_seconds(lambda: shell_forces(model, state, ws))
    ws.plan = None
    without = best_seconds(lambda: shell_forces(model, state, ws))
    n = model.n_elems
    print(f"element stage, {threads} thread(s): blocks {with_blocks / n * 1e9:.0f} ns, "
          f"shell_force {without / n * 1e9:.0f} ns per element ({without / with_blocks:.2f}x)")


if __name__ == "__main__":
    main(sys.argv[1:])
