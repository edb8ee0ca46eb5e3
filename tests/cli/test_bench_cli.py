"""``wovenimpact bench --json`` prints the documented shape (a tiny plate, so it is quick;
no timing is asserted)."""

from __future__ import annotations

import json

from typer.testing import CliRunner

from wovenimpact.cli.app import app


def test_bench_json_shape():
    result = CliRunner().invoke(app, ["bench", "--sizes", "400", "--kinds", "elastic,fabric",
                                      "--threads", "1", "--steps", "2", "--json"])
    assert result.exit_code == 0, result.output
    cases = json.loads(result.stdout.strip().splitlines()[-1])["cases"]
    assert [c["name"] for c in cases] == ["elastic_plate", "fabric_plate"]
    for c in cases:
        assert {"name", "elements", "threads", "ns_per_element_cycle"} <= set(c)
        assert c["elements"] == 400 and c["threads"] == 1 and c["ns_per_element_cycle"] > 0
