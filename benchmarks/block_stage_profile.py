"""Where the block stage's time goes (kernels.shell_blocks), stage by stage.

A diagnostic (not a test): steps CASE to T (seconds), then times loops over the plan's
blocks that run the block stage's stages cumulatively — gather; + kinematics; + table
look-up; + crossover points; + marked points (4′); + element; + scatter — each the
stages' own functions on the thread's scratch, as ``internal_force_blocks`` calls them
(its scalar fallback left out), best of 20, and prints ns per element of each increment
(docs/theory.md §4.6).

Usage: ``python benchmarks/block_stage_profile.py CASE T THREADS``, e.g.
``python benchmarks/block_stage_profile.py examples/plate_impact/plies4_120.toml 1e-4 1``;
CASE ``plate:N`` is ``make bench``'s fabric plate of about N elements
(``wovenimpact.benchmark.plate_model``), stepped to T.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
from numba import get_thread_id, njit, prange

from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import shell_blocks as SB
from wovenimpact.kernels import shell_layout as SL

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_block_stage import case_state  # noqa: E402

_U = np.uint64
STAGES = ("gather", "kinematics", "look-up", "crossover points", "marked points", "element",
          "scatter")


@njit(parallel=True, boundscheck=False, error_model="numpy")
def stages(upto, quads, sections, mat_params, step_yarn, x, v, omega, el_in, el_out, rows_in,
           rows_out, mat_row, dt, elems, lanes, block_sec, gg, gw, rg, a0s, inert, cn, old,
           kin, coef, geo, flag, exact, res, out_el, out_blk):
    """``internal_force_blocks``' block loop, its stages 1…upto (the scalar fallback and
    the erosion tests left out)."""
    pw = rows_in.shape[1]
    for bi in prange(lanes.shape[0]):
        b = _U(bi)
        tid = _U(get_thread_id())
        sec = _U(block_sec[b])
        thick = sections[sec, SL.C_THICK]
        m = _U(sections[sec, SL.C_MAT])
        for ll in range(SB.LANES):
            lu = _U(ll)
            e = _U(elems[b * _U(SB.LANES) + lu])
            for i in range(4):
                node = _U(quads[e, i])
                for d in range(3):
                    cn[tid, SB.at(9 * i + d, lu)] = x[node, d]
                    cn[tid, SB.at(9 * i + 3 + d, lu)] = v[node, d]
                    cn[tid, SB.at(9 * i + 6 + d, lu)] = omega[node, d]
            for k in range(3):
                old[tid, SB.at(SB.V_KAPPA + k, lu)] = el_in[e, SL.E_KAPPA + k]
                old[tid, SB.at(SB.V_M + k, lu)] = el_in[e, SL.E_M + k]
            old[tid, SB.at(SB.V_Q, lu)] = el_in[e, SL.E_Q]
            old[tid, SB.at(SB.V_Q + 1, lu)] = el_in[e, SL.E_Q + 1]
            for k in range(5):
                old[tid, SB.at(SB.V_HG + k, lu)] = el_in[e, SL.E_HG + k]
            old[tid, SB.at(SB.V_U_BEND, lu)] = el_in[e, SL.E_U_BEND]
            old[tid, SB.at(SB.V_U_HG, lu)] = el_in[e, SL.E_U_HG]
            worn = 0.0 if el_in[e, SL.E_ALIVE] != 0.0 else 1.0
            row0 = _U(mat_row[e])
            for g in range(4):
                r = row0 + _U(g)
                worn += 0.0 if rows_in[r, FL.S_ALIVE] != 0.0 else 1.0
                exact[tid, _U(g * SB.LANES) + lu] = (
                    (0.0 if rows_in[r, FL.S_DAMAGE] == 0.0 else 1.0)
                    + (0.0 if rows_in[r, FL.S_DAMAGE + 1] == 0.0 else 1.0))
            flag[tid, lu] = worn
        if upto >= 2:
            SB.kinematics_lanes(tid, b, cn, old, gg, rg, dt, kin, flag)
        if upto >= 3:
            SB.table_lookup(mat_params, m, tid, kin, coef, geo, exact)
        if upto >= 4:
            SB.crossover_points(tid, kin, coef, geo, res, SB.material_lanes(mat_params, m))
        if upto >= 5:
            SB.exact_points(mat_params, m, tid, b, elems, mat_row, el_in, rows_in, rows_out,
                            kin, exact, flag, res)
        if upto >= 6:
            SB.element_lanes(tid, b, cn, old, res, flag, gg, gw, rg, a0s, inert, out_el,
                             out_blk, dt, thick, sections[sec, SL.C_AREAL_MASS],
                             sections[sec, SL.C_BEND_E], sections[sec, SL.C_BEND_NU],
                             sections[sec, SL.C_SHEAR_K] * sections[sec, SL.C_SHEAR_G] * thick,
                             sections[sec, SL.C_HOURGLASS], step_yarn)
        if upto >= 7:
            for ll in range(lanes[b]):
                lu = _U(ll)
                e = _U(elems[b * _U(SB.LANES) + lu])
                if flag[tid, lu] != 0.0:
                    continue
                for c in range(SL.N_ELEM_STATE):
                    el_out[e, c] = out_el[tid, SB.at(c, lu)]
                row0 = _U(mat_row[e])
                for g in range(4):
                    r = row0 + _U(g)
                    q = _U(g * SB.LANES) + lu
                    for j in range(pw):
                        rows_out[r, j] = rows_in[r, j]
                    rows_out[r, FL.S_LAMBDA] = res[tid, SB.atq(SB.R_LAM_W, q)]
                    rows_out[r, FL.S_LAMBDA + 1] = res[tid, SB.atq(SB.R_LAM_F, q)]
                    rows_out[r, FL.S_GAMMA] = res[tid, SB.atq(SB.R_GAMMA, q)]
                    rows_out[r, FL.S_H] = res[tid, SB.atq(SB.R_H_W, q)]
                    rows_out[r, FL.S_H + 1] = res[tid, SB.atq(SB.R_H_F, q)]
                    rows_out[r, FL.S_TENSION] = res[tid, SB.atq(SB.R_T_W, q)]
                    rows_out[r, FL.S_TENSION + 1] = res[tid, SB.atq(SB.R_T_F, q)]
                    rows_out[r, FL.S_TAU] = res[tid, SB.atq(SB.R_TAU, q)]
                    rows_out[r, FL.S_SHEAR_ENERGY] = res[tid, SB.atq(SB.R_E_SHEAR, q)]
                    rows_out[r, FL.S_ENERGY] = res[tid, SB.atq(SB.R_ENERGY, q)]


def main(argv: list[str]) -> None:
    case, t_end, threads = argv[0], float(argv[1]), int(argv[2])
    found = case_state(case, t_end, threads)
    if found is None:
        return
    model, state, ws = found
    p, s, mesh = ws.plan, ws.scratch, ws.mesh
    rows_in, rows_out = state.mat, ws.mat

    def run(upto):
        stages(upto, mesh.quads, mesh.sections, mesh.mat_params, mesh.step_mode == SL.STEP_YARN,
               state.x, state.v, state.omega, state.elem, ws.elem, rows_in, rows_out,
               mesh.mat_row, state.dt, p.elems, p.lanes, p.section, p.gauss_grad,
               p.gauss_weight, p.ref_grad, p.area0, p.rot_inertia, s.corners, s.old, s.kin,
               s.coef, s.geo, s.flag, s.exact, s.res, s.out_el, s.out_blk)

    times = []
    for upto in range(1, len(STAGES) + 1):
        run(upto)
        best = float("inf")
        for _ in range(20):
            t0 = time.perf_counter()
            run(upto)
            best = min(best, time.perf_counter() - t0)
        times.append(best)
    n = p.elems.size
    print(f"t = {state.t:.3e} s, {threads} thread(s), {n} block lanes: ns per element")
    prev = 0.0
    for name, t in zip(STAGES, times):
        print(f"  {name:18s} {(t - prev) / n * 1e9:7.1f}")
        prev = t
    print(f"  {'all':18s} {times[-1] / n * 1e9:7.1f}")


if __name__ == "__main__":
    main(sys.argv[1:])
