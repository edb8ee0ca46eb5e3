"""The metal section of the validation report from cached results (no runs)."""

from __future__ import annotations

import json

from wovenimpact.studies.metal_validation import jones_lines


def test_jones_lines_tabulate_the_meshes_and_extrapolate(tmp_path):
    """Three cached meshes with W/H = 9, 10, 10.25: successive differences 1 and 0.25
    (ratio 4), Richardson estimate 10.25 + 0.25/3 = 10.333; its distance to the limits
    as stated."""
    rows = [{"elements_per_half_side": n, "element_size_m": 0.05 / n, "lambda": 145.0,
             "permanent_over_H": w, "max_over_H": w + 1, "jones_mode_over_H": 4.0,
             "jones_impulse_over_H": 11.0, "energy_error_fraction": 1e-4, "steps": 100 * n}
            for n, w in ((8, 9.0), (16, 10.0), (32, 10.25))]
    (tmp_path / "jones.json").write_text(json.dumps(rows))
    text = "\n".join(jones_lines(tmp_path, tmp_path))
    assert "| 16 | 3.125 | 10.000 | 11.000 | 1.0e-04 | 1600 |" in text
    assert "ratio 4.00" in text and "converged value 10.33 H" in text
    assert f"{10.3333333 / 11.0 - 1:+.1%}" in text and f"{10.3333333 / 4.0:.2f} ×" in text
