"""``wovenimpact calibrate crossover``: a fabric file from the 3-D cell's virtual tests
(calibration.crossover_calibration, docs/solid.md §6.6)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

from wovenimpact.calibration.crossover_calibration import drop_header, set_values
from wovenimpact.cli import app
from wovenimpact.errors import InputError
from wovenimpact.spec import load_material

ROOT = Path(__file__).resolve().parents[2]
TEMPLATE = ROOT / "examples" / "materials" / "kevlar_thesis.toml"


def test_set_values_replaces_a_tables_key_and_refuses_a_missing_one():
    """A key is replaced in its own table only (the fill's modulus is not the warp's), the
    comment follows the value, other lines stay; a key the template lacks is named."""
    text = '[a]\nx = 1  # old\ny = 2\n[b]\nx = 3\n'
    out = set_values(text, {("b", "x"): ("4", "from b")})
    assert out == '[a]\nx = 1  # old\ny = 2\n[b]\nx = 4  # from b\n'
    with pytest.raises(InputError, match="no 'z' in \\[a\\]"):
        set_values(text, {("a", "z"): ("0", "")})
    assert drop_header("# c\n\n[a]\nx = 1\n") == "[a]\nx = 1\n"


@pytest.mark.slow
def test_the_thesis_cell_writes_a_fabric_file_that_loads(tmp_path):
    """The thesis's cell (12 × 8 × 2 per yarn) and yarn over kevlar_thesis.toml (about
    half a minute): the written fabric.toml loads; its yarns' modulus is E1 of the
    extension, within 2 % of the yarn's E11 (96 GPa); its compaction a, b are the
    compression fit's; the geometry's values are in (27 threads per inch, width,
    thickness); T_u is the template yarn's strength times the cell's section; the shear
    law is the template's; the
    round trip is reported for the uniaxial, biaxial and compression tests, with the
    compaction law within 15 % of the cell's curve at 2 and 3 N (it is fitted to it); a
    run whose hourglass energy exceeds 5 % of its internal work is named in a warning."""
    out = tmp_path / "cal"
    result = CliRunner().invoke(app, [
        "calibrate", "crossover", str(ROOT / "examples" / "crossover" / "thesis_cell.toml"),
        "--yarn", str(ROOT / "examples" / "materials" / "kevlar_yarn_solid.toml"),
        "--template", str(TEMPLATE), "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads((out / "crossover_calibration.json").read_text())
    fabric = load_material(out / "fabric.toml")
    template = load_material(TEMPLATE)
    assert fabric.warp.modulus == pytest.approx(doc["e1_Pa"], rel=1e-4)
    assert doc["e1_Pa"] == pytest.approx(96e9, rel=0.02)
    assert fabric.compaction_a == pytest.approx(doc["a_m"], rel=1e-4)
    assert fabric.compaction_b == pytest.approx(doc["b_N"], rel=1e-4)
    assert fabric.warp.half_length == pytest.approx(0.5 * 0.0254 / 27, rel=1e-5)
    assert fabric.warp.h0 == pytest.approx(0.12495e-3, rel=1e-4)  # the cell's centreline
    assert fabric.fill.width == pytest.approx(0.9407e-3, rel=1e-5)
    strength = template.warp.ultimate_tension / template.warp.area
    assert fabric.warp.ultimate_tension == pytest.approx(strength * fabric.warp.area, rel=1e-4)
    assert (fabric.shear_g1, fabric.shear_g2, fabric.shear_c_max) == (
        template.shear_g1, template.shear_g2, template.shear_c_max)
    tests = {row["test"] for row in doc["round_trip"]}
    assert tests == {"uniaxial", "biaxial", "compression"}
    for row in doc["round_trip"]:
        if row["test"] == "compression" and row["at"] in ("2 N", "3 N"):
            assert abs(row["error"]) < 0.15, row
    # each run beyond the bounds (hourglass 5 %, kinetic 1 %, energy 1 %) is named
    for name, c in doc["checks"].items():
        named = any(w.startswith(f"{name}: hourglass") for w in doc["warnings"])
        assert named == (c["hourglass_fraction"] > 0.05), (name, c)
    assert (out / "compression.png").stat().st_size > 0
    assert (out / "extension.png").stat().st_size > 0
