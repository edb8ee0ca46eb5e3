"""Fabric plate step with the exact crossover solve vs the tabulated one (theory §1.9).

The plate of :mod:`wovenimpact.benchmark` (clamped, pre-stretched 2 %, moving), built
once with each option; the two are stepped alternately in the same process (blocks of
``--steps`` steps), and each option's minimum over ``--repeats`` blocks is reported, so a
loaded machine weighs on both alike. ``--kinds=fabric,fabric_reduced``,
``--size=10000``, ``--threads=1``.
"""

from __future__ import annotations

import dataclasses
import math
import sys
import time

from wovenimpact import benchmark as B
from wovenimpact.jit import set_threads
from wovenimpact.solver import Workspace, step


def arg(name, default):
    for a in sys.argv[1:]:
        if a.startswith(f"--{name}="):
            return a.split("=", 1)[1]
    return default


def plate(kind, n, crossover):
    load = B.load_material

    def patched(path):
        m = load(path)
        return dataclasses.replace(m, options=dataclasses.replace(m.options, crossover=crossover))

    B.load_material = patched
    try:
        return B.plate_model(kind, n)
    finally:
        B.load_material = load


def main():
    kinds = arg("kinds", "fabric,fabric_reduced").split(",")
    n = int(arg("size", "10000"))
    steps = int(arg("steps", "10"))
    repeats = int(arg("repeats", "5"))
    set_threads(int(arg("threads", "1")))
    for kind in kinds:
        runs = {}
        for c in ("exact", "table"):
            model, st = plate(kind, n, c)
            ws = Workspace.for_model(model, st)
            for _ in range(3):
                step(model, st, ws)
            runs[c] = (model, st, ws)
        best = {c: math.inf for c in runs}
        for _ in range(repeats):
            for c, (model, st, ws) in runs.items():
                t = time.perf_counter()
                for _ in range(steps):
                    step(model, st, ws)
                best[c] = min(best[c], (time.perf_counter() - t) / (steps * model.n_elems) * 1e9)
        print(f"{kind}_plate {runs['exact'][0].n_elems} elements: exact {best['exact']:.0f}, "
              f"table {best['table']:.0f} ns per element-cycle; ratio {best['exact'] / best['table']:.2f}×")


if __name__ == "__main__":
    main()
