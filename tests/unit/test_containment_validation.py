"""studies/containment_validation: the containment report from ladder results (synthetic
rows, no runs): regression over escaped runs only, the fewest layers that contained, the
mass table with the inner shell counted, undecided runs named and left out."""

from __future__ import annotations

import pytest

from wovenimpact.studies import containment_validation as cv


def _row(n, outcome, exit_speed, per_area):
    return {"id": f"v{n}", "status": "done", cv.KEY: n, "outcome": outcome,
            "fragment_exit_speed_m_per_s": exit_speed, "casing_mass_kg": 0.1 * n,
            "casing_mass_per_area_kg_per_m2": per_area, "max_bulge_m": 0.01 * n,
            "energy_error_fraction": 1e-3, "hourglass_fraction": 0.02, "wall_time_s": 60.0}


def ladder(c2=0.05, c1=-6.0, c0=150.0, shell=2.7, per_layer=0.5):
    """Escaped runs on V(N) = c2 N² + c1 N + c0 up to its first zero, contained beyond,
    one undecided; mass per area shell + N × per_layer."""
    rows = []
    for n in (4, 8, 12, 16, 30, 36, 40):
        v = c2 * n * n + c1 * n + c0
        rows.append(_row(n, "escaped" if v > 0 else "contained", max(v, 0.0),
                         shell + per_layer * n))
    rows.append(_row(20, "undecided", 40.0, shell + per_layer * 20))
    return rows


def test_regression_uses_escaped_runs_and_finds_their_zero():
    rows = ladder()
    res = cv.ladder_result(rows)
    reg = res["regression"]
    assert reg.coefficients == pytest.approx((0.05, -6.0, 150.0), rel=1e-9)
    # 0.05 N² − 6 N + 150 = 0 → N = 60 − √(3600 − 3000) = 35.5 (first root)
    assert reg.root == pytest.approx(60.0 - 600.0**0.5, rel=1e-9)
    assert reg.plies_to_stop == 36
    assert res["fewest_contained"] == 36  # V(30) = 15 escaped, V(36) = −1.2 contained
    assert res["undecided"] == [20]
    assert res["mass_per_area"](36) == pytest.approx(2.7 + 0.5 * 36)


def test_section_tables_the_ladders_names_undecided_and_counts_the_inner_shell(tmp_path,
                                                                               monkeypatch):
    ladders = {"containment_hybrid": ladder(), "containment_metal": ladder(0.0, -5.0, 130.0,
                                                                           0.0, 1.35)}
    monkeypatch.setattr("wovenimpact.studies.sweep.run_study",
                        lambda path, out, workers=2: ladders[path.stem])
    text = "\n".join(cv.containment_section(tmp_path / "work", tmp_path / "figs"))
    assert "| 4 | escaped | 126.8 | 133.0 |" in text  # ours beside the thesis's
    assert "undecided" in text and "20 plies — run them longer" in text
    # all-metal: V = 130 − 5 N reaches 0 at N = 26
    assert "**26 layers to contain**" in text
    assert "| Hybrid casing | 36 plies | 20.70 | 36 plies | 20.70 |" in text
    assert "| All-metal casing | 30 layers | 40.50 | 26 layers | 35.10 |" in text
    assert (tmp_path / "figs" / "containment_hybrid.png").exists()


def test_validate_containment_writes_its_own_report(tmp_path, monkeypatch):
    """``wovenimpact validate --containment`` writes the containment section alone, under
    its own title, to --report (the chapter-7 report is left alone)."""
    from typer.testing import CliRunner

    from wovenimpact.cli import app

    monkeypatch.setattr(cv, "containment_section",
                        lambda work, figures, workers=2, log=None: ["## section", "body"])
    report = tmp_path / "docs" / "validation_containment.md"
    result = CliRunner().invoke(app, ["validate", "--containment", "--work",
                                      str(tmp_path / "w"), "--report", str(report)])
    assert result.exit_code == 0, result.output
    text = report.read_text()
    assert text.startswith("# Validation: fan-blade containment (thesis chapter 8)")
    assert "## section\nbody\n" in text
