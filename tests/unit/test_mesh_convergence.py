"""Observed order, extrapolation and GCI of a mesh study (studies/convergence.py; Celik et
al. 2008): exact on answers that follow φ = φ_ext + C h^p, and no error bar where the
answers oscillate, diverge or converge at an order no element has."""

import csv
import json

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from typer.testing import CliRunner

from wovenimpact.cli import app
from wovenimpact.errors import InputError
from wovenimpact.studies.convergence import SAFETY_FACTOR, mesh_convergence, triple


@settings(max_examples=60, deadline=None)
@given(p=st.floats(0.6, 3.5), phi0=st.floats(-500, 500), c=st.floats(0.1, 50),
       sign=st.sampled_from([-1.0, 1.0]),
       h=st.lists(st.floats(0.5, 20), min_size=3, max_size=3, unique=True))
def test_a_power_law_gives_back_its_order_and_limit(p, phi0, c, sign, h):
    h = sorted(h)
    if h[1] / h[0] < 1.1 or h[2] / h[1] < 1.1:
        return  # sizes closer than 10 % carry no order to round-off
    values = [phi0 + sign * c * x ** p for x in h]
    t = triple(h, values)
    assert t.verdict == "monotone"
    assert t.order == pytest.approx(p, rel=1e-6)
    assert t.extrapolated == pytest.approx(phi0, abs=1e-6 * (abs(phi0) + c * h[2] ** p))


def test_the_gci_is_celik_s_band_on_the_finest_pair():
    h, p = (2.0, 3.0, 5.0), 1.0
    values = [10.0 + 4.0 * x for x in h]  # 18, 22, 30
    t = triple(h, values)
    r = 1.5 ** p
    assert t.gci_fine == pytest.approx(SAFETY_FACTOR * abs((18 - 22) / 18) / (r - 1))
    assert t.gci_fine * t.values[0] >= abs(t.values[0] - t.extrapolated)


def test_answers_that_go_up_then_down_get_no_order():
    t = triple([3, 4, 5], [100.0, 104.0, 101.0])
    assert t.verdict == "oscillatory" and t.extrapolated is None and t.gci_fine is None


def test_a_finer_step_larger_than_any_order_allows_is_diverging():
    # equal ratios: the finest step (10) is larger than the coarser one (2)
    t = triple([1, 2, 4], [100.0, 110.0, 112.0])
    assert t.verdict == "diverging" and t.order < 0 and t.extrapolated is None


def test_an_order_no_element_has_is_not_asymptotic():
    h = [3.0, 4.0, 7.0]
    t = triple(h, [1.0 + x ** 0.3 for x in h])
    assert t.verdict == "not asymptotic"
    assert t.order == pytest.approx(0.3, rel=1e-6)
    assert t.extrapolated is None


def test_every_consecutive_triple_finest_first():
    h = [7.0, 3.0, 5.0, 4.0]
    ts = mesh_convergence(h, [5.0 + x for x in h])
    assert [t.sizes for t in ts] == [(3.0, 4.0, 5.0), (4.0, 5.0, 7.0)]


@pytest.mark.parametrize("sizes, message", [([3, 4], "at least three"),
                                            ([3, 3, 4], "share an element size")])
def test_too_few_or_repeated_meshes_are_refused(sizes, message):
    with pytest.raises(InputError, match=message):
        mesh_convergence(sizes, [1.0] * len(sizes))


def _results(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def test_the_command_reads_a_study_s_results(tmp_path):
    rows = [{"id": f"v{i}", "contact.damping": z, "mesh.element_size": f"{h} mm",
             "status": "done", "casing_absorbed_energy_J": 300 + 20 * h + 100 * z}
            for i, (h, z) in enumerate((h, z) for h in (3, 4, 5, 7) for z in (0.0, 0.3))]
    rows.append({"id": "bad", "contact.damping": 0.0, "mesh.element_size": "2 mm",
                 "status": "failed", "casing_absorbed_energy_J": ""})
    results = tmp_path / "results.csv"
    _results(results, rows)
    run = CliRunner().invoke(app, ["convergence", str(results), "-m",
                                   "casing_absorbed_energy_J", "--where", "contact.damping=0.3",
                                   "--json"])
    assert run.exit_code == 0, run.output
    found = json.loads(run.output)["casing_absorbed_energy_J"]
    assert [t["h1"] for t in found] == pytest.approx([0.003, 0.004])
    assert found[0]["order"] == pytest.approx(1.0, rel=1e-6)
    assert found[0]["extrapolated"] == pytest.approx(330.0)

    run = CliRunner().invoke(app, ["convergence", str(results), "-m",
                                   "casing_absorbed_energy_J"])
    assert run.exit_code == 2 and "share an element size" in run.output
    run = CliRunner().invoke(app, ["convergence", str(results), "-m", "casing_absorbed_energy_J",
                                   "--where", "contact.damping=0.5"])
    assert run.exit_code == 2 and "no finished run has it" in run.output and "0.3" in run.output
