"""The crossover cell's validation page (reports/crossover_validation.py) from cached runs."""

from __future__ import annotations

import json

from wovenimpact.reports.crossover_validation import (
    THESIS_A_M,
    THESIS_B_N,
    cell_runs,
    page_lines,
)


def _runs(a_fine: float, b_fine: float, e1s=(96.42e9, 96.45e9, 96.47e9)) -> dict:
    comp = [{"mesh": [12 * k, 8 * k, 2 * k], "d_c_m": d, "a_m": a, "b_N": b, "r2": 0.9,
             "kinetic_fraction": 0.01, "hourglass_fraction": 0.02, "energy_error": 1e-9,
             "steps": 1000 * k, "elements": 384 * k**3, "wall_s": 10.0 * k,
             "curve_d_m": [0.0, d], "curve_force_N": [0.0, 3.0]}
            for k, d, a, b in ((1, 0.0140e-3, 0.0164e-3, 0.680), (2, 0.0125e-3, 0.0147e-3, 0.732),
                               (3, 0.0121e-3, a_fine, b_fine))]
    ext = [{"mesh": [12 * k, 8 * k, 2 * k], "e1_Pa": e, "nu": 1.2, "tangent_Pa": 46.6e9,
            "section_m2": 0.1452e-6, "kinetic_fraction": 0.001, "hourglass_fraction": 0.001,
            "energy_error": 1e-11, "steps": 1500 * k, "elements": 384 * k**3, "wall_s": 5.0 * k}
           for k, e in zip((1, 2, 3), e1s)]
    return {"compression": comp, "extension": ext}


def test_the_page_judges_each_acceptance_from_the_numbers(tmp_path):
    """The cached runs come back as written; d_c's step between the finer meshes is
    |0.0121 − 0.0125|/0.0121 = 3.3 %; a and b of the finest mesh 0.0154 mm and 1.094 N are
    −88 % and +11 % from the thesis's (not met), the thesis's own values are met; E1 96.45
    and 96.47 GPa are +0.3 % and +0.4 % from 96.117 (met), 100 GPa is not."""
    (tmp_path / "crossover_cell.json").write_text(json.dumps(_runs(0.0154e-3, 1.094)))
    text = "\n".join(page_lines(cell_runs(tmp_path)))
    assert "| 36 × 24 × 6 | 0.0121 | 0.0154 | 1.094 | 0.90 |" in text
    assert "moves 3.3%" in text and "hourglass energy at most 0.02 (limit 0.05)" in text
    assert "a -88%, b +11% from the thesis's (within 15%: not met)" in text
    assert "+0.3% and +0.4% from the thesis (within 2%: met)" in text
    met = "\n".join(page_lines(_runs(THESIS_A_M, THESIS_B_N)))
    assert "a +0%, b +0% from the thesis's (within 15%: met)" in met
    far = "\n".join(page_lines(_runs(THESIS_A_M, THESIS_B_N, (96e9, 100e9, 100e9))))
    assert "(within 2%: not met)" in far


def test_validate_crossover_writes_the_page_and_its_figure(tmp_path):
    """``wovenimpact validate --crossover --work W --report P`` on cached runs: the page at
    P, the compression figure beside it in validation/."""
    from typer.testing import CliRunner

    from wovenimpact.cli.app import app

    work = tmp_path / "work"
    work.mkdir()
    (work / "crossover_cell.json").write_text(json.dumps(_runs(0.0154e-3, 1.094)))
    page = tmp_path / "docs" / "page.md"
    result = CliRunner().invoke(app, ["validate", "--crossover", "--work", str(work),
                                      "--report", str(page)])
    assert result.exit_code == 0, result.output
    assert "E1 on the two finer meshes: 96.45 and 96.47 GPa" in page.read_text()
    figure = tmp_path / "docs" / "validation" / "crossover_compression.png"
    assert figure.read_bytes()[:4] == b"\x89PNG"
