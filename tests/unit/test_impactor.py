"""Impactor geometry and mass properties against closed forms."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.impactor import Impactor, fragment_simulating_projectile

RHO = 7922.0


def test_sphere_mass_and_inertia():
    r = 3e-3
    m, zc, ia, it = Impactor("sphere", r).mass_properties()
    m_exact = 4.0 / 3.0 * math.pi * r**3 * RHO
    assert m == pytest.approx(m_exact, rel=1e-6)
    assert zc == pytest.approx(r, rel=1e-9)
    assert ia == pytest.approx(0.4 * m_exact * r * r, rel=1e-5)
    assert it == pytest.approx(0.4 * m_exact * r * r, rel=1e-5)


def test_flat_cylinder_mass_and_inertia():
    r, L = 2.78e-3, 5.72e-3
    m, zc, ia, it = Impactor("cylinder", r, L).mass_properties()
    m_exact = math.pi * r * r * L * RHO
    assert m == pytest.approx(m_exact, rel=1e-12)
    assert zc == pytest.approx(L / 2, rel=1e-12)
    assert ia == pytest.approx(0.5 * m_exact * r * r, rel=1e-12)
    assert it == pytest.approx(m_exact * (3 * r * r + L * L) / 12, rel=1e-7)


@pytest.mark.parametrize("nose, nose_length, volume", [
    ("hemispherical", 0.0, lambda r, L, ln: math.pi * r * r * (L - r) + 2 / 3 * math.pi * r**3),
    ("conical", 4e-3, lambda r, L, ln: math.pi * r * r * (L - ln) + math.pi * r * r * ln / 3),
])
def test_nosed_cylinder_volumes(nose, nose_length, volume):
    r, L = 3e-3, 12e-3
    imp = Impactor("cylinder", r, L, nose=nose, nose_length=nose_length)
    m = imp.mass_properties()[0]
    assert m == pytest.approx(RHO * volume(r, L, nose_length), rel=1e-6)


def test_ogive_is_tangent_to_the_shank_and_pointed():
    r, L, ln = 3e-3, 15e-3, 6e-3
    imp = Impactor("cylinder", r, L, nose="ogive", nose_length=ln)
    z = np.array([0.0, ln - 1e-9, ln])
    rz = imp.radius_at(z)
    assert rz[0] == pytest.approx(0.0, abs=1e-12)
    assert rz[1] == pytest.approx(r, rel=1e-6) and rz[2] == pytest.approx(r)
    slope = (imp.radius_at(ln) - imp.radius_at(ln - 1e-7)) / 1e-7
    assert abs(slope) < 1e-3  # tangent ogive: no kink at the shank


@pytest.mark.parametrize("imp", [
    Impactor("sphere", 2e-3),
    Impactor("cylinder", 2e-3, 6e-3),
    Impactor("cylinder", 2e-3, 6e-3, fillet=0.5e-3),
    Impactor("cylinder", 2e-3, 6e-3, nose="hemispherical"),
    Impactor("cylinder", 2e-3, 6e-3, nose="conical", nose_length=2e-3),
    Impactor("cylinder", 2e-3, 6e-3, nose="ogive", nose_length=3e-3),
])
def test_profile_is_a_closed_meridian_polyline_on_the_surface(imp):
    p = imp.profile()
    assert p[0, 1] == 0.0 and p[-1, 1] == 0.0  # starts and ends on the axis
    assert np.all(np.diff(p[:, 0]) >= -1e-15)  # ζ never decreases
    inner = p[1:-1]
    on_shank = inner[:, 0] > 0.0
    assert np.allclose(imp.radius_at(inner[on_shank, 0]), inner[on_shank, 1], rtol=1e-9, atol=1e-12)


def test_fragment_simulating_projectile_weighs_1_1_grams():
    fsp = fragment_simulating_projectile()
    assert fsp.mass_properties()[0] == pytest.approx(1.1e-3, rel=1e-9)
    assert 2 * fsp.radius == pytest.approx(5.56e-3)


@pytest.mark.parametrize("kwargs, field", [
    (dict(shape="sphere", radius=-1e-3), "radius"),
    (dict(shape="cylinder", radius=1e-3, length=0.5e-3, nose="hemispherical"), "length"),
    (dict(shape="cylinder", radius=1e-3, length=5e-3, nose="conical"), "nose_length"),
    (dict(shape="cylinder", radius=1e-3, length=5e-3, nose="bullet"), "nose"),
    (dict(shape="cube", radius=1e-3), "shape"),
])
def test_bad_impactors_are_rejected_naming_the_field(kwargs, field):
    with pytest.raises(InputError, match=field):
        Impactor(**kwargs)
