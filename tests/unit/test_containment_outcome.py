"""containment.containment_outcome: geometry first, never a speed test alone."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wovenimpact.containment import containment_outcome

R = 0.25


def history(speed, radial, reach, outside):
    n = len(speed)
    return {"fragment_speed_m_per_s": np.asarray(speed, float),
            "fragment_radial_velocity_m_per_s": np.asarray(radial, float),
            "fragment_max_radius_m": np.asarray(reach, float),
            "intact_casing_outside": np.asarray(outside, float) * np.ones(n)}


@settings(max_examples=200, deadline=None)
@given(v0=st.floats(50.0, 400.0), loss=st.floats(0.0, 0.5), n=st.integers(2, 50),
       push=st.floats(0.011, 1.0))
def test_a_fragment_still_pushing_intact_layers_is_never_escaped(v0, loss, n, push):
    """Heavy or light, barely slowed or not: while intact casing lies outside it at the
    end and it still moves outwards (faster than the 1 % of its initial speed that
    counts as stopped), the run is undecided."""
    speed = np.linspace(v0, v0 * (1 - loss), n)
    radial = np.full(n, push * v0)
    reach = np.linspace(0.245, 0.26, n)
    h = history(speed, radial, reach, outside=1)
    assert containment_outcome(h, R)["outcome"] == "undecided"


@settings(max_examples=100, deadline=None)
@given(v_end=st.floats(1.0, 300.0), n=st.integers(2, 50))
def test_through_every_layer_and_still_going_out_is_escaped(v_end, n):
    h = history(np.linspace(300.0, v_end, n), np.full(n, 10.0), np.linspace(0.245, 0.3, n),
                outside=0)
    out = containment_outcome(h, R)
    assert out["outcome"] == "escaped" and out["fragment_exit_speed_m_per_s"] == v_end


def test_turned_back_against_intact_layers_is_contained_and_not_before_arriving():
    n = 20
    radial = np.linspace(50.0, -5.0, n)
    h = history(np.linspace(150.0, 40.0, n), radial, np.linspace(0.245, 0.252, n), outside=1)
    assert containment_outcome(h, R)["outcome"] == "contained"
    # the same velocities but the fragment never reached the casing: not contained
    h["fragment_max_radius_m"] = np.full(n, 0.2)
    assert containment_outcome(h, R)["outcome"] == "undecided"


def test_a_released_fragment_starts_at_omega_r_cm_and_is_undecided_before_impact(tmp_path):
    """The hybrid example (5 mm elements), run 6 µs: the fragment's initial
    centre-of-mass speed is ω r_cm of its relaxed configuration to 0.1 %, and a run that
    ends before the impact is undecided, not escaped."""
    from pathlib import Path

    from wovenimpact.io.history import read_csv
    from wovenimpact.runs import run_case

    case = Path(__file__).resolve().parents[2] / "examples" / "containment" / "hybrid_4.toml"
    summary = run_case(case, tmp_path / "out", overrides=[
        'run.end_time="6 us"'])
    h = read_csv(tmp_path / "out" / "history.csv")
    r_cm = float(h["fragment_cm_radius_m"][0])
    assert summary["fragment_initial_speed_m_per_s"] == pytest.approx(1047.0 * r_cm, rel=1e-3)
    assert summary["outcome"] == "undecided"
