"""Read shell meshes from gmsh files (``.msh``; meshio reads formats 2.2 and 4.1).

Shell elements are the file's quads and triangles (a triangle is stored as a quad with
its last node repeated, as for Abaqus files). Sets come from gmsh's *physical groups*:
a 2-D group becomes an element set of its quads and triangles, and every group of any
dimension (points, curves, surfaces) a node set of its elements' nodes, so that a
curve group names the edge to clamp. Names are the groups' names (``$PhysicalNames``);
an unnamed group is ``"<dim>:<tag>"``; elements in no group (physical tag 0) are in
no set. Line and point elements are not shells: they
only feed the node sets. Any other element type (volumes) is an :class:`InputError`.

Groups may overlap (a strip of the blade in both BLADE and RELEASE). Format 2.2 writes
such an element once per group: shell elements with identical node lists are merged
into one element that is in every group it was listed in. In format 4.1 meshio keeps
only the first physical group of each gmsh entity, so the other groups lose those
elements (:func:`gmsh_hint` says so where a set is missing).
"""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.model.mesh import Mesh

SHELL_TYPES = ("quad", "triangle")
SET_ONLY_TYPES = ("line", "vertex")


def read_msh(path: str | Path) -> Mesh:
    """Nodes, shell elements and physical-group sets of a gmsh file, 0-based; coordinates
    as written (the caller scales them by ``mesh.length_unit``). ``Mesh.ply`` is 0."""
    path = Path(path)
    if not path.is_file():
        raise InputError(f"mesh file {str(path)!r} not found")
    try:
        raw = meshio.read(path, file_format="gmsh")
    except (Exception, SystemExit) as err:  # meshio raises many kinds (even exits) on bad files
        raise InputError(f"{path}: not a readable gmsh file ({type(err).__name__}: "
                         f"{str(err)[:200]})") from None
    bad = sorted({b.type for b in raw.cells} - set(SHELL_TYPES) - set(SET_ONLY_TYPES))
    if bad:
        raise InputError(f"{path}: element types {bad} are not shells; a shell mesh has "
                         "quads and triangles (and lines or points for boundary groups)")
    physical = raw.cell_data.get("gmsh:physical")  # tag 0: in no physical group
    if physical is None or not any(np.any(np.asarray(t) != 0) for t in physical):
        raise InputError(f"{path}: no physical groups; name the surfaces (and the curves "
                         "to clamp) as physical groups in gmsh so that sections and "
                         "boundaries can refer to them")
    names = {(int(dim), int(tag)): name for name, (tag, dim) in raw.field_data.items()}
    quads, groups, node_groups = [], [], {}
    for block, tags in zip(raw.cells, physical):
        data = np.asarray(block.data, dtype=np.int64)
        dim = {"vertex": 0, "line": 1}.get(block.type, 2)
        for tag in np.unique(tags[tags != 0]):
            name = names.get((dim, int(tag)), f"{dim}:{int(tag)}")
            nodes = np.unique(data[tags == tag])
            node_groups[name] = np.union1d(node_groups.get(name, nodes[:0]), nodes)
        if block.type in SHELL_TYPES:
            quads.append(data if data.shape[1] == 4 else np.column_stack([data, data[:, 2]]))
            groups.append(np.asarray(tags, dtype=np.int64))
    if not quads:
        raise InputError(f"{path}: no shell elements (quads or triangles) found")
    quads, groups = np.concatenate(quads), np.concatenate(groups)
    # one element per distinct node list, in the file's order; element[i]: row i's element
    _, first, row_of = np.unique(quads, axis=0, return_index=True, return_inverse=True)
    order = np.argsort(first)
    element = np.argsort(order)[row_of.ravel()]
    quads = quads[first[order]]
    elem_sets = {names.get((2, int(t)), f"2:{int(t)}"): np.unique(element[groups == t])
                 for t in np.unique(groups[groups != 0])}
    pts = np.asarray(raw.points, dtype=float)
    nodes = pts if pts.shape[1] == 3 else np.column_stack([pts, np.zeros(len(pts))])
    used = np.unique(quads)
    if used.size < len(nodes):  # gmsh keeps geometry points no element uses: drop them
        renumber = np.full(len(nodes), -1, dtype=np.int64)
        renumber[used] = np.arange(used.size)
        quads = renumber[quads]
        nodes = nodes[used]
        node_groups = {k: renumber[v[renumber[v] >= 0]] for k, v in node_groups.items()}
    return Mesh(nodes=nodes, quads=quads, ply=np.zeros(len(quads), dtype=np.int64),
                node_sets={k: np.sort(v) for k, v in node_groups.items()},
                elem_sets=elem_sets)


def gmsh_hint(file: str) -> str:
    """Text to append to a "set not found" error about mesh ``file``: for a gmsh file,
    that meshio reads only the first physical group of each entity in format 4.1 and
    that format 2.2 keeps them all; "" for any other file."""
    if not str(file).lower().endswith(".msh"):
        return ""
    return ("; if it is a gmsh 4.1 file: meshio reads only the first physical group of each "
            "gmsh entity in format 4.1 (a surface in two groups is in the first only), so "
            "save the mesh in format 2.2 (gmsh -format msh22) to keep overlapping groups")
