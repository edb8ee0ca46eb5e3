"""``wovenimpact ballistics v50|plies`` on results tables."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from wovenimpact.cli.app import app


def write_results(path, key, values, residual):
    lines = [f"id,{key},status,error,residual_velocity_m_per_s"]
    lines += [f"x{i},{v},done,,{r}" for i, (v, r) in enumerate(zip(values, residual))]
    path.write_text("\n".join(lines) + "\n")


def test_v50_from_a_velocity_ladder(tmp_path):
    vs = np.array([80.0, 100.0, 120.0, 150.0, 200.0, 300.0])
    vr = np.clip(vs**2 - 110.0**2, 0, None) ** 0.5
    write_results(tmp_path / "r.csv", "impactor.velocity", [f"{v} m/s" for v in vs], vr)
    result = CliRunner().invoke(app, ["ballistics", "v50", str(tmp_path / "r.csv"), "--json"])
    assert result.exit_code == 0, result.output
    assert abs(json.loads(result.stdout)["v50_m_per_s"] - 110.0) < 0.1


def test_plies_regression_and_its_error_when_too_few_perforate(tmp_path):
    write_results(tmp_path / "r.csv", "mesh.plies", [1, 2, 4, 6], [82.0, 58.0, 18.0, 0.0])
    result = CliRunner().invoke(app, ["ballistics", "plies", str(tmp_path / "r.csv"), "--json"])
    assert result.exit_code == 0, result.output
    assert json.loads(result.stdout)["plies_to_stop"] == 6
    write_results(tmp_path / "s.csv", "mesh.plies", [1, 2, 4], [5.0, 0.0, 0.0])
    bad = CliRunner().invoke(app, ["ballistics", "plies", str(tmp_path / "s.csv")])
    assert bad.exit_code == 2 and "three perforated" in bad.output
