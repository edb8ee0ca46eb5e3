"""Single-element tests of the J2 metal model (docs/theory.md, "Metal shells").

One material point of a metal shell (reference thickness t0) is driven through a
prescribed in-plane history; the kernel is called exactly as the shell will call
it (F_old → F_new over Δt per step). Tests:

- ``uniaxial``: plane-stress uniaxial tension, F = diag(e^ε, λ_y) with the lateral
  stretch λ_y solved (Brent, to round-off) so that the lateral resultant N_yy is 0;
- ``biaxial``: equibiaxial tension F = diag(e^ε, e^ε);
- ``shear``: simple shear F = [[1, γ], [0, 1]].

Each runs at a constant strain rate (Δt = Δ(strain) / rate) until the point fails
or the history ends. The failure is located by bisection on the load parameter,
so the failure plastic strain equals the fracture strain (or D = 1) to round-off.
External work per unit reference area is the trapezoidal rule on the first Piola
resultant P = J N F⁻ᵀ, compared with the kernel's stored elastic energy + plastic
work + energy released at failure.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from wovenimpact.calibration import single_element
from wovenimpact.kernels import j2_layout as L
from wovenimpact.materials.metal import (
    MetalParameters,
    PointUpdate,
    initial_state,
    j2_parameter_row,
    update_points,
)

METAL_TESTS = ("uniaxial", "biaxial", "shear")
DEFAULT_STRAIN = {"uniaxial": 0.4, "biaxial": 0.25, "shear": 1.0}  # log strain; γ for shear
DEFAULT_STRAIN_RATE = 1e-3  # 1/s: quasi-static
DEFAULT_THICKNESS_M = 1e-3
ELEMENT_SIDE_M = 1e-3  # reference side of the element whose edge displacement is reported

#: history columns: name (with unit) and a one-line meaning, in file order
COLUMNS = {
    "load_parameter": "fraction of the prescribed history, 0 to 1",
    "strain": "applied strain: log strain ln F_xx (uniaxial, biaxial) or shear γ = F_xy",
    "F_xx": "deformation gradient F_xx",
    "F_yy": "deformation gradient F_yy (uniaxial: solved for N_yy = 0)",
    "F_xy": "deformation gradient F_xy",
    "stress_xx_Pa": "Cauchy stress σ_xx = N_xx / t (corotational frame)",
    "stress_yy_Pa": "Cauchy stress σ_yy",
    "stress_xy_Pa": "Cauchy stress σ_xy",
    "equivalent_stress_Pa": "von Mises equivalent of the Cauchy stress",
    "kirchhoff_equivalent_Pa": "von Mises equivalent of the Kirchhoff stress τ = Jσ (the "
    "return's variable: equals the flow stress while yielding)",
    "plastic_strain": "equivalent plastic strain ε̄p",
    "flow_stress_Pa": "flow stress σ_y of the point (table × rate factor)",
    "table_stress_Pa": "the file's hardening table at ε̄p (no rate factor)",
    "plastic_strain_rate_per_s": "equivalent plastic strain rate ε̇p of the step",
    "thickness_stretch": "λ3 = t / t0",
    "triaxiality": "η = σ_m / σ_eq",
    "damage": "Johnson–Cook damage D",
    "softening_damage": "damage D_e after the onset of failure (stress × (1 − D_e))",
    "alive": "1 until the point fails",
    "stored_energy_J_per_m2": "elastic stored energy per unit reference area",
    "plastic_work_J_per_m2": "plastic work per unit reference area",
    "failure_energy_J_per_m2": "elastic energy released at failure per unit reference area",
    "external_work_J_per_m2": "external work per unit reference area",
    "iterations": "iterations of the plane-stress return in this step",
}


@dataclass
class MetalElementTestResult:
    """History and headline figures of one metal single-element test."""

    test: str
    history: dict[str, np.ndarray]
    thickness: float
    strain_rate: float
    failure_load_parameter: float | None
    failure_plastic_strain: float | None
    failure_strain: float | None
    params: MetalParameters
    options: dict[str, object] = field(default_factory=dict)

    @property
    def energy_error_fraction(self) -> float:
        """max |W − (W_e + W_p)| / max W before failure (the failing step's work is the
        trapezoid of a stress that drops to zero within it: not a measure of the kernel)."""
        h = self.history
        alive = h["alive"] > 0.0
        w = h["external_work_J_per_m2"][alive]
        u = (h["stored_energy_J_per_m2"] + h["plastic_work_J_per_m2"])[alive]
        scale = np.max(np.abs(w)) if w.size else 0.0
        return float(np.max(np.abs(w - u)) / scale) if scale > 0.0 else 0.0

    @property
    def table_error_max(self) -> float:
        """max |τ_eq − σ_table(ε̄p) R(ε̇p)| / (σ_table R) over the yielding, alive states:
        the return against the file's table (and rate factor), evaluated here in NumPy."""
        h = self.history
        yielding = (np.diff(h["plastic_strain"], prepend=0.0) > 0.0) & (h["alive"] > 0.0)
        if not np.any(yielding):
            return 0.0
        ref = h["table_stress_Pa"] * rate_factor(self.params, h["plastic_strain_rate_per_s"])
        err = np.abs(h["kirchhoff_equivalent_Pa"] - ref) / ref
        return float(np.max(err[yielding]))

    def summary(self) -> dict[str, object]:
        h = self.history
        it = h["iterations"][1:]
        alive = h["alive"] > 0.0
        strain_fail = self.failure_strain
        disp = None
        if strain_fail is not None:
            grow = strain_fail if self.test == "shear" else math.expm1(strain_fail)
            disp = ELEMENT_SIDE_M * grow
        return {
            "test": self.test,
            "material": self.params.name,
            "max_stress_Pa": float(np.max(h["equivalent_stress_Pa"])),  # Cauchy, von Mises
            "max_kirchhoff_stress_Pa": float(np.max(h["kirchhoff_equivalent_Pa"])),
            "failure_plastic_strain": self.failure_plastic_strain,
            "failure_strain": strain_fail,
            "failure_displacement_m": disp,
            "plastic_work_J_per_m3": float(h["plastic_work_J_per_m2"][-1] / self.thickness),
            "final_plastic_strain": float(np.max(h["plastic_strain"])),
            "final_strain": float(h["strain"][-1]),
            "final_thickness_stretch": float(h["thickness_stretch"][alive][-1]),
            "table_error_max": self.table_error_max,
            "energy_error_fraction": self.energy_error_fraction,
            "strain_rate_per_s": self.strain_rate,
            "thickness_m": self.thickness,
            "element_side_m": ELEMENT_SIDE_M,
            "iterations_mean": float(np.mean(it)) if it.size else 0.0,
            "iterations_max": int(np.max(it)) if it.size else 0,
            "steps": int(h["load_parameter"].size - 1),
        }


def rate_factor(params: MetalParameters, rate: np.ndarray) -> np.ndarray:
    """1 + C ln(ε̇p/ε̇0) for ε̇p > ε̇0, else 1 (NumPy; the kernel's eq. J9)."""
    rate = np.asarray(rate, dtype=float)
    if params.rate is None:
        return np.ones_like(rate)
    r = rate / params.rate.reference_rate
    with np.errstate(divide="ignore"):
        return np.where(r > 1.0, 1.0 + params.rate.c * np.log(np.maximum(r, 1.0)), 1.0)


def piola(f: np.ndarray, resultant: np.ndarray) -> np.ndarray:
    """First Piola resultant P = J N F⁻ᵀ (force per unit reference length)."""
    n = np.array([[resultant[0], resultant[2]], [resultant[2], resultant[1]]])
    return np.linalg.det(f) * n @ np.linalg.inv(f).T


def _gradient(test: str, strain: float, lateral: float) -> np.ndarray:
    if test == "shear":
        return np.array([[1.0, strain], [0.0, 1.0]])
    stretch = math.exp(strain)
    return np.diag([stretch, stretch if test == "biaxial" else lateral])


class MetalPointDriver:
    """State of one test run: the point, its F, and the accepted history."""

    def __init__(self, params, test, strain_max, rate, thickness, element_length=None):
        self.params, self.test, self.strain_max = params, test, strain_max
        self.rate, self.t0 = rate, thickness
        self.p = j2_parameter_row(params)
        self.p_intact = self.p.copy()  # the same material without its failure criteria
        self.p_intact[L.P_FRACTURE] = 0.0
        self.p_intact[L.P_DAMAGE] = 0.0
        self.state = initial_state(
            params, lengths=None if element_length is None else [element_length])[0]
        self.f = np.eye(2)
        self.piola = np.zeros((2, 2))
        self.work = 0.0
        self.s = 0.0
        self.rows: list[list[float]] = []

    def trial(self, s_new: float) -> tuple[np.ndarray, PointUpdate]:
        """F and the point update at load parameter s_new from the accepted state."""
        d_strain = (s_new - self.s) * self.strain_max
        dt = abs(d_strain) / self.rate
        strain = s_new * self.strain_max

        def update(lateral: float, p: np.ndarray) -> tuple[np.ndarray, PointUpdate]:
            f = _gradient(self.test, strain, lateral)
            return f, update_points(p, self.f, f, self.state, dt, self.t0)

        if self.test != "uniaxial" or self.state[L.S_ALIVE] == 0.0:
            return update(self.f[1, 1], self.p)
        lam0 = self.f[1, 1]
        width = max(abs(d_strain), 1e-12)

        def n_yy(lam: float) -> float:
            # without the failure criteria: N_yy is then continuous and increasing in λ_y
            return update(lam, self.p_intact)[1].resultant[0, 1]

        lo, hi = lam0 * math.exp(-width), lam0 * math.exp(width)
        for _ in range(60):
            if n_yy(lo) <= 0.0 <= n_yy(hi):
                break
            lo, hi = lo * math.exp(-width), hi * math.exp(width)
        lam = brentq(n_yy, lo, hi, xtol=1e-16, rtol=8.9e-16, maxiter=200)
        return update(lam, self.p)

    def record(self, s: float, f: np.ndarray, upd: PointUpdate) -> None:
        st, n = upd.state[0], upd.resultant[0]
        t = self.t0 * st[L.S_THICK]
        sxx, syy, sxy = n[0] / t, n[1] / t, n[2] / t
        seq = math.sqrt(max(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy, 0.0))
        txx, tyy, txy = st[L.S_KIRCHHOFF : L.S_KIRCHHOFF + 3]
        teq = math.sqrt(max(txx * txx - txx * tyy + tyy * tyy + 3.0 * txy * txy, 0.0))
        strain = s * self.strain_max
        self.rows.append([
            s, strain, f[0, 0], f[1, 1], f[0, 1], sxx, syy, sxy, seq, teq,
            st[L.S_EPS_P], st[L.S_YIELD], float(self.params.flow_stress(st[L.S_EPS_P])),
            st[L.S_RATE], st[L.S_THICK], (sxx + syy) / (3.0 * seq) if seq > 0.0 else 0.0,
            st[L.S_JC_DAMAGE], st[L.S_SOFT_DAMAGE], st[L.S_ALIVE], st[L.S_ENERGY], st[L.S_PLASTIC_WORK],
            st[L.S_FAIL_ENERGY], self.work, st[L.S_RETURN_ITER],
        ])

    def accept(self, s: float, f: np.ndarray, upd: PointUpdate) -> None:
        p_new = piola(f, upd.resultant[0])
        self.work += 0.5 * float(np.sum((self.piola + p_new) * (f - self.f)))
        self.state, self.f, self.piola, self.s = upd.state[0], f, p_new, s
        self.record(s, f, upd)


def run_metal_element_test(
    params: MetalParameters,
    test: str,
    strain: float | None = None,
    n_steps: int = 400,
    strain_rate: float = DEFAULT_STRAIN_RATE,
    thickness: float = DEFAULT_THICKNESS_M,
    element_length: float | None = None,
) -> MetalElementTestResult:
    """Drive one J2 point through a test history to failure (or the end); record everything.

    Args:
        params: a ``j2_plastic`` material.
        test: one of :data:`METAL_TESTS`.
        strain: final log strain (uniaxial, biaxial) or shear γ; default per test.
        n_steps: number of equal load steps.
        strain_rate: rate of the applied strain (1/s); sets Δt of every step.
        thickness: reference thickness t0 (m).
        element_length: l_e = √A0 of the element the point stands for (m), for a
            material with a [material.regularisation]; None: its reference length.
    """
    if test not in METAL_TESTS:
        raise ValueError(f"test = {test!r} is not valid for a metal: choose one of "
                         f"{', '.join(METAL_TESTS)}")
    if params.kind != "j2_plastic":
        raise ValueError(
            f"material {params.name!r} is {params.kind}: element tests need j2_plastic"
        )
    if n_steps < 1:
        raise ValueError(f"steps = {n_steps} is not valid: it must be ≥ 1")
    strain_max = DEFAULT_STRAIN[test] if strain is None else strain
    if not strain_max > 0.0:
        raise ValueError(f"strain = {strain_max} is not valid: it must be > 0")
    if not strain_rate > 0.0:
        raise ValueError(f"strain rate = {strain_rate} 1/s is not valid: it must be > 0")
    drv = MetalPointDriver(params, test, strain_max, strain_rate, thickness, element_length)
    drv.record(0.0, drv.f, update_points(drv.p, drv.f, drv.f, drv.state, 0.0, thickness))
    fail_s = fail_eps = None
    for k in range(1, n_steps + 1):
        s_new = k / n_steps
        f_new, upd = drv.trial(s_new)
        if upd.state[0, L.S_ALIVE] == 0.0:
            # locate the load at which the point fails (bisection to round-off)
            lo, hi = drv.s, s_new
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                if drv.trial(mid)[1].state[0, L.S_ALIVE] == 0.0:
                    hi = mid
                else:
                    lo = mid
            if lo > drv.s:
                drv.accept(lo, *drv.trial(lo))
                f_new, upd = drv.trial(s_new)  # the rest of the step, from just before failure
            if upd.state[0, L.S_ALIVE] == 0.0:
                fail_s, fail_eps = lo, float(drv.state[L.S_EPS_P])
                drv.accept(s_new, f_new, upd)
                break
        drv.accept(s_new, f_new, upd)
    history = {name: np.array([r[j] for r in drv.rows]) for j, name in enumerate(COLUMNS)}
    return MetalElementTestResult(
        test=test,
        history=history,
        thickness=thickness,
        strain_rate=strain_rate,
        failure_load_parameter=fail_s,
        failure_plastic_strain=fail_eps,
        failure_strain=None if fail_s is None else fail_s * strain_max,
        params=params,
        options={"material": params.name},
    )


def write_history_csv(result: MetalElementTestResult, path: Path) -> Path:
    """Write the history as CSV (column names carry units); atomic replace."""
    return single_element.write_history_csv(result, path, COLUMNS)


read_history_csv = single_element.read_history_csv
