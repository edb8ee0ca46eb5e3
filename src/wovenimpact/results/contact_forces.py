"""Contact force per interface: the resultant force one part's surface exerts on
another's (what LS-DYNA writes to RCFORC), for history.csv (docs/outputs.md).

It is read from the pairs that acted at the last step's contact forces (the shells'
node–segment pairs, ``ShellContact.active``): a pair's force f acts on its node and −f,
shared by the weights, on its segment's corners, so the force part b exerts on part a
is

    F_ab = Σ_{pairs: node in a, segment in b} f  −  Σ_{pairs: node in b, segment in a} f

(both passes of a two-sided contact). It is computed when a row is written, not in the
step, so it costs the run nothing; a sum in pair order (``np.add.at``), the same for
any thread count.

The columns (:func:`contact_force_columns`) are those an engineer plots:

- a containment model: ``contact_force_blade_casing_N``, the magnitude of the force
  all casing layers exert on the blade, and ``contact_force_layer{k}_layer{k+1}_N``,
  that of layer k on layer k + 1 (innermost layer 0);
- a plate impact: ``contact_force_ply{p}_ply{q}_full_N`` for plies p, q met one after
  the other by the impactor (ordered along its initial travel), the force ply p exerts
  on ply q along that travel (positive: p pushes q ahead), times the symmetry factor —
  the convention of ``contact_force_full_N`` (the force on the impactor): whole-problem
  values.

Interfaces between the shells and a rigid body are the impactor's own columns; the
rigid plates' are not written here.
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from wovenimpact.interfaces import n_parts, part_arrays, part_names
from wovenimpact.model.model import travel_of_row
from wovenimpact.results.containment import is_containment
from wovenimpact.results.quantities import symmetry_factor


def interface_forces(cb, n_parts: int) -> np.ndarray:
    """(P, P, 3) F[a, b]: the force the surface of part b exerted on part a at the last
    contact forces (N, modelled part), P = ``n_parts``; zeros where no pair acted or the
    model has no shell contact. ``cb``: the step's solver.contact_stage.ContactBuffers."""
    out = np.zeros((n_parts, n_parts, 3))
    shells = cb.shells if cb is not None else None
    if shells is None or shells.n_active == 0:
        return out
    act = shells.active[:shells.n_active]
    nodes, pairs = act[:, 0], act[:, 1]
    a = cb.node_part[nodes]
    b = cb.seg_part[shells.pair_seg[pairs]]
    f = shells.pair_f[pairs, :3]
    np.add.at(out, (a, b), f)  # on the node's part, by the segment's
    np.add.at(out, (b, a), -f)  # and the reaction on the segment's part
    return out


def _numbered(names: list[str], stem: str) -> list[int]:
    """Indices of the parts named stem0, stem1, … in number order (until one is
    missing)."""
    found = []
    while f"{stem}{len(found)}" in names:
        found.append(names.index(f"{stem}{len(found)}"))
    return found


def _plies_along(model, names: list[str], direction: np.ndarray) -> list[tuple[str, int]]:
    """(name, part) of the parts named ply{p}, in the order the impactor travelling along
    ``direction`` meets them (their nodes' mean initial position along it)."""
    node_part = part_arrays(model)[0]
    plies = []
    for i, n in enumerate(names):
        if n.startswith("ply") and n[3:].isdigit():
            plies.append((float(np.mean(model.x0[node_part == i] @ direction)), n, i))
    return [(n, i) for _, n, i in sorted(plies)]


@dataclass(frozen=True)
class ForcePlan:
    """What a model's interface force columns read: per column, the part acted on and
    the parts acting (their forces summed), and whether the value is the magnitude or
    the component along ``direction`` times ``factor``."""

    columns: tuple[str, ...]
    on: tuple[int, ...]
    by: tuple[tuple[int, ...], ...]
    n_parts: int
    direction: np.ndarray | None  # None: the magnitude
    factor: float


def force_plan(model) -> ForcePlan:
    """The model's :class:`ForcePlan` (module docstring), made once per model (one entry
    kept, the model held by a weak reference: part_names reads every element set)."""
    ref = _PLAN_CACHE.get("model")
    if ref is not None and ref() is model:
        return _PLAN_CACHE["plan"]
    names = part_names(model)
    columns, on, by, direction, factor = [], [], [], None, 1.0
    if is_containment(model):
        layers = _numbered(names, "layer")
        if "blade" in names and layers:
            columns.append("contact_force_blade_casing_N")
            on.append(names.index("blade"))
            by.append(tuple(layers))
            for k in range(len(layers) - 1):
                columns.append(f"contact_force_layer{k}_layer{k + 1}_N")
                on.append(layers[k + 1])
                by.append((layers[k],))
    elif model.body_params.shape[0]:
        direction = travel_of_row(model, model.body_state0[0], 0)
        factor = symmetry_factor(model)
        plies = _plies_along(model, names, direction)
        for (p, i), (q, j) in zip(plies, plies[1:]):
            columns.append(f"contact_force_{p}_{q}_full_N")
            on.append(j)
            by.append((i,))
    plan = ForcePlan(tuple(columns), tuple(on), tuple(by), n_parts(model), direction, factor)
    _PLAN_CACHE.clear()
    _PLAN_CACHE.update(model=weakref.ref(model), plan=plan)
    return plan


_PLAN_CACHE: dict = {}


def contact_force_columns(model) -> tuple[str, ...]:
    """The interface force columns of the model's history (module docstring); none for a
    model without a blade and named layers, or without an impactor."""
    return force_plan(model).columns


def contact_force_row(model, cb) -> dict:
    """The interface force columns' values from the last contact forces (zeros before
    the first step: ``cb`` None)."""
    plan = force_plan(model)
    if not plan.columns:
        return {}
    F = interface_forces(cb, plan.n_parts)
    row = {}
    for name, a, bs in zip(plan.columns, plan.on, plan.by):
        f = F[a, list(bs)].sum(axis=0)
        row[name] = (float(np.linalg.norm(f)) if plan.direction is None
                     else float(f @ plan.direction * plan.factor))
    return row
