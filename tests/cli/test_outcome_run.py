"""The outcome rule on a real run: a heavy impactor on an intact ply is never perforated."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from wovenimpact.io.history import read_csv
from wovenimpact.results.quantities import QUIET_TIME, STEADY_VELOCITY
from wovenimpact.runs import run_case

ROOT = Path(__file__).resolve().parents[2]


def test_heavy_impactor_pushing_an_intact_ply_is_not_perforated(tmp_path):
    """The 1-ply example struck by a 5 kg flat-faced impactor at 100 m/s (1.88 mm
    elements, 18 µs): its speed barely changes — steady to 0.1 % over the last 10 µs,
    which the old rule took for a perforation — while the ply is intact and ahead of
    its nose. The outcome is ``undecided`` (or ``stopped``), never ``perforated``."""
    out = tmp_path / "heavy"
    summary = run_case(ROOT / "examples" / "plate_impact" / "plies1_100.toml", out, threads=1,
                       overrides=["impactor.mass=5 kg", "mesh.element_size=1.88 mm",
                                  "run.end_time=18 us", "run.history_interval=0.25 us",
                                  "run.field_interval=18 us", "run.checkpoint_interval=18 us"])
    h = read_csv(out / "history.csv")
    v = h["impactor_velocity_m_per_s"]
    window = h["time_s"] >= h["time_s"][-1] - QUIET_TIME
    print(f"\nheavy impactor: {summary['outcome']}, v_end = {v[-1]:.5f} m/s, peak force "
          f"{summary['peak_contact_force_N']:.0f} N, nose {h['impactor_nose_ahead_of_intact_m'][-1] * 1e3:+.3f} "
          f"mm past the intact ply, eroded {summary['eroded_elements']}")
    assert summary["peak_contact_force_N"] > 0.0  # it arrived
    assert np.ptp(v[window]) <= STEADY_VELOCITY * v[-1]  # the trap of the old rule
    assert summary["eroded_elements"] == 0 and h["intact_material_ahead"][-1] == 1
    assert h["impactor_nose_ahead_of_intact_m"][-1] < 0.0
    assert summary["outcome"] in ("undecided", "stopped")
    assert not summary["perforated"]


def test_a_plug_torn_free_is_not_intact_material(tmp_path):
    """A 10 mm quarter plate under the FSP: a ring of elements (centres 1–2.2 mm from the axis; 1 mm elements)
    is eroded and the element inside it (a plug, held only by the symmetry planes) is moved
    1 mm ahead of the nose. The plug is not intact material (nothing attaches it to the
    clamped edge); the ply outside the ring is, once moved ahead of the nose too."""
    from tests.cli.test_run_cli import CASE, IMPACTOR, write_case
    from wovenimpact.kernels import shell_layout as SL
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.results.quantities import attached_nodes, intact_material_ahead
    from wovenimpact.spec.case import load_case

    text = CASE.replace('[[initial_velocity]]\nvelocity = ["0 m/s", "0 m/s", "-60 m/s"]\n'
                        'radius = "1.5 mm"\n', "") + IMPACTOR.replace("{z}", "0.4 mm")
    compiled = compile_case(*load_case(write_case(tmp_path, text=text)))
    model, state = compiled.model, compiled.state
    assert intact_material_ahead(model, state)["intact_material_ahead"] == 1  # before
    centre = model.x0[model.quads].mean(axis=1)
    r = np.hypot(centre[:, 0], centre[:, 1])
    state.elem[(r > 1e-3) & (r < 2.2e-3), SL.E_ALIVE] = 0.0
    plug = np.unique(model.quads[r <= 1e-3])
    rest = np.setdiff1d(np.unique(model.quads[r >= 2.2e-3]), plug)
    state.x[:, 2] -= 1.5e-3  # the whole ply below the nose (0.4 mm above it at t = 0)
    state.x[plug, 2] -= 1e-3  # the plug further ahead still
    attached = attached_nodes(model, state)
    assert not attached[plug].any() and attached[rest].all()
    got = intact_material_ahead(model, state)
    assert got["intact_material_ahead"] == 1  # the ply outside the ring, within R + h
    state.x[rest, 2] += 3e-3  # the ply behind the nose: only the plug is ahead
    got = intact_material_ahead(model, state)
    assert got["intact_material_ahead"] == 0 and got["impactor_nose_ahead_of_intact_m"] > 0.0
