"""A rigid body flying sideways (``impactor.axis`` across ``impactor.direction``: a cylinder
whose side strikes as an edge) and the rectangular plate (``mesh.width``) of the
blade-edge strip (examples/strip/blade_edge_strip.toml; docs/theory.md §6, "A body
flying sideways"). Compile-level checks; the dynamics are in
tests/verification/test_contact_impact.py."""

from __future__ import annotations

import copy
import dataclasses
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from tests.corpus.generate import IMPACT, _set
from wovenimpact.errors import InputError
from wovenimpact.impactor import Impactor
from wovenimpact.kernels import rigid_body as RB
from wovenimpact.kernels.bundles import BodyContact, BodyContactOut, ContactNodes
from wovenimpact.kernels.contact_rigid import rigid_contact_forces
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.model.model import RigidBody, flies_sideways, travel_of_row
from wovenimpact.results.quantities import impactor_row, intact_material_ahead, travel_direction
from wovenimpact.setup.compile import compile_case
from wovenimpact.spec.case import case_from_dict
from wovenimpact.spec.fields import read_toml, set_dotted

ROOT = Path(__file__).resolve().parents[2]
STRIP = ROOT / "examples" / "strip" / "blade_edge_strip.toml"
MATERIALS = ROOT / "examples" / "materials"


def strip_doc(**changes) -> dict:
    doc = read_toml(STRIP, "case")
    set_dotted(doc, "mesh.element_size", "7 mm")
    for key, value in changes.items():
        set_dotted(doc, key.replace("__", "."), value)
    return doc


def compiled(doc: dict, base: Path = STRIP.parent):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        spec = case_from_dict(doc, source="strip.toml")
        return spec, compile_case(spec, base)


def check_refused(doc: dict, *fragments: str) -> str:
    with pytest.raises(InputError) as err:
        compiled(doc)
    text = str(err.value)
    for f in fragments:
        assert f in text, text
    return text


# --- the rectangular plate -----------------------------------------------------------


@pytest.mark.parametrize("quarter", [True, False])
def test_a_rectangle_has_its_own_count_along_each_side_and_its_edge_sets(quarter):
    """150 × 40 mm at 10 mm: round(7.5) = 8 and round(2) = 2 elements along the quarter's
    sides (twice that in the full plate); edge_x holds the nodes of the ends x = ±75 mm,
    edge_y those of y = ±20 mm, edge_outer both; the areas sum to the rectangle's."""
    m = plate_mesh(0.15, 0.01, quarter=quarter, width=0.04)
    k = 1 if quarter else 2
    nx, ny = 8 * k, 2 * k
    assert m.n_elems == nx * ny and m.n_nodes == (nx + 1) * (ny + 1)
    x, y = m.nodes[:, 0], m.nodes[:, 1]
    assert x.max() == 0.075 and y.max() == 0.02
    assert x.min() == (0.0 if quarter else -0.075) and y.min() == (0.0 if quarter else -0.02)
    assert np.all(np.abs(x[m.node_sets["edge_x"]]) == 0.075)
    assert np.all(np.abs(y[m.node_sets["edge_y"]]) == 0.02)
    assert m.node_sets["edge_x"].size == k * (ny + 1) and m.node_sets["edge_y"].size == k * (nx + 1)
    outer = np.union1d(m.node_sets["edge_x"], m.node_sets["edge_y"])
    assert np.array_equal(m.node_sets["edge_outer"], outer)
    assert m.area_vectors()[:, 2].sum() == pytest.approx(0.15 * 0.04 / (4 if quarter else 1),
                                                         rel=1e-12)
    assert np.all(m.area_vectors()[:, 2] > 0.0)  # counter-clockwise seen from +z
    centre = m.nodes[m.node_sets["centre"]]
    assert centre.tolist() == [[0.0, 0.0, 0.0]]


@pytest.mark.parametrize("quarter", [True, False])
def test_a_square_given_its_width_is_the_square_of_before(quarter):
    """width = side builds the same arrays as no width (the square generator), and the
    square's edge sets split its edge_outer."""
    a = plate_mesh(0.1, 0.013, plies=2, spacing=1e-3, quarter=quarter)
    b = plate_mesh(0.1, 0.013, plies=2, spacing=1e-3, quarter=quarter, width=0.1)
    assert np.array_equal(a.nodes, b.nodes) and np.array_equal(a.quads, b.quads)
    assert a.node_sets.keys() == b.node_sets.keys()
    for name in a.node_sets:
        assert np.array_equal(a.node_sets[name], b.node_sets[name])


@pytest.mark.parametrize("key, value, fragments", [
    ("mesh.width", "40", ("mesh.width", "has no unit")),
    ("mesh.width", "3 mm", ("mesh.element_size", "half of mesh.width")),
    ("mesh.width", "-3 mm", ("mesh.width",)),
    ("impactor.axis", [0, 0.1, 1], ("impactor.axis", "not perpendicular",
                                    "impactor.direction")),
    ("impactor.axis", [0, 0, 0], ("impactor.axis", "non-zero")),
])
def test_bad_widths_and_axes_are_refused_naming_the_key(key, value, fragments):
    check_refused(strip_doc(**{key.replace(".", "__"): value}), *fragments)


# --- the body's frame ----------------------------------------------------------------


def test_a_sideways_body_has_its_axis_across_and_its_travel_as_second_axis():
    """Cylinder 50 mm long along +y from its tip, travelling along −z at 150 m/s: the
    rotation's columns are the axis, the travel and axis × travel (orthonormal), the
    centre of mass is half the length along the axis from the tip, the velocity is
    the speed along the travel, and travel_of_row reads the travel back."""
    body = RigidBody(Impactor("cylinder", 2.49e-3, 0.05), tip=(0.0, -0.025, 5e-3),
                     direction=(0.0, 0.0, -2.0), speed=150.0, axis=(0.0, 3.0, 0.0))
    params, profile, state = body.pack()
    rot = state[RB.B_R:RB.B_R + 9].reshape(3, 3)
    assert np.allclose(rot.T @ rot, np.eye(3), atol=1e-15)
    assert rot[:, 0].tolist() == [0.0, 1.0, 0.0] and rot[:, 1].tolist() == [0.0, 0.0, -1.0]
    assert np.allclose(rot[:, 2], np.cross(rot[:, 0], rot[:, 1]))
    assert state[RB.B_X:RB.B_X + 3] == pytest.approx([0.0, 0.0, 5e-3], abs=1e-15)
    assert params[RB.BP_TIP] == pytest.approx(0.025, rel=1e-9)
    assert state[RB.B_V:RB.B_V + 3].tolist() == [0.0, 0.0, -150.0]
    assert body.travel_in_body == (0.0, 1.0, 0.0)
    with pytest.raises(InputError, match="not perpendicular"):
        RigidBody(Impactor("cylinder", 1e-3, 0.01), tip=(0, 0, 0), direction=(0, 0, -1),
                  axis=(0.0, 1.0, 1e-6)).pack()


def test_a_nose_first_body_compiles_and_digests_as_before_the_key():
    """Without impactor.axis the travel is −(the body's axis), the same array as the
    expression used before the key, and the Model's digest does not see the new field (a
    checkpoint of a run made before the key is still resumed); with it, the digest does."""
    spec, c = compiled(_set(copy.deepcopy(IMPACT), "materials",
                            {"kevlar": str(MATERIALS / "kevlar_thesis.toml")}), ROOT)
    model = c.model
    assert model.body_travel.tolist() == [[-1.0, 0.0, 0.0]]
    row = model.body_state0[0]
    assert np.array_equal(travel_of_row(model, row), -row[RB.B_R:RB.B_R + 9].reshape(3, 3)[:, 0])
    bare = dataclasses.replace(model, body_travel=np.zeros((0, 3)))
    assert bare.digest() == model.digest()
    _, strip = compiled(strip_doc())
    assert strip.model.body_travel.tolist() == [[0.0, 1.0, 0.0]]
    assert dataclasses.replace(strip.model, body_travel=np.zeros((0, 3))).digest() != \
        strip.model.digest()


def test_the_strip_example_strikes_with_the_side_of_its_edge():
    """The example compiles into a quarter strip (5 layers, the aluminium on top) and a
    quarter of a 0.1615 kg cylinder travelling along −z at 150 m/s, its lowest line
    0.25 mm above the aluminium's surface; the run's impactor row reads 150 m/s along
    the travel."""
    spec, c = compiled(strip_doc())
    model, state = c.model, c.state
    p = model.body_params[0]
    assert p[RB.BP_MASS] == pytest.approx(0.1615 / 4, rel=1e-12) and p[RB.BP_FRACTION] == 0.25
    assert travel_direction(model, state).tolist() == [0.0, 0.0, -1.0]
    assert impactor_row(model, state)["impactor_velocity_m_per_s"] == pytest.approx(150.0)
    top = model.x0[model.node_sets["ply4"], 2].max() + model.node_offset[model.node_sets["ply4"]].max()
    lowest = state.bodies[0, RB.B_X + 2] - 2.49e-3
    assert lowest - top == pytest.approx(0.25e-3, abs=1e-7)


# --- contact with the side -----------------------------------------------------------


def test_the_side_of_a_cylinder_pushes_nodes_out_along_its_radius():
    """A cylinder of radius R lying along y (tip at y = 0, length 10 mm), its axis at
    z = R + 0.1 mm: nodes with offset h = 0.25 mm at z = 0 under it at x = 0 and
    x = 0.5 mm are within h of its side and pushed along (x, z − z_c)/|…| by
    k (h − d); a node beyond its end face (y = 12 mm) and one beside it (x = 4 mm)
    get nothing."""
    r = 2e-3
    prof = Impactor("cylinder", r, 0.01).profile()
    zc = r + 0.1e-3
    tip, axis = np.array([0.0, 0.0, zc]), np.array([0.0, 1.0, 0.0])
    x = np.array([[0.0, 5e-3, 0.0], [0.5e-3, 5e-3, 0.0], [0.0, 12e-3, 0.0],
                  [4e-3, 5e-3, 0.0]])
    n = len(x)
    force, energy, zero = np.zeros((n, 3)), np.zeros(n), np.zeros(3)
    # k = β m / Δt² = 1e6 N/m with β = 1, m = 1 kg, Δt = 1 ms; no dashpot, no friction
    nodes = ContactNodes(x=x, v=np.zeros((n, 3)), active=np.ones(n, np.int8), mass=np.ones(n),
                         offset=np.full(n, 0.25e-3))
    body = BodyContact(tip=tip, axis=axis, velocity=zero, spin=zero, centre=zero,
                       prof_z=prof[:, 0], prof_r=prof[:, 1], reach=0.02, mass=1e30, beta=1.0,
                       zeta=0.0, mu=0.0)
    rigid_contact_forces(nodes, body, 1e-3, BodyContactOut(
        force=force, energy=energy, parts=np.zeros((n, 11)),
        contact_list=np.zeros(n, dtype=np.int64)))
    for i in (0, 1):
        rel = np.array([x[i, 0], 0.0, x[i, 2] - zc])
        d = np.linalg.norm(rel) - r
        assert force[i] == pytest.approx(1e6 * (0.25e-3 - d) * rel / np.linalg.norm(rel),
                                         rel=1e-9, abs=1e-9)
    assert force[2].tolist() == [0.0, 0.0, 0.0] and force[3].tolist() == [0.0, 0.0, 0.0]


# --- checks before the run and the outcome --------------------------------------------


def test_a_sideways_body_in_a_quarter_model_must_be_symmetric_about_both_planes():
    """Its middle (tip + length/2 along the axis) on the z axis and its axis along x or
    y; the example (middle at y = 0) compiles, its cylinder moved 5 mm along y does not;
    an axis along x through the origin's middle compiles too."""
    check_refused(strip_doc(impactor__position=["0 mm", "-20 mm", "5.4871 mm"]), "quarter model",
            "symmetric")
    check_refused(strip_doc(impactor__axis=[0, 1, 1e-3]), "impactor.axis")
    check_refused(strip_doc(impactor__axis=[1, 1, 0], impactor__position=["0 mm", "0 mm", "5.4871 mm"]),
            "quarter model")
    _, along_x = compiled(strip_doc(impactor__axis=[1, 0, 0],
                                    impactor__position=["-25 mm", "0 mm", "5.4871 mm"]))
    assert along_x.model.body_params.shape[0] == 1 and flies_sideways(along_x.model)


def full_strip(**changes) -> dict:
    doc = strip_doc(mesh__quarter=False, **changes)
    doc["boundary"] = [b for b in doc["boundary"] if not b["type"].startswith("symmetry")]
    return doc


def test_a_sideways_path_that_misses_the_strip_is_refused():
    """The full strip (y within ±20 mm): a 50 mm edge from y = 30 mm passes beside it;
    travelling away (+z) the strip is behind it; the example's path (y from −25 mm)
    meets it."""
    _, example = compiled(full_strip())
    assert example.model.body_params.shape[0] == 1 and flies_sideways(example.model)
    check_refused(full_strip(impactor__position=["0 mm", "30 mm", "5.4871 mm"]), "misses",
            "no node lies within")
    check_refused(full_strip(impactor__direction=[0, 0, 1]), "misses", "behind the nose")


def test_intact_material_ahead_is_read_in_the_edge_s_shadow():
    """At t = 0 the far surface of the lowest ply is 2.9971 + 0.2496 mm below the edge's
    leading line (its lowest line, R below its axis); moved 10 mm down the edge is past
    every layer; moved along x over the next column of nodes it is not, between two
    columns (7 mm mesh: none within R + h of its line) nothing is ahead of it, nor when
    shifted beside the full strip in y."""
    spec, c = compiled(strip_doc())
    model, state = c.model, c.state
    h = model.node_offset[model.node_sets["ply0"]].max()
    r = intact_material_ahead(model, state)
    assert r["intact_material_ahead"] == 1
    assert r["impactor_nose_ahead_of_intact_m"] == pytest.approx(-(2.9971e-3 + h), abs=1e-9)
    st = copy.deepcopy(state)
    st.bodies[0, RB.B_X + 2] -= 0.010
    r = intact_material_ahead(model, st)
    assert r["intact_material_ahead"] == 0
    assert r["impactor_nose_ahead_of_intact_m"] == pytest.approx(0.010 - 2.9971e-3 - h, abs=1e-9)
    st = copy.deepcopy(state)
    column = np.unique(model.x0[:, 0])[1]  # the next column of nodes (6.8 mm)
    st.bodies[0, RB.B_X] += column
    assert intact_material_ahead(model, st)["intact_material_ahead"] == 1
    st.bodies[0, RB.B_X] += 0.5 * column  # between two columns: no node in its shadow
    assert intact_material_ahead(model, st)["intact_material_ahead"] == 0
    _, full = compiled(full_strip())
    st = copy.deepcopy(full.state)
    st.bodies[0, RB.B_X + 1] += 0.075  # the edge now spans y = 50 … 100 mm
    r = intact_material_ahead(full.model, st)
    assert r == {"impactor_nose_ahead_of_intact_m": math.inf, "intact_material_ahead": 0}
