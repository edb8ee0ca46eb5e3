"""The fabric's parts and its material point: the yarn families, the model options and
the failure regularisation that :class:`~wovenimpact.materials.fabric.FabricParameters`
is made of, and :func:`initial_state` and :func:`update_points`, which run the kernel
(:mod:`wovenimpact.kernels.fabric`) on one point or a million and raise
:class:`MaterialPointError` naming the point and its state if any point fails.

:mod:`wovenimpact.materials.fabric` (the parameter set) and
:mod:`wovenimpact.materials.fabric_table` (the crossover table, built with the exact
point update) both import this module, which imports neither; the fabric's users import
these names from :mod:`wovenimpact.materials.fabric`. docs/theory.md §1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np

from wovenimpact.kernels import fabric_layout as L


@dataclass(frozen=True)
class YarnFamily:
    """One yarn family (warp or fill), SI units.

    Attributes:
        half_length: ℓ_i0 = 1/(2 n_j), in-plane half-length between crossings (m).
        crimp: c_i, yarn length / fabric length − 1.
        h0: crimp amplitude from eq. (5.5) (m).
        area: A_i, yarn cross-section (m²).
        modulus: E_i, yarn axial modulus (Pa).
        ultimate_tension: T_ui (N).
        width: b_i, yarn width (m).
        thickness: t_i, yarn thickness (m).
    """

    half_length: float
    crimp: float
    h0: float
    area: float
    modulus: float
    ultimate_tension: float
    width: float
    thickness: float

    @property
    def truss_length(self) -> float:
        """L_i0 = √(ℓ_i0² + h_i0²), initial half-truss length (eq. 6.18)."""
        return math.hypot(self.half_length, self.h0)


@dataclass(frozen=True)
class FabricOptions:
    """Model variants (docs/model.md §1.4–1.7; docs/theory.md §1.8)."""

    homogenisation: Literal["virial", "thesis"] = "virial"
    shear: Literal["true", "thesis"] = "true"
    frame: Literal["fibre", "green-naghdi"] = "fibre"
    failure: Literal["instant", "progressive"] = "instant"
    softening_strain: float = 0.0  # Δε_s (—), used with failure = "progressive"
    # a point whose broken family is stretched beyond this erodes (0: only when both
    # families are broken); nothing holds the element together across broken yarns
    erode_broken_stretch: float = 2.0
    # ... or either family crushed below this stretch (0: never): the point is then a
    # sliver (slack intact yarns, or intact yarns bunched) whose step shrinks like λ
    erode_broken_crush: float = 0.5
    # ... and, intact or not, once the cell is crushed both ways to λ_w λ_f below this
    # (0: never, the default; theory §1.4): yarns cannot pile into a fraction of their
    # cell, and the shell has no wrinkle below its element size
    erode_intact_crush: float = 0.0
    # crossover evaluation (theory §1.9): "table" interpolates the tabulated stored
    # energy while both families are intact and inside the table (fibre frame only),
    # "exact" always runs the height solve (the reference)
    crossover: Literal["table", "exact"] = "table"


@dataclass(frozen=True)
class FailureRegularisation:
    """Element-size regularisation of yarn failure (theory §1.4, "Failure that does not
    move with the mesh"). Each point knows its element's lengths h_w, h_f along the two
    yarn families (the element's reference area over its width across the family).

    Attributes:
        reference_length: h_ref (m), the element length at which the material's own T_u
            holds; None = the crossover cell along each family, 2ℓ_i0 (0.94 mm at 27 tpi).
        strength_scale: rows (h_i/h_ref, s): family i fails at s T_u, s piecewise linear in
            h_i/h_ref, flat beyond the first and last rows, s = 1 at h_ref; empty: s = 1.
        softening_opening: δ_s (m) of progressive failure: past s T_u a yarn's tension falls
            linearly to zero while the element opens by δ_s / s along the yarn — over the
            yarn strain Δε_s,i = δ_s ℓ_i0 / (s h_i L_i0) — so that the work of the
            softening, ½ s T_u · δ_s / s = ½ T_u δ_s per yarn crossing the crack, does not
            depend on h_i; 0: the material's fixed ``softening_strain``.
        erosion_opening: δ_e (m): a point whose family i is broken erodes once λ_i exceeds
            1 + δ_e/h_i (the crack opened by δ_e); 0: the opening at which an element of
            the reference length reaches ``erode_broken_stretch``, δ_e = (λ_e − 1) h_ref.
    """

    reference_length: float | None = None
    strength_scale: tuple[tuple[float, float], ...] = ()
    softening_opening: float = 0.0
    erosion_opening: float = 0.0


# --- running the kernel on points ------------------------------------------------
def regularised_columns(p: np.ndarray, lengths: np.ndarray) -> np.ndarray:
    """Each point's failure columns S_TU_SCALE, S_SOFT, S_ERODE_LIMIT (warp, fill each)
    from its element's lengths along the two families (theory §1.4).

    Args:
        p: the material's parameter row (:meth:`FabricParameters.to_array`).
        lengths: (n, 2) h_w, h_f (m); a length ≤ 0 stands for the reference length
            (a point without an element: the single-point drivers).

    Returns:
        (n, 6): s_w, s_f (T_u scales), Δε_s,w, Δε_s,f (softening strains), λ_lim,w,
        λ_lim,f (stretch of a broken family at which the point erodes; 0: never): 1 +
        δ_e/h_i, δ_e the erosion opening, by default (λ_e − 1) h_ref with λ_e the
        ``erode_broken_stretch`` option — that stretch on an element of the reference
        length, the same opening on any other.
    """
    lengths = np.atleast_2d(np.asarray(lengths, dtype=float))
    h_ref = p[L.P_REG_LENGTH:L.P_REG_LENGTH + 2]
    h = np.where(lengths > 0.0, lengths, h_ref)
    n_rows = int(p[L.P_REG_ROWS])
    table = p[L.P_REG_TABLE:L.P_REG_TABLE + 2 * n_rows].reshape(n_rows, 2)
    scale = np.interp(h / h_ref, table[:, 0], table[:, 1]) if n_rows else np.ones_like(h)
    out = np.empty((len(h), 6))
    out[:, 0:2] = scale
    opening = p[L.P_SOFT_OPENING]
    # the yarn strain over which the element opens by δ_s / s in its plane: a straight
    # yarn's strain grows by Δλ ℓ_i0 / L_i0 (eq. 6.19), and Δλ = δ_s / (s h_i)
    crimp = p[L.P_ELL0:L.P_ELL0 + 2] / p[L.P_LT0:L.P_LT0 + 2]
    out[:, 2:4] = crimp * opening / (scale * h) if opening > 0.0 else p[L.P_SOFT]
    erode = p[L.P_ERODE_OPENING]
    stretch = p[L.P_ERODE_STRETCH]
    if erode > 0.0:
        out[:, 4:6] = 1.0 + erode / h
    elif stretch > 0.0:  # the opening of an element of the reference length at λ_e
        out[:, 4:6] = 1.0 + (stretch - 1.0) * h_ref / h
    else:
        out[:, 4:6] = 0.0  # never
    return out


def set_regularised_columns(state: np.ndarray, p: np.ndarray, lengths: np.ndarray) -> None:
    """Write :func:`regularised_columns` into the state rows (n, N_STATE), in place."""
    cols = regularised_columns(p, lengths)
    state[:, L.S_TU_SCALE:L.S_TU_SCALE + 2] = cols[:, 0:2]
    state[:, L.S_SOFT:L.S_SOFT + 2] = cols[:, 2:4]
    state[:, L.S_ERODE_LIMIT:L.S_ERODE_LIMIT + 2] = cols[:, 4:6]


def initial_state(params, n_points: int = 1,
                  lengths: np.ndarray | None = None) -> np.ndarray:
    """States of ``n_points`` undeformed points of the fabric ``params``
    (:class:`~wovenimpact.materials.fabric.FabricParameters`): H_i = h_i0, λ_i = 1,
    intact, alive; their failure columns for elements of the given lengths (n_points, 2)
    along warp and fill (None: the reference length, i.e. the material's own T_u; theory
    §1.4)."""
    s = np.zeros((n_points, L.N_STATE))
    s[:, L.S_H] = params.warp.h0
    s[:, L.S_H + 1] = params.fill.h0
    s[:, L.S_LAMBDA] = 1.0
    s[:, L.S_LAMBDA + 1] = 1.0
    s[:, L.S_ALIVE] = 1.0
    set_regularised_columns(s, params.to_array(table=False),
                            np.zeros((n_points, 2)) if lengths is None else lengths)
    return s


@dataclass
class PointUpdate:
    """Result of :func:`update_points` (arrays over points)."""

    state: np.ndarray  # (n, N_STATE)
    resultant: np.ndarray  # (n, 3): N_xx, N_yy, N_xy (N/m)
    stiffness: np.ndarray  # (n,): tangent stiffness bound (N/m)


def update_points(
    p: np.ndarray, f_old: np.ndarray, f_new: np.ndarray, state: np.ndarray
) -> PointUpdate:
    """Advance material points from F_old to F_new; raise on any failed point.

    Args:
        p: parameter vector (:meth:`FabricParameters.to_array`).
        f_old, f_new: (n, 2, 2) or (2, 2) deformation gradients (reference yarn
            frame → current frame).
        state: (n, N_STATE) or (N_STATE,) states at the start of the step.

    Raises:
        MaterialPointError: naming the first failed point, why, and its input.
    """
    from wovenimpact.errors import MaterialPointError
    from wovenimpact.kernels.fabric import fabric_update_for_points

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
    p = np.ascontiguousarray(p, dtype=np.float64)
    fabric_update_for_points(p, f_old, f_new, state_in, state_out, res, stiff, status)
    bad = np.flatnonzero(status != L.STATUS_OK)
    if bad.size:
        i = int(bad[0])
        raise MaterialPointError(
            f"fabric point {i} of {n} ({bad.size} failed): {L.STATUS_TEXT[int(status[i])]}; "
            f"F_old = {f_old[i].tolist()}, F_new = {f_new[i].tolist()}, "
            f"state = {state_in[i].tolist()}"
        )
    return PointUpdate(state=state_out, resultant=res, stiffness=stiff)
