"""Single-element tests of the crossover model (thesis ch. 6.3; docs/theory.md §2).

One unit cell of side 2ℓ0 is driven through a prescribed in-plane deformation
history; the material kernel is called exactly as the shell element will call
it (F_old → F_new per step). Tests:

- ``uniaxial``: warp edge displaced by u (λ_w = 1 + u / 2ℓ_w0), fill length held
  (the thesis's test: the fill picks up tension through crimp interchange);
- ``uniaxial-free``: the same with the fill edges free of force (λ_f solved so
  that N_yy = 0, the largest such λ_f, i.e. the cell contracts only as needed);
- ``biaxial``: both edges displaced by u;
- ``shear``: simple shear F = [[1, κ], [0, 1]], κ = tan γ_max · s — the fill yarn
  rotates *and* stretches, the test that separates the fibre and Green–Naghdi frames;
- ``picture-frame``: pure trellis shear, yarns inextensible, the angle between
  them closing from 90° to 90° − γ_max.

External work per unit reference area is integrated with the trapezoidal rule
on the first Piola resultant P = J N F⁻ᵀ, W = Σ ½ (P_n + P_{n+1}) : ΔF, and
compared with the stored energy of the model. Instant yarn failure is located
by bisection on the load parameter, so the failure displacement is found to
round-off and the peak tension equals T_u.
"""

from __future__ import annotations

import csv
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from wovenimpact.kernels import fabric_layout as L
from wovenimpact.materials.fabric import FabricParameters, PointUpdate, initial_state, update_points

TESTS = ("uniaxial", "uniaxial-free", "biaxial", "shear", "picture-frame")
SHEAR_TESTS = ("shear", "picture-frame")
DEFAULT_DISPLACEMENT_M = 0.06e-3
DEFAULT_ANGLE_RAD = math.radians(60.0)

#: history columns: name (with unit) and a one-line meaning, in file order
COLUMNS = {
    "load_parameter": "fraction of the prescribed history, 0 to 1",
    "displacement_m": "edge displacement (shear tests: tangential edge displacement "
    "for simple shear, change of the cell diagonal for picture frame)",
    "stretch_w": "in-plane stretch λ_w of the warp",
    "stretch_f": "in-plane stretch λ_f of the fill",
    "shear_angle_deg": "trellis shear angle γ = 90° − θ",
    "tension_w_N": "warp yarn tension T_w",
    "tension_f_N": "fill yarn tension T_f",
    "height_w_m": "warp crimp height H_w",
    "height_f_m": "fill crimp height H_f",
    "N_xx_N_per_m": "membrane stress resultant N_xx (force per current length)",
    "N_yy_N_per_m": "membrane stress resultant N_yy",
    "N_xy_N_per_m": "membrane stress resultant N_xy",
    "shear_stress_Pa": "trellis shear stress τ",
    "damage_w": "warp damage d_w",
    "damage_f": "fill damage d_f",
    "alive": "1 while the point is not eroded",
    "stored_energy_J_per_m2": "stored energy per unit reference area (yarns, compaction, shear)",
    "external_work_J_per_m2": "external work per unit reference area",
    "iterations": "iterations of the crimp-height solve in this step",
}


@dataclass
class ElementTestResult:
    """History and headline figures of one single-element test."""

    test: str
    history: dict[str, np.ndarray]
    failure_displacement_m: float | None
    failure_load_parameter: float | None
    options: dict[str, object] = field(default_factory=dict)

    def _before_failure(self) -> np.ndarray:
        s = self.history["load_parameter"]
        if self.failure_load_parameter is None:
            return np.ones(s.size, dtype=bool)
        d = self.history["damage_w"] + self.history["damage_f"]
        return d == 0.0

    @property
    def energy_error_fraction(self) -> float:
        """max |W − U| / max W over the history before the first yarn failure."""
        mask = self._before_failure()
        w = self.history["external_work_J_per_m2"][mask]
        u = self.history["stored_energy_J_per_m2"][mask]
        scale = np.max(np.abs(w)) if w.size else 0.0
        if scale == 0.0:
            return 0.0
        return float(np.max(np.abs(w - u)) / scale)

    def summary(self) -> dict[str, object]:
        h = self.history
        it = h["iterations"][1:]
        return {
            "test": self.test,
            "failure_displacement_m": self.failure_displacement_m,
            "max_tension_w_N": float(np.max(h["tension_w_N"])),
            "max_tension_f_N": float(np.max(h["tension_f_N"])),
            "final_height_w_m": float(h["height_w_m"][-1]),
            "final_height_f_m": float(h["height_f_m"][-1]),
            "final_displacement_m": float(h["displacement_m"][-1]),
            "max_shear_angle_deg": float(np.max(np.abs(h["shear_angle_deg"]))),
            "energy_error_fraction": self.energy_error_fraction,
            "iterations_mean": float(np.mean(it)) if it.size else 0.0,
            "iterations_max": int(np.max(it)) if it.size else 0,
            "steps": int(h["load_parameter"].size - 1),
            **{f"option_{k}": v for k, v in self.options.items()},
        }


# --- prescribed histories --------------------------------------------------------
def deformation_history(
    params: FabricParameters, test: str, amplitude: float | None = None
) -> tuple[Callable[[float], np.ndarray], Callable[[np.ndarray], float]]:
    """F(s) for s ∈ [0, 1] and the displacement measure of F for one test.

    ``amplitude`` is the edge displacement (m) for the extension tests and the
    shear angle (rad) for the shear tests.
    """
    if test not in TESTS:
        raise ValueError(f"test = {test!r} is not valid: choose one of {', '.join(TESTS)}")
    side_w = 2.0 * params.warp.half_length
    side_f = 2.0 * params.fill.half_length
    if test in SHEAR_TESTS:
        ang = DEFAULT_ANGLE_RAD if amplitude is None else amplitude
        if not 0.0 < ang < 0.5 * math.pi:
            raise ValueError(f"shear angle = {math.degrees(ang)}° is not valid: give 0° < γ < 90°")
        if test == "shear":
            kappa_max = math.tan(ang)
            return (
                lambda s: np.array([[1.0, kappa_max * s], [0.0, 1.0]]),
                lambda f: f[0, 1] * side_f,
            )
        diag0 = math.sqrt(2.0)

        def frame(s: float) -> np.ndarray:
            half = 0.5 * ang * s
            c, sn = math.cos(half), math.sin(half)
            return np.array([[c, sn], [sn, c]])

        return frame, lambda f: side_w * (math.hypot(f[0, 0] + f[0, 1], f[1, 0] + f[1, 1]) - diag0)

    u_max = DEFAULT_DISPLACEMENT_M if amplitude is None else amplitude
    if not u_max > 0.0:
        raise ValueError(f"displacement = {u_max} m is not valid: it must be > 0")
    if test == "biaxial":
        return (
            lambda s: np.diag([1.0 + u_max * s / side_w, 1.0 + u_max * s / side_f]),
            lambda f: (f[0, 0] - 1.0) * side_w,
        )
    # uniaxial and uniaxial-free: the fill stretch of uniaxial-free is solved in the driver
    return lambda s: np.diag([1.0 + u_max * s / side_w, 1.0]), lambda f: (f[0, 0] - 1.0) * side_w


def _free_fill_stretch(
    p: np.ndarray, params: FabricParameters, f_prev: np.ndarray, f_trial: np.ndarray, state
) -> np.ndarray:
    """Largest λ_f ≤ the previous one with N_yy = 0 (fill edges free), by bisection."""

    def n_yy(lam: float) -> float:
        f = f_trial.copy()
        f[1, 1] = lam
        return update_points(p, f_prev, f, state).resultant[0, 1]

    hi = f_prev[1, 1]
    f = f_trial.copy()
    f[1, 1] = hi
    if n_yy(hi) <= 0.0:
        return f
    s_total = params.warp.h0 + params.fill.h0
    lt0 = params.fill.truss_length
    lo = math.sqrt(max(lt0 * lt0 - s_total * s_total, 0.0)) / params.fill.half_length
    if n_yy(lo) > 0.0:  # cannot happen for an admissible state; keep the guard honest
        raise RuntimeError("uniaxial-free: no fill stretch makes the fill edge force vanish")
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if mid <= lo or mid >= hi:
            break
        if n_yy(mid) > 0.0:
            hi = mid
        else:
            lo = mid
    f[1, 1] = lo
    return f


def _piola(f: np.ndarray, resultant: np.ndarray) -> np.ndarray:
    """First Piola resultant P = J N F⁻ᵀ (force per unit reference length)."""
    n = np.array([[resultant[0], resultant[2]], [resultant[2], resultant[1]]])
    return np.linalg.det(f) * n @ np.linalg.inv(f).T


def run_element_test(
    params: FabricParameters,
    test: str,
    amplitude: float | None = None,
    n_steps: int = 600,
) -> ElementTestResult:
    """Drive one unit cell through a test history and record everything.

    Args:
        params: material parameters (options included).
        test: one of :data:`TESTS`.
        amplitude: edge displacement in m (extension tests) or shear angle in rad
            (shear tests); defaults 0.06 mm and 60°.
        n_steps: number of equal load steps.
    """
    if n_steps < 1:
        raise ValueError(f"steps = {n_steps} is not valid: it must be ≥ 1")
    p = params.to_array()
    f_of_s, displacement = deformation_history(params, test, amplitude)
    free_fill = test == "uniaxial-free"
    instant = params.options.failure == "instant"

    def trial(state: np.ndarray, f_prev: np.ndarray, s: float) -> tuple[np.ndarray, PointUpdate]:
        f = f_of_s(s)
        if free_fill:
            f = _free_fill_stretch(p, params, f_prev, f, state)
        return f, update_points(p, f_prev, f, state)

    rows: list[list[float]] = []
    state = initial_state(params)[0]
    f_prev = f_of_s(0.0)
    p_prev = np.zeros((2, 2))
    work = 0.0

    def record(s: float, f: np.ndarray, upd: PointUpdate) -> None:
        st, n = upd.state[0], upd.resultant[0]
        rows.append(
            [
                s,
                displacement(f),
                st[L.S_LAMBDA],
                st[L.S_LAMBDA + 1],
                math.degrees(st[L.S_GAMMA]),
                st[L.S_TENSION],
                st[L.S_TENSION + 1],
                st[L.S_H],
                st[L.S_H + 1],
                n[0],
                n[1],
                n[2],
                st[L.S_TAU],
                st[L.S_DAMAGE],
                st[L.S_DAMAGE + 1],
                st[L.S_ALIVE],
                st[L.S_ENERGY],
                work,
                st[L.S_ITER],
            ]
        )

    def accept(s: float, f: np.ndarray, upd: PointUpdate) -> None:
        nonlocal state, f_prev, p_prev, work
        p_new = _piola(f, upd.resultant[0])
        work += 0.5 * float(np.sum((p_prev + p_new) * (f - f_prev)))
        state, f_prev, p_prev = upd.state[0], f, p_new
        record(s, f, upd)

    record(0.0, f_prev, update_points(p, f_prev, f_prev, state))
    failure_s: float | None = None
    failure_u: float | None = None
    s_prev = 0.0
    for k in range(1, n_steps + 1):
        s_new = k / n_steps
        f_new, upd = trial(state, f_prev, s_new)
        broke = np.any(upd.state[0, L.S_DAMAGE : L.S_DAMAGE + 2] > state[L.S_DAMAGE : L.S_DAMAGE + 2])
        if broke and instant and failure_s is None:
            # locate the load at which the first yarn reaches T_u (bisection to round-off)
            lo, hi = s_prev, s_new
            for _ in range(200):
                mid = 0.5 * (lo + hi)
                if mid <= lo or mid >= hi:
                    break
                _, u_mid = trial(state, f_prev, mid)
                d_old = state[L.S_DAMAGE : L.S_DAMAGE + 2]
                if np.any(u_mid.state[0, L.S_DAMAGE : L.S_DAMAGE + 2] > d_old):
                    hi = mid
                else:
                    lo = mid
            if lo > s_prev:
                f_lo, u_lo = trial(state, f_prev, lo)
                accept(lo, f_lo, u_lo)
            failure_s, failure_u = lo, displacement(f_prev)
            f_new, upd = trial(state, f_prev, s_new)
        elif broke and failure_s is None:
            failure_s, failure_u = s_new, displacement(f_new)
        accept(s_new, f_new, upd)
        s_prev = s_new

    history = {name: np.array([r[j] for r in rows]) for j, name in enumerate(COLUMNS)}
    o = params.options
    return ElementTestResult(
        test=test,
        history=history,
        failure_displacement_m=failure_u,
        failure_load_parameter=failure_s,
        options={
            "homogenisation": o.homogenisation,
            "shear": o.shear,
            "frame": o.frame,
            "failure": o.failure,
        },
    )


# --- files -------------------------------------------------------------------------
def write_history_csv(result: ElementTestResult, path: Path, columns=COLUMNS) -> Path:
    """Write the history's ``columns`` as CSV (column names carry units); atomic replace.
    The metal element test (calibration.metal_element) writes its own columns with it."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_suffix(path.suffix + ".tmp")
    names = list(columns)
    with open(tmp, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(names)
        for i in range(result.history[names[0]].size):
            w.writerow([repr(float(result.history[n][i])) for n in names])
    tmp.replace(path)
    return path


def read_history_csv(path: Path) -> dict[str, np.ndarray]:
    """Read a history written by :func:`write_history_csv`."""
    with open(path, newline="") as fh:
        r = csv.reader(fh)
        names = next(r)
        data = np.array([[float(x) for x in row] for row in r])
    return {n: data[:, j] for j, n in enumerate(names)}


@dataclass
class PathResult:
    """States along an arbitrary deformation path (see :func:`drive_path`)."""

    work: np.ndarray  # (n,) external work per unit reference area (J/m²)
    energy: np.ndarray  # (n,) stored energy per unit reference area (J/m²)
    states: np.ndarray  # (n, N_STATE)
    resultants: np.ndarray  # (n, 3) N_xx, N_yy, N_xy (N/m)


def drive_path(params: FabricParameters, path: np.ndarray) -> PathResult:
    """Drive one point along ``path`` (n, 2, 2), path[0] the start; trapezoidal work.

    The building block of load–unload cycle checks: for a conservative
    (hyperelastic) option set, ``work − energy`` is the quadrature error only.
    """
    p = params.to_array()
    n = path.shape[0]
    states = np.empty((n, L.N_STATE))
    res = np.empty((n, 3))
    work = np.zeros(n)
    upd = update_points(p, path[0], path[0], initial_state(params)[0])
    states[0], res[0] = upd.state[0], upd.resultant[0]
    p_prev = _piola(path[0], res[0])
    for k in range(1, n):
        upd = update_points(p, path[k - 1], path[k], states[k - 1])
        states[k], res[k] = upd.state[0], upd.resultant[0]
        p_new = _piola(path[k], res[k])
        work[k] = work[k - 1] + 0.5 * float(np.sum((p_prev + p_new) * (path[k] - path[k - 1])))
        p_prev = p_new
    return PathResult(work=work, energy=states[:, L.S_ENERGY].copy(), states=states, resultants=res)
