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
