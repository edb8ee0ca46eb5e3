"""Transverse compression of the thesis's crossover cell to 3 N: end conditions, mesh and
the yarn's moduli (docs/solid.md §6.3).

    python examples/crossover/compression_study.py [--quick]

Each row squeezes the cell of ``thesis_cell.toml`` (yarn ``kevlar_yarn_solid.toml``, Table
5-2) between rigid plates at 1 m/s until its force F_c reaches 3 N
(calibration.cell_compression.compress_cell) and prints the compression d_c at 3 N, the
fitted compaction law F = b d / (a − d) (eq. 5.8) and the checks (kinetic and hourglass
energy over the internal work, energy error). F_c is the plates' mean force with the ends
held by symmetry and the yarns' contact force with the thesis's end conditions (the ends
move only along their own yarn: they carry part of the press's force). ``--quick`` runs
the 12 × 8 × 2 rows only (about a minute; the full study about three).
"""

from __future__ import annotations

import dataclasses
import sys
import time
from pathlib import Path

from wovenimpact.calibration.cell_compression import compress_cell
from wovenimpact.spec import load_material
from wovenimpact.spec.crossover import load_geometry

HERE = Path(__file__).resolve().parent
THESIS = {"a_mm": 0.12389, "b_N": 0.98432}  # thesis §5.3.2, Fig. 5-10


def row(label, geometry, yarn, mesh, ends):
    """Compress once; one line of the table."""
    cell = geometry.model_copy(update={"mesh": geometry.mesh.model_copy(
        update={"along": mesh[0], "across": mesh[1], "through": mesh[2]})})
    t0 = time.perf_counter()
    r = compress_cell(cell, yarn, force=3.0, speed=1.0, ends=ends,
                      measure="yarns" if ends == "thesis" else "plates", max_time=2e-3)
    a = "—" if r.fit is None else f"{r.fit.a_m * 1e3:.4f}"
    b = "—" if r.fit is None else f"{r.fit.b_N:.3f}"
    r2 = "—" if r.fit is None else f"{r.fit.r2:.2f}"
    return (f"| {label} | {ends} | {mesh[0]} × {mesh[1]} × {mesh[2]} | {r.d[-1] * 1e3:.4f} | {a} | "
            f"{b} | {r2} | {r.force_press[-1]:.2f} / {r.force_base[-1]:.2f} / "
            f"{r.force_yarns[-1]:.2f} | {r.kinetic_fraction:.3f} | {r.hourglass_fraction:.3f} | "
            f"{r.energy_error:.0e} | {r.steps} ({time.perf_counter() - t0:.0f} s) |")


def main(quick: bool) -> None:
    geometry = load_geometry(HERE / "thesis_cell.toml")
    yarn = load_material(HERE.parent / "materials" / "kevlar_yarn_solid.toml")
    soft = {f: dataclasses.replace(yarn, e22=yarn.e22 * f, g12=yarn.g12 * f, g23=yarn.g23 * f)
            for f in (1 / 3, 1 / 10, 1 / 30)}
    rows = [("Table 5-2", yarn, (12, 8, 2), "symmetry"),
            ("Table 5-2", yarn, (12, 8, 2), "thesis")]
    if not quick:
        rows += [("Table 5-2", yarn, (18, 12, 3), "thesis"),
                 ("Table 5-2", yarn, (24, 16, 4), "thesis")]
    rows += [("E11 / 6", dataclasses.replace(yarn, e11=yarn.e11 / 6), (12, 8, 2), "thesis")]
    rows += [(f"E22, G12, G23 × 1/{round(1 / f)}", y, (12, 8, 2), "thesis")
             for f, y in soft.items()]
    print("| yarn | ends | mesh per yarn | d_c at 3 N (mm) | a (mm) | b (N) | r² | "
          "press / base / yarns (N) | kinetic | hourglass | energy error | steps (wall) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for label, y, mesh, ends in rows:
        print(row(label, geometry, y, mesh, ends), flush=True)
    print(f"| thesis (Abaqus, Fig. 5-10) | thesis | — | "
          f"{THESIS['a_mm'] * 3 / (THESIS['b_N'] + 3):.4f} | {THESIS['a_mm']} | {THESIS['b_N']} "
          "| — | — | — | — | — | — |")


if __name__ == "__main__":
    main("--quick" in sys.argv[1:])
