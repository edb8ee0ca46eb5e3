"""Mesh-convergence sections of the containment ring (issue 36, studies V0 and V2) for
docs/validation.md.

- V0, ``examples/studies/mesh_ring_v0.toml``: the 4-ply hybrid ring with failure switched
  off, to 0.3 ms, at 7 / 5 / 4 / 3 mm; the fragment's kinetic-energy loss must agree
  within 2 % across the meshes — what remains with failure on is then failure's.
- V2, ``examples/studies/mesh_ring_hybrid4.toml``: the same ring with failure, to its end,
  at 7 / 5 / 4 / 3 mm, three release angles per mesh (±0.1°) for a single run's scatter;
  the casing's absorbed energy within ±10 % and the exit speed within 3 % across the
  meshes.
- V0 along the axis, ``examples/studies/mesh_ring_v0_axial.toml``: the 1 mm aluminium ring
  alone, failure off, 7 and 5 mm around the ring and 5 / 3 / 2 / 1.5 / 1 mm along its axis —
  the size the casing's axial bending asks for (docs/theory.md §8.8, item 1).

Each section also gives, for every series of three or more sizes (the uniform meshes; or,
with ``mesh.casing.axial_element_size`` in the study, the sizes along the axis at one size
around), Celik et al.'s observed order, extrapolated value and GCI on its three finest
meshes (``studies.convergence.mesh_convergence``).

:func:`ring_section` runs (or reuses, from ``work/studies/<study>``) one of them and
returns its section as Markdown lines: the case, the commands that reproduce it, one row
per run, the per-mesh means and the acceptance. The fragment's blade mesh is held at
5 mm in both (``mesh.blade.element_size``) so that only the casing's mesh changes.
"""

from __future__ import annotations

from pathlib import Path

from wovenimpact.studies.convergence import mesh_convergence
from wovenimpact.units import to_si

ROOT = Path(__file__).resolve().parents[3]
MESH_KEY = "mesh.element_size"
AXIAL_KEY = "mesh.casing.axial_element_size"
ANGLE_KEY = "mesh.blade.angle"
# study → (heading, what it is, acceptance: [(metric, tolerance, label)],
#          convergence estimates: [(metric, label)])
RING_STUDIES = {
    "mesh_ring_v0": (
        "Containment ring, failure off (V0)",
        "The 4-ply hybrid ring (`examples/containment/hybrid_4.toml`) with failure switched "
        "off — yarns at 10 × their strength (3150 N), aluminium at a plastic strain of 100 — "
        "to 0.3 ms, before the first casing element fails on any of these meshes; the "
        "blade meshed at 5 mm throughout. What the fragment has lost by then is contact, "
        "bending and stretching only: if it moves with the mesh, failure is not the only "
        "cause of the mesh dependence.",
        [("fragment_energy_loss_J", 0.02, "the fragment's kinetic-energy loss")],
        [("fragment_energy_loss_J", "the fragment's kinetic-energy loss")]),
    "mesh_ring_hybrid4": (
        "Containment ring, 4 plies (V2)",
        "The 4-ply hybrid ring (`examples/containment/hybrid_4.toml`) as the example runs "
        "it, the blade meshed at 5 mm throughout, at three release angles per mesh "
        "(89.9 / 90 / 90.1°) to show a single run's scatter.",
        [("casing_absorbed_energy_J", 0.10, "the casing's absorbed energy"),
         ("fragment_exit_speed_m_per_s", 0.03, "the fragment's exit speed")],
        [("fragment_exit_speed_m_per_s", "the fragment's exit speed"),
         ("casing_absorbed_energy_J", "the casing's absorbed energy")]),
    "mesh_ring_v0_axial": (
        "Containment ring, failure off, sizes along the axis (V0)",
        "The 1 mm aluminium ring alone (`examples/containment/metal_24.toml` with one 1 mm "
        "layer), failure off (a plastic strain of 100), to 0.3 ms, the blade meshed at 5 mm; "
        "7 and 5 mm around the ring (`mesh.element_size`) and 5 / 3 / 2 / 1.5 / 1 mm along its "
        "axis (`mesh.casing.axial_element_size`). The ring bends along its axis within "
        "ℓ = √(R t)/[3(1 − ν²)]^¼ ≈ 12.3 mm (docs/theory.md §8.8): if the casing's share of "
        "the fragment's loss converges with the size along the axis, that size is what "
        "a ring's mesh must resolve.",
        [],
        [("casing_absorbed_energy_J", "the casing's absorbed energy"),
         ("fragment_energy_loss_J", "the fragment's kinetic-energy loss")]),
}


def _quiet(message: str) -> None:
    pass


def _float(value) -> float | None:
    try:
        return None if value in ("", None) else float(value)
    except (TypeError, ValueError):
        return None


def energy_loss(row: dict) -> float | None:
    """½ m (v0² − v²) of the fragment (J): v its exit speed, else its speed at the end."""
    m, v0 = _float(row.get("fragment_mass_kg")), _float(row.get("fragment_initial_speed_m_per_s"))
    v = _float(row.get("fragment_exit_speed_m_per_s"))
    v = _float(row.get("fragment_speed_at_end_m_per_s")) if v is None else v
    if m is None or v0 is None or v is None:
        return None
    return 0.5 * m * (v0 * v0 - v * v)


def mesh_label(values: dict) -> str:
    """A run's mesh as the section names it: its element size, or "around × along" when
    the study sets the size along the casing's axis apart (``mesh.casing.axial_element_size``)."""
    along = values.get(AXIAL_KEY)
    return f"{values[MESH_KEY]}" if along in (None, "") else f"{values[MESH_KEY]} × {along}"


def _mm(size: str, key: str) -> float:
    """A study's mesh size ("7 mm", "0.007 m") in mm."""
    return 1e3 * to_si(size, "length", key, gt=0)


def convergence_lines(rows: list[dict], metrics) -> list[str]:
    """Per metric and series of meshes (one series on uniform meshes; one per size around
    the ring when the study sets the size along the axis apart): Celik et al.'s estimate on
    the series' three finest meshes, from the per-mesh means — the observed order, the
    extrapolated value, the GCI and how far the series' coarsest mesh lies from it."""
    # each mesh's series name and its size in that series (mm), once per mesh
    place: dict[str, tuple[str, float]] = {}
    for r in rows:
        around, along = str(r[MESH_KEY]), r.get(AXIAL_KEY)
        place[mesh_label(r)] = (("", _mm(around, MESH_KEY)) if along in (None, "") else
                                (f"{around} around, ", _mm(along, AXIAL_KEY)))
    lines = []
    for metric, label in metrics:
        series: dict[str, list[tuple[float, float]]] = {}
        for key, (mean, _, _) in mesh_means(rows, metric).items():
            name, size = place[key]
            series.setdefault(name, []).append((size, mean))
        for name, points in series.items():
            points.sort()
            where = f"{name}along the axis" if name else "uniform meshes"
            sizes = " / ".join(f"{h:g}" for h, _ in points)
            if len(points) < 3:
                lines.append(f"- {label}, {where} ({sizes} mm): fewer than three meshes, "
                             "no estimate.")
                continue
            t = mesh_convergence(*zip(*points))[0]
            text = (f"- {label}, {where} ({sizes} mm): on {t.sizes[0]:g} / {t.sizes[1]:g} / "
                    f"{t.sizes[2]:g} mm {t.verdict}")
            if t.order is not None:
                text += f", order {t.order:.2f}"
            if t.extrapolated is not None:
                coarse = points[-1]
                gci = "—" if t.gci_fine is None else f"{t.gci_fine:.1%}"
                text += f", extrapolated {t.extrapolated:.4g}, GCI {gci} on {t.sizes[0]:g} mm"
                if t.extrapolated != 0.0:
                    text += (f"; {coarse[0]:g} mm is {coarse[1] / t.extrapolated - 1.0:+.1%} "
                             "from it")
            lines.append(text + ".")
    return lines


def mesh_means(rows: list[dict], metric: str) -> dict[str, tuple[float, float, int]]:
    """Per mesh (its ``mesh_label``, in the study's order): (mean, scatter = largest −
    smallest, runs) of ``metric`` over its finished runs (the release angles)."""
    out: dict[str, list[float]] = {}
    for r in rows:
        if r.get("status") != "done":
            continue
        v = energy_loss(r) if metric == "fragment_energy_loss_J" else _float(r.get(metric))
        if v is not None:
            out.setdefault(mesh_label(r), []).append(v)
    return {h: (sum(v) / len(v), max(v) - min(v), len(v)) for h, v in out.items()}


def spread(means: dict[str, tuple[float, float, int]]) -> float | None:
    """(largest − smallest) / smallest of the per-mesh means; None with fewer than two."""
    vals = [m for m, _, _ in means.values()]
    if len(vals) < 2 or min(vals) <= 0.0:
        return None
    return (max(vals) - min(vals)) / min(vals)


def acceptance_lines(rows: list[dict], sizes: list[str], checks) -> list[str]:
    """Per metric: the per-mesh means (± half the scatter) and the spread against its
    tolerance; "not all meshes finished" while some are missing."""
    lines = []
    for metric, tol, label in checks:
        means = mesh_means(rows, metric)
        listed = " / ".join(
            f"{means[h][0]:.1f} ± {means[h][1] / 2:.1f}" if h in means else "—" for h in sizes)
        s = spread(means)
        if len(means) < len(sizes):
            verdict = "not all meshes finished"
        else:
            verdict = (f"spread {s:.1%} of the smallest — {'met' if s <= tol else 'not met'} "
                       f"(acceptance {tol:.0%})")
        lines.append(f"- {label}: {listed} at {' / '.join(sizes)} (mean ± half the scatter "
                     f"over the release angles); {verdict}.")
    return lines


def num(v: float | None, fmt: str) -> str:
    return "—" if v is None else format(v, fmt)


def table_lines(rows: list[dict]) -> list[str]:
    """One row per run."""
    lines = ["| element size | release angle | outcome | fragment speed at exit or end (m/s) | "
             "fragment's loss (J) | casing absorbed (J) | contact damping (J) | energy error "
             "| hourglass / internal work | elements | wall (s) |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        if r.get("status") != "done":
            lines.append(f"| {mesh_label(r)} | {r.get(ANGLE_KEY, '')} | "
                         f"{r.get('status')}: {r.get('error', '')} | | | | | | | | |")
            continue
        speed = _float(r.get("fragment_exit_speed_m_per_s"))
        speed = _float(r.get("fragment_speed_at_end_m_per_s")) if speed is None else speed
        lines.append(
            f"| {mesh_label(r)} | {r.get(ANGLE_KEY, '')} | {r.get('outcome', '')} | "
            f"{num(speed, '.2f')} | {num(energy_loss(r), '.1f')} | "
            f"{num(_float(r.get('casing_absorbed_energy_J')), '.1f')} | "
            f"{num(_float(r.get('contact_damping_energy_J')), '.1f')} | "
            f"{num(_float(r.get('energy_error_fraction')), '.1e')} | "
            f"{num(_float(r.get('hourglass_fraction')), '.1%')} | "
            f"{r.get('elements', '')} | {num(_float(r.get('wall_time_s')), '.0f')} |")
    return lines


def ring_section(study: str, work: Path, workers: int = 1, log=_quiet) -> list[str]:
    """Run (or reuse) ``study`` (a key of ``RING_STUDIES``) in ``work/studies/<study>`` and
    return its section's lines."""
    from wovenimpact.studies.sweep import load_study, run_study

    title, what, checks, estimates = RING_STUDIES[study]
    path = ROOT / "examples" / "studies" / f"{study}.toml"
    _, variants, _ = load_study(path)
    sizes = list(dict.fromkeys(mesh_label(v.values) for v in variants))
    out = Path(work) / "studies" / study
    log(f"study {study} → {out}")
    rows = run_study(path, out, workers=workers)
    accept = ["Acceptance (issue 36):", "", *acceptance_lines(rows, sizes, checks), ""] \
        if checks else []
    return [f"## {title}", "", what, "", "Reproduce (one core, niced; hours for the finer "
            "meshes):", "", "```",
            f"nice wovenimpact sweep examples/studies/{study}.toml --out out/{study} --workers 1",
            f"wovenimpact validate --study {study}   # this section, into out/validation/validation.md",
            "```", "", *table_lines(rows), "", *accept,
            "Convergence (Celik et al. 2008; `wovenimpact convergence`):", "",
            *convergence_lines(rows, estimates), ""]
