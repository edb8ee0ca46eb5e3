"""``wovenimpact calibrate crimp|compression`` through typer's CliRunner."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest
from typer.testing import CliRunner

import wovenimpact.cli.calibrate  # noqa: F401  (registers the commands)
from wovenimpact.cli.app import app

ROOT = Path(__file__).resolve().parents[2]
SHIPPED_CSV = ROOT / "examples" / "calibration" / "compression_synthetic.csv"
H0_TABLE_5_1 = 0.12495e-3  # m
A_M, B_N = 0.12389e-3, 0.98432

runner = CliRunner()


def flat(text: str) -> str:
    """Output with line wrapping (rich wraps at 80 columns) undone."""
    return " ".join(text.split())


def test_crimp_json():
    r = runner.invoke(
        app, ["calibrate", "crimp", "--thread-count", "27 1/in", "--crimp", "0.0421", "--json"]
    )
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert set(out) == {"h0_m", "thickness_m", "half_length_m"}
    assert out["h0_m"] == pytest.approx(H0_TABLE_5_1, rel=5e-3)
    assert out["thickness_m"] == pytest.approx(4 * out["h0_m"], rel=1e-15)
    assert out["half_length_m"] == pytest.approx(0.0254 / 54, rel=1e-12)


def test_crimp_accepts_other_units_and_percent():
    r = runner.invoke(
        app, ["calibrate", "crimp", "--thread-count", "1062.99 1/m", "--crimp", "4.21 %", "--json"]
    )
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout)["h0_m"] == pytest.approx(H0_TABLE_5_1, rel=5e-3)


def test_crimp_table_for_a_person():
    r = runner.invoke(app, ["calibrate", "crimp", "--thread-count", "27 1/in", "--crimp", "0.0421"])
    assert r.exit_code == 0, r.output
    assert "h0_m" in r.stdout and "0.000124795" in r.stdout


@pytest.mark.parametrize(
    ("value", "expect"),
    [
        ("27", "--thread-count = '27' has no unit"),
        ("27 mm", "--thread-count = '27 mm' has the wrong dimension ([length])"),
        ("0 1/in", "--thread-count = '0 1/in' must be > 0"),
        ("many", "--thread-count = 'many' could not be read"),
    ],
)
def test_bad_thread_count_exits_2_naming_the_option(value, expect):
    r = runner.invoke(app, ["calibrate", "crimp", "--thread-count", value, "--crimp", "0.0421"])
    assert r.exit_code == 2
    assert expect in flat(r.output)
    assert "Traceback" not in r.output


def test_negative_crimp_exits_2():
    r = runner.invoke(app, ["calibrate", "crimp", "--thread-count", "27 1/in", "--crimp", "-0.1"])
    assert r.exit_code == 2
    assert "--crimp = '-0.1' must be ≥ 0" in flat(r.output)


def test_compression_json_writes_plot(tmp_path):
    r = runner.invoke(
        app, ["calibrate", "compression", str(SHIPPED_CSV), "--out", str(tmp_path), "--json"]
    )
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    assert {"a_m", "b_N", "r2", "rmse_N", "n_points", "plot"} <= set(out)
    assert out["a_m"] == pytest.approx(A_M, rel=0.02)
    assert out["b_N"] == pytest.approx(B_N, rel=0.02)
    assert out["r2"] > 0.99 and out["n_points"] == 40
    plot = Path(out["plot"])
    assert plot.parent == tmp_path and plot.read_bytes()[:4] == b"\x89PNG"


def test_compression_plot_defaults_to_the_data_directory(tmp_path):
    data = tmp_path / "curve.csv"
    shutil.copy(SHIPPED_CSV, data)
    r = runner.invoke(app, ["calibrate", "compression", str(data), "--weighting", "absolute"])
    assert r.exit_code == 0, r.output
    assert (tmp_path / "curve_fit.png").is_file()
    assert "a_m" in r.stdout


def test_compression_bad_file_exits_2_with_a_clean_message(tmp_path):
    bad = tmp_path / "bad.csv"
    bad.write_text("d_mm,F_N\n0.1,1\n0.2,abc\n0.3,3\n")
    r = runner.invoke(app, ["calibrate", "compression", str(bad)])
    assert r.exit_code == 2
    assert "line 3, column 'F_N': 'abc' is not a number" in flat(r.output)
    assert "Traceback" not in r.output
    r = runner.invoke(app, ["calibrate", "compression", str(tmp_path / "none.csv")])
    assert r.exit_code == 2 and "cannot read the data file" in flat(r.output)


# --- calibrate fracture ----------------------------------------------------------------
MATERIALS = ROOT / "examples" / "materials"


def test_fracture_writes_a_material_file_that_loads_with_the_fitted_table(tmp_path):
    """The 2024-T3 file (which has a [material.regularisation] already: it is replaced,
    not repeated) on 2 and 4 mm meshes, written about 2 mm: the file loads, carries the
    table of the JSON answer (s = 1 at 2 mm, the 4 mm row below 1: that mesh fractures
    later unregularised), the CSV shows the 4 mm mesh brought to the 2 mm elongation
    (3.2 % apart before), and the figure exists."""
    from wovenimpact.spec.material import load_material

    src = MATERIALS / "al2024t3_johnson_cook.toml"
    r = runner.invoke(app, ["calibrate", "fracture", str(src), "--out", str(tmp_path),
                            "--sizes", "2 mm, 4 mm", "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)
    mat = load_material(out["material_file"])
    reg = mat.regularisation
    assert reg.reference_length == pytest.approx(2e-3)
    assert [list(row) for row in reg.fracture_scale] == out["fracture_scale"]
    assert reg.fracture_scale[0] == (1.0, 1.0) and 0.9 < reg.fracture_scale[1][1] < 1.0
    assert reg.failure_displacement == 0.0
    assert mat.damage == load_material(src).damage  # the rest of the file as it was
    # matched to the fit's tolerance: 1.5 × the end's travel in one 4 mm time step
    tolerance = 1.5 * 10.0 * 0.9 * 4e-3 / mat.plane_stress_wave_speed
    u_ref = out["reference_elongation_at_fracture_m"]
    assert out["largest_error_before"] > 0.02
    assert out["largest_error_after"] * u_ref <= tolerance
    with open(out["csv_file"], newline="") as fh:
        import csv

        rows = list(csv.DictReader(fh))
    assert [float(row["element_size_mm"]) for row in rows] == [2.0, 4.0]
    assert abs(float(rows[1]["error_after"])) * u_ref <= tolerance
    assert Path(out["figure_file"]).stat().st_size > 0


def test_fracture_refuses_a_size_the_coupon_cannot_hold(tmp_path):
    r = runner.invoke(app, ["calibrate", "fracture", str(MATERIALS / "aluminium.toml"),
                            "--out", str(tmp_path), "--sizes", "3 mm, 4 mm"])
    assert r.exit_code != 0
    text = flat(r.output)
    assert "--sizes" in text and "3 mm" in text and "does not divide" in text


def test_fracture_refuses_a_material_without_fracture(tmp_path):
    doc = (MATERIALS / "titanium.toml").read_text().replace("fracture_strain = 0.25", "")
    path = tmp_path / "no_fracture.toml"
    path.write_text(doc)
    r = runner.invoke(app, ["calibrate", "fracture", str(path), "--out", str(tmp_path)])
    assert r.exit_code != 0
    assert "no fracture strain" in flat(r.output)
