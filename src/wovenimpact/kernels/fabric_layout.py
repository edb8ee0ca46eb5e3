"""Index layout of the crossover-model parameter vector and state vector.

Kept apart from the kernels so the Python side (materials/fabric.py, outputs,
tests) can name entries without importing compiled code. Plain integer
constants: Numba treats module-level ints as compile-time constants.

Parameter vector ``p`` (float64, length ``N_PARAM``, followed by the crossover table
when ``p[P_TAB_NW] > 0``: length ``N_PARAM + n_w + n_f + m_w + m_f + TAB_STRIDE n_w n_f``),
SI units.
Index 0/1 of a pair is warp/fill. The table rides in the same row of
``Model.mat_params`` (rows are zero-padded to the longest), so it reaches every
kernel without new arguments.
"""

# --- parameters -------------------------------------------------------------
P_E = 0  # E_i, yarn axial modulus (Pa); P_E + 1 for fill
P_AREA = 2  # A_i, yarn cross-section area (m²)
P_ELL0 = 4  # ℓ_i0, in-plane half-length of a family-i yarn between crossings (m)
P_H0 = 6  # h_i0, crimp amplitude (m)
P_TU = 8  # T_ui, ultimate yarn tension (N)
P_WIDTH = 10  # b_i, yarn width (m)
P_LT0 = 12  # L_i0 = √(ℓ_i0² + h_i0²), initial half-truss length (m) — derived
P_COMP_A = 14  # a, compaction law F = b δ / (a − δ) (m)
P_COMP_B = 15  # b (N)
P_G1 = 16  # trellis shear modulus before locking (Pa)
P_G2 = 17  # trellis shear modulus after full compaction (Pa)
P_GAMMA1 = 18  # γ1, true shear angle where parallel yarns touch (rad) — derived
P_GAMMA2 = 19  # γ2, true shear angle of full compaction (rad) — derived
P_BETA1 = 20  # β1 of the thesis shear variant, eq. (6.32) (rad) — derived
P_BETA2 = 21  # β2 of the thesis shear variant, eq. (6.33) (rad) — derived
P_THICK = 22  # t, shell (fabric) thickness (m), default 2 (h_w0 + h_f0)
P_SOFT = 23  # Δε_s, softening strain of progressive failure (—)
P_HOMOG = 24  # homogenisation option: HOMOG_VIRIAL or HOMOG_THESIS
P_SHEAR = 25  # shear option: SHEAR_TRUE or SHEAR_THESIS
P_FRAME = 26  # frame option: FRAME_FIBRE or FRAME_GREEN_NAGHDI
P_FAILURE = 27  # failure option: FAILURE_INSTANT or FAILURE_PROGRESSIVE
P_AREAL_MASS = 28  # μ, areal mass (kg/m²) — derived or measured
P_ERODE_STRETCH = 29  # erode once a broken family is stretched past this (—), 0: never
P_CROSSOVER = 30  # crossover evaluation: CROSSOVER_EXACT or CROSSOVER_TABLE (theory §1.9)
P_TAB_NW = 31  # n_w, knots of the stored-energy table along λ_w (0: no table)
P_TAB_NF = 32  # n_f, knots along λ_f
P_TAB_START = 33  # s, index in the row where the table starts (= N_PARAM)
P_TAB_NBW = 34  # m_w, buckets of the uniform knot-lookup map along λ_w
P_TAB_NBF = 35  # m_f, along λ_f
P_TAB_IBW = 36  # 1 / bucket width along λ_w
P_TAB_IBF = 37  # 1 / bucket width along λ_f
P_TAB_DATA = 38  # index in the row of the first knot's data (= s + n_w + n_f + m_w + m_f)
P_ERODE_CRUSH = 39  # with a family broken, erode once either is crushed below this (—), 0: never
P_ERODE_INTACT = 40  # intact too: erode once λ_w λ_f falls below this (—), 0: never (default)
# --- element-size regularisation of failure (theory §1.4, "Failure that does not move with
# the mesh"). The kernels never read these: they set each point's S_TU_SCALE, S_SOFT and
# S_ERODE_LIMIT at the start of a run (materials.fabric.regularised_columns), from the
# point's element lengths h_w, h_f along the two families.
P_REG_LENGTH = 41  # h_ref,i, reference length of family i (m): the crossover cell 2ℓ_i0 unless given
P_SOFT_OPENING = 43  # δ_s, post-peak opening of a yarn (m): Δε_s,i = δ_s / (s_i h_i); 0: none
P_ERODE_OPENING = 44  # δ_e, a broken family erodes once opened by this (m): λ_lim = 1 + δ_e/h_i;
#                       0: the fixed stretch P_ERODE_STRETCH
P_REG_ROWS = 45  # rows of the strength-scale table (0: no scaling, s = 1)
P_REG_TABLE = 46  # row k: h_i/h_ref,i at P_REG_TABLE + 2k, scale s of T_u at + 2k + 1
REG_ROWS_MAX = 16
# the smallest T_u scale s_i of the model's points of this material, per family (1 without a
# table): the vector element stage flags a point at s_floor T_u for the exact path, which
# applies the point's own s_i T_u (shell_blocks.crossover_points). Set by build_model.
P_TU_FLOOR = P_REG_TABLE + 2 * REG_ROWS_MAX
N_PARAM = P_TU_FLOOR + 2

CROSSOVER_EXACT = 0
CROSSOVER_TABLE = 1

# --- tabulated crossover (theory §1.9), appended to the parameter row ----------------
# From p[s] on (s = P_TAB_START; n_w, n_f, m_w, m_f as above):
#   p[s : s + n_w]                    knots λ_w (increasing, non-uniform)
#   p[s + n_w : s + n_w + n_f]        knots λ_f
#   next m_w, then m_f entries        bucket maps: bucket b = ⌊(λ − λ_first)·(1/width)⌋
#                                     holds the index of the knot interval containing its
#                                     left edge (widths ≤ the smallest knot spacing / 2,
#                                     so locating a point is O(1): no search)
#   p[P_TAB_DATA + TAB_STRIDE (i n_f + j) + q]: knot (i, j), entry q:
T_W = 0  # W, crossover stored energy per unit reference area (J/m²), shear excluded
T_W_W = 1  # ∂W/∂λ_w
T_W_F = 2  # ∂W/∂λ_f
T_W_WF = 3  # ∂²W/∂λ_w∂λ_f
T_HW = 4  # H_w (m), then ∂H_w/∂λ_w, ∂H_w/∂λ_f, ∂²H_w/∂λ_w∂λ_f at T_HW + 1..3
T_HF = 8  # H_f (m), and its three derivatives at T_HF + 1..3
T_EXACT = 12  # 1.0: the cell [λ_w,i, λ_w,i+1] × [λ_f,j, λ_f,j+1] is solved exactly (its
#              interpolant missed the accuracy target at build time), 0.0: interpolated
TAB_STRIDE = 13

HOMOG_VIRIAL = 0
HOMOG_THESIS = 1
SHEAR_TRUE = 0
SHEAR_THESIS = 1
FRAME_FIBRE = 0
FRAME_GREEN_NAGHDI = 1
FAILURE_INSTANT = 0
FAILURE_PROGRESSIVE = 1

# --- state (history variables and outputs of one material point) -------------
S_H = 0  # H_i, current crimp height of family i (m); S_H + 1 for fill
S_DAMAGE = 2  # d_i ∈ [0, 1], yarn damage (1 = broken)
S_LAMBDA = 4  # λ_i, stretch of family i (accumulated in the Green–Naghdi option)
S_GAMMA = 6  # γ, trellis shear angle (rad)
S_TAU = 7  # τ, trellis shear stress (Pa)
S_TENSION = 8  # T_i, yarn tension (N)
S_ALIVE = 10  # 1.0 while at least one family is intact, 0.0 once eroded
S_ENERGY = 11  # stored energy per unit reference area (J/m²): yarns + compaction + shear
S_SHEAR_ENERGY = 12  # shear part of S_ENERGY (J/m²)
S_ITER = 13  # iterations of the last height solve
# per point, set at the start of a run from its element's lengths and never changed (theory §1.4):
S_TU_SCALE = 14  # s_i, the scale of family i's T_u (1: unregularised); S_TU_SCALE + 1 for fill
S_SOFT = 16  # Δε_s,i, family i's softening strain of progressive failure (—)
S_ERODE_LIMIT = 18  # λ_lim,i: a broken family i stretched past it erodes the point (0: never)
N_STATE = 20

# --- status codes returned per point -----------------------------------------
STATUS_OK = 0
STATUS_NOT_CONVERGED = 1  # height solve exceeded its iteration budget
STATUS_BAD_KINEMATICS = 2  # stretch ≤ 0, yarns parallel or inverted, or non-finite input

STATUS_TEXT = {
    STATUS_OK: "ok",
    STATUS_NOT_CONVERGED: "crimp-height solve did not converge",
    STATUS_BAD_KINEMATICS: "inadmissible deformation (stretch ≤ 0, yarns parallel, or NaN)",
}
