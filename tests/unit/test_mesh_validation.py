"""The ring mesh-convergence sections (reports/mesh_validation.py, issue 36 V0 and V2): the
fragment's energy loss, the per-mesh means over release angles, the spread and the
acceptance, on rows shaped as the study's results."""

from __future__ import annotations

import pytest

from wovenimpact.reports import mesh_validation as mv
from wovenimpact.studies.sweep import load_study


def row(size, angle, casing, exit_speed, status="done"):
    return {"mesh.element_size": size, "mesh.blade.angle": angle, "status": status,
            "outcome": "escaped", "fragment_exit_speed_m_per_s": exit_speed,
            "fragment_initial_speed_m_per_s": 150.0, "fragment_mass_kg": 0.2,
            "casing_absorbed_energy_J": casing, "contact_damping_energy_J": 10.0,
            "energy_error_fraction": 1e-4, "hourglass_fraction": 0.03, "elements": 100,
            "wall_time_s": 60.0}


def test_the_fragments_loss_is_half_m_times_the_drop_in_speed_squared():
    assert mv.energy_loss(row("7 mm", "90 deg", 1.0, 100.0)) == pytest.approx(
        0.5 * 0.2 * (150.0**2 - 100.0**2))
    at_end = {"fragment_mass_kg": 0.2, "fragment_initial_speed_m_per_s": 150.0,
              "fragment_exit_speed_m_per_s": "", "fragment_speed_at_end_m_per_s": 149.0}
    assert mv.energy_loss(at_end) == pytest.approx(0.5 * 0.2 * (150.0**2 - 149.0**2))
    assert mv.energy_loss({"fragment_mass_kg": 0.2}) is None


def test_means_over_the_angles_and_the_spread_over_the_meshes_decide_the_acceptance():
    """7 mm: 600 / 640 J (mean 620, scatter 40); 5 mm: 560 / 580 (570): spread 50/570 =
    8.8 %, met at 10 %; exit speeds 130 and 136 m/s: 4.6 %, not met at 3 %."""
    rows = [row("7 mm", "89.9 deg", 600.0, 129.0), row("7 mm", "90 deg", 640.0, 131.0),
            row("5 mm", "89.9 deg", 560.0, 136.0), row("5 mm", "90 deg", 580.0, 136.0)]
    means = mv.mesh_means(rows, "casing_absorbed_energy_J")
    assert means["7 mm"] == pytest.approx((620.0, 40.0, 2)) and means["5 mm"][0] == 570.0
    assert mv.spread(means) == pytest.approx(50.0 / 570.0)
    lines = mv.acceptance_lines(rows, ["7 mm", "5 mm"], mv.RING_STUDIES["mesh_ring_hybrid4"][2])
    assert "620.0 ± 20.0 / 570.0 ± 10.0 at 7 mm / 5 mm" in lines[0]
    assert "spread 8.8% of the smallest — met (acceptance 10%)" in lines[0]
    assert "spread 4.6% of the smallest — not met (acceptance 3%)" in lines[1]
    short = mv.acceptance_lines(rows, ["7 mm", "5 mm", "4 mm"],
                                mv.RING_STUDIES["mesh_ring_hybrid4"][2])
    assert "/ —" in short[0] and "not all meshes finished" in short[0]


def test_a_failed_run_is_a_row_of_its_own_and_left_out_of_the_means():
    rows = [row("7 mm", "90 deg", 600.0, 129.0), row("5 mm", "90 deg", 0.0, 0.0, "failed")]
    table = mv.table_lines(rows)
    assert len(table) == 4 and "| 5 mm | 90 deg | failed:" in table[3]
    assert list(mv.mesh_means(rows, "casing_absorbed_energy_J")) == ["7 mm"]


@pytest.mark.parametrize("study", ["mesh_ring_v0", "mesh_ring_hybrid4"])
def test_the_studies_sweep_the_four_meshes_of_issue_36_with_the_blade_fixed(study):
    _, variants, _ = load_study(mv.ROOT / "examples" / "studies" / f"{study}.toml")
    sizes = list(dict.fromkeys(v.values["mesh.element_size"] for v in variants))
    assert sizes == ["7 mm", "5 mm", "4 mm", "3 mm"]
    assert {v.values["mesh.blade.element_size"] for v in variants} == {"5 mm"}


def test_the_axial_study_sets_the_size_along_the_axis_apart_with_the_blade_fixed():
    _, variants, _ = load_study(mv.ROOT / "examples" / "studies" / "mesh_ring_v0_axial.toml")
    labels = [mv.mesh_label(v.values) for v in variants]
    assert labels == [f"{a} × {b}" for a in ("7 mm", "5 mm")
                      for b in ("5 mm", "3 mm", "2 mm", "1.5 mm", "1 mm")]
    assert {v.values["mesh.blade.element_size"] for v in variants} == {"5 mm"}
    assert set(mv.RING_STUDIES) >= {"mesh_ring_v0", "mesh_ring_hybrid4", "mesh_ring_v0_axial"}


def test_the_convergence_of_a_quadratic_answer_is_order_two_and_extrapolates_to_its_limit():
    """φ(h) = 100 + 4 h² on 1 / 2 / 4 mm (two release angles at 2 mm, ±1 around the
    law): order 2, limit 100, GCI 1.25·|φ1 − φ2|/φ1/(2² − 1) = 1.25·12/104/3 = 4.8 %,
    4 mm is +64 % from it; a series of two meshes gets no estimate."""
    def at(size, casing, angle="90 deg"):
        return row(size, angle, casing, 100.0)
    rows = [at("4 mm", 164.0), at("2 mm", 115.0, "89.9 deg"), at("2 mm", 117.0),
            at("1 mm", 104.0), row("3 mm", "90 deg", 0.0, 0.0, "failed")]
    [line] = mv.convergence_lines(rows, [("casing_absorbed_energy_J", "casing")])
    assert line.startswith("- casing, uniform meshes (1 / 2 / 4 mm): on 1 / 2 / 4 mm monotone")
    assert "order 2.00, extrapolated 100, GCI 4.8% on 1 mm; 4 mm is +64.0% from it." in line
    two = mv.convergence_lines(rows[:3], [("casing_absorbed_energy_J", "casing")])
    assert two == ["- casing, uniform meshes (2 / 4 mm): fewer than three meshes, no estimate."]


def test_an_axial_study_is_estimated_along_the_axis_for_each_size_around():
    """Two series (7 and 5 mm around), each φ = 20 + 0.5 h_axis over 1 / 2 / 4 mm along:
    order 1, limit 20, on each; the table and the means name a run "around × along"."""
    rows = []
    for around in ("7 mm", "5 mm"):
        for along in (1.0, 2.0, 4.0):
            r = row(around, "90 deg", 20.0 + 0.5 * along, 100.0)
            r["mesh.casing.axial_element_size"] = f"{along:g} mm"
            rows.append(r)
    lines = mv.convergence_lines(rows, [("casing_absorbed_energy_J", "casing")])
    assert [line.split(" (")[0] for line in lines] == [
        "- casing, 7 mm around, along the axis", "- casing, 5 mm around, along the axis"]
    assert all("order 1.00, extrapolated 20," in line for line in lines)
    assert "| 7 mm × 1 mm | 90 deg |" in mv.table_lines(rows)[2]
    assert list(mv.mesh_means(rows, "casing_absorbed_energy_J"))[:2] == ["7 mm × 1 mm",
                                                                          "7 mm × 2 mm"]
