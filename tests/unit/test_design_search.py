"""The ply search finds the threshold of any monotone outcome with few evaluations."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from wovenimpact.errors import InputError
from wovenimpact.studies.design import search_plies

ROOT = Path(__file__).resolve().parents[2]


@given(threshold=st.integers(1, 40), start=st.integers(1, 8))
def test_search_finds_the_smallest_stopping_pack(threshold, start):
    calls = []

    def stops(batch):
        calls.append(list(batch))
        return {n: n >= threshold for n in batch}

    n, seen = search_plies(stops, start=start)
    assert n == threshold
    assert seen[n] and (n == 1 or seen.get(n - 1) is False or n - 1 < 1 or n - 1 not in seen
                        or not seen[n - 1])
    assert n - 1 == 0 or (n - 1) in seen  # the answer is bracketed by runs
    assert len(calls) <= 12


@given(threshold=st.integers(1, 40), start=st.integers(1, 8))
def test_one_at_a_time_the_search_runs_no_pack_the_others_make_needless(threshold, start):
    """batch_size 1 (one worker): one pack per round; while doubling, no pack above the
    first that held; the same answer, bracketed, in at most 2 log2(40) + 2 rounds."""
    calls = []

    def stops(batch):
        calls.append(list(batch))
        return {n: n >= threshold for n in batch}

    n, seen = search_plies(stops, start=start, batch_size=1)
    assert n == threshold and all(len(c) == 1 for c in calls)
    assert n == 1 or seen[n - 1] is False
    first_held = start
    while first_held < threshold:
        first_held *= 2
    assert max(seen) == first_held  # nothing run past the first doubling that held
    assert len(calls) <= 2 * math.ceil(math.log2(40)) + 2


def test_the_batch_size_is_one_or_two():
    with pytest.raises(InputError, match="batch_size"):
        search_plies(lambda batch: {n: True for n in batch}, batch_size=3)


def test_search_gives_up_past_the_limit():
    with pytest.raises(InputError, match="no pack"):
        search_plies(lambda batch: {n: False for n in batch}, max_plies=16)


def test_a_larger_pack_that_perforates_is_reported():
    """Near a ballistic limit the simulated outcome need not be monotonic (seen before
    the contact-stiffness fix: 175 m/s FSP, 5 and 8 plies stopped it, 7 did not): the
    answer comes with a warning."""
    from wovenimpact.studies.design import monotonic_warning

    assert monotonic_warning(5, {1: False, 2: False, 4: False, 5: True, 8: True}) == ""
    text = monotonic_warning(5, {1: False, 2: False, 4: False, 5: True, 7: False, 8: True})
    assert text.startswith("7 plies did not stop the impactor although 5 did")


def _fake_runs(threshold: int, slow: dict[int, int]):
    """A stand-in for the runs: n plies stop the impactor iff n ≥ threshold, but a pack
    in ``slow`` needs that many doublings of the end time to be decided."""
    calls = []

    def run_batch(docs, base, dirs, workers):
        out = []
        for d, where in zip(docs, dirs):
            n = d["mesh"]["plies"]
            doublings = round(math.log2(float(d["run"]["end_time"].split()[0]) / 250.0))
            calls.append((n, where.rsplit("/", 1)[-1], d["run"]["end_time"]))
            if doublings < slow.get(n, 0):
                out.append("undecided")
            else:
                out.append("stopped" if n >= threshold else "perforated")
        return out

    return run_batch, calls


def test_design_runs_an_undecided_pack_again_with_twice_the_end_time(tmp_path, monkeypatch):
    """A pack that ends undecided is run once more with twice run.end_time (its own
    directory), the search goes on with the decided outcome and says so."""
    from wovenimpact.studies import design

    run_batch, calls = _fake_runs(threshold=3, slow={2: 1})
    monkeypatch.setattr(design, "_run_batch", run_batch)
    heard = []
    case = ROOT / "examples" / "plate_impact" / "plies1_100.toml"
    result = design.design_plies(case, tmp_path, log=heard.append)
    assert result["plies_to_stop"] == 3
    assert result["runs"]["2"] == "perforated"
    assert result["reruns"] == {"2": "undecided → perforated with twice the end time"}
    assert (2, "plies_2_end2x", "500.0 us") in calls
    assert len(heard) == 1 and heard[0].startswith("2 plies: undecided at run.end_time = 250 us")


def test_design_with_one_worker_runs_one_pack_a_round(tmp_path, monkeypatch):
    """--workers 1: every batch is a single pack, and no pack above the first that held
    is run (threshold 3 from 1 ply: 1, 2, 4, then 3 — never 8)."""
    from wovenimpact.studies import design

    run_batch, calls = _fake_runs(threshold=3, slow={})
    sizes = []
    monkeypatch.setattr(design, "_run_batch", lambda docs, base, dirs, workers: (
        sizes.append(len(docs)), run_batch(docs, base, dirs, workers))[1])
    result = design.design_plies(ROOT / "examples" / "plate_impact" / "plies1_100.toml",
                                 tmp_path, workers=1)
    assert result["plies_to_stop"] == 3 and set(sizes) == {1}
    assert [n for n, _, _ in calls] == [1, 2, 4, 3]


def test_design_stops_when_a_pack_is_undecided_even_twice_as_long(tmp_path, monkeypatch):
    from wovenimpact.studies import design

    run_batch, _ = _fake_runs(threshold=3, slow={2: 2})
    monkeypatch.setattr(design, "_run_batch", run_batch)
    with pytest.raises(InputError, match=r"2 plies: undecided even with twice run.end_time"):
        design.design_plies(ROOT / "examples" / "plate_impact" / "plies1_100.toml", tmp_path)


def test_a_failed_pack_stops_the_search_with_its_error_and_keeps_the_others(tmp_path,
                                                                             monkeypatch):
    """A pack whose run fails (here: 2 plies) does not crash the search with a traceback:
    the batch finishes, the error names the pack and its error.txt, and the packs that
    ran stay for the next search to reuse."""
    from wovenimpact.studies import design

    run_batch, calls = _fake_runs(threshold=3, slow={})

    def failing(docs, base, dirs, workers):
        out = run_batch(docs, base, dirs, workers)
        for d in dirs:  # as _run_one leaves it for a run that raised
            if d.endswith("plies_2"):
                Path(d).mkdir(parents=True, exist_ok=True)
                (Path(d) / "error.txt").write_text("SimulationError: element 7 inverted\n")
        return ["failed: SimulationError: element 7 inverted" if d.endswith("plies_2") else o
                for d, o in zip(dirs, out)]

    monkeypatch.setattr(design, "_run_batch", failing)
    with pytest.raises(InputError, match=r"2 plies: the run failed: SimulationError: element 7 "
                       r"inverted \(see .*plies_2/error.txt\)\. The packs that ran are kept"):
        design.design_plies(ROOT / "examples" / "plate_impact" / "plies1_100.toml", tmp_path)
    assert [c[0] for c in calls] == [1, 2]  # both packs of the first batch ran


def test_run_one_reports_a_failing_pack_instead_of_raising(tmp_path):
    """The worker function itself never raises: a pack that cannot run returns
    "failed: …" and leaves its error.txt."""
    from wovenimpact.spec.fields import read_toml
    from wovenimpact.studies.design import _case_with_plies, _run_one

    case = ROOT / "examples" / "plate_impact" / "plies1_100.toml"
    doc = _case_with_plies(read_toml(case, "case file"), 1)
    doc["mesh"]["element_size"] = "-1 mm"
    result = _run_one(doc, str(case.parent), str(tmp_path / "p"))
    assert result.startswith("failed: InputError") and "mesh.element_size" in result
    assert "mesh.element_size" in (tmp_path / "p" / "error.txt").read_text()


def test_design_on_a_containment_case_searches_the_casing_layers(tmp_path, monkeypatch):
    """On a containment case N is mesh.casing.layers, ``contained`` counts as held and
    ``escaped`` as through; the answer carries the casing mass of the answer's run
    (inner shell counted, as its summary reports it)."""
    import json

    from wovenimpact.studies import design

    def run_batch(docs, base, dirs, workers):
        out = []
        for d, where in zip(docs, dirs):
            n = d["mesh"]["casing"]["layers"]
            assert "plies" not in d["mesh"]
            Path(where).mkdir(parents=True, exist_ok=True)
            (Path(where) / "summary.json").write_text(json.dumps(
                {"casing_mass_kg": 1.0 + 0.1 * n, "casing_mass_per_area_kg_per_m2": 2.0 * n}))
            out.append("contained" if n >= 7 else "escaped")
        return out

    monkeypatch.setattr(design, "_run_batch", run_batch)
    case = ROOT / "examples" / "containment" / "hybrid_4.toml"
    result = design.design_plies(case, tmp_path)
    assert result["layers_to_contain"] == 7
    assert result["casing_mass_kg"] == pytest.approx(1.7)
    assert result["runs"]["6"] == "escaped" and result["runs"]["7"] == "contained"
    assert result["warning"] == ""
    text = design.monotonic_warning(7, {7: True, 9: False}, "layers", "contain the fragment")
    assert text.startswith("9 layers did not contain the fragment although 7 did")


def test_a_pack_that_failed_its_energy_check_is_named_with_its_summary(tmp_path):
    """A run that finished but failed its energy check leaves no error.txt: the message
    points at its summary.json instead of a file that does not exist."""
    from wovenimpact.studies.design import refuse_failed

    (tmp_path / "plies_8").mkdir()
    with pytest.raises(InputError, match=r"8 plies: the run failed: energy balance failed "
                       r"\(see .*plies_8/summary.json\)"):
        refuse_failed({4: "perforated", 8: "failed: energy balance failed"}, tmp_path)


@pytest.mark.parametrize("override, field", [("mesh.casing.layers=abc", "mesh.casing.layers"),
                                             ("mesh.casing.layers=0", "mesh.casing.layers")])
def test_a_bad_containment_case_is_refused_before_any_run(tmp_path, override, field):
    """The case is validated before the search starts: a clear error naming the key
    (a ValueError or KeyError traceback before), and nothing is run."""
    from wovenimpact.studies.design import design_plies

    case = ROOT / "examples" / "containment" / "metal_24.toml"
    with pytest.raises(InputError, match=field):
        design_plies(case, tmp_path / "out", overrides=[override])
    assert not list((tmp_path / "out").glob("plies_*"))


def test_an_undecided_pack_is_continued_from_its_checkpoint(tmp_path):
    """A pack still undecided at its end time is continued to twice the end time from
    the checkpoint it ended with (continue_from), not run again from t = 0; the
    continued run ends where a fresh run to that time ends, to the bit."""
    from tests.corpus.generate import IMPACT, _set
    from wovenimpact.studies.design import _longer, _run_one, continue_from

    doc = _set(IMPACT, "materials", {"kevlar": str(ROOT / "examples" / "materials"
                                                 / "kevlar_thesis.toml")})
    doc = _set(doc, "run", {"end_time": "3 us", "history_interval": "0.5 us"})
    base = str(tmp_path)
    assert _run_one(doc, base, str(tmp_path / "plies_2")) == "undecided"  # still in contact
    longer = _longer(doc)
    continue_from(tmp_path / "plies_2", tmp_path / "plies_2_end2x", longer)
    _run_one(longer, base, str(tmp_path / "plies_2_end2x"))
    _run_one(longer, base, str(tmp_path / "fresh"))
    continued, fresh = (json.loads((tmp_path / d / "summary.json").read_text())
                        for d in ("plies_2_end2x", "fresh"))
    assert continued["restarted_from_step"] > 0 and fresh["restarted_from_step"] is None
    for key in ("steps", "end_time_s", "internal_work_J", "total_kinetic_energy_J"):
        assert continued[key] == fresh[key], key
