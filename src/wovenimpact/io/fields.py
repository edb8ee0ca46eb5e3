"""Field output: one VTU file per output time and a ParaView collection (``fields.pvd``).

Each ``step_{k:06d}.vtu`` (k the output frame, 0, 1, 2, …) holds the current
configuration ``State.x`` with

- point data ``displacement`` x − x0 (m) and ``velocity`` (m/s);
- cell data ``membrane_resultant`` (N_xx, N_yy, N_xy; N/m, corotational frame),
  ``alive`` (1 alive, 0 eroded), ``ply``, ``element`` (the Model's element index),
  and ``tension_warp``, ``tension_fill`` (N), ``damage_warp``, ``damage_fill`` (—),
  which are 0 for elements that are not fabric, ``thickness_ratio`` t/t0 and
  ``plastic_strain`` (the largest ε̄p of the element's points), 1 and 0 for elements
  that are not metal (metal_state), and ``fabric`` (1 where the element's material is
  a fabric, else 0);
- cell data ``von_mises_stress`` (Pa) and ``stress`` (σ_xx, σ_yy, σ_xy; Pa) of metal (J2)
  elements: of the element's points (in-plane and through the thickness), the one with
  the largest von Mises stress, its Cauchy stress in the point's rotated frame
  (metal_state.largest_von_mises); 0 for elements that are not J2;
- cell data ``element_set``: the index of the element's region, the element sets it
  belongs to (:func:`element_set_regions`), named in ``element_sets.json`` beside the
  frames, so ParaView's Threshold on it picks out a layer, ply or part.

Quads are written as VTK quads; an element whose quad repeats a node (a triangle)
is written as a VTK triangle in a second cell block, so VTK filters never see a
degenerate quad; a model of triangles only (or a part with no quads) has just the
triangle block. The ``element`` cell array maps cells back to Model elements.

Hexahedra (solid elements, docs/solid.md) are written as VTK hexahedra in a block of their
own, in the first part's files; their ``element`` is the Model's hexahedron index and
``ply`` their solid section's index. In a model with hexahedra every cell also has
``solid`` (1 for a hexahedron, 0 for a shell) and ``solid_stress`` (the hexahedron's
Cauchy stress σ in global axes, Voigt order 11, 22, 33, 23, 13, 12; Pa; 0 on shells), and
a hexahedron's ``von_mises_stress`` is that of σ; the other shell arrays are 0 there
(``alive``, ``thickness_ratio`` 1; ``element_set`` −1, the element sets being the shells').
After every file ``fields.pvd`` is rewritten atomically to list all files with
their times; ParaView opens it as one time series.

Parts: a model made of separate bodies can be written one file per body and frame,
``step_{k:06d}_{part}.vtu`` (each with its own nodes only), listed in ``fields.pvd``
with the collection's ``part`` index, which ParaView opens as the blocks of one
multiblock series — a containment run's ``casing`` and ``blade`` (:func:`model_parts`).
"""

from __future__ import annotations

import json
import xml.etree.ElementTree as ET
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.io.atomic import atomic_path, atomic_write_text
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels import solid_layout as HL
from wovenimpact.results.metal_state import (
    largest_von_mises,
    max_plastic_strain,
    thickness_ratio,
)
from wovenimpact.state import State

PVD_NAME = "fields.pvd"
SETS_NAME = "element_sets.json"  # the names of the ``element_set`` cell array's indices


def frame_name(k: int, part: str = "") -> str:
    """File name of output frame ``k`` (of ``part``, when the series has parts)."""
    return f"step_{k:06d}_{part}.vtu" if part else f"step_{k:06d}.vtu"


def model_parts(model) -> list[tuple[str, np.ndarray]]:
    """The (name, elements) parts a model's series is written in: a containment model's
    casing (elements of the ``casing.*`` sets' nodes) and blade (the rest), each its own
    block; any other model one unnamed part, every element (one file per frame)."""
    casing_sets = [k for k in model.node_sets if k.startswith("casing.layer")]
    if "blade.fragment" not in model.node_sets or not casing_sets:
        return [("", np.arange(model.n_elems, dtype=np.int64))]
    on = np.zeros(model.n_nodes, dtype=bool)
    for k in casing_sets:
        on[model.node_sets[k]] = True
    casing = on[model.quads].all(axis=1)
    return [("casing", np.flatnonzero(casing)), ("blade", np.flatnonzero(~casing))]


def fabric_elements(model) -> np.ndarray:
    """(n_elems,) True where the element's section material is a fabric."""
    mat = model.sections[model.elem_section, SL.C_MAT].astype(np.int64)
    return model.mat_kind[mat] == SL.MAT_FABRIC


def element_set_regions(model) -> tuple[np.ndarray, list[list[str]]]:
    """(n_elems,) region index of each element and, per index, the names of the element
    sets its elements belong to (sorted by name).

    Element sets may overlap (a plate's ``all`` and ``ply0``, a blade's ``blade`` and
    ``fragment``), so one index per set cannot label the cells; a region is a distinct
    combination of sets, so the regions partition the elements and each set is the union of
    the regions that name it. A set holding every element (``all``) tells nothing and is left
    out; elements in no set form a region with no name ([]), placed last. Regions are
    numbered in order of their sets' names (the region of the first set first)."""
    names = sorted(k for k, v in model.elem_sets.items()
                   if 0 < np.unique(np.asarray(v, dtype=np.int64)).size < model.n_elems)
    if not names:
        return np.zeros(model.n_elems, dtype=np.int64), [[]]
    member = np.zeros((model.n_elems, len(names)), dtype=bool)
    for j, k in enumerate(names):
        member[np.asarray(model.elem_sets[k], dtype=np.int64), j] = True
    rows, inverse = np.unique(member, axis=0, return_inverse=True)
    combos = [tuple(int(j) for j in np.flatnonzero(r)) for r in rows]
    order = sorted(range(len(combos)), key=lambda i: (not combos[i], combos[i]))
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    return rank[np.asarray(inverse).ravel()], [[names[j] for j in combos[i]] for i in order]


def element_sets_json(model, regions: list[list[str]], ids: np.ndarray) -> str:
    """Text of ``element_sets.json``: each ``element_set`` index with its sets and element
    count, each set with its indices, and the sets left out (holding every element)."""
    sets = {k: sorted(i for i, r in enumerate(regions) if k in r) for r in regions for k in r}
    counts = np.bincount(ids, minlength=len(regions))
    return json.dumps({
        "cell_array": "element_set",
        "regions": [{"element_set": i, "sets": r, "elements": int(counts[i])}
                    for i, r in enumerate(regions)],
        "sets": dict(sorted(sets.items())),
        "left_out": sorted(k for k in model.elem_sets if k not in sets),
    }, indent=1) + "\n"


def cell_blocks(quads: np.ndarray) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(VTK cell type, element indices, connectivity) of the quad and triangle blocks;
    a block with no cells is left out (meshio's VTU writer fails on an empty block)."""
    q = np.asarray(quads, dtype=np.int64)
    distinct = q != np.roll(q, -1, axis=1)  # corner c differs from corner c + 1
    tri = distinct.sum(axis=1) == 3
    conn = q[tri][distinct[tri]].reshape(-1, 3)  # drop the repeated corner, keep order
    blocks = [("quad", np.flatnonzero(~tri), q[~tri]), ("triangle", np.flatnonzero(tri), conn)]
    return [b for b in blocks if len(b[1])]


def element_fields(model, state: State, fabric: np.ndarray) -> dict[str, np.ndarray]:
    """Per-element output arrays (index = Model element)."""
    out = {
        "membrane_resultant": state.elem[:, SL.E_N:SL.E_N + 3],
        "alive": state.elem[:, SL.E_ALIVE],
        "ply": np.asarray(model.ply, dtype=np.int64),
        "element": np.arange(model.n_elems, dtype=np.int64),
    }
    # integrated sections: the mid-surface point of the first in-plane point (row
    # points // 2 of the element's material rows, Model.mat_row)
    n_points = model.sections[model.elem_section, SL.C_POINTS].astype(np.int64)
    elems = np.flatnonzero(fabric)
    rows = model.mat_row[elems] + n_points[elems] // 2
    for name, col in (("tension_warp", FL.S_TENSION), ("tension_fill", FL.S_TENSION + 1),
                      ("damage_warp", FL.S_DAMAGE), ("damage_fill", FL.S_DAMAGE + 1)):
        values = np.zeros(model.n_elems)
        if elems.size:
            values[elems] = state.mat[rows, col]
        out[name] = values
    out["thickness_ratio"] = thickness_ratio(model, state)
    out["plastic_strain"] = max_plastic_strain(model, state)
    out["fabric"] = np.asarray(fabric, dtype=np.int64)
    out["von_mises_stress"], out["stress"] = largest_von_mises(model, state)
    return out


def hex_fields(model, state: State, shell_fields: dict) -> dict[str, np.ndarray]:
    """Per-hexahedron output arrays with the names and widths of ``shell_fields`` (module
    docstring: 0 but for ``alive``, ``ply``, ``element``, ``thickness_ratio``, the
    stresses and ``solid``)."""
    n = model.n_hexes
    out = {name: np.zeros((n,) + np.shape(a)[1:], dtype=np.asarray(a).dtype)
           for name, a in shell_fields.items()}
    sig = state.hex[:, HL.H_SIG:HL.H_SIG + 6]
    out["alive"] = np.ones(n)
    out["ply"] = np.asarray(model.solid.section, dtype=np.int64)
    out["element"] = np.arange(n, dtype=np.int64)
    out["thickness_ratio"] = np.ones(n)
    out["element_set"] = np.full(n, -1, dtype=np.int64)
    dev = sig[:, :3] - sig[:, :3].mean(axis=1, keepdims=True)
    out["von_mises_stress"] = np.sqrt(1.5 * np.sum(dev**2, axis=1)
                                      + 3.0 * np.sum(sig[:, 3:]**2, axis=1))
    out["solid"] = np.ones(n, dtype=np.int64)
    out["solid_stress"] = np.ascontiguousarray(sig)
    return out


class FieldWriter:
    """Writes the VTU series of a run and keeps ``fields.pvd`` up to date.

    A new writer starts a new series at frame 0 (overwriting the files of an earlier
    one); :meth:`resume` continues an existing series after a restart.

    Args:
        directory: output directory (created if needed).
        model: the Model the states belong to.
        entries: (time, file name) already in the series (see :meth:`resume`).
        parts: (name, element indices) of the blocks each frame is written in, one file
            each (default :func:`model_parts`); one unnamed part writes one file per frame.
    """

    def __init__(self, directory: str | Path, model, entries=(), parts=None) -> None:
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.model = model
        self._entries: list[tuple[float, str]] = [(float(t), str(f)) for t, f in entries]
        self._parts = []
        for k, (name, elems) in enumerate(model_parts(model) if parts is None else parts):
            elems = np.asarray(elems, dtype=np.int64)
            hexes = model.solid.hexes if k == 0 else np.zeros((0, 8), dtype=np.int64)
            nodes = np.unique(np.concatenate([model.quads[elems].ravel(), hexes.ravel()]))
            local = np.full(model.n_nodes, -1, dtype=np.int64)
            local[nodes] = np.arange(nodes.size)
            blocks = cell_blocks(local[model.quads[elems]])
            if len(hexes):
                blocks.append(("hexahedron", np.arange(len(hexes)), local[hexes]))
            self._parts.append((name, elems, nodes, blocks))
        self._names = [name for name, *_ in self._parts]
        self._fabric = fabric_elements(model)
        self._sets, regions = element_set_regions(model)
        atomic_write_text(self.directory / SETS_NAME,
                          element_sets_json(model, regions, self._sets))

    @property
    def entries(self) -> tuple[tuple[float, str], ...]:
        """(time, file name) of every file in the series, in order."""
        return tuple(self._entries)

    @property
    def frames(self) -> int:
        """Frames written (each a file per part)."""
        return len(self._entries) // len(self._parts)

    def write(self, state: State, time: float | None = None) -> Path:
        """Write ``state`` as the next frame (at ``time``, default ``state.t``); returns
        the path of its (first part's) file."""
        t = float(state.t if time is None else time)
        if state.x.shape != self.model.x0.shape:
            raise InputError(f"state has {state.x.shape[0]} nodes, the model {self.model.n_nodes}")
        if self._entries and not t >= self._entries[-1][0]:
            raise InputError(f"field output time {t!r} s is before the last one "
                             f"({self._entries[-1][0]!r} s); times must not decrease")
        k = self._next_frame()
        per_elem = element_fields(self.model, state, self._fabric)
        per_elem["element_set"] = self._sets
        per_hex = None
        if self.model.n_hexes:
            per_elem["solid"] = np.zeros(self.model.n_elems, dtype=np.int64)
            per_elem["solid_stress"] = np.zeros((self.model.n_elems, 6))
            per_hex = hex_fields(self.model, state, per_elem)
        paths = []
        for part in self._parts:
            path = self.directory / frame_name(k, part[0])
            with atomic_path(path) as tmp:
                meshio.write(tmp, self._mesh(state, per_elem, part, per_hex),
                             file_format="vtu")
            self._entries.append((t, path.name))
            paths.append(path)
        self._write_pvd()
        return paths[0]

    @classmethod
    def resume(cls, directory: str | Path, model, frames: int, parts=None) -> FieldWriter:
        """Continue the series in ``directory`` after a restart whose checkpoint counted
        ``frames`` frames: the series goes on at frame ``frames``. Frames after those
        are dropped from ``fields.pvd`` and their files deleted (the restarted run writes
        them again); a collection listing fewer frames, or naming a missing file, is an
        :class:`InputError` (resuming would overwrite or lose frames).
        """
        directory = Path(directory)
        names = [name for name, _ in (model_parts(model) if parts is None else parts)]
        entries = read_pvd(directory / PVD_NAME)
        expected = [frame_name(k, name) for k in range(frames) for name in names]
        kept = entries[:len(expected)]
        if [name for _, name in kept] != expected:
            raise InputError(
                f"--restart: {directory / PVD_NAME} lists {len(entries) // len(names)} frames, "
                f"the checkpoint counts {frames} ({expected[0] if expected else ''}…); resuming "
                "would overwrite or lose frames: run without --restart to start again")
        missing = [name for _, name in kept if not (directory / name).exists()]
        if missing:
            raise InputError(f"--restart: {directory / missing[0]} (frame of the checkpoint's "
                             "series) is missing; run without --restart to start again")
        for old in directory.glob("step_*.vtu"):
            k = _frame_index(old.name)
            if k is not None and k >= frames:
                old.unlink()
        writer = cls(directory, model, kept, parts=parts)
        writer._write_pvd()
        return writer

    def _next_frame(self) -> int:
        frames = [_frame_index(name) for _, name in self._entries]
        return 1 + max((k for k in frames if k is not None), default=-1)

    def _mesh(self, state: State, per_elem: dict, part, per_hex=None) -> meshio.Mesh:
        _, elems, nodes, blocks = part

        def values(name, kind, idx):
            if kind == "hexahedron":  # (idx: the hexahedra)
                return np.ascontiguousarray(per_hex[name][idx])
            return np.ascontiguousarray(per_elem[name][elems[idx]])

        return meshio.Mesh(
            points=np.ascontiguousarray(state.x[nodes], dtype=float),
            cells=[(kind, conn) for kind, _, conn in blocks],
            point_data={"displacement": state.x[nodes] - self.model.x0[nodes],
                        "velocity": np.ascontiguousarray(state.v[nodes], dtype=float)},
            cell_data={name: [values(name, kind, idx) for kind, idx, _ in blocks]
                       for name in per_elem},
        )

    def _write_pvd(self) -> None:
        part_of = {name: i for i, name in enumerate(self._names)}
        atomic_write_text(self.directory / PVD_NAME, pvd_text(
            self._entries, [part_of.get(_part_name(f), 0) for _, f in self._entries]))


def pvd_text(entries, parts=None) -> str:
    """ParaView collection XML listing (time, file) entries, each in block ``parts[i]``
    (default 0)."""
    parts = [0] * len(entries) if parts is None else parts
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    lines += [f'    <DataSet timestep="{float(t)!r}" group="" part="{int(p)}" '
              f'file={quoteattr(f)}/>' for (t, f), p in zip(entries, parts)]
    lines += ["  </Collection>", "</VTKFile>", ""]
    return "\n".join(lines)


def read_pvd(path: str | Path) -> list[tuple[float, str]]:
    """(time, file) entries of a collection file; [] if it does not exist."""
    path = Path(path)
    if not path.exists():
        return []
    try:
        root = ET.parse(path).getroot()
        return [(float(d.attrib["timestep"]), d.attrib["file"]) for d in root.iter("DataSet")]
    except (ET.ParseError, KeyError, ValueError) as exc:
        raise InputError(f"field collection {path} is unreadable ({exc}); delete it and the "
                         "step_*.vtu files to start the series again") from None


def _frame_index(name: str) -> int | None:
    """k of ``step_{k}.vtu`` or ``step_{k}_{part}.vtu``; None for any other name."""
    stem = Path(name).stem
    digits = stem.removeprefix("step_").split("_", 1)[0]
    return int(digits) if stem.startswith("step_") and digits.isdigit() else None


def _part_name(name: str) -> str:
    """The part of ``step_{k}_{part}.vtu`` ("" for ``step_{k}.vtu``)."""
    rest = Path(name).stem.removeprefix("step_").split("_", 1)
    return rest[1] if len(rest) == 2 else ""
