"""Uniaxial extension of the 3-D crossover cell (issue 39's virtual test; thesis §5.3.1,
Figs. 5-6 to 5-8): the pulled yarn's force–strain curve, its modulus E1 and the strain
ratio the thesis calls ν.

The thesis pulls one yarn by its end and holds the other yarn's ends "fixed in space":
the pulled yarn straightens while the other bends, and the crossover moves out of plane.
Here the warp's x_max face moves along x at a constant speed (ramped in by the smooth
step) and is held in y and z, its x_min face is held in all three directions, and the
fill's two end faces are held in all three (:func:`cell_in_extension`). Nothing else
touches the cell; the yarns meet through their contact (docs/solid.md §6).

What is read (:func:`extend_cell`):

- the *cell's curve*: the pulled face's force F (its nodes' reactions along x) over the
  yarn's mean section A (the warp's volume over the cell's length), against the cell's
  strain ε = u / L (u the face's travel, L the cell's length along x): the modulus the
  shell's yarn sees, crimp straightening included;
- the thesis's *E1* (eq. 5.6): "elements selected at the middle of the yarn", those whose
  centre lies in the middle third of the cell's length, their axial stress over their
  axial strain in the material axes (τ11 / J over a1·(U − I)·a1, volume-weighted means);
- the thesis's *ν* (eq. 5.7), −ε2 / ε1, with ε1 the same axial strain and ε2 the strain
  of the same elements along the cell's other in-plane direction, a2 (across the yarn, in
  the fabric's plane): a strain ratio of the yarn's elements, not a fabric Poisson's
  ratio (the yarn's own ν12 is 0 in Table 5-2; what contraction there is comes from the
  crossing yarn's contact).

Quasi-static when the kinetic energy stays a small fraction of the internal work.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wovenimpact.calibration.crossover_cell import cell_solid
from wovenimpact.errors import InputError
from wovenimpact.kernels import solid_layout as L
from wovenimpact.model.model import BoundaryConditions, ShellContactParams, build_model
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver.explicit import Workspace, step
from wovenimpact.state import initial_state


def cell_in_extension(cell_spec, material, *, speed: float = 1.0, ramp: float = 5e-6,
                      hourglass: float = 0.05, contact=None, ratio: float = 0.0):
    """(cell, model): the crossover cell of a geometry spec (spec.crossover) of the
    transversely isotropic ``material``, the warp's x_max face pulled along x at ``speed``
    (m/s, ramped over ``ramp`` s) and held in y, z; its x_min face and the fill's y_min face
    held; the fill's y_max face held too (``ratio`` 0, the uniaxial test) or pulled along
    y at ``ratio`` × ``speed`` and held in x, z (a biaxial test at that ratio of the fill's
    strain to the warp's: the cell is square)."""
    if not ratio >= 0.0:
        raise InputError(f"ratio = {ratio!r}: valid is a ratio of strains ≥ 0")
    cell, part = cell_solid(cell_spec, material, hourglass)
    mesh = cell.mesh
    bcs = BoundaryConditions(len(mesh.nodes), ramp_time=ramp)
    held = ("warp.x_min", "fill.y_min") + (("fill.y_max",) if ratio == 0.0 else ())
    bcs.fix(np.concatenate([mesh.node_sets[n] for n in held]), (0, 1, 2))
    pulled = mesh.node_sets["warp.x_max"]
    bcs.fix(pulled, (1, 2)).prescribe(pulled, 0, speed)
    if ratio > 0.0:
        fill_end = mesh.node_sets["fill.y_max"]
        bcs.fix(fill_end, (0, 2)).prescribe(fill_end, 1, ratio * speed)
    model = build_model(mesh.nodes, np.zeros((0, 4), dtype=np.int64), {},
                        np.zeros(0, dtype=np.int64), bcs=bcs, solid=part,
                        node_sets=mesh.node_sets,
                        shell_contact=contact or ShellContactParams())
    return cell, model


def middle_hexes(cell, model) -> np.ndarray:
    """The warp's hexahedra whose centre lies in the middle third of the cell's length
    (the thesis's "elements selected at the middle of the yarn")."""
    warp = np.asarray(cell.mesh.hex_sets["warp"])
    centre = model.x0[model.solid.hexes[warp]].mean(axis=1)[:, 0]
    x0, x1 = cell.mesh.nodes[:, 0].min(), cell.mesh.nodes[:, 0].max()
    third = (x1 - x0) / 3.0
    return warp[(centre > x0 + third) & (centre < x1 - third)]


def axial_and_cross_strain(model, state, hexes, frames) -> tuple[float, float, float]:
    """(σ1, ε1, ε2): volume-weighted means over ``hexes`` of the axial stress τ11 / J in
    the material axes and of the strains a1·(U − I)·a1 and a2·(U − I)·a2 (U the right
    stretch in reference axes)."""
    h = state.hex[hexes]
    vol = h[:, L.H_VOL]
    v0 = model.solid.vol0[hexes]
    u6 = h[:, L.H_U:L.H_U + 6]
    U = np.empty((len(hexes), 3, 3))
    U[:, 0, 0], U[:, 1, 1], U[:, 2, 2] = u6[:, 0], u6[:, 1], u6[:, 2]
    U[:, 1, 2] = U[:, 2, 1] = u6[:, 3]
    U[:, 0, 2] = U[:, 2, 0] = u6[:, 4]
    U[:, 0, 1] = U[:, 1, 0] = u6[:, 5]
    a1, a2 = frames[hexes, 0], frames[hexes, 1]
    strain = U - np.eye(3)
    e1 = np.einsum("ei,eij,ej->e", a1, strain, a1)
    e2 = np.einsum("ei,eij,ej->e", a2, strain, a2)
    sigma1 = h[:, L.H_TAU] * v0 / vol  # τ11 / J
    w = v0 / v0.sum()
    return float(w @ sigma1), float(w @ e1), float(w @ e2)


@dataclass(frozen=True)
class CellExtension:
    """The curves of :func:`extend_cell` (SI).

    Attributes:
        strain: the cell's strain u / L at each sample.
        force: the pulled face's force (N); stress: force over the yarn's mean section.
        force_fill: the force along y on the fill's y_max face (N): its tension, picked
            up through crimp interchange when held (uniaxial) or pulled (biaxial).
        ratio: the fill's strain over the warp's (0: fill held).
        sigma1, eps1, eps2: the middle elements' axial stress and their strains along a1
            and a2 (module docstring).
        section: the yarn's mean section A (m²); length: the cell's length L (m).
        e1: the thesis's E1, the slope of σ1 against ε1 fitted through the origin over
            the samples with ε1 above a tenth of its last value (Pa).
        nu: −ε2/ε1 fitted the same way (the thesis's ν).
        tangent: the cell's tangent modulus dσ/dε over the last fifth of the strain (Pa).
        kinetic_fraction, hourglass_fraction, energy_error: the checks at the end.
        steps, elements.
    """

    strain: np.ndarray
    force: np.ndarray
    force_fill: np.ndarray
    ratio: float
    stress: np.ndarray
    sigma1: np.ndarray
    eps1: np.ndarray
    eps2: np.ndarray
    section: float
    length: float
    e1: float
    nu: float
    tangent: float
    kinetic_fraction: float
    hourglass_fraction: float
    energy_error: float
    steps: int
    elements: int


def extend_cell(cell_spec, material, *, strain: float = 0.01, speed: float = 1.0,
                ramp: float = 5e-6, samples: int = 50, hourglass: float = 0.05,
                ratio: float = 0.0) -> CellExtension:
    """Pull the warp until the cell's strain reaches ``strain``, sampling ``samples``
    times (module docstring); the fill held (``ratio`` 0) or pulled at ``ratio`` times
    the warp's strain (:func:`cell_in_extension`)."""
    cell, model = cell_in_extension(cell_spec, material, speed=speed, ramp=ramp,
                                    hourglass=hourglass, ratio=ratio)
    fill_end = cell.mesh.node_sets["fill.y_max"]
    state = initial_state(model)
    ws = Workspace.for_model(model, state)
    pulled = cell.mesh.node_sets["warp.x_max"]
    length = float(np.ptp(cell.mesh.nodes[:, 0]))
    warp = np.asarray(cell.mesh.hex_sets["warp"])
    section = float(np.sum(model.solid.vol0[warp])) / length
    middle = middle_hexes(cell, model)
    frames = model.solid.frame
    x_face0 = float(np.mean(model.x0[pulled, 0]))
    rows, kinetic = [], []
    every = strain / samples
    next_sample = every
    while True:
        step(model, state, ws)
        eps = (float(np.mean(state.x[pulled, 0])) - x_face0) / length
        if eps < next_sample:
            continue
        next_sample += every
        force = float(np.sum(state.f_ext[pulled, 0]))
        rows.append((eps, force, float(np.sum(state.f_ext[fill_end, 1])),
                     *axial_and_cross_strain(model, state, middle, frames)))
        balance = energy_balance(model, state)
        kinetic.append(balance["kinetic_J"] / max(balance["internal_work_J"], 1e-300))
        if eps >= strain:
            break
    arr = np.array(rows)
    e, f, f_fill, s1, e1, e2 = arr.T
    use = e1 > 0.1 * e1[-1]
    slope = float(s1[use] @ e1[use] / (e1[use] @ e1[use]))
    nu = float(-(e2[use] @ e1[use]) / (e1[use] @ e1[use]))
    late = e >= 0.8 * e[-1]
    tangent = float(np.polyfit(e[late], f[late] / section, 1)[0]) if late.sum() > 1 else float("nan")
    balance = energy_balance(model, state)
    return CellExtension(
        strain=e, force=f, force_fill=f_fill, ratio=float(ratio), stress=f / section, sigma1=s1, eps1=e1, eps2=e2, section=section,
        length=length, e1=slope, nu=nu, tangent=tangent,
        kinetic_fraction=float(max(kinetic[len(kinetic) // 2:])),
        hourglass_fraction=float(balance["hourglass_J"] / max(balance["internal_work_J"], 1e-300)),
        energy_error=float(balance["error_fraction"]), steps=int(state.step),
        elements=int(model.n_hexes))
