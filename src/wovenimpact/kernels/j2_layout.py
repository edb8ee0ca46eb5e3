"""Index layout of the J2 (metal) parameter vector and state vector.

Kept apart from the kernels so the Python side (materials/metal.py, outputs,
tests) can name entries without importing compiled code. Plain integer
constants: Numba treats module-level ints as compile-time constants.

Parameter vector ``p`` (float64, length ``N_PARAM``), SI units. Columns 0–2 are
E, ν, ρ as in the elastic row of :mod:`wovenimpact.kernels.shell_layout`
(``ELASTIC_MODULUS``, ``ELASTIC_POISSON``, ``ELASTIC_DENSITY``), so code that only needs
the elastic constants (bending of a resultant section, wave speeds) reads a metal row
unchanged.

Names that fabric_layout also defines mean the same there (``S_ALIVE``, ``S_ENERGY`` and
the ``STATUS_*`` codes, same values), or are each layout's own length or text table
(``N_PARAM``, ``N_STATE``, ``STATUS_TEXT``); a column that differs from the fabric's has a
name of its own (``P_YOUNG``, not the fabric's yarn modulus ``P_E``; ``S_KIRCHHOFF``, not
the trellis shear stress ``S_TAU``; ``S_JC_DAMAGE``, ``S_RETURN_ITER``).
tests/unit/test_layouts.py checks it.
"""

# --- parameters -------------------------------------------------------------
P_YOUNG = 0  # E, Young's modulus (Pa)
P_NU = 1  # ν, Poisson's ratio (—)
P_RHO = 2  # ρ, density (kg/m³)
P_FRACTURE = 3  # ε_f, equivalent plastic strain at failure (—); 0: no such criterion
P_RATE_C = 4  # C of the Johnson–Cook rate factor 1 + C ln(ε̇p/ε̇0) (—)
P_RATE_REF = 5  # ε̇0, its reference plastic strain rate (1/s); 0: no rate effect
P_DAMAGE = 6  # 1.0: Johnson–Cook damage on, 0.0: off
P_D = 7  # D1..D5 of the Johnson–Cook fracture strain (P_D + 0 … P_D + 4)
P_DAMAGE_REF = 12  # ε̇0 of the damage rate term (1/s)
P_N_HARD = 13  # number of rows of the hardening table (1 … N_HARD_MAX)
P_HARD = 14  # row k: ε_p at P_HARD + 2k, σ_y (Pa) at P_HARD + 2k + 1
N_HARD_MAX = 64
# element-size regularisation of fracture (theory §7.3). The kernel reads none of these:
# each point's S_FRAC_SCALE and S_EVOLUTION are set at the start of a run from its
# element's length l_e = √A0 (materials.metal.regularised_columns).
P_FRAC_LENGTH = P_HARD + 2 * N_HARD_MAX  # l_ref, the length at which ε_f holds as given (m)
P_FAIL_DISP = P_FRAC_LENGTH + 1  # ū_f, plastic displacement from onset to failure (m); 0: none
P_FRAC_ROWS = P_FRAC_LENGTH + 2  # rows of the fracture-strain scale table (0: s = 1)
P_FRAC_TABLE = P_FRAC_LENGTH + 3  # row k: l_e/l_ref at P_FRAC_TABLE + 2k, scale s at + 2k + 1
FRAC_ROWS_MAX = 16
P_HINGE_RATIO = P_FRAC_TABLE + 2 * FRAC_ROWS_MAX  # l_h/t, a fold's width in thicknesses; 0: none
N_PARAM = P_HINGE_RATIO + 1

# --- state (history variables and outputs of one material point) -------------
# S_ALIVE and S_ENERGY sit at the same columns as in fabric_layout, so a section
# kernel reads a point's alive flag and stored energy the same way for both kinds
# (tests/unit/test_j2_kernel.py checks it).
S_SIG = 0  # rotated Cauchy stress σ_xx, σ_yy, σ_xy (Pa), Green–Naghdi frame: S_SIG + 0..2
S_KIRCHHOFF = 3  # rotated Kirchhoff stress τ = J σ (Pa), the return's variable: +0..2
S_EPS_P = 6  # ε̄p, equivalent plastic strain (—)
S_PLASTIC_WORK = 7  # plastic work per unit reference area, cumulative (J/m²)
S_THICK = 8  # λ3 = t / t0, thickness stretch (—)
S_JC_DAMAGE = 9  # D, Johnson–Cook damage (—), 0 … ≥ 1
S_ALIVE = 10  # 1.0 until the point fails, then 0.0 for good (as fabric_layout.S_ALIVE)
S_ENERGY = 11  # elastic stored energy per unit reference area (J/m²) (as fabric_layout.S_ENERGY)
S_RATE = 12  # ε̇p, equivalent plastic strain rate of the last step (1/s)
S_YIELD = 13  # σ_y, current flow stress (Pa), rate factor included
S_FAIL_ENERGY = 14  # elastic energy per reference area released when the point failed (J/m²)
S_RETURN_ITER = 15  # iterations of the last return
# per point, set at the start of a run from its element's length and never changed (theory §7.3):
S_FRAC_SCALE = 16  # s, the scale of the fracture strain (constant and Johnson–Cook) (—)
S_EVOLUTION = 17  # l_e/ū_f: damage D_e grows by l_e Δε̄p/ū_f after onset (1/—); 0: fail at onset
S_SOFT_DAMAGE = 18  # D_e ∈ [0, 1], damage after the onset of failure; the stress is (1 − D_e) τ̃
# per point, set at the start of a run (theory §7.3, "Folds"): the factor x_b = max(1, l_e/l_h)
# on the bending part of the plastic strain when fracture is judged, l_h the hinge ratio
# times the section's thickness t0; 1: none
S_HINGE = 19
N_STATE = 20

# --- status codes returned per point -----------------------------------------
STATUS_OK = 0
STATUS_NOT_CONVERGED = 1  # the plane-stress return left |f| > RETURN_TOL_FAIL σ_y
STATUS_BAD_KINEMATICS = 2  # det F ≤ 0 or non-finite input

STATUS_TEXT = {
    STATUS_OK: "ok",
    STATUS_NOT_CONVERGED: "plane-stress return did not converge",
    STATUS_BAD_KINEMATICS: "inadmissible deformation (det F ≤ 0, or NaN)",
}
