"""The blade-edge strip section of docs/validation.md (issue 36, convergence study V1).

:func:`strip_section` runs (or reuses, from ``work``) the study
``examples/studies/mesh_strip_edge.toml`` — the blade-edge strip of
``examples/strip/blade_edge_strip.toml`` on 0.94 / 2 / 3 / 5 / 7 mm elements — as the case
is, with ``run.eroded_nodes = "keep"`` and struck by a blunter edge (radius 10 mm), and returns its section as Markdown
lines: the case, the commands that reproduce it, one table per variant of the study and
the acceptance of issue 36 (the strip's absorbed energy within 10 % from 2 to 7 mm).
``reports.validation.run_validation`` appends it to its report (``wovenimpact validate
--study mesh_strip_edge`` runs it alone).
"""

from __future__ import annotations

import csv
import json
import shutil
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
STUDY = "mesh_strip_edge"
REFERENCE = "0.94 mm"  # the crossover size: the reference of the convergence studies
JUDGED = ("2 mm", "3 mm", "5 mm", "7 mm")  # the acceptance's range
TOLERANCE = 0.10  # issue 36: absorbed energy within 10 % from 2 to 7 mm
# (heading, output suffix, --set overrides): the case; its eroded nodes kept; and the same
# wall struck by a blunter edge (radius 10 mm instead of 2.49, its axis raised to keep the
# 0.25 mm gap), which every mesh of the study resolves — what separates the mesh dependence
# of an under-resolved edge from the rest
BLUNT_EDGE = ("impactor.radius=10 mm", 'impactor.position=["0 mm", "-25 mm", "12.9971 mm"]')
VARIANTS = (("as the case is (eroded nodes removed)", "", ()),
            ("`--set run.eroded_nodes=keep`", "_keep", ("run.eroded_nodes=keep",)),
            ("a blunter edge, radius 10 mm (`--set 'impactor.radius=10 mm' --set "
             "'impactor.position=[\"0 mm\", \"-25 mm\", \"12.9971 mm\"]'`)", "_r10", BLUNT_EDGE))
EARLY = 20e-6  # s: the edge's first 3 mm of travel, when it meets the aluminium


def _quiet(message: str) -> None:
    pass


def _number(value, fmt: str) -> str:
    return "—" if value in ("", None) else format(float(value), fmt)


def _joules(values) -> str:
    return "—" if not isinstance(values, list) else " / ".join(f"{float(v):.1f}" for v in values)


def spread(rows: list[dict], key: str = "absorbed_energy_J",
           sizes=JUDGED) -> float | None:
    """(largest − smallest) / smallest of ``key`` over the finished runs of the element
    sizes ``sizes``; None unless all of them finished."""
    vals = [float(r[key]) for r in rows
            if r.get("mesh.element_size") in sizes and r.get("status") == "done"]
    if len(vals) != len(sizes) or min(vals) <= 0.0:
        return None
    return (max(vals) - min(vals)) / min(vals)


def early_loss(run_dir: Path, t: float = EARLY) -> float | None:
    """The impactor's kinetic energy lost by time ``t`` (J, whole model), from the run's
    history.csv (the row nearest ``t``; its ``_part`` columns are the modelled part's, so
    scaled by the summary's whole-model initial energy over the history's first row);
    None when the history or the summary is missing."""
    path, summary = run_dir / "history.csv", run_dir / "summary.json"
    if not (path.exists() and summary.exists()):
        return None
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        return None
    e0 = float(rows[0]["impactor_kinetic_energy_part_J"])
    full = float(json.loads(summary.read_text())["initial_impactor_kinetic_energy_J"])
    row = min(rows, key=lambda r: abs(float(r["time_s"]) - t))
    return (e0 - float(row["impactor_kinetic_energy_part_J"])) * full / e0


def table_lines(rows: list[dict], out: Path | None = None) -> list[str]:
    """One row per element size: outcome, the edge's speed at the end, the absorbed energy
    (and against the reference mesh's), what the edge lost in its first ``EARLY`` (from the
    run's history in ``out/runs/<id>``), eroded kinetic energy, contact work per layer, the
    energy error, hourglass share, added mass and wall time."""
    ref = next((float(r["absorbed_energy_J"]) for r in rows
                if r.get("mesh.element_size") == REFERENCE and r.get("status") == "done"), None)
    lines = ["| element size | outcome | edge speed at the end (m/s) | absorbed (J) | "
             f"/ 0.94 mm | lost by {EARLY * 1e6:.0f} µs (J) | eroded kinetic (J) | contact "
             "work per layer, plies 0–3 / aluminium (J) | energy error | hourglass / internal "
             "work | added mass | wall (s) |", "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("status") != "done":
            lines.append(f"| {r.get('mesh.element_size')} | failed: {r.get('error', '')} "
                         "| | | | | | | | | | |")
            continue
        e = float(r["absorbed_energy_J"])
        early = early_loss(out / "runs" / r["id"]) if out is not None and r.get("id") else None
        lines.append(
            f"| {r['mesh.element_size']} | {r.get('outcome', '')} | "
            f"{_number(r.get('residual_velocity_m_per_s'), '.2f')} | {e:.1f} | "
            f"{(e / ref if ref else float('nan')):.2f} | {_number(early, '.1f')} | "
            f"{_number(r.get('eroded_kinetic_energy_J'), '.2f')} | "
            f"{_joules(r.get('contact_work_per_ply_J'))} | "
            f"{_number(r.get('energy_error_fraction'), '.1e')} | "
            f"{_number(r.get('hourglass_fraction'), '.1%')} | "
            f"{_number(r.get('added_mass_fraction'), '.2%')} | "
            f"{_number(r.get('wall_time_s'), '.1f')} |")
    return lines


def verdict_line(rows: list[dict]) -> str:
    """The acceptance of issue 36 on these rows."""
    s = spread(rows)
    if s is None:
        return "Acceptance (absorbed energy within 10 % from 2 to 7 mm): not all runs finished."
    ok = "met" if s <= TOLERANCE else "not met"
    return (f"Acceptance (absorbed energy within {TOLERANCE:.0%} from 2 to 7 mm): the spread "
            f"over 2–7 mm is {s:.0%} of the smallest — {ok}.")


def strip_section(work: Path, figures: Path, workers: int = 1, log=_quiet) -> list[str]:
    """Run (or reuse) the study in ``work/studies/mesh_strip_edge`` (and ``…_keep``) and
    return the section's lines; its figures (absorbed energy against the element size,
    the edge's speed against time) are copied into ``figures``."""
    from wovenimpact.studies.sweep import run_study

    path = ROOT / "examples" / "studies" / f"{STUDY}.toml"
    lines = [
        "## Blade-edge strip (V1)", "",
        "The flat idealisation of the containment case `examples/containment/hybrid_4.toml` "
        "(`examples/strip/blade_edge_strip.toml`, docs/theory.md §6): its wall — 1 mm "
        "aluminium over 4 Kevlar plies, touching — as a 150 × 40 mm strip clamped at its ends "
        "(the casing's length between its clamped ends), quarter model, struck at mid-span "
        "by a rigid 4.98 mm edge (the side of a cylinder lying across the strip) at 150 m/s "
        "carrying the fragment's mass per unit length of edge (0.2292 kg over a mean chord "
        "of 56.76 mm: 4.038 kg/m, 0.1615 kg on 40 mm), to 250 µs. The case on which the "
        "fabric's failure regularisation (`strength_scale`, theory §1.4) is calibrated; "
        "judged by the rings (V2), never by this strip. Absorbed energy: the edge's kinetic "
        "energy lost; the contact work per layer is what each layer took (ply 0 is the "
        "farthest from the edge, the aluminium last; its plastic work included). The edge "
        "is through the wall on every mesh; `undecided` means it still drags torn debris at "
        "the end, the speed then being its speed at 250 µs.", "",
        "Reproduce (one core each, niced; outputs in `out/`):", "",
        "```",
        "nice wovenimpact sweep examples/studies/mesh_strip_edge.toml --out out/mesh_strip_edge --workers 1",
        "nice wovenimpact sweep examples/studies/mesh_strip_edge.toml --out out/mesh_strip_edge_keep \\",
        "    --workers 1 --set run.eroded_nodes=keep",
        "nice wovenimpact sweep examples/studies/mesh_strip_edge.toml --out out/mesh_strip_edge_r10 \\",
        "    --workers 1 --set 'impactor.radius=10 mm' \\",
        "    --set 'impactor.position=[\"0 mm\", \"-25 mm\", \"12.9971 mm\"]'",
        "wovenimpact validate --study mesh_strip_edge   # this section, into out/validation/validation.md",
        "```", ""]
    for label, suffix, overrides in VARIANTS:
        name = STUDY + suffix
        out = work / "studies" / name
        log(f"study {name} → {out}")
        rows = run_study(path, out, workers=workers, overrides=overrides)
        lines += [f"### {label}", "", *table_lines(rows, out), "", verdict_line(rows), ""]
        for png, what in (("absorbed_energy_J.png", "absorbed energy"),
                          ("impactor_velocity_m_per_s_histories.png", "the edge's speed")):
            if (out / "plots" / png).exists():
                figures.mkdir(parents=True, exist_ok=True)
                shutil.copy(out / "plots" / png, figures / f"{name}_{png}")
                lines += [f"![{name}: {what}](validation/{name}_{png})", ""]
    return lines
