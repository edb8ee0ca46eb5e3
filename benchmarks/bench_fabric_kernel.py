"""Throughput of the crossover kernel: ns per material-point update, exact solve vs table.

Points are driven through a realistic step: from a random stretched/sheared state
(F_old) to a slightly different one (F_new), warm-started from the converged state
at F_old, as the explicit solver will call it. The two crossover options (exact height
solve, tabulated stored energy: theory §1.9) run interleaved in the same process, the
minimum of ``repeats`` timings each, so that a loaded machine affects both alike. Prints
one line per option and thread count, and the ratio; ``--json`` prints them as JSON,
``--save=PATH`` also writes that JSON to PATH.
"""

from __future__ import annotations

import dataclasses
import json
import math
import sys
import time

import numba
import numpy as np

from wovenimpact.jit import set_threads
from wovenimpact.kernels import fabric_layout as L
from wovenimpact.kernels.fabric import fabric_update_for_points
from wovenimpact.spec import load_material
from wovenimpact.materials.fabric import initial_state
from performance_page import save_json  # benchmarks/ is the script's folder


def stretch_shear(lam_w, lam_f, gamma):
    return np.array([[lam_w, lam_f * math.sin(gamma)], [0.0, lam_f * math.cos(gamma)]])


def main(n: int = 200_000, repeats: int = 7) -> None:
    base = load_material("examples/materials/kevlar_thesis.toml")
    rows = {
        c: dataclasses.replace(base, options=dataclasses.replace(base.options, crossover=c)).to_array()
        for c in ("exact", "table")
    }
    rng = np.random.default_rng(1)
    lw, lf, g = rng.uniform(1.0, 1.035, n), rng.uniform(1.0, 1.035, n), rng.uniform(-0.3, 0.3, n)
    f_old = np.array([stretch_shear(*x) for x in zip(lw, lf, g)])
    f_new = np.array([stretch_shear(*x) for x in zip(lw + 1e-5, lf + 1e-5, g + 1e-4)])
    s0 = initial_state(base, n)
    out_n = np.empty((n, 3))
    out_k = np.empty(n)
    status = np.empty(n, dtype=np.int32)
    eye = np.repeat(np.eye(2)[None], n, axis=0)
    s_old = {}
    for c, p in rows.items():  # warm states at F_old, each option its own
        s_old[c] = np.empty_like(s0)
        fabric_update_for_points(p, eye, f_old, s0, s_old[c], out_n, out_k, status)
    s_new = np.empty_like(s0)
    results = []
    for threads in sorted({1, numba.config.NUMBA_NUM_THREADS}):
        set_threads(threads)
        best = {c: math.inf for c in rows}
        iters = {}
        for r in range(repeats + 1):  # the first round compiles / warms the caches
            for c, p in rows.items():
                t = time.perf_counter()
                fabric_update_for_points(p, f_old, f_new, s_old[c], s_new, out_n, out_k, status)
                if r:
                    best[c] = min(best[c], time.perf_counter() - t)
                iters[c] = s_new[:, L.S_ITER].copy()
        for c in rows:
            results.append({
                "name": "fabric_point_update", "crossover": c, "points": n, "threads": threads,
                "ns_per_point_update": best[c] / n * 1e9,
                "iterations_mean": float(iters[c].mean()), "iterations_max": int(iters[c].max()),
            })
    save_json({"cases": results}, sys.argv[1:])
    if "--json" in sys.argv:
        print(json.dumps({"cases": results}))
        return
    for r in results:
        print(
            f"{r['name']} ({r['crossover']}): {r['points']} points, {r['threads']} thread(s): "
            f"{r['ns_per_point_update']:.1f} ns per point update "
            f"(height solve {r['iterations_mean']:.2f} iterations mean, {r['iterations_max']} max)"
        )
    for i in range(0, len(results), 2):
        print(f"{results[i]['threads']} thread(s): exact / table = "
              f"{results[i]['ns_per_point_update'] / results[i + 1]['ns_per_point_update']:.2f}×")



if __name__ == "__main__":
    main()
