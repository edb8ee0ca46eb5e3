"""io/fields.py: VTU frames of a plate model and the ParaView collection that lists them."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.io.fields import PVD_NAME, FieldWriter, cell_blocks, read_pvd
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import j2_layout as J
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.model import Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.state import initial_state

STEEL = MetalParameters(name="steel", kind="elastic", density=7850.0, modulus=210e9, poisson=0.3)


@pytest.fixture
def model():
    m = plate_mesh(0.04, 0.01, plies=2, spacing=1e-3, quarter=True)
    return build_model(m.nodes, m.quads, {"plate": Section(material=STEEL, thickness=1e-3)},
                       np.zeros(len(m.quads), dtype=np.int64), ply=m.ply)


def moved(model, k: int):
    s = initial_state(model)
    rng = np.random.default_rng(k)
    s.t, s.step = k * 1e-6, 10 * k
    s.x = model.x0 + 1e-4 * rng.standard_normal(model.x0.shape)
    s.v = rng.standard_normal(model.x0.shape)
    s.elem[:, SL.E_N:SL.E_N + 3] = rng.standard_normal((model.n_elems, 3))
    s.elem[k % model.n_elems, SL.E_ALIVE] = 0.0
    return s


def pvd_entries(path):
    root = ET.parse(path).getroot()
    assert root.tag == "VTKFile" and root.attrib["type"] == "Collection"
    return [(float(d.attrib["timestep"]), d.attrib["file"]) for d in root.iter("DataSet")]


def test_three_frames_read_back(tmp_path, model):
    w = FieldWriter(tmp_path / "out", model)
    states = [moved(model, k) for k in range(3)]
    paths = [w.write(s) for s in states]
    assert [p.name for p in paths] == ["step_000000.vtu", "step_000001.vtu", "step_000002.vtu"]
    for s, p in zip(states, paths):
        m = meshio.read(p)
        assert len(m.cells) == 1 and m.cells[0].type == "quad"
        assert np.array_equal(m.cells[0].data, model.quads)
        assert np.array_equal(m.points, s.x)
        assert np.array_equal(m.point_data["displacement"], s.x - model.x0)
        assert np.array_equal(m.point_data["velocity"], s.v)
        cd = {k: v[0] for k, v in m.cell_data.items()}
        assert np.array_equal(cd["membrane_resultant"], s.elem[:, SL.E_N:SL.E_N + 3])
        assert np.array_equal(cd["alive"], s.elem[:, SL.E_ALIVE])
        assert np.array_equal(cd["ply"], model.ply)
        for name in ("tension_warp", "tension_fill", "damage_warp", "damage_fill"):
            assert np.all(cd[name] == 0.0), name  # steel: not a fabric
    entries = pvd_entries(tmp_path / "out" / PVD_NAME)
    assert [f for _, f in entries] == [p.name for p in paths]
    times = [t for t, _ in entries]
    assert times == [s.t for s in states] and times == sorted(set(times))


def test_explicit_time_and_no_going_back(tmp_path, model):
    w = FieldWriter(tmp_path, model)
    w.write(moved(model, 1), time=5e-6)
    assert w.entries == ((5e-6, "step_000000.vtu"),)
    with pytest.raises(InputError, match="before the last"):
        w.write(moved(model, 2), time=4e-6)


def test_resume_drops_later_frames(tmp_path, model):
    """A restart whose checkpoint counted 2 frames keeps those, deletes the later ones and
    numbers the next frame 2."""
    w = FieldWriter(tmp_path, model)
    for k in range(4):
        w.write(moved(model, k))
    r = FieldWriter.resume(tmp_path, model, frames=2)
    assert [f for _, f in r.entries] == ["step_000000.vtu", "step_000001.vtu"]
    assert not (tmp_path / "step_000002.vtu").exists()
    assert pvd_entries(tmp_path / PVD_NAME) == list(r.entries)
    r.write(moved(model, 2))
    assert [f for _, f in read_pvd(tmp_path / PVD_NAME)] == [
        "step_000000.vtu", "step_000001.vtu", "step_000002.vtu"]


def test_resume_refuses_a_series_shorter_than_the_checkpoints(tmp_path, model):
    """fields.pvd gone, or listing fewer frames than the checkpoint counted, or a counted
    frame file gone: resuming would overwrite or lose frames, so it is refused and the
    frames on disk are left alone."""
    w = FieldWriter(tmp_path, model)
    for k in range(3):
        w.write(moved(model, k))
    with pytest.raises(InputError, match="lists 3 frames, the checkpoint counts 4"):
        FieldWriter.resume(tmp_path, model, frames=4)
    (tmp_path / "step_000001.vtu").unlink()
    with pytest.raises(InputError, match="step_000001.vtu .* is missing"):
        FieldWriter.resume(tmp_path, model, frames=3)
    (tmp_path / PVD_NAME).unlink()
    with pytest.raises(InputError, match="lists 0 frames"):
        FieldWriter.resume(tmp_path, model, frames=2)
    assert (tmp_path / "step_000002.vtu").exists()


def test_corrupt_collection_is_named(tmp_path, model):
    (tmp_path / PVD_NAME).write_text("<VTKFile><Collection>")
    with pytest.raises(InputError, match="fields.pvd"):
        FieldWriter.resume(tmp_path, model, frames=0)


def test_fabric_columns_come_from_the_material_state(tmp_path, model, kevlar):
    mesh = plate_mesh(0.02, 0.01)
    sections = {"steel": Section(material=STEEL, thickness=1e-3),
                "fabric": Section(material=kevlar, bending_modulus=1e9,
                                  transverse_shear_modulus=3.28e9)}
    which = np.array(["steel", "fabric", "fabric", "steel"])
    fm = build_model(mesh.nodes, mesh.quads, sections, which)
    s = initial_state(fm)
    first = fm.mat_row[:-1]  # each element's first point's material row
    s.mat[first, FL.S_TENSION:FL.S_TENSION + 2] = [[1.0, 2.0], [3.0, 4.0], [5.0, 6.0],
                                                   [7.0, 8.0]]
    s.mat[first, FL.S_DAMAGE:FL.S_DAMAGE + 2] = 0.5
    cd = {k: v[0] for k, v in meshio.read(FieldWriter(tmp_path, fm).write(s)).cell_data.items()}
    assert cd["tension_warp"].tolist() == [0.0, 3.0, 5.0, 0.0]
    assert cd["tension_fill"].tolist() == [0.0, 4.0, 6.0, 0.0]
    assert cd["damage_warp"].tolist() == [0.0, 0.5, 0.5, 0.0]
    assert cd["damage_fill"].tolist() == [0.0, 0.5, 0.5, 0.0]


ALUMINIUM = MetalParameters(name="al", kind="j2_plastic", density=2780.0, modulus=72e9,
                            poisson=0.32, hardening=((0.0, 78e6), (0.18, 214e6)))


def test_metal_and_integrated_fabric_columns_in_one_model(tmp_path, kevlar):
    """Fabric integrated through the thickness (3 points) beside a J2 metal (5 points):
    a point's row of State.mat is then Model.point_width wide (the wider of the two kinds'
    state vectors), and the fabric columns
    come from the mid-level point's row; a metal element's plastic_strain is the largest ε̄p of
    its points and its thickness_ratio the Simpson-weighted λ3 (1/12, 4/12, 2/12, 4/12,
    1/12); a fabric element has 0 and 1, a metal one at rest 0 and 1."""
    mesh = plate_mesh(0.02, 0.01)
    sections = {"al": Section(material=ALUMINIUM, thickness=1e-3),
                "fabric": Section(material=kevlar, transverse_shear_modulus=3.28e9, points=3)}
    fm = build_model(mesh.nodes, mesh.quads, sections, np.array(["al", "fabric", "fabric", "al"]))
    w = fm.point_width
    assert w == max(J.N_STATE, FL.N_STATE)
    s = initial_state(fm)
    assert s.mat.shape[1] == w
    s.mat[fm.mat_row[1:3] + 1, FL.S_TENSION] = [3.0, 5.0]  # level 1 of 3: the mid-surface
    s.mat[fm.mat_row[0] + np.arange(5), J.S_EPS_P] = [0.01, 0.02, 0.05, 0.02, 0.01]
    s.mat[fm.mat_row[0] + np.arange(5), J.S_THICK] = [0.9, 0.96, 1.0, 0.96, 0.9]
    cd = {k: v[0] for k, v in meshio.read(FieldWriter(tmp_path, fm).write(s)).cell_data.items()}
    assert cd["tension_warp"].tolist() == [0.0, 3.0, 5.0, 0.0]
    assert cd["plastic_strain"].tolist() == [0.05, 0.0, 0.0, 0.0]
    assert cd["thickness_ratio"][0] == pytest.approx((0.9 + 4 * 0.96 + 2 + 4 * 0.96 + 0.9) / 12)
    assert cd["thickness_ratio"][1:3].tolist() == [1.0, 1.0]  # fabric
    assert cd["thickness_ratio"][3] == pytest.approx(1.0, rel=1e-15)  # metal at rest


def test_triangles_go_to_their_own_block(tmp_path):
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 2, 0]], dtype=float)
    quads = np.array([[0, 1, 2, 3], [3, 2, 4, 4]])
    blocks = cell_blocks(quads)
    assert [(k, i.tolist(), c.tolist()) for k, i, c in blocks] == [
        ("quad", [0], [[0, 1, 2, 3]]), ("triangle", [1], [[3, 2, 4]])]
    tm = build_model(nodes, quads, {"p": Section(material=STEEL, thickness=1e-3)}, [0, 0])
    s = initial_state(tm)
    s.elem[1, SL.E_N] = 9.0
    m = meshio.read(FieldWriter(tmp_path, tm).write(s))
    assert [b.type for b in m.cells] == ["quad", "triangle"]
    assert m.cell_data["element"][1].tolist() == [1]
    assert m.cell_data["membrane_resultant"][1][0, 0] == 9.0


@pytest.mark.parametrize("quads, types", [
    ([[0, 1, 2, 3], [3, 2, 4, 4]], ["quad", "triangle"]),
    ([[0, 1, 2, 2], [0, 2, 3, 3], [3, 2, 4, 4]], ["triangle"]),
    ([[0, 1, 2, 3]], ["quad"]),
])
def test_triangle_only_quad_only_and_mixed_meshes_write_readable_files(tmp_path, quads, types):
    """No empty cell block is written (meshio's VTU writer fails on one), whole model or
    one part at a time: a part of triangles only has just its triangle block."""
    nodes = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 2, 0]], dtype=float)
    quads = np.array(quads)
    tm = build_model(nodes, quads, {"p": Section(material=STEEL, thickness=1e-3)},
                     np.zeros(len(quads), dtype=np.int64))
    m = meshio.read(FieldWriter(tmp_path / "all", tm).write(initial_state(tm)))
    assert [b.type for b in m.cells] == types
    assert sum(len(b.data) for b in m.cells) == len(quads)
    assert np.sort(np.concatenate(m.cell_data["element"])).tolist() == list(range(len(quads)))
    last = [("rest", np.arange(len(quads) - 1)), ("last", [len(quads) - 1])]
    w = FieldWriter(tmp_path / "parts", tm, parts=last[1:] if len(quads) == 1 else last)
    w.write(initial_state(tm))
    m = meshio.read(tmp_path / "parts" / "step_000000_last.vtu")
    assert [(b.type, len(b.data)) for b in m.cells] == [(types[-1], 1)]


def test_parts_are_blocks_of_each_frame_and_resume_by_frame(tmp_path, model):
    """A series in two parts (the plies here): each frame is a file per part with that
    part's nodes and elements only, listed in fields.pvd with its part index; a restart
    counts frames, not files, keeps both files of the kept frames and deletes both of
    the later ones."""
    parts = [("lower", np.flatnonzero(model.ply == 0)), ("upper", np.flatnonzero(model.ply == 1))]
    w = FieldWriter(tmp_path, model, parts=parts)
    states = [moved(model, k) for k in range(3)]
    for s in states:
        w.write(s)
    assert w.frames == 3 and len(w.entries) == 6
    root = ET.parse(tmp_path / PVD_NAME).getroot()
    assert [(d.attrib["file"], d.attrib["part"]) for d in root.iter("DataSet")][:2] == [
        ("step_000000_lower.vtu", "0"), ("step_000000_upper.vtu", "1")]
    for name, elems in parts:
        m = meshio.read(tmp_path / f"step_000002_{name}.vtu")
        ids = np.concatenate(m.cell_data["element"])
        assert np.array_equal(np.sort(ids), elems)
        nodes = np.unique(model.quads[elems])
        assert np.allclose(m.points, states[2].x[nodes])  # its own nodes, in order
        # each cell's points are its element's nodes
        conn = np.concatenate([c.data for c in m.cells])
        assert np.allclose(m.points[conn], states[2].x[model.quads[ids]])
    r = FieldWriter.resume(tmp_path, model, frames=2, parts=parts)
    assert r.frames == 2
    assert not (tmp_path / "step_000002_lower.vtu").exists()
    assert not (tmp_path / "step_000002_upper.vtu").exists()
    r.write(states[2])
    assert [f for _, f in read_pvd(tmp_path / PVD_NAME)][-2:] == [
        "step_000002_lower.vtu", "step_000002_upper.vtu"]
    with pytest.raises(InputError, match="lists 3 frames, the checkpoint counts 4"):
        FieldWriter.resume(tmp_path, model, frames=4, parts=parts)


def test_von_mises_and_stress_of_a_stepped_metal_plate_and_zero_on_fabric(tmp_path, kevlar):
    """A small aluminium (J2, 5 points through the thickness) and fabric plate struck at
    its middle and stepped 40 times: each metal cell's ``von_mises_stress`` is
    √(σxx² − σxxσyy + σyy² + 3σxy²) of its ``stress`` cell array, as read back from the VTU,
    and the largest such value over the element's points computed here from State.mat (the
    kernel's stress); the metal is loaded (some stress above 1 MPa); fabric cells have 0."""
    from wovenimpact.solver import Workspace, step

    mesh = plate_mesh(0.02, 0.005)
    n = len(mesh.quads)
    which = np.where(np.arange(n) % 5 == 0, "fabric", "al")
    sections = {"al": Section(material=ALUMINIUM, thickness=1e-3),
                "fabric": Section(material=kevlar, transverse_shear_modulus=3.28e9, points=3)}
    fm = build_model(mesh.nodes, mesh.quads, sections, which)
    s = initial_state(fm)
    centre = np.argmin(np.sum(mesh.nodes[:, :2] ** 2, axis=1))
    s.v[centre, 2] = 200.0
    s.v[:, 0] = 20.0 * mesh.nodes[:, 0] / 0.02  # an in-plane stretch too
    ws = Workspace.for_model(fm, s)
    for _ in range(40):
        step(fm, s, ws)
    cd = {k: v[0] for k, v in meshio.read(FieldWriter(tmp_path, fm).write(s)).cell_data.items()}
    sig, vm = cd["stress"], cd["von_mises_stress"]
    assert sig.shape == (n, 3)
    from_components = np.sqrt(sig[:, 0] ** 2 - sig[:, 0] * sig[:, 1] + sig[:, 1] ** 2
                              + 3.0 * sig[:, 2] ** 2)
    assert np.allclose(vm, from_components, rtol=1e-12, atol=0.0)
    fabric = cd["fabric"] == 1
    assert fabric.sum() == (which == "fabric").sum()
    assert np.all(vm[fabric] == 0.0) and np.all(sig[fabric] == 0.0)
    points = {e: s.mat[fm.mat_row[e]:fm.mat_row[e + 1], J.S_SIG:J.S_SIG + 3]
              for e in np.flatnonzero(~fabric)}
    largest = {e: max(np.sqrt(a * a - a * b + b * b + 3 * c * c) for a, b, c in p)
               for e, p in points.items()}
    for e, value in largest.items():
        assert vm[e] == pytest.approx(value, rel=1e-12, abs=0.0)
    assert vm[~fabric].max() > 1e6


def test_element_sets_partition_the_cells_and_are_named_in_a_side_file(tmp_path, kevlar):
    """Overlapping element sets (``all``, two plies, a patch across both): each cell's
    ``element_set`` is its region (the sets it belongs to), the regions partition the
    elements, each set is exactly the union of the regions element_sets.json lists for it,
    and ``all`` (every element) is left out; a plate's plies alone are regions 0 and 1."""
    import json

    m = plate_mesh(0.02, 0.005, plies=2, spacing=1e-3)
    n = len(m.quads)
    sets = dict(m.elem_sets)
    sets["patch"] = np.array([0, 1, n // 2, n // 2 + 1])
    fm = build_model(m.nodes, m.quads, {"plate": Section(material=STEEL, thickness=1e-3)},
                     np.zeros(n, dtype=np.int64), ply=m.ply, elem_sets=sets)
    cd = {k: v[0] for k, v in meshio.read(FieldWriter(tmp_path, fm).write(initial_state(fm)))
          .cell_data.items()}
    ids = cd["element_set"]
    info = json.loads((tmp_path / "element_sets.json").read_text())
    assert info["cell_array"] == "element_set" and info["left_out"] == ["all"]
    regions = info["regions"]
    assert [r["element_set"] for r in regions] == list(range(len(regions)))
    assert sum(r["elements"] for r in regions) == n  # a partition: each cell in one region
    assert sorted(info["sets"]) == ["patch", "ply0", "ply1"]
    for name, members in info["sets"].items():
        assert np.array_equal(np.flatnonzero(np.isin(ids, members)), np.sort(sets[name]))
        assert all(name in regions[i]["sets"] for i in members)
    assert {tuple(r["sets"]) for r in regions} == {("ply0",), ("ply1",), ("patch", "ply0"),
                                                   ("patch", "ply1")}

    plain = build_model(m.nodes, m.quads, {"plate": Section(material=STEEL, thickness=1e-3)},
                        np.zeros(n, dtype=np.int64), ply=m.ply, elem_sets=m.elem_sets)
    FieldWriter(tmp_path / "plain", plain).write(initial_state(plain))
    cd = meshio.read(tmp_path / "plain" / "step_000000.vtu").cell_data
    assert np.array_equal(cd["element_set"][0], m.ply)
    info = json.loads((tmp_path / "plain" / "element_sets.json").read_text())
    assert [r["sets"] for r in info["regions"]] == [["ply0"], ["ply1"]]
