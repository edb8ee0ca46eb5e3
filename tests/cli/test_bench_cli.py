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
