"""``wovenimpact ballistics v50|plies`` on results tables."""

from __future__ import annotations

import json

import numpy as np
from typer.testing import CliRunner

from wovenimpact.cli.app import app


def write_results(path, key, values, residual, outcomes=None):
    outcomes = outcomes or ["perforated" if r > 0 else "stopped" for r in residual]
    lines = [f"id,{key},status,error,outcome,residual_velocity_m_per_s"]
    lines += [f"x{i},{v},done,,{o},{r}"
              for i, (v, r, o) in enumerate(zip(values, residual, outcomes))]
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


def test_fits_refuse_undecided_and_no_contact_runs_naming_them(tmp_path):
    """A run that ended still in contact (undecided) or never arrived (no contact) does
    not enter a fit: the command fails naming the variant by its parameter and id."""
    vs = [80.0, 100.0, 120.0, 150.0, 200.0, 300.0]
    vr = [0.0, 0.0, 30.0, 96.0, 164.0, 279.0]
    outcomes = ["stopped", "stopped", "undecided", "perforated", "perforated", "no contact"]
    write_results(tmp_path / "r.csv", "impactor.velocity", [f"{v} m/s" for v in vs], vr,
                  outcomes)
    result = CliRunner().invoke(app, ["ballistics", "v50", str(tmp_path / "r.csv")])
    assert result.exit_code == 2
    text = " ".join(result.output.split())
    assert "2 run(s) are not decided" in text
    assert "impactor.velocity = 120.0 m/s (variant x2): undecided" in text
    assert "impactor.velocity = 300.0 m/s (variant x5): no contact" in text
    write_results(tmp_path / "p.csv", "mesh.plies", [1, 2, 4, 6], [82.0, 58.0, 18.0, 0.0],
                  ["perforated", "perforated", "undecided", "stopped"])
    result = CliRunner().invoke(app, ["ballistics", "plies", str(tmp_path / "p.csv")])
    assert result.exit_code == 2
    assert "mesh.plies = 4 (variant x2): undecided" in " ".join(result.output.split())
    # a table without outcomes (written before they were recorded) is refused too
    (tmp_path / "old.csv").write_text("id,mesh.plies,status,error,residual_velocity_m_per_s\n"
                                      "a,1,done,,82.0\nb,2,done,,58.0\nc,4,done,,18.0\n")
    result = CliRunner().invoke(app, ["ballistics", "plies", str(tmp_path / "old.csv")])
    assert result.exit_code == 2 and "no outcome recorded" in " ".join(result.output.split())


def test_plies_regression_of_a_containment_study_uses_the_exit_speed_and_layers(tmp_path):
    """Thesis eq. 8.2: exit speed V(N) = 130 − 2 N − 0.1 N² of the escaped casings (4, 10,
    20 layers; 30 and 40 contained) → the root 27.4, so 28 layers contain the fragment."""
    n = [4, 10, 20, 30, 40]
    v = [max(0.0, 130.0 - 2.0 * k - 0.1 * k * k) for k in n]
    lines = ["id,mesh.casing.layers,status,error,outcome,fragment_exit_speed_m_per_s"]
    lines += [f"x{k},{k},done,,{'escaped' if s > 0 else 'contained'},{s}" for k, s in zip(n, v)]
    (tmp_path / "c.csv").write_text("\n".join(lines) + "\n")
    result = CliRunner().invoke(app, ["ballistics", "plies", str(tmp_path / "c.csv"), "--json"])
    assert result.exit_code == 0, result.output
    out = json.loads(result.stdout)
    assert out["layers_to_contain"] == 28 and abs(out["root"] - 27.42) < 0.01
    assert abs(out["c2"] + 0.1) < 1e-9 and abs(out["c0"] - 130.0) < 1e-6
    (tmp_path / "u.csv").write_text("\n".join(lines).replace(",contained,", ",undecided,") + "\n")
    bad = CliRunner().invoke(app, ["ballistics", "plies", str(tmp_path / "u.csv")])
    assert bad.exit_code == 2 and "mesh.casing.layers = 30" in bad.output
    # an escape whose speed was still falling at the end has no exit speed to fit
    settled = [lines[0] + ",fragment_exit_speed_settled"] + [
        f"{line},{'False' if line.startswith('x10,') else 'True'}" for line in lines[1:]]
    (tmp_path / "s.csv").write_text("\n".join(settled) + "\n")
    bad = CliRunner().invoke(app, ["ballistics", "plies", str(tmp_path / "s.csv")])
    text = " ".join(bad.output.split())
    assert bad.exit_code == 2 and "mesh.casing.layers = 10 (variant x10)" in text
    assert "still losing speed" in text


def test_v50_of_a_containment_study_says_which_fit_it_takes(tmp_path):
    """A containment ladder has exit speeds, no striking velocity: ``v50`` says so and
    names ``ballistics plies`` (it said only "no column 'impactor.velocity'")."""
    path = tmp_path / "c.csv"
    path.write_text("id,mesh.casing.layers,status,error,outcome,fragment_exit_speed_m_per_s\n"
                    "a,4,done,,escaped,125\nb,8,done,,escaped,100\n")
    result = CliRunner().invoke(app, ["ballistics", "v50", str(path)])
    text = " ".join(result.output.split())
    assert result.exit_code == 2
    assert "a containment study" in text and "wovenimpact ballistics plies" in text


def test_v50_of_one_mesh_of_a_study_over_meshes_and_velocities(tmp_path):
    """A ladder run on two meshes in one results.csv: ``--where`` keeps one mesh's rows
    ('1mm' matches the cell '1 mm'); each mesh gives its own V50 (110 and 90 m/s); an
    unknown value is refused, naming the values the column holds."""
    vs = np.array([80.0, 100.0, 120.0, 150.0, 200.0, 300.0])
    lines = ["id,mesh.element_size,impactor.velocity,status,error,outcome,"
             "residual_velocity_m_per_s"]
    for mesh, limit in (("1 mm", 110.0), ("0.5 mm", 90.0)):
        for i, v in enumerate(vs):
            r = max(v**2 - limit**2, 0.0) ** 0.5
            lines.append(f"{mesh}{i},{mesh},{v} m/s,done,,"
                         f"{'perforated' if r > 0 else 'stopped'},{r}")
    (tmp_path / "r.csv").write_text("\n".join(lines) + "\n")
    for value, limit in (("1mm", 110.0), ("0.5 mm", 90.0)):
        result = CliRunner().invoke(app, ["ballistics", "v50", str(tmp_path / "r.csv"),
                                          "--where", f"mesh.element_size={value}", "--json"])
        assert result.exit_code == 0, result.output
        assert abs(json.loads(result.stdout)["v50_m_per_s"] - limit) < 0.1
        assert json.loads(result.stdout)["runs"] == len(vs)
    result = CliRunner().invoke(app, ["ballistics", "v50", str(tmp_path / "r.csv"),
                                      "--where", "mesh.element_size=2 mm"])
    assert result.exit_code != 0 and "0.5 mm" in result.output and "1 mm" in result.output
