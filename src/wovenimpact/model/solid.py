"""Solid parts of a Model: 8-node hexahedra of a transversely isotropic elastic material.

docs/solid.md states the element (kernels/hex8.py) and the material
(kernels/transverse_isotropic.py); this module makes the arrays the solver reads of them:

- :class:`SolidSection`: a solid section, its material, hourglass coefficient r and the
  material axes of its elements (the fibre direction a1 and a direction for a2);
- :func:`solid_part` → :class:`SolidPart`: per hexahedron its material row, material frame
  M0 (rows a1, a2, a3), reference gradients b⁰_I, volume V0, hourglass stiffness
  k = r G_hg V0 Σ_I b⁰_I·b⁰_I and mass ρ V0 (lumped ⅛ to each corner by ``build_model``), and
  the node → (hexahedron, corner) map in CSR form through which the node pass gathers the
  corner forces (no scatter: the sum is the same for any thread count);
- :func:`block_mesh`: a box of hexahedra (``[mesh] kind = "block"``).

A Model without solids carries :data:`NO_SOLIDS`, whose arrays are empty.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.kernels import solid_layout as HL
from wovenimpact.kernels.hex8 import reference_geometry_for_hexes
from wovenimpact.materials.transverse_isotropic import (
    TransverseIsotropicParameters,
    material_frame,
)
from wovenimpact.model.mesh import Mesh

# a frame whose rows are further than this from orthonormal is refused
FRAME_TOLERANCE = 1e-9
# the faces of a block and the coordinate each lies at: (axis, 0 lower / 1 upper)
BLOCK_FACES = {"x_min": (0, 0), "x_max": (0, 1), "y_min": (1, 0), "y_max": (1, 1),
               "z_min": (2, 0), "z_max": (2, 1)}


@dataclass(frozen=True)
class SolidSection:
    """A solid section: the material of its hexahedra and their material axes.

    Attributes:
        material: a transversely isotropic elastic material (thesis Table 5-2's yarn).
        hourglass: r of the hourglass stiffness k = r G_hg V0 Σ_I b⁰_I·b⁰_I (docs/solid.md
            §1.3), 0 ≤ r < 1; default 0.05.
        fibre_direction: the fibre axis a1 of every element of the section (global; a
            per-element frame given to :func:`solid_part` wins).
        second_direction: a direction for a2, projected off a1 (default: the global axis
            least aligned with a1); a3 = a1 × a2.
    """

    material: TransverseIsotropicParameters
    hourglass: float = 0.05
    fibre_direction: tuple[float, float, float] = (1.0, 0.0, 0.0)
    second_direction: tuple[float, float, float] | None = None

    def frame(self) -> np.ndarray:
        """M0 (3×3, rows a1, a2, a3) of the section's elements."""
        return material_frame(self.fibre_direction, self.second_direction)


def is_solid_material(material) -> bool:
    """A material of solid sections (transversely isotropic), not of shells."""
    return isinstance(material, TransverseIsotropicParameters)


def _empty_int(*shape) -> np.ndarray:
    return np.zeros(shape, dtype=np.int64)


@dataclass(frozen=True, eq=False)
class SolidPart:
    """The hexahedra of a Model (SI). Never mutated; the solver reads them.

    Attributes:
        hexes: (n_hexes, 8) corner nodes (VTK/Abaqus C3D8 order).
        section: (n_hexes,) index into ``section_names``.
        section_names: the solid sections' names.
        mat: (n_hexes,) row of ``params``.
        params: (n_materials, N_TI_PARAM) material rows (solid_layout ``TI_*``).
        material_names: the materials' names.
        hourglass: (n_sections,) each section's hourglass coefficient r.
        frame: (n_hexes, 3, 3) material axes M0, rows a1, a2, a3 (global components).
        ref_grad: (n_hexes, 3, 8) reference gradients b⁰_I.
        vol0: (n_hexes,) reference volumes V0 (m³).
        hg_stiffness: (n_hexes,) hourglass stiffness k (N/m).
        mass: (n_hexes,) element masses ρ V0 (kg).
        node_ptr, node_elem, node_corner: CSR map node → (hexahedron, corner), the
            hexahedra in increasing order per node; node_ptr has n_nodes + 1 entries
            (empty for :data:`NO_SOLIDS`).
        sets: name → hexahedron indices (the solids' element sets).
        faces: (n_faces, 4) the exterior faces (those of one hexahedron only), their
            corners counter-clockwise seen from outside (x,ξ × x,η points out): the
            contact segments of the solids (docs/solid.md §6).
        face_hex: (n_faces,) the hexahedron of each exterior face.
        body: (n_hexes,) the solid body of each hexahedron: the connected sets of
            hexahedra (sharing a node), numbered in the order of their lowest
            hexahedron: each body is a contact surface of its own.
    """

    hexes: np.ndarray = field(default_factory=lambda: _empty_int(0, 8))
    section: np.ndarray = field(default_factory=lambda: _empty_int(0))
    section_names: tuple = ()
    mat: np.ndarray = field(default_factory=lambda: _empty_int(0))
    params: np.ndarray = field(default_factory=lambda: np.zeros((0, HL.N_TI_PARAM)))
    material_names: tuple = ()
    hourglass: np.ndarray = field(default_factory=lambda: np.zeros(0))
    frame: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 3)))
    ref_grad: np.ndarray = field(default_factory=lambda: np.zeros((0, 3, 8)))
    vol0: np.ndarray = field(default_factory=lambda: np.zeros(0))
    hg_stiffness: np.ndarray = field(default_factory=lambda: np.zeros(0))
    mass: np.ndarray = field(default_factory=lambda: np.zeros(0))
    node_ptr: np.ndarray = field(default_factory=lambda: _empty_int(0))
    node_elem: np.ndarray = field(default_factory=lambda: _empty_int(0))
    node_corner: np.ndarray = field(default_factory=lambda: _empty_int(0))
    sets: dict = field(default_factory=dict)
    faces: np.ndarray = field(default_factory=lambda: _empty_int(0, 4))
    face_hex: np.ndarray = field(default_factory=lambda: _empty_int(0))
    body: np.ndarray = field(default_factory=lambda: _empty_int(0))

    @property
    def n_bodies(self) -> int:
        """The connected solid bodies (contact surfaces)."""
        return int(self.body.max()) + 1 if self.body.size else 0

    @property
    def n_hexes(self) -> int:
        return self.hexes.shape[0]

    def node_masses(self, n_nodes: int) -> np.ndarray:
        """(n_nodes,) the lumped masses ρ V0 / 8 at each corner, summed per node."""
        out = np.zeros(n_nodes)
        if self.n_hexes:
            np.add.at(out, self.hexes.ravel(), np.repeat(0.125 * self.mass, 8))
        return out

    def digest_into(self, h) -> None:
        """Add every array that sets the solids' response to the SHA-256 ``h``."""
        for name in ("hexes", "section", "mat", "params", "hourglass", "frame", "vol0",
                     "hg_stiffness", "mass"):
            a = np.ascontiguousarray(getattr(self, name))
            h.update(b"solid." + name.encode())
            h.update(str(a.dtype).encode() + str(a.shape).encode())
            h.update(a.tobytes())

    def digest(self) -> str:
        h = hashlib.sha256()
        self.digest_into(h)
        return h.hexdigest()


NO_SOLIDS = SolidPart()


def hex_node_map(hexes: np.ndarray, n_nodes: int):
    """CSR map node → (hexahedron, corner), the hexahedra in increasing order per node."""
    flat = hexes.ravel()
    order = np.argsort(flat, kind="stable")
    ptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(flat, minlength=n_nodes), out=ptr[1:])
    return ptr, (order // 8).astype(np.int64), (order % 8).astype(np.int64)


# the six faces of a hexahedron in VTK/Abaqus corner order, each counter-clockwise seen
# from outside: ζ = −1, ζ = +1, η = −1, ξ = +1, η = +1, ξ = −1
HEX_FACES = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6],
                      [3, 0, 4, 7]], dtype=np.int64)


def exterior_faces(hexes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(faces, face_hex): the faces that belong to one hexahedron only (a face is known
    by its sorted corners), outward-ordered (:data:`HEX_FACES`), in hexahedron and face
    order."""
    if not hexes.shape[0]:
        return _empty_int(0, 4), _empty_int(0)
    all_faces = hexes[:, HEX_FACES].reshape(-1, 4)
    key = np.sort(all_faces, axis=1)
    _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    once = np.flatnonzero(counts[inverse.ravel()] == 1)
    return (np.ascontiguousarray(all_faces[once], dtype=np.int64),
            (once // 6).astype(np.int64))


def solid_bodies(hexes: np.ndarray, n_nodes: int) -> np.ndarray:
    """(n_hexes,) the connected body of each hexahedron (hexahedra sharing a node are
    one body), bodies numbered in the order of their lowest hexahedron."""
    parent = np.arange(n_nodes)

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for h in hexes:
        r0 = root(h[0])
        for c in h[1:]:
            rc = root(c)
            if rc != r0:
                parent[max(rc, r0)] = min(rc, r0)
                r0 = min(rc, r0)
    roots = np.array([root(h[0]) for h in hexes], dtype=np.int64)
    _, first, label = np.unique(roots, return_index=True, return_inverse=True)
    rank = np.argsort(np.argsort(first))  # bodies in the order of their lowest hexahedron
    return rank[label.ravel()].astype(np.int64)


def solid_node_map(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The model's node → (hexahedron, corner) map; all-zero pointers (no entries) for a
    model without solids."""
    s = model.solid
    if s.node_ptr.shape[0] == model.n_nodes + 1:
        return s.node_ptr, s.node_elem, s.node_corner
    return _empty_int(model.n_nodes + 1), _empty_int(0), _empty_int(0)


def _frames(sections: list[SolidSection], section: np.ndarray, frames) -> np.ndarray:
    """(n, 3, 3) material axes: ``frames`` as given (checked orthonormal and right-handed),
    else each section's."""
    n = section.shape[0]
    if frames is None:
        per_section = np.array([s.frame() for s in sections]).reshape(-1, 3, 3)
        return np.ascontiguousarray(per_section[section]) if n else np.zeros((0, 3, 3))
    f = np.ascontiguousarray(np.broadcast_to(np.asarray(frames, dtype=float).reshape(-1, 3, 3),
                                             (n, 3, 3)))
    err = np.abs(np.einsum("nij,nkj->nik", f, f) - np.eye(3)).max(axis=(1, 2)) if n else []
    det = np.linalg.det(f) if n else []
    bad = np.flatnonzero(~((np.asarray(err) < FRAME_TOLERANCE) & (np.asarray(det) > 0.0)))
    if bad.size:
        e = int(bad[0])
        raise InputError(f"hexahedron {e}: its material axes {f[e].tolist()} are not "
                         "orthonormal and right-handed (rows a1, a2, a3 = a1 × a2)")
    return f


def section_indices(given, names: list[str], n: int, kind: str, argument: str,
                    entity: str) -> np.ndarray:
    """(n,) int64 row indices of each element's section: ``given`` names (looked up in
    ``names``) or indices already; an InputError for an unknown ``kind`` name or a count
    that is not one per ``entity`` (``argument`` names the input). Used for the shells'
    sections (model.section_table) and the hexahedra's (:func:`solid_part`)."""
    sec = np.asarray(given)
    if sec.dtype.kind in "US":
        unknown = sorted(set(sec.tolist()) - set(names))
        if unknown:
            raise InputError(f"unknown {kind} {unknown[0]!r}; defined: {names}")
        sec = np.array([names.index(s) for s in sec.tolist()], dtype=np.int64)
    sec = np.ascontiguousarray(sec, dtype=np.int64)
    if sec.shape != (n,):
        raise InputError(f"{argument} must give one section per {entity} ({n})")
    return sec


def solid_part(x0, hexes, sections: dict[str, SolidSection], hex_section, frames=None,
               sets: dict | None = None) -> SolidPart:
    """The solid arrays of a Model (module docstring).

    Args:
        x0: (n_nodes, 3) reference coordinates (m).
        hexes: (n_hexes, 8) corner nodes in VTK/Abaqus C3D8 order.
        sections: name → SolidSection.
        hex_section: (n_hexes,) section name (str) or index into ``sections``.
        frames: (n_hexes, 3, 3) or (3, 3) material axes (rows a1, a2, a3) that replace the
            sections' (a yarn whose fibre follows its centreline); None: the sections'.
        sets: name → hexahedron indices.

    Raises:
        InputError: a node index out of range, an unknown section, a section whose
            material is not transversely isotropic, r outside [0, 1), a frame that is not
            a rotation, or an element of non-positive volume (corners not in C3D8 order,
            or a degenerate element), naming the element and its nodes.
    """
    x0 = np.ascontiguousarray(x0, dtype=float)
    h = np.ascontiguousarray(hexes, dtype=np.int64)
    if h.ndim != 2 or h.shape[1] != 8:
        raise InputError(f"hexes must be an (n, 8) array, got shape {h.shape}")
    if h.size and (h.min() < 0 or h.max() >= len(x0)):
        raise InputError(f"hexes refer to node {int(h.max())}, but there are {len(x0)} nodes")
    names = list(sections)
    sec = section_indices(hex_section, names, len(h), "solid section", "hex_section",
                          "hexahedron")
    mats: list[TransverseIsotropicParameters] = []
    for name in names:
        s = sections[name]
        if not is_solid_material(s.material):
            raise InputError(f"section {name!r}: a solid section needs a transversely "
                             f"isotropic material (kind = 'transversely_isotropic'), not "
                             f"{getattr(s.material, 'name', s.material)!r}")
        if not 0.0 <= s.hourglass < 1.0:
            raise InputError(f"section {name!r}: hourglass = {s.hourglass!r}; valid: "
                             "0 ≤ r < 1")
        if not any(s.material is m for m in mats):
            mats.append(s.material)
    sec_mat = np.array([next(i for i, m in enumerate(mats) if m is sections[n].material)
                        for n in names], dtype=np.int64)
    params = (np.array([m.to_array() for m in mats]) if mats
              else np.zeros((0, HL.N_TI_PARAM)))
    mat = sec_mat[sec] if len(h) else _empty_int(0)
    r = np.array([sections[n].hourglass for n in names], dtype=float)
    frame = _frames([sections[n] for n in names], sec, frames)
    ne = len(h)
    ref_grad = np.zeros((ne, 3, 8))
    vol0 = np.zeros(ne)
    k = np.zeros(ne)
    if ne:
        scale = np.ascontiguousarray(r[sec] * params[mat, HL.TI_HG_MODULUS])
        reference_geometry_for_hexes(h, x0, scale, ref_grad, vol0, k)
    bad = np.flatnonzero(~(vol0 > 0.0))
    if bad.size:
        e = int(bad[0])
        raise InputError(
            f"hexahedron {e} (nodes {h[e].tolist()}) has a non-positive volume "
            f"{vol0[e]:.3g} m³{f' ({bad.size} such elements)' if bad.size > 1 else ''}: its "
            "corners must follow the C3D8 order (0–3 one face counter-clockwise seen from "
            "the opposite face 4–7, node 4 above node 0)")
    ptr, elem, corner = hex_node_map(h, len(x0))
    faces, face_hex = exterior_faces(h)
    return SolidPart(
        hexes=h, section=sec, section_names=tuple(names), mat=mat, params=params,
        material_names=tuple(m.name for m in mats), hourglass=r, frame=frame,
        ref_grad=ref_grad, vol0=vol0, hg_stiffness=k, mass=params[mat, HL.TI_RHO] * vol0,
        node_ptr=ptr, node_elem=elem, node_corner=corner,
        sets={str(k_): np.asarray(v, dtype=np.int64) for k_, v in (sets or {}).items()},
        faces=faces, face_hex=face_hex, body=solid_bodies(h, len(x0)))


def block_mesh(size, elements, origin=(0.0, 0.0, 0.0)) -> Mesh:
    """A box of hexahedra: ``elements`` = (nx, ny, nz) along the edges ``size`` =
    (Lx, Ly, Lz) (m) from the corner ``origin``; nodes numbered x fastest, then y, then z.

    Node sets: "all" and the faces "x_min", "x_max", "y_min", "y_max", "z_min", "z_max".
    Element sets (of the hexahedra, ``Mesh.hex_sets``): "all".
    """
    lx, ly, lz = (float(v) for v in size)
    n = [int(v) for v in elements]
    if not all(np.isfinite(v) and v > 0.0 for v in (lx, ly, lz)):
        raise InputError(f"block size {list(size)} is not valid: three lengths > 0")
    if len(n) != 3 or min(n) < 1:
        raise InputError(f"block elements {list(elements)} are not valid: three counts ≥ 1")
    nx, ny, nz = n
    axes = [np.linspace(0.0, length, k + 1) + float(o)
            for length, k, o in zip((lx, ly, lz), n, origin)]
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    nodes = np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)

    def nid(i, j, k):
        return i + (nx + 1) * (j + (ny + 1) * k)

    i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
    i, j, k = (a.transpose(2, 1, 0).ravel() for a in (i, j, k))  # x fastest
    corners = [(HL.HEX_XI[c] > 0, HL.HEX_ETA[c] > 0, HL.HEX_ZETA[c] > 0) for c in range(8)]
    hexes = np.stack([nid(i + a, j + b, k + c) for a, b, c in corners], axis=1)
    grid = np.stack(np.meshgrid(np.arange(nx + 1), np.arange(ny + 1), np.arange(nz + 1),
                                indexing="ij"), axis=-1).transpose(2, 1, 0, 3).reshape(-1, 3)
    node_sets = {"all": np.arange(len(nodes))}
    for name, (axis, upper) in BLOCK_FACES.items():
        node_sets[name] = np.flatnonzero(grid[:, axis] == (n[axis] if upper else 0))
    return Mesh(nodes=nodes, quads=np.zeros((0, 4), dtype=np.int64),
                ply=np.zeros(0, dtype=np.int64), node_sets=node_sets,
                hexes=hexes.astype(np.int64), hex_sets={"all": np.arange(len(hexes))})
