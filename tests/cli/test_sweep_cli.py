"""``wovenimpact sweep``: variants, failure isolation, resume, results table and plots."""

from __future__ import annotations

import json
from pathlib import Path

from typer.testing import CliRunner

from tests.cli.test_run_cli import CASE, KEVLAR, write_case
from wovenimpact.cli.app import app

STUDY = """
[study]
name = "kick velocity"
case = "case.toml"
metrics = ["max_displacement_m", "energy_error_fraction"]

[parameters]
"initial_velocity.0.velocity" = [["0 m/s", "0 m/s", "-30 m/s"], ["0 m/s", "0 m/s", "-60 m/s"], ["0 m/s", "0 m/s", "-60"]]
"""


def test_sweep_runs_variants_isolates_a_failure_and_resumes(tmp_path: Path):
    write_case(tmp_path, end="8 us")
    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    out = tmp_path / "out"
    result = CliRunner().invoke(app, ["sweep", str(study), "--out", str(out), "--json"])
    assert result.exit_code == 1, result.output  # one variant has a value without unit
    res = json.loads(result.stdout.strip().splitlines()[-1])
    rows = res["results"]
    assert [r["status"] for r in rows] == ["done", "done", "failed"]
    assert "velocity" in rows[2]["error"] and "unit" in rows[2]["error"]
    d30, d60 = (float(r["max_displacement_m"]) for r in rows[:2])
    assert d60 > 1.5 * d30  # the faster kick moves the plate further
    assert (out / "results.csv").read_text().count("\n") == 4
    assert (out / "plots" / "max_displacement_m.png").exists()
    assert (out / "plots" / "structure_kinetic_energy_part_J_histories.png").exists()
    # the study's page links the page of each finished variant
    from tests.io.report_page import check_run_page, read_page

    page = read_page(out / "report.html")
    assert page.links == [f"runs/{r['id']}/report.html" for r in rows[:2]]
    for r in rows[:2]:
        check_run_page(out / "runs" / r["id"])
    # resume: finished variants are not run again
    stamp = (out / "runs" / rows[0]["id"] / "summary.json").stat().st_mtime_ns
    again = CliRunner().invoke(app, ["sweep", str(study), "--out", str(out), "--json"])
    assert again.exit_code == 1
    assert (out / "runs" / rows[0]["id"] / "summary.json").stat().st_mtime_ns == stamp


def test_sweep_reports_a_bad_parameter_key(tmp_path: Path):
    write_case(tmp_path, end="8 us")
    study = tmp_path / "study.toml"
    study.write_text(STUDY.replace('"initial_velocity.0.velocity"', '"impactor.velocity"'))
    result = CliRunner().invoke(app, ["sweep", str(study), "--out", str(tmp_path / "o")])
    assert result.exit_code == 2 and "impactor" in result.output


def test_sweep_on_a_dask_cluster_gives_the_local_results(tmp_path: Path):
    """The same study through a Dask scheduler (a local one here) gives the same rows."""
    from distributed import LocalCluster

    write_case(tmp_path, end="8 us")
    study = tmp_path / "study.toml"
    study.write_text(STUDY.replace(', ["0 m/s", "0 m/s", "-60"]', ""))
    from wovenimpact.studies.sweep import run_study

    heard = {"local": [], "dask": []}
    local = run_study(study, tmp_path / "local",
                      progress=lambda d, t, v, r: heard["local"].append((d, t, r["status"])))
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=False,
                      dashboard_address=None) as cluster:
        remote = run_study(study, tmp_path / "dask", scheduler=cluster.scheduler_address,
                           progress=lambda d, t, v, r: heard["dask"].append((d, t, r["status"])))
    assert [r["status"] for r in remote] == ["done", "done"]
    # progress hears of each variant as it finishes, on either back end
    assert heard["local"] == heard["dask"] == [(1, 2, "done"), (2, 2, "done")]
    assert [r["max_displacement_m"] for r in remote] == [r["max_displacement_m"] for r in local]


def test_example_studies_load_and_their_variants_validate():
    """Every variant of every shipped study is a valid case; material overrides (crimp,
    compaction) reach the material: the crimp study's h0 grows with the crimp."""
    from wovenimpact.setup.compile import load_case_material
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.studies.sweep import load_study

    root = Path(__file__).resolve().parents[2] / "examples" / "studies"
    for study in sorted(root.glob("*.toml")):
        info, variants, base = load_study(study)
        assert variants
        h0 = []
        for v in variants:
            spec = case_from_dict(v.document, source=f"{study.name}:{v.id}")
            mats = {n: load_case_material(base, n, ref) for n, ref in spec.materials.items()}
            h0.append(mats["kevlar"].warp.h0 if "kevlar" in mats else None)
        if study.stem == "thesis_crimp":
            assert h0[0] < h0[1] < h0[2]


def test_results_of_impact_runs_record_the_outcome(tmp_path: Path):
    """results.csv carries the outcome of every impact run, whatever the metrics (here
    the variants were finished earlier, so the study only reads their summaries back)."""
    import csv

    from wovenimpact.studies.sweep import run_study

    write_case(tmp_path, end="8 us")
    study = tmp_path / "study.toml"
    study.write_text(STUDY.replace(', ["0 m/s", "0 m/s", "-60"]', ""))
    out = tmp_path / "out"
    fake_finished_runs(study, out, ("stopped", "undecided"))
    run_study(study, out)
    with (out / "results.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [r["outcome"] for r in rows] == ["stopped", "undecided"]


def fake_finished_runs(study: Path, out: Path, outcomes) -> list:
    """Write parameters.json and a summary.json (current version and provenance digest)
    for the variants of ``study`` as if they had run; returns the variants."""
    from wovenimpact.provenance import provenance
    from wovenimpact.results.summary import SUMMARY_VERSION
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.studies.sweep import load_study

    _, variants, base = load_study(study)
    for v, outcome in zip(variants, outcomes):
        run = out / "runs" / v.id
        run.mkdir(parents=True)
        (run / "parameters.json").write_text(json.dumps(v.values, default=str))
        (run / "summary.json").write_text(json.dumps({
            "summary_version": SUMMARY_VERSION, "outcome": outcome,
            "max_displacement_m": 1e-3, "energy_error_fraction": 1e-4,
            "provenance": provenance(case_from_dict(v.document), base)}))
    return variants


def test_a_finished_variant_is_reused_only_while_its_digest_matches(tmp_path: Path):
    """A variant's summary stands only for the case, material file and code it was run
    with: after the material file changes it is not reused, and the reason is said."""
    import shutil

    from wovenimpact.studies.sweep import finished

    kevlar = tmp_path / "kevlar.toml"
    shutil.copy(KEVLAR, kevlar)
    (tmp_path / "case.toml").write_text(CASE.format(kevlar=kevlar.as_posix(), end="8 us"))
    study = tmp_path / "study.toml"
    study.write_text(STUDY.replace(', ["0 m/s", "0 m/s", "-60"]', ""))
    out = tmp_path / "out"
    variants = fake_finished_runs(study, out, ("stopped", "undecided"))
    v = variants[0]
    done, why = finished(out / "runs" / v.id, v.values, v.document, tmp_path)
    assert done["status"] == "done" and done["outcome"] == "stopped" and why == ""
    other = json.loads(json.dumps(v.document))
    other["sections"]["fabric"]["bending_modulus"] = "2 GPa"  # same values, another case
    done, why = finished(out / "runs" / v.id, v.values, other, tmp_path)
    assert done is None and why == "changed since it ran: the case"
    kevlar.write_text(kevlar.read_text() + "\n# edited\n")
    done, why = finished(out / "runs" / v.id, v.values, v.document, tmp_path)
    assert done is None and why == "changed since it ran: a material or mesh file"


def test_duplicate_variants_run_once_and_unknown_metrics_are_refused_before_any_run(
        tmp_path: Path):
    import warnings

    from wovenimpact.errors import InputWarning
    from wovenimpact.studies.sweep import load_study

    write_case(tmp_path, end="8 us")
    study = tmp_path / "study.toml"
    kick = '["0 m/s", "0 m/s", "-30 m/s"]'
    study.write_text(STUDY.replace('["0 m/s", "0 m/s", "-60 m/s"], ["0 m/s", "0 m/s", "-60"]',
                                   f"{kick}, {kick}"))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        _, variants, _ = load_study(study)
    assert len(variants) == 1  # three times the same kick
    assert any(issubclass(w.category, InputWarning) and "2 of the 3 variants repeat" in
               str(w.message) for w in caught)
    study.write_text(STUDY.replace('"energy_error_fraction"]', '"max_displacment_m"]'))
    out = tmp_path / "o"
    result = CliRunner().invoke(app, ["sweep", str(study), "--out", str(out)])
    assert result.exit_code == 2
    assert "study.metrics ['max_displacment_m']" in result.output
    assert "max_displacement_m" in result.output  # the valid names are listed
    assert not out.exists()  # nothing ran


def _children(pid: int) -> list[int]:
    """Process ids whose parent is ``pid`` (from /proc)."""
    found = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            found.append(int(stat.parent.name))
    return found


def _alive(pid: int) -> bool:
    """The process exists and is not a zombie."""
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def test_a_killed_sweep_leaves_no_worker_behind(tmp_path: Path):
    """``wovenimpact sweep`` killed outright (SIGKILL, no chance to clean up) while its two
    pool workers run variants that would take minutes: every worker ends by itself
    within seconds (each watches its parent), none goes on computing."""
    import os
    import signal
    import subprocess
    import sys
    import time

    if not Path("/proc/self/stat").exists():
        import pytest

        pytest.skip("needs /proc to find the worker processes")
    write_case(tmp_path, end="50 ms")  # ~3e5 steps a variant: minutes, were they left
    study = tmp_path / "study.toml"
    study.write_text(STUDY.replace(', ["0 m/s", "0 m/s", "-60"]', ""))
    out = tmp_path / "out"
    proc = subprocess.Popen(
        [sys.executable, "-c", "from wovenimpact.cli import main; main()", "sweep", str(study),
         "--out", str(out), "--workers", "2", "--json"],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 180.0
        while len(list(out.glob("runs/*/parameters.json"))) < 2:  # both variants started
            assert proc.poll() is None and time.monotonic() < deadline
            time.sleep(0.2)
        workers = _children(proc.pid)
        assert len(workers) >= 2
    finally:
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
    deadline = time.monotonic() + 20.0
    while any(_alive(w) for w in workers) and time.monotonic() < deadline:
        time.sleep(0.2)
    left = [w for w in workers if _alive(w)]
    for w in left:  # do not leave them to the rest of the suite
        os.kill(w, signal.SIGKILL)
    assert not left, f"workers {left} outlived the killed sweep"
    assert not any(out.glob("runs/*/summary.json"))  # they were cut short, as they should


def test_an_interrupted_variant_resumes_from_its_checkpoint(tmp_path: Path):
    """A variant cut short (a killed job, a session that ended: checkpoints, no summary)
    is restarted by the next sweep, not redone — what makes an hours-long ladder (the
    containment report) finish across sessions — and ends as the uninterrupted run; a
    checkpoint left by other values is not resumed."""
    import pytest

    from wovenimpact.errors import InputWarning
    from wovenimpact.runs import run_spec
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.studies.sweep import load_study, run_study

    write_case(tmp_path, end="12 us")
    study = tmp_path / "study.toml"
    study.write_text(STUDY.replace(', ["0 m/s", "0 m/s", "-60 m/s"], ["0 m/s", "0 m/s", "-60"]',
                                   ""))
    _, (v,), base = load_study(study)

    def summary(root):
        return json.loads((root / "runs" / v.id / "summary.json").read_text())

    assert run_study(study, tmp_path / "whole", workers=1)[0]["status"] == "done"
    whole = summary(tmp_path / "whole")
    cut = tmp_path / "cut" / "runs" / v.id
    cut.mkdir(parents=True)
    (cut / "parameters.json").write_text(json.dumps(v.values, indent=2, default=str) + "\n")
    run_spec(case_from_dict(v.document), base, cut, max_steps=int(0.8 * whole["steps"]))
    assert not (cut / "summary.json").exists()
    assert run_study(study, tmp_path / "cut", workers=1)[0]["status"] == "done"
    resumed = summary(tmp_path / "cut")
    assert resumed["restarted_from_step"] > 0.5 * whole["steps"]  # only the rest ran
    assert resumed["steps"] == whole["steps"]
    assert resumed["element_cycles"] == whole["element_cycles"]
    assert (cut / "history.csv").read_text() == (
        tmp_path / "whole" / "runs" / v.id / "history.csv").read_text()
    # the same directory cut short again, then asked for with other values: from the start
    (cut / "summary.json").unlink()
    (cut / "parameters.json").write_text(json.dumps({"other": 1}) + "\n")
    with pytest.warns(InputWarning, match="removing .* output files of an earlier run"):
        assert run_study(study, tmp_path / "cut", workers=1)[0]["status"] == "done"
    again = summary(tmp_path / "cut")
    assert again["restarted_from_step"] is None and again["steps"] == whole["steps"]


def test_a_metric_with_a_value_per_ply_is_plotted_one_line_per_ply(tmp_path: Path):
    """absorbed_energy_per_ply_J (a list per run) gets a figure with one line per ply
    beside the scalar metrics' (it stopped the sweep with a TypeError after results.csv)."""
    from wovenimpact.studies.plots import study_plots
    from wovenimpact.studies.sweep import StudyInfo, Variant

    info = StudyInfo(name="s", case="c.toml", metrics=["absorbed_energy_J",
                                                          "absorbed_energy_per_ply_J"])
    variants = [Variant(id=f"v{k}", values={"mesh.element_size": h}, document={})
                for k, h in enumerate(("1 mm", "2 mm"))]
    rows = [{"mesh.element_size": "1 mm", "absorbed_energy_J": 3.0,
             "absorbed_energy_per_ply_J": [1.0, 2.0]},
            {"mesh.element_size": "2 mm", "absorbed_energy_J": 4.0,
             "absorbed_energy_per_ply_J": [1.5, 2.5]}]
    written = study_plots(info, variants, rows, tmp_path)
    names = {p.name for p in written}
    assert {"absorbed_energy_J.png", "absorbed_energy_per_ply_J.png"} <= names
    assert all(p.stat().st_size > 0 for p in written)


def test_keep_older_code_keeps_runs_of_other_code_and_names_their_code(tmp_path: Path):
    """``--keep-older-code``: variants finished by other code (same case) are kept, a
    warning counts them and results.csv's code column names each run's source digest."""
    import csv

    import pytest

    from wovenimpact.errors import InputWarning
    from wovenimpact.provenance import digest_of
    from wovenimpact.studies.sweep import run_study

    write_case(tmp_path, end="8 us")
    study = tmp_path / "study.toml"
    study.write_text(STUDY.replace(', ["0 m/s", "0 m/s", "-60"]', ""))
    out = tmp_path / "out"
    for v in fake_finished_runs(study, out, ("stopped", "perforated")):
        path = out / "runs" / v.id / "summary.json"
        summary = json.loads(path.read_text())
        parts = {k: val for k, val in summary["provenance"].items() if k != "digest"}
        parts["source_digest"] = "0123456789abcdef"
        summary["provenance"] = {**parts, "digest": digest_of(parts)}
        path.write_text(json.dumps(summary))
    with pytest.warns(InputWarning, match="2 of 2 variants kept from runs made by other code"):
        run_study(study, out, keep_older_code=True)
    with (out / "results.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    assert [(r["outcome"], r["code"]) for r in rows] == [("stopped", "0123456789abcdef"),
                                                        ("perforated", "0123456789abcdef")]
