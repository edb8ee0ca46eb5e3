"""``wovenimpact crossover-cell GEOMETRY.toml``: the crossover cell of a geometry file,
written to look at and described in numbers (docs/solid.md §5).

:func:`write_cell` generates the cell (model/crossover_cell.py) and writes

- ``OUT/cell.vtu``: the hexahedra on their reference positions, with cell data ``yarn``
  (0 warp, 1 fill), ``fibre_direction`` (a1, the material axis along the yarn) and
  ``volume`` (m³), for ParaView;
- ``OUT/cell.json``: :func:`cell_summary`, the numbers also returned.

The virtual tests run the cell from a case (``[mesh] kind = "crossover"``).
"""

from __future__ import annotations

import json
from pathlib import Path

import meshio
import numpy as np

from wovenimpact.io.atomic import atomic_path, atomic_write_text
from wovenimpact.model.crossover_cell import (
    FAMILIES,
    CrossoverCell,
    crossover_cell,
    section_area,
    yarn_clearance,
)
from wovenimpact.model.solid import SolidSection, solid_part
from wovenimpact.materials.transverse_isotropic import TransverseIsotropicParameters
from wovenimpact.spec.crossover import load_geometry

# a unit material to measure the elements' volumes with (any would do)
_UNIT = SolidSection(TransverseIsotropicParameters(e11=1.0, e22=1.0, g12=1.0, g23=1.0,
                                                   nu12=0.0, nu23=0.0, density=1.0))


def cell_solid(cell_spec, material, hourglass: float = 0.05):
    """(cell, part): the crossover cell of a geometry spec (spec.crossover) and its
    yarns as one solid section of ``material`` (hourglass coefficient ``hourglass``), the
    material axes following the yarns — what the virtual tests run
    (calibration.cell_compression, calibration.cell_extension)."""
    cell = crossover_cell(cell_spec)
    mesh = cell.mesh
    part = solid_part(mesh.nodes, mesh.hexes,
                      {"yarn": SolidSection(material, hourglass=hourglass)},
                      np.zeros(len(mesh.hexes), dtype=np.int64), frames=cell.frames,
                      sets=mesh.hex_sets)
    return cell, part


def element_volumes(cell: CrossoverCell) -> np.ndarray:
    """V0 of each hexahedron (m³), the exact volume of the trilinear element."""
    n = len(cell.mesh.hexes)
    return solid_part(cell.mesh.nodes, cell.mesh.hexes, {"unit": _UNIT},
                      np.zeros(n, dtype=np.int64), frames=cell.frames).vol0


def cell_summary(cell: CrossoverCell, name: str = "") -> dict:
    """The cell in numbers (SI): its extent and thickness, each yarn's half-length
    between crossings ℓ, amplitude h0, crimp of its centreline, width, thickness, exact
    trimmed section area and meshed volume, the yarns' volume fraction of the cell (meshed
    volume / (cell area × thickness)), the smallest clearance between the yarns, and the
    element and node counts."""
    v = element_volumes(cell)
    sx, sy = cell.size
    out = {"cell": name, "section": cell.shape, "trim": cell.trim,
           "cell_size_x_m": sx, "cell_size_y_m": sy, "thickness_m": cell.thickness}
    total = 0.0
    for family in FAMILIES:
        y = cell.yarns[family]
        vol = float(v[cell.mesh.hex_sets[family]].sum())
        total += vol
        out.update({
            f"{family}_half_length_m": y.half_length,
            f"{family}_h0_m": y.amplitude,
            f"{family}_crimp": y.crimp,
            f"{family}_width_m": y.width,
            f"{family}_thickness_m": y.thickness,
            f"{family}_section_area_m2": section_area(cell.shape, cell.trim, y.width,
                                                       y.thickness),
            f"{family}_volume_m3": vol,
        })
    out["volume_fraction"] = total / (sx * sy * cell.thickness)
    out["clearance_m"] = yarn_clearance(cell.yarns, cell.shape, cell.trim)[0]
    out["elements"] = int(len(cell.mesh.hexes))
    out["nodes"] = int(cell.mesh.n_nodes)
    out["smallest_volume_m3"] = float(v.min())
    return out


def write_cell(geometry: str | Path, out: str | Path) -> dict:
    """Generate the cell of ``geometry`` and write ``out/cell.vtu`` and ``out/cell.json``
    (module docstring); returns the summary."""
    spec = load_geometry(geometry)
    cell = crossover_cell(spec)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary = cell_summary(cell, spec.cell.name)
    yarn = np.zeros(len(cell.mesh.hexes), dtype=np.int64)
    yarn[cell.mesh.hex_sets["fill"]] = 1
    mesh = meshio.Mesh(points=cell.mesh.nodes, cells=[("hexahedron", cell.mesh.hexes)],
                       cell_data={"yarn": [yarn],
                                  "fibre_direction": [np.ascontiguousarray(cell.frames[:, 0])],
                                  "volume": [element_volumes(cell)]})
    with atomic_path(out / "cell.vtu") as tmp:
        meshio.write(tmp, mesh, file_format="vtu")
    atomic_write_text(out / "cell.json", json.dumps(summary, indent=1) + "\n")
    return summary
