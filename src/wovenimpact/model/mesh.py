"""Shell meshes: the :class:`Mesh` container, structured plate meshes and distortion.

A :class:`Mesh` is what ``build_model`` needs for geometry (nodes, quads) plus the
ply index of each element and named node / element sets. Triangles are stored as
quads whose last node is repeated. Coordinates are in metres.

``plate_mesh`` builds the square target plates of the impact cases (full plate or
quarter model, one or several plies, each ply with its own nodes); ``distort``
perturbs the interior nodes of a single-ply mesh for patch tests.
"""

from __future__ import annotations

import math
import numbers
from dataclasses import dataclass, field

import numpy as np

from wovenimpact.errors import InputError

MAX_DISTORTION = 0.25  # amplitudes below this keep a square grid's quads convex


@dataclass
class Mesh:
    """Nodes, quads, ply indices and named sets of a shell mesh (SI, 0-based indices).

    Attributes:
        nodes: (n_nodes, 3) coordinates (m).
        quads: (n_elems, 4) node indices, counter-clockwise about the element normal;
            a triangle repeats its last node.
        ply: (n_elems,) ply (part) index of each element.
        node_sets: name → sorted node indices.
        elem_sets: name → element indices.
        hexes: (n_hexes, 8) node indices of the solid elements (8-node hexahedra, corners
            in VTK/Abaqus C3D8 order; docs/solid.md), numbered apart from the shells.
        hex_sets: name → hexahedron indices (the element sets of the solids).
        hex_frames: (n_hexes, 3, 3) material axes of the hexahedra (rows a1, a2, a3) that
            replace their solid sections' (a generated yarn's, following its centreline),
            or None.
    """

    nodes: np.ndarray
    quads: np.ndarray
    ply: np.ndarray
    node_sets: dict[str, np.ndarray] = field(default_factory=dict)
    elem_sets: dict[str, np.ndarray] = field(default_factory=dict)
    hexes: np.ndarray = field(default_factory=lambda: np.zeros((0, 8), dtype=np.int64))
    hex_sets: dict[str, np.ndarray] = field(default_factory=dict)
    hex_frames: np.ndarray | None = None

    def __post_init__(self) -> None:
        self.nodes = np.ascontiguousarray(self.nodes, dtype=float)
        self.quads = np.ascontiguousarray(self.quads, dtype=np.int64)
        self.ply = np.ascontiguousarray(self.ply, dtype=np.int64)
        if self.nodes.ndim != 2 or self.nodes.shape[1] != 3:
            raise InputError(f"mesh nodes must be an (n, 3) array, got shape {self.nodes.shape}")
        if self.quads.ndim != 2 or self.quads.shape[1] != 4:
            raise InputError(f"mesh quads must be an (m, 4) array, got shape {self.quads.shape}")
        if self.ply.shape != (len(self.quads),):
            raise InputError(
                f"mesh ply must give one index per element ({len(self.quads)}), "
                f"got shape {self.ply.shape}"
            )
        _check_indices("quads", self.quads, len(self.nodes), "node")
        self.node_sets = _index_sets("node set", self.node_sets, len(self.nodes), "node")
        self.elem_sets = _index_sets("element set", self.elem_sets, len(self.quads), "element")
        self.hexes = np.ascontiguousarray(self.hexes, dtype=np.int64).reshape(-1, 8)
        _check_indices("hexes", self.hexes, len(self.nodes), "node")
        self.hex_sets = _index_sets("element set", self.hex_sets, len(self.hexes),
                                    "hexahedron")
        if self.hex_frames is not None:
            self.hex_frames = np.ascontiguousarray(self.hex_frames, dtype=float)
            if self.hex_frames.shape != (len(self.hexes), 3, 3):
                raise InputError(f"mesh hex_frames must be an ({len(self.hexes)}, 3, 3) array, "
                                 f"got shape {self.hex_frames.shape}")

    @property
    def n_nodes(self) -> int:
        return self.nodes.shape[0]

    @property
    def n_elems(self) -> int:
        return self.quads.shape[0]

    def area_vectors(self) -> np.ndarray:
        """(n_elems, 3) ½ d13 × d24: element normal times area (exact for planar quads)."""
        return area_vectors(self.nodes, self.quads)


def node_set(mesh: Mesh, name: str, key: str) -> np.ndarray:
    """The nodes of the set ``name`` of ``mesh`` (``"all"``: every node); an InputError
    naming the case ``key`` and the sets there if it has none of that name."""
    if name == "all":
        return np.arange(mesh.n_nodes)
    if name not in mesh.node_sets:
        raise InputError(f"{key}: node set {name!r} does not exist; sets: "
                         f"{sorted(set(mesh.node_sets) | {'all'})}")
    return np.asarray(mesh.node_sets[name], dtype=np.int64)


def area_vectors(nodes: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """½ (x3 − x1) × (x4 − x2) of each quad: its area along its normal."""
    xe = nodes[quads]
    return 0.5 * np.cross(xe[:, 2] - xe[:, 0], xe[:, 3] - xe[:, 1])


def _check_indices(label: str, idx: np.ndarray, n: int, what: str) -> None:
    if idx.size and (idx.min() < 0 or idx.max() >= n):
        bad = int(idx.min()) if idx.min() < 0 else int(idx.max())
        raise InputError(f"{label} refer to {what} {bad}; valid: 0 ≤ index < {n}")


def _index_sets(kind: str, sets: dict, n: int, what: str) -> dict[str, np.ndarray]:
    out = {}
    for name, idx in sets.items():
        a = np.ascontiguousarray(idx, dtype=np.int64).ravel()
        _check_indices(f"{kind} {name!r}", a, n, what)
        out[str(name)] = a
    return out


# --- structured plates --------------------------------------------------------------


def plate_mesh(
    side: float,
    element_size: float,
    plies: int = 1,
    spacing: float = 0.0,
    quarter: bool = False,
    z0: float = 0.0,
    width: float | None = None,
) -> Mesh:
    """Square (or rectangular) plate of ``plies`` plies in the planes z = z0 + k·spacing.

    The full plate spans [−side/2, side/2] × [−width/2, width/2] (width = side unless
    given: a square), the quarter model [0, side/2] × [0, width/2] (with symmetry on
    x = 0 and y = 0). The quarter model has round(side / 2 / element_size) elements
    along x and round(width / 2 / element_size) along y (at least 1 each); the full
    plate twice that, so that a node always sits at the centre and the full plate is
    the mirror image of the quarter model. Each ply has its own nodes (numbered ply by
    ply, x fastest).

    Node sets: "all", "edge_outer" (the clamped edges: all four for the full plate,
    x = side/2 and y = width/2 for the quarter model), "edge_x" / "edge_y" (the edges
    normal to x, x = ±side/2, and to y, y = ±width/2; in the quarter model the outer
    one only: a strip along x is clamped at its ends by "edge_x"), "symmetry_x" /
    "symmetry_y" (quarter model: nodes on x = 0 / y = 0), "centre" (the node at
    x = y = 0 of each ply) and "ply{k}". Element sets: "all" and "ply{k}".

    Args:
        side: length of the full plate along x (m).
        element_size: target element edge length (m), 0 < element_size ≤ side
            and ≤ width.
        plies: number of plies, ≥ 1.
        spacing: distance between ply mid-planes (m), > 0 when plies > 1.
        quarter: build the quarter model instead of the full plate.
        z0: height of the first ply (m).
        width: length of the full plate along y (m); None: ``side`` (a square).
    """
    _check_plate_arguments(side, element_size, plies, spacing, z0)
    coords = _axis_coordinates(side, element_size, quarter)
    n = len(coords) - 1
    if width is None:
        ycoords, ny = coords, n
    else:
        if not (_finite(width) and width > 0):
            raise InputError(f"width = {width!r} m; valid: a finite length > 0")
        if not element_size <= width:
            raise InputError(f"element_size = {element_size!r} m; valid: 0 < element_size "
                             f"≤ width ({width!r} m)")
        ycoords = _axis_coordinates(width, element_size, quarter)
        ny = len(ycoords) - 1
    per_ply = (n + 1) * (ny + 1)
    gx, gy = np.meshgrid(coords, ycoords)  # row j holds y = ycoords[j]
    nodes = np.concatenate([
        np.column_stack([gx.ravel(), gy.ravel(), np.full(per_ply, z0 + k * spacing)])
        for k in range(plies)
    ])
    base = _grid_quads(n, ny)
    quads = np.concatenate([base + k * per_ply for k in range(plies)])
    ply = np.repeat(np.arange(plies, dtype=np.int64), len(base))
    local = _plate_local_node_sets(n, quarter, ny)
    node_sets = {name: _per_ply(idx, per_ply, plies) for name, idx in local.items()}
    node_sets["all"] = np.arange(plies * per_ply, dtype=np.int64)
    elem_sets = {"all": np.arange(len(quads), dtype=np.int64)}
    for k in range(plies):
        node_sets[f"ply{k}"] = np.arange(k * per_ply, (k + 1) * per_ply, dtype=np.int64)
        elem_sets[f"ply{k}"] = np.arange(k * len(base), (k + 1) * len(base), dtype=np.int64)
    return Mesh(nodes=nodes, quads=quads, ply=ply, node_sets=node_sets, elem_sets=elem_sets)


def _finite(x) -> bool:
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and math.isfinite(x)


def _check_plate_arguments(side, element_size, plies, spacing, z0) -> None:
    if not (_finite(side) and side > 0):
        raise InputError(f"side = {side!r} m; valid: a finite length > 0")
    if not (_finite(element_size) and 0 < element_size <= side):
        raise InputError(
            f"element_size = {element_size!r} m; valid: 0 < element_size ≤ side ({side!r} m)"
        )
    if isinstance(plies, bool) or not isinstance(plies, (int, np.integer)) or plies < 1:
        raise InputError(f"plies = {plies!r}; valid: a whole number ≥ 1")
    if not _finite(spacing):
        raise InputError(f"spacing = {spacing!r} m; valid: a finite distance")
    if plies > 1 and spacing <= 0:
        raise InputError(
            f"spacing = {spacing!r} m with plies = {plies}; valid: the distance between "
            "ply mid-planes, > 0"
        )
    if not _finite(z0):
        raise InputError(f"z0 = {z0!r} m; valid: a finite height")


def _axis_coordinates(side: float, element_size: float, quarter: bool) -> np.ndarray:
    """Node coordinates along one edge: 0 and ±side/2 exactly, symmetric about 0."""
    half = 0.5 * side
    n_half = max(1, math.floor(half / element_size + 0.5))
    pos = np.linspace(0.0, half, n_half + 1)
    return pos if quarter else np.concatenate([-pos[:0:-1], pos])


def _grid_quads(n: int, ny: int | None = None) -> np.ndarray:
    """Quads of an (n+1)×(ny+1) node grid (ny = n by default), x fastest,
    counter-clockwise seen from +z."""
    ny = n if ny is None else ny
    j, i = np.divmod(np.arange(n * ny, dtype=np.int64), n)
    n0 = j * (n + 1) + i
    return np.column_stack([n0, n0 + 1, n0 + n + 2, n0 + n + 1])


def _plate_local_node_sets(n: int, quarter: bool, ny: int | None = None
                           ) -> dict[str, np.ndarray]:
    """Node sets of one ply's (n+1)×(ny+1) grid (ny = n by default)."""
    ny = n if ny is None else ny
    j, i = np.divmod(np.arange((n + 1) * (ny + 1), dtype=np.int64), n + 1)
    where = np.flatnonzero
    if quarter:
        return {
            "edge_outer": where((i == n) | (j == ny)),
            "edge_x": where(i == n),
            "edge_y": where(j == ny),
            "symmetry_x": where(i == 0),
            "symmetry_y": where(j == 0),
            "centre": where((i == 0) & (j == 0)),
        }
    return {
        "edge_outer": where((i == 0) | (i == n) | (j == 0) | (j == ny)),
        "edge_x": where((i == 0) | (i == n)),
        "edge_y": where((j == 0) | (j == ny)),
        "centre": where((i == n // 2) & (j == ny // 2)),
    }


def _per_ply(local: np.ndarray, per_ply: int, plies: int) -> np.ndarray:
    return np.concatenate([local + k * per_ply for k in range(plies)])


# --- distortion for patch tests -----------------------------------------------------


def distort(mesh: Mesh, amplitude: float, seed: int) -> Mesh:
    """A copy of a single-ply planar mesh with its interior nodes moved at random.

    Each node not on the mesh boundary moves in the x–y plane by a vector drawn
    uniformly from the disc of radius amplitude × h, h the shortest element edge.
    For a grid of squares any amplitude < 0.25 keeps every quad convex; the result
    is checked either way.

    Args:
        mesh: one ply (all ``mesh.ply`` equal), all nodes at the same z.
        amplitude: fraction of the element size, 0 ≤ amplitude < 0.25.
        seed: seed of the random generator (same seed, same mesh).
    """
    if not 0.0 <= amplitude < MAX_DISTORTION:
        raise InputError(f"amplitude = {amplitude!r}; valid: 0 ≤ amplitude < {MAX_DISTORTION}")
    if np.unique(mesh.ply).size > 1:
        raise InputError(
            f"distort needs a single-ply mesh; this one has plies {np.unique(mesh.ply).tolist()}"
        )
    if mesh.n_nodes and np.ptp(mesh.nodes[:, 2]) > 0.0:
        raise InputError("distort moves nodes in the x–y plane; all nodes must have the same z")
    h = _shortest_edge(mesh)
    interior = np.setdiff1d(np.arange(mesh.n_nodes), boundary_nodes(mesh.quads))
    rng = np.random.default_rng(seed)
    radius = amplitude * h * np.sqrt(rng.random(interior.size))
    angle = 2.0 * np.pi * rng.random(interior.size)
    nodes = mesh.nodes.copy()
    nodes[interior, 0] += radius * np.cos(angle)
    nodes[interior, 1] += radius * np.sin(angle)
    bad = np.flatnonzero(~_same_turns(mesh.nodes, nodes, mesh.quads))
    if bad.size:
        raise InputError(
            f"amplitude = {amplitude!r} makes element {int(bad[0])} non-convex; use a smaller one"
        )
    return Mesh(
        nodes=nodes, quads=mesh.quads.copy(), ply=mesh.ply.copy(),
        node_sets={k: v.copy() for k, v in mesh.node_sets.items()},
        elem_sets={k: v.copy() for k, v in mesh.elem_sets.items()},
    )


def _edges(quads: np.ndarray) -> np.ndarray:
    """(4 m, 2) element edges, each sorted, degenerate (repeated-node) edges removed."""
    e = np.stack([quads, np.roll(quads, -1, axis=1)], axis=2).reshape(-1, 2)
    e = np.sort(e, axis=1)
    return e[e[:, 0] != e[:, 1]]


def boundary_nodes(quads: np.ndarray) -> np.ndarray:
    """Sorted nodes on edges that belong to a single element."""
    edges, count = np.unique(_edges(quads), axis=0, return_counts=True)
    return np.unique(edges[count == 1])


def _shortest_edge(mesh: Mesh) -> float:
    e = _edges(mesh.quads)
    if not len(e):
        raise InputError("distort needs a mesh with at least one element")
    return float(np.min(np.linalg.norm(mesh.nodes[e[:, 1]] - mesh.nodes[e[:, 0]], axis=1)))


def _corner_turns(nodes: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """(m, 4) z-component of (x_{c+1} − x_c) × (x_{c+2} − x_{c+1}) at each corner."""
    xe = nodes[quads][:, :, :2]
    a = np.roll(xe, -1, axis=1) - xe
    b = np.roll(a, -1, axis=1)
    return a[:, :, 0] * b[:, :, 1] - a[:, :, 1] * b[:, :, 0]


def _same_turns(before: np.ndarray, after: np.ndarray, quads: np.ndarray) -> np.ndarray:
    """Per element: every non-degenerate corner turns the same way as before, strictly."""
    t0, t1 = _corner_turns(before, quads), _corner_turns(after, quads)
    degenerate = t0 == 0.0  # the corners of a repeated node
    return np.all(degenerate | (np.sign(t1) == np.sign(t0)), axis=1)
