"""In-plane shear of the thesis's crossover geometry in a pin-jointed frame (docs/solid.md
§6.7).

    python examples/crossover/shear_study.py [--quick] [--ends held|free_z|hinged] [--friction MU]

The 2 × 2 plain-weave repeat of ``thesis_cell.toml`` (``repeat = 2``; yarn
``kevlar_yarn_solid.toml``, Table 5-2) is sheared by its yarns' end faces
(calibration.cell_shear.shear_cell) at 2000 rad/s toward 30°, on a coarse mesh and on the
thesis's (elements per crossing and yarn: 6 × 4 × 2 and 12 × 8 × 2); each run stops at 30°
or where it leaves quasi-statics. Printed: the shear stress τ at a few angles beside the
shell's trellis law of ``kevlar_thesis.toml`` (theory §1.6), the angle reached and why the
run stopped, the first angle with a contact force between parallel yarns, the locking
angles of both rules on the cell's curve and on the shell's law over the same angles, the
trellis law's γ1, γ2 for the fabric's width and for the cell's meshed (trimmed) width, and
the checks. ``--quick``: the coarse mesh only. ``--ends``: the frame's end conditions
(calibration.cell_shear: "held", the default, clamps the end faces; "hinged" drives each end
face along its mid-height line only, so the crossings can open; "free_z" frees the end faces
in z, so each yarn can climb); the cell's thickening and the crossings' contact at 4° are printed
too. ``--friction MU``: Coulomb friction between the yarns.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np

from wovenimpact.calibration.cell_shear import (
    locking_angle,
    meshed_trellis_angles,
    meshed_width,
    shear_cell,
    stiffening_angle,
    trellis_law,
)
from wovenimpact.model.crossover_cell import crossover_cell
from wovenimpact.model.model import ShellContactParams
from wovenimpact.spec import load_material
from wovenimpact.spec.crossover import load_geometry

HERE = Path(__file__).resolve().parent
ANGLES = (2.0, 4.0, 6.0, 8.0, 10.0)


def deg(x: float) -> str:
    return "—" if math.isnan(x) else f"{math.degrees(x):.1f}°"


def main(quick: bool, ends: str = "held", friction: float = 0.0) -> None:
    base = load_geometry(HERE / "thesis_cell.toml")
    yarn = load_material(HERE.parent / "materials" / "kevlar_yarn_solid.toml")
    fabric = load_material(HERE.parent / "materials" / "kevlar_thesis.toml")
    g1, g2 = fabric.locking_angles
    law = dict(g1=fabric.shear_g1, g2=fabric.shear_g2, gamma1=g1, gamma2=g2)
    meshes = [(6, 4, 2)] if quick else [(6, 4, 2), (12, 8, 2)]
    head = " | ".join(f"τ at {a:g}° (MPa)" for a in ANGLES)
    print(f"| mesh per crossing and yarn | elements | {head} | reached | stopped by | "
          "parallel contact from | locking (tangents / 10× tangent) | kinetic | hourglass | "
          "energy error | steps (wall) | thickening at the end (µm) | crossings' contact at 4° (N) |")
    print("|" + "---|" * (12 + len(ANGLES)))
    contact = ShellContactParams(friction=friction) if friction else None
    cell = None
    for m in meshes:
        spec = base.model_copy(update={
            "cell": base.cell.model_copy(update={"repeat": 2}),
            "mesh": base.mesh.model_copy(update={"along": m[0], "across": m[1],
                                                  "through": m[2]})})
        cell = crossover_cell(spec)
        t0 = time.perf_counter()
        r = shear_cell(spec, yarn, angle=math.radians(30.0), rate=2e3, ends=ends,
                       contact=contact)
        wall = time.perf_counter() - t0
        taus = " | ".join(
            f"{np.interp(math.radians(a), r.gamma, r.stress) / 1e6:.2f}"
            if math.radians(a) <= r.gamma[-1] else "—" for a in ANGLES)
        touch = np.flatnonzero(r.parallel_force > 0.0)
        first = deg(r.gamma[touch[0]]) if touch.size else "none"
        why = "30°" if r.stopped == "angle" else r.stopped.split(" at ")[0][:40]
        print(f"| {m[0]} × {m[1]} × {m[2]} | {r.elements} | {taus} | {deg(r.gamma[-1])} | "
              f"{why} | {first} | {deg(locking_angle(r.gamma, r.stress))} / "
              f"{deg(stiffening_angle(r.gamma, r.stress))} | {r.kinetic_fraction:.4f} | "
              f"{r.hourglass_fraction:.4f} | {r.energy_error:.1e} | {r.steps} ({wall:.0f} s) | "
              f"{r.thickening[-1] * 1e6:.1f} | "
              + (f"{np.interp(math.radians(4.0), r.gamma, r.crossing_contact):.2f} |"
                 if r.gamma[-1] >= math.radians(4.0) else "— |"))
        shell = trellis_law(r.gamma, **law)
        print("|   shell's trellis law, same angles | | " + " | ".join(
            f"{trellis_law([math.radians(a)], **law)[0] / 1e6:.1f}" for a in ANGLES)
            + f" | | | | {deg(locking_angle(r.gamma, shell))} / "
              f"{deg(stiffening_angle(r.gamma, shell))} | | | | | | |")
        secant = r.stress / np.maximum(r.gamma, 1e-12)
        late = r.gamma >= 0.5 * r.gamma[-1]
        print(f"|   cell's secant modulus τ/γ over the second half (MPa) | | "
              f"{secant[late].min() / 1e6:.1f}–{secant[late].max() / 1e6:.1f} | | | | | | | | | | | | | |")
    pitch = cell.size[1] / cell.repeat
    m1, m2 = meshed_trellis_angles(spec, fabric.shear_c_max)
    print(f"\ntrellis law's γ1, γ2: fabric width {fabric.warp.width * 1e3:.4f} mm over pitch "
          f"{pitch * 1e3:.5f} mm: {deg(g1)}, {deg(g2)}; the cell's meshed width "
          f"{meshed_width(cell) * 1e3:.4f} mm: {deg(m1)}, {deg(m2)}; G1 = "
          f"{fabric.shear_g1 / 1e9:g} GPa, G2 = {fabric.shear_g2 / 1e9:g} GPa")


if __name__ == "__main__":
    args = sys.argv[1:]
    main("--quick" in args,
         ends=args[args.index("--ends") + 1] if "--ends" in args else "held",
         friction=float(args[args.index("--friction") + 1]) if "--friction" in args else 0.0)
