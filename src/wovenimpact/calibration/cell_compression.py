"""Transverse compression of the 3-D crossover cell between rigid plates (issue 39's
virtual test; thesis §5.3.2, Fig. 5-10): the force–compression curve F_c(d_c) and its
fit by the compaction law F = b·d / (a − d) (eq. 5.8, :mod:`calibration.compression`).

The cell (model.crossover_cell) lies between a held plate under it and one moving down
at a constant speed (ramped in by the smooth step), both rigid planes
(model.rigid_plane; frictionless by default). The press touches the warp's crest only and
the base the fill's trough, so the force crosses from yarn to yarn through their contact
(docs/solid.md §6). The yarns' end faces are held along their own yarn: the symmetry
planes of the periodic cell. d_c is the cell's loss of thickness (highest node less
lowest node, against the start): the plates' penalty overlaps are left out. F_c is the
mean of the two plates' forces. The run stops once F_c reaches the target force.
Quasi-static when the kinetic energy stays a small fraction of the internal work
(``kinetic_fraction``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from wovenimpact.calibration.compression import CompressionFit, fit_compression
from wovenimpact.calibration.crossover_cell import cell_solid
from wovenimpact.errors import InputError
from wovenimpact.interfaces import n_parts, part_names
from wovenimpact.kernels.contact_plane import PL_F
from wovenimpact.kernels.integrate import FIXED
from wovenimpact.model.model import BoundaryConditions, ShellContactParams, build_model
from wovenimpact.model.rigid_plane import RigidPlane
from wovenimpact.results.contact_forces import interface_forces
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver.explicit import Workspace, step
from wovenimpact.state import initial_state

# the yarns' end faces and the direction along each yarn
END_FACES = (("warp.x_min", 0), ("warp.x_max", 0), ("fill.y_min", 1), ("fill.y_max", 1))
# how the end faces are held: "symmetry" along their own yarn only (the periodic cell's
# symmetry planes), "thesis" in the two other directions only (thesis §5.3.2: "the only
# displacements authorized are along each yarn's principal direction")
END_CONDITIONS = ("symmetry", "thesis")


def cell_between_plates(cell_spec, material, *, speed: float = 1.0, ramp: float = 5e-6,
                        hourglass: float = 0.05, contact=None, ends: str = "symmetry"):
    """(cell, model): the crossover cell of a geometry spec (spec.crossover) of the
    transversely isotropic ``material`` between a held plate under it ("base") and one
    moving down at ``speed`` (m/s, ramped over ``ramp`` s) over it ("press"); the yarns'
    end faces held as ``ends`` says (:data:`END_CONDITIONS`)."""
    if ends not in END_CONDITIONS:
        raise InputError(f"ends = {ends!r}: valid are {', '.join(END_CONDITIONS)}")
    cell, part = cell_solid(cell_spec, material, hourglass)
    mesh = cell.mesh
    bcs = BoundaryConditions(len(mesh.nodes))
    for name, dof in END_FACES:
        held = (dof,) if ends == "symmetry" else tuple(d for d in range(3) if d != dof)
        for d in held:
            bcs.code[mesh.node_sets[name], d] = FIXED
    bcs.ramp_time = ramp
    z = mesh.nodes[:, 2]
    planes = [RigidPlane(point=(0.0, 0.0, z.min()), normal=(0.0, 0.0, 1.0), name="base"),
              RigidPlane(point=(0.0, 0.0, z.max()), normal=(0.0, 0.0, -1.0),
                         velocity=(0.0, 0.0, -speed), name="press")]
    model = build_model(mesh.nodes, np.zeros((0, 4), dtype=np.int64), {},
                        np.zeros(0, dtype=np.int64), bcs=bcs, solid=part,
                        rigid_planes=planes, node_sets=mesh.node_sets,
                        shell_contact=contact or ShellContactParams())
    return cell, model


@dataclass(frozen=True)
class CellCompression:
    """The curve of :func:`compress_cell` (SI) and its fit.

    Attributes:
        t, d, force: time, the cell's compression d_c and force F_c at each sample.
        force_base, force_press: the two plates' forces (their mean is ``force``).
        force_yarns: the vertical force the warp presses the fill with, through their
            contact (the thesis's F_c, "the contact force between the yarns"; equal to
            the plates' with the ends held by symmetry, less where the ends carry some).
        kinetic_fraction: the largest kinetic energy over the internal work in the
            second half of the run (quasi-static when small).
        hourglass_fraction: hourglass energy over internal work at the end.
        energy_error: the energy balance's error fraction at the end.
        fit: the compaction law fitted to the samples with F ≥ 1 % of the target; None
            when it does not fit (too few samples, or a curve without a limit).
        steps, elements: the steps taken and the hexahedra.
    """

    t: np.ndarray
    d: np.ndarray
    force: np.ndarray
    force_base: np.ndarray
    force_press: np.ndarray
    force_yarns: np.ndarray
    kinetic_fraction: float
    hourglass_fraction: float
    energy_error: float
    fit: CompressionFit | None
    steps: int
    elements: int


def compress_cell(cell_spec, material, *, force: float = 3.0, speed: float = 1.0,
                  ramp: float = 5e-6, sample: float = 0.5e-6, max_time: float = 1e-3,
                  hourglass: float = 0.05, ends: str = "symmetry",
                  measure: str = "plates") -> CellCompression:
    """Squeeze the cell until F_c reaches ``force`` (N) or ``max_time`` (s) passes,
    sampling every ``sample`` s (module docstring); fit a and b. F_c is the plates' mean
    force (``measure = "plates"``) or the yarns' contact force (``"yarns"``, the thesis's
    with its end conditions ``ends = "thesis"``)."""
    if measure not in ("plates", "yarns"):
        raise InputError(f"measure = {measure!r}: valid are plates, yarns")
    _, model = cell_between_plates(cell_spec, material, speed=speed, ramp=ramp,
                                   hourglass=hourglass, ends=ends)
    names = part_names(model)
    warp, fill, parts = names.index("warp"), names.index("fill"), n_parts(model)
    state = initial_state(model)
    ws = Workspace.for_model(model, state)
    thick0 = float(np.ptp(model.x0[:, 2]))
    rows = []
    kinetic = []
    next_sample = sample
    while state.t < max_time:
        step(model, state, ws)
        if state.t < next_sample:
            continue
        next_sample += sample
        f_base, f_press = -state.planes[0, PL_F + 2], state.planes[1, PL_F + 2]
        d = thick0 - float(np.ptp(state.x[:, 2]))
        f_yarns = -float(interface_forces(ws.contact, parts)[fill, warp, 2])
        f_c = 0.5 * (f_base + f_press) if measure == "plates" else f_yarns
        rows.append((state.t, d, f_c, f_base, f_press, f_yarns))
        balance = energy_balance(model, state)
        kinetic.append((state.t, balance["kinetic_J"], balance["internal_work_J"]))
        if rows[-1][2] >= force:
            break
    arr = np.array(rows).reshape(-1, 6)
    kin = np.array(kinetic).reshape(-1, 3)
    late = kin[:, 0] >= 0.5 * kin[-1, 0]
    kinetic_fraction = float(np.max(kin[late, 1] / np.maximum(kin[late, 2], 1e-300)))
    balance = energy_balance(model, state)
    use = (arr[:, 2] >= 0.01 * force) & (arr[:, 1] > 0.0)
    try:
        fit = fit_compression(arr[use, 1], arr[use, 2], source="crossover cell")
    except InputError:  # too few points, or a curve without a limit: no fit
        fit = None
    return CellCompression(
        t=arr[:, 0], d=arr[:, 1], force=arr[:, 2], force_base=arr[:, 3],
        force_press=arr[:, 4], force_yarns=arr[:, 5], kinetic_fraction=kinetic_fraction,
        hourglass_fraction=float(balance["hourglass_J"] / max(balance["internal_work_J"],
                                                               1e-300)),
        energy_error=float(balance["error_fraction"]), fit=fit, steps=int(state.step),
        elements=int(model.n_hexes))
