"""report.html: verdicts consistent with summary.json, every plot inlined and decodable,
nothing fetched from elsewhere; the hook in a run, in a study and in the index."""

from __future__ import annotations

import json
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

import wovenimpact  # noqa: E402
from tests.io.report_page import check_run_page, read_page  # noqa: E402
from wovenimpact.errors import InputWarning  # noqa: E402
from wovenimpact.io.report import write_index, write_run_report, write_study_report  # noqa: E402
from wovenimpact.runs import run_case  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
TOUR = ROOT / "examples" / "cases" / "fabric_plate_impulse.toml"
SMALL = ['run.end_time="1 us"', 'mesh.side="10 mm"', 'mesh.element_size="1.88 mm"']


def fake_run(out: Path, **summary) -> Path:
    """A run directory with a summary.json and two small plots."""
    (out / "plots").mkdir(parents=True)
    for name in ("energy.png", "impactor.png"):
        fig, ax = plt.subplots(figsize=(2, 1.5))
        ax.plot([0, 1], [1, 0])
        fig.savefig(out / "plots" / name)
        plt.close(fig)
    (out / "summary.json").write_text(json.dumps({"case": "fake <case> & co", **summary}))
    return out


@pytest.mark.parametrize("summary", [
    dict(outcome="stopped", residual_velocity_m_per_s=0.0, rebound_velocity_m_per_s=23.3,
         energy_error_fraction=0.004, hourglass_fraction=0.05),
    dict(outcome="perforated", residual_velocity_m_per_s=84.0, rebound_velocity_m_per_s=0.0,
         energy_error_fraction=0.02, hourglass_fraction=0.25),
    dict(outcome="undecided", residual_velocity_m_per_s=12.0, energy_error_fraction=0.01),
    dict(energy_error_fraction=1e-5),  # no impactor, no hourglass key: n/a
    dict(energy_error_fraction=1e-5, max_displacement_m=0.004),  # its displacement instead
])
def test_verdicts_follow_the_summary_and_its_thresholds(tmp_path, summary):
    out = fake_run(tmp_path / "run", **summary)
    write_run_report(out, case_text='[case]\nname = "a <b> & \'c\'"\n', case_path="x.toml",
                     overrides=['run.end_time="5 us"'], model_digest="abc123")
    page = check_run_page(out)
    text = "".join(page.text)
    assert 'name = "a <b> & \'c\'"' in text  # the case, escaped in HTML, read back intact
    assert 'run.end_time="5 us"' in text and "abc123" in text
    assert wovenimpact.__version__ in text and "fake <case> & co" in text


def test_the_verdicts_come_first(tmp_path):
    out = fake_run(tmp_path / "run", outcome="stopped", energy_error_fraction=0.0)
    html = write_run_report(out).read_text()
    assert html.index('class="verdict') < html.index('id="summary"') < html.index("<img")


def test_a_run_writes_its_page_with_the_case_as_run(tmp_path):
    out = tmp_path / "out"
    with pytest.warns(InputWarning, match="clipped to the end time"):
        run_case(TOUR, out, overrides=SMALL)
    page = check_run_page(out)
    text = "".join(page.text)
    assert TOUR.read_text() in text  # the case file, verbatim
    assert all(o in text for o in SMALL)
    assert page.verdicts["energy_error_fraction"]["status"] == "pass"


def test_study_page_links_each_run_page_and_inlines_the_plots(tmp_path):
    out = tmp_path / "study"
    rows = []
    for vid, outcome in (("aaa", "stopped"), ("bbb", "perforated")):
        fake_run(out / "runs" / vid, outcome=outcome, energy_error_fraction=0.001)
        write_run_report(out / "runs" / vid)
        rows.append({"id": vid, "impactor.velocity": "100 m/s", "status": "done",
                     "error": "", "outcome": outcome})
    rows.append({"id": "ccc", "impactor.velocity": "9", "status": "failed",
                 "error": "no unit", "outcome": ""})
    fake_run(out, case="study")  # its plots/ are the comparison plots
    page = read_page(write_study_report(out, "velocity <study>", rows))
    assert page.links == ["runs/aaa/report.html", "runs/bbb/report.html"]
    assert all((out / link).exists() for link in page.links)
    assert len(page.images) == 2 and not page.external
    index = read_page(write_index(tmp_path, "all"))
    assert "study/report.html" in index.links and "study/runs/aaa/report.html" in index.links
    assert all((tmp_path / link).exists() for link in index.links)


def test_the_page_shows_the_summarys_case_digest_not_a_second_one(tmp_path):
    """One case digest per run: the provenance table repeats summary.json's (the resolved
    case) and its run digest; the digest of the case text is shown only when the summary
    has no provenance."""
    from wovenimpact.io.report import digest

    text = '[case]\nname = "x"\n'
    out = fake_run(tmp_path / "run", energy_error_fraction=0.0,
                   provenance={"case_digest": "7f24bebc00000000", "digest": "d1d2d3d4d5d6d7d8"})
    html = write_run_report(out, case_text=text, overrides=["a=1"]).read_text()
    provenance = html[html.index('id="provenance"'):]
    assert "7f24bebc00000000" in provenance and "d1d2d3d4d5d6d7d8" in provenance
    assert digest(text + "\n--set a=1") not in html
    bare = fake_run(tmp_path / "bare", energy_error_fraction=0.0)
    assert digest(text + "\n--set a=1") in write_run_report(bare, case_text=text,
                                                            overrides=["a=1"]).read_text()


CONTAINMENT = dict(
    outcome="escaped", contained=False, fragment_exit_speed_m_per_s=125.4,
    fragment_speed_at_end_m_per_s=125.4, fragment_exit_speed_settled=False,
    fragment_mass_kg=0.229, fragment_initial_speed_m_per_s=150.2, max_bulge_m=0.0412,
    casing_absorbed_energy_J=812.5, absorbed_energy_per_layer_J=[300.0, 250.0, 150.0, 100.0, 12.5],
    held_energy_per_layer_J=[10.0, 5.0, 4.0, 3.0, 1.0],
    absorbed_energy_per_material_J={"aluminium": 300.0, "kevlar": 512.5},
    casing_mass_kg=1.9, casing_mass_per_area_kg_per_m2=8.1, casing_layers=5,
    stopped_when_decided=None, energy_error_fraction=4e-4, energy_tolerance=0.01,
    hourglass_fraction=0.03, end_time_s=0.0025, first_time_step_s=2.1e-7,
    element_size_m=0.01, blade_element_size_m=0.005, summary_version=4,
    mesh_verdict={"kevlar": {"element_length_mm": [10.0, 10.0], "reference_length_mm": 0.6,
                             "calibrated_range_mm": None, "judged_on": "eroded elements",
                             "verdict": "not regularised", "striking_radius_mm": 2.49,
                             "striker_resolved": False, "ok": False}})


def boxes_of(page) -> dict[str, str]:
    return {k: v["text"] for k, v in page.verdicts.items()}


def test_a_containment_page_answers_in_its_own_terms_and_says_how_far_to_trust_it(tmp_path):
    """A containment summary gets its own boxes — outcome, the fragment's exit speed, the
    energy the casing absorbed, the largest bulge, in m/s, J and mm, no residual velocity
    — and a trust block with the element sizes and the --set overrides, the energy error
    with its threshold in %, and the exit speed that had not settled."""
    out = fake_run(tmp_path / "run", **CONTAINMENT)
    write_run_report(out, case_text='[case]\nname = "ring"\n',
                     overrides=['mesh.element_size="10 mm"'])
    page = check_run_page(out)
    boxes = boxes_of(page)
    assert "residual_velocity_m_per_s" not in boxes
    speed = boxes["fragment_exit_speed_m_per_s"]
    assert "fragment exit speed (threshold 0 m/s: contained)" in speed
    assert "125.4 m/s" in speed and "released at 150.2 m/s" in speed
    # 812.5 J of ½ 0.229 kg (150.2 m/s)² = 2583 J
    absorbed = boxes["casing_absorbed_energy_J"]
    assert "812.5 J" in absorbed
    assert "31 % of the fragment's ½ m v² at release (2583 J)" in absorbed
    assert "41.2 mm" in boxes["max_bulge_m"]
    assert page.verdicts["outcome"]["status"] == "fail"
    assert "(threshold contained)" in boxes["outcome"]
    energy = boxes["energy_error_fraction"]
    assert "0.04 %" in energy and "≤ 1 %" in energy
    assert "exit speed still changing" in boxes["outcome_settled"]
    assert "none (no mass scaling)" in boxes["added_mass_fraction"]
    html = (out / "report.html").read_text()
    trust = html[html.index('id="trust"'):html.index('id="summary"')]
    assert "casing 10 mm, blade 5 mm" in trust
    assert 'mesh.element_size="10 mm"' in trust.replace("&quot;", '"')
    assert "not regularised" in trust  # the mesh verdict
    # the summary in engineering units, grouped
    assert page.summary_rows["max_bulge_m"] == "answer"
    assert page.summary_rows["casing_mass_per_area_kg_per_m2"] == "structure"
    assert page.summary_rows["element_size_m"] == "run"
    summary_html = html[html.index('id="summary"'):html.index('id="plots"')]
    assert "Casing and fragment" in summary_html and "kg/m²" in summary_html
    row = summary_html[summary_html.index('data-key="max_bulge_m"'):]
    assert ">41.2<" in row[:row.index("</tr>")] and ">mm<" in row[:row.index("</tr>")]
    row = summary_html[summary_html.index('data-key="end_time_s"'):]
    assert ">2.5<" in row[:row.index("</tr>")] and ">ms<" in row[:row.index("</tr>")]


@pytest.mark.parametrize("summary, value, status", [
    (dict(outcome="stopped", residual_velocity_m_per_s=0.0, rebound_velocity_m_per_s=23.3,
          initial_velocity_m_per_s=120.0), "0.0 m/s, rebound 23.3 m/s", "pass"),
    (dict(outcome="perforated", residual_velocity_m_per_s=84.0, rebound_velocity_m_per_s=0.0,
          initial_velocity_m_per_s=120.0), "84.0 m/s", "fail"),
])
def test_a_plate_page_gives_the_residual_velocity_or_the_rebound(tmp_path, summary, value,
                                                                 status):
    out = fake_run(tmp_path / "run", **summary, absorbed_energy_J=37.6,
                   initial_impactor_kinetic_energy_J=75.2, max_deflection_m=0.0123,
                   energy_error_fraction=0.001, element_size_m=0.002)
    write_run_report(out)
    page = check_run_page(out)
    boxes = boxes_of(page)
    assert "fragment_exit_speed_m_per_s" not in boxes and "max_bulge_m" not in boxes
    assert value in boxes["residual_velocity_m_per_s"]
    assert "struck at 120.0 m/s" in boxes["residual_velocity_m_per_s"]
    assert page.verdicts["residual_velocity_m_per_s"]["status"] == status
    assert "(threshold stopped)" in boxes["outcome"]
    assert "37.6 J" in boxes["absorbed_energy_J"]
    assert "50 % of the impactor's kinetic energy (75.2 J)" in boxes["absorbed_energy_J"]
    assert "12.3 mm" in boxes["max_deflection_m"]
    assert page.verdicts["outcome_settled"]["status"] == "pass"
    html = (out / "report.html").read_text()
    trust = html[html.index('id="trust"'):html.index('id="summary"')]
    assert ">2 mm<" in trust and "none: the case as written" in trust


def test_an_unknown_key_lands_in_other_and_internals_stay_out_of_the_summary(tmp_path):
    out = fake_run(tmp_path / "run", outcome="undecided", residual_velocity_m_per_s=12.0,
                   my_new_metric=3.5, summary_version=4,
                   provenance={"case_digest": "7f24bebc00000000", "digest": "d1d2"})
    html = write_run_report(out).read_text()
    page = check_run_page(out)
    assert page.summary_rows["my_new_metric"] == "other"
    assert "summary_version" not in page.summary_rows and "provenance" not in page.summary_rows
    provenance = html[html.index('id="provenance"'):]
    assert "summary version" in provenance  # shown there instead
    assert page.verdicts["outcome_settled"]["status"] == "fail"  # undecided: run longer


def test_trust_thresholds_are_in_the_unit_of_their_values():
    """Hourglass share and added mass in % beside thresholds in %; too much added mass is
    red, none at all (no mass scaling) green."""
    from wovenimpact.io.report import trust_boxes

    boxes = {v.key: v for v in trust_boxes({"hourglass_fraction": 0.125,
                                            "added_mass_fraction": 0.035,
                                            "added_mass_kg": 0.0121})}
    assert boxes["hourglass_fraction"].value == "12.5 %"
    assert boxes["hourglass_fraction"].threshold == "≤ 10 %"
    assert boxes["hourglass_fraction"].status == "fail"
    added = boxes["added_mass_fraction"]
    assert added.value == "3.5 % of the model's mass" and added.threshold == "≤ 2 %"
    assert added.status == "fail" and added.note == "12.1 g"
    assert {v.key: v for v in trust_boxes({})}["added_mass_fraction"].status == "pass"


def test_the_trust_block_comes_before_the_grouped_summary(tmp_path):
    out = fake_run(tmp_path / "run", **CONTAINMENT)
    html = write_run_report(out).read_text()
    assert (html.index('data-key="outcome"') < html.index('<section id="trust">')
            < html.index('data-key="energy_error_fraction"') < html.index('id="summary"')
            < html.index('id="summary-answer"') < html.index("<img"))


def test_a_containment_run_shows_its_fragments_exit_speed_and_thresholds_in_the_values_unit():
    """The second box of a containment run names the fragment's exit speed (not a residual
    velocity with a 0 m/s threshold); the energy error's threshold is in % like its value."""
    from wovenimpact.io.report import verdicts

    boxes = {v.key: v for v in verdicts({"outcome": "escaped", "energy_error_fraction": 4e-4,
                                         "fragment_exit_speed_m_per_s": 125.4})}
    speed = boxes["fragment_exit_speed_m_per_s"]
    assert speed.name == "fragment exit speed" and speed.value == "125.4 m/s"
    assert speed.threshold == "0 m/s: contained" and speed.status == "fail"
    assert "residual_velocity_m_per_s" not in boxes
    energy = boxes["energy_error_fraction"]
    assert energy.value == "0.04 %" and energy.threshold == "≤ 1 %" and energy.status == "pass"
    undecided = {v.key: v for v in verdicts({"outcome": "undecided",
                                             "fragment_exit_speed_m_per_s": None})}
    assert undecided["fragment_exit_speed_m_per_s"].value == "none: undecided"
    assert undecided["fragment_exit_speed_m_per_s"].status == "na"
    plate = {v.key: v for v in verdicts({"outcome": "perforated",
                                         "residual_velocity_m_per_s": 84.0})}
    assert plate["residual_velocity_m_per_s"].name == "residual velocity"
    assert plate["residual_velocity_m_per_s"].threshold == "0 m/s"
    assert "fragment_exit_speed_m_per_s" not in plate


def test_every_summary_key_the_code_writes_has_a_group_a_label_and_a_meaning():
    """A key added to results/summary.py's lists without a line in io/summary_keys.py
    would land in "other" with no meaning: this names it."""
    from wovenimpact.io.summary_keys import INTERNAL, KEYS
    from wovenimpact.results.summary import (
        COMMON_SUMMARY_KEYS,
        CONTAINMENT_SUMMARY_KEYS,
        IMPACT_SUMMARY_KEYS,
    )

    written = set(COMMON_SUMMARY_KEYS + IMPACT_SUMMARY_KEYS + CONTAINMENT_SUMMARY_KEYS)
    assert sorted(written - set(KEYS) - set(INTERNAL)) == []
    assert [k for k, v in KEYS.items() if not (v.label and v.group and v.meaning)] == []
