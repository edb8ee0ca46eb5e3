"""Energies of a run's outputs: the summary's kinetic energies cover the bodies they say,
and the energy plot's balance error is the summary's energy_error_fraction in joules."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tests.cli.test_run_cli import CASE, IMPACTOR, write_case
from wovenimpact.io.history import read_csv
from wovenimpact.io.plots import energy_curves
from wovenimpact.runs import run_case


@pytest.fixture(scope="module")
def impact_run(tmp_path_factory):
    """The 10 mm quarter plate struck by the FSP at 120 m/s for 15 µs."""
    tmp = tmp_path_factory.mktemp("impact")
    text = CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                        'radius = "1.5 mm"\n', "") + IMPACTOR.replace("{z}", "0.4 mm")
    out = tmp / "out"
    summary = run_case(write_case(tmp, text=text, end="15 us"), out, threads=1)
    return summary, read_csv(out / "history.csv"), out


def test_plotted_balance_error_is_the_summary_error_in_joules(impact_run):
    """The curve drawn as the balance error is energy_error_fraction × normaliser of
    every history row (whole problem); it equals the imbalance of the plotted energies
    themselves (structure and impactor kinetic, internal work, eroded kinetic, external
    work, contact energy — the old plot left the impactor and the contact out); its
    largest value over the normaliser is the summary's energy_error_fraction, and it
    stays below 1 % of the initial kinetic energy."""
    summary, h, out = impact_run
    factor = summary["symmetry_factor"]
    assert factor == 4.0
    c = energy_curves(h, factor)
    error = c["balance error"]
    assert np.array_equal(error, factor * h["energy_error_fraction"] * h["energy_normaliser_part_J"])
    e0 = summary["initial_total_kinetic_energy_J"]
    total = (c["structure kinetic"] + c["impactor kinetic"] + c["internal work"]
             + c["eroded kinetic"] - c["external work"] + c["contact energy"])
    assert np.allclose(np.abs(total - e0), error, rtol=0.0, atol=1e-12 * e0)
    assert float(np.max(h["energy_error_fraction"])) == summary["energy_error_fraction"]
    print(f"\nbalance error: at most {error.max():.3e} J of {e0:.3f} J "
          f"({error.max() / e0:.1e}); summary energy_error_fraction "
          f"{summary['energy_error_fraction']:.1e}")
    assert error.max() < 0.01 * e0
    assert (out / "plots" / "energy.png").stat().st_size > 0
    assert "contact dissipated" in c  # drawn as a part of the contact energy


def test_summary_kinetic_energies_say_what_they_cover(impact_run):
    """structure + impactor = total, now and at t = 0; the initial total is the
    impactor's ½ m v² here (the plate starts at rest); hourglass_fraction is hourglass
    energy (live elements and eroded ones at erosion) over internal work."""
    summary, h, _ = impact_run
    s = summary
    assert "kinetic_energy_J" not in s and "initial_kinetic_energy_J" not in s
    assert s["total_kinetic_energy_J"] == pytest.approx(
        s["structure_kinetic_energy_J"] + s["impactor_kinetic_energy_J"], rel=1e-14)
    assert s["initial_total_kinetic_energy_J"] == pytest.approx(
        s["initial_structure_kinetic_energy_J"] + s["initial_impactor_kinetic_energy_J"],
        rel=1e-14)
    assert s["initial_impactor_kinetic_energy_J"] == pytest.approx(0.5 * 1.1e-3 * 120.0**2,
                                                                   rel=1e-9)
    assert s["initial_structure_kinetic_energy_J"] == pytest.approx(0.0, abs=1e-15)
    assert s["absorbed_energy_J"] == pytest.approx(
        s["initial_impactor_kinetic_energy_J"] - s["impactor_kinetic_energy_J"], rel=1e-12)
    assert s["hourglass_fraction"] == pytest.approx(
        (s["hourglass_energy_J"] + s["eroded_hourglass_energy_J"]) / s["internal_work_J"],
        rel=1e-12)
    assert 0.0 <= s["hourglass_fraction"] < 1.0


def test_metal_run_draws_its_plastic_dissipation(tmp_path):
    """A metal run (examples/metal_impact/aluminium_fsp.toml, coarsened to 1 mm elements
    and 8 µs): history.csv has plastic_work_part_J, the energy plot draws it as
    "plastic dissipation" (whole problem: × the symmetry factor), summary.json's
    plastic_work_J is its last value, a part of the internal work (it grows from 0 and
    never exceeds it), and the balance error stays below 1 %."""
    case = Path(__file__).resolve().parents[2] / "examples" / "metal_impact" / "aluminium_fsp.toml"
    out = tmp_path / "out"
    summary = run_case(case, out, threads=1,
                       overrides=("run.end_time=8 us", "mesh.element_size=1 mm",
                                  "run.field_interval=8 us", "run.checkpoint_interval=8 us"))
    h = read_csv(out / "history.csv")
    factor = summary["symmetry_factor"]
    c = energy_curves(h, factor)
    assert np.array_equal(c["plastic dissipation"], factor * h["plastic_work_part_J"])
    assert summary["plastic_work_J"] == pytest.approx(c["plastic dissipation"][-1], rel=1e-12)
    assert h["plastic_work_part_J"][0] == 0.0 and summary["plastic_work_J"] > 0.0
    assert np.all(h["plastic_work_part_J"] <= h["internal_work_part_J"] + 1e-15)
    assert summary["energy_error_fraction"] < 0.01
