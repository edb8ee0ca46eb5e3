"""Per-element quantities of metal (J2) sections, read from their points' states.

A J2 section keeps one state row per material point (kernels/j2_layout.py): element e
owns rows ``Model.mat_row[e]`` … of ``State.mat``, in-plane point g (one, or four for a
2×2 membrane) and through-thickness level k at row ``mat_row[e] + g · n_pts + k``
(kernels/shell.py, ``full_membrane`` / ``section_response``). Weighting a per-point
quantity per unit reference area by the Simpson weight w_k (Σ w_k = 1) and the in-plane
weight (A0 for one point, det J_g for the 2×2 points, Σ_g = A0) gives the element's
value — the same quadrature the shell uses for its forces (docs/theory.md §7.6).

- :func:`plastic_work` (J): Σ over the J2 points of S_PLASTIC_WORK (J/m² of reference
  area) × weights, live and eroded elements alike (an eroded element's points keep
  their state): the energy the metal dissipated plastically, a part of the internal
  work W_int that the balance's ``stored`` does not hold.
- :func:`max_plastic_strain` (—): the largest equivalent plastic strain ε̄p of an
  element's points (0 for elements whose material is not J2).
- :func:`thickness_ratio` (—): t / t0 = Σ_k w_k λ3,k averaged over the in-plane points
  (λ3 = S_THICK, the thickness stretch from plastic incompressibility and the elastic
  plane-stress ε33, eq. J10); 1 for elements whose material is not J2.
- :func:`largest_von_mises` (Pa): of each element's points, the one whose in-plane
  Cauchy stress σ (S_SIG: σ_xx, σ_yy, σ_xy in the point's Green–Naghdi rotated frame,
  the element's reference axes carried with the material's rotation; plane stress,
  σ_zz = 0) has the largest von Mises stress √(σxx² − σxxσyy + σyy² + 3σxy²): that
  stress and its three components, as LS-DYNA's shell output takes the largest over the
  integration points; 0 for elements whose material is not J2. The stress is the point's
  own (the kernel's, with damage and failure in it: a failed point's is 0), not
  re-derived from strains.
"""

from __future__ import annotations

import numpy as np

from wovenimpact.kernels import j2_layout as J
from wovenimpact.kernels import shell_layout as SL


def has_metal(model) -> bool:
    """The model has a J2 (plastic metal) material."""
    return bool(np.any(model.mat_kind == SL.MAT_J2))


def simpson_weights(n_pts: int) -> np.ndarray:
    """w_k of the n-point (odd) Simpson rule on [−t/2, t/2] normalised to Σ w_k = 1;
    [1.0] for a resultant section (n = 1), as ``section_response`` weights its points."""
    if n_pts == 1:
        return np.ones(1)
    w = np.array([1.0 if k in (0, n_pts - 1) else (4.0 if k % 2 else 2.0) for k in range(n_pts)])
    return w / (3.0 * (n_pts - 1))


def _j2_sections(model):
    """For each J2 section with elements: (elements, its points' rows in ``state.mat``
    (elements, in-plane points × levels), levels, in-plane points)."""
    for sec in range(model.sections.shape[0]):
        row = model.sections[sec]
        if model.mat_kind[int(row[SL.C_MAT])] != SL.MAT_J2:
            continue
        elems = np.flatnonzero(model.elem_section == sec)
        if elems.size == 0:
            continue
        n_pts, n_in = int(row[SL.C_POINTS]), int(row[SL.C_INPLANE])
        yield elems, model.mat_row[elems][:, None] + np.arange(n_in * n_pts), n_pts, n_in


def _j2_point_values(model, state, column: int):
    """For each J2 section: (elements, in-plane weights (m²), Simpson weights, values
    (elements, in-plane points, levels)) of state column ``column``."""
    for elems, rows, n_pts, n_in in _j2_sections(model):
        values = state.mat[rows, column].reshape(len(elems), n_in, n_pts)  # that column only
        if n_in == 4:
            w_in = model.gauss_weight[elems]
        else:
            w_in = model.area0[elems][:, None]
        yield elems, w_in, simpson_weights(n_pts), values


def plastic_work(model, state) -> float:
    """Plastic work of every J2 point in the model (J; module docstring)."""
    return float(np.sum(element_plastic_work(model, state)))


def element_plastic_work(model, state) -> np.ndarray:
    """(n_elems,) plastic work of each element's J2 points (J, modelled part; 0 for
    elements whose material is not J2; module docstring)."""
    out = np.zeros(model.n_elems)
    for elems, w_in, w_k, values in _j2_point_values(model, state, J.S_PLASTIC_WORK):
        out[elems] = np.einsum("eg,egk,k->e", w_in, values, w_k)
    return out


def thickness_ratio(model, state) -> np.ndarray:
    """(n_elems,) current thickness over reference thickness (module docstring)."""
    out = np.ones(model.n_elems)
    for elems, w_in, w_k, values in _j2_point_values(model, state, J.S_THICK):
        per_point = np.einsum("egk,k->eg", values, w_k)
        out[elems] = np.sum(per_point * w_in, axis=1) / np.sum(w_in, axis=1)
    return out


def max_plastic_strain(model, state) -> np.ndarray:
    """(n_elems,) the largest ε̄p over each element's points (module docstring)."""
    out = np.zeros(model.n_elems)
    for elems, _, _, values in _j2_point_values(model, state, J.S_EPS_P):
        out[elems] = values.reshape(len(elems), -1).max(axis=1)
    return out


def von_mises(sig: np.ndarray) -> np.ndarray:
    """Plane-stress von Mises stress of (…, 3) σ_xx, σ_yy, σ_xy."""
    sxx, syy, sxy = sig[..., 0], sig[..., 1], sig[..., 2]
    return np.sqrt(sxx * sxx - sxx * syy + syy * syy + 3.0 * sxy * sxy)


def largest_von_mises(model, state) -> tuple[np.ndarray, np.ndarray]:
    """(n_elems,) the largest von Mises stress over each element's J2 points (Pa) and
    (n_elems, 3) the stress σ_xx, σ_yy, σ_xy of that point (Pa; module docstring)."""
    vm = np.zeros(model.n_elems)
    sig = np.zeros((model.n_elems, 3))
    for elems, rows, _, _ in _j2_sections(model):
        points = state.mat[rows, J.S_SIG:J.S_SIG + 3]  # (elements, points, 3)
        per_point = von_mises(points)
        best = np.argmax(per_point, axis=1)
        take = np.arange(elems.size)
        vm[elems] = per_point[take, best]
        sig[elems] = points[take, best]
    return vm, sig
