"""SI parameter set of the metals: J2 plasticity (blade, casing) and elastic (impactor).

docs/model.md §5; thesis 7.1.2 (Table 7-1, steel impactor), 8.2.3 (Table 8-1, titanium
blade), 8.3.1 (Table 8-2, aluminium casing). Plane-stress J2 with a piecewise-linear
isotropic hardening table; a point fails when its equivalent plastic strain reaches
``fracture_strain``, or, with a Johnson–Cook damage set, when its damage reaches 1.
Optional Johnson–Cook rate factor 1 + C ln(ε̇p/ε̇0). Temperature is not modelled
(T* = 0: the thermal factors of Johnson–Cook are 1). The kernel is
:mod:`wovenimpact.kernels.j2`; the parameter vector's layout is
:mod:`wovenimpact.kernels.j2_layout`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from wovenimpact.kernels import j2_layout as L


@dataclass(frozen=True)
class RateParameters:
    """Johnson–Cook rate factor 1 + C ln(ε̇p/ε̇0) for ε̇p > ε̇0 (1 below).

    Attributes:
        c: C (—), ≥ 0.
        reference_rate: ε̇0 (1/s), > 0.
    """

    c: float
    reference_rate: float


@dataclass(frozen=True)
class DamageParameters:
    """Johnson–Cook fracture strain ε_f = (D1 + D2 e^{D3 η})(1 + D4 ln ε̇*)(1 + D5 T*).

    ε̇* = max(ε̇p/ε̇0, 1); T* = 0 here (temperature not modelled), so D5 is kept for
    the record only. Damage D = Σ Δε̄p / ε_f; the point fails at D ≥ 1.

    Attributes:
        d: (D1, D2, D3, D4, D5).
        reference_rate: ε̇0 of the rate term (1/s).
    """

    d: tuple[float, float, float, float, float]
    reference_rate: float

    def fracture_strain(self, triaxiality: float, rate_ratio: float = 1.0) -> float:
        """ε_f(η, ε̇*) (T* = 0)."""
        d1, d2, d3, d4, _ = self.d
        return (d1 + d2 * math.exp(d3 * triaxiality)) * (
            1.0 + d4 * math.log(max(rate_ratio, 1.0))
        )


@dataclass(frozen=True)
class FractureRegularisation:
    """Element-size regularisation of fracture (theory §7.3; LS-DYNA *MAT_224 LCI, GISSMO
    LCREGD, OpenRadioss /FAIL/INIEVO). Each point knows its element's length l_e = √A0.

    Attributes:
        reference_length: l_ref (m), the element length at which the fracture strain
            (constant or Johnson–Cook) holds as given (0: none; the scale table and
            the softening need one).
        fracture_scale: rows (l_e/l_ref, s): the point's fracture strain is s ε_f, s
            piecewise linear in l_e/l_ref, flat beyond the first and last rows, s = 1 at
            l_ref; empty: s = 1.
        failure_displacement: ū_f (m): after the onset of failure the damage D_e grows by
            l_e Δε̄p/ū_f and the stress is (1 − D_e) times the undamaged one, so that the
            work of the softening per unit crack area does not depend on l_e; the point
            fails at D_e = 1. 0: it fails at onset.
        hinge_ratio: l_h/t, the width over which a fold of the sheet bends, in the
            section's thicknesses t: an element longer than l_h bends over its whole
            length what the sheet bends over l_h, so the bending part of a point's
            plastic strain counts x_b = l_e/l_h times when fracture is judged (theory
            §7.3, "Folds"). 0: none.
    """

    reference_length: float = 0.0
    fracture_scale: tuple[tuple[float, float], ...] = ()
    failure_displacement: float = 0.0
    hinge_ratio: float = 0.0


@dataclass(frozen=True)
class MetalParameters:
    """Validated metal parameters (SI).

    Attributes:
        name: material name from the file.
        kind: ``"j2_plastic"`` or ``"elastic"``.
        density: ρ (kg/m³).
        modulus: Young's modulus E (Pa).
        poisson: ν (—), 0 ≤ ν < 0.5.
        hardening: ((ε_p, σ_y), ...) with ε_p (—) strictly increasing from 0 and σ_y
            (Pa) non-decreasing; one row = perfectly plastic; empty for ``"elastic"``.
        fracture_strain: equivalent plastic strain at failure (—), or None (no failure).
        rate: Johnson–Cook rate factor, or None (rate-independent).
        damage: Johnson–Cook damage, or None.
        regularisation: element-size regularisation of fracture, or None.
    """

    name: str
    kind: Literal["j2_plastic", "elastic"]
    density: float
    modulus: float
    poisson: float
    hardening: tuple[tuple[float, float], ...] = ()
    fracture_strain: float | None = None
    rate: RateParameters | None = None
    damage: DamageParameters | None = None
    regularisation: FractureRegularisation | None = None

    @property
    def shear_modulus(self) -> float:
        """G = E / (2 (1 + ν)) (Pa)."""
        return self.modulus / (2.0 * (1.0 + self.poisson))

    @property
    def plane_stress_wave_speed(self) -> float:
        """c = √(E / (ρ (1 − ν²))) (m/s), the plate wave speed used for the stable step."""
        return (self.modulus / (self.density * (1.0 - self.poisson**2))) ** 0.5

    def flow_stress(self, eps_p: float | np.ndarray) -> np.ndarray:
        """Table flow stress σ_h(ε̄p) (Pa): piecewise linear, flat beyond the last row."""
        e = np.array([r[0] for r in self.hardening])
        s = np.array([r[1] for r in self.hardening])
        return np.interp(eps_p, e, s)

    def to_array(self) -> np.ndarray:
        """Pack into the flat parameter vector read by :mod:`wovenimpact.kernels.j2`."""
        return j2_parameter_row(self)


def j2_parameter_row(params: MetalParameters) -> np.ndarray:
    """The J2 kernel's parameter vector (layout in :mod:`~wovenimpact.kernels.j2_layout`).

    Raises:
        ValueError: an elastic material (no hardening table), or a table longer than
            ``N_HARD_MAX`` rows.
    """
    if params.kind != "j2_plastic" or not params.hardening:
        raise ValueError(f"material {params.name!r}: a J2 row needs a j2_plastic material")
    n = len(params.hardening)
    if n > L.N_HARD_MAX:
        raise ValueError(
            f"material {params.name!r}: hardening table has {n} rows, at most {L.N_HARD_MAX}"
        )
    p = np.zeros(L.N_PARAM)
    p[L.P_YOUNG] = params.modulus
    p[L.P_NU] = params.poisson
    p[L.P_RHO] = params.density
    p[L.P_FRACTURE] = params.fracture_strain or 0.0
    if params.rate is not None:
        p[L.P_RATE_C] = params.rate.c
        p[L.P_RATE_REF] = params.rate.reference_rate
    if params.damage is not None:
        p[L.P_DAMAGE] = 1.0
        p[L.P_D : L.P_D + 5] = params.damage.d
        p[L.P_DAMAGE_REF] = params.damage.reference_rate
    p[L.P_N_HARD] = n
    for k, (e, s) in enumerate(params.hardening):
        p[L.P_HARD + 2 * k] = e
        p[L.P_HARD + 2 * k + 1] = s
    r = params.regularisation
    if r is not None:
        if len(r.fracture_scale) > L.FRAC_ROWS_MAX:
            raise ValueError(f"material {params.name!r}: fracture_scale has "
                             f"{len(r.fracture_scale)} rows, at most {L.FRAC_ROWS_MAX}")
        p[L.P_FRAC_LENGTH] = r.reference_length
        p[L.P_FAIL_DISP] = r.failure_displacement
        p[L.P_FRAC_ROWS] = len(r.fracture_scale)
        for k, (x, sc) in enumerate(r.fracture_scale):
            p[L.P_FRAC_TABLE + 2 * k] = x
            p[L.P_FRAC_TABLE + 2 * k + 1] = sc
        p[L.P_HINGE_RATIO] = r.hinge_ratio
    return p


# --- running the kernel on points ------------------------------------------------
def regularised_columns(p: np.ndarray, lengths: np.ndarray, thickness=0.0) -> np.ndarray:
    """Each point's S_FRAC_SCALE, S_EVOLUTION and S_HINGE from its element's length l_e
    = √A0 and its section's thickness t0 (theory §7.3).

    Args:
        p: the material's J2 parameter row (:func:`j2_parameter_row`).
        lengths: (n,) l_e (m); a length ≤ 0 stands for the reference length (a point
            without an element: the single-point drivers).
        thickness: t0 (m), scalar or (n,); ≤ 0: no fold law (x_b = 1).

    Returns:
        (n, 3): s (scale of the fracture strain), l_e/ū_f (0: failure at onset) and
        x_b = max(1, l_e/l_h) (1: no hinge length).
    """
    lengths = np.asarray(lengths, dtype=float).reshape(-1)
    l_ref = p[L.P_FRAC_LENGTH]
    out = np.zeros((len(lengths), 3))
    out[:, 0] = 1.0
    out[:, 2] = 1.0
    # the fold law needs no reference length; a point without an element is no fold
    hinge = p[L.P_HINGE_RATIO] * np.broadcast_to(np.asarray(thickness, dtype=float),
                                                 lengths.shape)
    folds = (hinge > 0.0) & (lengths > 0.0)
    out[folds, 2] = np.maximum(1.0, lengths[folds] / hinge[folds])
    if l_ref <= 0.0:
        return out
    le = np.where(lengths > 0.0, lengths, l_ref)
    n_rows = int(p[L.P_FRAC_ROWS])
    if n_rows:
        table = p[L.P_FRAC_TABLE:L.P_FRAC_TABLE + 2 * n_rows].reshape(n_rows, 2)
        out[:, 0] = np.interp(le / l_ref, table[:, 0], table[:, 1])
    if p[L.P_FAIL_DISP] > 0.0:
        out[:, 1] = le / p[L.P_FAIL_DISP]
    return out


def set_regularised_columns(state: np.ndarray, p: np.ndarray, lengths: np.ndarray,
                            thickness=0.0) -> None:
    """Write :func:`regularised_columns` into the state rows (n, N_STATE), in place."""
    cols = regularised_columns(p, lengths, thickness)
    state[:, L.S_FRAC_SCALE] = cols[:, 0]
    state[:, L.S_EVOLUTION] = cols[:, 1]
    state[:, L.S_HINGE] = cols[:, 2]


def initial_state(params: MetalParameters, n_points: int = 1,
                  lengths: np.ndarray | None = None, thickness: float = 0.0) -> np.ndarray:
    """States of ``n_points`` virgin points: no stress, λ3 = 1, alive, σ_y = σ_h(0); their
    fracture columns for elements of the given lengths l_e (None: the reference length,
    i.e. the fracture strain as given) and a section of thickness t0 (0: no fold law;
    theory §7.3)."""
    s = np.zeros((n_points, L.N_STATE))
    s[:, L.S_THICK] = 1.0
    s[:, L.S_ALIVE] = 1.0
    s[:, L.S_YIELD] = params.hardening[0][1]
    set_regularised_columns(s, j2_parameter_row(params),
                            np.zeros(n_points) if lengths is None else lengths, thickness)
    return s


@dataclass
class PointUpdate:
    """Result of :func:`update_points` (arrays over points)."""

    state: np.ndarray  # (n, N_STATE)
    resultant: np.ndarray  # (n, 3): N_xx, N_yy, N_xy (N/m)
    stiffness: np.ndarray  # (n,): tangent stiffness bound (N/m)


def update_points(
    p: np.ndarray,
    f_old: np.ndarray,
    f_new: np.ndarray,
    state: np.ndarray,
    dt: float,
    thickness: float,
) -> PointUpdate:
    """Advance J2 points from F_old to F_new over ``dt``; raise on any failed point.

    Args:
        p: parameter vector (:func:`j2_parameter_row`).
        f_old, f_new: (n, 2, 2) or (2, 2) deformation gradients.
        state: (n, N_STATE) or (N_STATE,) states at the start of the step.
        dt: the step (s); rates are Δε̄p/dt (dt ≤ 0: rate terms off).
        thickness: reference thickness t0 (m).

    Raises:
        MaterialPointError: naming the first failed point, why, and its input.
    """
    from wovenimpact.errors import MaterialPointError
    from wovenimpact.kernels.j2 import j2_update_for_points

    f_old = np.ascontiguousarray(np.asarray(f_old, dtype=np.float64).reshape(-1, 2, 2))
    f_new = np.ascontiguousarray(np.asarray(f_new, dtype=np.float64).reshape(-1, 2, 2))
    state_in = np.ascontiguousarray(np.asarray(state, dtype=np.float64).reshape(-1, L.N_STATE))
    n = f_new.shape[0]
    if f_old.shape[0] != n or state_in.shape[0] != n:
        raise ValueError(
            f"point counts differ: f_old {f_old.shape[0]}, f_new {n}, state {state_in.shape[0]}"
        )
    state_out = np.empty_like(state_in)
    res = np.empty((n, 3))
    stiff = np.empty(n)
    status = np.empty(n, dtype=np.int32)
    j2_update_for_points(
        np.ascontiguousarray(p, dtype=np.float64), f_old, f_new, float(dt), float(thickness),
        state_in, state_out, res, stiff, status,
    )
    bad = np.flatnonzero(status != L.STATUS_OK)
    if bad.size:
        i = int(bad[0])
        raise MaterialPointError(
            f"J2 point {i} of {n} ({bad.size} failed): {L.STATUS_TEXT[int(status[i])]}; "
            f"F_old = {f_old[i].tolist()}, F_new = {f_new[i].tolist()}, dt = {dt}, "
            f"state = {state_in[i].tolist()}"
        )
    return PointUpdate(state=state_out, resultant=res, stiffness=stiff)
