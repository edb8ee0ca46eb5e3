"""``wovenimpact crossover-cell GEOMETRY.toml``: the plain-weave crossover cell of a geometry
file as two yarns of 8-node hexahedra (calibration/crossover_cell.py, docs/solid.md §5)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from wovenimpact.cli.app import app, emit, fail
from wovenimpact.errors import InputError


@app.command("crossover-cell")
def crossover_cell(
    geometry: Annotated[Path, typer.Argument(help="The geometry file (TOML), e.g. "
                                                  "examples/crossover/thesis_cell.toml.")],
    out: Annotated[Path, typer.Option("--out", help="Folder for cell.vtu and cell.json.")] = (
        Path("cell")),
    as_json: Annotated[bool, typer.Option("--json", help="Print one JSON object (SI units).")
                       ] = False,
) -> None:
    """Generate a crossover cell: two yarns swept along their cosine centrelines (thesis
    eq. 5.1) with lenticular or elliptical sections, their material axes along them. Writes
    OUT/cell.vtu (ParaView) and OUT/cell.json (sizes, crimps, volumes, volume fraction);
    a case runs the cell with [mesh] kind = "crossover"."""
    from wovenimpact.calibration.crossover_cell import write_cell

    try:
        summary = write_cell(geometry, out)
    except InputError as err:
        fail(str(err))
    emit(summary, as_json, title=f"crossover cell: {summary['cell']}")
