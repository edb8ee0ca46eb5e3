"""Comparison figures of a study (matplotlib PNG, like the thesis's Figs. 7-6 to 7-9)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from wovenimpact.io.atomic import save_png  # noqa: E402
from wovenimpact.io.history import read_csv  # noqa: E402

# the history column overlaid across variants, first one present wins
HISTORY_PREFERENCE = ("impactor_velocity_m_per_s", "structure_kinetic_energy_part_J")


def study_plots(info, variants, rows, out: Path) -> list[Path]:
    """One figure per metric against the variants, and the overlaid time histories."""
    written = []
    labels = [", ".join(f"{k.split('.')[-1]}={r[k]}" for k in variants[0].values) for r in rows]
    for metric in info.metrics:
        vals = [(lab, r[metric]) for lab, r in zip(labels, rows) if r.get(metric) not in ("", None)]
        if not vals:
            continue
        fig, ax = plt.subplots(figsize=(7, 4))
        if isinstance(vals[0][1], (list, tuple)):  # one value per ply or layer: a line each
            for k in range(max(len(v) for _, v in vals)):
                ax.plot(range(len(vals)), [float(v[k]) if k < len(v) else float("nan")
                                           for _, v in vals], "o-", label=f"[{k}]")
            ax.legend(fontsize=7)
        else:
            ax.plot(range(len(vals)), [float(v) for _, v in vals], "o-")
        ax.set_xticks(range(len(vals)), [lab for lab, _ in vals], rotation=30, ha="right",
                      fontsize=7)
        ax.set_ylabel(metric)
        ax.set_title(f"{info.name}: {metric}")
        ax.grid(alpha=0.3)
        fig.tight_layout()
        path = out / "plots" / f"{metric}.png"
        save_png(fig, path)
        written.append(path)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    column = None
    for v, lab in zip(variants, labels):
        hist = out / "runs" / v.id / "history.csv"
        if not hist.exists():
            continue
        h = read_csv(hist)
        column = column or next((c for c in HISTORY_PREFERENCE if c in h), None)
        if column:
            ax.plot(h["time_s"] * 1e6, h[column], label=lab)
    if column:
        ax.set_xlabel("time (µs)")
        ax.set_ylabel(column)
        ax.set_title(info.name)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        path = out / "plots" / f"{column}_histories.png"
        save_png(fig, path)
        written.append(path)
    else:
        plt.close(fig)
    return written
