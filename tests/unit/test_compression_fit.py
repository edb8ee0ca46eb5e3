"""calibration/compression.py: fit of F = b·d/(a − d), thesis eq. (5.8) and App. A."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from wovenimpact.calibration.compression import (
    compaction_force,
    fit_compression,
    plot_compression_fit,
    read_compression_csv,
)
from wovenimpact.errors import InputError

ROOT = Path(__file__).resolve().parents[2]
SHIPPED_CSV = ROOT / "examples" / "calibration" / "compression_synthetic.csv"
A_M, B_N = 0.12389e-3, 0.98432  # thesis §5.3.2 / Table 7-2
NOISY_REL = 0.02  # recovery from 1 % noise
EXACT_REL = 1e-8  # recovery from noise-free data


def synthetic(n=40, noise=0.0, seed=0):
    d = np.linspace(0.9 * A_M / n, 0.9 * A_M, n)
    F = compaction_force(d, A_M, B_N)
    if noise:
        F = F * (1.0 + noise * np.random.default_rng(seed).standard_normal(n))
    return d, F


@pytest.mark.parametrize("weighting", ["relative", "absolute"])
def test_exact_recovery_from_noise_free_data(weighting):
    d, F = synthetic()
    fit = fit_compression(d, F, weighting=weighting)
    assert fit.a_m == pytest.approx(A_M, rel=EXACT_REL)
    assert fit.b_N == pytest.approx(B_N, rel=EXACT_REL)
    assert fit.r2 == pytest.approx(1.0, abs=1e-12)
    assert fit.rmse_N < 1e-9 * B_N
    assert fit.n_points == 40 and fit.weighting == weighting


def test_recovery_from_noisy_data():
    d, F = synthetic(noise=0.01, seed=2024)
    fit = fit_compression(d, F)
    assert fit.a_m == pytest.approx(A_M, rel=NOISY_REL)
    assert fit.b_N == pytest.approx(B_N, rel=NOISY_REL)
    assert fit.r2 > 0.99
    assert fit.a_m > d.max()


def test_fit_is_the_least_squares_minimum():
    """Oracle: perturbing the fitted a or b never lowers the cost of its weighting."""
    d, F = synthetic(noise=0.01, seed=7)
    for weighting, w in (("relative", 1.0 / F), ("absolute", np.ones_like(F))):
        fit = fit_compression(d, F, weighting=weighting)

        def cost(a, b, w=w):
            return float(np.sum(((compaction_force(d, a, b) - F) * w) ** 2))

        best = cost(fit.a_m, fit.b_N)
        for da, db in ((1, 0), (-1, 0), (0, 1), (0, -1), (1, 1), (-1, -1)):
            assert cost(fit.a_m * (1 + 1e-5 * da), fit.b_N * (1 + 1e-5 * db)) >= best


def test_outlier_does_not_break_the_fit():
    d, F = synthetic()
    F = F.copy()
    F[0] *= 50.0
    fit = fit_compression(d, F, weighting="absolute")
    assert np.isfinite(fit.a_m) and fit.a_m > d.max() and fit.b_N > 0


def test_fallback_guess_when_the_line_guess_is_inadmissible():
    """F ∝ d/(a − d)²: the straight line through d/F crosses zero before max(d), so the
    line's a is below the data (inadmissible) and the fallback start is used."""
    a = 1e-4
    d = np.linspace(0.01, 0.99, 30) * a
    F = 1e-8 * d / (a - d) ** 2
    slope, intercept = np.polyfit(d, d / F, 1)
    assert -intercept / slope < d.max()  # the premise of this test
    fit = fit_compression(d, F)
    assert d.max() < fit.a_m < 1.01 * a and fit.r2 > 0.99


def test_data_without_a_compaction_limit_are_rejected():
    """F ∝ d^0.9 never stiffens: the best a runs off to infinity (a straight line)."""
    d = np.linspace(1e-6, 1e-4, 30)
    with pytest.raises(InputError, match="do not reach the compaction limit"):
        fit_compression(d, 1e4 * d**0.9)


def test_shipped_csv_recovers_the_thesis_constants(tmp_path):
    data = read_compression_csv(SHIPPED_CSV)
    assert data.d_m.size == 40
    assert data.d_m.max() == pytest.approx(0.9 * A_M, rel=1e-5)  # d_mm → m
    fit = fit_compression(data.d_m, data.F_N)
    assert fit.a_m == pytest.approx(A_M, rel=NOISY_REL)
    assert fit.b_N == pytest.approx(B_N, rel=NOISY_REL)  # F_mN → N
    assert fit.r2 > 0.99
    png = plot_compression_fit(data, fit, tmp_path / "fit.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("header", "d_scale", "F_scale"),
    [("d_m,F_N", 1.0, 1.0), ("d_mm,F_mN", 1e3, 1e3), ("d_mm,F_N", 1e3, 1.0), ("F_N,d_um", 1e6, 1)],
)
def test_csv_units_are_converted(tmp_path, header, d_scale, F_scale):
    d, F = synthetic(n=10)
    path = tmp_path / "data.csv"
    rows = [header]
    for x, y in zip(d, F):
        pair = (repr(float(x * d_scale)), repr(float(y * F_scale)))
        rows.append(",".join(pair if header.startswith("d") else pair[::-1]))
    path.write_text("\n".join(rows) + "\n")
    data = read_compression_csv(path)
    np.testing.assert_allclose(data.d_m, d, rtol=1e-14)
    np.testing.assert_allclose(data.F_N, F, rtol=1e-14)


def write(tmp_path, text: str) -> Path:
    path = tmp_path / "bad.csv"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    ("text", "expect"),
    [
        ("", "empty file"),
        ("x,y\n0.1,1\n0.2,2\n0.3,3\n", "no column named d_<unit>"),
        ("d_mm,G_N\n0.1,1\n0.2,2\n0.3,3\n", "no column named F_<unit>"),
        ("d,F\n0.1,1\n0.2,2\n0.3,3\n", "no column named d_<unit>"),
        ("d_mm,d_m,F_N\n0.1,1,1\n0.2,2,2\n0.3,3,3\n", "more than one column named d_<unit>"),
        ("d_kg,F_N\n0.1,1\n0.2,2\n0.3,3\n", "column 'd_kg': unit 'kg' has the wrong dimension"),
        ("d_mm,F_furlongs\n0.1,1\n0.2,2\n0.3,3\n", "column 'F_furlongs'"),
        ("d_mm,F_xyz\n0.1,1\n0.2,2\n0.3,3\n", "column 'F_xyz': unit 'xyz'"),
        ("d_mm,F_N\n0.1,1\n0.2,abc\n0.3,3\n", "line 3, column 'F_N': 'abc' is not a number"),
        ("d_mm,F_N\n0.1,1\n0.2,nan\n0.3,3\n", "line 3, column 'F_N': 'nan' is not a number"),
        ("d_mm,F_N\n0.1,1\n0.2\n0.3,3\n", "line 3, column 'F_N': '' is not a number"),
        ("d_mm,F_N\n0.1,1\n0.2,2\n", "2 data point(s) is not enough"),
        ("d_mm,F_N\n0.1,1\n-0.2,2\n0.3,3\n", "must be ≥ 0"),
        ("d_mm,F_N\n0.1,1\n0.1,2\n0.1,3\n", "2 distinct compressions"),
        ("d_mm,F_N\n0.1,0\n0.2,0\n0.3,0\n", "all forces are zero"),
    ],
)
def test_bad_csv_gives_input_error(tmp_path, text, expect):
    path = write(tmp_path, text)
    with pytest.raises(InputError) as err:
        read_compression_csv(path)
    msg = str(err.value)
    assert msg.startswith(str(path)) and expect in msg


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="cannot read the data file"):
        read_compression_csv(tmp_path / "none.csv")


def test_comment_lines_and_blank_lines_are_skipped(tmp_path):
    d, F = synthetic(n=5)
    body = "\n".join(f"{float(x)!r},{float(y)!r}" for x, y in zip(d, F))
    data = read_compression_csv(write(tmp_path, f"# source: FE crossover\nd_m,F_N\n\n{body}\n"))
    assert data.d_m.size == 5


def test_relative_weighting_rejects_zero_force_at_positive_compression():
    d, F = synthetic(n=10)
    F = F.copy()
    F[3] = 0.0
    with pytest.raises(InputError, match="weighting 'absolute'"):
        fit_compression(d, F)
    fit_compression(d, F, weighting="absolute")


def test_origin_point_is_accepted_by_both_weightings():
    d, F = synthetic(n=10)
    d, F = np.r_[0.0, d], np.r_[0.0, F]
    for weighting in ("relative", "absolute"):
        assert fit_compression(d, F, weighting=weighting).a_m == pytest.approx(A_M, rel=EXACT_REL)


def test_unknown_weighting():
    d, F = synthetic(n=10)
    with pytest.raises(InputError, match="weighting"):
        fit_compression(d, F, weighting="log")
