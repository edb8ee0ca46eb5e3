"""The named stages of the shell element (kernels/shell.py), each checked alone against
what it must satisfy: rigid motions strain nothing, linear fields are reproduced
exactly, forces balance, the plate law and the stable-step formula hold."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wovenimpact.kernels.shell import (
    bending_and_shear,
    centre_gradient,
    centre_membrane_forces,
    corner_forces,
    corotational_frame,
    element_stable_step,
    hourglass_resultants,
    family_stable_step,
    hourglass_vectors,
    kinematic_step,
    midpoint_frame,
    midpoint_rates,
)
from wovenimpact.kernels.shell_layout import E_HG, E_M, E_Q, E_U_BEND, E_U_HG, N_ELEM_STATE

RNG = np.random.default_rng(20261125)


def random_quad(rng, size=0.01, warp=0.0):
    """A convex quad about a random centre, turned by a random rotation: (px, py, pz)."""
    base = np.array([[-1.0, -1.0], [1.0, -1.0], [1.0, 1.0], [-1.0, 1.0]]) * 0.5 * size
    base = base + rng.uniform(-0.15, 0.15, base.shape) * size
    pts = np.column_stack([base, warp * size * np.array([1.0, -1.0, 1.0, -1.0])])
    q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    pts = pts @ q.T + rng.normal(size=3)
    return tuple(map(tuple, pts.T))


@pytest.mark.parametrize("seed", range(5))
def test_a_rigid_motion_gives_no_curvature_or_shear_increment(seed):
    """Velocities rigid about the midpoint configuration (the one the rates belong to):
    v = V + W × x^{n−1/2}, every corner spinning at W."""
    rng = np.random.default_rng(seed)
    mid_pts = np.array(random_quad(rng, warp=0.02)).T
    trans, spin = rng.normal(size=3) * 50.0, rng.normal(size=3) * 300.0
    vel = trans + np.cross(spin, mid_pts)
    dt = 1e-7
    pts = mid_pts + 0.5 * dt * vel
    mid = midpoint_frame(*map(tuple, pts.T), *map(tuple, vel.T), dt)
    spins = tuple(tuple(np.full(4, w)) for w in spin)
    rates = midpoint_rates(mid, *map(tuple, vel.T), *spins, dt)
    # each term is ~|W| Δt / size = 3e-3 (curvature) before the rigid parts cancel
    scale = np.linalg.norm(spin) * dt / 0.01
    assert np.abs(np.array(rates[5:])).max() < 1e-9 * scale


def test_a_linear_spin_field_bends_by_its_gradient():
    """θ_y = κ_x x̂, θ_x = −κ_y ŷ on a flat element: Δκ_x = κ Δt, Δκ_y = κ_y Δt exactly
    (the BLT gradients reproduce linear fields), no twist."""
    px, py, pz = (-0.004, 0.005, 0.006, -0.005), (-0.005, -0.004, 0.004, 0.006), (0.0,) * 4
    kap_x, kap_y, dt = 3.0, -2.0, 1e-6
    mid = midpoint_frame(px, py, pz, (0.0,) * 4, (0.0,) * 4, (0.0,) * 4, dt)
    lx, ly = mid[3]
    e1, e2 = np.array(mid[0]), np.array(mid[1])
    # local spins θ_y = κ_x x̂, θ_x = −κ_y ŷ, given to the kernel in global axes
    spins = np.array([-kap_y * y * e1 + kap_x * x * e2 for x, y in zip(lx, ly)])
    rates = midpoint_rates(mid, (0.0,) * 4, (0.0,) * 4, (0.0,) * 4, *map(tuple, spins.T), dt)
    dkx, dky, dkxy2 = rates[5:8]
    assert dkx == pytest.approx(kap_x * dt, rel=1e-12)
    assert dky == pytest.approx(kap_y * dt, rel=1e-12)
    assert abs(dkxy2) < 1e-12 * kap_x * dt


def test_the_centre_gradient_reproduces_a_homogeneous_deformation():
    ref = np.array([[-0.5, -0.4], [0.6, -0.5], [0.4, 0.5], [-0.5, 0.4]]) * 0.01
    area2 = ((ref[2, 0] - ref[0, 0]) * (ref[3, 1] - ref[1, 1])
             - (ref[3, 0] - ref[1, 0]) * (ref[2, 1] - ref[0, 1]))
    g1 = tuple((ref[[1, 2, 3, 0], 1] - ref[[3, 0, 1, 2], 1]) / area2)
    g2 = tuple((ref[[3, 0, 1, 2], 0] - ref[[1, 2, 3, 0], 0]) / area2)
    f_true = np.array([[1.07, 0.12], [-0.05, 0.93]])
    cur = ref @ f_true.T + np.array([0.3, -0.2])
    f = centre_gradient(tuple(cur[:, 0]), tuple(cur[:, 1]), g1, g2)
    np.testing.assert_allclose(np.reshape(f, (2, 2)), f_true, rtol=0, atol=1e-13)


def test_one_point_membrane_forces_balance_and_do_the_virtual_work_of_the_stress():
    g1 = (-50.0, 50.0, 50.0, -50.0)
    g2 = (-50.0, -50.0, 50.0, 50.0)  # a 1 cm square
    a0, f = 1e-4, (1.05, 0.1, -0.02, 0.97)
    n11, n22, n12 = 900.0, -40.0, 120.0
    mf_x, mf_y = centre_membrane_forces(a0, n11, n22, n12, *f, g1, g2)
    assert abs(sum(mf_x)) < 1e-12 and abs(sum(mf_y)) < 1e-12
    # virtual work: Σ f̂_I · δx_I = A0 P : δF for a virtual field δx_I = G X_I (δF = G)
    from wovenimpact.kernels.shell import first_piola
    p = np.reshape(first_piola(n11, n22, n12, *f), (2, 2))
    ref = np.array([[-0.005, -0.005], [0.005, -0.005], [0.005, 0.005], [-0.005, 0.005]])
    grad = np.array([[0.3, -0.7], [0.2, 0.5]])
    dx = ref @ grad.T
    work = np.dot(mf_x, dx[:, 0]) + np.dot(mf_y, dx[:, 1])
    assert work == pytest.approx(a0 * np.sum(p * grad), rel=1e-12)


def test_a_resultant_section_follows_the_plate_law_and_books_its_energy():
    el_in = np.zeros((1, N_ELEM_STATE))
    el_in[0, E_M:E_M + 3] = (2.0, -1.0, 0.5)
    el_in[0, E_Q:E_Q + 2] = (30.0, -20.0)
    el_in[0, E_U_BEND] = 0.125
    el_out = el_in.copy()
    e_b, nu, t, kgt, area = 70e9, 0.3, 1e-3, 0.8e9, 2e-5
    dk = (1e-3, -2e-3, 4e-4)
    dg = (3e-5, 1e-5)
    d_b, mxx, myy, mxy, qx, qy, w = bending_and_shear(
        np.uint64(0), el_in, el_out, area, False, 0.0, t, e_b, nu, kgt, 0.0, 0.0, 0.0,
        *dk, *dg)
    d = e_b * t**3 / (12.0 * (1.0 - nu**2))
    assert d_b == pytest.approx(d, rel=1e-15)
    m_new = el_in[0, E_M:E_M + 3] + d * np.array(
        [dk[0] + nu * dk[1], dk[1] + nu * dk[0], 0.5 * (1.0 - nu) * dk[2]])
    np.testing.assert_allclose([mxx, myy, mxy], m_new, rtol=1e-14)
    q_new = el_in[0, E_Q:E_Q + 2] + kgt * np.array(dg)
    np.testing.assert_allclose([qx, qy], q_new, rtol=1e-14)
    np.testing.assert_allclose(el_out[0, E_M:E_M + 3], m_new, rtol=1e-14)
    work = area * (np.dot(0.5 * (el_in[0, E_M:E_M + 3] + m_new), dk)
                   + np.dot(0.5 * (el_in[0, E_Q:E_Q + 2] + q_new), dg))
    assert el_out[0, E_U_BEND] == pytest.approx(0.125 + work, rel=1e-13)
    assert w == 1.0


def test_hourglass_resultants_ignore_linear_velocity_fields():
    px, py, pz = (-0.004, 0.005, 0.006, -0.005), (-0.005, -0.004, 0.004, 0.006), (0.0,) * 4
    frame = corotational_frame(px, py, pz)
    lx, ly = frame[3]
    gam, bb = hourglass_vectors(lx, ly, *frame[5])
    el_in = np.zeros((1, N_ELEM_STATE))
    el_in[0, E_HG:E_HG + 5] = (1.0, 2.0, 3.0, 4.0, 5.0)
    el_out = el_in.copy()
    linear = tuple(0.3 + 2.0 * x - 5.0 * y for x, y in zip(lx, ly))
    hg = hourglass_resultants(np.uint64(0), el_in, el_out, 1e6, 1e6, 1e6, gam, linear,
                              linear, linear, linear, linear, 1e-6)
    np.testing.assert_allclose(hg, (1.0, 2.0, 3.0, 4.0, 5.0), rtol=0, atol=1e-9)
    # the hourglass pattern h = (1, −1, 1, −1) loads every mode: Q += k (γ·h) Δt
    h = (1.0, -1.0, 1.0, -1.0)
    k, dt = 2e6, 1e-6
    hg = hourglass_resultants(np.uint64(0), el_in, el_out, k, k, k, gam, h, h, h, h, h, dt)
    rate = float(np.dot(gam, h))
    assert rate > 0.5
    np.testing.assert_allclose(hg, np.arange(1.0, 6.0) + k * rate * dt, rtol=1e-14)
    energy = sum(0.5 * (q0 + q1) * rate * dt for q0, q1 in zip(range(1, 6), hg))
    assert el_out[0, E_U_HG] == pytest.approx(energy, rel=1e-13)


@pytest.mark.parametrize("seed", range(3))
def test_corner_forces_sum_to_zero(seed):
    rng = np.random.default_rng(seed)
    px, py, pz = random_quad(rng)
    frame = corotational_frame(px, py, pz)
    lx, ly = frame[3]
    gam, _ = hourglass_vectors(lx, ly, *frame[5])
    a0 = frame[4]
    g1, g2 = frame[5]
    mf_x, mf_y = centre_membrane_forces(a0, *rng.normal(size=3) * 1e3, 1.0, 0.0, 0.0, 1.0,
                                        g1, g2)
    blocks = np.zeros((1, 4, 6))
    res = rng.normal(size=10) * 10.0
    fsum = corner_forces(np.uint64(0), blocks, frame, mf_x, mf_y, (0.0,) * 4, gam, *res)
    scale = np.abs(blocks[0, :, :3]).max()
    assert scale > 0.0
    np.testing.assert_allclose(blocks[0, :, :3].sum(axis=0), 0.0, atol=1e-12 * scale)
    assert fsum == pytest.approx(blocks[0, :, 0].sum(), abs=1e-12 * scale)


def test_the_stable_step_of_a_square_is_its_side_over_the_wave_speed():
    side, c_memb, mu, t = 0.005, 5e7, 0.5, 5e-4  # C_m (N/m), μ (kg/m²)
    px, py, pz = (0.0, side, side, 0.0), (0.0, 0.0, side, side), (0.0,) * 4
    a = side * side
    inertia = 0.25 * mu * a * max(t * t / 12.0, a / 8.0)
    dt = element_stable_step(px, py, pz, a, c_memb, 1e3, mu, inertia, 0.0, 1.0)
    assert dt == pytest.approx(side / math.sqrt(c_memb / mu), rel=1e-14)
    # a stiff bending term: the corners' spins govern, Δt = 2 √(I/k_θ)
    d_b, bb, kgt = 1e3, 4.0 / a, 1e3
    dt = element_stable_step(px, py, pz, a, c_memb, kgt, mu, inertia, d_b, bb)
    assert dt == pytest.approx(2.0 * math.sqrt(inertia / (a * (0.25 * kgt + d_b * bb))),
                               rel=1e-14)
    assert dt < side / math.sqrt(c_memb / mu)


def test_the_kinematic_step_lets_no_corner_pair_close_or_open_more_than_its_fraction():
    """kinematic_step (run.stable_step = "yarn"): Δt = η |Δx|²/|Δx·Δv| of the pair
    closing or opening fastest relative to its length; corners moving across their line
    (a struck node leaving its neighbours normal to the plate) or moving as a rigid
    translation do not limit the step."""
    from wovenimpact.kernels.shell_layout import KINEMATIC_FRACTION

    side = 0.005
    px, py, pz = (0.0, side, side, 0.0), (0.0, 0.0, side, side), (0.0,) * 4
    still = (0.0,) * 4
    # corner 1 runs at 100 m/s towards corner 0 along their side (length 5 mm)
    dt = kinematic_step(px, py, pz, (0.0, -100.0, 0.0, 0.0), still, still, KINEMATIC_FRACTION)
    assert dt == pytest.approx(KINEMATIC_FRACTION * side / 100.0, rel=1e-14)
    # the same pair opening (a slack yarn pulled taut within a step), alike
    dt = kinematic_step(px, py, pz, (0.0, 100.0, 0.0, 0.0), still, still, KINEMATIC_FRACTION)
    assert dt == pytest.approx(KINEMATIC_FRACTION * side / 100.0, rel=1e-14)
    # a corner leaving normal to the plate, a rigid translation
    assert kinematic_step(px, py, pz, still, still, (0.0, 0.0, 300.0, 0.0), 0.5) == math.inf
    assert kinematic_step(px, py, pz, (7.0,) * 4, (-3.0,) * 4, (1.0,) * 4, 0.5) == math.inf
    # and along a diagonal: corner 2 towards corner 0, |Δx|² = 2 side²
    diagonal = (0.0, 0.0, -50.0, 0.0), (0.0, 0.0, -50.0, 0.0), still
    closing = 2.0 * side * 50.0  # −Δx·Δv
    for eta in (KINEMATIC_FRACTION, 0.25, 0.5):  # run.kinematic_fraction: Δt ∝ η
        dt = kinematic_step(px, py, pz, *diagonal, eta)
        assert dt == pytest.approx(eta * 2.0 * side**2 / closing, rel=1e-14)


def test_a_yarn_familys_step_is_its_reference_length_over_its_wave_speed():
    """family_stable_step: a square's side along the yarns over √((k + k_s)/μ), from the
    reference gradients at its centre; a slack family (k = 0) does not limit the step."""
    side, k, k_s, mu = 0.004, 1.5e7, 4e4, 0.4775
    g = (-0.5 / side, 0.5 / side, 0.5 / side, -0.5 / side)  # ∂N_I/∂X of a square
    assert family_stable_step(k, k_s, mu, g) == pytest.approx(
        side / math.sqrt((k + k_s) / mu), rel=1e-14)
    assert family_stable_step(0.0, k_s, mu, g) == math.inf
