"""``wovenimpact element-test`` on metals (and that fabric runs still work) via CliRunner."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from typer.testing import CliRunner

import wovenimpact.cli.element_test  # noqa: F401  (registers the command)
from wovenimpact.cli.app import app
from wovenimpact.calibration.metal_element import read_history_csv

ROOT = Path(__file__).resolve().parents[2]
MATERIALS = ROOT / "examples" / "materials"
runner = CliRunner()


def flat(text: str) -> str:
    return " ".join(text.split())


def test_aluminium_uniaxial_to_fracture(tmp_path):
    r = runner.invoke(app, ["element-test", "uniaxial", "--material",
                            str(MATERIALS / "aluminium.toml"), "--out", str(tmp_path), "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    for key in ("max_stress_Pa", "failure_plastic_strain", "plastic_work_J_per_m3",
                "test", "failure_displacement_m", "energy_error_fraction", "steps",
                "iterations_mean", "iterations_max", "history_csv"):
        assert key in out
    assert out["failure_plastic_strain"] == pytest.approx(0.18, rel=1e-12)
    # Cauchy σ at failure = table 213.78 MPa / J, J − 1 the elastic volume change
    assert out["max_stress_Pa"] == pytest.approx(213.78e6, rel=2e-3)
    assert out["table_error_max"] < 1e-8 and out["energy_error_fraction"] < 1e-4
    # plastic work per volume ≈ ∫ σ_y dε̄p = ½ (77.951 + 213.78) MPa × 0.18
    assert out["plastic_work_J_per_m3"] == pytest.approx(0.5 * (77.951e6 + 213.78e6) * 0.18,
                                                         rel=2e-3)
    assert {p.name for p in tmp_path.iterdir()} >= {
        "history.csv", "summary.json", "stress_strain.png", "stresses.png", "energy.png"}
    h = read_history_csv(tmp_path / "history.csv")
    assert h["alive"][-1] == 0.0 and h["plastic_strain"][-2] == pytest.approx(0.18, rel=1e-12)


@pytest.mark.parametrize("test", ["biaxial", "shear"])
def test_johnson_cook_titanium_at_a_high_rate(tmp_path, test):
    r = runner.invoke(app, ["element-test", test, "--material",
                            str(MATERIALS / "ti6al4v_johnson_cook.toml"), "--out", str(tmp_path),
                            "--strain-rate", "1000 1/s", "--steps", "100", "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert out["failure_plastic_strain"] is not None and out["table_error_max"] < 1e-8
    assert out["strain_rate_per_s"] == 1000.0 and out["max_stress_Pa"] > 1.1e9


@pytest.mark.parametrize(
    ("args", "expect"),
    [
        (["picture-frame", "--material", "titanium.toml"], "not valid for a metal"),
        (["shear", "--material", "titanium.toml", "--displacement", "1 mm"], "fabric options"),
        (["uniaxial", "--material", "steel.toml"], "kind 'elastic' has no plasticity"),
        (["uniaxial", "--material", "aluminium.toml", "--strain-rate", "1 m/s"],
         "--strain-rate = '1 m/s' has the wrong dimension"),
        (["uniaxial", "--material", "aluminium.toml", "--strain", "-1"], "--strain = -1.0"),
        (["uniaxial", "--material", "kevlar_thesis.toml", "--strain", "0.1"],
         "--strain is a metal option"),
    ],
)
def test_bad_arguments_name_the_option(tmp_path, args, expect):
    args = [a if not a.endswith(".toml") else str(MATERIALS / a) for a in args]
    r = runner.invoke(app, ["element-test", *args, "--out", str(tmp_path)])
    assert r.exit_code == 2
    assert expect in flat(r.output)


def test_fabric_element_test_still_runs(tmp_path):
    r = runner.invoke(app, ["element-test", "uniaxial", "--material",
                            str(MATERIALS / "kevlar_thesis.toml"), "--out", str(tmp_path),
                            "--steps", "50", "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["max_tension_w_N"] > 0.0
