"""reports/containment_validation: the containment report from ladder results (synthetic
rows, no runs): regression over escaped runs only, the fewest layers that contained, the
mass table with the inner shell counted, undecided runs named and left out."""

from __future__ import annotations

import pytest

from wovenimpact.reports import containment_validation as cv


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
    assert res["most_escaped_below"] == 30
    assert res["undecided"] == [20]
    assert res["mass_per_area"](36) == pytest.approx(2.7 + 0.5 * 36)
    assert res["regression_points"] == 5  # 4, 8, 12, 16, 30 escaped


def test_a_regression_through_exactly_three_points_says_so(tmp_path):
    """With three escaped N the quadratic passes through them: R² = 1 by construction,
    and the report says so instead of letting it read as a good fit."""
    rows = [_row(n, "escaped", 150.0 - 5.0 * n - 0.1 * n * n, 2.7 + 0.5 * n) for n in (4, 8, 12)]
    rows.append(_row(24, "contained", 0.0, 2.7 + 0.5 * 24))
    res = cv.ladder_result(rows)
    assert res["regression_points"] == 3
    assert res["regression"].r2 == pytest.approx(1.0, abs=1e-12)
    lines, _ = cv.ladder_lines("containment_metal", "Metal", "layers", {}, "note", rows,
                               tmp_path)
    assert any("R² = 1 by construction" in line for line in lines)
    rows.append(_row(16, "escaped", 150.0 - 5.0 * 16 - 0.1 * 256 + 3.0, 2.7 + 0.5 * 16))
    lines, _ = cv.ladder_lines("containment_metal", "Metal", "layers", {}, "note", rows,
                               tmp_path)
    assert not any("by construction" in line for line in lines)


def test_an_escape_whose_speed_was_still_falling_stays_out_of_the_regression():
    """A run that escaped but ended with its fragment still losing speed
    (fragment_exit_speed_settled false, as a bool or as results.csv text) has no known
    exit speed: the regression is that of the other escaped runs; it still counts as
    having let the fragment through."""
    rows = ladder()
    base = cv.ladder_result(rows)["regression"].coefficients
    for flag in (False, "False"):
        extra = {**_row(6, "escaped", 300.0, 5.7), cv.SETTLED: flag}
        res = cv.ladder_result(rows + [extra])
        assert res["regression"].coefficients == pytest.approx(base, rel=1e-9)
        assert cv.unsettled(extra)
    assert not cv.unsettled({**extra, cv.SETTLED: True})
    assert not cv.unsettled(_row(6, "escaped", 120.0, 5.7))  # an older row, no column
    fewer = [r for r in rows if r[cv.KEY] != 30]  # then 16 is the last escape below 36
    assert cv.ladder_result(fewer + [{**_row(33, "escaped", 9.0, 19.2),
                                      cv.SETTLED: False}])["most_escaped_below"] == 33


def test_section_tables_the_ladders_names_undecided_and_counts_the_inner_shell(tmp_path,
                                                                               monkeypatch):
    ladders = {"containment_hybrid": ladder(), "containment_metal": ladder(0.0, -5.0, 130.0,
                                                                           0.0, 1.35)}
    monkeypatch.setattr("wovenimpact.studies.sweep.run_study",
                        lambda path, out, workers=2, overrides=(): ladders[path.stem])
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
                        lambda work, figures, workers=2, log=None, overrides=(), runs=():
                        ["## section", "body"])
    report = tmp_path / "docs" / "validation_containment.md"
    result = CliRunner().invoke(app, ["validate", "--containment", "--work",
                                      str(tmp_path / "w"), "--report", str(report)])
    assert result.exit_code == 0, result.output
    text = report.read_text()
    assert text.startswith("# Validation: fan-blade containment (thesis chapter 8)")
    assert "## section\nbody\n" in text


def _run_dir(root, name, layers, materials, outcome, exit_speed, per_area, digest="abc"):
    """A finished containment run's folder: its summary.json, as
    results.summary.summarise writes it."""
    import json

    d = root / name
    d.mkdir(parents=True)
    summary = {**_row(0, outcome, exit_speed, per_area), "casing_layers": layers,
               "absorbed_energy_per_material_J": {m: 100.0 for m in materials},
               "elements": 1000 * layers, "provenance": {"source_digest": digest}}
    for k in ("id", "status", cv.KEY):
        summary.pop(k)
    (d / "summary.json").write_text(json.dumps(summary))
    return d


def test_a_report_from_given_runs_sorts_them_into_ladders_and_names_what_is_unfinished(
        tmp_path):
    """``--runs``: a casing of aluminium and fabric is a hybrid one of layers − 1 plies,
    one of aluminium alone an all-metal one of its layers; a run with checkpoints and no
    summary is named with the time it reached and left out; the code digests are said;
    a folder that is not a containment run is refused."""
    from wovenimpact.errors import InputError
    from wovenimpact.io.history import History

    runs = tmp_path / "runs"
    _run_dir(runs, "r4", 5, ("aluminium", "fabric"), "escaped", 104.8, 4.68)
    _run_dir(runs, "r10", 11, ("aluminium", "fabric"), "contained", 0.0, 7.53, digest="def")
    _run_dir(runs, "m4", 4, ("aluminium",), "escaped", 120.0, 5.4)
    cut = runs / "r8"
    (cut / "checkpoints").mkdir(parents=True)
    (cut / "checkpoints" / "checkpoint_000000100.npz").write_bytes(b"")
    h = History(["time_s", "step"])
    h.append({"time_s": 0.0, "step": 0})
    h.append({"time_s": 2.75e-3, "step": 100})
    h.write_csv(cut / "history.csv")
    ladders, unfinished = cv.rows_from_runs([runs])
    assert [r[cv.KEY] for r in ladders["containment_hybrid"]] == [4, 10]
    assert [r[cv.KEY] for r in ladders["containment_metal"]] == [4]
    assert unfinished == [f"{cut} (stopped at 2.75 ms)"]
    text = "\n".join(cv.containment_section(tmp_path / "w", tmp_path / "f", runs=[runs]))
    assert "| 4 | escaped | 104.8 | 133.0 |" in text and "| 10 | contained |" in text
    assert "| 5000 |" in text  # the 4-ply run's elements
    assert "`abc`, `def`" in text and "stopped at 2.75 ms" in text
    assert ("Fewest plies run that contained the fragment: **10**; 4 let it through and "
            "5–9 are not decided by a run: by runs the answer lies between 5 and 10 plies."
            in text)
    assert not (tmp_path / "w").exists()  # nothing ran
    # one layer count between the last escape and the first containment
    _run_dir(runs, "m8", 8, ("aluminium",), "escaped", 36.3, 11.1)
    _run_dir(runs, "m10", 10, ("aluminium",), "contained", 0.0, 13.9)
    text = "\n".join(cv.containment_section(tmp_path / "w", tmp_path / "f", runs=[runs]))
    assert ("Fewest layers run that contained the fragment: **10**; 8 let it through and 9 "
            "is not decided by a run: by runs the answer is 9 or 10 layers." in text)
    (runs / "plate").mkdir()
    (runs / "plate" / "summary.json").write_text('{"outcome": "stopped"}')
    with pytest.raises(InputError, match="not a containment run"):
        cv.rows_from_runs([runs])


def test_two_runs_of_one_ladder_at_the_same_count_are_refused(tmp_path):
    """``--runs`` given a sensitivity run beside the ladder's (the same 4 layers, another
    blade) would put two points at one N in the table and the regression: refused,
    naming both folders."""
    from wovenimpact.errors import InputError

    runs = tmp_path / "runs"
    _run_dir(runs, "m4", 4, ("aluminium",), "escaped", 96.7, 5.6)
    _run_dir(runs, "m8", 8, ("aluminium",), "escaped", 36.3, 11.1)
    assert [r[cv.KEY] for r in cv.rows_from_runs([runs])[0]["containment_metal"]] == [4, 8]
    _run_dir(tmp_path / "sens", "m4_stagger45", 4, ("aluminium",), "escaped", 122.0, 5.6)
    with pytest.raises(InputError, match=r"two finished runs of the containment_metal "
                       r"ladder at 4 layers: .*m4 and .*m4_stagger45"):
        cv.rows_from_runs([runs, tmp_path / "sens"])


def test_validate_containment_from_runs_names_its_command_and_set_needs_containment(tmp_path):
    """The report made from ``--runs`` says the command that made it; ``--set`` or
    ``--runs`` without ``--containment`` is refused (the chapter-7 studies run their own
    cases), before anything runs."""
    from typer.testing import CliRunner

    from wovenimpact.cli import app

    runs = tmp_path / "runs"
    _run_dir(runs, "r4", 5, ("aluminium", "fabric"), "escaped", 104.8, 4.68)
    report = tmp_path / "docs" / "validation_containment.md"
    result = CliRunner().invoke(app, ["validate", "--containment", "--runs", str(runs),
                                      "--report", str(report)])
    assert result.exit_code == 0, result.output
    assert f"`wovenimpact validate --containment --runs {runs}`" in report.read_text()
    bad = CliRunner().invoke(app, ["validate", "--set", "mesh.element_size=7 mm",
                                   "--work", str(tmp_path / "w")])
    assert bad.exit_code != 0 and "--set goes with --containment" in bad.output
    assert not (tmp_path / "w").exists()


def test_runs_that_contradict_the_regression_or_each_other_are_named(tmp_path):
    """The metal ladder's case: the regression answered 14 layers although the 14-layer
    run let the fragment out; and an escape above the fewest layers that contained is
    a non-monotonic outcome. Both are said beside the answers."""
    rows = [_row(n, "escaped", 130.0 + 4.0 * n - n * n, 2.8 * n) for n in (4, 8, 10, 12)]
    rows += [_row(14, "escaped", 4.4, 39.0), _row(15, "contained", 0.0, 41.7),
             _row(16, "escaped", 1.0, 44.5), _row(18, "contained", 0.0, 50.0)]
    reg = cv.ladder_result(rows)["regression"]
    assert reg.plies_to_stop <= 16
    lines, _ = cv.ladder_lines("containment_metal", "Metal", "layers", {}, "note", rows,
                               tmp_path)
    text = "\n".join(lines)
    assert "The runs contradict the regression" in text and "the runs' answer stands" in text
    assert "Not monotonic: 16 layers let the fragment out although 15 contained it" in text
    clean = [r for r in rows if r[cv.KEY] not in (14, 16)]
    text = "\n".join(cv.ladder_lines("containment_metal", "Metal", "layers", {}, "note", clean,
                                     tmp_path)[0])
    assert "contradict" not in text and "Not monotonic" not in text


def test_runs_striking_with_another_fragment_are_not_one_ladder(tmp_path):
    """A run on another mesh strikes with another fragment (the released row is one
    element wide): given beside the ladder's runs it is refused, naming both; runs with
    one fragment pass."""
    import json
    import shutil

    from wovenimpact.errors import InputError

    runs = tmp_path / "runs"
    for name, layers, mass in (("m4", 4, 0.2289), ("m8", 8, 0.2289), ("m12", 12, 0.2243)):
        d = _run_dir(runs, name, layers, ("aluminium",), "escaped", 100.0 - 5 * layers, 2.8)
        summary = json.loads((d / "summary.json").read_text())
        summary.update(fragment_mass_kg=mass, fragment_initial_speed_m_per_s=150.4)
        (d / "summary.json").write_text(json.dumps(summary))
    with pytest.raises(InputError, match=r"mixes fragments: .*m12.* 0.2243 kg"):
        cv.rows_from_runs([runs])
    shutil.rmtree(runs / "m12")
    assert [r[cv.KEY] for r in cv.rows_from_runs([runs])[0]["containment_metal"]] == [4, 8]
