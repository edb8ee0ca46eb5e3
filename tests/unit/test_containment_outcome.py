"""containment.containment_outcome: geometry first, never a speed test alone."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from wovenimpact.results.containment import containment_outcome

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


@settings(max_examples=200, deadline=None)
@given(v0=st.floats(50.0, 400.0), loss=st.floats(0.0, 0.5), n=st.integers(2, 400),
       push=st.floats(0.011, 1.0), depth=st.floats(-0.2, 0.0))
def test_a_steady_fragment_still_inside_the_casing_envelope_is_never_escaped(v0, loss, n, push,
                                                                           depth):
    """The clear-of-the-casing route to ``escaped`` is geometry first: with intact casing
    outside, a fragment whose innermost node is not beyond the casing's outer radius is
    undecided however steady its speed and however long the history."""
    outer = R + 0.003
    h = history(np.linspace(v0, v0 * (1 - loss), n), np.full(n, push * v0),
                np.linspace(0.245, 0.45, n), outside=1)
    h["time_s"] = np.linspace(0.0, 4e-3, n)
    h["fragment_min_radius_m"] = np.full(n, outer + depth)
    assert containment_outcome(h, R, outer)["outcome"] == "undecided"


@settings(max_examples=100, deadline=None)
@given(v_end=st.floats(20.0, 300.0), n=st.integers(60, 400), wobble=st.floats(0.0, 0.49))
def test_a_fragment_clear_of_the_casing_that_nothing_slows_is_escaped(v_end, n, wobble):
    """Metal strips peeled out of the casing stay joined to it and lie outside the
    fragment (``intact_casing_outside``), but a fragment wholly beyond the casing's outer
    radius whose speed has held within 0.5 % for the last 500 µs is escaped at that
    speed (6 aluminium layers on the 7 mm ring: 75.0 m/s from 3.4 ms, its innermost node
    11 cm outside the casing). Still losing speed, not yet clear, or a history shorter
    than the window: undecided."""
    from wovenimpact.results.containment import EXIT_SPEED_SETTLED

    outer = R + 0.003
    t = np.linspace(0.0, 4e-3, n)
    speed = np.where(t < 3e-3, v_end * (1.0 + 0.5 * (3e-3 - t) / 3e-3), v_end)
    h = history(speed, np.full(n, 0.9 * v_end), np.linspace(0.245, 0.5, n), outside=1)
    h["time_s"] = t
    h["fragment_min_radius_m"] = np.linspace(0.1, outer + 0.1, n)
    # within the tolerance over the last 500 µs (at most twice the amplitude from the last)
    h["fragment_speed_m_per_s"][t >= 3.6e-3] *= 1.0 + wobble * EXIT_SPEED_SETTLED * np.cos(
        t[t >= 3.6e-3] * 1e4)
    out = containment_outcome(h, R, outer)
    assert out["outcome"] == "escaped"
    assert out["fragment_exit_speed_m_per_s"] == h["fragment_speed_m_per_s"][-1]
    slowing = {**h, "fragment_speed_m_per_s": np.linspace(2 * v_end, v_end, n)}
    undecided = containment_outcome(slowing, R, outer)
    assert undecided["outcome"] == "undecided"
    # no exit speed is known yet: none is reported, only the speed at the end
    assert undecided["fragment_exit_speed_m_per_s"] is None
    assert undecided["fragment_speed_at_end_m_per_s"] == v_end
    inside = {**h, "fragment_min_radius_m": np.full(n, outer - 1e-4)}
    assert containment_outcome(inside, R, outer)["outcome"] == "undecided"
    short = {k: v[t >= 3.7e-3] for k, v in h.items()}
    assert containment_outcome(short, R, outer)["outcome"] == "undecided"
    older = {k: v for k, v in h.items() if k != "fragment_min_radius_m"}  # an older run
    assert containment_outcome(older, R, outer)["outcome"] == "undecided"


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
    centre-of-mass speed is ω r_cm of its relaxed configuration to 0.1 %, a run that
    ends before the impact is undecided, not escaped, and its report.html is a whole
    offline page consistent with its summary."""
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
    from tests.io.report_page import check_run_page

    check_run_page(tmp_path / "out")


def test_containment_outputs_bulge_layer_and_material_energies_and_fragment_plot(tmp_path):
    """A coarse two-ply hybrid casing (10 mm elements) run into the impact (the tip,
    moving tangentially, reaches the casing after about 200 µs; 300 µs): the
    history carries the outermost layer's bulge and the summary's largest bulge is at
    least every recorded one; there is an absorbed energy per layer (the next test checks
    them against quantities.ply_energies) and the materials' energies are those layers'
    sums (aluminium: the inner shell; the fabric section: the plies); the run draws the
    fragment plot and not a plate's deflection profile, and writes casing and blade as
    two VTU blocks; its history has the blade–casing and layer contact forces."""
    from pathlib import Path

    from wovenimpact.io.history import read_csv
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.runs import run_case

    case = Path(__file__).resolve().parents[2] / "examples" / "containment" / "hybrid_4.toml"
    out = tmp_path / "out"
    summary = run_case(case, out, overrides=[
        'run.end_time="300 us"', 'mesh.element_size="10 mm"', "mesh.casing.layers=2",
        'run.field_interval="150 us"', 'run.checkpoint_interval="300 us"'])
    h = read_csv(out / "history.csv")
    bulge = h["outer_layer_bulge_m"]
    assert bulge[0] == pytest.approx(0.0, abs=1e-12)
    assert summary["max_bulge_m"] >= float(np.max(bulge)) > 0.0  # the casing was pushed out
    per_layer = summary["absorbed_energy_per_layer_J"]
    assert len(per_layer) == summary["casing_layers"] == 3  # inner shell + 2 plies
    per_material = summary["absorbed_energy_per_material_J"]
    assert len(per_material) == 2
    names = list(per_material)
    assert per_material[names[0]] == pytest.approx(per_layer[0], rel=1e-12)  # aluminium
    assert per_material[names[1]] == pytest.approx(per_layer[1] + per_layer[2], rel=1e-12)
    assert sum(per_layer) > 0.0
    assert summary["casing_absorbed_energy_J"] == pytest.approx(sum(per_layer), rel=1e-12)
    # the history's casing energies (the energy plot's casing panel) end at the summary's
    # absorbed energy; the casing holds less than it absorbed, the fragment lost more
    assert h["casing_absorbed_energy_part_J"][-1] == pytest.approx(
        summary["casing_absorbed_energy_J"], rel=1e-12)
    held = h["casing_kinetic_energy_part_J"][-1] + h["casing_element_energy_part_J"][-1]
    assert 0.0 < held <= h["casing_absorbed_energy_part_J"][-1] * (1.0 + 1e-9)
    lost = h["fragment_kinetic_energy_part_J"][0] - h["fragment_kinetic_energy_part_J"][-1]
    assert lost > h["casing_absorbed_energy_part_J"][-1] > 0.0
    # the element sizes as run (the override, and the blade's: the casing's by default)
    assert summary["element_size_m"] == summary["blade_element_size_m"] == pytest.approx(0.01)
    # absorbed = the contact work the layer's nodes received: the run's per-node sums
    # (final checkpoint) add up to the whole contact work, the blade gave what the layers
    # took plus what the contact dashpots dissipated and the penalty springs hold
    from wovenimpact.results.containment import layer_absorbed_energies
    from wovenimpact.io.checkpoint import latest_checkpoint, load_checkpoint
    from wovenimpact.spec.case import load_case

    spec, base = load_case(case, [
        'run.end_time="300 us"', 'mesh.element_size="10 mm"', "mesh.casing.layers=2",
        'run.field_interval="150 us"', 'run.checkpoint_interval="300 us"'])
    model = compile_case(spec, base).model
    state = load_checkpoint(latest_checkpoint(out / "checkpoints"), model.digest())
    assert state.t == pytest.approx(summary["end_time_s"], rel=1e-12)
    # every key a study may ask of a containment case is there (stopped_when_decided:
    # None, the run reached its end time undecided)
    from wovenimpact.results.summary import summary_keys

    assert set(summary_keys(spec)) <= set(summary)
    assert summary["stopped_when_decided"] is None and summary["outcome"] == "undecided"
    assert layer_absorbed_energies(model, state) == pytest.approx(per_layer, rel=1e-12)
    total = float(np.sum(state.contact_work))
    assert total == pytest.approx(-summary["contact_energy_J"], rel=1e-9)
    assert int(model.ply.max()) == 3  # layers 0–2, then the blade
    blade = float(np.sum(state.contact_work[np.unique(model.quads[model.ply == 3])]))
    assert blade < -sum(per_layer) < 0.0  # the fragment lost more than the casing took
    assert sum(per_layer) + blade == pytest.approx(total, rel=1e-9)
    assert (out / "plots" / "fragment.png").exists()
    # the contact force histories (results.contact_forces): blade on casing and layer k on
    # layer k + 1, zero before the impact, acting once the tip has struck
    forces = ["contact_force_blade_casing_N", "contact_force_layer0_layer1_N",
              "contact_force_layer1_layer2_N"]
    assert all(h[c][0] == 0.0 for c in forces)
    assert all(np.max(h[c]) > 0.0 for c in forces[:2])
    assert not (out / "plots" / "ply_deflection.png").exists()
    # the VTU series: casing and blade as the blocks (parts 0, 1) of each frame, each file
    # with its own nodes, together every element once
    import meshio

    from wovenimpact.io.fields import PVD_NAME, read_pvd

    files = [f for _, f in read_pvd(out / "fields" / PVD_NAME)]
    assert files[:2] == ["step_000000_casing.vtu", "step_000000_blade.vtu"]
    assert len(files) == 6  # frames at 0, 150 and 300 µs
    pvd = (out / "fields" / PVD_NAME).read_text()
    assert 'part="1" file="step_000002_blade.vtu"' in pvd
    casing, blade = (meshio.read(out / "fields" / f) for f in files[4:])
    ids = np.concatenate([np.concatenate(m.cell_data["element"]) for m in (casing, blade)])
    assert np.array_equal(np.sort(ids), np.arange(summary["elements"]))
    for m in (casing, blade):
        used = np.unique(np.concatenate([c.data.ravel() for c in m.cells]))
        assert used.size == m.points.shape[0]  # no point outside the part's cells
    check_layer_columns(out, summary)


def check_layer_columns(out, summary):
    """The per-layer history columns of a containment run: each layer's absorbed energy
    sums, at every row, to the casing's absorbed energy (a conservation check within
    round-off: the layers share no node) and ends at the summary's per-layer figure; a
    row's intact-casing flag is 1 exactly when one of the layers' is; the layer energy
    plot and the pictures (casing near the fragment and the blade, every alive element
    in view drawn) are written."""
    import json

    from wovenimpact.io.history import read_csv
    from wovenimpact.results.containment import layer_perforation_times

    h = read_csv(out / "history.csv")
    n = summary["casing_layers"]
    energy = np.array([h[f"casing_layer{k}_absorbed_energy_part_J"] for k in range(n)])
    total = h["casing_absorbed_energy_part_J"]
    assert np.any(total > 0.0)
    scale = np.maximum(np.abs(energy).sum(axis=0), 1e-300)
    assert np.all(np.abs(energy.sum(axis=0) - total) <= 1e-12 * scale)
    assert energy[:, -1].tolist() == summary["absorbed_energy_per_layer_J"]
    flags = np.array([h[f"casing_layer{k}_intact_outside"] for k in range(n)])
    assert np.array_equal(flags.max(axis=0), h["intact_casing_outside"])
    assert summary["layer_perforated_at_s"] == layer_perforation_times(h, n)
    assert (out / "plots" / "layer_energy.png").stat().st_size > 1000
    index = json.loads((out / "pictures" / "pictures.json").read_text())
    assert index and all(e["drawn"] == e["alive_in_view"] > 0 for e in index)
    assert all(e["vtu"][0].endswith("_casing.vtu") and e["vtu"][1].endswith("_blade.vtu")
               for e in index)


def test_layer_energies_are_the_generated_plies_energies():
    """On a generated casing (layers = plies 0…N, the blade's ply after them) the layer
    energies equal quantities.ply_energies of those plies for any velocities and element
    energies, and each layer is named by its material (inner shell aluminium, then the
    fabric)."""
    from wovenimpact.results.containment import layer_energies, layer_materials
    from wovenimpact.kernels import shell_layout as SL
    from wovenimpact.results.quantities import ply_energies

    model, state = coarse_two_ply_casing()
    rng = np.random.default_rng(7)
    state.v[:] = rng.normal(0.0, 30.0, state.v.shape)
    for col in (SL.E_U_MEMB, SL.E_U_BEND, SL.E_U_HG):
        state.elem[:, col] = rng.uniform(0.0, 1e-3, model.n_elems)
    assert layer_energies(model, state) == pytest.approx(ply_energies(model, state)[:3],
                                                         rel=1e-12)
    names = layer_materials(model)
    assert len(names) == 3 and names[1] == names[2] != names[0]
    # the names of the material files (kevlar_thesis.toml carries name = "kevlar_thesis")
    assert names[0] == "aluminium" and names[1] == "kevlar_thesis"


def test_layer_absorbed_energies_sum_the_contact_work_of_each_layers_nodes():
    """The absorbed energy of a layer is the contact work of its own nodes (layers share
    no node; the blade's nodes count for none), and the per-material figures are the
    sums of their layers'."""
    from wovenimpact.results.containment import (
        energy_per_material,
        layer_absorbed_energies,
        layer_elements,
    )

    model, state = coarse_two_ply_casing()
    state.contact_work = np.random.default_rng(3).normal(0.0, 1.0, model.n_nodes)
    nodes = [np.unique(model.quads[e]) for e in layer_elements(model)]
    assert sum(n.size for n in nodes) == np.unique(np.concatenate(nodes)).size  # disjoint
    expected = [float(np.sum(state.contact_work[n])) for n in nodes]
    assert layer_absorbed_energies(model, state) == pytest.approx(expected, rel=1e-12)
    per_material = energy_per_material(model, state)
    assert list(per_material.values()) == pytest.approx(
        [expected[0], expected[1] + expected[2]], rel=1e-12)


def test_force_pair_power_books_each_nodes_share_and_keeps_the_sum():
    """The trapezoid power Σ_a ½ (f_old + f_new)_a · v_a is summed in node order (the same
    bits as a plain loop), and each node's ½ (f_old + f_new)_a · v_a Δt is added to its
    accumulator."""
    from wovenimpact.kernels.integrate import force_pair_power

    rng = np.random.default_rng(11)
    f_old, f_new, v = (rng.normal(size=(50, 3)) for _ in range(3))
    acc = np.zeros(50)
    dt = 3e-7
    power = force_pair_power(f_old, f_new, v, dt, acc)
    s = 0.0
    for a in range(50):
        for j in range(3):
            s += (f_old[a, j] + f_new[a, j]) * v[a, j]
    assert power == 0.5 * s
    per_node = 0.5 * np.sum((f_old + f_new) * v, axis=1) * dt
    assert acc == pytest.approx(per_node, rel=1e-12)
    force_pair_power(f_old, f_new, v, dt, acc)  # it accumulates
    assert acc == pytest.approx(2.0 * per_node, rel=1e-12)


def coarse_two_ply_casing(sector: bool = False):
    """Model and initial state of the 4-ply example reduced to 2 plies at 10 mm (with
    ``sector``: a 120° sector, 60°–180°, its cut edges clamped, in place of the ring)."""
    from pathlib import Path

    from wovenimpact.setup.compile import compile_case
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.spec.fields import read_toml, set_dotted

    path = Path(__file__).resolve().parents[2] / "examples" / "containment" / "hybrid_4.toml"
    doc = read_toml(path, "case")
    set_dotted(doc, "mesh.element_size", "10 mm")
    set_dotted(doc, "mesh.casing.layers", 2)
    if sector:
        set_dotted(doc, "mesh.casing.sector", "120 deg")
        set_dotted(doc, "mesh.casing.centre_angle", "120 deg")
        for key in ("fine_sector", "coarse_element_size"):
            doc["mesh"]["casing"].pop(key)
        doc["boundary"].append({"nodes": "casing.cut_edges", "type": "clamped"})
    compiled = compile_case(case_from_dict(doc, str(path)), path.parent)
    return compiled.model, compiled.state


@pytest.mark.parametrize("one_watch", [False, True])
def test_a_piece_of_ply_torn_free_ahead_of_the_fragment_does_not_hold_it(one_watch):
    """Only casing material joined to the supports through live elements counts as
    intact: a patch of the outer ply cut free (every element round it eroded) and lying
    beyond the fragment does not keep a run undecided, nor is it the layer's bulge; the
    same patch still part of its ply does both. Each row computed afresh, and with one
    CasingWatch for all of them, as a run does (its anchored mask must follow the
    erosion between rows)."""
    import math

    from wovenimpact.results.containment import FRAGMENT, CasingWatch, layer_elements
    from wovenimpact.results.containment import fragment_row as row_of
    from wovenimpact.kernels import shell_layout as SL

    model, state = coarse_two_ply_casing()
    watch = CasingWatch(model) if one_watch else None

    def fragment_row(model, state):
        return row_of(model, state, watch)

    nodes = model.node_sets[FRAGMENT]
    cm = model.node_mass[nodes] @ state.x[nodes] / model.node_mass[nodes].sum()
    phi_cm = math.atan2(cm[1], cm[0])
    layers = layer_elements(model)
    centroid = state.x[model.quads].mean(axis=1)
    dphi = np.abs(np.angle(np.exp(1j * (np.arctan2(centroid[:, 1], centroid[:, 0]) - phi_cm))))
    patch = layers[-1][(dphi[layers[-1]] < 0.06) & (np.abs(centroid[layers[-1], 2] - cm[2])
                                                     < 0.02)]
    assert 0 < patch.size < layers[-1].size // 4
    assert fragment_row(model, state)["intact_casing_outside"] == 1
    for inner in layers[:-1]:  # the shell and the first ply gone
        state.elem[inner, SL.E_ALIVE] = 0.0
    assert fragment_row(model, state)["intact_casing_outside"] == 1  # the outer ply holds
    # the patch pushed 0.2 m out while still part of its ply is the layer's bulge
    moved = np.unique(model.quads[patch])
    radial = state.x[moved, :2] / np.hypot(*state.x[moved, :2].T)[:, None]
    state.x[moved, :2] += 0.2 * radial
    assert fragment_row(model, state)["outer_layer_bulge_m"] == pytest.approx(0.2, rel=1e-9)
    rest = np.setdiff1d(layers[-1], patch)
    state.elem[rest, SL.E_ALIVE] = 0.0  # the patch alone is left, free of the supports
    row = fragment_row(model, state)
    assert row["intact_casing_outside"] == 0
    assert row["outer_layer_bulge_m"] == 0.0  # debris is not a bulge


def test_a_fragment_past_the_sectors_cut_edge_is_undecided_not_escaped():
    """Beyond a 120° sector's cut edge there is no casing in the model (the rest of the
    ring is missing, not broken): a fragment there is ``fragment_beyond_casing`` and the
    run is undecided, however it moves; inside the sector it is not."""
    import math

    from wovenimpact.results.containment import FRAGMENT, fragment_row

    def turned(model, state, deg):
        """The fragment's nodes of ``state`` turned by ``deg`` about the casing axis."""
        nodes = model.node_sets[FRAGMENT]
        c, s = math.cos(math.radians(deg)), math.sin(math.radians(deg))
        x = state.x.copy()
        x[nodes, 0] = c * state.x[nodes, 0] - s * state.x[nodes, 1]
        x[nodes, 1] = s * state.x[nodes, 0] + c * state.x[nodes, 1]
        return x

    model, state = coarse_two_ply_casing(sector=True)
    nodes = model.node_sets[FRAGMENT]
    centre = model.node_mass[nodes] @ state.x[nodes] / model.node_mass[nodes].sum()
    start = math.degrees(math.atan2(centre[1], centre[0]))
    assert 60.0 < start < 180.0  # the example's sector spans 60°–180°
    assert fragment_row(model, state)["fragment_beyond_casing"] == 0
    state.x = turned(model, state, 175.0 - start)
    assert fragment_row(model, state)["fragment_beyond_casing"] == 0
    state.x = turned(model, state, 200.0 - 175.0)
    assert fragment_row(model, state)["fragment_beyond_casing"] == 1
    h = history([150.0, 70.0], [0.0, 20.0], [0.24, 0.29], [1, 0])
    h["fragment_beyond_casing"] = [0, 1]
    assert containment_outcome(h, R)["outcome"] == "undecided"
    h["fragment_beyond_casing"] = [0, 0]
    assert containment_outcome(h, R)["outcome"] == "escaped"
    # the example's full ring has casing at every angle: its fragment turned to the
    # sector's "beyond" angle (200°) and on round the ring is always covered
    model, state = coarse_two_ply_casing()
    nodes = model.node_sets[FRAGMENT]
    centre = model.node_mass[nodes] @ state.x[nodes] / model.node_mass[nodes].sum()
    state.x = turned(model, state, 200.0 - math.degrees(math.atan2(centre[1], centre[0])))
    for _ in range(4):
        assert fragment_row(model, state)["fragment_beyond_casing"] == 0
        state.x = turned(model, state, 90.0)


def test_decided_since_is_the_start_of_the_last_outcomes_streak():
    """row_outcomes reads each row as containment_outcome would have had the run ended
    there; decided_since gives the outcome of the last row and the first time of the
    unbroken run of rows that read it."""
    from wovenimpact.results.containment import decided_since, row_outcomes

    t = np.arange(10) * 1e-4
    h = history(np.full(10, 100.0), [20, 20, -5, -5, 20, -5, -5, -5, -5, -5],
                np.full(10, 0.26), outside=1)
    h["time_s"] = t
    rows = row_outcomes(h, R)
    assert list(rows[:5]) == ["undecided", "undecided", "contained", "contained", "undecided"]
    for n in range(1, 11):
        part = {k: v[:n] for k, v in h.items()}
        assert rows[n - 1] == containment_outcome(part, R)["outcome"]
    assert decided_since(h, R) == ("contained", t[5])


def test_an_escape_stops_the_run_only_once_the_fragments_speed_has_settled():
    """The stop rule on histories (runs.decision_watch): escaped rows for the whole hold
    are not enough while the fragment is still losing speed (dragging torn plies, as 2
    plies on the 7 mm ring did: 117.7 → 111.5 m/s in the 500 µs after it passed); once
    its speed has stayed within 0.5 % for the hold, the run stops. Contained stops on
    the hold alone; undecided never stops."""

    from wovenimpact.results.containment import (
        CONTAINMENT_COLUMNS,
        EXIT_SPEED_SETTLED,
        speed_settled,
    )
    from wovenimpact.io.history import History
    from wovenimpact.runs import decision_watch

    model, _ = coarse_two_ply_casing()
    watch = decision_watch(model, 500e-6)
    n = 11  # rows 0 … 1 ms, 100 µs apart; escaped (nothing intact outside) from row 1
    t = np.arange(n) * 100e-6

    def read(speed, radial, outside):
        h = History(CONTAINMENT_COLUMNS + ("time_s",))
        for i in range(n):
            h.append({"time_s": t[i], "fragment_speed_m_per_s": speed[i],
                      "fragment_radial_velocity_m_per_s": radial[i],
                      "fragment_cm_radius_m": 0.3, "fragment_max_radius_m": 0.3,
                      "fragment_min_radius_m": 0.2,
                      "intact_casing_outside": outside[i], "fragment_beyond_casing": 0,
                      "outer_layer_bulge_m": 0.0})
        return watch(h)

    out = [1] + [0] * (n - 1)
    falling = np.linspace(150.0, 100.0, n)  # 5 m/s every 100 µs
    assert read(falling, np.full(n, 50.0), out) is None
    settled = np.r_[np.linspace(150.0, 112.0, 5), np.full(n - 5, 111.5)]
    assert read(settled, np.full(n, 50.0), out) == "escaped"
    # within the tolerance counts as settled, just beyond it does not
    tol = EXIT_SPEED_SETTLED * 111.5
    wobble = settled.copy()
    wobble[6] += 0.99 * tol
    assert read(wobble, np.full(n, 50.0), out) == "escaped"
    wobble[6] += 0.02 * tol
    assert read(wobble, np.full(n, 50.0), out) is None
    assert not speed_settled({"time_s": t, "fragment_speed_m_per_s": falling}, t[-1] + 1.0)
    # the summary's flag: the last 500 µs of an escape, None for any other outcome
    from wovenimpact.results.containment import exit_speed_settled

    # Python bools (summary.json carries them: numpy's bool_ ended a run's summary with a
    # TypeError)
    assert exit_speed_settled({"time_s": t, "fragment_speed_m_per_s": settled},
                              "escaped") is True
    assert exit_speed_settled({"time_s": t, "fragment_speed_m_per_s": falling},
                              "escaped") is False
    assert exit_speed_settled({"time_s": t, "fragment_speed_m_per_s": falling},
                              "contained") is None
    # contained (turned back, intact casing outside): stops on the hold, speed or not
    assert read(falling, np.r_[50.0, np.full(n - 1, -5.0)], [1] * n) == "contained"
    assert read(falling, np.full(n, 20.0), [1] * n) is None  # still pushing: undecided


def test_stop_when_decided_ends_the_run_once_the_outcome_has_held(tmp_path, monkeypatch):
    """run.stop_when_decided: the run ends at the first history row at which the
    outcome has read the same for the hold (not at end_time), writes its checkpoint,
    history and summary there, and says so in the summary. The outcome is forced here
    (escaped from 10 µs on: a real casing takes milliseconds to decide) to test the
    stopping alone; row_outcomes has its own tests above."""
    from pathlib import Path

    import wovenimpact.runs as runs
    from wovenimpact.io.history import read_csv

    real = runs.decided_since

    def forced(h, inner, outer):
        assert real(h, inner, outer)[0] == "undecided"  # the real rule before impact
        t = np.asarray(h["time_s"])
        since = t[t >= 10e-6]
        return ("escaped", float(since[0])) if since.size else ("undecided", float(t[0]))

    monkeypatch.setattr(runs, "decided_since", forced)
    case = Path(__file__).resolve().parents[2] / "examples" / "containment" / "hybrid_4.toml"
    out = tmp_path / "out"
    summary = runs.run_case(case, out, overrides=[
        'run.end_time="60 us"', 'mesh.element_size="10 mm"', "mesh.casing.layers=1",
        'run.stop_when_decided="20 us"', 'run.history_interval="2 us"'])
    from wovenimpact.io.checkpoint import checkpoint_meta, latest_checkpoint

    t = read_csv(out / "history.csv")["time_s"]
    assert summary["stopped_when_decided"] == "escaped"
    decided = t[t >= 10e-6][0]  # the first row the forced outcome reads escaped
    assert 30e-6 <= summary["end_time_s"] < 34e-6  # the first row ≥ decided + 20 µs
    assert t[-1] == pytest.approx(summary["end_time_s"], rel=1e-12)
    assert t[-1] >= decided + 20e-6 > t[-2]
    # the last checkpoint is the stop's: it counts every history row written
    assert checkpoint_meta(latest_checkpoint(out / "checkpoints"))["history_rows"] == len(t)


def test_stop_when_decided_on_a_case_without_a_fragment_is_refused(tmp_path):
    from pathlib import Path

    from wovenimpact.errors import InputError
    from wovenimpact.runs import run_case

    case = Path(__file__).resolve().parents[2] / "examples" / "plate_impact" / "plies1_100.toml"
    with pytest.raises(InputError, match="run.stop_when_decided"):
        run_case(case, tmp_path / "out", overrides=['run.stop_when_decided="0.1 ms"'])
    assert not (tmp_path / "out" / "history.csv").exists()


def test_summary_json_takes_numpy_scalars_and_refuses_anything_else():
    """runs._json_scalar, summary.json's fallback: numpy's bool_, float64 and int64 are
    written as Python values (a numpy bool_ once ended a finished containment run with a
    TypeError before its summary was written); an object that is no number is still
    refused, naming its type."""
    import json

    from wovenimpact.runs import _json_scalar

    text = json.dumps({"a": np.bool_(True), "b": np.float64(1.5), "c": np.int64(3)},
                      default=_json_scalar)
    assert json.loads(text) == {"a": True, "b": 1.5, "c": 3}
    with pytest.raises(TypeError, match="object"):
        json.dumps({"d": object()}, default=_json_scalar)


def test_the_casing_mass_per_area_sums_the_layers_areal_masses():
    """The wall's mass per unit area is each layer's areal mass summed through it: the
    1 mm aluminium shell (2.78 kg/m²) and two Kevlar plies (the sections' own areal
    masses) — not the mass over the mean layer area, which weighs the inner shell, at
    the smallest radius, low."""
    from wovenimpact.results.containment import casing_summary, fragment_row
    from wovenimpact.kernels import shell_layout as SL

    model, state = coarse_two_ply_casing()
    h = {k: np.array([v]) for k, v in fragment_row(model, state).items()}
    h["time_s"] = np.array([0.0])
    summary = casing_summary(model, state, h)
    sections = [model.section_names.index(s) for s in ("shell", "fabric", "fabric")]
    expected = sum(float(model.sections[s, SL.C_AREAL_MASS]) for s in sections)
    assert expected == pytest.approx(2.78 + 2 * 0.4775, rel=1e-3)
    assert summary["casing_mass_per_area_kg_per_m2"] == pytest.approx(expected, rel=1e-12)
