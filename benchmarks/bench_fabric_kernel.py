"""Throughput of the crossover kernel: ns per material-point update (serial and threaded).

Points are driven through a realistic step: from a random stretched/sheared state
(F_old) to a slightly different one (F_new), warm-started from the converged state
at F_old, as the explicit solver will call it. Prints one line per thread count.
"""

from __future__ import annotations

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


def stretch_shear(lam_w, lam_f, gamma):
    return np.array([[lam_w, lam_f * math.sin(gamma)], [0.0, lam_f * math.cos(gamma)]])


def main(n: int = 200_000, repeats: int = 5) -> None:
    params = load_material("examples/materials/kevlar_thesis.toml")
    p = params.to_array()
    rng = np.random.default_rng(1)
    lw, lf, g = rng.uniform(1.0, 1.035, n), rng.uniform(1.0, 1.035, n), rng.uniform(-0.3, 0.3, n)
    f_old = np.array([stretch_shear(*x) for x in zip(lw, lf, g)])
    f_new = np.array([stretch_shear(*x) for x in zip(lw + 1e-5, lf + 1e-5, g + 1e-4)])
    s0 = initial_state(params, n)
    s_old = np.empty_like(s0)
    out_n = np.empty((n, 3))
    out_k = np.empty(n)
    status = np.empty(n, dtype=np.int32)
    eye = np.repeat(np.eye(2)[None], n, axis=0)
    fabric_update_for_points(p, eye, f_old, s0, s_old, out_n, out_k, status)  # warm state
    s_new = np.empty_like(s_old)
    results = []
    for threads in sorted({1, numba.config.NUMBA_NUM_THREADS}):
        set_threads(threads)
        fabric_update_for_points(p, f_old, f_new, s_old, s_new, out_n, out_k, status)  # compile
        best = math.inf
        for _ in range(repeats):
            t = time.perf_counter()
            fabric_update_for_points(p, f_old, f_new, s_old, s_new, out_n, out_k, status)
            best = min(best, time.perf_counter() - t)
        it = s_new[:, L.S_ITER]
        results.append(
            {
                "name": "fabric_point_update",
                "points": n,
                "threads": threads,
                "ns_per_point_update": best / n * 1e9,
                "iterations_mean": float(it.mean()),
                "iterations_max": int(it.max()),
            }
        )
    ratio = results[0]["ns_per_point_update"] / results[-1]["ns_per_point_update"]
    if "--json" in sys.argv:
        print(json.dumps({"cases": results, "speedup": ratio}))
        return
    for r in results:
        print(
            f"{r['name']}: {r['points']} points, {r['threads']} thread(s): "
            f"{r['ns_per_point_update']:.1f} ns per point update "
            f"(height solve {r['iterations_mean']:.2f} iterations mean, {r['iterations_max']} max)"
        )
    print(f"speed-up {results[0]['threads']} → {results[-1]['threads']} threads: {ratio:.2f}×")


if __name__ == "__main__":
    main()
