"""kernels/hex8.py, kernels/polar3.py, kernels/transverse_isotropic.py and
materials/transverse_isotropic.py: the one-point hexahedron with Flanagan–Belytschko
stiffness hourglass control and the transversely isotropic material (docs/solid.md).

Every check is against something the kernels do not compute themselves: NumPy 2×2×2 Gauss
quadrature of the trilinear element, scipy's polar decomposition, a compliance matrix
written out here, finite-difference stiffness matrices and their NumPy eigenvalues, and
closed forms derived in the docstrings.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg
from hypothesis import assume, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from tests.verification.hex_driver import PARENT, THESIS_YARN, HexModel, box_mesh
from wovenimpact.errors import InputError
from wovenimpact.kernels import solid_layout as L
from wovenimpact.materials.transverse_isotropic import (
    TransverseIsotropicParameters,
    initial_state,
    material_frame,
    update_points,
)

H = 1e-3  # m, edge of the reference cube
ROUND_OFF = 1e-12  # identities that hold to round-off (relative)
EXACT = 1e-10  # acceptance of the exactness tests (patch, objectivity): relative
SMALL_STRAIN = 1e-7  # strain of the modulus tests: finite-strain terms are O(1e-7)
MODULUS_TOL = 1e-6  # σ/ε against the modulus, relative (≫ SMALL_STRAIN, ≪ any wrong term)

SIG = slice(L.H_SIG, L.H_SIG + 6)
VOIGT = ((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))


def full(v):
    """3×3 from Voigt (tensor components)."""
    a = np.zeros((3, 3))
    for k, (i, j) in enumerate(VOIGT):
        a[i, j] = a[j, i] = v[k]
    return a


def cube_nodes(h=H):
    return 0.5 * h * PARENT + 0.5 * h


def distorted(rng, amount=0.15, h=H):
    """A cube with each corner moved by up to ``amount`` h (Jacobian positive everywhere)."""
    return cube_nodes(h) + amount * h * rng.uniform(-1.0, 1.0, (8, 3))


def gauss_points(x):
    """The trilinear element at nodes x at its 2×2×2 Gauss points: (∂N/∂ξ (8, 3), the
    Jacobian ∂x/∂ξ) at each, weights 1."""
    g = 1.0 / math.sqrt(3.0)
    xi, eta, zeta = PARENT.T
    for a in (-g, g):
        for b in (-g, g):
            for c in (-g, g):
                dn = np.stack([xi * (1 + eta * b) * (1 + zeta * c),
                               eta * (1 + xi * a) * (1 + zeta * c),
                               zeta * (1 + xi * a) * (1 + eta * b)], axis=1) / 8.0
                yield dn, x.T @ dn


def gauss_oracle(x):
    """V = ∫ det J and B_I = ∫ ∇N_I dV of the trilinear element, 2×2×2 Gauss (exact for
    both: det J and cof J ∂N/∂ξ are at most cubic in each parent coordinate)."""
    vol, big_b = 0.0, np.zeros((8, 3))
    for dn, jac in gauss_points(x):
        det = np.linalg.det(jac)
        big_b += dn @ np.linalg.inv(jac) * det
        vol += det
    return vol, big_b


def one_element(x0, params=THESIS_YARN, frame=np.eye(3), hourglass=0.05):
    return HexModel(np.asarray(x0, dtype=float), np.arange(8)[None, :], params, frame,
                    hourglass)


def jump(model, x, state=None, x_prev=None):
    """One step of the element from ``state`` at ``x_prev`` (default: the virgin state at
    the reference positions) straight to positions x (the increment x − x_prev over
    Δt = 1). Returns (nodal forces, new state rows, every column written)."""
    el_in = model.state() if state is None else state
    x = np.asarray(x, dtype=float)
    x_prev = model.nodes if x_prev is None else x_prev
    el_out = np.full_like(el_in, np.nan)
    f, _, _ = model.forces(x, x - x_prev, 1.0, el_in, el_out)
    assert np.all(np.isfinite(el_out))
    return f, el_out


def rotations():
    return st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1),
                     st.floats(0.05, math.pi)).filter(
        lambda r: np.linalg.norm(r[:3]) > 0.1).map(
        lambda r: Rotation.from_rotvec(np.array(r[:3]) / np.linalg.norm(r[:3]) * r[3])
        .as_matrix())


# --- geometry ----------------------------------------------------------------------
@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), amount=st.floats(0.0, 0.2))
def test_volume_and_gradients_are_the_exact_integrals(seed, amount):
    x = distorted(np.random.default_rng(seed), amount)
    model = one_element(x)
    vol, big_b = gauss_oracle(x)
    assert model.mesh.vol0[0] == pytest.approx(vol, rel=ROUND_OFF)
    b = model.mesh.ref_grad[0].T  # (8, 3)
    assert np.abs(b * vol - big_b).max() <= ROUND_OFF * np.abs(big_b).max()
    # Σ_I b_I = 0 and Σ_I x_I ⊗ b_I = I: a linear field has the exact gradient
    assert np.abs(b.sum(axis=0)).max() <= ROUND_OFF / H
    assert np.abs(x.T @ b - np.eye(3)).max() <= ROUND_OFF


def test_hourglass_stiffness_of_a_cube():
    """k = r G_hg V0 Σ b·b = 3/2 r G_hg h on a cube (docstring of kernels/hex8.py)."""
    model = one_element(cube_nodes(), hourglass=0.05)
    assert model.mesh.hg_stiffness[0] == pytest.approx(
        1.5 * 0.05 * THESIS_YARN.hourglass_modulus * H, rel=ROUND_OFF)


# --- polar decomposition -------------------------------------------------------------
@settings(max_examples=200, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), size=st.floats(0.0, 0.8))
def test_polar_decomposition_matches_scipy(seed, size):
    rng = np.random.default_rng(seed)
    f = Rotation.random(random_state=int(rng.integers(2**31))).as_matrix() @ (
        np.eye(3) + size * rng.uniform(-1, 1, (3, 3)))
    assume(np.linalg.det(f) > 0.05)
    _, u_ref = scipy.linalg.polar(f, side="right")
    state = update_points(THESIS_YARN, np.eye(3), f, initial_state(1))[0]
    u = full(state[L.H_U:L.H_U + 6])
    assert np.abs(u - u_ref).max() <= ROUND_OFF * np.abs(u_ref).max()


# --- objectivity -------------------------------------------------------------------
@pytest.mark.parametrize("axis", [(0, 0, 1), (1, 0, 0), (1, 2, 3)])
def test_rigid_rotation_of_90_degrees_gives_zero_stress(axis):
    x0 = distorted(np.random.default_rng(3))
    q = Rotation.from_rotvec(np.array(axis) / np.linalg.norm(axis) * math.pi / 2).as_matrix()
    frame = material_frame([1.0, 1.0, 0.2])
    model = one_element(x0, frame=frame)
    f, out = jump(model, x0 @ q.T)
    e11 = THESIS_YARN.e11
    assert np.abs(out[0, SIG]).max() <= EXACT * e11
    assert np.abs(out[0, L.H_TAU:L.H_TAU + 6]).max() <= EXACT * e11
    assert np.abs(f).max() <= EXACT * e11 * H * H
    assert abs(out[0, L.H_W]) <= EXACT * e11 * H**3
    # a control: the same step with a stretch does stress the element
    f2, out2 = jump(model, 1.001 * x0 @ q.T)
    assert np.abs(out2[0, SIG]).max() > 1e-4 * THESIS_YARN.e22


def test_prestressed_element_rotated_rigidly_carries_its_stress_along():
    """σ' = Q σ Qᵀ, the same energy, and hourglass forces turned with Q."""
    rng = np.random.default_rng(11)
    x0 = distorted(rng)
    model = one_element(x0, frame=material_frame([0.3, 1.0, 0.4], [0.0, 0.0, 1.0]),
                        hourglass=0.5)
    strain = np.eye(3) + 1e-3 * rng.uniform(-1, 1, (3, 3))
    hourglass_pattern = 1e-5 * np.outer(PARENT[:, 0] * PARENT[:, 1], [0.3, -1.0, 0.5])
    x1 = x0 @ strain.T + hourglass_pattern
    f1, s1 = jump(model, x1)
    q = Rotation.from_rotvec([0.0, 0.0, math.pi / 2]).as_matrix()
    f2, s2 = jump(model, x1 @ q.T, state=s1, x_prev=x1)
    sig1, sig2 = full(s1[0, SIG]), full(s2[0, SIG])
    assert np.abs(sig2 - q @ sig1 @ q.T).max() <= EXACT * np.abs(sig1).max()
    assert np.abs(f2 - f1 @ q.T).max() <= EXACT * np.abs(f1).max()
    assert s2[0, L.H_W] == pytest.approx(s1[0, L.H_W], rel=EXACT)
    assert s2[0, L.H_W_HG] == pytest.approx(s1[0, L.H_W_HG], rel=EXACT)
    assert s1[0, L.H_W_HG] > 0.0


# --- material: moduli ----------------------------------------------------------------
def compliance(e11, e22, g12, g23, nu12, nu23):
    """ε = S σ in the material axes, Voigt with engineering shears (written out here)."""
    s = np.diag([1 / e11, 1 / e22, 1 / e22, 1 / g23, 1 / g12, 1 / g12])
    s[0, 1] = s[1, 0] = s[0, 2] = s[2, 0] = -nu12 / e11
    s[1, 2] = s[2, 1] = -nu23 / e22
    return s


materials = st.builds(
    lambda e11, r22, r12, r23, nu12, nu23: (e11, e11 * r22, e11 * r22 * r12, e11 * r22 * r23,
                                            nu12, nu23),
    st.floats(1e9, 200e9), st.floats(0.01, 1.0), st.floats(0.1, 2.0), st.floats(0.1, 2.0),
    st.floats(0.0, 0.45), st.floats(-0.4, 0.45))


@settings(max_examples=150, deadline=None)
@given(consts=materials, frame_rot=rotations(), rigid=rotations(),
       axis=st.sampled_from([0, 1, 2]))
def test_uniaxial_stress_along_a_material_axis_gives_its_modulus(consts, frame_rot, rigid,
                                                                axis):
    """Stress along a1 gives E11, along a2 or a3 gives E22, the others zero, for any
    orientation of the material axes and any rigid rotation of the deformed point."""
    e11, e22, g12, g23, nu12, nu23 = consts
    params = TransverseIsotropicParameters(e11=e11, e22=e22, g12=g12, g23=g23, nu12=nu12,
                                           nu23=nu23, density=1000.0)
    m0 = frame_rot  # rows: the material axes in global components
    unit = np.zeros(6)
    unit[axis] = 1.0
    eps_m = compliance(e11, e22, g12, g23, nu12, nu23) @ unit
    eps_m *= SMALL_STRAIN / eps_m[axis]
    strain_m = np.diag(eps_m[:3])  # no shear strain under a normal stress
    f = rigid @ (np.eye(3) + m0.T @ strain_m @ m0)
    state = update_points(params, m0, f, initial_state(1))[0]
    axes_now = rigid @ m0.T  # current material axes (columns)
    sig_m = axes_now.T @ full(state[SIG]) @ axes_now
    modulus = (e11, e22, e22)[axis]
    assert sig_m[axis, axis] / SMALL_STRAIN == pytest.approx(modulus, rel=MODULUS_TOL)
    others = np.abs(sig_m).copy()
    others[axis, axis] = 0.0
    assert others.max() <= MODULUS_TOL * abs(sig_m[axis, axis])


@settings(max_examples=60, deadline=None)
@given(angle=st.floats(0.0, math.pi), nu23=st.floats(-0.4, 0.45))
def test_isotropic_across_the_fibre_when_g23_is_the_isotropic_value(angle, nu23):
    """With G23 = E22 / (2 (1 + ν23)) a stress along any direction ⟂ a1 gives E22."""
    e22 = 3.28e9
    params = TransverseIsotropicParameters(e11=96e9, e22=e22, g12=3.28e9,
                                           g23=e22 / (2 * (1 + nu23)), nu12=0.0, nu23=nu23,
                                           density=1440.0)
    assert params.is_isotropic_across
    n = np.array([0.0, math.cos(angle), math.sin(angle)])  # a1 = x
    t = np.array([0.0, -math.sin(angle), math.cos(angle)])
    eps = SMALL_STRAIN * (np.outer(n, n) - nu23 * np.outer(t, t))
    state = update_points(params, np.eye(3), np.eye(3) + eps, initial_state(1))[0]
    sig = full(state[SIG])
    assert n @ sig @ n / SMALL_STRAIN == pytest.approx(e22, rel=MODULUS_TOL)
    assert np.abs(sig - (n @ sig @ n) * np.outer(n, n)).max() <= MODULUS_TOL * e22 * SMALL_STRAIN
    assert not THESIS_YARN.is_isotropic_across  # Table 5-2's G23 = E22 is not that value


def test_stored_energy_is_half_strain_stress():
    rng = np.random.default_rng(5)
    eps = 1e-6 * rng.uniform(-1, 1, (3, 3))
    eps = 0.5 * (eps + eps.T)
    state = update_points(THESIS_YARN, np.eye(3), np.eye(3) + eps, initial_state(1))[0]
    assert state[L.H_W] == pytest.approx(0.5 * np.sum(full(state[SIG]) * eps), rel=1e-5)


# --- hourglass -----------------------------------------------------------------------
HG_AMPLITUDE = 1e-10  # m: q/H = 1e-7, the size of the geometric terms dropped below
FIRST_ORDER = 1e-6  # closed forms of the undeformed cube hold to O(q/H) (relative)


@pytest.mark.parametrize("mode", range(4))
@pytest.mark.parametrize("direction", range(3))
def test_hourglass_mode_of_a_cube_is_resisted_and_its_energy_booked(mode, direction):
    """u_I = q h_αI e_i: no strain at the point, corner forces k q h_αI/8 e_i (γ = h/8),
    work f·u = k q² > 0, hourglass energy ½ k q² (to first order in q/h)."""
    h_alpha = np.array([L.HEX_H1, L.HEX_H2, L.HEX_H3, L.HEX_H4][mode])
    q = HG_AMPLITUDE
    u = np.zeros((8, 3))
    u[:, direction] = q * h_alpha
    model = one_element(cube_nodes())
    k = model.mesh.hg_stiffness[0]
    f, out = jump(model, cube_nodes() + u)
    # zero to the round-off of F (a strain q/h would give E11 q/h = 1e7 times more)
    assert np.abs(out[0, SIG]).max() <= ROUND_OFF * THESIS_YARN.e11
    expected = np.zeros((8, 3))
    expected[:, direction] = k * q * h_alpha / 8.0
    assert np.abs(f - expected).max() <= FIRST_ORDER * k * q
    assert np.sum(f * u) == pytest.approx(k * q * q, rel=FIRST_ORDER)
    assert out[0, L.H_W_HG] == pytest.approx(0.5 * k * q * q, rel=FIRST_ORDER)


def full_integration_energy(x, u, c_voigt):
    """½ ∫ ε : C : ε dV of the trilinear element, 2×2×2 Gauss (small strain)."""
    energy = 0.0
    for dn, jac in gauss_points(x):
        grad = u.T @ (dn @ np.linalg.inv(jac))
        eps = 0.5 * (grad + grad.T)
        ev = np.array([eps[0, 0], eps[1, 1], eps[2, 2],
                       2 * eps[1, 2], 2 * eps[0, 2], 2 * eps[0, 1]])
        energy += 0.5 * ev @ c_voigt @ ev * np.linalg.det(jac)
    return energy


def physical_coefficient(mode, direction):
    """r at which a cube's hourglass energy equals the fully integrated element's, for an
    isotropic ν = 0 material (G_hg = G): ½ k q² = ½ ∫ ε:C:ε dV with k = 3/2 r G h gives
    r = 8/3 for a displacement in the plane of a two-index mode (ηζ, ξζ, ξη), 16/9 across
    it, and 32/27 for ξηζ (docs/solid.md, "Scale of r")."""
    if mode == 3:
        return 32.0 / 27.0
    across = (0, 1, 2)[mode]  # ηζ: x, ξζ: y, ξη: z
    return 16.0 / 9.0 if direction == across else 8.0 / 3.0


@pytest.mark.parametrize("mode", range(4))
@pytest.mark.parametrize("direction", range(3))
def test_scale_of_r_against_the_fully_integrated_element(mode, direction):
    g = 10e9
    iso = TransverseIsotropicParameters(e11=2 * g, e22=2 * g, g12=g, g23=g, nu12=0.0,
                                        nu23=0.0, density=1000.0)
    model = one_element(cube_nodes(), params=iso, hourglass=physical_coefficient(mode,
                                                                                 direction))
    h_alpha = np.array([L.HEX_H1, L.HEX_H2, L.HEX_H3, L.HEX_H4][mode])
    u = np.zeros((8, 3))
    u[:, direction] = HG_AMPLITUDE * h_alpha
    _, out = jump(model, cube_nodes() + u)
    reference = full_integration_energy(cube_nodes(), u, iso.stiffness())
    assert out[0, L.H_W_HG] == pytest.approx(reference, rel=FIRST_ORDER)
    assert out[0, L.H_W] <= ROUND_OFF * reference  # the one point sees no strain


@settings(max_examples=40, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_linear_fields_produce_no_hourglass_force(seed):
    rng = np.random.default_rng(seed)
    x0 = distorted(rng, 0.2)
    model = one_element(x0, hourglass=1.0)
    grad = 1e-3 * rng.uniform(-1, 1, (3, 3))
    x1 = x0 + x0 @ grad.T + 1e-4 * rng.uniform(-1, 1, 3)
    _, out = jump(model, x1)
    k = model.mesh.hg_stiffness[0]
    assert np.abs(out[0, L.H_HG:L.H_HG + 12]).max() <= ROUND_OFF * k * 1e-3 * H
    assert abs(out[0, L.H_W_HG]) <= ROUND_OFF * k * (1e-3 * H) ** 2
    # a control: a hourglass pattern added to the same field is seen
    _, out2 = jump(model, x1 + 1e-6 * H * np.outer(PARENT.prod(axis=1), [1.0, 0.0, 0.0]))
    assert out2[0, L.H_W_HG] > 0.0


def test_hourglass_mode_vibrates_at_its_frequency_and_keeps_its_energy():
    """A free cube started in a hourglass mode: ω² = k / (ρ V) (γ = h/8, modal mass ρV),
    energy passed between kinetic and hourglass, no stress; central differences give
    ω_Δ = (2/Δt) arcsin(ω Δt / 2)."""
    model = one_element(cube_nodes(), hourglass=0.5)
    k = model.mesh.hg_stiffness[0]
    rho_v = THESIS_YARN.density * H**3
    omega = math.sqrt(k / rho_v)
    dt = 0.05 * 2.0 / omega
    v0 = np.zeros((8, 3))
    v0[:, 1] = 0.01 * PARENT[:, 0] * PARENT[:, 2]  # ξζ in y
    periods = 3.0
    n_steps = int(periods * 2 * math.pi / omega / dt)
    _, _, state, hist, rec = model.run(cube_nodes(), v0, dt, n_steps,
                                       record=lambda x, v: x[6, 1] - cube_nodes()[6, 1])
    disp = np.array(rec)
    crossings = np.flatnonzero(np.diff(np.sign(disp[1:]))) + 1
    t0 = [c + disp[c] / (disp[c] - disp[c + 1]) for c in crossings]
    period = 2.0 * np.mean(np.diff(t0)) * dt
    omega_cd = 2.0 / dt * math.asin(omega * dt / 2.0)
    assert 2 * math.pi / period == pytest.approx(omega_cd, rel=1e-4)
    total = hist[:, 1] + hist[:, 2] + hist[:, 3]
    assert np.abs(total - total[0]).max() <= 1e-9 * total[0]
    assert hist[:, 3].max() == pytest.approx(total[0], rel=0.02)  # all through the spring
    # no stress to first order in the amplitude q (the current γ differ from h/8 by
    # O(q/h), which couples other modes in at second order)
    q_over_h = 0.01 / omega / H
    assert np.abs(state[0, SIG]).max() <= FIRST_ORDER * THESIS_YARN.e11 * q_over_h


# --- stable step -----------------------------------------------------------------------
def stiffness_by_differences(model, x0, delta):
    """K = ∂f/∂x of the element at its reference, central differences from the virgin
    state (one step straight to each perturbed position)."""
    n = 24
    kmat = np.zeros((n, n))
    for j in range(n):
        dx = np.zeros(n)
        dx[j] = delta
        fp, _ = jump(model, x0 + dx.reshape(8, 3))
        fm, _ = jump(model, x0 - dx.reshape(8, 3))
        kmat[:, j] = (fp - fm).ravel() / (2 * delta)
    return 0.5 * (kmat + kmat.T)


def critical_step(model, x0):
    """2 / ω_max with the lumped masses of the model (NumPy eigenvalues)."""
    kmat = stiffness_by_differences(model, x0, 1e-7 * H)
    m = np.repeat(model.mass, 3)
    omega2 = np.linalg.eigvalsh(kmat / np.sqrt(np.outer(m, m))).max()
    return 2.0 / math.sqrt(omega2)


def element_step(model, x0):
    el_in = model.state()
    el_out = model.state()
    _, dt_min, _ = model.forces(x0, np.zeros_like(x0), 0.0, el_in, el_out)
    return dt_min


def test_stable_step_of_a_cube_is_exact_without_hourglass_stiffness():
    """l_e = h and c² = λ_max(C)/ρ: exactly the single cube's critical step 2/ω_max."""
    model = one_element(cube_nodes(), frame=material_frame([1.0, 0.4, 0.3]), hourglass=0.0)
    dt_e = element_step(model, cube_nodes())
    assert dt_e == pytest.approx(H / math.sqrt(THESIS_YARN.e11 / THESIS_YARN.density),
                                 rel=ROUND_OFF)
    assert dt_e == pytest.approx(critical_step(model, cube_nodes()), rel=1e-5)


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), hourglass=st.floats(0.0, 3.0),
       iso=st.booleans())
def test_stable_step_bounds_the_critical_step_of_distorted_elements(seed, hourglass, iso):
    rng = np.random.default_rng(seed)
    x0 = distorted(rng, 0.25) * np.array([1.0, 0.5, 3.0])  # also elongated
    params = THESIS_YARN if not iso else TransverseIsotropicParameters(
        e11=70e9, e22=70e9, g12=70e9 / 2.98, g23=70e9 / 2.98, nu12=0.49, nu23=0.49,
        density=2700.0)
    model = one_element(x0, params=params, frame=Rotation.random(
        random_state=int(rng.integers(2**31))).as_matrix(), hourglass=hourglass)
    dt_e = element_step(model, x0)
    dt_crit = critical_step(model, x0)
    assert dt_e <= dt_crit * (1 + 1e-6)
    assert dt_e >= 0.5 * dt_crit  # a bound, not a gross underestimate (0.64 seen at worst)


# --- determinism -----------------------------------------------------------------------
def test_force_stage_is_bitwise_the_same_on_1_and_2_threads():
    import numba

    from wovenimpact.jit import set_threads

    rng = np.random.default_rng(2)
    nodes, hexes = box_mesh(8, 6, 5, 8e-3, 6e-3, 5e-3)
    nodes = nodes + 0.2e-3 * rng.uniform(-1, 1, nodes.shape)
    frames = np.array([material_frame(rng.normal(size=3)) for _ in hexes])
    model = HexModel(nodes, hexes, THESIS_YARN, frames, 0.1)
    x = nodes + 1e-5 * rng.uniform(-1, 1, nodes.shape)
    v = 1e2 * rng.uniform(-1, 1, nodes.shape)
    el_in = model.state()
    el_in[:, L.H_TAU:L.H_TAU + 6] = 1e6 * rng.uniform(-1, 1, (len(hexes), 6))
    el_in[:, L.H_HG:L.H_HG + 12] = 1e-2 * rng.uniform(-1, 1, (len(hexes), 12))

    def run():
        el_out = np.full_like(el_in, np.nan)  # poisoned: every column must be written
        f, dt_min, blocks = model.forces(x, v, 1e-8, el_in, el_out)
        return f, dt_min, blocks, el_out

    before = numba.get_num_threads()
    try:
        set_threads(1)
        one = run()
        set_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = run()
    finally:
        set_threads(before)
    for a, b in zip(one, two):
        assert np.array_equal(a, b)
    assert np.all(np.isfinite(one[3]))


# --- parameters ------------------------------------------------------------------------
def test_parameter_row_of_the_thesis_yarn():
    p = THESIS_YARN.to_array()
    c = np.linalg.inv(compliance(96e9, 3.28e9, 3.28e9, 3.28e9, 0.0, 0.0))
    assert p[L.TI_C11] == pytest.approx(c[0, 0], rel=ROUND_OFF)
    assert p[L.TI_C22] == pytest.approx(c[1, 1], rel=ROUND_OFF)
    assert p[L.TI_C66] == pytest.approx(c[5, 5], rel=ROUND_OFF)
    assert p[L.TI_WAVE_MODULUS] == pytest.approx(96e9, rel=ROUND_OFF)  # ν = 0: C11 = E11
    assert p[L.TI_HG_MODULUS] == pytest.approx(3.28e9, rel=ROUND_OFF)
    assert p[L.TI_RHO] == 1440.0
    coupled = TransverseIsotropicParameters(e11=96e9, e22=3.28e9, g12=2e9, g23=1.5e9,
                                            nu12=0.3, nu23=0.2, density=1440.0).to_array()
    c = np.linalg.inv(compliance(96e9, 3.28e9, 2e9, 1.5e9, 0.3, 0.2))
    for col, (i, j) in ((L.TI_C11, (0, 0)), (L.TI_C12, (0, 1)), (L.TI_C22, (1, 1)),
                        (L.TI_C23, (1, 2)), (L.TI_C44, (3, 3)), (L.TI_C66, (4, 4))):
        assert coupled[col] == pytest.approx(c[i, j], rel=ROUND_OFF)
    mandel = c.copy()
    mandel[3:, 3:] *= 2.0
    assert coupled[L.TI_WAVE_MODULUS] == pytest.approx(np.linalg.eigvalsh(mandel).max(),
                                                       rel=ROUND_OFF)


@pytest.mark.parametrize("field, value", [
    ("e11", 0.0), ("e22", -3.28e9), ("g12", float("nan")), ("g23", 0.0),
    ("density", -1.0), ("nu23", 1.0), ("nu23", -1.2), ("nu12", 4.0), ("nu12", float("inf")),
])
def test_invalid_constants_are_input_errors_naming_the_field(field, value):
    kwargs = dict(e11=96e9, e22=3.28e9, g12=3.28e9, g23=3.28e9, nu12=0.0, nu23=0.0,
                  density=1440.0, name="yarn")
    kwargs[field] = value
    with pytest.raises(InputError, match=rf"'yarn': {field} = "):
        TransverseIsotropicParameters(**kwargs)


def test_material_frame():
    m = material_frame([2.0, 0.0, 0.0], [1.0, 1.0, 0.0])
    assert np.allclose(m, np.eye(3), atol=ROUND_OFF)
    m = material_frame([1.0, 2.0, 3.0])
    assert np.allclose(m @ m.T, np.eye(3), atol=ROUND_OFF) and np.linalg.det(m) > 0
    with pytest.raises(InputError, match="fibre direction"):
        material_frame([0.0, 0.0, 0.0])
    with pytest.raises(InputError, match="second material direction"):
        material_frame([1.0, 0.0, 0.0], [2.0, 0.0, 0.0])
