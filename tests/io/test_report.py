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


def test_a_containment_run_shows_its_fragments_exit_speed_and_thresholds_in_the_values_unit():
    """The second box of a containment run names the fragment's exit speed (not a residual
    velocity with a 0 m/s threshold); the energy error's threshold is in % like its value."""
    from wovenimpact.io.report import verdicts

    boxes = {v.key: v for v in verdicts({"outcome": "escaped", "energy_error_fraction": 4e-4,
                                         "fragment_exit_speed_m_per_s": 125.4})}
    speed = boxes["residual_velocity_m_per_s"]
    assert speed.name == "fragment exit speed" and speed.value == "125.40 m/s"
    assert speed.threshold == "none: contained" and speed.status == "fail"
    energy = boxes["energy_error_fraction"]
    assert energy.value == "0.04 %" and energy.threshold == "≤ 1 %" and energy.status == "pass"
    plate = {v.key: v for v in verdicts({"outcome": "perforated", "residual_velocity_m_per_s": 84.0})}
    assert plate["residual_velocity_m_per_s"].name == "residual velocity"
    assert plate["residual_velocity_m_per_s"].threshold == "0 m/s"
