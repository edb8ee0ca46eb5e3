"""Is a refactoring bitwise neutral? Run a case for N steps through the solver API in two
source trees and compare the States with ``np.array_equal``.

    git worktree add /tmp/base <base commit>
    PYTHONPATH=/tmp/base/src python benchmarks/bitwise_state.py save CASE 300 base.npz
    PYTHONPATH=src python benchmarks/bitwise_state.py save CASE 300 new.npz
    python benchmarks/bitwise_state.py compare base.npz new.npz

``save`` writes x, v, omega, energy, elem, mat, f_int, f_ext, bodies, t and dt of the
State after STEPS steps (``--threads N``: N Numba threads); ``compare`` prints each array
as equal or not and exits 1 on any difference. PYTHONPATH picks the tree (the package is
installed editable from one of them). Issue 13: 300 steps of
examples/plate_impact/plies4_120.toml are the check of a kernel refactoring.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

FIELDS = ("x", "v", "omega", "energy", "elem", "mat", "f_int", "f_ext", "bodies", "t", "dt")


def save(case: str, steps: int, out: str, threads: int | None) -> None:
    import wovenimpact
    from wovenimpact.jit import configure_threading, set_threads
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.solver import Workspace, step
    from wovenimpact.spec.case import load_case

    configure_threading()
    if threads:
        set_threads(threads)
    spec, base = load_case(case)
    compiled = compile_case(spec, Path(base))
    model, state = compiled.model, compiled.state
    ws = Workspace.for_model(model, state)
    t0 = time.perf_counter()
    for _ in range(steps):
        step(model, state, ws)
    print(f"{wovenimpact.__file__}: {steps} steps of {case} ({model.n_elems} elements) in "
          f"{time.perf_counter() - t0:.2f} s, t = {state.t:.9e} s")
    np.savez(out, **{name: getattr(state, name) for name in FIELDS})


def compare(a: str, b: str) -> bool:
    fa, fb = np.load(a), np.load(b)
    same_all = True
    for name in FIELDS:
        same = np.array_equal(fa[name], fb[name])
        same_all &= same
        print(f"{name:7s} {'bitwise equal' if same else 'DIFFERENT'}  {fa[name].shape}")
    print("all bitwise equal" if same_all else "DIFFERENT")
    return same_all


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p_save = sub.add_parser("save", help="run CASE for STEPS steps, save the State to OUT")
    p_save.add_argument("case")
    p_save.add_argument("steps", type=int)
    p_save.add_argument("out")
    p_save.add_argument("--threads", type=int, default=None)
    p_cmp = sub.add_parser("compare", help="compare two saved States bitwise")
    p_cmp.add_argument("a")
    p_cmp.add_argument("b")
    args = parser.parse_args()
    if args.command == "save":
        save(args.case, args.steps, args.out, args.threads)
    else:
        sys.exit(0 if compare(args.a, args.b) else 1)


if __name__ == "__main__":
    main()
