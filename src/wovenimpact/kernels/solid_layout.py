"""Column layout of the solid (8-node hexahedron) tables and of the transversely isotropic
material's parameter row, shared by the solid kernels and the Python side.

Kept apart from the kernels (as :mod:`~wovenimpact.kernels.shell_layout`) so that the
Python side can name entries without importing compiled code. docs/solid.md states the
element and the material these columns belong to.

Node order of a hexahedron (VTK / Abaqus C3D8): corner I sits at the parent coordinates
(ξ_I, η_I, ζ_I) of ``HEX_XI``, ``HEX_ETA``, ``HEX_ZETA``: 0 (−,−,−), 1 (+,−,−),
2 (+,+,−), 3 (−,+,−), 4 (−,−,+), 5 (+,−,+), 6 (+,+,+), 7 (−,+,+). The hourglass base
vectors h_α of Flanagan & Belytschko (1981) are ``HEX_H1`` … ``HEX_H4`` = ηζ, ξζ, ξη, ξηζ
at the corners.

Symmetric tensors are stored as 6 values in Voigt order 11, 22, 33, 23, 13, 12
(tensor components, not engineering shears).

Element state (one row per hexahedron, ``N_HEX_STATE`` values):

- ``H_TAU``: rotated Kirchhoff stress τ_m = M0 Rᵀ (J σ) R M0ᵀ in the element's material
  axes (6, Pa): the variable the material integrates (Green–Naghdi frame).
- ``H_U``: right stretch U of the one-point F = R U (6, reference global axes).
- ``H_HG``: hourglass generalised forces Q̂_α, mode α's 3 components at
  ``H_HG + 3 α + i`` (N), in the rotated frame (forces on the corners are R Q̂_α γ_αI).
- ``H_SIG``: Cauchy stress σ in global axes (6, Pa), for output.
- ``H_W``: stored strain energy of the element V0 W (J); per unit reference volume
  (J/m³) for a material point driven alone (volume 1).
- ``H_W_HG``: hourglass energy of the element (J), the work of the hourglass forces.
- ``H_DT``: the element's stable step l_e / c_e (s), before the solver's safety factor.
- ``H_VOL``: current volume V (m³).

Transversely isotropic parameter row (``N_TI_PARAM`` values, SI): the engineering
constants as given (E11, E22 = E33, G12 = G13, G23, ν12 = ν13, ν23, ρ) and what the kernel
reads: the stiffness C in material axes (``TI_C11`` … ``TI_C66``; C13 = C12, C33 = C22,
C55 = C66 = G12, C44 = G23), the largest eigenvalue of C in Mandel form (the stable step's
modulus, ``TI_WAVE_MODULUS``) and the modulus the hourglass stiffness is scaled with
(``TI_HG_MODULUS``, the mean shear modulus (2 G12 + G23)/3). E11, ν12 and ρ sit in the
columns of the elastic row's E, ν, ρ (shell_layout ``ELASTIC_*``), so code that only needs
a density reads this row unchanged.
"""

from __future__ import annotations

# parent coordinates of the corners and the hourglass base vectors (Flanagan–Belytschko)
HEX_XI = (-1.0, 1.0, 1.0, -1.0, -1.0, 1.0, 1.0, -1.0)
HEX_ETA = (-1.0, -1.0, 1.0, 1.0, -1.0, -1.0, 1.0, 1.0)
HEX_ZETA = (-1.0, -1.0, -1.0, -1.0, 1.0, 1.0, 1.0, 1.0)
HEX_H1 = tuple(e * z for e, z in zip(HEX_ETA, HEX_ZETA))  # ηζ
HEX_H2 = tuple(x * z for x, z in zip(HEX_XI, HEX_ZETA))  # ξζ
HEX_H3 = tuple(x * e for x, e in zip(HEX_XI, HEX_ETA))  # ξη
HEX_H4 = tuple(x * e * z for x, e, z in zip(HEX_XI, HEX_ETA, HEX_ZETA))  # ξηζ
HEX_MODES = 4  # hourglass modes per direction

# element state
H_TAU = 0
H_U = 6
H_HG = 12
H_SIG = 24
H_W = 30
H_W_HG = 31
H_DT = 32
H_VOL = 33
N_HEX_STATE = 34

# transversely isotropic parameter row
TI_E11 = 0  # E11, modulus along the fibre axis a1 (Pa)
TI_NU12 = 1  # ν12 = ν13 (—)
TI_RHO = 2  # ρ, density (kg/m³)
TI_E22 = 3  # E22 = E33, transverse modulus (Pa)
TI_G12 = 4  # G12 = G13, axial shear modulus (Pa)
TI_G23 = 5  # G23, transverse shear modulus (Pa)
TI_NU23 = 6  # ν23 (—)
TI_C11 = 7  # stiffness C in the material axes (Pa): C11
TI_C12 = 8  # C12 = C13
TI_C22 = 9  # C22 = C33
TI_C23 = 10  # C23
TI_C44 = 11  # C44 = G23 (τ23 = 2 C44 d23)
TI_C66 = 12  # C55 = C66 = G12
TI_WAVE_MODULUS = 13  # λ_max of C (Mandel form): c_max² = λ_max / ρ (Pa)
TI_HG_MODULUS = 14  # hourglass modulus G_hg = (2 G12 + G23)/3 (Pa)
N_TI_PARAM = 15

# status codes of a solid material point (the element reports shell_layout EL_* codes)
POINT_OK = 0
POINT_BAD_KINEMATICS = 1  # det F ≤ 0 or non-finite F
POINT_NOT_CONVERGED = 2  # the polar decomposition did not converge

POINT_STATUS_TEXT = {
    POINT_OK: "ok",
    POINT_BAD_KINEMATICS: "inadmissible deformation (det F ≤ 0, or NaN)",
    POINT_NOT_CONVERGED: "polar decomposition did not converge",
}
