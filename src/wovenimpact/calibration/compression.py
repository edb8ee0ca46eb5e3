"""Fit of the transverse compaction law F = b·d / (a − d) (thesis eq. 5.8, §5.3.2, App. A).

The thesis extracted the contact force F_c and the mean compression d_c of a 3D
crossover model and fitted a and b by least squares on F (App. A, Maple
``NLPsolve``), giving a = 0.12389 mm, b = 984.32 mN. :func:`fit_compression`
does the same with ``scipy.optimize.least_squares`` under the bounds a > max(d)
(the law is singular at d = a) and b > 0, starting from the straight line

    d / F = a/b − d/b

(eq. 5.8 rearranged), which is exact for noise-free data. By default the residuals
are relative (each point weighted by 1/F), so the soft start of the curve counts
as much as its stiff end; ``weighting="absolute"`` reproduces the App. A cost.
"""

from __future__ import annotations

import csv
import io
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

from wovenimpact.errors import InputError
from wovenimpact.spec.fields import read_text
from wovenimpact.units import QuantityError, to_si

MIN_POINTS = 3
MAX_A_OVER_D = 100.0  # a fit with a beyond 100 × max(d) means the data show no limit
Weighting = Literal["relative", "absolute"]


@dataclass(frozen=True)
class CompressionData:
    """Measured compaction curve in SI units.

    Attributes:
        d_m: compression d of the crossover (m), shape (n,).
        F_N: contact force F (N), shape (n,).
        source: where the data came from (file name), for messages and plots.
    """

    d_m: NDArray[np.float64]
    F_N: NDArray[np.float64]
    source: str = "<array>"


@dataclass(frozen=True)
class CompressionFit:
    """Result of :func:`fit_compression`.

    Attributes:
        a_m: a (m), the compression at which F → ∞.
        b_N: b (N); the initial stiffness is b/a.
        r2: coefficient of determination of F.
        rmse_N: root-mean-square residual of F (N).
        n_points: number of data points.
        weighting: ``"relative"`` or ``"absolute"`` residuals (see :func:`fit_compression`).
    """

    a_m: float
    b_N: float
    r2: float
    rmse_N: float
    n_points: int
    weighting: str = "relative"


MAX_COMPRESSION = 0.1  # m: a ply of fabric compacts by a fraction of a millimetre
MIN_COMPRESSION = 1e-9  # m
MAX_FORCE = 1e9  # N


def compaction_force(d: NDArray[np.float64] | float, a: float, b: float):
    """F = b·d / (a − d), thesis eq. (5.8) (N for d, a in m and b in N)."""
    return b * np.asarray(d) / (a - np.asarray(d))


def _check_data(d: NDArray[np.float64], F: NDArray[np.float64], source: str) -> None:
    if d.shape != F.shape or d.ndim != 1:
        raise InputError(f"{source}: d and F must be 1-D arrays of the same length")
    if d.size < MIN_POINTS:
        raise InputError(
            f"{source}: {d.size} data point(s) is not enough to fit a and b "
            f"(valid: at least {MIN_POINTS} rows)"
        )
    if not (np.all(np.isfinite(d)) and np.all(np.isfinite(F))):
        raise InputError(f"{source}: d and F must be finite numbers")
    if np.any(d < 0.0) or np.any(F < 0.0):
        raise InputError(
            f"{source}: d and F must be ≥ 0 (compression and compressive force are positive)"
        )
    if d.max() > MAX_COMPRESSION or F.max() > MAX_FORCE:
        raise InputError(
            f"{source}: largest d = {d.max():g} m, F = {F.max():g} N (valid: a ply's compaction, "
            f"d ≤ {MAX_COMPRESSION:g} m and F ≤ {MAX_FORCE:g} N; check the units in the header)"
        )
    if d.max() < MIN_COMPRESSION:
        raise InputError(
            f"{source}: the largest compression d = {d.max():g} m is below {MIN_COMPRESSION:g} m "
            "(valid: a measured compaction; check the units in the header)"
        )
    if np.unique(d[d > 0.0]).size < 2:
        raise InputError(f"{source}: at least 2 distinct compressions d > 0 are needed")
    if not np.any(F > 0.0):
        raise InputError(f"{source}: all forces are zero; nothing to fit")


def _initial_guess(d: NDArray[np.float64], F: NDArray[np.float64]) -> tuple[float, float]:
    """a, b from the line d/F = a/b − d/b through points with F > 0, else a safe guess."""
    ok = (d > 0.0) & (F > 0.0)
    slope, intercept = np.polyfit(d[ok], d[ok] / F[ok], 1)
    d_max = float(d.max())
    if slope < 0.0 and intercept > 0.0:
        b = -1.0 / slope
        a = intercept * b
        if a > d_max:
            return a, b
    a = 1.1 * d_max  # fallback: a just beyond the data, b from the median point
    b = float(np.median(F[ok] * (a - d[ok]) / d[ok]))
    return a, b


def fit_compression(
    d_m: NDArray[np.float64],
    F_N: NDArray[np.float64],
    source: str = "<array>",
    weighting: Weighting = "relative",
) -> CompressionFit:
    """Least-squares fit of a, b in F = b·d / (a − d) (eq. 5.8) to data in SI units.

    Args:
        d_m, F_N: compressions (m) and forces (N), shape (n,), n ≥ 3.
        source: name used in messages.
        weighting: ``"relative"`` minimises Σ ((F_model,i − F_i)/F_i)², right for a
            measurement error proportional to the force and giving the soft start of
            the curve (initial stiffness b/a) as much weight as its stiff end;
            ``"absolute"`` minimises Σ (F_model,i − F_i)², the cost of the thesis's
            App. A. Points with d = F = 0 carry no information and are skipped by
            ``"relative"``.

    Bounds: a > max(d), b > 0. R² and RMSE are of the unweighted residual in F.

    Raises:
        InputError: fewer than 3 points, negative or non-finite values, degenerate
            data, a zero force at d > 0 with relative weighting, or data so far from
            the compaction limit that a is not determined (a > 100 max(d)).
    """
    d = np.asarray(d_m, dtype=float)
    F = np.asarray(F_N, dtype=float)
    _check_data(d, F, source)
    if weighting not in ("relative", "absolute"):
        raise InputError(f"weighting = {weighting!r} is not valid: use 'relative' or 'absolute'")
    d_max = float(d.max())
    f_scale = float(np.max(F))
    a0, b0 = _initial_guess(d, F)
    # Scaled unknowns u = a/d_max (> 1) and v = b/f_scale (> 0) keep the problem O(1):
    # F/f_scale = v·dn/(u − dn) with dn = d/d_max.
    use = np.ones(d.size, dtype=bool)
    if weighting == "relative":
        zero_force = (F == 0.0) & (d > 0.0)
        if np.any(zero_force):
            i = int(np.flatnonzero(zero_force)[0])
            raise InputError(
                f"{source}: point {i + 1} has F = 0 at d = {d[i]:g} m > 0, which relative "
                "weighting cannot use (valid: F > 0 wherever d > 0, or weighting 'absolute')"
            )
        use = F > 0.0
    dn, Fn = d[use] / d_max, F[use] / f_scale
    weight = 1.0 / Fn if weighting == "relative" else np.ones_like(Fn)

    def residual(x: NDArray[np.float64]) -> NDArray[np.float64]:
        return (x[1] * dn / (x[0] - dn) - Fn) * weight

    lower = (1.0 + 1e-9, 1e-12)
    x0 = (max(a0 / d_max, 1.0 + 1e-6), max(b0 / f_scale, 1e-9))
    sol = least_squares(
        residual, x0, bounds=(lower, (np.inf, np.inf)), xtol=1e-15, ftol=1e-15, gtol=1e-15
    )
    a, b = sol.x[0] * d_max, sol.x[1] * f_scale
    if a > MAX_A_OVER_D * d_max:
        raise InputError(
            f"{source}: the data do not reach the compaction limit: the best fit has "
            f"a = {a:.3g} m > {MAX_A_OVER_D:g} × max(d) = {MAX_A_OVER_D * d_max:.3g} m, i.e. a "
            f"straight line of stiffness b/a = {b / a:.4g} N/m (valid: data compressed far "
            "enough for the force to rise steeply, as d approaches a)"
        )
    res = compaction_force(d, a, b) - F
    ss_res = float(res @ res)
    ss_tot = float(((F - F.mean()) ** 2).sum())
    return CompressionFit(
        a_m=float(a),
        b_N=float(b),
        r2=1.0 - ss_res / ss_tot if ss_tot > 0.0 else math.nan,
        rmse_N=math.sqrt(ss_res / d.size),
        n_points=int(d.size),
        weighting=weighting,
    )


def _column_scale(name: str, prefix: str, dimension: str, source: str) -> float:
    """SI factor of a column named ``<prefix>_<unit>`` (``d_mm`` → 1e-3)."""
    unit = name[len(prefix) + 1 :]
    try:
        return to_si(f"1 {unit}", dimension, f"{source}: column {name!r}")
    except QuantityError as err:
        raise InputError(
            f"{source}: column {name!r}: unit {unit!r} {err.problem} "
            f"(valid: {prefix}_<unit> with {err.valid.split(' such as')[0]}, "
            "e.g. d_m, d_mm / F_N, F_mN)"
        ) from None


def read_compression_csv(path: str | Path) -> CompressionData:
    """Read a compaction curve from a CSV file with a header row.

    The header names the columns with their units: ``d_<length unit>`` and
    ``F_<force unit>``, e.g. ``d_m,F_N``, ``d_mm,F_mN`` or ``d_mm,F_N``. Other
    columns are ignored; lines starting with ``#`` are comments.

    Raises:
        InputError: unreadable file, missing or ambiguous columns, non-numeric
            cells, fewer than 3 rows, negative values.
    """
    path = Path(path)
    source = str(path)
    text = read_text(path, "data file")
    try:
        rows = [(n, r) for n, r in enumerate(csv.reader(io.StringIO(text, newline="")), start=1)
                if _is_data(r)]
    except csv.Error as err:
        raise InputError(f"{source}: not a readable CSV file ({err})") from None
    if not rows:
        raise InputError(f"{source}: empty file (valid: a header d_mm,F_mN then data rows)")
    header = [h.strip() for h in rows[0][1]]
    cols = {}
    for prefix, dimension in (("d", "length"), ("F", "force")):
        found = [i for i, h in enumerate(header) if h.split("_")[0].lower() == prefix.lower()]
        found = [i for i in found if "_" in header[i]]
        if len(found) != 1:
            what = "no" if not found else "more than one"
            raise InputError(
                f"{source}: line {rows[0][0]}: {what} column named {prefix}_<unit> in the "
                f"header {header} (valid: e.g. d_m,F_N or d_mm,F_mN or d_mm,F_N)"
            )
        i = found[0]
        cols[prefix] = (i, header[i], _column_scale(header[i], prefix, dimension, source))
    values = {"d": [], "F": []}
    for line, row in rows[1:]:
        for prefix, (i, name, scale) in cols.items():
            cell = row[i].strip() if i < len(row) else ""
            try:
                x = float(cell)
            except ValueError:
                x = math.nan
            if not math.isfinite(x):
                raise InputError(
                    f"{source}: line {line}, column {name!r}: {cell!r} is not a number "
                    "(valid: a finite decimal number)"
                )
            values[prefix].append(x * scale)
    d, F = np.array(values["d"]), np.array(values["F"])
    _check_data(d, F, source)
    return CompressionData(d_m=d, F_N=F, source=source)


def _is_data(row: list[str]) -> bool:
    return bool(row) and any(c.strip() for c in row) and not row[0].lstrip().startswith("#")


def plot_compression_fit(data: CompressionData, fit: CompressionFit, path: str | Path) -> Path:
    """Save a PNG of the data points and the fitted curve (mm, N); returns the path."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    path = Path(path)
    fig = Figure(figsize=(6.0, 4.5), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot()
    d_curve = np.linspace(0.0, float(data.d_m.max()), 200)
    ax.plot(data.d_m * 1e3, data.F_N, "o", ms=4, label=f"data ({Path(data.source).name})")
    ax.plot(
        d_curve * 1e3,
        compaction_force(d_curve, fit.a_m, fit.b_N),
        "-",
        label=(
            f"F = b d/(a − d): a = {fit.a_m * 1e3:.5g} mm, b = {fit.b_N:.5g} N, R² = {fit.r2:.4f}"
        ),
    )
    ax.axvline(fit.a_m * 1e3, color="0.5", ls="--", lw=1, label="d = a (F → ∞)")
    ax.set_xlabel("compression d (mm)")
    ax.set_ylabel("contact force F (N)")
    ax.set_title("Transverse compaction of the crossover (thesis eq. 5.8)")
    ax.grid(True, alpha=0.3)
    ax.legend(loc="upper left", fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    return path
