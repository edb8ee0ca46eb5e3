"""Ply regression (thesis eq. 7.1 method) and Lambert–Jonas fits on known data."""

from __future__ import annotations

import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.studies.ballistics import lambert_jonas_fit, quadratic_ply_regression


def test_quadratic_through_three_points_and_the_plies_to_stop():
    """Thesis residuals 1, 2, 4 plies → 82, 58, 18 m/s: the parabola through them is
    4/3 X² − 28 X + 108.67; it reaches zero at X = 5.14, so 6 plies stop the impactor
    (the thesis's conclusion). Its printed eq. 7.1 (2.7639X² − 37.161X + 118.12) does not
    pass through its own printed residuals (83.7, 55.5, 15.1 m/s): it is reproduced
    exactly from its own values, with the same answer, 6 plies."""
    reg = quadratic_ply_regression([1, 2, 4], [82.0, 58.0, 18.0])
    assert reg.coefficients == pytest.approx((4 / 3, -28.0, 326 / 3), rel=1e-12)
    assert reg.r2 == pytest.approx(1.0)
    assert reg.root == pytest.approx(5.1381, abs=1e-4) and reg.plies_to_stop == 6
    curve = [2.7639 * x * x - 37.161 * x + 118.12 for x in (1, 2, 4)]
    thesis = quadratic_ply_regression([1, 2, 4], curve)
    assert thesis.coefficients == pytest.approx((2.7639, -37.161, 118.12), rel=1e-9)
    assert thesis.predict(5)[()] == pytest.approx(1.41, abs=0.01)
    assert thesis.plies_to_stop == 6


def test_regression_that_never_reaches_zero_says_so():
    reg = quadratic_ply_regression([1, 2, 3], [90.0, 85.0, 84.0])
    assert reg.plies_to_stop is None and reg.root is None


@pytest.mark.parametrize("c2", [0.0, 1e-17, -1e-17, 1e-12, 1e-6])
@pytest.mark.parametrize("slope, start", [(-5.0, 130.0), (-1.3, 40.0), (-17.0, 420.0)])
def test_a_nearly_straight_ladder_has_the_zero_of_its_line(c2, slope, start):
    """A fit that is a line to rounding (c2 ~ 1e-17 from exact straight-line data) must
    put the zero where the line has it: (−c1 − √disc)/2c2 cancels every digit there (it
    read 24.5 for 130 − 5 N, whose zero is 26)."""
    from wovenimpact.studies.ballistics import _first_zero

    root = _first_zero(c2, slope, start, start=1.0)
    line = -start / slope
    # the exact near root moves by c2 line² / |slope| at most (to first order)
    assert root == pytest.approx(line, rel=1e-9, abs=2 * abs(c2) * line**2 / abs(slope))
    n = np.array([2.0, 4.0, 6.0, 8.0, 12.0])
    reg = quadratic_ply_regression(n, start + slope * n)
    assert reg.root == pytest.approx(line, rel=1e-9)
    assert reg.plies_to_stop == int(np.ceil(line - 1e-9))


def test_lambert_jonas_recovers_known_parameters():
    a, p, vbl = 0.9, 2.3, 85.0
    vs = np.array([70.0, 80.0, 90.0, 100.0, 110.0, 125.0, 140.0])
    vr = a * np.clip(vs**p - vbl**p, 0, None) ** (1 / p)
    fit = lambert_jonas_fit(vs, vr)
    assert fit.v_bl == pytest.approx(vbl, rel=1e-4)
    assert fit.a == pytest.approx(a, rel=1e-4) and fit.p == pytest.approx(p, rel=1e-3)
    rng = np.random.default_rng(0)
    noisy = np.where(vr > 0, vr + rng.normal(0, 1.0, vr.shape), 0.0)
    assert lambert_jonas_fit(vs, noisy).v_bl == pytest.approx(vbl, abs=3.0)


def test_lambert_jonas_needs_perforating_runs():
    with pytest.raises(InputError, match="perforating"):
        lambert_jonas_fit([50.0, 60.0, 120.0], [0.0, 0.0, 30.0])
