"""Geometry files of a plain-weave crossover cell (TOML) → a validated spec in SI.

The cell of ``wovenimpact crossover-cell GEOMETRY.toml`` (model/crossover_cell.py, thesis
§5.2.1): two yarns, the warp along x and the fill along y, crossing at the origin; each
yarn's centreline the cosine of eq. (5.1), its section lenticular (two cosine arcs,
trimmed at the tips) or elliptical, and a structured mesh of 8-node hexahedra swept along
it. Every dimensioned value carries its unit; problems are reported together, naming the
key (as for case and material files, spec/fields.py)::

    [cell]
    name = "thesis Table 5-1"
    repeat = 1                   # or 2: the 2 × 2 plain-weave repeat (two yarns a family)
    [warp]                       # along x
    thread_count = "27 1/in"     # of this family: its yarns' pitch is 1 / thread_count
    crimp = 0.0421
    width = "0.9407 mm"          # optional: the pitch less the gap
    thickness = "0.2499 mm"      # optional: twice the crossing family's h0
    h0 = "0.12495 mm"            # optional: eq. (5.5) of the crossing family's count
    gap = "0 mm"                 # between neighbouring yarns of the family
    [fill]                       # optional: the warp's values
    [section]
    shape = "lenticular"         # or "elliptical"
    trim = 0.2                   # the tips cut where the section is 0.2 of its thickness
    [mesh]
    along = 12                   # elements along each yarn, across it, through it
    across = 8
    through = 2
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

from pydantic import BaseModel, Field, ValidationError

from wovenimpact.spec.fields import (
    STRICT,
    input_error,
    integer,
    problems_from_validation,
    quantity,
    read_toml,
)

MAX_CRIMP = 0.5  # as material files (a crimp of 50 % is no woven fabric)


class CellInfo(BaseModel):
    """``[cell]``: a name for the outputs, and the crossings along each yarn."""

    model_config = STRICT
    name: str = Field(min_length=1)
    # 1: one crossover (thesis §5.2.1); 2: the 2 × 2 plain-weave repeat, two warp yarns
    # over and under two fill yarns (model/crossover_cell.py) — a yarn with a neighbour
    repeat: integer(ge=1, le=2, example=2) = 1


class YarnGeometrySpec(BaseModel):
    """``[warp]`` / ``[fill]``: one yarn family of the cell (thesis Table 5-1)."""

    model_config = STRICT
    # threads per length of this family: its yarns lie 1 / thread_count apart
    thread_count: quantity("inverse_length", gt=0, example="27 1/in")
    crimp: quantity("dimensionless", ge=0, le=MAX_CRIMP, example="0.0421")
    # not given: the pitch 1 / thread_count less the gap
    width: quantity("length", gt=0, example="0.9407 mm") | None = None
    # not given: twice the crossing family's h0 (the thesis's yarns, which meet over the cell)
    thickness: quantity("length", gt=0, example="0.2499 mm") | None = None
    # the centreline's amplitude; not given: eq. (5.5) from the crimp and the crossing count
    h0: quantity("length", gt=0, example="0.12495 mm") | None = None
    # between neighbouring yarns of this family (Shahkarami's gap; the thesis's is 0)
    gap: quantity("length", ge=0, example="0 mm") = 0.0


class CellSectionSpec(BaseModel):
    """``[section]``: the yarns' cross-section."""

    model_config = STRICT
    # lenticular: two cosine arcs (the thesis's); elliptical: half an ellipse each side
    shape: Literal["lenticular", "elliptical"] = "lenticular"
    # the tips are cut where the section's thickness falls to this fraction of the yarn's
    # (thesis Fig. 5-3: sharp tips give degenerate elements)
    trim: quantity("dimensionless", gt=0, lt=1, example="0.2") = 0.2


class CellMeshSpec(BaseModel):
    """``[mesh]``: hexahedra along each yarn (over the cell), across its width and through
    its thickness."""

    model_config = STRICT
    along: integer(ge=2, le=1000, example=12) = 12
    across: integer(ge=1, le=1000, example=8) = 8
    through: integer(ge=1, le=100, example=2) = 2


class CrossoverCellSpec(BaseModel):
    """A whole geometry file."""

    model_config = STRICT
    cell: CellInfo
    warp: YarnGeometrySpec
    # not given: the warp's
    fill: YarnGeometrySpec | None = None
    section: CellSectionSpec = CellSectionSpec()
    mesh: CellMeshSpec = CellMeshSpec()

    @property
    def families(self) -> tuple[YarnGeometrySpec, YarnGeometrySpec]:
        """(warp, fill), the fill the warp's values when not given."""
        return self.warp, self.fill if self.fill is not None else self.warp


def geometry_from_dict(doc: dict, source: str = "<dict>") -> CrossoverCellSpec:
    """Validate a parsed geometry document; all problems in one InputError."""
    try:
        return CrossoverCellSpec.model_validate(doc)
    except ValidationError as err:
        raise input_error(problems_from_validation(err, CrossoverCellSpec), source) from None


def load_geometry(path: str | Path) -> CrossoverCellSpec:
    """Read and validate a geometry file."""
    path = Path(path)
    return geometry_from_dict(read_toml(path, "geometry file"), source=str(path))
