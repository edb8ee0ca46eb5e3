"""model/mesh.py: structured plate meshes, their sets and orientation, and distortion."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.model.mesh import Mesh, boundary_nodes, distort, plate_mesh

SIDE = 0.1  # m


def on(mesh: Mesh, name: str) -> np.ndarray:
    return mesh.nodes[mesh.node_sets[name]]


@pytest.mark.parametrize(("quarter", "h", "n_edge"), [(False, 0.01, 10), (True, 0.01, 5),
                                                      (False, 0.0105, 10), (True, 0.009, 6)])
def test_counts(quarter, h, n_edge):
    m = plate_mesh(SIDE, h, quarter=quarter)
    assert m.n_elems == n_edge**2
    assert m.n_nodes == (n_edge + 1) ** 2
    assert m.quads.dtype == np.int64 and m.ply.dtype == np.int64


def test_full_plate_uses_an_even_count_so_a_node_is_at_the_centre():
    m = plate_mesh(SIDE, SIDE / 7)  # round(7) is odd: the full plate takes 2 × round(3.5)
    assert m.n_elems == 8**2
    assert on(m, "centre").tolist() == [[0.0, 0.0, 0.0]]


def test_element_size_equal_to_side_gives_one_element_per_quarter_edge():
    assert plate_mesh(SIDE, SIDE, quarter=True).n_elems == 1
    assert plate_mesh(SIDE, SIDE).n_elems == 4


@pytest.mark.parametrize(("quarter", "area"), [(False, SIDE**2), (True, SIDE**2 / 4)])
def test_areas_sum_to_the_plate_area_per_ply(quarter, area):
    m = plate_mesh(SIDE, 0.013, plies=3, spacing=1e-3, quarter=quarter)
    a = m.area_vectors()
    for k in range(3):
        assert a[m.elem_sets[f"ply{k}"], 2].sum() == pytest.approx(area, rel=1e-12)


def test_counter_clockwise_seen_from_plus_z():
    a = plate_mesh(SIDE, 0.01, plies=2, spacing=1e-3).area_vectors()
    assert np.all(a[:, 2] > 0) and np.all(a[:, :2] == 0)


def test_extent_and_ply_planes():
    m = plate_mesh(SIDE, 0.01, plies=3, spacing=2e-3, z0=-1e-3)
    assert m.nodes[:, 0].min() == -SIDE / 2 and m.nodes[:, 0].max() == SIDE / 2
    assert m.nodes[:, 1].min() == -SIDE / 2 and m.nodes[:, 1].max() == SIDE / 2
    for k in range(3):
        z = m.nodes[m.node_sets[f"ply{k}"], 2]
        assert np.all(z == -1e-3 + k * 2e-3)
        assert np.all(m.ply[m.elem_sets[f"ply{k}"]] == k)
        # each ply uses its own nodes only
        assert set(np.unique(m.quads[m.elem_sets[f"ply{k}"]])) == set(m.node_sets[f"ply{k}"])
    q = plate_mesh(SIDE, 0.01, quarter=True)
    assert q.nodes[:, :2].min() == 0.0 and q.nodes[:, :2].max() == SIDE / 2


def test_full_plate_node_sets():
    m = plate_mesh(SIDE, 0.01, plies=2, spacing=1e-3)
    edge = on(m, "edge_outer")
    half = SIDE / 2
    assert np.all(np.isclose(np.abs(edge[:, :2]), half, rtol=0, atol=0).any(axis=1))
    assert len(edge) == 2 * 4 * 10
    assert "symmetry_x" not in m.node_sets and "symmetry_y" not in m.node_sets
    assert on(m, "centre").tolist() == [[0.0, 0.0, 0.0], [0.0, 0.0, 1e-3]]
    assert m.node_sets["all"].tolist() == list(range(m.n_nodes))
    assert m.elem_sets["all"].tolist() == list(range(m.n_elems))


def test_quarter_model_node_sets():
    m = plate_mesh(SIDE, 0.01, quarter=True)
    half = SIDE / 2
    edge = on(m, "edge_outer")
    assert np.all((edge[:, 0] == half) | (edge[:, 1] == half)) and len(edge) == 2 * 6 - 1
    assert np.all(on(m, "symmetry_x")[:, 0] == 0.0) and len(m.node_sets["symmetry_x"]) == 6
    assert np.all(on(m, "symmetry_y")[:, 1] == 0.0) and len(m.node_sets["symmetry_y"]) == 6
    assert on(m, "centre").tolist() == [[0.0, 0.0, 0.0]]
    # the sets are exactly the nodes on those lines
    x, y = m.nodes[:, 0], m.nodes[:, 1]
    assert set(m.node_sets["edge_outer"]) == set(np.flatnonzero((x == half) | (y == half)))
    assert set(m.node_sets["symmetry_x"]) == set(np.flatnonzero(x == 0.0))


def test_full_plate_is_symmetric_about_the_centre():
    x = np.unique(plate_mesh(SIDE, 0.007).nodes[:, 0])
    assert np.array_equal(x, -x[::-1])


@pytest.mark.parametrize(
    ("kwargs", "words"),
    [
        ({"side": 0.0, "element_size": 0.01}, ["side = 0.0", "> 0"]),
        ({"side": -1.0, "element_size": 0.01}, ["side = -1.0"]),
        ({"side": math.nan, "element_size": 0.01}, ["side = nan"]),
        ({"side": 0.1, "element_size": 0.0}, ["element_size = 0.0", "0 < element_size ≤ side"]),
        ({"side": 0.1, "element_size": 0.2}, ["element_size = 0.2", "side (0.1 m)"]),
        ({"side": 0.1, "element_size": 0.01, "plies": 0}, ["plies = 0", "≥ 1"]),
        ({"side": 0.1, "element_size": 0.01, "plies": 1.5}, ["plies = 1.5"]),
        ({"side": 0.1, "element_size": 0.01, "plies": 2}, ["spacing = 0.0", "plies = 2", "> 0"]),
        ({"side": 0.1, "element_size": 0.01, "plies": 2, "spacing": -1e-3}, ["spacing = -0.001"]),
    ],
)
def test_invalid_arguments(kwargs, words):
    with pytest.raises(InputError) as err:
        plate_mesh(**kwargs)
    for w in words:
        assert w in str(err.value)


def test_single_ply_needs_no_spacing():
    assert plate_mesh(SIDE, 0.05, plies=1, spacing=0.0).n_elems == 4


def test_mesh_validates_shapes_and_indices():
    with pytest.raises(InputError, match=r"\(m, 4\)"):
        Mesh(nodes=np.zeros((3, 3)), quads=np.zeros((1, 3)), ply=[0])
    with pytest.raises(InputError, match="node 7"):
        Mesh(nodes=np.zeros((4, 3)), quads=[[0, 1, 2, 7]], ply=[0])
    with pytest.raises(InputError, match="node set 'top'"):
        Mesh(nodes=np.zeros((4, 3)), quads=[[0, 1, 2, 3]], ply=[0], node_sets={"top": [9]})


def test_distort_moves_interior_nodes_only_within_the_amplitude():
    m = plate_mesh(SIDE, 0.01, quarter=True)
    d = distort(m, 0.2, seed=3)
    moved = np.linalg.norm(d.nodes - m.nodes, axis=1)
    boundary = boundary_nodes(m.quads)
    assert np.all(moved[boundary] == 0.0)
    interior = np.setdiff1d(np.arange(m.n_nodes), boundary)
    assert np.all(moved[interior] > 0.0) and moved.max() <= 0.2 * 0.01 * (1 + 1e-12)
    assert np.all(d.nodes[:, 2] == m.nodes[:, 2])
    assert d.area_vectors()[:, 2].sum() == pytest.approx(SIDE**2 / 4, rel=1e-12)
    assert np.array_equal(distort(m, 0.2, seed=3).nodes, d.nodes)
    assert not np.array_equal(distort(m, 0.2, seed=4).nodes, d.nodes)


def test_distort_keeps_quads_convex():
    d = distort(plate_mesh(SIDE, 0.01), 0.249, seed=0)
    xe = d.nodes[d.quads][:, :, :2]
    a = np.roll(xe, -1, axis=1) - xe
    b = np.roll(a, -1, axis=1)
    assert np.all(a[:, :, 0] * b[:, :, 1] - a[:, :, 1] * b[:, :, 0] > 0)


@pytest.mark.parametrize("amplitude", [-0.1, 0.25, math.nan])
def test_distort_rejects_amplitudes(amplitude):
    with pytest.raises(InputError, match="amplitude"):
        distort(plate_mesh(SIDE, 0.01), amplitude, seed=0)


def test_distort_needs_a_single_ply():
    with pytest.raises(InputError, match="single-ply"):
        distort(plate_mesh(SIDE, 0.01, plies=2, spacing=1e-3), 0.1, seed=0)
