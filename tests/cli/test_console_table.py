"""The console's summary table (cli/app.py emit): every value is printed, NumPy scalars and
lists of them included, and text that looks like rich markup is shown as written."""

from __future__ import annotations

import numpy as np

from wovenimpact.cli.app import cell, console, emit


def test_lists_of_numpy_floats_and_bracketed_text_are_printed_not_dropped(capsys):
    result = {"absorbed_energy_per_ply_J": [np.float64(3.2212345678), np.float64(1.5)],
              "by_interface": {"ply0-impactor": np.float64(2.5)}, "note": "[bold]x[/bold]",
              "count": np.int64(7), "speed": 129.71234567}
    with console.capture() as cap:
        emit(result, False, "summary")
    out = cap.get()
    assert "[3.22123, 1.5]" in out
    assert "{ply0-impactor: 2.5}" in out
    assert "[bold]x[/bold]" in out and "129.712" in out and " 7 " in out


def test_cell_formats_nested_values():
    assert cell([np.float64(1.0) / 3.0, (2, np.float32(0.5))]) == "[0.333333, [2, 0.5]]"
    assert cell(np.array([1.0, 2.0])) == "[1, 2]"
    assert cell(None) == "None" and cell(True) == "True"


def test_the_run_summary_is_grouped_in_engineering_units_as_on_the_report(capsys):
    """``wovenimpact run``'s table: the report's groups and units (io/summary_keys.py),
    NumPy scalars printed, an unknown key under "other", the provenance left out."""
    from wovenimpact.cli.app import emit_summary

    summary = {"outcome": "escaped", "fragment_exit_speed_m_per_s": np.float64(125.4),
               "max_bulge_m": np.float64(0.0412),
               "absorbed_energy_per_layer_J": [np.float64(300.0), np.float64(12.5)],
               "end_time_s": 0.0025, "my_new_metric": 7, "summary_version": 4,
               "provenance": {"digest": "d1d2d3d4"}}
    with console.capture() as cap:
        emit_summary(summary, False, "summary")
    out = cap.get()
    lines = out.splitlines()
    bulge = next(line for line in lines if "largest bulge" in line)
    assert "41.2" in bulge and " mm " in bulge and "max_bulge_m" in bulge
    assert "300, 12.5" in out and "125.4" in out
    ms = next(line for line in lines if "end time" in line)
    assert "2.5" in ms and " ms " in ms
    assert out.index("Answer") < out.index("Casing and fragment") < out.index("Run and checks")
    assert out.index("Other keys") < out.index("my_new_metric")
    assert "d1d2d3d4" not in out and "summary_version" not in out
