"""Where a case's step goes: the solver's stage timers over N steps from a given time.

A diagnostic (not a test): compiles CASE (with ``KEY=VALUE`` overrides), steps it to
T_START, then times N steps with ``Workspace.profile`` on and prints ms per step and
ns per element-cycle, each stage's share, and the shell contact's candidate count.

Usage: ``python benchmarks/stage_profile.py CASE T_START N [KEY=VALUE ...]``, e.g.
``NUMBA_NUM_THREADS=1 python benchmarks/stage_profile.py
examples/containment/hybrid_10.toml 1.5e-4 100``.
"""

from __future__ import annotations

import sys
import time

from wovenimpact.model.compile import compile_case
from wovenimpact.solver.explicit import Workspace, step
from wovenimpact.spec.case import load_case


def main(argv: list[str]) -> None:
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
        print(f"shell contact: {shells.n_pairs} candidates, {shells.searches} searches")


if __name__ == "__main__":
    main(sys.argv[1:])
