"""model/abaqus.py: shell meshes and sets from Abaqus input files (via meshio)."""

from __future__ import annotations

from pathlib import Path

import meshio
import numpy as np
import pytest

from wovenimpact.errors import InputError, InputWarning
from wovenimpact.model.abaqus import read_inp
from wovenimpact.model.mesh import plate_mesh

# 2×1 strip of S4R quads (elements 10, 11) and one S3 triangle (element 20) on top
STRIP = """*HEADING
strip
** a comment
*NODE
1, 0.0, 0.0, 0.0
2, 1.0, 0.0, 0.0
3, 2.0, 0.0, 0.0
4, 0.0, 1.0, 0.0
5, 1.0, 1.0, 0.0
6, 2.0, 1.0, 0.0
7, 1.0, 2.0, 0.0
*ELEMENT, TYPE=S4R
10, 1, 2, 5, 4
11, 2, 3, 6, 5
*ELEMENT, TYPE=S3, ELSET=cap
20, 4, 5, 7
*NSET, NSET=left
1, 4
*NSET, NSET=bottom, GENERATE
1, 3, 1
*ELSET, ELSET=strip, GENERATE
10, 11, 1
*ELSET, ELSET=mixed
11, 20
"""


def write(tmp_path: Path, text: str, name: str = "mesh.inp") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_strip_with_a_triangle(tmp_path):
    m = read_inp(write(tmp_path, STRIP))
    assert m.nodes.shape == (7, 3)
    assert m.nodes[6].tolist() == [1.0, 2.0, 0.0]
    assert m.quads.tolist() == [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 6, 6]]
    assert m.ply.tolist() == [0, 0, 0]
    assert m.node_sets["left"].tolist() == [0, 3]
    assert m.node_sets["bottom"].tolist() == [0, 1, 2]
    assert m.elem_sets["strip"].tolist() == [0, 1]
    assert m.elem_sets["mixed"].tolist() == [1, 2]
    assert m.elem_sets["cap"].tolist() == [2]
    assert np.all(m.area_vectors()[:, 2] > 0)


def test_line_elements_are_skipped_with_a_warning(tmp_path):
    text = STRIP.replace("*NSET, NSET=left", "*ELEMENT, TYPE=B31\n30, 1, 2\n*NSET, NSET=left")
    with pytest.warns(InputWarning, match="skipping 1 'line' elements"):
        m = read_inp(write(tmp_path, text))
    assert len(m.quads) == 3
    assert m.elem_sets["mixed"].tolist() == [1, 2]


def test_solid_elements_are_an_error(tmp_path):
    text = STRIP.replace("TYPE=S3, ELSET=cap\n20, 4, 5, 7", "TYPE=C3D4, ELSET=cap\n20, 4, 5, 7, 1")
    with pytest.raises(InputError, match="'tetra'.*not a shell"):
        read_inp(write(tmp_path, text))


def test_unknown_element_type_is_named(tmp_path):
    text = STRIP.replace("TYPE=S3,", "TYPE=M3D3,")
    with pytest.raises(InputError, match="M3D3"):
        read_inp(write(tmp_path, text))


@pytest.mark.parametrize(
    ("old", "new", "words"),
    [
        ("*NSET, NSET=bottom", "*NSET, NSET=left", "defined again"),
        ("*ELSET, ELSET=mixed\n11, 20", "*ELSET, ELSET=mixed\nstrip, cap", "by name"),
        ("*ELSET, ELSET=mixed", "*ELSET, ELSET=cap", "both on *ELEMENT"),
        ("*NODE\n", "*INCLUDE, INPUT=other.inp\n*NODE\n", "INCLUDE"),
        ("*ELEMENT, TYPE=S4R", "*NODE\n8, 5.0, 5.0, 0.0\n*ELEMENT, TYPE=S4R", "second *NODE"),
        ("*ELEMENT, TYPE=S3", "*ELSET, ELSET=early\n10\n*ELEMENT, TYPE=S3", "above the *ELEMENT"),
        ("11, 2, 3, 6, 5", "11, 2, 3, 6, 99", "cannot read"),
        ("*NODE\n", "*Part, name=P\n*NODE\n", "*PART is not supported"),
        ("*NSET, NSET=left", "*Assembly, name=A\n*Instance, name=I, part=P\n5.0, 0.0, 0.0\n"
                             "*End Instance\n*NSET, NSET=left", "*ASSEMBLY is not supported"),
        ("*NSET, NSET=left", "*Instance, name=I, part=P\n*End Instance\n*NSET, NSET=left",
         "*INSTANCE is not supported"),
    ],
)
def test_constructs_meshio_would_misread_are_refused(tmp_path, old, new, words):
    assert old in STRIP
    with pytest.raises(InputError, match="mesh.inp") as err:
        read_inp(write(tmp_path, STRIP.replace(old, new, 1)))
    assert words in str(err.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError, match="not found"):
        read_inp(tmp_path / "nothing.inp")


def test_plate_mesh_written_by_meshio_reads_back(tmp_path):
    plate = plate_mesh(0.1, 0.02, quarter=True)
    path = tmp_path / "plate.inp"
    sets = {k: v for k, v in plate.node_sets.items()}
    meshio.write(path, meshio.Mesh(plate.nodes, [("quad", plate.quads)], point_sets=sets,
                                   cell_sets={"ply0": [plate.elem_sets["ply0"]]}),
                 file_format="abaqus")
    back = read_inp(path)
    assert np.array_equal(back.nodes, plate.nodes)
    assert np.array_equal(back.quads, plate.quads)
    for name, idx in plate.node_sets.items():
        assert np.array_equal(back.node_sets[name], idx), name
    assert np.array_equal(back.elem_sets["ply0"], plate.elem_sets["ply0"])
