"""Figures of a single-element test, in the manner of thesis Figs. 6-10 to 6-15."""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from wovenimpact.calibration.single_element import SHEAR_TESTS, ElementTestResult  # noqa: E402
from wovenimpact.io.atomic import save_png  # noqa: E402


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    return save_png(fig, path)


def plot_element_test(result: ElementTestResult, out_dir: Path) -> list[Path]:
    """Write the PNG figures of one test into ``out_dir``; return their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    h = result.history
    shear = result.test in SHEAR_TESTS
    if shear:
        x, xlabel = h["shear_angle_deg"], "shear angle γ (°)"
    else:
        x, xlabel = h["displacement_m"] * 1e3, "edge displacement (mm)"
    title = f"{result.test} — " + ", ".join(f"{k} {v}" for k, v in result.options.items())
    paths = []

    fig, ax = plt.subplots(figsize=(6, 4))  # Figs. 6-10, 6-13: yarn tensions
    ax.plot(x, h["tension_w_N"], label="warp T_w")
    ax.plot(x, h["tension_f_N"], "--", label="fill T_f")
    if result.failure_displacement_m is not None and not shear:
        ax.axvline(result.failure_displacement_m * 1e3, color="grey", lw=0.8, ls=":")
    ax.set(xlabel=xlabel, ylabel="yarn tension (N)", title=title)
    ax.legend()
    ax.grid(alpha=0.3)
    paths.append(_save(fig, out_dir / "tensions.png"))

    fig, ax = plt.subplots(figsize=(6, 4))  # Figs. 6-12, 6-14: crimp heights
    ax.plot(x, h["height_w_m"] * 1e3, label="warp H_w")
    ax.plot(x, h["height_f_m"] * 1e3, "--", label="fill H_f")
    ax.set(xlabel=xlabel, ylabel="crimp height (mm)", title=title)
    ax.legend()
    ax.grid(alpha=0.3)
    paths.append(_save(fig, out_dir / "heights.png"))

    fig, ax = plt.subplots(figsize=(6, 4))  # stress resultants
    for name, style in (("N_xx_N_per_m", "-"), ("N_yy_N_per_m", "--"), ("N_xy_N_per_m", ":")):
        ax.plot(x, h[name] / 1e3, style, label=name.split("_N")[0])
    ax.set(xlabel=xlabel, ylabel="membrane resultant (kN/m)", title=title)
    ax.legend()
    ax.grid(alpha=0.3)
    paths.append(_save(fig, out_dir / "resultants.png"))

    fig, ax = plt.subplots(figsize=(6, 4))  # energy balance
    ax.plot(x, h["external_work_J_per_m2"], label="external work W")
    ax.plot(x, h["stored_energy_J_per_m2"], "--", label="stored energy U")
    ax.set(
        xlabel=xlabel,
        ylabel="energy per reference area (J/m²)",
        title=f"energy error before failure {result.energy_error_fraction:.2e}",
    )
    ax.legend()
    ax.grid(alpha=0.3)
    paths.append(_save(fig, out_dir / "energy.png"))

    if shear:  # Fig. 6-15: shear stress and secant modulus against the shear angle
        gam = np.radians(h["shear_angle_deg"])
        with np.errstate(invalid="ignore", divide="ignore"):
            g_sec = np.where(np.abs(gam) > 0, h["shear_stress_Pa"] / gam, np.nan)
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(h["shear_angle_deg"], g_sec / 1e9, label="secant modulus τ/γ")
        ax.set(xlabel=xlabel, ylabel="shear modulus (GPa)", title=title)
        ax2 = ax.twinx()
        ax2.plot(h["shear_angle_deg"], h["shear_stress_Pa"] / 1e6, "r--", label="τ")
        ax2.set_ylabel("shear stress τ (MPa)")
        ax.grid(alpha=0.3)
        fig.legend(loc="upper left")
        paths.append(_save(fig, out_dir / "shear.png"))
    return paths


def plot_metal_element_test(result, out_dir: Path) -> list[Path]:
    """Figures of a metal single-element test (:mod:`~wovenimpact.calibration.metal_element`):
    the stress–plastic-strain curve with the file's hardening table drawn over it, the
    stress components against the applied strain, and the energy balance."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    h = result.history
    params = result.params
    alive = h["alive"] > 0.0
    title = f"{params.name}: {result.test}, {result.strain_rate:g} 1/s"
    paths = []

    fig, ax = plt.subplots(figsize=(6, 4))  # σ_eq against ε̄p, table over it
    eps = h["plastic_strain"][alive]
    ax.plot(eps, h["kirchhoff_equivalent_Pa"][alive] / 1e6, lw=2.5, alpha=0.6,
            label="point: Kirchhoff τ_eq (the return's variable)")
    ax.plot(eps, h["equivalent_stress_Pa"][alive] / 1e6, "--", label="point: Cauchy σ_eq")
    if params.rate is not None:
        from wovenimpact.calibration.metal_element import rate_factor

        scaled = h["table_stress_Pa"] * rate_factor(params, h["plastic_strain_rate_per_s"])
        ax.plot(eps, scaled[alive] / 1e6, "g-.", lw=1,
                label="table × (1 + C ln(ε̇p/ε̇0)) at the point's rate")
    e_tab = np.array([r[0] for r in params.hardening])
    s_tab = np.array([r[1] for r in params.hardening])
    e_pt = float(np.max(eps)) if eps.size else 0.0
    e_max = 1.3 * e_pt if e_pt > 0.0 else float(e_tab[-1])
    keep = e_tab <= e_max
    e_tab, s_tab = e_tab[keep], s_tab[keep]
    if not keep.all():  # the table continues beyond the plot: draw it to the edge
        e_tab = np.append(e_tab, e_max)
        s_tab = np.append(s_tab, params.flow_stress(e_max))
    e_line = np.append(e_tab, e_max * 1.05) if e_max > e_tab[-1] else e_tab
    s_line = np.append(s_tab, s_tab[-1]) if e_max > e_tab[-1] else s_tab
    ax.plot(e_line, s_line / 1e6, "k:", lw=1)
    ax.plot(e_tab, s_tab / 1e6, "k.", ms=5, label="hardening table of the file")
    if result.failure_plastic_strain is not None:
        ax.axvline(result.failure_plastic_strain, color="r", lw=0.8, ls=":", label="failure")
    ax.set(xlabel="equivalent plastic strain ε̄p", ylabel="equivalent stress (MPa)",
           title=f"{title}\nmax |τ_eq − table × R| / σ_y = {result.table_error_max:.1e}",
           xlim=(0.0, max(e_max, 1e-6) * 1.05))
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    paths.append(_save(fig, out_dir / "stress_strain.png"))

    fig, ax = plt.subplots(figsize=(6, 4))  # components against the applied strain
    x = h["strain"]
    for name, style in (("stress_xx_Pa", "-"), ("stress_yy_Pa", "--"), ("stress_xy_Pa", ":")):
        ax.plot(x, h[name] / 1e6, style, label=name.split("_Pa")[0].replace("stress_", "σ_"))
    xlabel = "shear γ" if result.test == "shear" else "log strain ln F_xx"
    ax.set(xlabel=xlabel, ylabel="Cauchy stress (MPa)", title=title)
    ax.legend()
    ax.grid(alpha=0.3)
    paths.append(_save(fig, out_dir / "stresses.png"))

    fig, ax = plt.subplots(figsize=(6, 4))  # energy balance
    w_e, w_p = h["stored_energy_J_per_m2"], h["plastic_work_J_per_m2"]
    ax.plot(x, h["external_work_J_per_m2"], label="external work W")
    ax.plot(x, w_e + w_p + h["failure_energy_J_per_m2"], "--",
            label="elastic + plastic + released at failure")
    ax.plot(x, w_p, ":", label="plastic work")
    ax.set(xlabel=xlabel, ylabel="energy per reference area (J/m²)",
           title=f"energy error {result.energy_error_fraction:.2e}")
    ax.legend()
    ax.grid(alpha=0.3)
    paths.append(_save(fig, out_dir / "energy.png"))
    return paths
