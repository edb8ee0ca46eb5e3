"""The metal section of docs/validation.md (issue 10), as Markdown lines.

:func:`metal_section` runs (or reuses, from ``work``) the metal verification and
validation cases and returns their section: Jones's impulsively loaded clamped plate on
three meshes (verification/jones_plate.py), the examples of ``examples/metal_impact/`` (their
outcome, energies and balance error), and the perforation ladder of
``examples/studies/metal_perforation_v50.toml`` with its Lambert–Jonas V50.
``reports.validation.run_validation`` appends it to its report; ``python -m
wovenimpact.reports.metal_validation WORK OUT.md`` writes it alone (docs/validation_metal.md).
"""

from __future__ import annotations

import json
import shutil
import sys
import tomllib
from pathlib import Path

from wovenimpact.errors import InputError

ROOT = Path(__file__).resolve().parents[3]
METAL_CASES = ("aluminium_fsp", "hybrid_coupon", "perforation_blunt")
LADDER = "metal_perforation_v50"
JONES_MESHES = (8, 16, 32)
LADDER_MESHES = ("1 mm", "0.5 mm", "0.25 mm")  # issue 36, V3: the ladder on three meshes
V50_TOLERANCE = 0.05  # issue 36, V3: V50 within 5 % across the meshes


def _quiet(message: str) -> None:
    pass


def jones_lines(work: Path, figures: Path, log=_quiet) -> list[str]:
    """The Jones plate on three meshes (results cached in ``work/jones.json``)."""
    from wovenimpact.verification.jones_plate import jones_figure, jones_study

    cache = work / "jones.json"
    figure = figures / "jones_plate.png"
    if cache.exists():
        rows = json.loads(cache.read_text())
    else:
        log(f"Jones plate, meshes {JONES_MESHES} → {figure}")
        results = jones_study(JONES_MESHES)
        jones_figure(results, figure)
        rows = [{k: v for k, v in r.items()
                 if k not in ("time_s", "deflection_m", "energy_balance")} for r in results]
        work.mkdir(parents=True, exist_ok=True)
        cache.write_text(json.dumps(rows, indent=1))
    r0 = rows[0]
    lines = [
        "### Jones's impulsively loaded clamped plate (verification/jones_plate.py)", "",
        "100 mm square 6061-T6 plate, 1 mm, elastic–perfectly plastic (σ0 = 276 MPa), "
        f"5 points, clamped, uniform 77 m/s: λ = ρV0²L²/(σ0H²) = {r0['lambda']:.0f}. "
        "Jones's pyramid mechanism with the square yield curve gives W_f/H = √(1 + Γ) − 1, "
        f"Γ = λ/6 when the mode starts with its mid-point at V0 ({r0['jones_mode_over_H']:.2f}) "
        f"and Γ = λ with all of the impulse's energy ({r0['jones_impulse_over_H']:.2f}); "
        "docs/theory.md §7.8.", "",
        "| elements per half side | element (mm) | permanent W/H | largest W/H | "
        "energy error | steps |", "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['elements_per_half_side']} | {r['element_size_m'] * 1e3:.3f} | "
                     f"{r['permanent_over_H']:.3f} | {r['max_over_H']:.3f} | "
                     f"{r['energy_error_fraction']:.1e} | {r['steps']} |")
    w = [r["permanent_over_H"] for r in rows]
    if len(w) == 3 and w[2] != w[1]:
        ratio = (w[1] - w[0]) / (w[2] - w[1])
        extrapolated = w[2] + (w[2] - w[1]) / (ratio - 1.0) if ratio > 1.0 else float("nan")
        lines += ["", f"Successive differences {w[1] - w[0]:+.3f}, {w[2] - w[1]:+.3f} (ratio "
                  f"{ratio:.2f}); Richardson estimate of the converged value {extrapolated:.2f} H, "
                  f"{extrapolated / r0['jones_impulse_over_H'] - 1:+.1%} from the whole-impulse "
                  f"limit and {extrapolated / r0['jones_mode_over_H']:.2f} × the mode-at-V0 one."]
    return lines + ["", "![Jones plate](validation/jones_plate.png)", ""]


def case_lines(work: Path, figures: Path, log=_quiet) -> list[str]:
    """The examples of examples/metal_impact/ (summaries cached in ``work/cases``)."""
    from wovenimpact.runs import reused_or_run

    lines = ["### Examples (examples/metal_impact/)", "",
             "| case | outcome | residual (m/s) | absorbed (J) | plastic work (J) | eroded "
             "internal (J) | eroded elements | hourglass / internal work | energy error |",
             "|---|---|---|---|---|---|---|---|---|"]
    for name in METAL_CASES:
        out = work / "cases" / name
        s = reused_or_run(ROOT / "examples" / "metal_impact" / f"{name}.toml", out, log,
                          "metal case")
        hg = s["hourglass_fraction"]
        lines.append(
            f"| {name} | {s['outcome']} | {s['residual_velocity_m_per_s']:.1f} | "
            f"{s['absorbed_energy_J']:.2f} | {s['plastic_work_J']:.2f} | "
            f"{s['eroded_internal_energy_J']:.3f} | {s['eroded_elements']} | "
            f"{'n/a' if hg is None else f'{hg:.0%}'} | {s['energy_error_fraction']:.1e} |")
        energy = out / "plots" / "energy.png"
        if energy.exists():
            shutil.copy(energy, figures / f"metal_{name}_energy.png")
    return lines + ["", "Energies of the whole problem; the energy plot of each run draws the "
                    "plastic dissipation and the eroded energy "
                    "(![hybrid coupon](validation/metal_hybrid_coupon_energy.png)).", ""]


def ladder_lines(work: Path, workers: int = 1, log=_quiet, element_size: str = "1 mm"
                 ) -> tuple[list[str], float | None]:
    """The perforation ladder with ``element_size`` elements and its Lambert–Jonas V50
    (runs kept in ``work/studies``; the case's own mesh is 1 mm): the section's lines and
    the V50 (m/s, None when the ladder does not bracket it)."""
    from wovenimpact.studies.ballistics import lambert_jonas_fit, require_decided
    from wovenimpact.studies.sweep import run_study
    from wovenimpact.units import to_si

    name = LADDER if element_size == "1 mm" else f"{LADDER}_{element_size.replace(' ', '')}"
    log(f"study {name} → {work / 'studies' / name}")
    rows = run_study(ROOT / "examples" / "studies" / f"{LADDER}.toml",
                     work / "studies" / name, workers=workers,
                     overrides=() if name == LADDER else (f"mesh.element_size={element_size}",))
    lines = [f"### Perforation ladder, {element_size} elements "
             "(examples/studies/metal_perforation_v50.toml)", "",
             f"1 mm Al 2024-T3 (Johnson–Cook, Lesuer 2000), 60 mm square clamped, {element_size} "
             "elements (quarter model), 5 points; rigid blunt steel cylinder 10 mm × 20 mm "
             "(12.3 g).", "", "| velocity | outcome | residual (m/s) | plastic work (J) | "
             "energy error |", "|---|---|---|---|---|"]
    for r in rows:
        if r["status"] != "done":
            lines.append(f"| {r['impactor.velocity']} | {r['status']} | | | |")
            continue
        lines.append(f"| {r['impactor.velocity']} | {r['outcome']} | "
                     f"{float(r['residual_velocity_m_per_s']):.1f} | "
                     f"{float(r['plastic_work_J']):.2f} | "
                     f"{float(r['energy_error_fraction']):.1e} |")
    done = [r for r in rows if r["status"] == "done"]
    v50 = None
    try:
        require_decided(done, "impactor.velocity", f"study {LADDER}")
        fit = lambert_jonas_fit([to_si(r["impactor.velocity"], "velocity", "velocity")
                                 for r in done],
                                [float(r["residual_velocity_m_per_s"]) for r in done])
        v50 = fit.v_bl
        lines += ["", f"Lambert–Jonas: V50 = {fit.v_bl:.1f} m/s (a = {fit.a:.3f}, p = "
                  f"{fit.p:.2f}, rms {fit.rms:.2f} m/s). **Not compared with a published "
                  "ballistic limit**: no test with a stated plate, projectile and result "
                  "could be read in the reference library (docs/theory.md §7.9)."]
    except InputError as err:
        lines += ["", f"Lambert–Jonas fit not possible: {err}"]
    return lines + [""], v50


def v50_mesh_line(v50s: dict[str, float | None], fillet: str) -> str:
    """Issue 36's V3 acceptance on the ladders' V50 by element size: the spread
    (largest − smallest) / smallest within ``V50_TOLERANCE``; ``fillet`` is the case's
    stated edge radius of the projectile's rim (as its file gives it)."""
    got = {h: v for h, v in v50s.items() if v is not None}
    listed = " / ".join(f"{v:.1f}" if v is not None else "—" for v in v50s.values())
    head = (f"Mesh convergence (V3): V50 = {listed} m/s on {' / '.join(v50s)} elements, the "
            f"projectile's rim rounded to the case's stated fillet ({fillet})")
    if len(got) != len(v50s):
        return head + "; not every ladder brackets its V50."
    spread = (max(got.values()) - min(got.values())) / min(got.values())
    ok = "met" if spread <= V50_TOLERANCE else "not met"
    return head + (f": spread {spread:.1%} of the smallest (acceptance {V50_TOLERANCE:.0%}: "
                   f"{ok}).")


def metal_section(work: str | Path, figures: str | Path, log=_quiet, workers: int = 1
                  ) -> list[str]:
    """The metal section of the validation report (module docstring); runs live in
    ``work/metal``, figures are written to ``figures`` (docs/validation/)."""
    work = Path(work) / "metal"
    figures = Path(figures)
    figures.mkdir(parents=True, exist_ok=True)
    lines = ["## Metal shells (issue 10)", "", *jones_lines(work, figures, log),
             *case_lines(work, figures, log)]
    v50s = {}
    for size in LADDER_MESHES:
        ladder, v50s[size] = ladder_lines(work, workers, log, element_size=size)
        lines += ladder
    case = tomllib.loads((ROOT / "examples" / "metal_impact" / "perforation_blunt.toml"
                          ).read_text())
    return lines + [v50_mesh_line(v50s, case["impactor"].get("fillet", "0 mm")), ""]


def main(argv: list[str]) -> None:
    """``python -m wovenimpact.reports.metal_validation WORK OUT.md``."""
    from wovenimpact.io.atomic import atomic_write_text

    work, out = Path(argv[0]), Path(argv[1])
    lines = metal_section(work, out.parent / "validation", log=print)
    atomic_write_text(out, "\n".join(lines) + "\n")


if __name__ == "__main__":
    main(sys.argv[1:])
