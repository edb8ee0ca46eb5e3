"""Selective mass scaling (kernels.mass_scaling; docs/theory.md §4, "Mass scaling"): an
element crushed during a run no longer drags the step down, the mass it gets is the one
that restores its step, the kinetic energy that mass brings is booked so the balance
still closes, a restart is bitwise, and bad settings are refused with their key."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.verification.meshes import elastic, rect_grid
from wovenimpact.errors import InputError, SimulationError
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver import Workspace, step
from wovenimpact.state import MASS_SCALING, initial_state


def crushed_strip(fraction: float, max_added: float = 1.0):
    """A 4 × 1 strip of 10 mm elements, the first three held, the free end driven back
    at 40 m/s: only the last element is crushed, to 40 % of its length at 150 µs."""
    nodes, quads = rect_grid(4, 1, 0.04, 0.01)
    bc = BoundaryConditions(len(nodes), ramp_time=5e-6)
    held = np.flatnonzero(nodes[:, 0] <= 0.03 + 1e-12)
    bc.fix(held)
    right = np.flatnonzero(np.isclose(nodes[:, 0], 0.04))
    bc.prescribe(right, 0, -40.0)
    model = build_model(nodes, quads, {"s": Section(elastic(), thickness=1e-3)},
                        np.zeros(len(quads), int), bcs=bc, erode_dt_fraction=0.05,
                        mass_scaling_fraction=fraction, max_added_mass_fraction=max_added)
    return model


def run_to(model, t_end):
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    dts, dt_crushed = [], math.inf
    while st.t < t_end:
        step(model, st, ws)
        dts.append(st.dt)
        dt_crushed = min(dt_crushed, st.elem[3, SL.E_DT])
    run_to.dt_crushed = dt_crushed  # smallest unscaled L_e/c_e of the crushed element
    return st, ws, np.array(dts)


def test_a_crushed_element_gets_the_mass_that_restores_its_step_and_the_balance_closes():
    f = 0.8
    plain, _, dt_plain = run_to(crushed_strip(0.0), 150e-6)
    model = crushed_strip(f)
    st, ws, dts = run_to(model, 150e-6)
    first = st.dt_first
    # without scaling the crushed element drags the step to ~40 % of the first
    assert dt_plain.min() < 0.5 * first
    # with it the step never falls below f Δt₁ (to round-off)
    assert dts.min() >= f * first * (1 - 1e-12)
    # only the crushed element carries added mass, r = (f Δt₁/(α Δt_e))² − 1 at its
    # smallest step Δt_e (it is crushed monotonically)
    assert np.count_nonzero(st.mass_ratio) == 1
    expected = (f * first / model.alpha / run_to.dt_crushed) ** 2 - 1
    assert st.mass_ratio[3] == pytest.approx(expected, rel=1e-12)
    assert st.mass_ratio[3] > 2.0  # crushed to about 40 %: (0.8/0.4)² − 1 = 3
    # its nodes carry a quarter of r_e m_e each; the others nothing
    quarter = 0.25 * st.mass_ratio[3] * model.elem_mass[3]
    np.testing.assert_allclose(st.added_mass[model.quads[3]], quarter, rtol=1e-14)
    assert np.count_nonzero(st.added_mass) == 4
    # two of the crushed element's nodes are held (at rest), the driven pair moves at
    # 40 m/s and takes ½ Δm v² of kinetic energy with each mass increase
    assert st.energy[MASS_SCALING] > 0.0
    eb = energy_balance(model, st)
    print(f"\nadded {st.added_mass.sum():.3e} kg (×{1 + st.mass_ratio[3]:.3f} on element 3), "
          f"mass-scaling energy {st.energy[MASS_SCALING]:.3e} J, error {eb['error_fraction']:.2e}"
          f" (unscaled run {energy_balance(crushed_strip(0.0), plain)['error_fraction']:.2e}); "
          f"steps {len(dts)} vs {len(dt_plain)}")
    assert eb["error_fraction"] < 1e-3
    # leaving the mass-scaling energy out of the balance would show as an error
    assert st.energy[MASS_SCALING] > 10 * abs(eb["drift_J"])
    assert len(dts) < len(dt_plain)


def test_the_kinematic_bound_of_the_yarn_step_gets_no_mass():
    """Under ``run.stable_step = "yarn"`` an element's step is also bounded by how fast
    its corners close (``kinematic_step``); no added mass raises that bound, so mass
    scaling must leave it out. A soft strip (c ≈ 260 m/s) whose end is driven at 40 m/s
    closes its last element at 0.4 % of its length per µs: the kinematic bound,
    η L/v = 12.5 µs, lies far below f Δt₁ while the element's wave bound stays above it
    (crushed to 70 % only). Scaling the kinematic bound would add mass at every step
    without raising it (before the fix: mass × 5.8 on that element by 56 µs)."""
    nodes, quads = rect_grid(4, 1, 0.04, 0.01)
    bc = BoundaryConditions(len(nodes), ramp_time=5e-6)
    bc.fix(np.flatnonzero(nodes[:, 0] <= 0.03 + 1e-12))
    bc.prescribe(np.flatnonzero(np.isclose(nodes[:, 0], 0.04)), 0, -40.0)
    f = 0.6
    model = build_model(nodes, quads,
                        {"s": Section(elastic(modulus=60e6, density=1000.0), thickness=1e-3)},
                        np.zeros(len(quads), int), bcs=bc, erode_dt_fraction=0.05,
                        mass_scaling_fraction=f, max_added_mass_fraction=1.0,
                        stable_step="yarn")
    st, ws, dts = run_to(model, 75e-6)
    wave0 = st.dt_first / model.alpha
    # the element's wave bound never needed mass: it stayed above the target
    assert run_to.dt_crushed > f * wave0
    # the step followed the kinematic bound, well below the target, without mass
    assert dts.min() < 0.5 * f * st.dt_first
    assert not np.any(st.mass_ratio)
    assert not np.any(st.added_mass)
    # the bound is the driven element's alone (the held ones do not move)
    assert np.isfinite(st.elem[3, SL.E_DT_KIN])
    assert np.all(np.isinf(st.elem[:3, SL.E_DT_KIN]))


def test_a_restart_rebuilds_the_scaled_masses_bit_for_bit():
    model = crushed_strip(0.8)
    st, ws, _ = run_to(model, 100e-6)
    assert np.any(st.added_mass > 0.0)
    again = st.copy()
    ws2 = Workspace.for_model(model, again)
    for _ in range(20):
        step(model, st, ws)
        step(model, again, ws2)
    assert st.equals(again)


def test_too_much_added_mass_stops_the_run_naming_the_key():
    model = crushed_strip(0.8, max_added=0.1)
    with pytest.raises(SimulationError, match="max_added_mass_fraction"):
        run_to(model, 150e-6)


@pytest.mark.parametrize("fraction", [0.05, 0.01, 1.0, -0.1])
def test_scaling_at_or_below_the_erosion_fraction_or_out_of_range_is_refused(fraction):
    with pytest.raises(InputError, match="mass_scaling_fraction"):
        crushed_strip(fraction)


def test_the_case_key_is_checked_against_erode_dt_fraction():
    from pathlib import Path

    from wovenimpact.spec.case import load_case

    case = Path(__file__).resolve().parents[2] / "examples" / "plate_impact" / "plies1_100.toml"
    with pytest.raises(InputError, match="mass_scaling_fraction"):
        load_case(case, ["run.mass_scaling_fraction=0.03"])
    spec, _ = load_case(case, ["run.mass_scaling_fraction=0.3"])
    assert math.isclose(spec.run.mass_scaling_fraction, 0.3)
