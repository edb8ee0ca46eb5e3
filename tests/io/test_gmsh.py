"""Shell meshes from gmsh files (model/gmsh.py) and imported casings: physical groups as
element and node sets, coordinates in the file's length unit, the warp following the
circumference of a cylinder."""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.model.gmsh import read_msh

ROOT = Path(__file__).resolve().parents[2]


def write_cylinder_sector(path: Path, radius=250.0, length=150.0, n_theta=6, n_z=3,
                          sector=np.pi / 3):
    """A cylindrical sector of quads in millimetres, as gmsh writes it: physical surface
    "casing" (tag 1) and physical curves "end_low" and "end_high" (tags 2 and 3) along
    its two ends; one unused geometry point (gmsh keeps them) at the origin."""
    th = np.linspace(-sector / 2, sector / 2, n_theta + 1)
    zs = np.linspace(0.0, length, n_z + 1)
    pts = [[0.0, 0.0, 0.0]]
    pts += [[radius * np.cos(t), radius * np.sin(t), z] for z in zs for t in th]
    pts = np.array(pts)
    idx = 1 + np.arange((n_z + 1) * (n_theta + 1)).reshape(n_z + 1, n_theta + 1)
    quads = np.stack([idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, 1:].ravel(),
                      idx[1:, :-1].ravel()], axis=1)
    low = np.stack([idx[0, :-1], idx[0, 1:]], axis=1)
    high = np.stack([idx[-1, :-1], idx[-1, 1:]], axis=1)
    cells = [("quad", quads), ("line", np.vstack([low, high]))]
    phys = [np.ones(len(quads), int), np.r_[np.full(len(low), 2), np.full(len(high), 3)]]
    mesh = meshio.Mesh(pts, cells, cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys},
                       field_data={"casing": np.array([1, 2]), "end_low": np.array([2, 1]),
                                   "end_high": np.array([3, 1])})
    meshio.write(path, mesh, file_format="gmsh22", binary=False)
    return len(quads), (n_theta + 1) * (n_z + 1)


def test_physical_groups_become_sets_and_unused_points_are_dropped(tmp_path):
    n_quads, n_nodes = write_cylinder_sector(tmp_path / "c.msh")
    mesh = read_msh(tmp_path / "c.msh")
    assert mesh.n_elems == n_quads and mesh.n_nodes == n_nodes
    assert sorted(mesh.elem_sets) == ["casing"]
    assert mesh.elem_sets["casing"].tolist() == list(range(n_quads))
    assert np.allclose(mesh.nodes[mesh.node_sets["end_low"], 2], 0.0)
    assert np.allclose(mesh.nodes[mesh.node_sets["end_high"], 2], 150.0)
    assert len(mesh.node_sets["end_low"]) == 7
    assert np.allclose(np.hypot(mesh.nodes[:, 0], mesh.nodes[:, 1]), 250.0)


def test_a_file_without_physical_groups_or_with_volumes_is_refused(tmp_path):
    pts = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1.0]])
    meshio.write(tmp_path / "a.msh", meshio.Mesh(pts, [("quad", np.array([[0, 1, 2, 3]]))]),
                 file_format="gmsh22", binary=False)
    with pytest.raises(InputError, match="no physical groups"):
        read_msh(tmp_path / "a.msh")
    tet = meshio.Mesh(pts, [("tetra", np.array([[0, 1, 2, 4]]))],
                      cell_data={"gmsh:physical": [np.array([1])],
                                 "gmsh:geometrical": [np.array([1])]})
    meshio.write(tmp_path / "t.msh", tet, file_format="gmsh22", binary=False)
    with pytest.raises(InputError, match=r"\['tetra'\] are not shells"):
        read_msh(tmp_path / "t.msh")
    (tmp_path / "x.msh").write_bytes(b"\x00\x01not a mesh")
    with pytest.raises(InputError, match="not a readable gmsh file"):
        read_msh(tmp_path / "x.msh")


def test_an_imported_casing_in_millimetres_with_circumferential_warp(tmp_path):
    """A case with ``kind = "gmsh"``, ``length_unit = "1 mm"`` and ``warp_direction =
    "circumferential"``: the nodes sit at r = 0.25 m, the element's warp axis e1 is the
    hoop direction at its centroid (to 1e-12), and the curve group clamps the end."""
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.spec.case import load_case

    write_cylinder_sector(tmp_path / "casing.msh")
    kevlar = (ROOT / "examples" / "materials" / "kevlar_thesis.toml").as_posix()
    (tmp_path / "case.toml").write_text(f"""
[case]
name = "imported casing"
[materials]
kevlar = {{ file = "{kevlar}" }}
[sections.fabric]
material = "kevlar"
bending_modulus = "1 GPa"
transverse_shear_modulus = "3.28 GPa"
[mesh]
kind = "gmsh"
file = "casing.msh"
sections = {{ casing = "fabric" }}
length_unit = "1 mm"
warp_direction = "circumferential"
[[boundary]]
nodes = "end_low"
type = "clamped"
[[initial_velocity]]
velocity = ["0 m/s", "0 m/s", "1 m/s"]
[run]
end_time = "1 us"
""")
    spec, base = load_case(tmp_path / "case.toml")
    compiled = compile_case(spec, base)
    model = compiled.model
    assert np.allclose(np.hypot(model.x0[:, 0], model.x0[:, 1]), 0.25, rtol=1e-12)
    x = model.x0[model.quads]
    c = x.mean(axis=1)
    hoop = np.stack([-c[:, 1], c[:, 0], np.zeros(len(c))], axis=1)
    hoop /= np.linalg.norm(hoop, axis=1, keepdims=True)
    # the material frame of every element is the one the hoop direction gives
    from wovenimpact.model.model import material_frame_gradients

    ref = material_frame_gradients(model.x0, model.quads, hoop)[0]
    assert np.allclose(model.ref_grad, ref, atol=1e-12 * np.abs(ref).max())
    axial = material_frame_gradients(model.x0, model.quads, (0.0, 0.0, 1.0))[0]
    assert not np.allclose(model.ref_grad, axial, atol=1e-3 * np.abs(ref).max())
    clamped = compiled.mesh.node_sets["end_low"]
    assert np.all(model.bc_code[clamped] != 0)


def test_an_element_in_two_physical_groups_is_one_element_in_both_sets(tmp_path):
    """gmsh 2.2 writes an element once per physical group it is in: BLADE (tag 1) holds
    two quads and a triangle, RELEASE (tag 2) one quad and the triangle again. They are
    read as three elements (not five: double mass), the sets overlapping."""
    pts = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0], [1, 1, 0], [2, 1, 0],
                    [1, 2, 0.0]])
    q = np.array([[0, 1, 4, 3], [1, 2, 5, 4]])
    t = np.array([[3, 4, 6]])
    cells = [("quad", q), ("triangle", t), ("quad", q[1:]), ("triangle", t)]
    phys = [np.array([1, 1]), np.array([1]), np.array([2]), np.array([2])]
    meshio.write(tmp_path / "d.msh",
                 meshio.Mesh(pts, cells, cell_data={"gmsh:physical": phys,
                                                    "gmsh:geometrical": phys},
                             field_data={"BLADE": np.array([1, 2]),
                                         "RELEASE": np.array([2, 2])}),
                 file_format="gmsh22", binary=False)
    mesh = read_msh(tmp_path / "d.msh")
    assert mesh.quads.tolist() == [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 6, 6]]
    assert mesh.elem_sets["BLADE"].tolist() == [0, 1, 2]
    assert mesh.elem_sets["RELEASE"].tolist() == [1, 2]
    assert mesh.node_sets["RELEASE"].tolist() == [1, 2, 3, 4, 5, 6]


def test_a_missing_set_of_a_gmsh_file_suggests_format_2_2(tmp_path):
    """meshio reads only the first physical group of each entity of a gmsh 4.1 file: the
    error for a set a .msh file lacks says so (and an Abaqus file's does not)."""
    from types import SimpleNamespace

    from wovenimpact.setup.compile import containment_sets

    write_cylinder_sector(tmp_path / "c.msh")
    sets = SimpleNamespace(blade="casing", release="RELEASE", root="end_low",
                           fragment="casing", casing_layers=["casing"])
    with pytest.raises(InputError, match=r"'RELEASE' is not an element set of c\.msh.*"
                                         r"first physical group.*4\.1.*-format msh22"):
        containment_sets(read_msh(tmp_path / "c.msh"), sets, "c.msh")
    with pytest.raises(InputError) as err:
        containment_sets(read_msh(tmp_path / "c.msh"), sets, "c.inp")
    assert "msh22" not in str(err.value)
