"""Uniaxial and biaxial extension of the thesis's crossover cell (docs/solid.md §6.5).

    python examples/crossover/extension_study.py [--quick]

Each row pulls the warp of ``thesis_cell.toml`` (yarn ``kevlar_yarn_solid.toml``, Table
5-2) by its end at 1 m/s to a cell strain of 1 %, the fill's ends held
(calibration.cell_extension.extend_cell), and prints the thesis's E1 and ν (eqs. 5.6, 5.7:
the middle elements' axial stress over axial strain, and their strain across the yarn
over it), the cell's tangent modulus (the pulled end's force over the yarn's section,
against the cell's strain) and the checks; then, on the thesis's mesh, the fill pulled too
at 0.5, 1 and 2 times the warp's strain (biaxial), the two yarns' end forces at 0.5 and 1 %.
``--quick``: the thesis's mesh only, no biaxial rows.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

from wovenimpact.calibration.cell_extension import extend_cell
from wovenimpact.spec import load_material
from wovenimpact.spec.crossover import load_geometry

HERE = Path(__file__).resolve().parent


def main(quick: bool) -> None:
    geometry = load_geometry(HERE / "thesis_cell.toml")
    yarn = load_material(HERE.parent / "materials" / "kevlar_yarn_solid.toml")
    meshes = [(12, 8, 2)] if quick else [(12, 8, 2), (18, 12, 3), (24, 16, 4)]
    print("| mesh per yarn | E1 (GPa) | ν = −ε2/ε1 | cell tangent at 1 % (GPa) | yarn section (mm²) | "
          "kinetic | hourglass | energy error | steps (wall) |")
    print("|---|---|---|---|---|---|---|---|---|")
    for m in meshes:
        cell = geometry.model_copy(update={"mesh": geometry.mesh.model_copy(
            update={"along": m[0], "across": m[1], "through": m[2]})})
        t0 = time.perf_counter()
        r = extend_cell(cell, yarn, strain=0.01)
        print(f"| {m[0]} × {m[1]} × {m[2]} | {r.e1 / 1e9:.2f} | {r.nu:.2f} | {r.tangent / 1e9:.1f} | "
              f"{r.section * 1e6:.4f} | {r.kinetic_fraction:.4f} | {r.hourglass_fraction:.4f} | "
              f"{r.energy_error:.0e} | {r.steps} ({time.perf_counter() - t0:.0f} s) |", flush=True)
    print("| thesis (Abaqus, §5.3.1) | 96.117 | ≈ 0.30 | — | — | — | — | — | — |")
    if quick:
        return
    print()
    print("| fill strain / warp strain | warp / fill force at 0.5 % (N) | at 1 % (N) | kinetic |")
    print("|---|---|---|---|")
    for ratio in (0.0, 0.5, 1.0, 2.0):
        r = extend_cell(geometry, yarn, strain=0.01, ratio=ratio)
        i = int(abs(r.strain - 0.005).argmin())
        print(f"| {ratio:g}{' (fill held)' if ratio == 0 else ''} | {r.force[i]:.1f} / "
              f"{r.force_fill[i]:.1f} | {r.force[-1]:.1f} / {r.force_fill[-1]:.1f} | "
              f"{r.kinetic_fraction:.4f} |", flush=True)


if __name__ == "__main__":
    main("--quick" in sys.argv[1:])
