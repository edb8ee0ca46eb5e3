"""materials/crimp.py and calibration/crimp.py: crimp amplitude of a cosine yarn, thesis
eq. (5.1)–(5.5)."""

from __future__ import annotations

import itertools
import math
import sys

import pytest
from hypothesis import given
from hypothesis import strategies as st
from scipy.integrate import quad

from wovenimpact.calibration.crimp import calibrate_crimp
from wovenimpact.materials.crimp import (
    crimp_amplitude,
    crimp_of_amplitude,
    half_length_from_thread_count,
)

INCH = 0.0254
N_27_TPI = 27 / INCH  # threads per metre
H0_TABLE_5_1 = 0.12495e-3  # m, thesis Table 5-1 (Maple)
H0_EXACT = 0.12480e-3  # m, the integral solved to machine precision (docs/model.md §1)
THESIS_REL = 5e-3  # the thesis's printed h0 and ours agree to 0.5 %


def test_half_length_is_half_the_crossing_pitch():
    assert half_length_from_thread_count(N_27_TPI) == pytest.approx(0.47037e-3, rel=1e-5)


@pytest.mark.parametrize("n", [0.0, -1.0, math.nan])
def test_half_length_rejects_non_positive_thread_count(n):
    with pytest.raises(ValueError, match="thread count"):
        half_length_from_thread_count(n)


def test_h0_of_the_thesis_fabric():
    h0 = crimp_amplitude(half_length_from_thread_count(N_27_TPI), 0.0421)
    assert h0 == pytest.approx(H0_TABLE_5_1, rel=THESIS_REL)
    assert h0 == pytest.approx(H0_EXACT, abs=0.000005e-3)  # 0.12480 mm to the printed digits


def test_h0_solves_the_arc_length_integral_of_eq_5_5():
    """Independent oracle: quadrature of eq. (5.5) instead of the elliptic integral."""
    ell = half_length_from_thread_count(N_27_TPI)
    h0 = crimp_amplitude(ell, 0.0421)
    k = math.pi * h0 / (2 * ell)
    length, _ = quad(
        lambda x: math.sqrt(1 + k * k * math.sin(math.pi * x / (2 * ell)) ** 2),
        0.0,
        ell,
        epsabs=0.0,
        epsrel=1e-13,
    )
    assert length == pytest.approx(ell * (1 + 0.0421), rel=1e-12)


def test_calibrate_crimp_gives_thickness_four_h0():
    r = calibrate_crimp(N_27_TPI, 0.0421)
    assert r.half_length_m == pytest.approx(0.5 / N_27_TPI, rel=1e-15)
    assert r.h0_m == pytest.approx(H0_TABLE_5_1, rel=THESIS_REL)
    assert r.thickness_m == 4 * r.h0_m


def test_zero_crimp_gives_a_straight_yarn():
    assert crimp_amplitude(0.47e-3, 0.0) == 0.0
    assert crimp_of_amplitude(0.0, 0.47e-3) == pytest.approx(0.0, abs=1e-16)


@pytest.mark.parametrize("c", [-1e-6, -0.0421, math.nan])
def test_negative_crimp_is_rejected(c):
    with pytest.raises(ValueError, match="crimp"):
        crimp_amplitude(0.47e-3, c)


@given(
    # ℓ from 0.1 mm to 10 mm: thread counts from 127 down to 1.3 per inch.
    ell=st.floats(min_value=1e-4, max_value=1e-2),
    c=st.floats(min_value=0.0, max_value=1.0),
)
def test_crimp_of_amplitude_inverts_crimp_amplitude(ell, c):
    h = crimp_amplitude(ell, c)
    assert h >= 0.0
    assert crimp_of_amplitude(h, ell) == pytest.approx(c, abs=1e-12)


def test_crimp_amplitude_accuracy_does_not_depend_on_the_length_scale():
    ell, c = 1e-5, 0.5625  # found by hypothesis
    assert crimp_of_amplitude(crimp_amplitude(ell, c), ell) == pytest.approx(c, abs=1e-12)


@pytest.mark.parametrize("k", [0.01, 0.03, 0.1, 0.3])
def test_small_amplitude_limit(k):
    """c = k²/4 − 3k⁴/64 + 5k⁶/256 − …, k = π h / (2ℓ) (series of E(−k²), alternating).

    The leading term is the asymptote; the error of each truncation is below the
    first omitted term, plus the rounding of c = (2/π) E − 1, a difference from 1
    (a few machine epsilons in absolute terms).
    """
    rounding = 4 * sys.float_info.epsilon
    ell = 0.47e-3
    h = 2 * ell * k / math.pi
    c = crimp_of_amplitude(h, ell)
    assert abs(c - k**2 / 4) <= 3 * k**4 / 64 + rounding
    assert abs(c - (k**2 / 4 - 3 * k**4 / 64)) <= 5 * k**6 / 256 + rounding


def test_crimp_grows_with_amplitude():
    ell = 0.47e-3
    values = [crimp_of_amplitude(h, ell) for h in (0.0, 0.05e-3, 0.1e-3, 0.2e-3, 1e-3)]
    assert all(a < b for a, b in itertools.pairwise(values))
