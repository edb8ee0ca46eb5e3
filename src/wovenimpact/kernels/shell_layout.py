"""Column layout of the shell tables shared by the solver and the shell kernels.

Sections (``Model.sections``, one row per section, SI):

- ``C_THICK``: shell thickness t (m).
- ``C_MAT``: row of ``Model.mat_params`` / ``Model.mat_kind`` (stored as float).
- ``C_AREAL_MASS``: mass per unit reference area μ (kg/m²).
- ``C_BEND_E``, ``C_BEND_NU``: modulus and Poisson ratio of the bending resultant
  M = D κ, D = E t³/(12 (1 − ν²)) (the metal's own, or the small elastic bending
  stiffness of a fabric, docs/model.md §1.8).
- ``C_SHEAR_G``: transverse shear modulus G of Q = k G t γ (Pa); ``C_SHEAR_K`` its
  factor k (5/6).
- ``C_HOURGLASS``: hourglass stiffness coefficient r (—).
- ``C_POINTS``: through-thickness integration points: 1 = resultant section (membrane
  from the material, bending M = D κ), n ≥ 3 odd = the material evaluated at n
  Simpson points z_k (membrane N = Σ w_k N_k, bending M = Σ w_k z_k N_k).
- ``C_INPLANE``: in-plane membrane points: 1 = one point at the centre plus
  Flanagan–Belytschko hourglass springs on the in-plane modes (``MEMBRANE_REDUCED``),
  4 = 2×2 Gauss points, no in-plane hourglass modes (``MEMBRANE_FULL``; theory §4.5).

Material kinds (``Model.mat_kind``): ``MAT_ELASTIC`` (params E, ν, ρ in columns
``ELASTIC_MODULUS``, ``ELASTIC_POISSON``, ``ELASTIC_DENSITY`` of ``Model.mat_params``;
a prefix of their own, apart from the ``E_*`` element-state columns), ``MAT_FABRIC``
(the crossover parameter vector of :mod:`wovenimpact.kernels.fabric_layout`) and
``MAT_J2`` (plane-stress J2 plasticity, :mod:`wovenimpact.kernels.j2_layout`; E, ν, ρ
in the same first columns).

Per-element state (``State.elem``, one row per element):

- ``E_F``: in-plane deformation gradient F (4 values, row-major F11 F12 F21 F22)
  from the reference material frame (warp along x) to the corotational frame.
- ``E_N``: membrane resultant N_xx, N_yy, N_xy (N/m), corotational frame.
- ``E_M``: moments M_xx, M_yy, M_xy (N·m/m); ``E_Q``: transverse shears Q_x, Q_y (N/m).
- ``E_HG``: hourglass generalised forces (membrane x, y; w; θx, θy).
- ``E_U_MEMB``: membrane stored energy (J); ``E_U_BEND``: bending + transverse shear
  energy (J); ``E_U_HG``: hourglass energy (J).
- ``E_DT``: the element's stable time step L_e / c_e (s), before the factor α: its wave
  bound, the one mass scaling raises (c_e ∝ 1/√μ).
- ``E_DT_KIN``: the element's kinematic step under ``run.stable_step = "yarn"`` (s,
  before α; ``kinematic_step``), ∞ otherwise. It bounds the step beside ``E_DT`` but
  depends on the motion alone: no added mass raises it, so mass scaling leaves it out.
- ``E_ALIVE``: 1.0 alive, 0.0 eroded.
- ``E_KAPPA``: total curvatures κ_x, κ_y, 2κ_xy (1/m), accumulated from the rates (used
  by integrated sections).

- ``E_FG``: the in-plane F at the four Gauss points of a fully integrated membrane
  (4 × 4 values, point g at ``E_FG + 4 g``).

The material state of an element is ``n_inplane × n_points`` consecutive rows of
``State.mat`` from ``Model.mat_row[e]``, each ``Model.point_width`` values wide (the
longest state vector of the model's material kinds; a shorter one uses the first
columns): row ``mat_row[e] + g · n_points + k`` for in-plane point g and
through-thickness point k (one row for a one-point resultant section, and one unused row
for an elastic material).
"""

from __future__ import annotations

# sections
C_THICK = 0
C_MAT = 1
C_AREAL_MASS = 2
C_BEND_E = 3
C_BEND_NU = 4
C_SHEAR_G = 5
C_SHEAR_K = 6
C_HOURGLASS = 7
C_POINTS = 8
C_INPLANE = 9
N_SECTION = 10

MEMBRANE_REDUCED = 1
MEMBRANE_FULL = 4

# the fabric elements' stable step (run.stable_step; theory §4, "Stable step")
STEP_ISOTROPIC = 0  # L_e / c_e with the largest membrane tangent per current length
STEP_YARN = 1  # each taut yarn family over its reference length, plus a kinematic limit
STABLE_STEPS = {"isotropic": STEP_ISOTROPIC, "yarn": STEP_YARN}  # run.stable_step's words
# η of the kinematic bound (kernels.shell.kinematic_step; run.kinematic_fraction's default):
# the fraction of its distance a corner pair may close or open in one step
KINEMATIC_FRACTION = 0.05

# material kinds and the elastic parameter vector (a row of Model.mat_params)
MAT_ELASTIC = 0
MAT_FABRIC = 1
MAT_J2 = 2
ELASTIC_MODULUS = 0  # E (Pa)
ELASTIC_POISSON = 1  # ν (—)
ELASTIC_DENSITY = 2  # ρ (kg/m³)

# element state
E_F = 0
E_N = 4
E_M = 7
E_Q = 10
E_HG = 12
E_U_MEMB = 17
E_U_BEND = 18
E_U_HG = 19
E_DT = 20
E_ALIVE = 21
E_KAPPA = 22
E_FG = 25
E_DT_KIN = 41
N_ELEM_STATE = 42

# per-element status codes written by the force kernel
EL_OK = 0
EL_INVERTED = 1  # non-positive area or Jacobian
EL_MATERIAL = 2  # material point failed to converge or got inadmissible kinematics
EL_NAN = 3
