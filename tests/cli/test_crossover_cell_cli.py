"""``wovenimpact crossover-cell``: the thesis's cell written as VTU and JSON, and a geometry
that cannot be built refused naming its key."""

from __future__ import annotations

import json
from pathlib import Path

import meshio
import numpy as np
import pytest
from typer.testing import CliRunner

from wovenimpact.cli.app import app

ROOT = Path(__file__).resolve().parents[2]
THESIS = ROOT / "examples" / "crossover" / "thesis_cell.toml"


def test_the_thesis_cell_is_written_for_paraview_and_in_numbers(tmp_path):
    """Table 5-1: a cell 0.9407 mm square and 0.4998 mm thick, yarns 0.2499 mm thick
    meeting with no clearance; the trimmed lenticular section (0.1466 mm²) is 2 % below
    the whole lens (2/π) W t of Table 7-2's area (0.149664 mm²); the VTU holds the 384
    hexahedra with their yarn and fibre direction (unit, slopes within ±23°)."""
    out = tmp_path / "cell"
    result = CliRunner().invoke(app, ["crossover-cell", str(THESIS), "--out", str(out),
                                      "--json"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout.strip().splitlines()[-1])
    assert summary == json.loads((out / "cell.json").read_text())
    assert summary["cell_size_x_m"] == pytest.approx(0.0254 / 27, rel=1e-12)
    assert summary["thickness_m"] == pytest.approx(0.4998e-3, rel=1e-12)
    assert summary["clearance_m"] == 0.0
    lens = 2.0 / np.pi * 0.9407e-3 * 0.2499e-3
    assert lens == pytest.approx(0.149664e-6, rel=1e-4)
    assert summary["warp_section_area_m2"] == pytest.approx(0.97978 * lens, rel=1e-4)
    assert 0.5 < summary["volume_fraction"] < 0.7
    m = meshio.read(out / "cell.vtu")
    assert [c.type for c in m.cells] == ["hexahedron"] and len(m.cells[0].data) == 384
    a1 = m.cell_data["fibre_direction"][0]
    np.testing.assert_allclose(np.linalg.norm(a1, axis=1), 1.0, rtol=1e-12)
    assert np.bincount(m.cell_data["yarn"][0]).tolist() == [192, 192]
    assert np.abs(a1[:, 2]).max() < np.sin(np.radians(23.0))
    assert m.cell_data["volume"][0].sum() == pytest.approx(
        summary["warp_volume_m3"] + summary["fill_volume_m3"], rel=1e-12)


def test_a_geometry_that_overlaps_is_refused_and_writes_nothing(tmp_path):
    bad = tmp_path / "thick.toml"
    bad.write_text(THESIS.read_text().replace('thickness = "0.2499 mm"',
                                              'thickness = "0.3 mm"'))
    result = CliRunner().invoke(app, ["crossover-cell", str(bad), "--out",
                                      str(tmp_path / "o")])
    assert result.exit_code == 2
    assert "overlap" in result.output and "warp.thickness" in result.output
    assert not (tmp_path / "o").exists()
