"""Contact interfaces: the parts that meet, their names, and the energy booked per
interface (docs/theory.md §6, "Contact energy per interface").

A *part* is a contact surface (``Model.ply``: a plate's ply, a casing's layer, the blade,
an imported mesh's part or element set) or a rigid body; an *interface* is a pair of
parts, (part of the node, part of the segment or body), both passes of a node–segment
pair in one: "ply0-ply1", "layer3-layer4", "layer0-blade", "ply0-impactor".
``State.contact_books`` holds, per kind (kernels.contact_energy: SPRING, DAMPING,
FRICTION) and ordered pair of parts, the energy that part of the contact forces took
out of the structure.
"""

from __future__ import annotations

import numpy as np

from wovenimpact.kernels.contact_energy import DAMPING, FRICTION, N_KINDS, SPRING

# at most this many surfaces get books of their own; those beyond share the last one
# (an imported mesh of many loose parts would otherwise make the books large)
MAX_SURFACES = 64


def solid_body_count(model) -> int:
    """The model's connected solid bodies (each a contact surface; docs/solid.md §6)."""
    solid = getattr(model, "solid", None)
    return solid.n_bodies if solid is not None and solid.n_hexes else 0


def surface_labels(model) -> tuple[np.ndarray, int, bool]:
    """(elem_part, n_surfaces, lumped): each element's part, the rank of its
    ``Model.ply`` label among the model's labels, and the number of surface parts; with
    more than MAX_SURFACES labels (``lumped``) the ranks from MAX_SURFACES − 1 on share
    the last part. The solid bodies are surfaces after the shells' (:func:`hex_parts`);
    the rigid bodies and the rigid plates follow the surfaces (:func:`n_parts`)."""
    labels, rank = np.unique(model.ply, return_inverse=True)
    n_labels = labels.size + solid_body_count(model)
    lumped = n_labels > MAX_SURFACES
    return (np.minimum(rank, MAX_SURFACES - 1).astype(np.int64),
            int(max(min(n_labels, MAX_SURFACES), 1)), bool(lumped))


def hex_parts(model) -> np.ndarray:
    """(n_hexes,) the part of each hexahedron: its solid body's, after the shells'
    surfaces."""
    if not solid_body_count(model):
        return np.zeros(0, dtype=np.int64)
    first = np.unique(model.ply).size
    return np.minimum(first + model.solid.body, MAX_SURFACES - 1).astype(np.int64)


def n_parts(model) -> int:
    """Parts of the books: the surfaces, then one per rigid body, then one per rigid
    plate."""
    return (surface_labels(model)[1] + int(model.body_params.shape[0])
            + len(getattr(model, "rigid_planes", ())))


def part_arrays(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(node_part, elem_part, body_part): the part of each node (the lowest of its
    elements', shells' then hexahedra's; 0 for a node without elements), of each
    element and of each body, then of each rigid plate (``body_part`` holds both)."""
    elem_part, n_surf, _ = surface_labels(model)
    n = model.n_nodes
    counts = np.diff(model.node_ptr)
    low = np.full(n, np.iinfo(np.int64).max)
    np.minimum.at(low, np.repeat(np.arange(n), counts), elem_part[model.node_elem])
    if solid_body_count(model):
        np.minimum.at(low, model.solid.hexes.ravel(), np.repeat(hex_parts(model), 8))
        counts = counts + np.diff(model.solid.node_ptr)
    node_part = np.where(counts > 0, low, 0).astype(np.int64)
    n_rigid = int(model.body_params.shape[0]) + len(getattr(model, "rigid_planes", ()))
    body_part = n_surf + np.arange(n_rigid, dtype=np.int64)
    return node_part, elem_part, body_part


def empty_books(model) -> np.ndarray:
    """State.contact_books at t = 0: (2, N_KINDS, P, P) zeros, P = :func:`n_parts`; [0]
    the energy booked up to the last whole step, [1] the second half of the last step's
    forces, booked against the velocities after it (kernels.contact_energy), added to
    [0] at the next step."""
    p = n_parts(model)
    return np.zeros((2, N_KINDS, p, p))


def part_names(model) -> list[str]:
    """A name per part that a user recognises: the element set that holds exactly the
    surface's elements — "ply{k}" of a plate, "layer{k}" and "blade" of a containment
    model (the name after the last dot where those are distinct; the shortest set if
    several match) — else "surface{k}" ("other surfaces" for the lumped last part); the
    bodies "impactor" (or "impactor{b}" with several)."""
    elem_part, n_surf, lumped = surface_labels(model)
    sets = {name: np.sort(np.asarray(e, dtype=np.int64)) for name, e in model.elem_sets.items()
            if name != "all"}
    exact: list[str | None] = []
    for part in range(n_surf):
        elems = np.flatnonzero(elem_part == part)
        found = sorted((name for name, e in sets.items() if np.array_equal(e, elems)),
                       key=lambda name: (len(name), name))
        exact.append(found[0] if found else None)
    tails = [None if e is None else e.rsplit(".", 1)[-1] for e in exact]
    n_shell_surf = np.unique(model.ply).size
    hexp = hex_parts(model)
    hex_sets = {name: np.sort(np.asarray(e, dtype=np.int64))
                for name, e in getattr(getattr(model, "solid", None), "sets", {}).items()
                if name != "all"}
    for part in range(n_shell_surf, n_surf):  # the solid bodies: a hexahedron set's name
        hexes = np.flatnonzero(hexp == part)
        found = sorted((name for name, e in hex_sets.items() if np.array_equal(e, hexes)),
                       key=lambda name: (len(name), name))
        exact[part] = found[0] if found else None
        tails[part] = exact[part]
    names = []
    for part, (full, tail) in enumerate(zip(exact, tails)):
        if lumped and part == n_surf - 1:
            names.append("other surfaces")
        elif full is None:
            names.append(f"surface{part}")
        else:
            names.append(tail if tails.count(tail) == 1 else full)
    nb = int(model.body_params.shape[0])
    names += ["impactor"] if nb == 1 else [f"impactor{b}" for b in range(nb)]
    names += [plane.name for plane in getattr(model, "rigid_planes", ())]
    return names


def interface_energies(model, books: np.ndarray, kind: int, factor: float = 1.0) -> dict:
    """{"a-b": J} of one kind (DAMPING, FRICTION or SPRING) of the booked energies
    ``books`` (State.contact_books[0]), both orders of each pair of parts summed, times
    ``factor`` (the symmetry factor: whole-problem values); only the interfaces where
    contact acted (any kind booked), in the order of their parts."""
    names = part_names(model)
    p = books.shape[1]
    out = {}
    for a in range(p):
        for b in range(a, p):
            both = books[:, a, b] + (books[:, b, a] if b != a else 0.0)
            if np.any(both != 0.0):
                out[f"{names[a]}-{names[b]}"] = factor * float(both[kind])
    return out


def booked_totals(books: np.ndarray) -> dict[str, float]:
    """The books summed over every interface (J, modelled part): spring, damping and
    friction; their sum is −W_contact (the solver's contact work) to round-off."""
    return {"spring": float(np.sum(books[SPRING])), "damping": float(np.sum(books[DAMPING])),
            "friction": float(np.sum(books[FRICTION]))}
