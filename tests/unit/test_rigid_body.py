"""Rigid-body central differences: free flight, constant force, torque-free spin."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wovenimpact.kernels.rigid_body import B_R, B_V, B_W, B_X, N_BODY_STATE, advance_body


def body(v=(0.0, 0.0, -120.0), w=(0.0, 0.0, 0.0)):
    s = np.zeros(N_BODY_STATE)
    s[B_V:B_V + 3] = v
    s[B_R:B_R + 9] = np.eye(3).ravel()
    s[B_W:B_W + 3] = w
    return s


def test_constant_force_gives_exact_uniform_acceleration():
    s = body()
    m, f, dt = 1.1e-3, np.array([0.0, 0.0, 50.0]), 1e-7
    t = 0.0
    for k in range(1000):
        advance_body(s, m, 1e-10, 2e-10, f, np.zeros(3), dt if k else 0.0, dt)
        t += dt
    # v at t − dt/2, x at t: exact for a constant force with central differences
    assert s[B_V + 2] == pytest.approx(-120.0 + f[2] / m * (t - 0.5 * dt), rel=1e-12)
    z_exact = -120.0 * t + 0.5 * f[2] / m * t * t
    assert s[B_X + 2] == pytest.approx(z_exact, rel=1e-6)


def test_spin_about_a_principal_axis_keeps_energy_and_orthonormality():
    """Torque-free spin about the axis of revolution: ω constant, R a rotation about
    that axis by ω t, kinetic energy constant."""
    s = body(v=(0, 0, 0), w=(300.0, 0.0, 0.0))
    dt = 1e-6
    kes = []
    for k in range(2000):
        kes.append(advance_body(s, 1.0, 2e-7, 5e-7, np.zeros(3), np.zeros(3), dt if k else 0.0, dt))
    r = s[B_R:B_R + 9].reshape(3, 3)
    assert np.allclose(r @ r.T, np.eye(3), atol=1e-12)
    angle = 300.0 * 2000 * dt
    expect = np.array([[1, 0, 0], [0, math.cos(angle), -math.sin(angle)],
                       [0, math.sin(angle), math.cos(angle)]])
    assert np.allclose(r, expect, atol=1e-9)
    assert np.ptp(kes[1:]) < 1e-12 * kes[1]
