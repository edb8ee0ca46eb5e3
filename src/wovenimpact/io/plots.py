"""Figures of a run (matplotlib, written atomically as PNG)."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from wovenimpact.io.atomic import atomic_path  # noqa: E402


def energy_plot(h: dict, path: str | Path, title: str = "") -> Path:
    """Energy balance against time: kinetic, internal work, hourglass, external work,
    eroded, and the balance error KE + W_int + E_eroded,kin − W_ext − KE0."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    t = h["time_s"] * 1e6
    fig, ax = plt.subplots(figsize=(7, 4.2))
    ax.plot(t, h["kinetic_energy_J"], label="kinetic")
    ax.plot(t, h["internal_work_J"], label="internal work")
    ax.plot(t, h["stored_energy_J"], "--", label="stored (elastic)")
    ax.plot(t, h["hourglass_energy_J"], label="hourglass")
    ax.plot(t, h["external_work_J"], label="external work")
    ax.plot(t, h["eroded_kinetic_energy_J"] + h["eroded_internal_energy_J"], label="eroded")
    total = (h["kinetic_energy_J"] + h["internal_work_J"] + h["eroded_kinetic_energy_J"]
             - h["external_work_J"])
    ax.plot(t, total - total[0], "k:", label="balance error")
    ax.set_xlabel("time (µs)")
    ax.set_ylabel("energy (J)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120, format="png")
    plt.close(fig)
    return path
