"""Field output: one VTU file per output time and a ParaView collection (``fields.pvd``).

Each ``step_{k:06d}.vtu`` (k the output frame, 0, 1, 2, …) holds the current
configuration ``State.x`` with

- point data ``displacement`` x − x0 (m) and ``velocity`` (m/s);
- cell data ``membrane_resultant`` (N_xx, N_yy, N_xy; N/m, corotational frame),
  ``alive`` (1 alive, 0 eroded), ``ply``, ``element`` (the Model's element index),
  and ``tension_warp``, ``tension_fill`` (N), ``damage_warp``, ``damage_fill`` (—),
  which are 0 for elements that are not fabric, and ``thickness_ratio`` t/t0 and
  ``plastic_strain`` (the largest ε̄p of the element's points), 1 and 0 for elements
  that are not metal (metal_state).

Quads are written as VTK quads; an element whose quad repeats a node (a triangle)
is written as a VTK triangle in a second cell block, so VTK filters never see a
degenerate quad. The ``element`` cell array maps cells back to Model elements.
After every file ``fields.pvd`` is rewritten atomically to list all files with
their times; ParaView opens it as one time series.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.io.atomic import atomic_path, atomic_write_text
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import shell_layout as S
from wovenimpact.metal_state import max_plastic_strain, thickness_ratio
from wovenimpact.state import State

PVD_NAME = "fields.pvd"


def frame_name(k: int) -> str:
    """File name of output frame ``k``."""
    return f"step_{k:06d}.vtu"


def fabric_elements(model) -> np.ndarray:
    """(n_elems,) True where the element's section material is a fabric."""
    mat = model.sections[model.elem_section, S.C_MAT].astype(np.int64)
    return model.mat_kind[mat] == S.MAT_FABRIC


def cell_blocks(quads: np.ndarray) -> list[tuple[str, np.ndarray, np.ndarray]]:
    """(VTK cell type, element indices, connectivity) of the quad and triangle blocks."""
    q = np.asarray(quads, dtype=np.int64)
    distinct = q != np.roll(q, -1, axis=1)  # corner c differs from corner c + 1
    tri = distinct.sum(axis=1) == 3
    blocks = [("quad", np.flatnonzero(~tri), q[~tri])]
    if tri.any():
        idx = np.flatnonzero(tri)
        conn = q[tri][distinct[tri]].reshape(-1, 3)  # drop the repeated corner, keep order
        blocks.append(("triangle", idx, conn))
    return blocks


def element_fields(model, state: State, fabric: np.ndarray) -> dict[str, np.ndarray]:
    """Per-element output arrays (index = Model element)."""
    out = {
        "membrane_resultant": state.elem[:, S.E_N:S.E_N + 3],
        "alive": state.elem[:, S.E_ALIVE],
        "ply": np.asarray(model.ply, dtype=np.int64),
        "element": np.arange(model.n_elems, dtype=np.int64),
    }
    # integrated sections: the mid-surface point (block points // 2 of the state row)
    # (a point's block is model.point_width wide: 16 beside a metal section, not FL.N_STATE)
    mid = (model.sections[model.elem_section, S.C_POINTS].astype(np.int64) // 2) * model.point_width
    rows = np.flatnonzero(fabric)
    for name, col in (("tension_warp", FL.S_TENSION), ("tension_fill", FL.S_TENSION + 1),
                      ("damage_warp", FL.S_DAMAGE), ("damage_fill", FL.S_DAMAGE + 1)):
        values = np.zeros(model.n_elems)
        if rows.size:
            values[rows] = state.mat[rows, mid[rows] + col]
        out[name] = values
    out["thickness_ratio"] = thickness_ratio(model, state)
    out["plastic_strain"] = max_plastic_strain(model, state)
    return out


class FieldWriter:
    """Writes the VTU series of a run and keeps ``fields.pvd`` up to date.

    A new writer starts a new series at frame 0 (overwriting the files of an earlier
    one); :meth:`resume` continues an existing series after a restart.

    Args:
        directory: output directory (created if needed).
        model: the Model the states belong to.
        entries: (time, file name) already in the series (see :meth:`resume`).
    """

    def __init__(self, directory: str | Path, model, entries=()) -> None:
        self.directory = Path(directory)
        self.directory.mkdir(parents=True, exist_ok=True)
        self.model = model
        self._entries: list[tuple[float, str]] = [(float(t), str(f)) for t, f in entries]
        self._blocks = cell_blocks(model.quads)
        self._fabric = fabric_elements(model)

    @property
    def entries(self) -> tuple[tuple[float, str], ...]:
        """(time, file name) of every file in the series, in order."""
        return tuple(self._entries)

    def write(self, state: State, time: float | None = None) -> Path:
        """Write ``state`` as the next frame (at ``time``, default ``state.t``)."""
        t = float(state.t if time is None else time)
        if state.x.shape != self.model.x0.shape:
            raise InputError(f"state has {state.x.shape[0]} nodes, the model {self.model.n_nodes}")
        if self._entries and not t >= self._entries[-1][0]:
            raise InputError(f"field output time {t!r} s is before the last one "
                             f"({self._entries[-1][0]!r} s); times must not decrease")
        path = self.directory / frame_name(self._next_frame())
        with atomic_path(path) as tmp:
            meshio.write(tmp, self._mesh(state), file_format="vtu")
        self._entries.append((t, path.name))
        self._write_pvd()
        return path

    @classmethod
    def resume(cls, directory: str | Path, model, t: float) -> FieldWriter:
        """Continue the series in ``directory`` after a restart from time ``t``.

        Entries with time > t are dropped from ``fields.pvd`` and their files deleted
        (the restarted run writes them again).
        """
        entries = read_pvd(Path(directory) / PVD_NAME)
        kept = [(time, name) for time, name in entries if not time > t]
        for _, name in entries[len(kept):]:
            (Path(directory) / name).unlink(missing_ok=True)
        writer = cls(directory, model, kept)
        writer._write_pvd()
        return writer

    def _next_frame(self) -> int:
        frames = [_frame_index(name) for _, name in self._entries]
        return 1 + max((k for k in frames if k is not None), default=-1)

    def _mesh(self, state: State) -> meshio.Mesh:
        per_elem = element_fields(self.model, state, self._fabric)
        return meshio.Mesh(
            points=np.ascontiguousarray(state.x, dtype=float),
            cells=[(kind, conn) for kind, _, conn in self._blocks],
            point_data={"displacement": state.x - self.model.x0,
                        "velocity": np.ascontiguousarray(state.v, dtype=float)},
            cell_data={name: [np.ascontiguousarray(a[idx]) for _, idx, _ in self._blocks]
                       for name, a in per_elem.items()},
        )

    def _write_pvd(self) -> None:
        atomic_write_text(self.directory / PVD_NAME, pvd_text(self._entries))


def pvd_text(entries) -> str:
    """ParaView collection XML listing (time, file) entries."""
    lines = ['<?xml version="1.0"?>',
             '<VTKFile type="Collection" version="0.1" byte_order="LittleEndian">',
             "  <Collection>"]
    lines += [f'    <DataSet timestep="{float(t)!r}" group="" part="0" file={quoteattr(f)}/>'
              for t, f in entries]
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
    stem = Path(name).stem
    digits = stem.removeprefix("step_")
    return int(digits) if stem.startswith("step_") and digits.isdigit() else None
