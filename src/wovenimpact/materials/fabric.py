"""Python side of the yarn-crossover fabric model: parameters and point updates.

The physics lives in :mod:`wovenimpact.kernels.fabric` (Numba). This module
holds the SI parameter set (:class:`FabricParameters`), packs it into the flat
parameter vector the kernels read (layout in :mod:`wovenimpact.kernels.fabric_layout`),
and offers :func:`initial_state` and :func:`update_points`, which run the kernel
on one point or a million and raise :class:`MaterialPointError` naming the
point and its state if any point fails. docs/theory.md §1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
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
    """Model variants (MODEL.md §1.4–1.7; docs/theory.md §1.8)."""

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
class FabricParameters:
    """Complete, validated parameter set of the crossover model (SI).

    Attributes:
        warp, fill: the two yarn families.
        compaction_a: a of F = b δ / (a − δ) (m), eq. (5.8).
        compaction_b: b (N).
        shear_g1, shear_g2: trellis shear moduli before locking / at full compaction (Pa).
        shear_c_max: compaction ratio C_max at full locking (—).
        fibre_density: ρ_y (kg/m³).
        areal_density: measured areal mass (kg/m²); None = from yarn volume (§1.8).
        thickness: shell thickness (m); None = 2 (h_w0 + h_f0) (= 4 h0, Table 5-1).
        options: model variants.
        name: the material file's name (a label for reports; no part of the model).
    """

    warp: YarnFamily
    fill: YarnFamily
    compaction_a: float
    compaction_b: float
    shear_g1: float
    shear_g2: float
    shear_c_max: float
    fibre_density: float
    areal_density: float | None = None
    thickness: float | None = None
    options: FabricOptions = field(default_factory=FabricOptions)
    name: str = field(default="", compare=False)

    # --- derived quantities ---------------------------------------------------
    @property
    def shell_thickness(self) -> float:
        """Shell thickness t (m): given, or 2 (h_w0 + h_f0) = 4 h0 for a balanced weave."""
        if self.thickness is not None:
            return self.thickness
        return 2.0 * (self.warp.h0 + self.fill.h0)

    @property
    def areal_mass(self) -> float:
        """μ (kg/m²): measured, or ρ_y [A_w (1+c_w)/(2ℓ_f0) + A_f (1+c_f)/(2ℓ_w0)] (§1.8)."""
        if self.areal_density is not None:
            return self.areal_density
        w, f = self.warp, self.fill
        return self.fibre_density * (
            w.area * (1.0 + w.crimp) / (2.0 * f.half_length)
            + f.area * (1.0 + f.crimp) / (2.0 * w.half_length)
        )

    @property
    def locking_angles(self) -> tuple[float, float]:
        """(γ1, γ2) in rad of the true-angle trellis law (§1.6, eq. 3.13–3.14).

        Parallel warp yarns are 2ℓ_f0 apart along the fill; they touch when
        2ℓ_f0 sin θ = b_w, and are fully compacted when 2ℓ_f0 sin θ = C_max b_w
        (same for the fill). The family that locks first sets γ1 and γ2. A yarn
        as wide as its pitch (zero gap, the reference fabric) gives γ1 = 0.
        """
        ratios = (
            self.warp.width / (2.0 * self.fill.half_length),
            self.fill.width / (2.0 * self.warp.half_length),
        )
        r = max(ratios)
        gamma1 = 0.5 * math.pi - math.asin(min(r, 1.0))
        gamma2 = 0.5 * math.pi - math.asin(min(self.shear_c_max * r, 1.0))
        return gamma1, gamma2

    @property
    def thesis_locking_angles(self) -> tuple[float, float]:
        """(β1, β2) in rad of the thesis shear variant, eq. (6.32)–(6.33).

        sin β1 = mean_i(b_i / ℓ_i0), sin β2 = mean_i(C_max b_i / ℓ_i0). For the
        reference fabric these sines are 2.0 and 1.3: no such angle exists, so
        the thesis's locking never engages and G = G1 throughout. We represent
        an unreachable angle by π/2 (β = asin(H/ℓ) ≤ π/2 always) and say so in
        :meth:`warnings`.
        """
        s1 = 0.5 * (self.warp.width / self.warp.half_length + self.fill.width / self.fill.half_length)
        s2 = self.shear_c_max * s1
        beta = lambda s: math.asin(s) if s <= 1.0 else 0.5 * math.pi  # noqa: E731
        return beta(s1), beta(s2)

    def warnings(self) -> list[str]:
        """Model caveats worth showing a user of these parameters."""
        out = []
        if self.options.shear == "thesis":
            s1 = 0.5 * (
                self.warp.width / self.warp.half_length + self.fill.width / self.fill.half_length
            )
            if s1 >= 1.0:
                out.append(
                    f"shear = 'thesis': sin β1 = b/ℓ0 = {s1:.3f} ≥ 1 (eq. 6.32), so the thesis's "
                    "locking angles do not exist and G = G1 at every shear angle"
                )
        return out

    def to_array(self) -> np.ndarray:
        """Pack into the flat parameter vector read by the kernels (with the crossover
        table appended when ``options.crossover == "table"`` and the frame is the fibre
        frame; the Green–Naghdi option keeps the exact solve)."""
        p = np.zeros(L.N_PARAM)
        for i, y in enumerate((self.warp, self.fill)):
            p[L.P_E + i] = y.modulus
            p[L.P_AREA + i] = y.area
            p[L.P_ELL0 + i] = y.half_length
            p[L.P_H0 + i] = y.h0
            p[L.P_TU + i] = y.ultimate_tension
            p[L.P_WIDTH + i] = y.width
            p[L.P_LT0 + i] = y.truss_length
        p[L.P_COMP_A] = self.compaction_a
        p[L.P_COMP_B] = self.compaction_b
        p[L.P_G1] = self.shear_g1
        p[L.P_G2] = self.shear_g2
        p[L.P_GAMMA1], p[L.P_GAMMA2] = self.locking_angles
        p[L.P_BETA1], p[L.P_BETA2] = self.thesis_locking_angles
        p[L.P_THICK] = self.shell_thickness
        o = self.options
        p[L.P_SOFT] = o.softening_strain
        p[L.P_HOMOG] = {"virial": L.HOMOG_VIRIAL, "thesis": L.HOMOG_THESIS}[o.homogenisation]
        p[L.P_SHEAR] = {"true": L.SHEAR_TRUE, "thesis": L.SHEAR_THESIS}[o.shear]
        p[L.P_FRAME] = {"fibre": L.FRAME_FIBRE, "green-naghdi": L.FRAME_GREEN_NAGHDI}[o.frame]
        p[L.P_FAILURE] = {"instant": L.FAILURE_INSTANT, "progressive": L.FAILURE_PROGRESSIVE}[
            o.failure
        ]
        p[L.P_AREAL_MASS] = self.areal_mass
        p[L.P_ERODE_STRETCH] = o.erode_broken_stretch
        p[L.P_ERODE_CRUSH] = o.erode_broken_crush
        p[L.P_ERODE_INTACT] = o.erode_intact_crush
        p[L.P_TAB_START] = L.N_PARAM
        if o.crossover == "table" and o.frame == "fibre":
            from wovenimpact.materials.fabric_table import with_table

            p = with_table(self, p)
        else:
            p[L.P_CROSSOVER] = L.CROSSOVER_EXACT
        return p


# --- running the kernel on points ------------------------------------------------
def initial_state(params: FabricParameters, n_points: int = 1) -> np.ndarray:
    """States of ``n_points`` undeformed points: H_i = h_i0, λ_i = 1, intact, alive."""
    s = np.zeros((n_points, L.N_STATE))
    s[:, L.S_H] = params.warp.h0
    s[:, L.S_H + 1] = params.fill.h0
    s[:, L.S_LAMBDA] = 1.0
    s[:, L.S_LAMBDA + 1] = 1.0
    s[:, L.S_ALIVE] = 1.0
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
