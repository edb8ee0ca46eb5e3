"""Figures of a run (matplotlib, written atomically as PNG)."""

from __future__ import annotations

from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from wovenimpact.io.atomic import save_png  # noqa: E402


DAMPING_COLUMNS = ("contact_dissipated_part_J", "contact_damping_part_J")  # first present


def energy_curves(h: dict, symmetry_factor: float = 1.0) -> dict[str, np.ndarray]:
    """The curves of :func:`energy_plot`, whole-problem values (J): the history's
    modelled-part columns (``*_part_J``) × ``symmetry_factor``.

    Keys: ``structure kinetic``, ``impactor kinetic`` (with an impactor), ``contact
    energy`` and its part ``contact dissipated`` (dashpots and friction, when the
    history has it), of which ``contact damping`` (the dashpots' own work, booked pair by
    pair) and, when any, ``contact friction``, ``internal work`` with its parts ``stored (live elements)``,
    ``hourglass (live elements)``, ``eroded internal (at erosion)`` and, for metal
    runs, ``plastic dissipation`` (the J2 points' plastic work, live and eroded
    elements), ``eroded kinetic``, ``external work``, and ``balance error`` =
    |energy_drift|: its largest value over the last ``energy_normaliser`` (× the same
    factor) is exactly summary.json's ``energy_error_fraction``. The balance is structure
    kinetic + impactor kinetic + internal work + eroded kinetic − external work + contact
    energy − initial kinetic energy; parts are not added again.
    """
    f = symmetry_factor
    out = {"structure kinetic": f * h["structure_kinetic_energy_part_J"]}
    if "impactor_kinetic_energy_part_J" in h:
        out["impactor kinetic"] = f * h["impactor_kinetic_energy_part_J"]
    out["contact energy"] = f * h["contact_energy_part_J"]
    damping = next((c for c in DAMPING_COLUMNS if c in h), None)
    if damping:
        out["contact dissipated"] = f * h[damping]
    if "contact_damping_energy_part_J" in h:
        out["contact damping"] = f * h["contact_damping_energy_part_J"]
    if np.any(h.get("contact_friction_energy_part_J", 0.0)):
        out["contact friction"] = f * h["contact_friction_energy_part_J"]
    out["internal work"] = f * h["internal_work_part_J"]
    out["stored (live elements)"] = f * h["stored_energy_part_J"]
    out["hourglass (live elements)"] = f * h["hourglass_energy_part_J"]
    out["eroded internal (at erosion)"] = f * h["eroded_internal_energy_part_J"]
    if "plastic_work_part_J" in h:
        out["plastic dissipation"] = f * h["plastic_work_part_J"]
    out["eroded kinetic"] = f * h["eroded_kinetic_energy_part_J"]
    out["external work"] = f * h["external_work_part_J"]
    out["balance error"] = f * np.abs(h["energy_drift_part_J"])
    return out


def energy_plot(h: dict, path: str | Path, title: str = "", symmetry_factor: float = 1.0) -> Path:
    """Energies of the whole system against time (:func:`energy_curves`, whole-problem
    values): structure and impactor kinetic energy, internal work and its parts (dashed),
    contact energy and what contact dashpots and friction dissipated of it (dashed; the
    dashpots' and friction's own shares dash-dotted),
    eroded, external work, and the balance error, with a line at 1 % of the initial
    kinetic energy for scale.

    A containment run's history (with the casing's columns,
    ``containment.CASING_ENERGY_COLUMNS``) gets two panels instead
    (:func:`containment_energy_plot`): the fragment's kilojoules would flatten the
    casing's energies near zero on one axis."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if all(c in h for c in CASING_CURVES.values()):
        fig = containment_energy_figure(h, title, symmetry_factor)
    else:
        fig = single_energy_figure(h, title, symmetry_factor)
    fig.tight_layout()
    save_png(fig, path)
    return path


def _initial_kinetic(h: dict, symmetry_factor: float) -> float:
    return symmetry_factor * (h["structure_kinetic_energy_part_J"][0]
                              + (h["impactor_kinetic_energy_part_J"][0]
                                 if "impactor_kinetic_energy_part_J" in h else 0.0))


def single_energy_figure(h: dict, title: str = "", symmetry_factor: float = 1.0):
    """The one-panel figure of :func:`energy_plot` (every run but a containment one)."""
    t = h["time_s"] * 1e6
    curves = energy_curves(h, symmetry_factor)
    dashed = {"stored (live elements)", "hourglass (live elements)",
              "eroded internal (at erosion)", "contact dissipated", "plastic dissipation"}
    dotted = {"contact damping", "contact friction"}
    fig, ax = plt.subplots(figsize=(7.5, 4.6))
    for label, y in curves.items():
        if label == "balance error":
            ax.plot(t, y, "k:", lw=1.6,
                    label="balance error |drift| (energy_error_fraction × energy put in)")
        else:
            ax.plot(t, y, "--" if label in dashed else "-." if label in dotted else "-",
                    label=label)
    e0 = _initial_kinetic(h, symmetry_factor)
    if e0 > 0.0:
        ax.axhline(0.01 * e0, color="0.6", lw=0.8, label="1 % of the initial kinetic energy")
    ax.set_xlabel("time (µs)")
    ax.set_ylabel("energy, whole problem (J)")
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2)
    return fig


# the casing panel's own curves: label → history column (containment.casing_energy_row)
CASING_CURVES = {"casing absorbed (contact work received)": "casing_absorbed_energy_part_J",
                 "casing kinetic": "casing_kinetic_energy_part_J",
                 "casing elements' stored + hourglass": "casing_element_energy_part_J"}
FRAGMENT_CURVE = "fragment_kinetic_energy_part_J"


def containment_curves(h: dict, symmetry_factor: float = 1.0) -> tuple[dict, dict]:
    """The two panels' curves of a containment run's energy plot (J, whole problem):

    - the fragment and the whole model: ``fragment kinetic`` (Σ ½ m v² over its nodes),
      ``structure kinetic`` (every node: the spinning hub part, the fragment and the
      casing), ``internal work``, ``external work`` (the blade root's prescribed spin),
      ``contact energy`` and the ``balance error``;
    - the casing: the energy it absorbed (the contact work its layers' nodes received,
      summary.json's ``casing_absorbed_energy_J`` at the end), its kinetic energy, the
      stored and hourglass energy its elements hold, and what is left of the absorbed
      energy, ``casing dissipated (absorbed − kinetic − held)``: broken yarns, plastic
      flow, eroded pieces and the layers' contact with each other; beside them the
      whole model's contact damping and friction, eroded kinetic and eroded internal
      energy (all but the blade's release row are the casing's), and the balance error
      again on this scale.
    """
    f = symmetry_factor
    every = energy_curves(h, f)
    whole = {"fragment kinetic": f * h[FRAGMENT_CURVE]}
    for label in ("structure kinetic", "internal work", "external work", "contact energy",
                  "balance error"):
        whole[label] = every[label]
    casing = {label: f * h[c] for label, c in CASING_CURVES.items()}
    casing["casing dissipated (absorbed − kinetic − held)"] = (
        casing["casing absorbed (contact work received)"] - casing["casing kinetic"]
        - casing["casing elements' stored + hourglass"])
    for label in ("contact damping", "contact friction", "eroded kinetic",
                  "eroded internal (at erosion)", "balance error"):
        if label in every:
            casing[label] = every[label]
    return whole, casing


def containment_energy_figure(h: dict, title: str = "", symmetry_factor: float = 1.0):
    """Two panels sharing the time axis (:func:`containment_curves`): the fragment's
    kinetic energy with the whole model's books above, the casing's energies below on
    their own scale."""
    t = h["time_s"] * 1e6
    whole, casing = containment_curves(h, symmetry_factor)
    fig, (top, bottom) = plt.subplots(2, 1, figsize=(7.5, 7.2), sharex=True)
    for ax, curves in ((top, whole), (bottom, casing)):
        for label, y in curves.items():
            if label == "balance error":
                ax.plot(t, y, "k:", lw=1.6, label="balance error |drift| (whole model)")
            elif label.startswith(("contact damping", "contact friction")):
                ax.plot(t, y, "-.", label=f"{label} (whole model)")
            elif label.startswith("eroded"):
                ax.plot(t, y, ":", label=f"{label} (whole model)")
            else:
                ax.plot(t, y, "--" if "dissipated" in label else "-",
                        lw=2.0 if label in ("fragment kinetic",
                                            "casing absorbed (contact work received)") else 1.2,
                        label=label)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    e0 = _initial_kinetic(h, symmetry_factor)
    if e0 > 0.0:
        top.axhline(0.01 * e0, color="0.6", lw=0.8, label="1 % of the initial kinetic energy")
        top.legend(fontsize=7, ncol=2)
    top.set_ylabel("fragment and whole model (J)")
    top.set_title(title)
    bottom.set_ylabel("casing (J)")
    bottom.set_xlabel("time (µs)")
    return fig


def impactor_plot(h: dict, path: str | Path, title: str = "", markers=()) -> Path:
    """Impactor velocity along its travel, and the contact force on it, against time;
    ``markers`` (time in s, label; :func:`event_markers`): each ply's first perforation
    and the instant the outcome was decided, as labelled vertical lines."""
    path = Path(path)
    t = h["time_s"] * 1e6
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    _mark((a1, a2), markers)
    a1.plot(t, h["impactor_velocity_m_per_s"])
    a1.set_ylabel("impactor velocity (m/s)")
    a1.set_title(title)
    a1.grid(alpha=0.3)
    a2.plot(t, h["contact_force_full_N"], color="C3")
    a2.set_ylabel("contact force, full model (N)")
    a2.set_xlabel("time (µs)")
    a2.grid(alpha=0.3)
    fig.tight_layout()
    save_png(fig, path)
    return path


def event_markers(perforated, decided, names=None) -> list[tuple[float, str]]:
    """(time in s, label) of the instants marked on the fragment and impactor plots: each
    layer's (ply's) first perforation (``perforated``, one time or None a layer, in
    order; ``names`` their labels) and the instant the outcome was decided (``decided``,
    None: not decided). Layers perforated at the same instant share one marker."""
    names = list(names) if names is not None else [f"layer {k}" for k in range(len(perforated))]
    at: dict[float, list[str]] = {}
    for name, t in zip(names, perforated):
        if t is not None:
            at.setdefault(float(t), []).append(name)
    out = [(t, " + ".join(n) + " perforated") for t, n in at.items()]
    if decided is not None:
        out.append((float(decided), "outcome decided"))
    return out


def _mark(axes, markers) -> None:
    """Vertical lines at the ``markers`` (time s, label), labelled on the first axes."""
    for i, (t, label) in enumerate(markers):
        colour = "k" if label == "outcome decided" else "C2"
        for ax in axes:
            ax.axvline(t * 1e6, color=colour, lw=0.9, ls="--" if colour == "k" else ":")
        axes[0].annotate(label, (t * 1e6, 1.0), xycoords=("data", "axes fraction"),
                         xytext=(2, -4 - 9 * (i % 4)), textcoords="offset points",
                         fontsize=6.5, color=colour, va="top")


def fragment_plot(h: dict, path: str | Path, title: str = "", outcome: str = "",
                  markers=()) -> Path:
    """A containment run against time: the fragment's centre-of-mass speed and its
    radial velocity (outward positive), and the outermost casing layer's bulge (its
    largest outward radial displacement), from the history columns of
    ``containment.fragment_row``; ``markers`` (time in s, label; :func:`event_markers`)
    are drawn as labelled vertical lines: each layer's first perforation and the
    instant the outcome was decided."""
    path = Path(path)
    t = h["time_s"] * 1e6
    fig, (a1, a2) = plt.subplots(2, 1, figsize=(7, 5.5), sharex=True)
    _mark((a1, a2), markers)
    a1.plot(t, h["fragment_speed_m_per_s"], label="speed of the centre of mass")
    a1.plot(t, h["fragment_radial_velocity_m_per_s"], label="radial velocity (outward +)")
    a1.axhline(0.0, color="k", lw=0.6)
    a1.set_ylabel("fragment (m/s)")
    a1.set_title(f"{title}: {outcome}" if outcome else title)
    a1.grid(alpha=0.3)
    a1.legend(fontsize=7)
    a2.plot(t, h["outer_layer_bulge_m"] * 1e3, color="C3")
    a2.set_ylabel("outermost layer bulge (mm)")
    a2.set_xlabel("time (µs)")
    a2.grid(alpha=0.3)
    fig.tight_layout()
    save_png(fig, path)
    return path


def layer_energy_columns(h: dict) -> list[str]:
    """The per-layer (casing) or per-ply (plate) energy columns of a history, in layer
    order: ``casing_layer{k}_absorbed_energy_part_J`` or ``ply{p}_contact_work_part_J``."""
    import re

    found = []
    for c in h:
        m = (re.fullmatch(r"casing_layer(\d+)_absorbed_energy_part_J", c)
             or re.fullmatch(r"ply(\d+)_contact_work_part_J", c))
        if m:
            found.append((int(m.group(1)), c))
    return [c for _, c in sorted(found)]


def layer_energy_plot(h: dict, path: str | Path, title: str = "",
                      symmetry_factor: float = 1.0, names=None, markers=()) -> Path | None:
    """The energy each casing layer (or ply) absorbed against time (J, whole problem):
    the contact work its nodes received (:func:`layer_energy_columns` × the symmetry
    factor), one line a layer, with their sum; ``names`` label the layers (default
    "layer k" / "ply p"), ``markers`` as on the fragment plot. None (nothing written)
    when the history has no such column."""
    columns = layer_energy_columns(h)
    if not columns:
        return None
    path = Path(path)
    t = h["time_s"] * 1e6
    plate = columns[0].startswith("ply")
    if names is None:
        names = [c.split("_")[0].replace("casing_layer", "layer ").replace("ply", "ply ")
                 for c in columns]
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    total = np.zeros(t.shape)
    for name, c in zip(names, columns):
        y = symmetry_factor * np.asarray(h[c], dtype=float)
        total = total + y
        ax.plot(t, y, label=name)
    ax.plot(t, total, "k--", lw=1.0, label="sum over the " + ("plies" if plate else "layers"))
    _mark((ax,), markers)
    ax.set_xlabel("time (µs)")
    ax.set_ylabel(("contact work per ply" if plate else "absorbed energy per layer")
                  + ", whole problem (J)")
    return _finish_time_plot(fig, ax, title, "center left", path)


def contact_force_plot(h: dict, path: str | Path, title: str = "", markers=()) -> Path | None:
    """The contact force histories of results.contact_forces (kN): the blade on the casing
    and layer k on layer k + 1 (containment), or ply on ply along the impactor's travel
    with the force on the impactor (plate impact); ``markers`` as on the fragment plot.
    None (nothing written) when the history has no such column."""
    columns = [c for c in h if c.startswith("contact_force_") and c != "contact_force_full_N"]
    if "contact_force_full_N" in h and columns:
        columns = ["contact_force_full_N"] + columns
    if not columns:
        return None
    path = Path(path)
    t = h["time_s"] * 1e6
    fig, ax = plt.subplots(figsize=(7.5, 4.4))
    for c in columns:
        label = ("on the impactor" if c == "contact_force_full_N" else
                 c.removeprefix("contact_force_").removesuffix("_full_N").removesuffix("_N")
                 .replace("_", " on ", 1).replace("_", " "))
        ax.plot(t, 1e-3 * np.asarray(h[c], dtype=float), label=label,
                lw=1.6 if c in ("contact_force_full_N", "contact_force_blade_casing_N") else 1.0)
    _mark((ax,), markers)
    ax.set_xlabel("time (µs)")
    plate = columns[0] == "contact_force_full_N"  # along the travel, whole problem
    ax.set_ylabel("contact force along the travel (kN)" if plate else "contact force (kN)")
    return _finish_time_plot(fig, ax, title, "upper right", path)


def _finish_time_plot(fig, ax, title: str, legend_loc: str, path: Path) -> Path:
    """Title, grid and a two-column legend at ``legend_loc``; saved to ``path``."""
    ax.set_title(title)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc=legend_loc)
    fig.tight_layout()
    save_png(fig, path)
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
    save_png(fig, path)
    return path


def write_run_plots(out: Path, title: str, model, state, h: dict, summary: dict) -> None:
    """The plots of a finished run in ``OUT/plots``: energies; a containment run's fragment
    plot, a plate's deflection profile and impactor plot, each with the instants its
    layers (plies) were first perforated and its outcome decided; the energy each layer
    or ply absorbed over time; the contact forces between the parts."""
    from wovenimpact.results.containment import is_containment, layer_materials
    from wovenimpact.results.quantities import symmetry_factor  # (the parameters' name)

    plots = out / "plots"
    factor = symmetry_factor(model)
    energy_plot(h, plots / "energy.png", title=title, symmetry_factor=factor)
    if is_containment(model):  # a plate's deflection along y = 0 means nothing on a casing
        names = [f"layer {k} ({m})" for k, m in enumerate(layer_materials(model))]
        markers = event_markers(summary.get("layer_perforated_at_s", []),
                                summary.get("outcome_decided_at_s"), names)
        fragment_plot(h, plots / "fragment.png", title=title,
                      outcome=summary.get("outcome", ""), markers=markers)
    else:
        if model.n_elems:  # (a model of hexahedra has no plies)
            deflection_plot(model, state, plots / "ply_deflection.png", title=title)
        numbers = np.unique(model.ply)
        names = [f"ply {p}" for p in numbers]
        markers = event_markers(summary.get("ply_perforated_at_s", []),
                                summary.get("outcome_decided_at_s"), names)
    if "impactor_velocity_m_per_s" in h:
        impactor_plot(h, plots / "impactor.png", title=title, markers=markers)
    layer_energy_plot(h, plots / "layer_energy.png", title=title, symmetry_factor=factor,
                      names=names, markers=markers)
    contact_force_plot(h, plots / "contact_forces.png", title=title, markers=markers)
