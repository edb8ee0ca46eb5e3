"""Impulsively loaded, fully clamped square plate against Jones's rigid-plastic theory.

Verification of the metal section at large deflection (issue 10; docs/theory.md §7.8).
A square plate of side 2L and thickness H, clamped on all four edges, is given a
uniform transverse velocity V0 at t = 0. Jones's approximate rigid–perfectly-plastic
method with membrane forces (N. Jones, Structural Impact, ch. 7; Int. J. Solids Struct.
7, 1007, 1971) takes the pyramid mechanism w = W φ (four rigid triangles, hinge lines
along the edges and the diagonals) and a square yield curve in the (N, M) plane (the
membrane force N0 = σ0 H and the moment M0 = σ0 H²/4 act together on a hinge line,
D = Σ∫(M0 + N0 w) θ̇ dl): edges 4 × 2L × M0 × Ẇ/L, diagonals 4 × √2 L × (M0 + N0 w̄)
× √2 Ẇ/L with the mean w̄ = W/2 along them, so the work to reach W is 16 M0 W + 2 N0 W².
(For the 2L × 2B plate the same steps give the form of Jones's result,
W_f/H = (3 − ξ0)(√(1 + Γ) − 1) / (2[1 + (ξ0 − 1)(ξ0 − 2)]) with his ξ0 = β(√(3 + β²) − β);
for the simply supported square, no edge hinges, ½(√(1 + 2λ/3) − 1).) What a single
mode cannot say is how much of the impulse's kinetic energy 2 μ V0² L² (μ = ρH) it
carries; the two limits are

    mid-point velocity V0 (Jones's approximate method): E = μ (2L²/3) V0²/2, the
        pyramid's kinetic energy, 1/6 of the impulse's → W_f/H = √(1 + λ/6) − 1;
    all of the impulse's kinetic energy absorbed by the mechanism (the rigid-plastic
        energy balance: nothing is left elastic or moving) → W_f/H = √(1 + λ) − 1;

with λ = ρ V0² L² / (σ0 H²). The exact rigid-plastic response is expected between: its
travelling-hinge phase (a flat centre moving at V0 while hinges run in from the edges,
seen in the runs) holds more than the pyramid's energy, and plastic work is done along
the way that the final pyramid does not show. :func:`jones_band` returns the two.

Which of them Jones's published comparison with experiments uses, and its scatter,
could not be checked here (Structural Impact is not in the reference library);
docs/theory.md §7.8 says so and reports the computed deflections against both.

:class:`JonesPlate` runs a quarter model (symmetry on x = 0 and y = 0) of an
elastic–perfectly-plastic J2 plate (5 Simpson points), no rate effect, no failure;
the permanent deflection is the mid-point deflection averaged over the last
``settle_fraction`` of the run, when the plate only vibrates elastically about its
permanent shape.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wovenimpact.materials.metal import MetalParameters
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.results.metal_state import plastic_work
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver import Workspace, step
from wovenimpact.state import initial_state


def jones_lambda(density: float, speed: float, half_side: float, yield_stress: float,
                 thickness: float) -> float:
    """λ = ρ V0² L² / (σ0 H²), Jones's dimensionless initial kinetic energy."""
    return density * speed**2 * half_side**2 / (yield_stress * thickness**2)


def jones_clamped_square(gamma: float) -> float:
    """W_f / H = √(1 + Γ) − 1: permanent mid-point deflection of a fully clamped square
    plate, pyramid mechanism, square yield curve, Γ = 2 E / (σ0 H L²) with E the kinetic
    energy the mechanism starts with (module docstring)."""
    return math.sqrt(1.0 + gamma) - 1.0


def jones_band(lam: float) -> tuple[float, float]:
    """(mode, impulse): W_f/H with the pyramid starting at V0 (Γ = λ/6, Jones's
    approximate method) and with all of the impulse's kinetic energy (Γ = λ)."""
    return jones_clamped_square(lam / 6.0), jones_clamped_square(lam)


def aluminium_6061_t6() -> MetalParameters:
    """Elastic–perfectly-plastic 6061-T6 (typical handbook values, ASM: E 68.9 GPa,
    ν 0.33, ρ 2700 kg/m³, 0.2 % yield 276 MPa), rate-independent, no failure: the
    material of Jones's rigid-plastic theory (σ0) with the elasticity of the metal."""
    return MetalParameters(name="6061-T6 (perfectly plastic)", kind="j2_plastic",
                           density=2700.0, modulus=68.9e9, poisson=0.33,
                           hardening=((0.0, 276e6),))


@dataclass
class JonesPlate:
    """The problem (SI): a 100 mm square, 1 mm thick 6061-T6 plate at 77 m/s (λ = 145;
    the kinetic energy is 14 × the elastic capacity σ0²/2E of the plate's volume, so
    rigid-plastic theory applies); ``elements`` per half side of the quarter model."""

    material: MetalParameters = field(default_factory=aluminium_6061_t6)
    half_side: float = 50e-3
    thickness: float = 1e-3
    speed: float = 77.0
    elements: int = 8  # per half side (quarter model)
    points: int = 5
    end_time: float = 400e-6
    settle_fraction: float = 0.4

    @property
    def lam(self) -> float:
        sigma0 = self.material.hardening[0][1]
        return jones_lambda(self.material.density, self.speed, self.half_side, sigma0,
                            self.thickness)

    def model(self):
        """The quarter model (symmetry on x = 0 and y = 0, outer edges clamped) and the
        initial velocity field (V0 everywhere but on the clamped edges)."""
        mesh = plate_mesh(2.0 * self.half_side, self.half_side / self.elements, quarter=True)
        bc = BoundaryConditions(mesh.n_nodes)
        bc.symmetry(mesh.node_sets["symmetry_x"], 0).symmetry(mesh.node_sets["symmetry_y"], 1)
        edge = mesh.node_sets["edge_outer"]
        bc.fix(edge)
        sec = Section(self.material, thickness=self.thickness, points=self.points)
        model = build_model(mesh.nodes, mesh.quads, {"plate": sec},
                            np.zeros(mesh.n_elems, int), bcs=bc)
        velocity = np.zeros((mesh.n_nodes, 3))
        velocity[:, 2] = -self.speed
        velocity[edge] = 0.0
        return model, velocity, int(mesh.node_sets["centre"][0])

    def run(self) -> dict:
        """Run to ``end_time``; the mid-point deflection history, the permanent and
        the largest deflection over H, the theory's band and the energy balance."""
        model, velocity, centre = self.model()
        state = initial_state(model, velocity=velocity)
        ws = Workspace.for_model(model, state)
        times, defl = [0.0], [0.0]
        max_error = 0.0
        while state.t < self.end_time:
            step(model, state, ws)
            times.append(state.t)
            defl.append(-(state.x[centre, 2] - model.x0[centre, 2]))
            if state.step % 50 == 0:
                max_error = max(max_error, energy_balance(model, state)["error_fraction"])
        eb = energy_balance(model, state)
        times, defl = np.array(times), np.array(defl)
        late = times >= (1.0 - self.settle_fraction) * self.end_time
        mode, impulse = jones_band(self.lam)
        return {
            "elements_per_half_side": self.elements, "points": self.points,
            "element_size_m": self.half_side / self.elements, "lambda": self.lam,
            "thickness_m": self.thickness,
            "time_s": times, "deflection_m": defl,
            "permanent_over_H": float(np.mean(defl[late]) / self.thickness),
            "max_over_H": float(np.max(defl) / self.thickness),
            "jones_mode_over_H": mode, "jones_impulse_over_H": impulse,
            "energy_error_fraction": max(max_error, eb["error_fraction"]),
            "steps": int(state.step), "energy_balance": eb,
            "plastic_work_J": plastic_work(model, state),
        }


def jones_study(elements=(8, 16, 32), out: str | Path | None = None, **kwargs) -> list[dict]:
    """The plate on three meshes; with ``out``, the figure of the mid-point deflection
    histories over H against Jones's band (docs/validation/jones_plate.png)."""
    results = [JonesPlate(elements=n, **kwargs).run() for n in elements]
    if out is not None:
        jones_figure(results, out)
    return results


def jones_figure(results: list[dict], path: str | Path) -> Path:
    """Mid-point deflection / H against time for each mesh and Jones's two limits."""
    from wovenimpact.io.atomic import save_png as _save
    from wovenimpact.io.plots import plt

    path = Path(path)
    fig, ax = plt.subplots(figsize=(7.0, 4.2))
    r0 = results[0]
    ax.axhspan(r0["jones_mode_over_H"], r0["jones_impulse_over_H"], color="0.88",
               label=f"Jones's pyramid, λ = {r0['lambda']:.0f}: from V0 at the mid-point "
                     f"({r0['jones_mode_over_H']:.2f} H) to the whole impulse's energy "
                     f"({r0['jones_impulse_over_H']:.2f} H)")
    for r in results:
        ax.plot(r["time_s"] * 1e6, r["deflection_m"] / r["thickness_m"],
                label=f"{r['elements_per_half_side']} el. per half side: permanent "
                      f"{r['permanent_over_H']:.3f} H")
    ax.set_xlabel("time (µs)")
    ax.set_ylabel("mid-point deflection / H")
    ax.set_title("Fully clamped square plate, uniform impulsive velocity (quarter model)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    _save(fig, path)
    return path
