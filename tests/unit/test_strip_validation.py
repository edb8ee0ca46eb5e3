"""The blade-edge strip section of docs/validation.md (reports/strip_validation.py): its
table, its spread and the acceptance verdict, on rows of the study's results."""

from __future__ import annotations

import pytest

from wovenimpact.reports.strip_validation import early_loss, spread, table_lines, verdict_line
from wovenimpact.reports.strip_validation import ROOT, STUDY
from wovenimpact.studies.sweep import load_study


def rows(energies: dict) -> list[dict]:
    return [{"mesh.element_size": h, "status": "done", "outcome": "perforated",
             "residual_velocity_m_per_s": 145.0, "absorbed_energy_J": e,
             "contact_work_per_ply_J": [1.0, 2.0, 3.0, 4.0, 5.0],
             "eroded_kinetic_energy_J": 1.0, "energy_error_fraction": 1e-4,
             "hourglass_fraction": 0.01, "added_mass_fraction": 0.001, "wall_time_s": 3.0}
            for h, e in energies.items()]


def test_the_spread_is_over_2_to_7_mm_and_the_verdict_follows_it():
    """(max − min)/min over 2, 3, 5, 7 mm, the 0.94 mm reference left out: 100 → 109 J is
    9 %, met; 100 → 120 J is 20 %, not met; a missing run gives no verdict."""
    ok = rows({"0.94 mm": 50.0, "2 mm": 100.0, "3 mm": 109.0, "5 mm": 104.0, "7 mm": 101.0})
    assert spread(ok) == pytest.approx(0.09)
    assert "is 9% of the smallest — met" in verdict_line(ok)
    bad = rows({"0.94 mm": 50.0, "2 mm": 100.0, "3 mm": 110.0, "5 mm": 115.0, "7 mm": 120.0})
    assert spread(bad) == pytest.approx(0.20) and "not met" in verdict_line(bad)
    short = rows({"0.94 mm": 50.0, "2 mm": 100.0, "3 mm": 110.0, "7 mm": 120.0})
    assert spread(short) is None and "not all runs finished" in verdict_line(short)


def test_the_table_has_a_row_per_mesh_with_the_ratio_to_the_reference():
    lines = table_lines(rows({"0.94 mm": 50.0, "2 mm": 100.0}))
    assert len(lines) == 4 and lines[0].count("|") == lines[2].count("|") == 13
    assert "| 2.00 | — |" in lines[3] and "1.0 / 2.0 / 3.0 / 4.0 / 5.0" in lines[3]


def test_the_early_loss_is_the_impactors_kinetic_energy_lost_by_20_us(tmp_path):
    """From the run's history: E(0) − E(t nearest 20 µs); 100 → 70 J at 20 µs is 30 J (the
    row at 30 µs, 60 J, is not the nearest) of a quarter model, 120 J of the whole (the
    summary's 400 J at the start); a run without history gives a dash."""
    run = tmp_path / "runs" / "abc"
    run.mkdir(parents=True)
    (run / "history.csv").write_text(
        "time_s,impactor_kinetic_energy_part_J\n0,100\n1e-05,90\n2.1e-05,70\n3e-05,60\n")
    (run / "summary.json").write_text('{"initial_impactor_kinetic_energy_J": 400.0}')
    assert early_loss(run) == pytest.approx(120.0)
    r = rows({"0.94 mm": 50.0, "2 mm": 100.0})
    r[0]["id"], r[1]["id"] = "abc", "missing"
    lines = table_lines(r, tmp_path)
    assert "| 1.00 | 120.0 |" in lines[2] and "| 2.00 | — |" in lines[3]


def test_the_study_sweeps_the_five_meshes_of_issue_36_on_the_strip_example():
    info, variants, base = load_study(ROOT / "examples" / "studies" / f"{STUDY}.toml")
    assert [v.values["mesh.element_size"] for v in variants] == [
        "0.94 mm", "2 mm", "3 mm", "5 mm", "7 mm"]
    assert (base / info.case).resolve() == (ROOT / "examples" / "strip" /
                                            "blade_edge_strip.toml").resolve()
