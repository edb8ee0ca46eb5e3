"""io/history.py: time histories in memory and as CSV."""

from __future__ import annotations

import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.io.history import History, read_csv

COLUMNS = ("time_s", "step", "kinetic_energy_J", "reaction_z_N")


def filled(n: int = 5) -> History:
    h = History(COLUMNS)
    for k in range(n):
        h.append({"time_s": k * 1e-6 / 3, "step": 10 * k, "kinetic_energy_J": 12.0 / (k + 1),
                  "reaction_z_N": np.float64(-k * 0.1)})
    return h


def test_csv_round_trip_is_exact_and_keeps_types(tmp_path):
    h = filled()
    h.write_csv(tmp_path / "history.csv")
    back = read_csv(tmp_path / "history.csv")
    assert list(back) == list(COLUMNS)
    for name, a in h.arrays().items():
        assert back[name].dtype == a.dtype
        assert back[name].tobytes() == a.tobytes(), name
    assert back["step"].dtype == np.int64 and back["time_s"].dtype == np.float64
    text = (tmp_path / "history.csv").read_text()
    assert text.splitlines()[0] == "time_s,step,kinetic_energy_J,reaction_z_N"


def test_from_csv_continues_the_history(tmp_path):
    filled(3).write_csv(tmp_path / "h.csv")
    h = History.from_csv(tmp_path / "h.csv")
    assert h.columns == COLUMNS and len(h) == 3
    h.append({"time_s": 1e-6, "step": 30, "kinetic_energy_J": 3.0, "reaction_z_N": 0.0})
    assert h.arrays()["step"].tolist() == [0, 10, 20, 30]


def test_keep_first_keeps_the_rows_a_checkpoint_counted(tmp_path):
    h = filled(5)
    h.keep_first(3)
    assert h.arrays()["step"].tolist() == [0, 10, 20]
    h.keep_first(0)
    assert len(h) == 0
    h.write_csv(tmp_path / "empty.csv")
    back = read_csv(tmp_path / "empty.csv")
    assert list(back) == list(COLUMNS) and all(len(a) == 0 for a in back.values())


def test_non_finite_values_survive(tmp_path):
    h = History(("time_s", "x_m"))
    h.append({"time_s": 0.0, "x_m": float("nan")})
    h.append({"time_s": 1.0, "x_m": float("-inf")})
    h.write_csv(tmp_path / "h.csv")
    x = read_csv(tmp_path / "h.csv")["x_m"]
    assert np.isnan(x[0]) and x[1] == -np.inf


@pytest.mark.parametrize(
    ("row", "words"),
    [
        ({"time_s": 0.0, "step": 1, "kinetic_energy_J": 0.0}, "missing columns ['reaction_z_N']"),
        ({"time_s": 0.0, "step": 1, "kinetic_energy_J": 0.0, "reaction_z_N": 0.0, "x": 1},
         "unknown columns ['x']"),
        ({"time_s": "0", "step": 1, "kinetic_energy_J": 0.0, "reaction_z_N": 0.0}, "'0'"),
    ],
)
def test_bad_rows(row, words):
    with pytest.raises(InputError) as err:
        History(COLUMNS).append(row)
    assert words in str(err.value)


@pytest.mark.parametrize(
    ("columns", "words"),
    [(("step", "x_m"), "time_s"), (("time_s", "time_s"), "repeat"), (("time_s", "a,b"), "a,b")],
)
def test_bad_columns(columns, words):
    with pytest.raises(InputError, match=words):
        History(columns)


def test_malformed_csv(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("time_s,x_m\n0.0,1.0\n1.0\n")
    with pytest.raises(InputError, match="bad.csv:3"):
        read_csv(p)
    p.write_text("time_s,x_m\n0.0,abc\n")
    with pytest.raises(InputError, match="'abc'"):
        read_csv(p)
    with pytest.raises(InputError, match="cannot be read"):
        read_csv(tmp_path / "absent.csv")
