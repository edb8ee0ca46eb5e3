"""``wovenimpact bench --json`` prints the documented shape (a tiny plate, so it is quick;
no timing is asserted)."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from wovenimpact.cli.app import app


def test_bench_json_shape():
    result = CliRunner().invoke(app, ["bench", "--sizes", "400", "--kinds", "elastic,metal,fabric",
                                      "--threads", "1", "--steps", "2", "--json"])
    assert result.exit_code == 0, result.output
    doc = json.loads(result.stdout.strip().splitlines()[-1])
    cases = doc["cases"]
    assert {"cpu", "cores", "numba", "wovenimpact", "date"} <= set(doc["machine"])
    assert [c["name"] for c in cases] == ["elastic_plate", "metal_plate", "fabric_plate"]
    for c in cases:
        assert {"name", "elements", "threads", "ns_per_element_cycle"} <= set(c)
        assert c["elements"] == 400 and c["threads"] == 1 and c["ns_per_element_cycle"] > 0


def test_bench_prints_the_machine_line_first():
    result = CliRunner().invoke(app, ["bench", "--sizes", "100", "--kinds", "elastic",
                                      "--threads", "1", "--steps", "1"])
    assert result.exit_code == 0, result.output
    assert result.stdout.splitlines()[0].startswith("machine: ")


def test_bench_refuses_an_unknown_kind():
    result = CliRunner().invoke(app, ["bench", "--sizes", "100", "--kinds", "steel",
                                      "--threads", "1", "--steps", "1"])
    assert result.exit_code == 2
    assert "bench kind 'steel'" in result.output and "metal" in result.output


def test_bench_reports_memory_and_ratios_to_the_elastic_plate_and_the_previous_release():
    """Each case carries its memory per element (the arrays of model, state and workspace:
    at least the 3 float64 node vectors x, v, f per node) and its ratios; the ratios are
    the quotients of the figures (compare), and a case the stored release lacks has
    none."""
    from wovenimpact.benchmark import compare, release_figures

    result = CliRunner().invoke(app, ["bench", "--sizes", "400", "--kinds", "elastic,fabric",
                                      "--threads", "1", "--steps", "2", "--json"])
    assert result.exit_code == 0, result.output
    elastic, fabric = json.loads(result.stdout.strip().splitlines()[-1])["cases"]
    nodes_per_element = 21 * 21 / 400
    for c in (elastic, fabric):
        assert c["bytes_per_element"] > 3 * 3 * 8 * nodes_per_element
    assert fabric["bytes_per_element"] > elastic["bytes_per_element"]  # material state
    assert fabric["ratio_to_elastic"] == (fabric["ns_per_element_cycle"]
                                          / elastic["ns_per_element_cycle"])
    previous = release_figures([elastic])  # a release that only had the elastic plate
    cases = compare([dict(elastic, ns_per_element_cycle=2 * elastic["ns_per_element_cycle"]),
                     dict(fabric)], previous)
    assert abs(cases[0]["ratio_to_previous"] - 2.0) < 1e-2  # stored rounded to 0.1 ns
    assert cases[1]["ratio_to_previous"] is None
