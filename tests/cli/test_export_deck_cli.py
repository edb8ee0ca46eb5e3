"""``wovenimpact export-deck``: a case's compiled mesh written as an LS-DYNA deck that
``[mesh] kind = "lsdyna"`` reads back to the same mesh."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from typer.testing import CliRunner

from wovenimpact.cli import app
from wovenimpact.model.lsdyna import read_deck
from wovenimpact.setup.compile import compile_case
from wovenimpact.spec.case import load_case

ROOT = Path(__file__).resolve().parents[2]
CASE = ROOT / "examples" / "plate_impact" / "plies2_100.toml"
COARSE = ["--set", "mesh.element_size=4.85 mm"]


def test_a_plate_cases_mesh_is_written_and_read_back(tmp_path):
    """The 2-ply plate at 4.85 mm: the command says what it wrote; the deck read back has
    the compiled model's nodes (to 1e-15 m), shells, one part per ply and the plies' sets."""
    out = tmp_path / "plate.k"
    result = CliRunner().invoke(app, ["export-deck", str(CASE), "--out", str(out), *COARSE])
    assert result.exit_code == 0, result.output
    assert f"{out}:" in result.output.replace("\n", "") and "shells" in result.output
    spec, base = load_case(CASE, ["mesh.element_size=4.85 mm"])
    model = compile_case(spec, base).model
    deck = read_deck(out)
    assert np.max(np.abs(deck.mesh.nodes - model.x0)) < 1e-15
    assert np.array_equal(deck.mesh.quads, model.quads)
    parts = {name for name in deck.mesh.elem_sets if name.startswith("PART_")}
    assert len(parts) == np.unique(model.ply).size == 2


def test_a_bad_case_is_refused_and_nothing_written(tmp_path):
    """A key the schema does not know is refused by name (exit 2) and no deck is written."""
    out = tmp_path / "bad.k"
    result = CliRunner().invoke(app, ["export-deck", str(CASE), "--out", str(out),
                                      "--set", "mesh.element_sise=1 mm"])
    assert result.exit_code == 2
    assert "element_sise" in result.output
    assert not out.exists()
