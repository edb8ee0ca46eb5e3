"""The containment report (issue 11): our ladders beside the thesis's (its chapter 8).

:func:`containment_section` runs (or reuses, from ``work``: a run is reused only when its
provenance digest matches) the two ladder studies of ``examples/studies/`` — the hybrid
casing (1 mm aluminium shell wrapped in N Kevlar plies) and the all-metal casing (N
layers of 0.5 mm aluminium) — and returns Markdown lines:

- per ladder, a table of every run (outcome, exit speed, the thesis's exit speed at the
  same N, casing mass and mass per unit area, largest bulge, energy error, hourglass
  share, wall time) and a figure of exit speed against N, ours and the thesis's;
- the quadratic regression of exit speed against N (thesis eq. 8.2) over the decided
  runs that let the fragment through (``escaped``), and the layers it predicts to contain;
  beside it the fewest layers that contained the fragment in a run;
- the mass table: the lightest casing of each kind that contained the fragment in a
  run, and the one the regression predicts, with its mass per unit area — the inner
  shell counted (the thesis's Table 8-4 left it out).

Undecided runs (still pushing intact layers at the end time) enter neither the
regression nor the answer; they are listed with a word. ``wovenimpact validate
--containment`` writes the section alone to docs/validation_containment.md (the ladders
take hours: they are not part of the chapter-7 report). ``--set`` changes the ladders'
case (a coarser mesh); ``--runs`` tabulates runs made elsewhere instead
(:func:`rows_from_runs`), each with its element count and code digest.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

from wovenimpact.errors import InputError
from wovenimpact.studies.ballistics import SETTLED, unsettled

ROOT = Path(__file__).resolve().parents[3]
KEY = "mesh.casing.layers"
# thesis ch. 8 (docs/model.md §6): exit speed (m/s) of the fragment from 149 m/s
THESIS_HYBRID = {4: 133.0, 6: 131.0, 8: 129.0, 10: 124.0}
THESIS_METAL = {4: 123.3, 8: 111.0, 12: 95.5, 18: 81.9, 20: 35.9, 24: 0.6}
LADDERS = (
    ("containment_hybrid", "Hybrid casing: 1 mm aluminium shell + N Kevlar plies", "plies",
     THESIS_HYBRID, "the thesis ran 4–10 plies (its solver failed beyond) and extrapolated "
     "about 30 to contain"),
    ("containment_metal", "All-metal casing: N layers of 0.5 mm aluminium", "layers",
     THESIS_METAL, "the thesis: 25 layers contained the fragment"),
)


def _quiet(message: str) -> None:
    """The default progress reporter: says nothing."""


def _fmt(value, spec: str, missing: str = "") -> str:
    """``value`` formatted with ``spec``, or ``missing`` for None/NaN/empty."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return missing
    return missing if math.isnan(v) else format(v, spec)


def _mm(value) -> float | None:
    """A length in m as mm (None if not a number)."""
    try:
        return float(value) * 1e3
    except (TypeError, ValueError):
        return None


def ladder_result(rows: list[dict]) -> dict:
    """What a ladder's finished rows say: the regression of the escaped runs' exit speed
    against N (None with fewer than three distinct N; runs whose exit speed had not
    settled are left out), the fewest layers that contained
    the fragment in a run (None if none did), the most layers below those that let it
    through, the undecided N, and the mass per unit area
    of a casing of N layers interpolated between the runs (a function of N)."""
    from wovenimpact.studies.ballistics import quadratic_ply_regression

    done = [r for r in rows if r.get("status") == "done"]
    through = [r for r in done if r.get("outcome") == "escaped"]
    escaped = [(float(r[KEY]), float(r["fragment_exit_speed_m_per_s"])) for r in through
               if not unsettled(r)]
    contained = sorted(int(float(r[KEY])) for r in done if r.get("outcome") == "contained")
    undecided = sorted(int(float(r[KEY])) for r in done
                       if r.get("outcome") not in ("escaped", "contained"))
    points = len({n for n, _ in escaped})  # distinct N the regression would rest on
    regression = None
    if points >= 3:
        regression = quadratic_ply_regression(*zip(*escaped))
    per_area = sorted((float(r[KEY]), float(r["casing_mass_per_area_kg_per_m2"])) for r in done)

    def mass_per_area(n: float) -> float | None:
        """Linear in N between (and beyond) the runs: each layer adds the same mass."""
        if len(per_area) < 2:
            return per_area[0][1] if per_area and per_area[0][0] == n else None
        (n0, m0), (n1, m1) = per_area[0], per_area[-1]
        return m0 + (m1 - m0) * (n - n0) / (n1 - n0) if n1 != n0 else None

    below = [float(r[KEY]) for r in through if not contained or float(r[KEY]) < contained[0]]
    return {"regression": regression, "regression_points": points,
            "fewest_contained": contained[0] if contained else None,
            "most_escaped_below": int(max(below)) if below else None,
            "undecided": undecided, "mass_per_area": mass_per_area}


def ladder_lines(name: str, title: str, unit: str, thesis: dict, note: str, rows: list[dict],
                 figures: Path) -> tuple[list[str], dict]:
    """The table, figure and regression of one ladder (rows: its study results)."""
    lines = [f"### {title} (examples/studies/{name}.toml)", "", f"{note[0].upper()}{note[1:]}.", "",
             f"| {unit} | outcome | exit speed (m/s) | thesis (m/s) | casing (kg) | "
             "kg/m² | largest bulge (mm) | energy error | hourglass / internal work | wall (s) | "
             "elements |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        n = int(float(r[KEY]))
        if r.get("status") != "done":
            lines.append(f"| {n} | {r.get('status')}: {r.get('error', '')} | | "
                         f"{_fmt(thesis.get(n), '.1f')} | | | | | | | |")
            continue
        outcome = f"{r['outcome']} (speed still falling)" if unsettled(r) else r["outcome"]
        lines.append(
            f"| {n} | {outcome} | {_fmt(r['fragment_exit_speed_m_per_s'], '.1f')} | "
            f"{_fmt(thesis.get(n), '.1f')} | {_fmt(r['casing_mass_kg'], '.3f')} | "
            f"{_fmt(r['casing_mass_per_area_kg_per_m2'], '.2f')} | "
            f"{_fmt(_mm(r.get('max_bulge_m')), '.1f')} | "
            f"{_fmt(r['energy_error_fraction'], '.1e')} | "
            f"{_fmt(r.get('hourglass_fraction'), '.1%', 'n/a')} | {_fmt(r.get('wall_time_s'), '.0f')} | "
            f"{_fmt(r.get('elements'), '.0f')} |")
    result = ladder_result(rows)
    reg = result["regression"]
    lines.append("")
    if reg is not None:
        c2, c1, c0 = reg.coefficients
        lines.append(f"Quadratic regression (eq. 8.2) of the escaped runs: V_exit(N) = "
                     f"{c2:.4g} N² {c1:+.4g} N {c0:+.4g} (R² = {reg.r2:.3f}); it reaches zero "
                     + (f"at N = {reg.root:.1f}: **{reg.plies_to_stop} {unit} to contain**."
                        if reg.plies_to_stop else "nowhere on its decreasing branch."))
        if result["regression_points"] == 3:
            lines.append("Three escaped N for three coefficients: the parabola passes through "
                         "them (as the thesis's eq. 8.2 did), so R² = 1 by construction and "
                         "says nothing of the fit; a fourth escaped N would test it.")
    else:
        lines.append("No regression: it needs escaped runs at three or more N.")
    if result["fewest_contained"] is not None:
        fewest, below = result["fewest_contained"], result["most_escaped_below"]
        lines.append(f"Fewest {unit} run that contained the fragment: **{fewest}**" + (
            "." if below is None else
            f"; {below} let it through, so by runs the answer is **{fewest}** {unit}."
            if below == fewest - 1 else
            f"; {below} let it through and {below + 1} is not decided by a run: by runs "
            f"the answer is {below + 1} or {fewest} {unit}."
            if below == fewest - 2 else
            f"; {below} let it through and {below + 1}–{fewest - 1} are not decided by a "
            f"run: by runs the answer lies between {below + 1} and {fewest} {unit}."))
    escaped_at = {int(float(r[KEY])) for r in rows
                  if r.get("status") == "done" and r.get("outcome") == "escaped"}
    if reg is not None and reg.plies_to_stop:
        beaten = sorted(n for n in escaped_at if n >= reg.plies_to_stop)
        if beaten:
            lines.append(f"The runs contradict the regression: {', '.join(map(str, beaten))} "
                         f"{unit} let the fragment out, at or above its {reg.plies_to_stop}; "
                         "the runs' answer stands.")
    if result["fewest_contained"] is not None:
        above = sorted(n for n in escaped_at if n > result["fewest_contained"])
        if above:
            lines.append(f"Not monotonic: {', '.join(map(str, above))} {unit} let the fragment "
                         f"out although {result['fewest_contained']} contained it (near the "
                         "limit an outcome can turn on round-off, theory §8.8).")
    falling = [int(float(r[KEY])) for r in rows if r.get("status") == "done" and unsettled(r)]
    if falling:
        lines.append(f"Escaped with the speed still falling at the end (not in the "
                     f"regression): {', '.join(map(str, falling))} {unit} — run them longer.")
    if result["undecided"]:
        lines.append(f"Undecided at the end time (still pushing intact layers, not yet at "
                     f"the casing, or past the modelled casing; not used): "
                     f"{', '.join(map(str, result['undecided']))} {unit} — run them longer.")
    figure = exit_speed_figure(rows, thesis, title, unit, figures / f"{name}.png", reg)
    lines += ["", f"![{title}](validation/{figure.name})", ""]
    return lines, result


def exit_speed_figure(rows, thesis: dict, title: str, unit: str, path: Path, regression=None
                      ) -> Path:
    """Exit speed against N: our decided runs (contained at 0), the thesis's points and
    the regression curve."""
    import numpy as np

    from wovenimpact.io.atomic import save_png as _save
    from wovenimpact.io.plots import plt

    fig, ax = plt.subplots(figsize=(7, 4))
    done = [r for r in rows if r.get("status") == "done"
            and r.get("outcome") in ("escaped", "contained")]
    if done:
        ax.plot([float(r[KEY]) for r in done],
                [float(r["fragment_exit_speed_m_per_s"]) for r in done], "o", label="wovenimpact")
    ax.plot(list(thesis), list(thesis.values()), "s", mfc="none", label="thesis")
    if regression is not None:
        n = np.linspace(min(float(r[KEY]) for r in done), (regression.root or max(
            float(r[KEY]) for r in done)), 100)
        ax.plot(n, regression.predict(n), "-", lw=0.8, label="regression (eq. 8.2)")
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xlabel(unit)
    ax.set_ylabel("fragment exit speed (m/s)")
    ax.set_title(title, fontsize=9)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    _save(fig, path)
    return path


def mass_table(results: dict[str, dict]) -> list[str]:
    """The lightest casing of each kind that contains the fragment: by runs and by the
    regression (mass per unit area of the whole casing, the inner shell counted)."""
    lines = ["### Mass of the lightest casing that contains the fragment", "",
             "Mass per unit area of the casing wall (every layer, the inner aluminium shell "
             "included; the thesis's Table 8-4 left the shell out).", "",
             "| casing | by runs | kg/m² | by regression | kg/m² |", "|---|---|---|---|---|"]
    for name, title, unit, _, _ in LADDERS:
        res = results[name]
        runs = res["fewest_contained"]
        reg = res["regression"]
        by_reg = reg.plies_to_stop if reg is not None else None
        lines.append(
            f"| {title.split(':')[0]} | {f'{runs} {unit}' if runs else 'none contained'} | "
            f"{_fmt(res['mass_per_area'](runs) if runs else None, '.2f', '—')} | "
            f"{f'{by_reg} {unit}' if by_reg else '—'} | "
            f"{_fmt(res['mass_per_area'](by_reg) if by_reg else None, '.2f', '—')} |")
    return lines + [""]


def containment_section(work: str | Path, figures: str | Path, log=_quiet, workers: int = 2,
                        overrides=(), runs=()) -> list[str]:
    """The containment report (module docstring): the runs live in ``work/containment``
    (``overrides``: ``--set KEY=VALUE`` for every run of both ladders), or are the finished
    runs under the ``runs`` directories; the figures go to ``figures``."""
    from wovenimpact.studies.sweep import run_study

    work = Path(work) / "containment"
    figures = Path(figures)
    figures.mkdir(parents=True, exist_ok=True)
    lines = intro_lines()
    results = {}
    from_runs, unfinished = rows_from_runs(runs) if runs else (None, [])
    if runs:
        lines += runs_lines(from_runs, unfinished)
    for name, title, unit, thesis, note in LADDERS:
        if from_runs is not None:
            rows = from_runs[name]
        else:
            path = ROOT / "examples" / "studies" / f"{name}.toml"
            if not path.exists():
                raise InputError(f"no study file {path}")
            log(f"study {name} → {work / name}")
            rows = run_study(path, work / name, workers=workers, overrides=overrides)
        ladder, results[name] = ladder_lines(name, title, unit, thesis, note, rows, figures)
        lines += ladder
        plots = work / name / "plots"
        for png in sorted(plots.glob("*.png")) if plots.exists() and not runs else ():
            shutil.copy(png, figures / f"{name}_{png.name}")
    return lines + mass_table(results)


def intro_lines() -> list[str]:
    """The section's opening paragraph."""
    return ["## Fan-blade containment (thesis chapter 8; issue 11)", "",
            "A titanium fragment released at 1047 rad/s (examples/containment/; geometry, "
            "spin state and release: docs/theory.md §8) against the full casing ring, "
            "graded: `element_size` within 150° about the impact zone, growing to the coarse "
            "size around the rest. The thesis's numbers are trends to compare with, not "
            "targets; nothing is tuned to them.", "",
            "Why ours differ (docs/theory.md §8.6, sensitivity runs, not tuning): two inputs "
            "the thesis does not print each move the exit speed by more than the gap — how "
            "the blade meets the casing (the default blade is a fan blade's, its chord 30° "
            "from the axis at the root and 60° at the tip, with a curved tip; a flat blade "
            "flying face-on loads far more of the casing: 4-ply hybrid casing 102.75 m/s "
            "face-on against 129.90 with the default blade, 7 mm ring, both by the default "
            "stable step) and the hybrid "
            "casing's inner aluminium shell (ours 1 mm).", "",
            "Mesh: the answers are not mesh-converged (docs/theory.md §8.8). They follow "
            "the element's edge along the casing's axis, where the casing bends over a "
            "length of about √(R t): on the 10-ply ring 3 and 2 mm instead of 7 mm along the "
            "axis raise the exit speed 13 % and 17 % (on four plies 3.4 % and 5.1 %; the "
            "ten plies' extrapolated value is 8 % above 2 mm's), and a finer mesh absorbs "
            "less, so the layers a 7 mm ladder needs to contain are too few. The all-metal "
            "casing's 0.5 mm layers bend within 8.7 mm, and its answer moves most: 12 layers "
            "let the fragment out at 25 m/s (not settled at 4 ms) on 7 × 7 mm, at 101 m/s "
            "on 7 mm around × 3 mm along the axis and at 106 m/s on 7 × 2 mm (converging at "
            "order 2.9 to 108 m/s), so the 15 layers of the 7 mm ladder are far too few.", ""]


def runs_lines(ladders: dict[str, list[dict]], unfinished: list[str]) -> list[str]:
    """What a report made from given runs says of them: their meshes and code digests,
    and the runs that have not finished."""
    rows = [r for rs in ladders.values() for r in rs]
    digests = sorted({str(r.get("source_digest")) for r in rows})
    lines = [f"Tabulated from {len(rows)} finished runs (`--runs`), not rerun: their meshes "
             "are the table's element counts; code (source digest) "
             f"{', '.join(f'`{d}`' for d in digests)}."]
    if unfinished:
        lines.append(f"Not finished, left out: {'; '.join(unfinished)}.")
    return lines + [""]


def _ladder_of(summary: dict) -> tuple[str, int] | None:
    """Which ladder a containment run belongs to and its N: a casing of two materials is
    a hybrid one (its innermost layer is the aluminium shell, the rest are plies: N =
    layers − 1), a casing of one material an all-metal one (N = layers); None for a run
    that is not a containment run."""
    materials = summary.get("absorbed_energy_per_material_J")
    layers = summary.get("casing_layers")
    if not materials or not layers:
        return None
    return ("containment_hybrid", int(layers) - 1) if len(materials) > 1 else (
        "containment_metal", int(layers))


def rows_from_runs(paths) -> dict[str, list[dict]]:
    """Ladder rows (as :func:`run_study` gives them) from finished run directories: each
    path is a run (it holds summary.json) or a folder of runs. A run cut short (a
    checkpoint, no summary) cannot say which ladder it belongs to: it is listed apart,
    with the time it reached. Every row carries its elements and its code's source
    digest. Two finished runs of one ladder at the same N are refused (InputError naming
    both): a summary does not say which other input differs (a sensitivity run: another
    blade stagger, shell or mesh), and a ladder must have one point per N. Returns the
    rows of each ladder, sorted by N, and the unfinished runs."""
    import json

    from wovenimpact.results.containment import exit_speed_settled
    from wovenimpact.io.checkpoint import latest_checkpoint
    from wovenimpact.io.history import read_csv

    dirs = []
    for p in map(Path, paths):
        if not p.is_dir():
            raise InputError(f"--runs {p}: no such directory")
        dirs += [p] if (p / "summary.json").exists() or (p / "checkpoints").is_dir() else sorted(
            d for d in p.iterdir() if (d / "summary.json").exists() or (d / "checkpoints").is_dir())
    out: dict[str, list[dict]] = {name: [] for name, *_ in LADDERS}
    unfinished: list[str] = []
    for d in dirs:
        if not (d / "summary.json").exists():
            if latest_checkpoint(d / "checkpoints") is None or not (d / "history.csv").exists():
                continue
            t = read_csv(d / "history.csv")["time_s"]
            unfinished.append(f"{d} (stopped at {float(t[-1]) * 1e3:.2f} ms)" if len(t)
                              else str(d))
            continue
        summary = json.loads((d / "summary.json").read_text(encoding="utf-8"))
        ladder = _ladder_of(summary)
        if ladder is None:
            raise InputError(f"--runs {d}: not a containment run (its summary has no casing)")
        name, n = ladder
        if SETTLED not in summary and (d / "history.csv").exists():  # an older summary
            summary[SETTLED] = exit_speed_settled(read_csv(d / "history.csv"),
                                                  summary.get("outcome", ""))
        out[name].append({**summary, "id": d.name, "path": str(d), "status": "done", KEY: n,
                          "source_digest": summary.get("provenance", {}).get("source_digest")})
    for name, rows in out.items():
        rows.sort(key=lambda r: float(r[KEY]))
        for a, b in zip(rows, rows[1:]):
            if a[KEY] == b[KEY]:
                unit = next(u for n, _, u, _, _ in LADDERS if n == name)
                raise InputError(
                    f"--runs: two finished runs of the {name} ladder at {a[KEY]} {unit}: "
                    f"{a['path']} and {b['path']}; a ladder takes one run per number of "
                    f"{unit} — pass the folders of one ladder (a run with another blade, "
                    "shell or mesh belongs to another report)")
        check_one_fragment(name, rows)
    return out, unfinished


def check_one_fragment(name: str, rows: list[dict]) -> None:
    """The runs of one ladder must strike with one fragment — the same mass and initial
    speed to 1e-9 — or they are not one ladder: another blade, spin rate or element size
    (the released row is one element wide, so the fragment's mass follows the mesh:
    0.229 kg at 5 mm, 0.224 kg at 12 mm). Refused, naming a run of each fragment; rows
    without these keys (older summaries) are not compared."""
    keys = ("fragment_mass_kg", "fragment_initial_speed_m_per_s")
    known = [r for r in rows if all(r.get(k) is not None for k in keys)]
    ref = known[0] if known else None
    for r in known[1:]:
        if any(abs(float(r[k]) - float(ref[k])) > 1e-9 * abs(float(ref[k])) for k in keys):
            raise InputError(
                f"--runs: the {name} ladder mixes fragments: {ref['path']} strikes with "
                f"{float(ref[keys[0]]):.6g} kg at {float(ref[keys[1]]):.6g} m/s, {r['path']} "
                f"with {float(r[keys[0]]):.6g} kg at {float(r[keys[1]]):.6g} m/s (another blade, "
                "spin rate or element size): pass the runs of one ladder")

