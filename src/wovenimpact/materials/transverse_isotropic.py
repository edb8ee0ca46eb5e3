"""SI parameter set of a transversely isotropic linear elastic solid (the yarn of the 3-D
crossover cell, thesis §5.2.2, Table 5-2: E11 = 96 GPa, E22 = E33 = G12 = G13 = G23 =
3.28 GPa, ν = 0, 1.44 g/cm³).

The fibre axis a1 is stiff (E11); the plane (a2, a3) across it has E22 = E33, and the
shear moduli are G12 = G13 (axial) and G23 (transverse). The material is transversely
isotropic about a1 in the strict sense only when G23 = E22 / (2 (1 + ν23))
(:attr:`TransverseIsotropicParameters.is_isotropic_across`); otherwise — the thesis's own
table, G23 = E22 with ν23 = 0, is such a case (the isotropic value would be 1.64 GPa) — it
is square-symmetric about a1 and the second material axis a2 matters: give the element
its full material frame (:func:`material_frame`).

The kernel is :mod:`wovenimpact.kernels.transverse_isotropic`; the parameter row's layout
is :mod:`wovenimpact.kernels.solid_layout` (``TI_*``). docs/solid.md states the model.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wovenimpact.errors import InputError, MaterialPointError
from wovenimpact.kernels import solid_layout as L

# the row of the parameter table a point update reads: a table of one material's row
ONLY_ROW = 0


@dataclass(frozen=True)
class TransverseIsotropicParameters:
    """Validated engineering constants (SI) of a transversely isotropic elastic solid.

    Attributes:
        e11: E11, modulus along the fibre axis a1 (Pa), > 0.
        e22: E22 = E33, transverse modulus (Pa), > 0.
        g12: G12 = G13, axial shear modulus (Pa), > 0.
        g23: G23, transverse shear modulus (Pa), > 0.
        nu12: ν12 = ν13 (—): lateral strain −ν12 ε under a stress along a1.
        nu23: ν23 (—), |ν23| < 1.
        density: ρ (kg/m³), > 0.
        name: the material's name, for messages.

    Raises:
        InputError: naming the field, its value and what is valid; the Poisson ratios
            must also leave C positive definite, (1 + ν23)(1 − ν23 − 2 ν12² E22/E11) > 0.
    """

    e11: float
    e22: float
    g12: float
    g23: float
    nu12: float
    nu23: float
    density: float
    name: str = "transverse_isotropic"

    def __post_init__(self) -> None:
        for field, unit in (("e11", "Pa"), ("e22", "Pa"), ("g12", "Pa"), ("g23", "Pa"),
                            ("density", "kg/m³")):
            value = getattr(self, field)
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value > 0.0):
                raise InputError(f"material {self.name!r}: {field} = {value!r} {unit} is not "
                                 f"valid: give a finite number > 0")
        for field in ("nu12", "nu23"):
            value = getattr(self, field)
            if not (isinstance(value, (int, float)) and math.isfinite(value)):
                raise InputError(f"material {self.name!r}: {field} = {value!r} is not valid: "
                                 f"give a finite number")
        if not abs(self.nu23) < 1.0:
            raise InputError(f"material {self.name!r}: nu23 = {self.nu23!r} is not valid: "
                             f"|nu23| < 1 (positive definite stiffness)")
        limit = math.sqrt((1.0 - self.nu23) * self.e11 / (2.0 * self.e22))
        if not abs(self.nu12) < limit:
            raise InputError(
                f"material {self.name!r}: nu12 = {self.nu12!r} is not valid with e11 = "
                f"{self.e11!r} Pa, e22 = {self.e22!r} Pa, nu23 = {self.nu23!r}: |nu12| < "
                f"√((1 − nu23) E11 / (2 E22)) = {limit:.6g} (positive definite stiffness)")

    @property
    def is_isotropic_across(self) -> bool:
        """True if G23 = E22 / (2 (1 + ν23)) (to 1e-12): isotropic in the (a2, a3) plane,
        so any a2 ⟂ a1 gives the same response."""
        g_iso = self.e22 / (2.0 * (1.0 + self.nu23))
        return abs(self.g23 - g_iso) <= 1e-12 * g_iso

    def compliance(self) -> np.ndarray:
        """S (6×6, Voigt 11, 22, 33, 23, 13, 12 with engineering shears γ = 2 ε): ε = S σ."""
        s = np.zeros((6, 6))
        s[0, 0] = 1.0 / self.e11
        s[1, 1] = s[2, 2] = 1.0 / self.e22
        s[0, 1] = s[1, 0] = s[0, 2] = s[2, 0] = -self.nu12 / self.e11
        s[1, 2] = s[2, 1] = -self.nu23 / self.e22
        s[3, 3] = 1.0 / self.g23
        s[4, 4] = s[5, 5] = 1.0 / self.g12
        return s

    def stiffness(self) -> np.ndarray:
        """C = S⁻¹ (6×6, Voigt with engineering shears), material axes (Pa)."""
        c = np.zeros((6, 6))
        c[:3, :3] = np.linalg.inv(self.compliance()[:3, :3])
        c[3, 3] = self.g23
        c[4, 4] = c[5, 5] = self.g12
        return c

    @property
    def wave_modulus(self) -> float:
        """λ_max of C in Mandel form (shear rows scaled by 2): ρ c² ≤ λ_max for every plane
        wave, the stable step's modulus (docs/solid.md, "Stable step")."""
        c = self.stiffness()
        mandel = c.copy()
        mandel[3:, 3:] *= 2.0
        return float(np.linalg.eigvalsh(mandel).max())

    @property
    def hourglass_modulus(self) -> float:
        """G_hg = (G12 + G13 + G23)/3 = (2 G12 + G23)/3 (Pa), the modulus the hourglass
        stiffness is scaled with (docs/solid.md, "Hourglass control")."""
        return (2.0 * self.g12 + self.g23) / 3.0

    def to_array(self) -> np.ndarray:
        """The kernel's parameter row (solid_layout ``TI_*``)."""
        c = self.stiffness()
        p = np.zeros(L.N_TI_PARAM)
        p[L.TI_E11] = self.e11
        p[L.TI_NU12] = self.nu12
        p[L.TI_RHO] = self.density
        p[L.TI_E22] = self.e22
        p[L.TI_G12] = self.g12
        p[L.TI_G23] = self.g23
        p[L.TI_NU23] = self.nu23
        p[L.TI_C11] = c[0, 0]
        p[L.TI_C12] = c[0, 1]
        p[L.TI_C22] = c[1, 1]
        p[L.TI_C23] = c[1, 2]
        p[L.TI_C44] = c[3, 3]
        p[L.TI_C66] = c[5, 5]
        p[L.TI_WAVE_MODULUS] = self.wave_modulus
        p[L.TI_HG_MODULUS] = self.hourglass_modulus
        return p


def material_frame(fibre, second=None) -> np.ndarray:
    """Orthonormal material axes (3×3, rows a1, a2, a3) from the fibre direction and a
    direction for a2 (projected off a1; default: the global axis least aligned with a1).
    a3 = a1 × a2 (right-handed).

    Raises:
        InputError: a zero fibre direction, or a second direction parallel to it.
    """
    a1 = np.asarray(fibre, dtype=float).reshape(3)
    n1 = np.linalg.norm(a1)
    if not (np.isfinite(n1) and n1 > 0.0):
        raise InputError(f"fibre direction {a1.tolist()} is not valid: give a non-zero vector")
    a1 = a1 / n1
    if second is None:
        second = np.eye(3)[int(np.argmin(np.abs(a1)))]
    a2 = np.asarray(second, dtype=float).reshape(3)
    a2 = a2 - (a2 @ a1) * a1
    n2 = np.linalg.norm(a2)
    if not (np.isfinite(n2) and n2 > 1e-12 * max(1.0, float(np.linalg.norm(second)))):
        raise InputError(f"second material direction {np.asarray(second).tolist()} is not "
                         f"valid: give a vector not parallel to the fibre {a1.tolist()}")
    a2 = a2 / n2
    return np.array([a1, a2, np.cross(a1, a2)])


def initial_state(n: int) -> np.ndarray:
    """Rows of ``n`` unstrained points or elements (solid_layout ``H_*``): U = I, the
    rest zero."""
    s = np.zeros((n, L.N_HEX_STATE))
    s[:, L.H_U:L.H_U + 3] = 1.0
    return s


def update_points(params: TransverseIsotropicParameters, frames, f, state) -> np.ndarray:
    """Advance points to F^n = f (n, 3, 3) from their state rows (n, N_HEX_STATE) with
    material axes ``frames`` (n, 3, 3) or one (3, 3) for all; returns the new rows
    (σ at ``H_SIG``, τ_m at ``H_TAU``, U at ``H_U``, W per unit volume at ``H_W``).

    Raises:
        MaterialPointError: naming the first point that could not be updated and why.
    """
    from wovenimpact.kernels.transverse_isotropic import ti_update_for_points

    f = np.ascontiguousarray(np.asarray(f, dtype=np.float64).reshape(-1, 3, 3))
    n = f.shape[0]
    frames = np.ascontiguousarray(np.broadcast_to(
        np.asarray(frames, dtype=np.float64).reshape(-1, 3, 3), (n, 3, 3)))
    state_in = np.ascontiguousarray(np.asarray(state, dtype=np.float64).reshape(n, -1))
    state_out = state_in.copy()
    status = np.zeros(n, dtype=np.int32)
    ti_update_for_points(params.to_array()[None, :], ONLY_ROW, frames, f, state_in, state_out,
                         status)
    bad = np.flatnonzero(status != L.POINT_OK)
    if bad.size:
        i = int(bad[0])
        raise MaterialPointError(f"solid point {i} of {n} ({bad.size} failed): "
                                 f"{L.POINT_STATUS_TEXT[int(status[i])]}; F = {f[i].tolist()}")
    return state_out
