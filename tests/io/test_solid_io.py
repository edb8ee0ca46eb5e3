"""Solid elements in the inputs and outputs (docs/solid.md §4): case files with
``[solid_sections]`` and a block of hexahedra, Abaqus files with C3D8R / C3D8 bricks beside
shells, VTU frames with VTK hexahedra, and a restart that ends bitwise as an
uninterrupted run, the hexahedra's state included."""

from __future__ import annotations

import json
from pathlib import Path

import meshio
import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.io.checkpoint import latest_checkpoint, load_checkpoint
from wovenimpact.io.fields import FieldWriter
from wovenimpact.kernels import solid_layout as L
from wovenimpact.kernels.integrate import FIXED
from wovenimpact.model.abaqus import read_inp
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.model.model import Section, build_model
from wovenimpact.model.solid import SolidSection, block_mesh, solid_part
from wovenimpact.runs import run_case
from wovenimpact.setup.compile import compile_case
from wovenimpact.spec.case import case_from_dict, load_case
from wovenimpact.spec.material import load_material
from wovenimpact.state import initial_state
from tests.restart import interrupted_and_resumed

ROOT = Path(__file__).resolve().parents[2]
YARN = ROOT / "examples" / "materials" / "kevlar_yarn_solid.toml"
STEEL = ROOT / "examples" / "materials" / "steel.toml"

CASE = """
[case]
name = "yarn block pulled"

[materials]
yarn = "{yarn}"

[solid_sections.yarn]
material = "yarn"
fibre_direction = [1, 0, 0]
second_direction = [0, 1, 0]

[mesh]
kind = "block"
size = ["4 mm", "1 mm", "1 mm"]
elements = [8, 2, 2]
section = "yarn"

[[boundary]]
nodes = "x_min"
type = "pinned"

[[boundary]]
nodes = "x_max"
type = "velocity"
dof = "ux"
velocity = "2 m/s"

[run]
end_time = "{end}"
field_interval = "0.5 us"
history_interval = "0.05 us"
checkpoint_interval = "0.5 us"
"""


def write_case(tmp_path: Path, end: str = "2 us") -> Path:
    path = tmp_path / "block.toml"
    path.write_text(CASE.format(yarn=YARN.as_posix(), end=end), encoding="utf-8")
    return path


def test_restart_of_a_solid_run_ends_bitwise_identical(tmp_path):
    """A block of hexahedra pulled at one end, killed after a checkpoint and restarted,
    ends with the same history.csv, the same State (hexahedra's stress, stretch,
    hourglass forces and energies included) and the same frames as an uninterrupted
    run."""
    case = write_case(tmp_path)
    _, whole, broken, a, b = interrupted_and_resumed(case, tmp_path, 0.7)
    assert a.hex.shape == (32, L.N_HEX_STATE) and np.abs(a.hex[:, L.H_SIG]).max() > 1e6
    assert a.equals(b)
    assert a.hex.tobytes() == b.hex.tobytes()
    fa = sorted(p.name for p in (whole / "fields").glob("*.vtu"))
    assert fa == sorted(p.name for p in (broken / "fields").glob("*.vtu"))
    sa = json.loads((whole / "summary.json").read_text())
    sb = json.loads((broken / "summary.json").read_text())
    assert sb["restarted_from_step"] > 0
    assert sa["elements"] == 32 and sa["element_cycles"] == sb["element_cycles"] > 0
    assert sa["energy_check"] == "pass" and sa["stored_energy_J"] > 0.0


def test_the_fields_of_a_solid_run_are_hexahedra_meshio_reads_back(tmp_path):
    """The run's last frame holds one VTK hexahedron per element, on the current
    positions, with the hexahedra's Cauchy stress (``solid_stress``) and von Mises stress
    of the State it was written from."""
    case = write_case(tmp_path, end="1 us")
    out = tmp_path / "out"
    run_case(case, out)
    spec, base = load_case(case)
    compiled = compile_case(spec, base)
    model = compiled.model
    state = load_checkpoint(latest_checkpoint(out / "checkpoints"), model.digest())
    frames = sorted((out / "fields").glob("step_*.vtu"))
    m = meshio.read(frames[-1])
    assert [c.type for c in m.cells] == ["hexahedron"]
    assert len(m.cells[0].data) == model.n_hexes
    cd = {k: v[0] for k, v in m.cell_data.items()}
    order = cd["element"]
    assert sorted(order.tolist()) == list(range(model.n_hexes))
    np.testing.assert_array_equal(m.points[m.cells[0].data], state.x[model.solid.hexes[order]])
    np.testing.assert_array_equal(cd["solid_stress"], state.hex[order, L.H_SIG:L.H_SIG + 6])
    assert (cd["solid"] == 1).all()
    sxx = state.hex[order, L.H_SIG]
    assert np.abs(sxx).max() > 1e6  # the block is pulled along x
    assert cd["von_mises_stress"] == pytest.approx(np.abs(sxx), rel=0.05)


def test_a_frame_of_shells_and_hexahedra_has_both_blocks(tmp_path):
    """A steel plate with a yarn block on its own nodes: quads and hexahedra in one file,
    each cell array the length of both blocks, 0 where it does not apply."""
    plate = plate_mesh(10e-3, 2.5e-3)
    block = block_mesh((2e-3, 2e-3, 1e-3), (2, 2, 1), origin=(0.0, 0.0, 1e-3))
    nodes = np.vstack([plate.nodes, block.nodes])
    hexes = block.hexes + len(plate.nodes)
    part = solid_part(nodes, hexes, {"yarn": SolidSection(load_material(YARN))},
                      np.zeros(len(hexes), dtype=np.int64))
    model = build_model(nodes, plate.quads, {"plate": Section(load_material(STEEL),
                                                             thickness=1e-3)},
                        np.zeros(plate.n_elems, dtype=np.int64), solid=part)
    st = initial_state(model)
    st.hex[:, L.H_SIG] = 1.0 + np.arange(model.n_hexes)
    m = meshio.read(FieldWriter(tmp_path, model).write(st))
    assert [c.type for c in m.cells] == ["quad", "hexahedron"]
    assert [len(c.data) for c in m.cells] == [plate.n_elems, 4]
    for name, data in m.cell_data.items():
        assert [len(d) for d in data] == [plate.n_elems, 4], name
    assert m.cell_data["solid"][0].tolist() == [0] * plate.n_elems
    assert m.cell_data["solid_stress"][1][:, 0].tolist() == [1.0, 2.0, 3.0, 4.0]
    assert m.cell_data["element"][1].tolist() == [0, 1, 2, 3]
    assert len(m.points) == model.n_nodes
    # the block's nodes, in no shell, have their rotations held; the plate's do not
    assert (model.bc_code[len(plate.nodes):, 3:] == FIXED).all()
    assert not model.bc_code[:len(plate.nodes)].any()


INP = """*HEADING
two bricks and a shell
*NODE
1, 0., 0., 0.
2, 1., 0., 0.
3, 1., 1., 0.
4, 0., 1., 0.
5, 0., 0., 1.
6, 1., 0., 1.
7, 1., 1., 1.
8, 0., 1., 1.
9, 2., 0., 0.
10, 2., 1., 0.
11, 2., 0., 1.
12, 2., 1., 1.
13, 0., 0., -1.
14, 1., 0., -1.
*ELEMENT, TYPE=C3D8R, ELSET=YARN
1, 1, 2, 3, 4, 5, 6, 7, 8
2, 2, 9, 10, 3, 6, 11, 12, 7
*ELEMENT, TYPE=S4R, ELSET=SKIN
3, 13, 14, 2, 1
*NSET, NSET=END
9, 10, 11, 12
"""


def test_an_abaqus_file_of_bricks_and_shells_compiles_into_both(tmp_path):
    """C3D8R bricks are read as hexahedra (Abaqus's corner order is VTK's) with their
    element set, beside the S4R shells; a case gives the set a solid section, whose
    elements get its frame and their mass ρ V0 lumped in eighths on the nodes."""
    (tmp_path / "mixed.inp").write_text(INP, encoding="utf-8")
    mesh = read_inp(tmp_path / "mixed.inp")
    assert mesh.hexes.tolist() == [[0, 1, 2, 3, 4, 5, 6, 7], [1, 8, 9, 2, 5, 10, 11, 6]]
    assert mesh.quads.tolist() == [[12, 13, 1, 0]]
    assert mesh.hex_sets["YARN"].tolist() == [0, 1] and "YARN" not in mesh.elem_sets
    assert mesh.elem_sets["SKIN"].tolist() == [0] and "SKIN" not in mesh.hex_sets
    doc = {
        "case": {"name": "bricks"},
        "materials": {"yarn": YARN.as_posix(), "steel": STEEL.as_posix()},
        "sections": {"skin": {"material": "steel", "thickness": "0.1 mm"}},
        "solid_sections": {"yarn": {"material": "yarn", "fibre_direction": [0, 0, 1]}},
        "mesh": {"kind": "abaqus", "file": "mixed.inp", "length_unit": "1 mm",
                 "sections": {"YARN": "yarn", "SKIN": "skin"}},
        "run": {"end_time": "1 us"},
    }
    model = compile_case(case_from_dict(doc), tmp_path).model
    assert model.n_hexes == 2 and model.n_elems == 1
    np.testing.assert_allclose(model.solid.vol0, 1e-9, rtol=1e-12)
    np.testing.assert_allclose(model.solid.frame[:, 0], [[0, 0, 1], [0, 0, 1]])
    mass = 1440.0 * 1e-9 / 8.0
    assert model.node_mass[8] == pytest.approx(mass)  # a corner of the second brick only
    assert model.node_mass[4] == pytest.approx(mass)
    assert model.node_mass[0] > mass  # shared with the shell


@pytest.mark.parametrize("change, key", [
    ({"solid_sections": {"yarn": {"material": "steel"}}}, "solid_sections.yarn.material"),
    ({"sections": {"yarn2": {"material": "yarn", "thickness": "1 mm"}}},
     "sections.yarn2.material"),
    ({"solid_sections": {"yarn": {"material": "yarn", "hourglass": 1.5}}},
     "solid_sections.yarn.hourglass"),
    ({"solid_sections": {"yarn": {"material": "yarn", "fibre": [1, 0, 0]}}},
     "solid_sections.yarn.fibre"),
    ({"mesh": {"kind": "block", "size": ["1 mm", "1 mm", "1 mm"], "elements": [1, 1, 1],
               "section": "shell"}}, "mesh.section"),
    ({"mesh": {"kind": "block", "size": ["1 mm", "1 mm"], "elements": [1, 1, 1],
               "section": "yarn"}}, "mesh.size"),
    ({"mesh": {"kind": "block", "size": ["1 mm", "1 mm", "1 mm"], "elements": [1, 0, 1],
               "section": "yarn"}}, "mesh.elements"),
])
def test_a_wrong_solid_input_is_refused_naming_its_key(tmp_path, change, key):
    doc = {
        "case": {"name": "block"},
        "materials": {"yarn": YARN.as_posix(), "steel": STEEL.as_posix()},
        "sections": {"shell": {"material": "steel", "thickness": "1 mm"}},
        "solid_sections": {"yarn": {"material": "yarn"}},
        "mesh": {"kind": "block", "size": ["1 mm", "1 mm", "1 mm"], "elements": [1, 1, 1],
                 "section": "yarn"},
        "run": {"end_time": "1 us"},
    }
    for table, value in change.items():
        doc[table] = {**doc[table], **value} if table.endswith("sections") else value
    with pytest.raises(InputError, match=key.replace(".", r"\.")):
        compile_case(case_from_dict(doc), tmp_path)


@pytest.mark.parametrize("extra, sections, message", [
    ("*ELSET, ELSET=SKIN2\n3\n", {"SKIN": "skin", "SKIN2": "skin2"},
     r"mesh\.sections: element 0 is in two sets with different sections \('skin' and 'skin2'\)"),
    ("*ELSET, ELSET=YARN2\n2\n", {"YARN": "yarn", "YARN2": "yarn2"},
     r"mesh\.sections: brick 1 is in two sets with different sections \('yarn' and 'yarn2'\)"),
])
def test_an_element_in_two_sets_of_different_sections_is_refused(tmp_path, extra, sections,
                                                                  message):
    """setup.compile.give_section, for the shells' sets and the bricks'."""
    (tmp_path / "mixed.inp").write_text(INP + extra, encoding="utf-8")
    doc = {
        "case": {"name": "bricks"},
        "materials": {"yarn": YARN.as_posix(), "steel": STEEL.as_posix()},
        "sections": {n: {"material": "steel", "thickness": "0.1 mm"} for n in ("skin", "skin2")},
        "solid_sections": {n: {"material": "yarn"} for n in ("yarn", "yarn2")},
        "mesh": {"kind": "abaqus", "file": "mixed.inp", "length_unit": "1 mm",
                 "sections": {"SKIN": "skin", "YARN": "yarn", **sections}},
        "run": {"end_time": "1 us"},
    }
    with pytest.raises(InputError, match=message):
        compile_case(case_from_dict(doc), tmp_path)
