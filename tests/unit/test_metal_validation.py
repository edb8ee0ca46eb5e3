"""The metal section of the validation report from cached results (no runs)."""

from __future__ import annotations

import json

from wovenimpact.reports.metal_validation import jones_lines


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


def test_the_v50_mesh_line_judges_the_spread_against_five_percent():
    """Issue 36, V3: (max − min)/min of the ladders' V50; 75 / 73 / 72 m/s is 4.2 %, met;
    75 / 65 m/s is 15.4 %, not met; a ladder without a V50 gives no verdict."""
    from wovenimpact.reports.metal_validation import v50_mesh_line

    ok = v50_mesh_line({"1 mm": 75.0, "0.5 mm": 73.0, "0.25 mm": 72.0}, "0.5 mm")
    assert "75.0 / 73.0 / 72.0 m/s on 1 mm / 0.5 mm / 0.25 mm" in ok
    assert "spread 4.2% of the smallest" in ok and ": met" in ok and "(0.5 mm)" in ok
    bad = v50_mesh_line({"1 mm": 75.0, "0.5 mm": 65.0}, "0 mm")
    assert "spread 15.4%" in bad and "not met" in bad
    none = v50_mesh_line({"1 mm": 75.0, "0.5 mm": None}, "0.5 mm")
    assert "75.0 / —" in none and "not every ladder brackets" in none


def test_the_jones_figure_is_drawn_from_histories(tmp_path):
    """jones_figure draws each mesh's deflection history over Jones's band into a PNG."""
    import numpy as np

    from wovenimpact.verification.jones_plate import jones_figure

    t = np.linspace(0.0, 4e-4, 50)
    results = [{"time_s": t, "deflection_m": 1e-3 * n / 8 * np.sin(t / 4e-4),
                "thickness_m": 1e-3, "elements_per_half_side": n, "permanent_over_H": n / 8,
                "lambda": 145.0, "jones_mode_over_H": 4.0, "jones_impulse_over_H": 11.0}
               for n in (8, 16)]
    path = jones_figure(results, tmp_path / "jones.png")
    assert path.read_bytes()[:4] == b"\x89PNG"
