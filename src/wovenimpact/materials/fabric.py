"""Python side of the yarn-crossover fabric model: parameters and point updates.

The physics lives in :mod:`wovenimpact.kernels.fabric` (Numba). This module
holds the SI parameter set (:class:`FabricParameters`), packs it into the flat
parameter vector the kernels read (layout in :mod:`wovenimpact.kernels.fabric_layout`),
and offers :func:`initial_state` and :func:`update_points`, which run the kernel
on one point or a million and raise :class:`MaterialPointError` naming the
point and its state if any point fails (they, and the parts of the parameter set,
are defined in :mod:`wovenimpact.materials.fabric_point`, below the crossover
table). docs/theory.md §1.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from wovenimpact.kernels import fabric_layout as L
from wovenimpact.materials.fabric_point import (  # noqa: F401  (the fabric's public names)
    FabricOptions,
    FailureRegularisation,
    PointUpdate,
    YarnFamily,
    initial_state,
    regularised_columns,
    set_regularised_columns,
    update_points,
)


def trellis_locking_angles(ratio: float, c_max: float) -> tuple[float, float]:
    """(γ1, γ2) in rad of eqs. 3.13–3.14 for parallel yarns of width b a pitch p apart,
    ``ratio`` = b / p: they touch when p cos γ = b, γ1 = π/2 − asin(b/p), and are
    compacted to C_max b when p cos γ = C_max b (a ratio above 1 counts as 1: γ = 0)."""
    return (0.5 * math.pi - math.asin(min(ratio, 1.0)),
            0.5 * math.pi - math.asin(min(c_max * ratio, 1.0)))


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
        regularisation: element-size regularisation of failure (none by default).
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
    regularisation: FailureRegularisation = field(default_factory=FailureRegularisation)
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
        return trellis_locking_angles(max(ratios), self.shear_c_max)

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

    def to_array(self, table: bool = True) -> np.ndarray:
        """Pack into the flat parameter vector read by the kernels (with the crossover
        table appended when ``options.crossover == "table"`` and the frame is the fibre
        frame; the Green–Naghdi option keeps the exact solve). ``table=False``: the first
        N_PARAM entries alone, without building the table."""
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
        r = self.regularisation
        for i, y in enumerate((self.warp, self.fill)):
            p[L.P_REG_LENGTH + i] = (r.reference_length if r.reference_length is not None
                                     else 2.0 * y.half_length)
        p[L.P_SOFT_OPENING] = r.softening_opening
        p[L.P_ERODE_OPENING] = r.erosion_opening
        if len(r.strength_scale) > L.REG_ROWS_MAX:
            raise ValueError(f"strength_scale has {len(r.strength_scale)} rows; at most "
                             f"{L.REG_ROWS_MAX}")
        p[L.P_REG_ROWS] = len(r.strength_scale)
        p[L.P_TU_FLOOR:L.P_TU_FLOOR + 2] = 1.0  # a model lowers it to its points' smallest s
        for k, (x, sc) in enumerate(r.strength_scale):
            p[L.P_REG_TABLE + 2 * k] = x
            p[L.P_REG_TABLE + 2 * k + 1] = sc
        p[L.P_TAB_START] = L.N_PARAM
        if not table:
            return p
        if o.crossover == "table" and o.frame == "fibre":
            from wovenimpact.materials.fabric_table import with_table

            p = with_table(self, p)
        else:
            p[L.P_CROSSOVER] = L.CROSSOVER_EXACT
        return p
