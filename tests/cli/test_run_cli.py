"""``wovenimpact run``: outputs, JSON summary, restart identity and input errors."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from typer.testing import CliRunner

from wovenimpact.cli.app import app
from wovenimpact.io.checkpoint import latest_checkpoint
from wovenimpact.io.history import read_csv
from wovenimpact.runs import run_case
from wovenimpact.setup.compile import compile_case
from wovenimpact.spec.case import load_case
from tests.restart import interrupted_and_resumed

ROOT = Path(__file__).resolve().parents[2]
KEVLAR = ROOT / "examples" / "materials" / "kevlar_thesis.toml"

CASE = """
[case]
name = "small fabric plate"

[materials]
kevlar = "{kevlar}"

[sections.fabric]
material = "kevlar"
bending_modulus = "1 GPa"
transverse_shear_modulus = "3.28 GPa"

[mesh]
kind = "plate"
side = "10 mm"
element_size = "0.94 mm"
quarter = true
section = "fabric"

[[boundary]]
nodes = "edge_outer"
type = "clamped"

[[boundary]]
nodes = "symmetry_x"
type = "symmetry_x"

[[boundary]]
nodes = "symmetry_y"
type = "symmetry_y"

[[initial_velocity]]
velocity = ["0 m/s", "0 m/s", "-60 m/s"]
radius = "1.5 mm"

[run]
end_time = "{end}"
field_interval = "5 us"
history_interval = "0.5 us"
checkpoint_interval = "4 us"
"""


def write_case(tmp_path: Path, end="20 us", text=CASE, name="case.toml") -> Path:
    path = tmp_path / name
    path.write_text(text.format(kevlar=KEVLAR.as_posix(), end=end), encoding="utf-8")
    return path


def test_run_writes_every_output_and_a_json_summary(tmp_path):
    case = write_case(tmp_path)
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["run", str(case), "--out", str(out), "--json"])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout.strip().splitlines()[-1])
    for key in ("steps", "wall_time_s", "ns_per_element_cycle", "energy_error_fraction",
                "max_displacement_m", "element_cycles"):
        assert key in summary
    assert summary["end_time_s"] >= 20e-6
    assert summary["energy_error_fraction"] < 1e-3
    assert json.loads((out / "summary.json").read_text())["steps"] == summary["steps"]
    header = (out / "history.csv").read_text().splitlines()[0].split(",")
    assert header[0] == "time_s" and "structure_kinetic_energy_part_J" in header
    assert (out / "plots" / "energy.png").stat().st_size > 1000
    pvd = (out / "fields" / "fields.pvd").read_text()
    assert pvd.count("<DataSet") == 1 + 4  # t = 0, then every 5 µs to 20 µs
    assert latest_checkpoint(out / "checkpoints") is not None


def two_plies_struck() -> str:
    """CASE as two plies one shell thickness apart, struck by the FSP at 120 m/s."""
    return (CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                         'radius = "1.5 mm"\n', "")
            .replace('section = "fabric"', 'section = "fabric"\nplies = 2\nspacing = "0.4992 mm"')
            + IMPACTOR.replace("{z}", "0.8992 mm"))


@pytest.mark.parametrize("kind", ["kicked ply", "two plies struck"])
def test_restart_ends_bitwise_identical_to_an_uninterrupted_run(tmp_path, kind):
    """Killed after a checkpoint and restarted, a run ends bitwise as an uninterrupted
    one: a kicked ply, and two plies struck by the impactor, whose shell–shell contact
    (rebuilt on restart, candidates searched afresh) pushes the lower ply."""
    text = CASE if kind == "kicked ply" else two_plies_struck()
    end = "12 us" if kind == "kicked ply" else "15 us"
    case = write_case(tmp_path, end=end, text=text)
    # "killed" after the 8 µs checkpoint (one every 4 µs)
    full, whole, broken, a, b = interrupted_and_resumed(case, tmp_path, 0.8)
    if kind == "two plies struck":
        assert min(full["max_deflection_per_ply_m"]) > 0.0  # the lower ply was struck too
    assert a.equals(b)
    fa = sorted(p.name for p in (whole / "fields").glob("*.vtu"))
    fb = sorted(p.name for p in (broken / "fields").glob("*.vtu"))
    assert fa == fb
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (whole, broken))
    assert sb["restarted_from_step"] > 0 and sa["restarted_from_step"] is None
    assert sb["element_cycles"] == sa["element_cycles"]  # both invocations counted
    assert sb["provenance"] == sa["provenance"]


def test_a_run_logged_to_a_file_prints_progress_lines(tmp_path, monkeypatch):
    """With stderr not a terminal (a batch job's log) the run prints a plain progress
    line every LOG_EVERY_S of wall time — simulated time against the end time, step,
    Δt, steps per second, ETA — where a live bar would print nothing until the end."""
    import re

    import wovenimpact.cli.run as cli_run

    monkeypatch.setattr(cli_run, "LOG_EVERY_S", 0.0)
    case = write_case(tmp_path, end="8 us")
    result = CliRunner().invoke(app, ["run", str(case), "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    found = re.findall(r"case: t = ([\d.]+) / 8\.00 µs \((\d+)%\), step (\d+), Δt ([\d.e+-]+) s",
                       result.output)
    assert found, result.output
    times = [float(t) for t, *_ in found]
    assert times == sorted(times) and 0.0 < times[-1] < 8.5  # the last step may pass 8 µs
    assert all(0 <= int(pct) <= 100 for _, pct, *_ in found)
    # before any of them: that it compiles (a first run's minute is said, not silent),
    # then the model's size and the steps ahead, once, as stepping starts
    text = " ".join(result.output.split())
    assert text.index("case: building the model") < text.index("case: stepping")
    start = re.search(r"case: stepping ([\d,]+) elements, ([\d,]+) nodes; first step "
                      r"([\d.e+-]+) s: at least ([\d,]+) steps to t = 8 µs", text)
    assert start, text
    dt1 = float(start.group(3))
    assert int(start.group(4).replace(",", "")) == pytest.approx(8e-6 / dt1, abs=1)
    assert text.count("case: stepping") == 1 and text.index("stepping") < text.index("case: t = ")


def test_a_restart_may_change_the_stop_rules_but_not_what_the_steps_compute(tmp_path):
    """``run.max_added_mass_fraction`` and ``run.stop_when_decided`` only stop a run: a
    restart that raises them (a run stopped at its added-mass limit, to be continued)
    replays the same steps, bit for bit; ``run.mass_scaling_fraction`` changes the steps
    and a restart with another one is refused."""
    from wovenimpact.errors import InputError
    from wovenimpact.provenance import restart_parts

    case = write_case(tmp_path, end="12 us")
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    full = run_case(case, whole)
    run_case(case, cut, max_steps=int(0.8 * full["steps"]))
    with pytest.raises(InputError, match="before a change of the case"):
        run_case(case, cut, restart=True, overrides=["run.mass_scaling_fraction=0.3"])
    run_case(case, cut, restart=True, overrides=["run.max_added_mass_fraction=0.5"])
    assert (whole / "history.csv").read_text() == (cut / "history.csv").read_text()
    containment = ROOT / "examples" / "containment" / "hybrid_4.toml"
    parts = restart_parts(*load_case(containment))
    assert restart_parts(*load_case(containment, [
        'run.stop_when_decided="1 ms"', "run.max_added_mass_fraction=0.05"])) == parts
    assert restart_parts(*load_case(containment, ["run.mass_scaling_fraction=0.2"])) != parts


def test_restart_refuses_side_files_that_do_not_match_its_checkpoint(tmp_path):
    """A restart trusts nothing beside its checkpoint: a deleted history.csv, a history
    cut short, a deleted fields.pvd (resuming would overwrite the frames), an end time
    before the checkpoint's, or a material file changed since are each refused with a
    message, and nothing in the directory is touched."""
    import shutil

    from wovenimpact.errors import InputError

    kevlar = tmp_path / "kevlar.toml"
    shutil.copy(KEVLAR, kevlar)
    case = tmp_path / "case.toml"
    case.write_text(CASE.format(kevlar=kevlar.as_posix(), end="12 us"), encoding="utf-8")
    cut = tmp_path / "cut"
    assert "interrupted_at_step" in run_case(case, cut, max_steps=60)  # after the 8 µs one

    def history_cut(d):
        lines = (d / "history.csv").read_text().splitlines(keepends=True)
        (d / "history.csv").write_text("".join(lines[:3]))

    sabotage = {
        "history.csv is missing": lambda d: (d / "history.csv").unlink(),
        "does not hold the": history_cut,
        "overwrite or lose frames": lambda d: (d / "fields" / "fields.pvd").unlink(),
    }
    for i, (message, spoil) in enumerate(sabotage.items()):
        d = shutil.copytree(cut, tmp_path / f"spoilt{i}")
        spoil(d)
        before = {p: p.read_bytes() for p in d.rglob("*") if p.is_file()}
        with pytest.raises(InputError, match=message):
            run_case(case, d, restart=True)
        assert {p: p.read_bytes() for p in d.rglob("*") if p.is_file()} == before
    short = tmp_path / "short.toml"
    short.write_text(CASE.format(kevlar=kevlar.as_posix(), end="6 us"), encoding="utf-8")
    with pytest.raises(InputError, match="past run.end_time"):  # the checkpoint is at 8 µs
        run_case(short, cut, restart=True)
    kevlar.write_text(kevlar.read_text() + "\n# edited\n")
    with pytest.raises(InputError, match="before a change of a material or mesh file"):
        run_case(case, cut, restart=True)


@pytest.mark.parametrize(
    "edit, message",
    [
        (("[run]", "[run]\nbogus = 1"), "run.bogus"),
        (("[run]", '[run]\neroded_nodes = "stay"'), "run.eroded_nodes"),
        (('end_time = "{end}"', 'end_time = "20"'), "run.end_time"),
        (('element_size = "0.94 mm"', 'element_size = "-0.94 mm"'), "mesh.element_size"),
        (('nodes = "edge_outer"', 'nodes = "rim"'), "boundary[0].nodes"),
        (('material = "kevlar"', 'material = "aramid"'), "sections.fabric.material"),
        (('velocity = ["0 m/s", "0 m/s", "-60 m/s"]', 'velocity = ["0 m/s", "0 m/s"]'),
         "initial_velocity"),
        # a NaN or zero direction is refused where it is written (it used to fail later as
        # a "non-positive Jacobian" or run with a NaN impactor)
        (('section = "fabric"', 'section = "fabric"\nwarp_direction = [nan, 1, 0]'),
         "mesh.warp_direction"),
        (('section = "fabric"', 'section = "fabric"\nwarp_direction = [0, 0, 0]'),
         "mesh.warp_direction"),
    ],
)
def test_bad_case_files_give_errors_that_name_the_key(tmp_path, edit, message):
    case = write_case(tmp_path, text=CASE.replace(*edit))
    result = CliRunner().invoke(app, ["run", str(case), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert message in result.output


@pytest.mark.parametrize("case", sorted((ROOT / "examples" / "cases").glob("*.toml")))
def test_example_cases_are_valid_and_compile(case):
    spec, base = load_case(case)
    compiled = compile_case(spec, base)
    assert compiled.model.n_elems > 0
    assert np.any(compiled.state.v != 0.0) or spec.boundary


def test_a_case_on_an_abaqus_mesh_runs(tmp_path):
    """mesh.kind = "abaqus": nodes, S4R elements and sets read from an .inp file; the
    element set maps to a section and a node set carries the clamp."""
    n = 4
    lines = ["*HEADING", "strip", "*NODE"]
    k = 0
    for j in range(2):
        for i in range(n + 1):
            k += 1
            lines.append(f"{k}, {i * 1.0}, {j * 1.0}, 0.0")
    lines.append("*ELEMENT, TYPE=S4R, ELSET=PLY")
    for i in range(n):
        a = i + 1
        lines.append(f"{i + 1}, {a}, {a + 1}, {a + n + 2}, {a + n + 1}")
    lines += ["*NSET, NSET=LEFT", f"1, {n + 2}"]
    (tmp_path / "strip.inp").write_text("\n".join(lines) + "\n")
    case = tmp_path / "abaqus.toml"
    case.write_text(f"""
[case]
name = "abaqus strip"
[materials]
steel = "{(ROOT / 'examples' / 'materials' / 'steel.toml').as_posix()}"
[sections.plate]
material = "steel"
thickness = "10 mm"
[mesh]
kind = "abaqus"
file = "strip.inp"
sections = {{ PLY = "plate" }}
[[boundary]]
nodes = "LEFT"
type = "clamped"
[[initial_velocity]]
velocity = ["0 m/s", "0 m/s", "1 m/s"]
[run]
end_time = "1 us"
""")
    spec, base = load_case(case)
    compiled = compile_case(spec, base)
    assert compiled.model.n_elems == n and compiled.model.n_nodes == 2 * (n + 1)
    summary = run_case(case, tmp_path / "out")
    assert summary["steps"] > 0 and summary["energy_error_fraction"] < 1e-6


def test_initial_rigid_rotation_sets_v_equal_omega_cross_r(tmp_path):
    text = CASE.replace(
        '[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\nradius = "1.5 mm"',
        '[[initial_velocity]]\nangular_velocity = ["0 rad/s", "100 rad/s", "1047 rad/s"]\n'
        'centre = ["1 mm", "2 mm", "0 mm"]',
    )
    case = write_case(tmp_path, text=text)
    spec, base = load_case(case)
    st = compile_case(spec, base).state
    model = compile_case(spec, base).model
    omega = np.array([0.0, 100.0, 1047.0])
    expect = np.cross(omega, model.x0 - [1e-3, 2e-3, 0.0])
    free = model.bc_code[:, :3] == 0
    assert np.allclose(st.v[free], expect[free], rtol=0, atol=1e-12)
    assert np.all(st.v[~free] == 0.0)


IMPACTOR = """
[impactor]
shape = "cylinder"
radius = "2.78 mm"
length = "5.72 mm"
mass = "1.1 g"
position = ["0 mm", "0 mm", "{z}"]
direction = [0, 0, -1]
velocity = "120 m/s"
"""


def test_impactor_is_placed_with_its_mass_and_velocity(tmp_path):
    from wovenimpact.kernels import rigid_body as RB

    case = write_case(tmp_path, text=CASE + IMPACTOR.replace("{z}", "1 mm"))
    spec, base = load_case(case)
    compiled = compile_case(spec, base)
    p, st = compiled.model.body_params[0], compiled.state.bodies[0]
    assert p[RB.BP_MASS] == pytest.approx(0.25 * 1.1e-3)  # quarter model: a quarter body
    assert p[RB.BP_AXIAL_ONLY] == 1.0
    assert st[RB.B_V:RB.B_V + 3] == pytest.approx([0.0, 0.0, -120.0])
    # centre of mass half a length behind the tip, along +z (the tail is behind)
    assert st[RB.B_X + 2] == pytest.approx(1e-3 + 0.5 * 5.72e-3)
    ke = 0.5 * 0.25 * 1.1e-3 * 120.0**2
    assert compiled.state.energy[5] == pytest.approx(ke + 0.5 * compiled.model.node_mass @ (
        np.sum(compiled.state.v**2, axis=1)))


def test_impactor_overlapping_the_plies_is_an_error(tmp_path):
    case = write_case(tmp_path, text=CASE + IMPACTOR.replace("{z}", "0.1 mm"))
    result = CliRunner().invoke(app, ["run", str(case), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert "impactor.position" in result.output and "overlaps" in result.output


def test_impact_run_reports_outcome_velocity_and_energies(tmp_path):
    """A small plate struck by the FSP at 120 m/s for 15 µs: the history carries the
    impactor columns, the summary the outcome fields; 15 µs is too short to decide (the
    impactor is still pushing the ply: undecided, slowed but not stopped), and the
    energy balance holds to 1e-3 (measured 9.9e-5)."""
    text = CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                        'radius = "1.5 mm"\n', "") + IMPACTOR.replace("{z}", "0.4 mm")
    case = write_case(tmp_path, text=text, end="15 us")
    out = tmp_path / "out"
    summary = run_case(case, out)
    for key in ("residual_velocity_m_per_s", "perforated", "max_deflection_m",
                "energy_error_fraction", "absorbed_energy_J", "absorbed_energy_per_ply_J",
                "wall_time_s", "element_cycles", "ns_per_element_cycle"):
        assert key in summary
    header = (out / "history.csv").read_text().splitlines()[0]
    assert "impactor_velocity_m_per_s" in header and "contact_force_full_N" in header
    assert "intact_material_ahead" in header and "impactor_nose_ahead_of_intact_m" in header
    assert summary["peak_contact_force_N"] > 0.0
    assert 0.0 < summary["absorbed_energy_J"] < 0.5 * 1.1e-3 * 120.0**2
    assert summary["outcome"] == "undecided" and not summary["perforated"]
    h = read_csv(out / "history.csv")
    v = h["impactor_velocity_m_per_s"]
    assert v[0] == pytest.approx(120.0) and 0.0 < v[-1] < 120.0  # slowed, still coming
    assert h["intact_material_ahead"][-1] == 1 and h["contact_force_full_N"][-1] > 0.0
    assert summary["energy_error_fraction"] < 1e-3 and summary["energy_check"] == "pass"
    assert (out / "plots" / "impactor.png").exists() and (out / "plots" / "ply_deflection.png").exists()


def test_pre_perforated_ply_lets_the_impactor_through_untouched(tmp_path):
    """A hole wider than the impactor (elements eroded at t = 0): no contact, the impactor
    keeps its velocity exactly, the eroded elements and their orphaned nodes stay out."""
    text = CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                        'radius = "1.5 mm"\n', "") + IMPACTOR.replace("{z}", "0.4 mm") + (
        '\n[[initial_erosion]]\nradius = "4 mm"\n')
    case = write_case(tmp_path, text=text, end="20 us")
    summary = run_case(case, tmp_path / "out")
    assert summary["outcome"] == "no contact" and not summary["perforated"]
    assert summary["residual_velocity_m_per_s"] == pytest.approx(120.0, rel=1e-12)
    assert summary["peak_contact_force_N"] == 0.0
    assert summary["eroded_elements"] > 0
    assert summary["energy_error_fraction"] < 1e-9


def test_design_plies_finds_the_pack_that_stops_the_impactor(tmp_path):
    """Real runs on a small plate struck at 60 m/s: the answer N is a pack that stopped
    the impactor, bracketed by a run of N − 1 plies that it perforated."""
    text = CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                        'radius = "1.5 mm"\n', "").replace(
        'section = "fabric"', 'section = "fabric"\nplies = 1\nspacing = "0.4992 mm"') + (
        IMPACTOR.replace("{z}", "0.4 mm").replace('"120 m/s"', '"60 m/s"'))
    case = write_case(tmp_path, text=text, end="300 us")
    result = CliRunner().invoke(app, ["design", "plies", str(case), "--out", str(tmp_path / "d"),
                                      "--json"])
    assert result.exit_code == 0, result.output
    answer = json.loads(result.stdout.strip().splitlines()[-1])
    n = answer["plies_to_stop"]
    assert answer["runs"][str(n)] == "stopped"
    assert n == 1 or answer["runs"][str(n - 1)] == "perforated"
    assert answer["areal_mass_kg_per_m2"] == pytest.approx(n * 0.4775, rel=1e-3)
    print(f"\ndesign search: {n} plies stop it; runs {answer['runs']}")
    # a second search reads the finished runs back instead of running them again, and
    # --check 1 runs the pack above the answer as well
    summaries = sorted((tmp_path / "d").glob("plies_*/summary.json"))
    stamps = [p.stat().st_mtime_ns for p in summaries]
    again = CliRunner().invoke(app, ["design", "plies", str(case), "--out", str(tmp_path / "d"),
                                     "--json", "--check", "1"])
    checked = json.loads(again.stdout.strip().splitlines()[-1])
    assert [p.stat().st_mtime_ns for p in summaries] == stamps
    assert checked["plies_to_stop"] == n and str(n + 1) in checked["runs"]
    assert checked["runs"][str(n + 1)] in ("stopped", "perforated")
    assert (checked["warning"] == "") == (checked["runs"][str(n + 1)] == "stopped")


def test_set_overrides_change_the_case_and_bad_ones_are_named(tmp_path):
    """--set KEY=VALUE (TOML value or plain text) changes the run; a key the case lacks
    or a value out of range is an input error naming it."""
    case = write_case(tmp_path, end="20 us")
    out = tmp_path / "o"
    result = CliRunner().invoke(app, [
        "run", str(case), "--out", str(out), "--json", "--set", "run.end_time=6 us",
        "--set", 'initial_velocity.0.velocity=["0 m/s", "0 m/s", "-30 m/s"]'])
    assert result.exit_code == 0, result.output
    summary = json.loads(result.stdout)
    assert 6e-6 <= summary["end_time_s"] < 6e-6 + 2 * summary["first_time_step_s"]
    base = tmp_path / "b"
    run_case(case, base, overrides=["run.end_time=6 us"])

    def ke0(d):
        rows = (d / "history.csv").read_text().splitlines()
        return float(rows[1].split(",")[rows[0].split(",").index("structure_kinetic_energy_part_J")])

    assert ke0(out) == pytest.approx(ke0(base) / 4.0, rel=1e-12)  # half the speed
    for bad, words in (("impactor.velocity=100 m/s", "has no 'impactor'"),
                       ("run.end_time=-1 us", "run.end_time"),
                       ("run.end_time", "expected KEY=VALUE"),
                       ("run.end_time.unit=s", "'run.end_time' is a value")):
        result = CliRunner().invoke(app, ["run", str(case), "--out", str(out), "--set", bad])
        assert result.exit_code == 2 and words in result.output, result.output


def test_negative_impactor_speed_is_an_error_naming_the_key(tmp_path):
    """The impactor's speed is a magnitude along ``direction``: a negative one is refused
    (issue 4's bad-case list: unknown key, missing unit, negative velocity, overlap)."""
    case = write_case(tmp_path, text=CASE + IMPACTOR.replace("{z}", "0.4 mm"))
    result = CliRunner().invoke(app, ["run", str(case), "--out", str(tmp_path / "o"),
                                      "--set", "impactor.velocity=-120 m/s"])
    assert result.exit_code == 2
    assert "impactor.velocity" in result.output and "must be > 0" in result.output


def test_design_run_interrupted_by_a_crash_resumes_from_its_checkpoint(tmp_path):
    """A pack run cut short (checkpoints, no summary) is restarted, not redone: the
    resumed run takes only the remaining steps and ends with the uninterrupted outcome."""
    from wovenimpact.spec.fields import read_toml
    from wovenimpact.studies.design import _case_with_plies, _run_one

    text = CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                        'radius = "1.5 mm"\n', "") + IMPACTOR.replace("{z}", "0.4 mm")
    case = write_case(tmp_path, text=text, end="12 us")
    doc = _case_with_plies(read_toml(case, "case file"), 1)
    whole, cut = tmp_path / "whole", tmp_path / "cut"
    assert _run_one(doc, str(tmp_path), str(whole)) == "undecided"
    a = json.loads((whole / "summary.json").read_text())
    full_steps = a["steps"]
    # the crash: the same call, stopped after most of its steps (checkpoints every 4 µs)
    (cut / "checkpoints").mkdir(parents=True)
    (cut / "parameters.json").write_text(json.dumps(doc, indent=2, default=str) + "\n")
    from wovenimpact.runs import run_spec
    from wovenimpact.spec.case import case_from_dict

    run_spec(case_from_dict(doc), tmp_path, cut, max_steps=int(0.8 * full_steps))
    assert not (cut / "summary.json").exists() and latest_checkpoint(cut / "checkpoints")
    assert _run_one(doc, str(tmp_path), str(cut)) == "undecided"
    resumed = json.loads((cut / "summary.json").read_text())
    assert resumed["steps"] == full_steps  # same end, restart bitwise (tested above)
    assert resumed["restarted_from_step"] > 0.5 * full_steps  # only the rest ran
    assert resumed["element_cycles"] == a["element_cycles"]  # every invocation counted
    assert resumed["residual_velocity_m_per_s"] == a["residual_velocity_m_per_s"]


def test_penalty_stiffness_does_not_follow_a_falling_step(tmp_path):
    """k = β m / max(Δt, Δt_first)²: the same penetration gives the same force when the
    step falls below the first one, and a quarter of it when the step doubles."""
    from wovenimpact.kernels import rigid_body as RB
    from wovenimpact.solver.contact_stage import ContactBuffers, contact_forces

    text = CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                        'radius = "1.5 mm"\n', "") + IMPACTOR.replace("{z}", "0.4 mm")
    compiled = compile_case(*load_case(write_case(tmp_path, text=text)))
    model, state = compiled.model, compiled.state
    state.bodies[0, RB.B_X + 2] -= 0.3e-3  # the flat nose 0.05 mm into the ply's surface
    state.bodies[0, RB.B_V:RB.B_V + 3] = 0.0  # at rest: no dashpot force, the spring alone
    state.dt_first = 1e-7
    cb = ContactBuffers.for_model(model)
    alive = np.ones(model.n_elems, dtype=np.uint8)

    def force(dt):
        return contact_forces(model, state, cb, dt, alive, 0)[0][0][2]

    f_ref = force(1e-7)
    assert f_ref > 0.0  # the ply pushes the impactor back up
    assert force(1e-8) == f_ref
    assert force(2e-7) == pytest.approx(f_ref / 4.0, rel=1e-12)


def test_a_node_eroded_in_the_step_takes_no_contact_force(tmp_path):
    """Momentum, with ``run.eroded_nodes = "remove"``: a node whose last element erodes in
    this step leaves the model in the node update, so the contact stage must neither push
    it nor let it push the body (with "keep", the default, it stays contact-active:
    tests/verification/test_eroded_nodes.py).
    With the elements under the face eroded this step, the body feels only the nodes
    that keep a live element; with nothing eroded it feels them all."""
    from wovenimpact.kernels import rigid_body as RB
    from wovenimpact.solver.contact_stage import ContactBuffers, contact_forces

    text = CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                        'radius = "1.5 mm"\n', "") + IMPACTOR.replace("{z}", "0.4 mm")
    compiled = compile_case(*load_case(write_case(tmp_path, text=text),
                                       ['run.eroded_nodes="remove"']))
    model, state = compiled.model, compiled.state
    state.bodies[0, RB.B_X + 2] -= 0.3e-3  # the flat nose 0.05 mm into the ply's surface
    state.dt_first = 1e-7
    cb = ContactBuffers.for_model(model)
    alive = np.ones(model.n_elems, dtype=np.uint8)
    contact_forces(model, state, cb, 1e-7, alive, 0)
    pushed = np.flatnonzero(np.linalg.norm(cb.f_con, axis=1) > 0.0)
    assert pushed.size > 0
    # erode every element of the pushed nodes: they are left without a live element
    gone = np.unique(np.concatenate([model.node_elem[model.node_ptr[n]:model.node_ptr[n + 1]]
                                     for n in pushed]))
    alive[gone] = 0
    resultants = contact_forces(model, state, cb, 1e-7, alive, gone.size)
    orphan = [n for n in pushed
              if not alive[model.node_elem[model.node_ptr[n]:model.node_ptr[n + 1]]].any()]
    assert orphan and np.all(cb.f_con[orphan] == 0.0)
    body_force = resultants[0][0]
    assert np.allclose(body_force, -cb.f_con.sum(axis=0) * np.array([0, 0, 1.0]), atol=1e-12)


@pytest.mark.parametrize("direction", ["[nan, 0, -1]", "[0, 0, 0]", "[0, inf, -1]"])
def test_a_bad_impactor_direction_is_an_error_naming_the_key(tmp_path, direction):
    text = CASE + IMPACTOR.replace("{z}", "2 mm").replace("direction = [0, 0, -1]",
                                                          f"direction = {direction}")
    assert f"direction = {direction}" in text
    result = CliRunner().invoke(app, ["run", str(write_case(tmp_path, text=text)),
                                      "--out", str(tmp_path / "o")])
    assert result.exit_code == 2
    assert "impactor.direction" in result.output


def test_a_reused_output_directory_is_cleared_of_an_earlier_runs_outputs(tmp_path):
    """Frames, plots and checkpoints another case left in OUT are removed (with a warning
    saying so) before a fresh run writes its own; files the run never writes stay."""
    from wovenimpact.errors import InputWarning

    out = tmp_path / "out"
    stale = [out / "fields" / "step_000099.vtu", out / "plots" / "impactor.png",
             out / "checkpoints" / "checkpoint_000999999.npz", out / "summary.json",
             out / "fields" / "element_sets.json"]
    for p in stale:
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_text("another case's output")
    (out / "notes.txt").write_text("mine")
    with pytest.warns(InputWarning, match="removing 5 output files of an earlier run"):
        summary = run_case(write_case(tmp_path, end="8 us"), out)
    assert not any(p.exists() and p.read_text() == "another case's output" for p in stale)
    assert (out / "notes.txt").read_text() == "mine"
    frames = sorted(p.name for p in (out / "fields").glob("*.vtu"))
    assert frames == [f"step_{k:06d}.vtu" for k in range(len(frames))]
    assert summary["steps"] > 0 and not (out / "plots" / "impactor.png").exists()


def test_a_run_stopped_by_the_solver_keeps_its_history_up_to_the_stop(tmp_path, monkeypatch):
    """A run that stops on a SimulationError (a collapse, too much added mass) writes the
    history up to the step that failed, not only to its last checkpoint: that history is
    what explains the stop. A restart still resumes from the checkpoint."""
    import wovenimpact.runs as runs
    from wovenimpact.errors import SimulationError

    case = write_case(tmp_path, end="12 us")
    out = tmp_path / "out"
    real_step = runs.step

    def failing_step(model, state, ws, *a, **k):
        if state.t > 10e-6:  # past the 8 µs checkpoint
            raise SimulationError("stopped on purpose")
        real_step(model, state, ws, *a, **k)

    monkeypatch.setattr(runs, "step", failing_step)
    with pytest.raises(SimulationError, match="on purpose"):
        run_case(case, out)
    t = read_csv(out / "history.csv")["time_s"]
    assert t[-1] > 10e-6 - 0.5e-6 and t[-1] <= 10e-6 + 1e-6  # rows to the stop, past 8 µs
    monkeypatch.setattr(runs, "step", real_step)
    whole = run_case(case, tmp_path / "whole")
    resumed = run_case(case, out, restart=True)
    assert resumed["restarted_from_step"] > 0 and resumed["steps"] == whole["steps"]
    assert (out / "history.csv").read_text() == (tmp_path / "whole" / "history.csv").read_text()
