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


def impactor_plot(h: dict, path: str | Path, title: str = "") -> Path:
    """Impactor velocity along its travel, and the contact force on it, against time."""
    path = Path(path)
    t = h["time_s"] * 1e6
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    a1.plot(t, h["impactor_velocity_m_per_s"])
    a1.set_ylabel("impactor velocity (m/s)")
    a1.set_title(title)
    a1.grid(alpha=0.3)
    a2.plot(t, h["contact_force_full_N"], color="C3")
    a2.set_ylabel("contact force, full model (N)")
    a2.set_xlabel("time (µs)")
    a2.grid(alpha=0.3)
    fig.tight_layout()
    _save(fig, path)
    return path


def deflection_plot(model, state, path: str | Path, title: str = "") -> Path:
    """Deflection of each ply along the line y ≈ 0 (the x axis through the impact
    point) at the end of the run."""
    import numpy as np

    path = Path(path)
    fig, ax = plt.subplots(figsize=(7, 4))
    u = state.x - model.x0
    for p in np.unique(model.ply):
        nodes = np.unique(model.quads[model.ply == p])
        y = np.abs(model.x0[nodes, 1])
        line = nodes[y <= y.min() + 1e-12]
        order = np.argsort(model.x0[line, 0])
        ax.plot(model.x0[line[order], 0] * 1e3, u[line[order], 2] * 1e3, label=f"ply {p}")
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("deflection u_z (mm)")
    ax.set_title(f"{title}: t = {state.t * 1e6:.1f} µs")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    _save(fig, path)
    return path


def _save(fig, path: Path) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=120, format="png")
    plt.close(fig)
