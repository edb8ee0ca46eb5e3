"""The impactor-contact section of docs/validation.md, as Markdown lines.

:func:`smith_strip_lines` runs (or reuses, from ``work``) the flat-face strip impact of
``verification/strip_impact.py`` at 100 and 300 m/s, draws each run's force and kink
histories over Smith, McCrackin and Schiefer's (1958) theory
(``docs/validation/strip_impact_<speed>.png``) and tabulates the measured force, kink
speed and strain against the theory (docs/theory.md §6.2).
``reports.validation.run_validation`` appends the section to its report.
"""

from __future__ import annotations

import json
from pathlib import Path

SPEEDS = (100.0, 300.0)  # m/s, the speeds of tests/verification/test_contact_impact.py


def _quiet(message: str) -> None:
    pass


def strip_figure(result: dict, path: Path, title: str = "") -> Path:
    """Contact force and kink position against time, with Smith's theory drawn over."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    from wovenimpact.io.atomic import save_png

    h = result["history"]
    th = result["theory"]
    t_us = h["time_s"] * 1e6
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(t_us, h["contact_force_N"], lw=0.8, label="wovenimpact")
    a1.axhline(th["force_N"], color="k", ls="--", label="Smith et al. (1958)")
    peak = float(np.max(h["contact_force_N"]))
    if peak > 3.0 * th["force_N"]:  # the pick-up of the struck material, one step long
        a1.set_ylim(-0.5 * th["force_N"], 3.0 * th["force_N"])
        a1.text(0.98, 0.95, f"first contact: {peak / 1e3:.0f} kN (off scale), the\nstruck "
                "material picked up", transform=a1.transAxes, ha="right", va="top",
                fontsize=8)
    a1.set_xlabel("time (µs)")
    a1.set_ylabel("force on the face (N)")
    a1.legend()
    a1.grid(alpha=0.3)
    t0 = result["first_contact_s"] or 0.0
    a2.plot(t_us, h["kink_position_m"] * 1e3, lw=0.8, label="wovenimpact (half deflection)")
    tt = np.linspace(t0, h["time_s"][-1], 50)
    a2.plot(tt * 1e6, (result["contact_half_width_m"] + 0.5 * th["kink_speed"] * (tt - t0)) * 1e3,
            "k--", label="a + U t / 2 (theory)")
    a2.set_xlabel("time (µs)")
    a2.set_ylabel("position (mm)")
    a2.legend()
    a2.grid(alpha=0.3)
    fig.suptitle(title or "flat face on an elastic strip")
    fig.tight_layout()
    return save_png(fig, path)


def strip_rows(work: Path, figures: Path, log=_quiet) -> list[dict]:
    """The strip impact at each of :data:`SPEEDS`: its figures drawn, its figures against
    the theory returned (cached in ``work/smith_strip.json``; delete it to run again)."""
    from wovenimpact.verification.strip_impact import StripImpact, strip_impact

    cache = work / "smith_strip.json"
    if cache.exists():
        return json.loads(cache.read_text())
    rows = []
    for speed in SPEEDS:
        figure = figures / f"strip_impact_{speed:.0f}.png"
        log(f"flat face on an elastic strip at {speed:.0f} m/s → {figure}")
        r = strip_impact(StripImpact(speed=speed))
        strip_figure(r, figure, f"5 kg flat face at {speed:.0f} m/s on a 0.5 mm elastic strip")
        rows.append({"speed_m_per_s": speed, "figure": figure.name,
                     **{k: v for k, v in r.items() if k != "history"}})
    work.mkdir(parents=True, exist_ok=True)
    cache.write_text(json.dumps(rows, indent=1))
    return rows


def smith_strip_lines(work: Path, figures: Path, log=_quiet) -> list[str]:
    """The section: a table of force, kink speed and strain against Smith's theory, and
    the histories."""
    rows = strip_rows(work, figures, log)
    lines = [
        "## Impactor contact: a flat face on an elastic strip (verification/strip_impact.py)",
        "",
        "A 5 kg flat face (radius 3 mm) strikes a 0.5 mm steel-like strip (2 mm wide, ν = 0, "
        "0.125 mm elements, quarter model) at constant speed; Smith, McCrackin and Schiefer "
        "(1958) give the strain behind the longitudinal wave, the kink speed (laboratory "
        "frame) and the force on the face. Means after the first microsecond; docs/theory.md "
        "§6.2. Tests: tests/verification/test_contact_impact.py (each within 5 %).", "",
        "| speed | force (N) | theory | kink speed (m/s) | theory | strain | theory | "
        "struck nodes off the face (mm) |", "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        th = r["theory"]
        lines.append(
            f"| {r['speed_m_per_s']:.0f} m/s | {r['force_N']:.1f} ({r['force_error']:+.1%}) | "
            f"{th['force_N']:.1f} | {r['kink_speed_m_per_s']:.1f} "
            f"({r['kink_speed_error']:+.1%}) | {th['kink_speed']:.1f} | {r['strain']:.5f} "
            f"({r['strain_error']:+.1%}) | {th['strain']:.5f} | "
            f"{r['max_stray_from_face_m'] * 1e3:.3f} |")
    for r in rows:
        lines += ["", f"![strip at {r['speed_m_per_s']:.0f} m/s](validation/{r['figure']})"]
    return lines + [""]
