"""Ballistic post-processing: plies to stop an impactor, and the ballistic limit V50.

Two estimates a designer compares (issue 4, point 6):

- the thesis's method (eq. 7.1): fit the residual velocity against the number of
  plies with a quadratic, V_r(N) ≈ c2 N² + c1 N + c0, and read off the first whole
  number of plies at which it reaches zero;
- the Lambert–Jonas relation between striking velocity V_s and residual velocity V_r,
  V_r = a (V_s^p − V_bl^p)^{1/p} for V_s > V_bl and 0 below, fitted by least squares;
  V_bl estimates the ballistic limit V50.

Both take decided runs only (:func:`require_decided`): a run whose outcome is
``undecided`` (it ended still in contact) or ``no contact`` (it never arrived) says
nothing about the residual velocity and is refused, with the variants named.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from wovenimpact.errors import InputError


DECIDED = ("perforated", "stopped")
CONTAINMENT_DECIDED = ("escaped", "contained")


def require_decided(rows: list[dict], key: str, source: str, decided=DECIDED) -> None:
    """Refuse study rows that are not decided runs.

    Args:
        rows: finished rows of a study's results (``id``, the parameter ``key``,
            ``outcome``).
        key: the parameter column that names a variant (e.g. ``impactor.velocity``).
        source: what the rows come from (a path), for the message.
        decided: the outcomes that count as decided (``CONTAINMENT_DECIDED`` for the
            runs of a casing).

    Raises:
        InputError: a row lacks an outcome, or its outcome is not one of ``decided``
            (``perforated`` or ``stopped``); the message names each such variant by
            ``key`` and id.
    """
    if any("outcome" not in r or r["outcome"] in ("", None) for r in rows):
        raise InputError(f"{source}: no outcome recorded for some runs (results written "
                         "before outcomes were recorded, or not impact runs): run the study "
                         "again into a new output directory")
    bad = [r for r in rows if r["outcome"] not in decided]
    if bad:
        names = "; ".join(f"{key} = {r.get(key, '?')} (variant {r.get('id', '?')}): "
                          f"{r['outcome']}" for r in bad)
        raise InputError(
            f"{source}: {len(bad)} run(s) are not decided, so they cannot enter the fit — "
            f"{names}. An undecided run ended still in contact with intact material ahead: "
            "lengthen run.end_time and run the study again into a new output directory; a "
            "'no contact' run never reached the target.")


SETTLED = "fragment_exit_speed_settled"


def unsettled(row: dict) -> bool:
    """An escaped casing run whose fragment was still losing speed at its end
    (``fragment_exit_speed_settled`` false, as a bool or as results.csv text): its exit
    speed is not known. A row without the column (an older wovenimpact) is not."""
    return row.get("outcome") == "escaped" and str(row.get(SETTLED, "")).strip().lower() in (
        "false", "0")


def require_settled(rows: list[dict], key: str, source: str) -> None:
    """Refuse escaped casing runs whose exit speed was still changing at their end
    (:func:`unsettled`: the fragment still dragged torn layers), by ``key`` and id."""
    bad = [r for r in rows if unsettled(r)]
    if bad:
        names = "; ".join(f"{key} = {r.get(key, '?')} (variant {r.get('id', '?')})"
                          for r in bad)
        raise InputError(
            f"{source}: {len(bad)} escaped run(s) ended with the fragment still losing "
            f"speed, so their exit speed is not known and cannot enter the fit — {names}. "
            "Lengthen run.end_time (or keep run.stop_when_decided, which waits for the "
            "speed to settle) and run the study again into a new output directory.")


@dataclass(frozen=True)
class PlyRegression:
    """V_r(N) = c2 N² + c1 N + c0 fitted to (plies, residual velocity) points.

    Attributes:
        coefficients: (c2, c1, c0) in m/s per ply², per ply and m/s.
        r2: coefficient of determination of the fit.
        plies_to_stop: smallest whole N ≥ 1 with predicted V_r(N) ≤ 0, or None if
            the parabola never reaches zero (it turns up first).
        root: the real N where V_r(N) = 0 on the decreasing branch, or None.
    """

    coefficients: tuple[float, float, float]
    r2: float
    plies_to_stop: int | None
    root: float | None

    def predict(self, plies) -> np.ndarray:
        c2, c1, c0 = self.coefficients
        n = np.asarray(plies, dtype=float)
        return c2 * n * n + c1 * n + c0


def quadratic_ply_regression(plies, residual) -> PlyRegression:
    """Fit V_r(N) by least squares (exact through three points, as the thesis did).

    Only perforating runs (V_r > 0) carry information about the curve; the caller
    passes them. Needs at least three distinct ply counts.
    """
    n = np.asarray(plies, dtype=float)
    v = np.asarray(residual, dtype=float)
    if n.shape != v.shape or n.ndim != 1:
        raise InputError("plies and residual velocities must be 1-D sequences of equal length")
    if np.unique(n).size < 3:
        counts = ", ".join(f"{k:g}" for k in np.unique(n))
        raise InputError(f"a quadratic needs at least three distinct ply counts, got {counts}")
    c2, c1, c0 = np.polyfit(n, v, 2)
    pred = c2 * n * n + c1 * n + c0
    ss_res = float(np.sum((v - pred) ** 2))
    ss_tot = float(np.sum((v - v.mean()) ** 2))
    r2 = 1.0 - ss_res / ss_tot if ss_tot > 0 else 1.0
    root = _first_zero(c2, c1, c0, start=float(n.min()))
    stop = None if root is None else max(1, math.ceil(root - 1e-12))
    return PlyRegression((float(c2), float(c1), float(c0)), r2, stop, root)


def _first_zero(c2: float, c1: float, c0: float, start: float) -> float | None:
    """Smallest root ≥ start of c2 N² + c1 N + c0 reached while the curve decreases."""
    if abs(c2) < 1e-300:
        if c1 >= 0:
            return None
        r = -c0 / c1
        return r if r >= start else None
    disc = c1 * c1 - 4 * c2 * c0
    if disc < 0:
        return None
    # the cancellation-free form (q = −½(c1 + sign(c1) √disc); roots q/c2 and c0/q):
    # (−c1 ± √disc)/2c2 loses every digit of the near root when the fit is nearly
    # linear (c2 ~ 1e-17 from a straight ladder put the zero of 130 − 5 N at 24.5)
    q = -0.5 * (c1 + math.copysign(math.sqrt(disc), c1))
    roots = sorted(r for r in (q / c2, c0 / q if q != 0.0 else q / c2) if math.isfinite(r))
    for r in roots:
        slope = 2 * c2 * r + c1
        if r >= start and slope <= 0:
            return r
    return None


@dataclass(frozen=True)
class LambertJonas:
    """V_r = a (V_s^p − V_bl^p)^{1/p} fit (velocities in m/s)."""

    a: float
    p: float
    v_bl: float
    rms: float

    def predict(self, v_s) -> np.ndarray:
        v = np.asarray(v_s, dtype=float)
        core = np.clip(v**self.p - self.v_bl**self.p, 0.0, None)
        return self.a * core ** (1.0 / self.p)


def lambert_jonas_fit(v_striking, v_residual, fix_a: float | None = None) -> LambertJonas:
    """Least-squares Lambert–Jonas fit; V_bl is the ballistic-limit estimate (V50).

    Args:
        v_striking, v_residual: runs (m/s); stopped runs have V_r = 0 and bound V_bl
            from below.
        fix_a: hold a fixed (e.g. 1, or the rigid-plug value m_p/(m_p + m_pl)) when
            few points are available; otherwise a, p and V_bl are all fitted.
    """
    vs = np.asarray(v_striking, dtype=float)
    vr = np.asarray(v_residual, dtype=float)
    if vs.shape != vr.shape or vs.ndim != 1:
        raise InputError("striking and residual velocities must be 1-D sequences of equal length")
    perf = vr > 0
    if perf.sum() < (2 if fix_a is not None else 3):
        raise InputError(
            f"a Lambert–Jonas fit needs at least {2 if fix_a is not None else 3} perforating "
            f"runs (V_r > 0), got {int(perf.sum())}"
        )
    stopped = vs[~perf]
    lo = float(stopped.max()) if stopped.size else 0.0
    hi = float(vs[perf].min())

    def model(theta):
        a, p, vbl = (fix_a, theta[0], theta[1]) if fix_a is not None else theta
        core = np.clip(vs**p - vbl**p, 0.0, None)
        return a * core ** (1.0 / p) - vr

    v0 = 0.5 * (lo + hi) if lo > 0 else 0.5 * hi
    if fix_a is not None:
        x0, lb, ub = [2.0, v0], [1.0, lo], [10.0, hi]
    else:
        x0, lb, ub = [1.0, 2.0, v0], [0.05, 1.0, lo], [2.0, 10.0, hi]
    x0 = np.clip(x0, np.array(lb) + 1e-9, np.array(ub) - 1e-9)
    sol = least_squares(model, x0, bounds=(lb, ub))
    a, p, vbl = (fix_a, *sol.x) if fix_a is not None else sol.x
    rms = float(np.sqrt(np.mean(sol.fun**2)))
    return LambertJonas(float(a), float(p), float(vbl), rms)
