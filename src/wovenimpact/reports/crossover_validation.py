"""The 3-D crossover cell's validation page (docs/validation_crossover.md), generated.

:func:`crossover_page` runs (or reuses, from ``work``) the thesis's virtual tests of its
chapter 5 on the cell of ``examples/crossover/thesis_cell.toml`` with the yarn of
``examples/materials/kevlar_yarn_solid.toml`` (Table 5-2), on three meshes per yarn:

- transverse compression between rigid plates to 3 N with the thesis's end conditions
  (``calibration.cell_compression.compress_cell``): d_c at 3 N and the compaction law
  F = b d/(a − d) fitted (eq. 5.8), beside the thesis's a and b (Fig. 5-10);
- uniaxial extension of the warp to 1 % with the fill's ends held
  (``calibration.cell_extension.extend_cell``): E1 and the strain ratio of eqs. 5.6–5.7,
  beside the thesis's 96.117 GPa and ≈ 0.30;

with each run's checks (kinetic and hourglass energy over the internal work, energy
error), the spread between the two finer meshes, and the force–compression curves drawn
over the thesis's law (``docs/validation/crossover_compression.png``); and, on the 2 × 2
repeat of the same cell, the picture-frame shear test the thesis could not run
(``calibration.cell_shear.shear_cell``, :func:`shear_runs`): the shear stress against the
shear angle with the end sections clamped and hinged, whether the parallel yarns meet (the
jam), both locking rules, the shell's trellis law beside it
(``docs/validation/crossover_shear.png``).
``wovenimpact validate --crossover`` writes it; docs/solid.md §6 explains the tests.
"""

from __future__ import annotations

import json
import math
import time
from datetime import date
from pathlib import Path

import numpy as np

from wovenimpact.io.atomic import atomic_write_text

ROOT = Path(__file__).resolve().parents[3]
MESHES = ((12, 8, 2), (18, 12, 3), (24, 16, 4))  # elements along × across × through a yarn
THESIS_A_M, THESIS_B_N = 0.12389e-3, 0.98432  # thesis §5.3.2, Fig. 5-10 (eq. 5.8)
THESIS_E1, THESIS_NU = 96.117e9, 0.30  # thesis §5.3.1
FORCE_N, STRAIN = 3.0, 0.01  # the compression's target force and the extension's strain
E1_TOLERANCE, AB_TOLERANCE = 0.02, 0.15  # issue 39's acceptance on two meshes
# the shear runs: elements along × across × through per crossing and yarn, the frame's ends,
# the rate (rad/s) and the angle asked (deg); each stops earlier if the cell gives way
SHEAR_RUNS = (((6, 4, 2), "held", 2e3, 30.0), ((12, 8, 2), "held", 2e3, 30.0),
              ((6, 4, 2), "hinged", 2e3, 30.0), ((12, 8, 2), "hinged", 2e3, 30.0),
              ((18, 12, 4), "hinged", 2e3, 4.0))
SHEAR_ANGLES = (1.0, 2.0, 4.0, 6.0, 8.0, 10.0)  # deg, the table's columns
SHEAR_MESH_TOLERANCE = 0.05  # τ at 1° between the two finer hinged meshes, called converged


def _quiet(message: str) -> None:
    pass


def _mesh_text(m) -> str:
    return f"{m[0]} × {m[1]} × {m[2]}"


def _cell(geometry, mesh):
    return geometry.model_copy(update={"mesh": geometry.mesh.model_copy(
        update={"along": mesh[0], "across": mesh[1], "through": mesh[2]})})


def compression_row(result, mesh, wall_s: float) -> dict:
    """One compression run as the page's row (SI), its curve included."""
    fit = result.fit
    return {"mesh": list(mesh), "d_c_m": float(result.d[-1]),
            "a_m": None if fit is None else fit.a_m, "b_N": None if fit is None else fit.b_N,
            "r2": None if fit is None else fit.r2,
            "kinetic_fraction": result.kinetic_fraction,
            "hourglass_fraction": result.hourglass_fraction,
            "energy_error": result.energy_error, "steps": result.steps,
            "elements": result.elements, "wall_s": wall_s,
            "curve_d_m": [float(x) for x in result.d],
            "curve_force_N": [float(x) for x in result.force_yarns]}


def extension_row(result, mesh, wall_s: float) -> dict:
    """One extension run as the page's row (SI)."""
    return {"mesh": list(mesh), "e1_Pa": result.e1, "nu": result.nu,
            "tangent_Pa": result.tangent, "section_m2": result.section,
            "kinetic_fraction": result.kinetic_fraction,
            "hourglass_fraction": result.hourglass_fraction,
            "energy_error": result.energy_error, "steps": result.steps,
            "elements": result.elements, "wall_s": wall_s}


def cell_runs(work: Path, meshes=MESHES, log=_quiet) -> dict:
    """Both tests on every mesh (cached in ``work/crossover_cell.json``; delete it to run
    again)."""
    from wovenimpact.calibration.cell_compression import compress_cell
    from wovenimpact.calibration.cell_extension import extend_cell
    from wovenimpact.spec import load_material
    from wovenimpact.spec.crossover import load_geometry

    cache = work / "crossover_cell.json"
    if cache.exists():
        return json.loads(cache.read_text())
    geometry = load_geometry(ROOT / "examples" / "crossover" / "thesis_cell.toml")
    yarn = load_material(ROOT / "examples" / "materials" / "kevlar_yarn_solid.toml")
    runs = {"compression": [], "extension": []}
    for mesh in meshes:
        log(f"crossover cell {_mesh_text(mesh)}: compression to {FORCE_N:g} N")
        t0 = time.perf_counter()
        r = compress_cell(_cell(geometry, mesh), yarn, force=FORCE_N, speed=1.0,
                          ends="thesis", measure="yarns", max_time=2e-3)
        runs["compression"].append(compression_row(r, mesh, time.perf_counter() - t0))
        log(f"crossover cell {_mesh_text(mesh)}: extension to {STRAIN:.0%}")
        t0 = time.perf_counter()
        e = extend_cell(_cell(geometry, mesh), yarn, strain=STRAIN)
        runs["extension"].append(extension_row(e, mesh, time.perf_counter() - t0))
    work.mkdir(parents=True, exist_ok=True)
    atomic_write_text(cache, json.dumps(runs, indent=1))
    return runs


def _finite_or_none(x: float) -> float | None:
    return None if math.isnan(x) else float(x)


def shear_row(result, mesh, *, ends: str, rate: float, angle_deg: float,
              wall_s: float) -> dict:
    """One shear run as the page's row (SI, angles in rad), its curve included."""
    from wovenimpact.calibration.cell_shear import locking_angle, stiffening_angle

    touch = np.flatnonzero(result.parallel_force > 0.0)
    return {"mesh": list(mesh), "ends": ends, "rate": rate, "angle_asked": math.radians(angle_deg),
            "elements": result.elements, "reached": float(result.gamma[-1]),
            "stopped": result.stopped,
            "parallel_from": float(result.gamma[touch[0]]) if touch.size else None,
            "locking": _finite_or_none(locking_angle(result.gamma, result.stress)),
            "stiffening": _finite_or_none(stiffening_angle(result.gamma, result.stress)),
            "kinetic_fraction": result.kinetic_fraction,
            "hourglass_fraction": result.hourglass_fraction,
            "energy_error": result.energy_error, "steps": result.steps, "wall_s": wall_s,
            "curve_gamma": [float(x) for x in result.gamma],
            "curve_stress_Pa": [float(x) for x in result.stress]}


def shear_law() -> dict:
    """The shell's trellis law of the reference fabric (``kevlar_thesis.toml``, theory
    §1.6), and the angles at which the cell's parallel yarns, as meshed (their trimmed
    width), would meet (eqs. 3.13–3.14 on that width)."""
    from wovenimpact.calibration.cell_shear import meshed_trellis_angles
    from wovenimpact.spec import load_material
    from wovenimpact.spec.crossover import load_geometry

    fabric = load_material(ROOT / "examples" / "materials" / "kevlar_thesis.toml")
    g1, g2 = fabric.locking_angles
    geometry = load_geometry(ROOT / "examples" / "crossover" / "thesis_cell.toml")
    m1, m2 = meshed_trellis_angles(_repeat(geometry, MESHES[0]), fabric.shear_c_max)
    return {"g1_Pa": fabric.shear_g1, "g2_Pa": fabric.shear_g2, "gamma1": g1, "gamma2": g2,
            "meshed_gamma1": m1, "meshed_gamma2": m2}


def _repeat(geometry, mesh):
    cell = _cell(geometry, mesh)
    return cell.model_copy(update={"cell": cell.cell.model_copy(update={"repeat": 2})})


def shear_runs(work: Path, runs=SHEAR_RUNS, log=_quiet) -> dict:
    """The picture-frame runs of ``runs`` on the 2 × 2 repeat of the thesis's cell
    (cached in ``work/crossover_shear.json``; delete it to run again)."""
    from wovenimpact.calibration.cell_shear import shear_cell
    from wovenimpact.spec import load_material
    from wovenimpact.spec.crossover import load_geometry

    cache = work / "crossover_shear.json"
    if cache.exists():
        return json.loads(cache.read_text())
    geometry = load_geometry(ROOT / "examples" / "crossover" / "thesis_cell.toml")
    yarn = load_material(ROOT / "examples" / "materials" / "kevlar_yarn_solid.toml")
    rows = []
    for mesh, ends, rate, angle in runs:
        log(f"crossover repeat {_mesh_text(mesh)}: shear, ends {ends}, toward {angle:g}°")
        t0 = time.perf_counter()
        r = shear_cell(_repeat(geometry, mesh), yarn, angle=math.radians(angle), rate=rate,
                       ends=ends)
        rows.append(shear_row(r, mesh, ends=ends, rate=rate, angle_deg=angle,
                              wall_s=time.perf_counter() - t0))
    out = {"runs": rows, "law": shear_law()}
    work.mkdir(parents=True, exist_ok=True)
    atomic_write_text(cache, json.dumps(out, indent=1))
    return out


def _law_stress(gamma, law: dict):
    from wovenimpact.calibration.cell_shear import trellis_law

    return trellis_law(gamma, law["g1_Pa"], law["g2_Pa"], law["gamma1"], law["gamma2"])


def shear_figure(shear: dict, path: Path) -> Path:
    """τ against γ of every shear run, the shell's trellis law over the same angles (log
    scale: the law is one to two orders above the cell)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from wovenimpact.io.atomic import save_png

    fig, ax = plt.subplots(figsize=(7, 4.2))
    top = 0.0
    for r in shear["runs"]:
        g = np.array(r["curve_gamma"])
        tau = np.array(r["curve_stress_Pa"])
        keep = tau > 0.0
        ax.semilogy(np.degrees(g[keep]), tau[keep] / 1e6, lw=1.0,
                    ls="-" if r["ends"] == "held" else "--",
                    label=f"cell {_mesh_text(r['mesh'])}, ends {r['ends']}")
        top = max(top, float(g.max()))
    g = np.linspace(0.01 * top, top, 200)
    ax.semilogy(np.degrees(g), _law_stress(g, shear["law"]) / 1e6, "k:",
                label="shell's trellis law (kevlar_thesis.toml)")
    ax.set_xlabel("shear angle γ (°)")
    ax.set_ylabel("shear stress τ (MPa)")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3, which="both")
    ax.set_title("Picture-frame shear of the 2 × 2 repeat")
    fig.tight_layout()
    return save_png(fig, path)


def _deg(x: float | None) -> str:
    return "none" if x is None else f"{math.degrees(x):.1f}°"


def _toward_jam(r: dict, law: dict) -> bool:
    """Whether a run was asked past the angle its parallel yarns meet at: the locking rules
    are read only on those (on a shorter run the initial window is the ramp's)."""
    return r["angle_asked"] >= law["meshed_gamma1"]


def _shear_name(r: dict) -> str:
    return f"{_mesh_text(r['mesh'])} {r['ends']}"


def _stopped_text(r: dict) -> str:
    if r["stopped"] == "angle":
        return "the angle asked"
    return "gave way" if r["stopped"].startswith("kinetic energy") else "an element crushed"


def shear_lines(shear: dict) -> list[str]:
    """The shear section's Markdown lines from :func:`shear_runs`."""
    law, runs = shear["law"], shear["runs"]
    head = " / ".join(f"{a:g}" for a in SHEAR_ANGLES)
    lines = [
        "## In-plane shear in a picture frame (thesis §5.3.3, which could not run it)", "",
        "The 2 × 2 repeat of the same cell (`repeat = 2`), its yarns' end faces driven by a "
        "pin-jointed frame (each yarn turned by ±γ/2, its end section square to it), "
        "frictionless; *held*: the end faces clamped, *hinged*: driven along their "
        "mid-height line only, so the crossings can open. τ = T/(A0 t) from the frame's "
        "moment T. A run stops at the angle asked or where the cell leaves quasi-statics "
        "(\"gave way\": its kinetic energy above 5 % of the internal work). Locking: the "
        "tangents' rule (initial and final branches) and the first angle where the tangent "
        "reaches 10 times the initial one; none when the curve does not stiffen that much.",
        "", f"| mesh per crossing and yarn | ends | elements | τ at {head}° (MPa) | reached, "
        "stopped by | parallel yarns meet from | locking: tangents / 10× tangent | kinetic | "
        "hourglass | energy error | steps | wall (s) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in runs:
        g, tau = np.array(r["curve_gamma"]), np.array(r["curve_stress_Pa"])
        taus = " / ".join(f"{np.interp(math.radians(a), g, tau) / 1e6:.2f}"
                          if math.radians(a) <= g[-1] else "—" for a in SHEAR_ANGLES)
        lines.append(f"| {_mesh_text(r['mesh'])} | {r['ends']} | {r['elements']} | {taus} | "
                     f"{_deg(r['reached'])}, {_stopped_text(r)} | {_deg(r['parallel_from'])} | "
                     + (f"{_deg(r['locking'])} / {_deg(r['stiffening'])} | "
                        if _toward_jam(r, law) else "— | ")
                     + f"{r['kinetic_fraction']:.3f} | {r['hourglass_fraction']:.3f} | "
                     f"{r['energy_error']:.0e} | {r['steps']} | {r['wall_s']:.0f} |")
    shell = " / ".join(f"{_law_stress([math.radians(a)], law)[0] / 1e6:.1f}"
                       for a in SHEAR_ANGLES)
    lines.append(f"| the shell's trellis law (G1 {law['g1_Pa'] / 1e6:.1f} MPa, G2 "
                 f"{law['g2_Pa'] / 1e9:.2f} GPa, γ1 {_deg(law['gamma1'])}, γ2 "
                 f"{_deg(law['gamma2'])}) | — | — | {shell} | — | — | — | — | — | — | — | — |")
    jammed = [r for r in runs if r["parallel_from"] is not None]
    locked = [r for r in runs if _toward_jam(r, law)
              and (r["locking"] is not None or r["stiffening"] is not None)]
    early = [_deg(g) for g in sorted(r["reached"] for r in runs if r["stopped"] != "angle")]
    if jammed:
        jam = f"The parallel yarns meet in {len(jammed)} of {len(runs)} runs."
    else:
        jam = ("The parallel yarns never meet: as meshed (their trimmed width) they would at "
               f"{_deg(law['meshed_gamma1'])}"
               + (f"; the runs stopped early gave way or crushed at {', '.join(early)}."
                  if early else "."))
        jam += (" The crossings resist instead: with no gap between them, turning the yarns "
                "makes them overlap in proportion to γ, which the yarns take up by compressing "
                "across, so the cell resists from the first degree (solid.md §6.7).")
    lock = ("A locking angle is found on " + ", ".join(_shear_name(r) for r in locked) + "."
            if locked else "Neither rule finds a locking angle on the curves of the runs asked "
            "toward the jam.")
    lines += ["", "Acceptance (the test runs to jamming and reports a locking angle, compared "
              f"with the trellis law): {'met' if jammed and locked else 'not met'}. {jam} {lock}"]
    one = math.radians(1.0)
    at_one = [(r, np.interp(one, r["curve_gamma"], r["curve_stress_Pa"])) for r in runs
              if r["ends"] == "hinged" and r["curve_gamma"][-1] >= one]
    if len(at_one) > 1:
        step = _spread([t for _, t in at_one])
        lines += ["", "Mesh (hinged ends, τ at 1°): "
                  + ", ".join(f"{_mesh_text(r['mesh'])} {t / 1e6:.2f} MPa" for r, t in at_one)
                  + f"; the two finer meshes differ by {step:.0%} (converged within "
                  f"{SHEAR_MESH_TOLERANCE:.0%}: {'yes' if step <= SHEAR_MESH_TOLERANCE else 'no'})."]
    lines += ["", checks_line(runs, label=_shear_name), "",
              "![shear](validation/crossover_shear.png)", ""]
    return lines


def _spread(values) -> float:
    """|last − second last| / |last|: the step between the two finer meshes."""
    return abs(values[-1] - values[-2]) / abs(values[-1])


def compression_figure(rows: list[dict], path: Path) -> Path:
    """F_c against d_c of every mesh, with the thesis's fitted law over it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from wovenimpact.io.atomic import save_png

    fig, ax = plt.subplots(figsize=(7, 4.2))
    for r in rows:
        ax.plot(np.array(r["curve_d_m"]) * 1e3, r["curve_force_N"], lw=1.0,
                label=f"cell {_mesh_text(r['mesh'])}")
    d = np.linspace(0.0, THESIS_A_M * FORCE_N / (THESIS_B_N + FORCE_N), 100)
    ax.plot(d * 1e3, THESIS_B_N * d / (THESIS_A_M - d), "k--",
            label="thesis, b d/(a − d) (Fig. 5-10)")
    ax.set_xlabel("compression d_c (mm)")
    ax.set_ylabel("force F_c (N)")
    ax.set_ylim(0.0, 1.05 * FORCE_N)
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    ax.set_title("Transverse compression of the crossover cell (thesis ends)")
    fig.tight_layout()
    return save_png(fig, path)


KINETIC_LIMIT, HOURGLASS_LIMIT, ENERGY_LIMIT = 0.01, 0.05, 0.01  # issue 39's quasi-static checks


def checks_line(rows: list[dict], label=lambda r: _mesh_text(r["mesh"])) -> str:
    """The largest kinetic and hourglass energies (over the internal work) and energy
    error of the runs, each against its limit, naming (``label``) the runs that pass it."""
    parts = []
    for key, limit, name in (("kinetic_fraction", KINETIC_LIMIT, "kinetic energy"),
                             ("hourglass_fraction", HOURGLASS_LIMIT, "hourglass energy"),
                             ("energy_error", ENERGY_LIMIT, "energy error")):
        over = [label(r) for r in rows if r[key] > limit]
        worst = max(r[key] for r in rows)
        parts.append(f"{name} at most {worst:.2g} (limit {limit:g}"
                     + (f"; above it on {', '.join(over)})" if over else ")"))
    return "Checks: " + "; ".join(parts) + "."


def page_lines(runs: dict) -> list[str]:
    """The page's Markdown lines from the runs (:func:`cell_runs`)."""
    comp, ext = runs["compression"], runs["extension"]
    lines = [
        "# Validation: the 3-D crossover cell (thesis chapter 5)", "",
        f"Regenerated by `wovenimpact validate --crossover` on {date.today().isoformat()}. "
        "The cell of `examples/crossover/thesis_cell.toml` (Table 5-1: 27 threads per inch, "
        "crimp 0.0421, zero gap) with the yarn of `examples/materials/kevlar_yarn_solid.toml` "
        "(Table 5-2: E11 96 GPa, E22 = G = 3.28 GPa, ν = 0); meshes are elements along × "
        "across × through one yarn. The tests, their boundary conditions and what the "
        "differences mean: [solid.md](solid.md) §6.", "",
        f"## Transverse compression to {FORCE_N:g} N (thesis §5.3.2, eq. 5.8)", "",
        "The yarns' contact force F_c against the compression d_c, the ends moving only "
        "along their own yarn (the thesis's); F = b d/(a − d) fitted to the samples above 1 % "
        "of the target.", "",
        "| mesh per yarn | d_c at 3 N (mm) | a (mm) | b (N) | r² | kinetic | hourglass | "
        "energy error | steps | wall (s) |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in comp:
        a = "—" if r["a_m"] is None else f"{r['a_m'] * 1e3:.4f}"
        b = "—" if r["b_N"] is None else f"{r['b_N']:.3f}"
        r2 = "—" if r["r2"] is None else f"{r['r2']:.2f}"
        lines.append(f"| {_mesh_text(r['mesh'])} | {r['d_c_m'] * 1e3:.4f} | {a} | {b} | {r2} | "
                     f"{r['kinetic_fraction']:.3f} | {r['hourglass_fraction']:.3f} | "
                     f"{r['energy_error']:.0e} | {r['steps']} | {r['wall_s']:.0f} |")
    d_thesis = THESIS_A_M * FORCE_N / (THESIS_B_N + FORCE_N)
    lines.append(f"| thesis (Abaqus, Fig. 5-10) | {d_thesis * 1e3:.4f} | {THESIS_A_M * 1e3:.5f} "
                 f"| {THESIS_B_N:.5f} | — | — | — | — | — | — |")
    d = [r["d_c_m"] for r in comp]
    fine = comp[-1]
    ab_met = (fine["a_m"] is not None and fine["b_N"] is not None
              and abs(fine["a_m"] / THESIS_A_M - 1.0) <= AB_TOLERANCE
              and abs(fine["b_N"] / THESIS_B_N - 1.0) <= AB_TOLERANCE)
    ab = ("no law fitted" if fine["a_m"] is None else
          f"a {fine['a_m'] / THESIS_A_M - 1:+.0%}, b {fine['b_N'] / THESIS_B_N - 1:+.0%}")
    lines += ["", f"Between the two finer meshes d_c at 3 N moves {_spread(d):.1%}. At 3 N the "
              f"cell is compressed {d[-1] * 1e3:.4f} mm, the thesis's curve {d_thesis * 1e3:.4f} "
              f"mm ({d_thesis / d[-1]:.1f} times as far); on the finest mesh {ab} from the "
              f"thesis's (within {AB_TOLERANCE:.0%}: "
              f"{'met' if ab_met else 'not met'}). Why they differ (the yarn's transverse moduli "
              "of Table 5-2 against the curve the thesis prints; its trimmed tips and general "
              "contact are not fully specified): solid.md §6.3.", "",
              checks_line(comp), "",
              "![compression](validation/crossover_compression.png)", "",
              f"## Uniaxial extension of the warp to {STRAIN:.0%} (thesis §5.3.1, eqs. 5.6–5.7)",
              "", "The warp pulled by its end, the fill's ends held. E1 and ν = −ε2/ε1 from the "
              "middle elements' axial stress and strains (the thesis's definition); the cell's "
              "tangent is the pulled end's force over the yarn's section against the cell's "
              "strain.", "",
              "| mesh per yarn | E1 (GPa) | ν = −ε2/ε1 | cell tangent at 1 % (GPa) | "
              "yarn section (mm²) | kinetic | hourglass | energy error | steps | wall (s) |",
              "|---|---|---|---|---|---|---|---|---|---|"]
    for r in ext:
        lines.append(f"| {_mesh_text(r['mesh'])} | {r['e1_Pa'] / 1e9:.2f} | {r['nu']:.2f} | "
                     f"{r['tangent_Pa'] / 1e9:.1f} | {r['section_m2'] * 1e6:.4f} | "
                     f"{r['kinetic_fraction']:.4f} | {r['hourglass_fraction']:.4f} | "
                     f"{r['energy_error']:.0e} | {r['steps']} | {r['wall_s']:.0f} |")
    lines.append(f"| thesis (Abaqus, §5.3.1) | {THESIS_E1 / 1e9:.3f} | ≈ {THESIS_NU:.2f} | — | — "
                 "| — | — | — | — | — |")
    lines += ["", checks_line(ext)]
    e1 = [r["e1_Pa"] for r in ext]
    met = all(abs(v / THESIS_E1 - 1.0) <= E1_TOLERANCE for v in e1[-2:])
    lines += ["", f"E1 on the two finer meshes: {e1[-2] / 1e9:.2f} and {e1[-1] / 1e9:.2f} GPa, "
              f"{e1[-2] / THESIS_E1 - 1:+.1%} and {e1[-1] / THESIS_E1 - 1:+.1%} from the thesis "
              f"(within {E1_TOLERANCE:.0%}: {'met' if met else 'not met'}); ν "
              f"{ext[-2]['nu']:.2f} and {ext[-1]['nu']:.2f} against the thesis's ≈ "
              f"{THESIS_NU:.2f}, same definition (solid.md §6.5 says why they differ).", ""]
    if "shear" in runs:
        lines += shear_lines(runs["shear"])
    return lines


def crossover_page(work: Path, report: Path = ROOT / "docs" / "validation_crossover.md",
                   log=_quiet) -> Path:
    """Run (or reuse) the cell's tests, draw the figure and write the page."""
    work, report = Path(work), Path(report)
    runs = dict(cell_runs(work, log=log), shear=shear_runs(work, log=log))
    compression_figure(runs["compression"], report.parent / "validation"
                       / "crossover_compression.png")
    shear_figure(runs["shear"], report.parent / "validation" / "crossover_shear.png")
    atomic_write_text(report, "\n".join(page_lines(runs)) + "\n")
    return report
