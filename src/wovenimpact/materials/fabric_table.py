"""Building the tabulated crossover of a fabric material (theory §1.9), Python side.

At compile time the exact crossover solve (``kernels/fabric.py``) is run on a tensor grid
of knots in (λ_w, λ_f) with failure switched off; for each knot it gives the heights and
tensions, hence the stored energy W per unit reference area and its exact gradient

    ∂W/∂λ_i = 2 T_i cos ψ_i ℓ_i0 / A0,   cos ψ_i = ℓ_i / L_i,   A0 = 4 ℓ_w0 ℓ_f0

(envelope theorem: the heights minimise the cell energy, so only the explicit dependence
on ℓ_i counts). The cross derivative ∂²W/∂λ_w∂λ_f and the heights' derivatives are
central finite differences of these exact quantities (step ``FD_STEP`` in λ). The block
is appended to the material's parameter row (layout: ``kernels/fabric_layout``) and read
by ``kernels/fabric_table.crossover_from_table``.

Grid (the choice, measured in theory §1.9): from 0.8 (well into compression, where both
yarns are slack or one is straight) to 1.02 × the failure stretch of a straight yarn,
λ_u = L0 (1 + T_u/EA)/ℓ0. Spacing ``COARSE`` away from the non-smooth places and ``FINE``
around them: the onset of contact through λ = 1 (W ≡ 0 on one side, W ∝ D² on the other:
∂²W jumps there) with the knee of the crimp interchange just above it (λ up to L0/ℓ0, where a
yarn becomes taut when straight), and the onset line of a strongly compressed crossing
family (its slack height reaches h_w0 + h_f0).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import hashlib
import math
import os
import zipfile
from pathlib import Path

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.jit import cache_root, source_digest
from wovenimpact.kernels import fabric_layout as L
from wovenimpact.materials.fabric_point import FabricOptions, initial_state, update_points

FD_STEP = 1e-6  # λ step of the central differences for the cross and height derivatives
LAMBDA_MIN = 0.8  # lower end of the table; below it the exact solve runs
FAILURE_MARGIN = 1.02  # upper end = margin × straight-yarn failure stretch
COARSE = 5e-3  # knot spacing away from the non-smooth places (λ)
FINE = 1e-3  # knot spacing around the onset of contact and the knee
# knots 1 ± REST_STEPS (and 1) along each family: cells shrinking geometrically onto the
# undeformed state λ = (1, 1), where the onset of contact passes (theory §1.9, "rest
# cells"); the lookup's buckets keep the width of the knots outside the cluster, so a
# point inside it steps through a few knots
REST_STEPS = 1e-7 * 2.0 ** np.arange(12)  # 1e-7 … 2.05e-4
# the table's largest failure stretch: λ_u = 3 is a yarn at 200 % strain, beyond any fibre;
# a larger T_u (e.g. "failure off" as T_u = 1 MN, λ_u ≈ 350) would ask for ~10⁹ cells
MAX_FAILURE_STRETCH = 3.0


def _exact_parameters(params):
    """The same fabric with failure off and the exact solve (the table's oracle)."""
    big = 1e30
    return dataclasses.replace(
        params,
        warp=dataclasses.replace(params.warp, ultimate_tension=big),
        fill=dataclasses.replace(params.fill, ultimate_tension=big),
        options=FabricOptions(crossover="exact"),
    )


def exact_crossover(params, lam_w, lam_f) -> dict[str, np.ndarray]:
    """Exact crossover at stretches (λ_w, λ_f) (arrays), from the undeformed state.

    Returns arrays ``W`` (J/m², per unit reference area, no shear), ``W_w``, ``W_f``
    (exact gradient, envelope theorem), ``H_w``, ``H_f`` (m), ``T_w``, ``T_f`` (N).
    Failure is off (T_u → ∞). Where both yarns are slack the heights are not unique;
    these are the undeformed heights projected onto the admissible set.
    """
    ex = _exact_parameters(params)
    lam_w, lam_f = np.broadcast_arrays(np.asarray(lam_w, float), np.asarray(lam_f, float))
    shape = lam_w.shape
    lw, lf = lam_w.ravel(), lam_f.ravel()
    n = lw.size
    f_new = np.zeros((n, 2, 2))
    f_new[:, 0, 0] = lw
    f_new[:, 1, 1] = lf
    f_old = np.repeat(np.eye(2)[None], n, axis=0)
    st = update_points(ex.to_array(), f_old, f_new, initial_state(ex, n)).state
    w, f = params.warp, params.fill
    area0 = 4.0 * w.half_length * f.half_length
    ell_w, ell_f = lw * w.half_length, lf * f.half_length
    h_w, h_f = st[:, L.S_H], st[:, L.S_H + 1]
    t_w, t_f = st[:, L.S_TENSION], st[:, L.S_TENSION + 1]
    cos_w = ell_w / np.hypot(ell_w, h_w)
    cos_f = ell_f / np.hypot(ell_f, h_f)
    out = {
        "W": st[:, L.S_ENERGY],
        "W_w": 2.0 * t_w * cos_w * w.half_length / area0,
        "W_f": 2.0 * t_f * cos_f * f.half_length / area0,
        "H_w": h_w,
        "H_f": h_f,
        "T_w": t_w,
        "T_f": t_f,
    }
    return {k: v.reshape(shape) for k, v in out.items()}


def failure_stretch(yarn) -> float:
    """λ at which a straight yarn reaches T_u: L0 (1 + T_u/EA)/ℓ0 (the largest λ at failure)."""
    return yarn.truss_length * (1.0 + yarn.ultimate_tension / (yarn.modulus * yarn.area)) / (
        yarn.half_length
    )


def _tension_at(yarn, lam: float) -> float:
    """T_u that puts the failure stretch at ``lam`` (inverse of :func:`failure_stretch`)."""
    return (lam * yarn.half_length / yarn.truss_length - 1.0) * yarn.modulus * yarn.area


def compressed_onset(own, other) -> float:
    """λ of family ``own`` below which it is slack even at height h_w0 + h_f0 (√(L0² − ℓ²) ≥ S)."""
    s = own.h0 + other.h0
    q = own.truss_length**2 - s * s
    return math.sqrt(q) / own.half_length if q > 0.0 else 0.0


def knots(lo: float, hi: float, fine: list[tuple[float, float]], coarse=COARSE, dense=FINE,
          kinks=()):
    """Increasing knots on [lo, hi]: spacing ``dense`` inside the intervals ``fine``,
    ``coarse`` elsewhere (each stretch uniform, its ends kept), and a knot on each of
    ``kinks`` (where W's second derivative jumps along a grid line)."""
    edges = sorted({lo, hi, *[min(max(x, lo), hi) for ab in fine for x in ab],
                    *[k for k in kinks if lo < k < hi]})
    out = [lo]
    for a, b in zip(edges[:-1], edges[1:]):
        mid = 0.5 * (a + b)
        h = dense if any(f0 <= mid <= f1 for f0, f1 in fine) else coarse
        n = max(1, math.ceil((b - a) / h - 1e-9))
        out.extend(a + (b - a) * np.arange(1, n + 1) / n)
    return np.array(out)


def family_knots(own, other, coarse=COARSE, dense=FINE, family: str = "yarn") -> np.ndarray:
    """Knots along one family's stretch (module docstring: the grid choice).

    Raises InputError when the family is not crimped (h0 = 0: the table measures heights
    against h0, and the material files refuse it, spec.material) or its failure stretch
    exceeds ``MAX_FAILURE_STRETCH`` (the grid would not fit in memory)."""
    if not own.h0 > 0.0:
        raise InputError(
            f"{family}.h0 = {own.h0:g} m (crimp {own.crimp:g}): the crossover table needs "
            "crimped yarns, its heights measured against h0 (docs/theory.md §1.9); valid: "
            "h0 > 0, e.g. from a crimp > 0 such as 0.0421 (eq. 5.5)")
    lam_u = failure_stretch(own)
    if lam_u > MAX_FAILURE_STRETCH:
        raise InputError(
            f"{family}.ultimate_tension = {own.ultimate_tension:.6g} N puts the yarn's failure stretch "
            f"at λ_u = {lam_u:.4g} (strain {lam_u - 1:.3g}); the crossover table spans up to "
            f"1.02 λ_u and allows λ_u ≤ {MAX_FAILURE_STRETCH:g} (valid: ultimate_tension ≤ "
            f"{_tension_at(own, MAX_FAILURE_STRETCH):.6g} N). To switch failure off, give a "
            f"tension the run never reaches (e.g. 10 × the yarn's), or crossover = \"exact\"")
    hi = FAILURE_MARGIN * lam_u
    taut = own.truss_length / own.half_length
    comp = compressed_onset(own, other)
    fine = [(0.985, taut + 0.012)]
    if comp > LAMBDA_MIN:
        fine.append((comp - 0.01, comp + 0.01))
    k = knots(LAMBDA_MIN, hi, fine, coarse, dense, kinks=(taut, comp))
    rest = np.concatenate([1.0 - REST_STEPS, [1.0], 1.0 + REST_STEPS])
    # regular knots inside the rest cluster's span give way to it
    k = k[np.abs(k - 1.0) > REST_STEPS[-1] * (1.0 + 1e-9)]
    return np.unique(np.concatenate([k, rest]))


def kink_knots(own, other, k: np.ndarray) -> np.ndarray:
    """Mask of the knots that lie on a grid-aligned kink line of W: the taut point
    λ = L0/ℓ0 (a straight yarn starts to carry tension) and the compressed onset."""
    marks = (own.truss_length / own.half_length, compressed_onset(own, other))
    return np.array([any(abs(x - m) < 1e-12 for m in marks) for x in k])


def bucket_map(k: np.ndarray) -> tuple[np.ndarray, float]:
    """Uniform lookup map of the knots ``k`` (layout in fabric_layout): buckets of width half
    the smallest knot spacing outside the rest cluster (REST_STEPS), each holding the index
    of the knot interval that contains its left edge; returns (map, 1/width). A point
    steps forward from its bucket's interval at most once outside the cluster, through up
    to len(REST_STEPS) knots inside it. (Buckets of 5e-4 for knots 9.9e-4 apart, not
    aligned with them, made most look-ups step once: 39 → 55 ns per evaluation.)"""
    d = np.diff(k)
    outside = np.minimum(np.abs(k[:-1] - 1.0), np.abs(k[1:] - 1.0)) >= REST_STEPS[-1] * (1 - 1e-9)
    width = 0.5 * float(np.min(d[outside]))
    nb = int(math.ceil((k[-1] - k[0]) / width)) + 1
    edges = k[0] + width * np.arange(nb)
    idx = np.clip(np.searchsorted(k, edges, side="right") - 1, 0, len(k) - 2)
    return idx.astype(float), 1.0 / width


def install(head: np.ndarray, knots_w: np.ndarray, knots_f: np.ndarray, data: np.ndarray):
    """The parameter row: ``head`` (N_PARAM entries) with the table header set, followed by
    knots, bucket maps and knot data (nw, nf, TAB_STRIDE) — layout in fabric_layout."""
    bw, ibw = bucket_map(knots_w)
    bf, ibf = bucket_map(knots_f)
    row = np.concatenate([head[: L.N_PARAM], knots_w, knots_f, bw, bf, data.ravel()])
    row[L.P_CROSSOVER] = L.CROSSOVER_TABLE
    row[L.P_TAB_NW], row[L.P_TAB_NF] = len(knots_w), len(knots_f)
    row[L.P_TAB_START] = L.N_PARAM
    row[L.P_TAB_NBW], row[L.P_TAB_NBF] = len(bw), len(bf)
    row[L.P_TAB_IBW], row[L.P_TAB_IBF] = ibw, ibf
    row[L.P_TAB_DATA] = L.N_PARAM + len(knots_w) + len(knots_f) + len(bw) + len(bf)
    return row


def table_data(row: np.ndarray) -> np.ndarray:
    """View (nw, nf, TAB_STRIDE) of the knot data in a parameter row."""
    nw, nf = int(row[L.P_TAB_NW]), int(row[L.P_TAB_NF])
    s = int(row[L.P_TAB_DATA])
    return row[s:s + nw * nf * L.TAB_STRIDE].reshape(nw, nf, L.TAB_STRIDE)


def table_knots(row: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    nw, nf, s = int(row[L.P_TAB_NW]), int(row[L.P_TAB_NF]), int(row[L.P_TAB_START])
    return row[s:s + nw], row[s + nw:s + nw + nf]


def tabulate(params, knots_w: np.ndarray, knots_f: np.ndarray, fd_step: float = FD_STEP):
    """Knot data (nw, nf, TAB_STRIDE) for ``params`` on the given knots (layout in
    fabric_layout), T_EXACT entries 0."""
    nw, nf = len(knots_w), len(knots_f)
    e = fd_step
    gw, gf = np.meshgrid(knots_w, knots_f, indexing="ij")
    offs = [(0, 0), (e, 0), (-e, 0), (0, e), (0, -e), (e, e), (e, -e), (-e, e), (-e, -e)]
    lw = np.stack([gw + a for a, _ in offs])
    lf = np.stack([gf + b for _, b in offs])
    ex = exact_crossover(params, lw, lf)
    c, xp, xm, yp, ym, pp, pm, mp, mm = range(9)
    data = np.zeros((nw, nf, L.TAB_STRIDE))
    data[..., L.T_W] = ex["W"][c]
    data[..., L.T_W + 1] = ex["W_w"][c]
    data[..., L.T_W + 2] = ex["W_f"][c]
    # cross derivative: on a kink line λ_w = const only the derivative along the line,
    # ∂(∂W/∂λ_w)/∂λ_f, is single-valued (and likewise for λ_f); elsewhere the mean
    d_along_f = (ex["W_w"][yp] - ex["W_w"][ym]) / (2 * e)
    d_along_w = (ex["W_f"][xp] - ex["W_f"][xm]) / (2 * e)
    kink_w = kink_knots(params.warp, params.fill, knots_w)[:, None]
    kink_f = kink_knots(params.fill, params.warp, knots_f)[None, :]
    data[..., L.T_W + 3] = np.where(
        kink_w & ~kink_f, d_along_f,
        np.where(kink_f & ~kink_w, d_along_w, 0.5 * (d_along_f + d_along_w)),
    )
    for q, key in ((L.T_HW, "H_w"), (L.T_HF, "H_f")):
        h = ex[key]
        data[..., q] = h[c]
        data[..., q + 1] = (h[xp] - h[xm]) / (2 * e)
        data[..., q + 2] = (h[yp] - h[ym]) / (2 * e)
        data[..., q + 3] = (h[pp] - h[pm] - h[mp] + h[mm]) / (4 * e * e)
    return data


TOLERANCE = 1e-4  # accuracy target (theory §1.9 states the norms)
BUILD_SAFETY = 0.5  # cells are marked exact above BUILD_SAFETY × TOLERANCE at build time
CELL_SAMPLES = tuple(np.linspace(0.0, 1.0, 9))  # 9 × 9 samples per cell, edges included


def reference_scales(params) -> dict[str, float]:
    """Scales of the accuracy norms: T_u per family (tensions), h_i0 (heights), and
    W_u = min_i T_ui² L_i0 / (E_i A_i A0), the energy of a straight family at failure
    per unit reference area (energy)."""
    w, f = params.warp, params.fill
    area0 = 4.0 * w.half_length * f.half_length
    wu = min(y.ultimate_tension**2 * y.truss_length / (y.modulus * y.area * area0) for y in (w, f))
    return {"T_w": w.ultimate_tension, "T_f": f.ultimate_tension, "H_w": w.h0, "H_f": f.h0,
            "W": wu}


def table_errors(params, row: np.ndarray, lam_w, lam_f) -> dict[str, np.ndarray]:
    """Errors of the table in ``row`` against the exact solve at (λ_w, λ_f), each divided
    by its scale (:func:`reference_scales`); NaN where the norm does not apply: heights
    while a yarn is slack (not unique), everything beyond failure (T_i ≥ T_ui) or where the
    table defers to the exact solve. Tensions as the kernel derives them."""
    from wovenimpact.kernels.fabric_table import crossover_from_table_for_points

    lam_w = np.ascontiguousarray(lam_w, dtype=float).ravel()
    lam_f = np.ascontiguousarray(lam_f, dtype=float).ravel()
    out = np.empty((lam_w.size, 6))
    crossover_from_table_for_points(row, lam_w, lam_f, out)
    ex = exact_crossover(params, lam_w, lam_f)
    w, f = params.warp, params.fill
    area0 = 4.0 * w.half_length * f.half_length
    sc = reference_scales(params)
    hw, hf = np.maximum(out[:, 4], 0.0), np.maximum(out[:, 5], 0.0)
    ell_w, ell_f = lam_w * w.half_length, lam_f * f.half_length
    tw = np.maximum(out[:, 2] * area0 * np.hypot(ell_w, hw) / (2 * w.half_length * ell_w), 0.0)
    tf = np.maximum(out[:, 3] * area0 * np.hypot(ell_f, hf) / (2 * f.half_length * ell_f), 0.0)
    valid = (out[:, 0] == 1.0) & (ex["T_w"] < w.ultimate_tension) & (ex["T_f"] < f.ultimate_tension)
    contact = valid & (ex["T_w"] > 0.0) & (ex["T_f"] > 0.0)
    nan = np.nan
    return {
        "T_w": np.where(valid, np.abs(tw - ex["T_w"]) / sc["T_w"], nan),
        "T_f": np.where(valid, np.abs(tf - ex["T_f"]) / sc["T_f"], nan),
        "W": np.where(valid, np.abs(out[:, 1] - ex["W"]) / sc["W"], nan),
        "H_w": np.where(contact, np.abs(hw - ex["H_w"]) / sc["H_w"], nan),
        "H_f": np.where(contact, np.abs(hf - ex["H_f"]) / sc["H_f"], nan),
        "contact": (ex["T_w"] > 0.0) & (ex["T_f"] > 0.0),
    }


def slack_overlap(params, lam_w, lam_f) -> np.ndarray:
    """The overlap D = (h_w0 − Hs_w) + (h_f0 − Hs_f) of theory §1.3 at (λ_w, λ_f): ≤ 0 where
    both yarns can be slack while touching; the heights there are not unique, the
    admissible H_w spanning an interval of width −D."""
    def offset(y, lam):
        dq = (lam * y.half_length - y.half_length) * (lam * y.half_length + y.half_length)
        q = y.h0 * y.h0 - dq
        return np.where(q > 0.0, dq / (y.h0 + np.sqrt(np.maximum(q, 0.0))), y.h0)
    return offset(params.warp, lam_w) + offset(params.fill, lam_f)


def mark_exact_cells(params, row, tol=BUILD_SAFETY * TOLERANCE):
    """Mark (T_EXACT, in place) every cell of the table in ``row`` whose interpolant misses
    ``tol`` at a CELL_SAMPLES² grid of interior points, and every cell the onset of contact
    crosses (yarns slack at some samples, in contact at others: the heights there have a
    kink, and on the slack side they are not even unique) — unless, on its slack side,
    the interval of admissible heights is narrower than ``tol`` h_0 at every sample
    (the tiny cells around the undeformed state, REST_STEPS: the heights are then unique
    to the tolerance, and the interpolant meets it); returns the marked fraction."""
    knots_w, knots_f = table_knots(row)
    nw, nf = len(knots_w), len(knots_f)
    sw = np.asarray(CELL_SAMPLES)
    cw = knots_w[:-1, None] + np.diff(knots_w)[:, None] * sw[None, :]  # (nw − 1, s)
    cf = knots_f[:-1, None] + np.diff(knots_f)[:, None] * sw[None, :]
    lw = np.broadcast_to(cw[:, None, :, None], (nw - 1, nf - 1, sw.size, sw.size))
    lf = np.broadcast_to(cf[None, :, None, :], (nw - 1, nf - 1, sw.size, sw.size))
    err = table_errors(params, row, lw, lf)
    contact = err.pop("contact").reshape(nw - 1, nf - 1, -1)
    worst = np.nanmax(np.stack([np.nan_to_num(e, nan=0.0) for e in err.values()]), axis=0)
    bad = worst.reshape(nw - 1, nf - 1, -1).max(axis=2) > tol
    width = np.where(contact, 0.0, -slack_overlap(params, lw, lf).reshape(nw - 1, nf - 1, -1))
    unique = width.max(axis=2) <= tol * min(params.warp.h0, params.fill.h0)
    bad |= contact.any(axis=2) & ~contact.all(axis=2) & ~unique
    table_data(row)[:-1, :-1, L.T_EXACT] = bad.astype(float)
    return float(bad.mean())


def _options_free(params):
    return dataclasses.replace(params, options=FabricOptions(crossover="exact"))


TABLE_HEADER = (L.P_CROSSOVER, L.P_TAB_NW, L.P_TAB_NF, L.P_TAB_START, L.P_TAB_NBW,
                L.P_TAB_NBF, L.P_TAB_IBW, L.P_TAB_IBF, L.P_TAB_DATA)


def table_cache_dir() -> Path | None:
    """Where built tables are kept between runs: ``$XDG_CACHE_HOME/wovenimpact/tables``
    (``~/.cache`` when unset), beside the compiled kernels; none with
    ``WOVENIMPACT_TABLE_CACHE=0``."""
    if os.environ.get("WOVENIMPACT_TABLE_CACHE", "1") in ("0", "false", "no"):
        return None
    return cache_root() / "tables"


def table_key(params) -> str:
    """The name of a table on disk: SHA-256 of the material's parameter vector (options
    left out, as in the table) and of the package's sources (``jit.source_digest``: any
    change of the code builds the tables afresh)."""
    head = _options_free(params).to_array()
    return hashlib.sha256(head.tobytes() + source_digest().encode()).hexdigest()[:24]


def _read_table(path: Path, key: str) -> np.ndarray | None:
    """The row stored at ``path`` under ``key``, or None if the file is missing, not a
    table of this key, or damaged (the caller then builds it). No pickles are read."""
    try:
        with np.load(path, allow_pickle=False) as f:
            if str(f["key"]) != key:
                return None
            row = np.array(f["row"], dtype=np.float64)
    except (OSError, KeyError, ValueError, EOFError, zipfile.BadZipFile):
        return None
    if row.ndim != 1 or row.size <= L.N_PARAM or row[L.P_CROSSOVER] != L.CROSSOVER_TABLE:
        return None
    with contextlib.suppress(OSError):
        os.utime(path)  # recently used: kept when the folder is pruned
    return row


TABLE_CACHE_FILES = 64  # tables kept on disk (~2.3 MB each); the least recently used go


def _write_table(path: Path, key: str, row: np.ndarray) -> None:
    """Store ``row`` at ``path`` (written to a temporary name, then renamed: a reader never
    sees half a file), and keep the TABLE_CACHE_FILES most recently used tables of the
    folder. A cache that cannot be written is skipped: it only saves time."""
    tmp = path.with_name(f"{path.stem}.{os.getpid()}.tmp.npz")
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        np.savez(tmp, key=np.array(key), row=row)
        os.replace(tmp, path)
        tables = [f for f in path.parent.glob("*.npz") if ".tmp." not in f.name]  # not
        # another process's file being written
        kept = sorted(tables, key=lambda f: f.stat().st_mtime, reverse=True)
        for old in kept[TABLE_CACHE_FILES:]:
            old.unlink(missing_ok=True)
    except OSError:
        tmp.unlink(missing_ok=True)


@functools.lru_cache(maxsize=64)
def _cached_table(params) -> np.ndarray:
    """The table row of ``params`` (options-free): from this process's memory, else from
    the disk cache (:func:`table_cache_dir`), else built (1–2 s) and stored there."""
    folder = table_cache_dir()
    key = table_key(params) if folder is not None else ""
    row = _read_table(folder / f"{key}.npz", key) if folder is not None else None
    if row is None:
        kw = family_knots(params.warp, params.fill, family="warp")
        kf = family_knots(params.fill, params.warp, family="fill")
        row = install(np.zeros(L.N_PARAM), kw, kf, tabulate(params, kw, kf))
        mark_exact_cells(params, row)
        if folder is not None:
            _write_table(folder / f"{key}.npz", key, row)
    row.flags.writeable = False
    return row


def with_table(params, head: np.ndarray) -> np.ndarray:
    """The parameter row ``head`` (N_PARAM entries) with the material's crossover table
    installed (built once per parameter set and cached; options do not enter it)."""
    row = _cached_table(_options_free(params)).copy()
    keep = np.ones(L.N_PARAM, bool)
    keep[list(TABLE_HEADER)] = False
    row[: L.N_PARAM][keep] = head[: L.N_PARAM][keep]
    return row
