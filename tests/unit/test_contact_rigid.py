"""Signed distance and penalty forces of the rigid body-of-revolution contact."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wovenimpact.impactor import Impactor
from wovenimpact.kernels.bundles import BodyContact, BodyContactOut, ContactNodes
from wovenimpact.kernels.contact_rigid import profile_distance, rigid_contact_forces

R = 2e-3


@settings(max_examples=300, deadline=None)
@given(zeta=st.floats(-3 * R, 5 * R), rho=st.floats(0.0, 3 * R))
def test_sphere_distance_is_exact(zeta, rho):
    """Sphere of radius R, tip at ζ = 0: d = |(ζ − R, ρ)| − R to the polyline's chord error."""
    prof = Impactor("sphere", R).profile(n=400)
    d, nz, nr = profile_distance(zeta, rho, prof[:, 0], prof[:, 1])
    exact = math.hypot(zeta - R, rho) - R
    chord = R * (1 - math.cos(math.pi / 800))  # sagitta of one polyline segment
    assert d == pytest.approx(exact, abs=chord + 1e-15)
    r = math.hypot(zeta - R, rho)
    # at the centre every direction is normal; near it the polyline's chord ripple moves
    # the closest point by an angle ≈ √(2 chord / r): < 1e-2 needs r > 2e4 chord ≈ 0.15 R
    if abs(exact) > 10 * chord and r > 0.25 * R:
        assert nz == pytest.approx((zeta - R) / r, abs=1e-2)
        assert nr == pytest.approx(rho / r, abs=1e-2)


@pytest.mark.parametrize("zeta, rho, expect", [
    (-1e-3, 0.5e-3, 1e-3),       # in front of the flat face
    (1e-3, 0.5e-3, -1e-3),       # inside, closest to the flat face
    (3e-3, 3e-3, 1e-3),          # beside the shank
    (3e-3, 1.5e-3, -0.5e-3),     # inside, closest to the shank
    (7e-3, 0.0, 1e-3),           # behind the tail
])
def test_flat_cylinder_distances(zeta, rho, expect):
    prof = Impactor("cylinder", R, 6e-3).profile()
    d = profile_distance(zeta, rho, prof[:, 0], prof[:, 1])[0]
    assert d == pytest.approx(expect, abs=1e-15)


def test_penalty_force_pushes_nodes_out_along_the_normal():
    """A flat-faced cylinder lying below z = −0.1 mm (its face), nodes at z = 0 with a
    contact offset h = 0.25 mm: the nodes over the face are within h of it and get
    f = k (h − d) along +z, away from the body; the node beyond the radius gets none."""
    imp = Impactor("cylinder", R, 6e-3)
    prof = imp.profile()
    axis = np.array([0.0, 0.0, -1.0])  # tail below the tip: the body lies under z = tip
    tip = np.array([0.0, 0.0, -0.1e-3])
    x = np.array([[0.0, 0.0, 0.0], [1e-3, 0.0, 0.0], [5e-3, 0.0, 0.0]])
    force = np.zeros((3, 3))
    energy = np.zeros(3)
    zero = np.zeros(3)
    # k = β m / Δt² = 1e6 N/m with β = 1, m = 1 kg, Δt = 1 ms; no dashpot, no friction
    nodes = ContactNodes(x=x, v=np.zeros((3, 3)), active=np.ones(3, np.int8), mass=np.ones(3),
                         offset=np.full(3, 0.25e-3))
    body = BodyContact(tip=tip, axis=axis, velocity=zero, spin=zero, centre=zero,
                       prof_z=prof[:, 0], prof_r=prof[:, 1], reach=10e-3, mass=1e30, beta=1.0,
                       zeta=0.0, mu=0.0)
    rigid_contact_forces(nodes, body, 1e-3, BodyContactOut(
        force=force, energy=energy, parts=np.zeros((3, 11)),
        contact_list=np.zeros(3, dtype=np.int64)))
    gap = 0.25e-3 - 0.1e-3
    assert force[0] == pytest.approx([0.0, 0.0, 1e6 * gap])
    assert force[1] == pytest.approx([0.0, 0.0, 1e6 * gap])
    assert np.all(force[2] == 0.0)  # beyond the radius: no contact
    assert energy[0] == pytest.approx(0.5 * 1e6 * gap * gap)


def test_dashpot_and_friction_act_on_the_velocity_relative_to_the_body():
    """Nodes on the flat face of a body that moves at V = (1, 0, −3) m/s and spins at
    ω = 50 rad/s about its axis: the dashpot force is −c v_n n with c = 2 ζ √β m_r/Δt,
    m_r = m/(1 + m_c/M) the node's mass reduced by the body's recoil (here the body's
    mass M equals the 2 m in contact: m_r = m/2), and v_n the normal velocity relative to the body's surface point (V + ω × r); friction
    opposes the relative tangential velocity with μ |f_n|, capped at ½ m |v_t|/Δt; the
    penalty energy is ½ k g²."""
    imp = Impactor("cylinder", R, 6e-3)
    prof = imp.profile()
    axis = np.array([0.0, 0.0, -1.0])
    tip = np.array([0.0, 0.0, -0.1e-3])
    centre = tip + 3e-3 * axis
    x = np.array([[0.0, 0.0, 0.0], [1e-3, 0.0, 0.0]])
    v = np.array([[0.0, 0.0, -1.0], [0.5, 0.0, -2.0]])
    body_v = np.array([1.0, 0.0, -3.0])
    body_w = np.array([0.0, 0.0, 50.0])
    beta, zeta, mu, dt, m = 0.1, 0.7, 0.3, 1e-7, 2e-6
    force = np.zeros((2, 3))
    energy = np.zeros(2)
    nodes = ContactNodes(x=x, v=v, active=np.ones(2, np.int8), mass=np.full(2, m),
                         offset=np.full(2, 0.25e-3))
    body = BodyContact(tip=tip, axis=axis, velocity=body_v, spin=body_w, centre=centre,
                       prof_z=prof[:, 0], prof_r=prof[:, 1], reach=10e-3, mass=2.0 * m,
                       beta=beta, zeta=zeta, mu=mu)
    rigid_contact_forces(nodes, body, dt, BodyContactOut(
        force=force, energy=energy, parts=np.zeros((2, 11)),
        contact_list=np.zeros(2, dtype=np.int64)))
    k = beta * m / dt**2
    c = 2.0 * zeta * np.sqrt(beta) * (m / 2.0) / dt
    gap = 0.25e-3 - 0.1e-3
    n = np.array([0.0, 0.0, 1.0])
    for i in range(2):
        v_rel = v[i] - (body_v + np.cross(body_w, x[i] - centre))
        vn = v_rel @ n
        f_n = k * gap - c * vn
        vt = v_rel - vn * n
        f_t = min(mu * abs(f_n), 0.5 * m * np.linalg.norm(vt) / dt)
        expect = f_n * n - f_t * vt / np.linalg.norm(vt)
        assert force[i] == pytest.approx(expect, rel=1e-12)
        assert energy[i] == pytest.approx(0.5 * k * gap * gap, rel=1e-12)
