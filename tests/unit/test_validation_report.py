"""The pieces of docs/validation.md that judge acceptance: full-plate cases, the
convergence verdicts and the hourglass spread (synthetic summaries, no runs)."""

from wovenimpact.reports.validation import ROOT, commentary, full_plate, spread_line
from wovenimpact.spec.case import case_from_dict
from wovenimpact.spec.fields import read_toml


def test_full_plate_drops_only_the_symmetry_conditions_and_validates():
    path = ROOT / "examples" / "plate_impact" / "plies4_120.toml"
    doc = read_toml(path, "case file")
    full = full_plate(doc)
    assert doc["mesh"]["quarter"] is True  # the input is not changed
    assert full["mesh"]["quarter"] is False
    assert [b["type"] for b in full["boundary"]] == ["clamped"]
    spec = case_from_dict(full, source="full plate")
    assert spec.mesh.quarter is False


def _row(variant, residual, rebound, delta_residual=0.0, delta_rebound=0.0):
    return {"case": "c", "changes": {}, "variant": variant, "outcome": "perforated",
            "residual_velocity_m_per_s": residual, "rebound_velocity_m_per_s": rebound,
            "delta_residual": delta_residual, "delta_rebound": delta_rebound}


CASES = {"plies1_100": {"outcome": "stopped", "perforated": False,
                        "initial_total_kinetic_energy_J": 5.5}}


def test_convergence_verdicts_follow_the_acceptance_limits():
    # perforating: 100 m/s residual; mesh moves 4.9 (within 5 %), symmetry 2.1 (outside 2 %)
    rows = [_row("ref", 100.0, 0.0), _row("fine", 104.9, 0.0, 4.9),
            _row("full", 97.9, 0.0, -2.1)]
    text = commentary(CASES, rows)[1]
    assert "residual velocity (100.00 m/s) moves by 4.90 m/s" in text
    assert "(within 5 % or 2 m/s)" in text and "(outside 2 %)" in text
    # stopped: the rebound is judged; 10 m/s rebound, mesh 2.5 m/s > max(0.5, 2)
    rows = [_row("ref", 0.0, 10.0), _row("fine", 0.0, 12.5, 0.0, 2.5),
            _row("full", 0.0, 10.1, 0.0, 0.1)]
    text = commentary(CASES, rows)[1]
    assert "rebound velocity (10.00 m/s) moves by 2.50 m/s" in text
    assert "(outside 5 % or 2 m/s)" in text and "(within 2 %)" in text


def test_spread_line_reports_the_extremes():
    rows = [{"status": "done", "rebound_velocity_m_per_s": v, "absorbed_energy_J": e,
             "hourglass_fraction": h / 4.0}
            for v, e, h in ((23.0, 7.6, 1.0), (24.5, 7.5, 2.0))]
    rows.append({"status": "failed"})
    line = spread_line(rows)
    assert "2 runs" in line and "23.00–24.50 m/s" in line and "7.500–7.600 J" in line
    assert "from 25.0% to 50.0%" in line


def test_the_early_impulse_verdict_follows_the_10_percent_limit():
    rows = [_row("ref", 100.0, 0.0), _row("fine", 104.0, 0.0, 4.0),
            _row("full", 100.5, 0.0, 0.5)]
    rows[1]["delta_impulse"] = 0.099
    assert "moves by +9.9% from the 0.94 mm" in commentary(CASES, rows)[1]
    assert "(within 10 %)" in commentary(CASES, rows)[1]
    rows[1]["delta_impulse"] = -0.101
    assert "(outside 10 %)" in commentary(CASES, rows)[1]


def test_early_impulse_is_the_momentum_lost_by_the_window_end(tmp_path):
    """A body of 2 g slowed linearly from 100 to 60 m/s over 4 µs, sampled every 2 µs:
    the momentum lost by 3 µs is m·30 m/s = 0.06 N·s, exactly, between samples; the first
    contact is the first sample with a force."""
    import json

    from wovenimpact.reports.validation import early_impulse, first_contact_time

    (tmp_path / "history.csv").write_text(
        "time_s,impactor_velocity_m_per_s,contact_force_full_N\n"
        "0.0,100.0,0.0\n2e-6,80.0,20000.0\n4e-6,60.0,20000.0\n")
    (tmp_path / "summary.json").write_text(json.dumps(
        {"initial_velocity_m_per_s": 100.0, "initial_impactor_kinetic_energy_J": 10.0}))
    assert abs(early_impulse(tmp_path, 3e-6) - 0.06) < 1e-12
    assert first_contact_time(tmp_path) == 2e-6


def test_undecided_runs_get_no_verdict_and_are_named():
    """Only decided runs are judged: an undecided convergence run and an undecided case
    are named as such instead of entering the comparison."""
    rows = [_row("ref", 100.0, 0.0), _row("fine", 0.0, 0.0, -100.0),
            _row("full", 99.0, 0.0, -1.0)]
    for r in rows:
        r["outcome"] = "perforated"
    rows[1]["outcome"] = "undecided"
    cases = {**CASES, "plies2_100": {"outcome": "undecided", "perforated": False,
                                     "initial_total_kinetic_energy_J": 5.5}}
    text = commentary(cases, rows)
    assert any("no convergence verdict — fine undecided" in line for line in text)
    assert not any("moves by" in line for line in text)
    assert any(line.startswith("- Not decided at their end time") and "plies2_100 (undecided)"
               in line for line in text)


def test_a_summary_of_an_older_rule_is_not_taken_as_finished(tmp_path):
    """A variant's summary written before issue 9's outcome rule (no summary_version), or
    of the current version without the provenance digest of issue 12, is run again; one
    of the current version with the case's digest is kept."""
    import json

    from wovenimpact.provenance import provenance
    from wovenimpact.results.summary import SUMMARY_VERSION
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.spec.fields import read_toml
    from wovenimpact.studies.sweep import finished

    case = ROOT / "examples" / "plate_impact" / "plies1_100.toml"
    doc = read_toml(case, "case file")
    (tmp_path / "parameters.json").write_text(json.dumps({"a": 1}))
    (tmp_path / "summary.json").write_text(json.dumps({"outcome": "perforated"}))
    assert finished(tmp_path, {"a": 1}, doc, case.parent) == (
        None, "its summary was written by an older wovenimpact (summary_version)")
    current = {"outcome": "perforated", "summary_version": SUMMARY_VERSION}
    (tmp_path / "summary.json").write_text(json.dumps(current))
    done, why = finished(tmp_path, {"a": 1}, doc, case.parent)
    assert done is None and "no provenance digest" in why
    current["provenance"] = provenance(case_from_dict(doc), case.parent)
    (tmp_path / "summary.json").write_text(json.dumps(current))
    assert finished(tmp_path, {"a": 1}, doc, case.parent)[0]["outcome"] == "perforated"


def test_a_run_of_other_code_is_kept_only_when_asked_and_only_for_the_same_case(tmp_path):
    """A finished variant whose summary names other code is run again by default
    ("the code" changed); with older_code (``sweep --keep-older-code``) it is kept, but
    not if its case changed too."""
    import json

    from wovenimpact.provenance import digest_of, provenance
    from wovenimpact.results.summary import SUMMARY_VERSION
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.spec.fields import read_toml
    from wovenimpact.studies.sweep import finished

    case = ROOT / "examples" / "plate_impact" / "plies1_100.toml"
    doc = read_toml(case, "case file")
    prov = provenance(case_from_dict(doc), case.parent)
    (tmp_path / "parameters.json").write_text(json.dumps({"a": 1}))

    def write(**changes):
        parts = {k: v for k, v in prov.items() if k != "digest"} | changes
        summary = {"outcome": "stopped", "summary_version": SUMMARY_VERSION,
                   "provenance": {**parts, "digest": digest_of(parts)}}
        (tmp_path / "summary.json").write_text(json.dumps(summary))

    write(source_digest="0123456789abcdef")
    done, why = finished(tmp_path, {"a": 1}, doc, case.parent)
    assert done is None and why == "changed since it ran: the code"
    assert finished(tmp_path, {"a": 1}, doc, case.parent, older_code=True)[0]["outcome"] == "stopped"
    write(source_digest="0123456789abcdef", case_digest="fedcba9876543210")
    done, why = finished(tmp_path, {"a": 1}, doc, case.parent, older_code=True)
    assert done is None and why == "changed since it ran: the case, the code"


def test_a_failed_design_search_is_reported_not_fatal(tmp_path, monkeypatch):
    """A pack whose run fails (e.g. its energy check) stops the design search; validate
    writes that into the report instead of losing the whole report."""
    from wovenimpact.errors import InputError
    from wovenimpact.reports import validation
    from wovenimpact.studies import design

    def failing(*args, **kwargs):
        raise InputError("8 plies: the run failed: energy balance failed")

    monkeypatch.setattr(design, "design_plies", failing)
    text = "\n".join(validation.design_lines("design_175", tmp_path, workers=1))
    assert "## design_175: plies to stop the impactor, by runs" in text
    assert "**No answer: the search stopped.** 8 plies: the run failed" in text


def test_a_report_of_some_studies_runs_only_those(tmp_path, monkeypatch):
    """validate --study: the report holds the asked studies' sections alone; no example
    case, convergence run or metal section is run (each would raise here)."""
    import wovenimpact.runs
    from wovenimpact.reports import validation

    def refuse(*args, **kwargs):
        raise AssertionError("a run outside the asked studies")

    monkeypatch.setattr(wovenimpact.runs, "reused_or_run", refuse)
    monkeypatch.setattr(validation, "convergence_runs", refuse)
    monkeypatch.setattr(validation, "metal_section", refuse)
    monkeypatch.setattr(validation, "smith_strip_lines", refuse)
    asked = []
    monkeypatch.setattr(validation, "study_sections", lambda studies, work, figures, workers,
                        log: (asked.extend(studies) or [f"## {s}" for s in studies], {}))
    report = validation.run_validation(tmp_path / "w", tmp_path / "w" / "validation.md",
                                       studies=("mesh_ring_v0",), workers=1,
                                       studies_only=True)
    text = report.read_text()
    assert asked == ["mesh_ring_v0"]
    assert text.startswith("# Validation: selected studies") and "## mesh_ring_v0" in text
    assert "## Example cases" not in text and "## Commentary" not in text
