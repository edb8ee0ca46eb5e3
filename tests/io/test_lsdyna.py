"""model/lsdyna.py: shell meshes, parts, section thicknesses and sets from LS-DYNA keyword
decks, in each of the deck formats; and the decks with errors, each refused naming the
file, the line, the keyword and the value."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from wovenimpact.errors import InputError, InputWarning
from wovenimpact.model.lsdyna import REAL, read_deck, real_text

# A 2×1 strip of quads (elements 10, 11: part 1) and a triangle on top (element 20:
# part 2), as rows of values; each format below writes the same deck.
NODES = [(1, 0.0, 0.0, 0.0), (2, 1.0, 0.0, 0.0), (3, 2.0, 0.0, 0.0), (4, 0.0, 1.0, 0.0),
         (5, 1.0, 1.0, 0.0), (6, 2.0, 1.0, 0.0), (7, 1.0, 2.0, 0.25)]
SHELLS = [(10, 1, 1, 2, 5, 4), (11, 1, 2, 3, 6, 5), (20, 2, 4, 5, 7, 7)]


def card(values, widths, fmt="standard"):
    """One card in fixed columns: standard, I10 (narrow fields widened to 10) or long."""
    widths = {"standard": widths, "i10": [max(w, 10) for w in widths],
              "long": [20] * len(widths)}[fmt]
    return "".join(f"{v:>{w}}" for v, w in zip(values, widths))


def deck(fmt="standard", suffix="", header="*KEYWORD", free=False):
    """The strip deck; ``suffix`` after each keyword ('+', '%', '-', '')."""
    def c(values, widths):
        return ",".join(str(v) for v in values) if free else card(values, widths, fmt)
    k = f" {suffix}" if suffix else ""
    lines = [header, "$ the strip", f"*NODE{k}"]
    lines += [c(n, [8, 16, 16, 16]) for n in NODES]
    lines += [f"*ELEMENT_SHELL{k}"] + [c(e, [8] * 6) for e in SHELLS]
    lines += [f"*PART{k}", "strip", c((1, 1, 1), [10] * 3),
              "cap", c((2, 12, 1), [10] * 3)]  # two parts under one keyword
    lines += [f"*SECTION_SHELL{k}", c((1, 2, 0.8333, 3), [10] * 4), c((0.5,) * 4, [10] * 4)]
    lines += [f"*SECTION_SHELL_TITLE{k}", "thick one", c((12, 2, 0.8333, 3), [10] * 4),
              c((1.5,), [10])]
    lines += [f"*SET_NODE_LIST{k}", c((7,), [10]), c((1, 4), [10] * 2)]
    lines += [f"*SET_NODE_LIST_GENERATE_TITLE{k}", "bottom", c((9,), [10]), c((1, 3), [10] * 2)]
    lines += [f"*SET_SHELL_LIST_TITLE{k}", "right and cap", c((8,), [10]),
              c((11, 20), [10] * 2)]
    lines += ["*END", "anything after *END is not read"]
    return "\n".join(lines) + "\n"


def write(tmp_path: Path, text: str, name: str = "deck.k") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def check_strip(d):
    m = d.mesh
    assert m.nodes.tolist() == [list(n[1:]) for n in NODES]
    assert m.quads.tolist() == [[0, 1, 4, 3], [1, 2, 5, 4], [3, 4, 6, 6]]
    assert d.element_ids.tolist() == [10, 11, 20] and d.part_ids.tolist() == [1, 1, 2]
    assert d.thickness.tolist() == [0.5, 0.5, 1.5]
    assert {k: v.tolist() for k, v in m.elem_sets.items()} == {
        "PART_1": [0, 1], "PART_2": [2], "SET_SHELL_8": [1, 2]}
    assert m.node_sets["SET_NODE_7"].tolist() == [0, 3]
    assert m.node_sets["SET_NODE_9"].tolist() == [0, 1, 2]
    assert m.node_sets["PART_2"].tolist() == [3, 4, 6]  # a part's nodes, to clamp
    assert m.node_sets["SET_SHELL_8"].tolist() == [1, 2, 3, 4, 5, 6]
    assert d.titles == {"PART_1": "strip", "PART_2": "cap", "SET_NODE_9": "bottom",
                        "SET_SHELL_8": "right and cap"}
    assert np.all(m.area_vectors()[:, 2] > 0)


@pytest.mark.parametrize("fmt, suffix, header, free", [
    ("standard", "", "*KEYWORD", False),
    ("standard", "", "*KEYWORD", True),            # free format: commas
    ("long", "+", "*KEYWORD", False),              # 20-column fields, per keyword
    ("long", "", "*KEYWORD LONG=Y", False),        # ... for the whole deck
    ("standard", "", "*KEYWORD 100000000 LONG=S", False),  # LONG=S: standard input
    ("i10", "%", "*KEYWORD", False),               # I10: 8-column fields widened to 10
    ("i10", "", "*keyword i10=y", False),
    ("standard", "-", "*KEYWORD LONG=Y", False),   # '-': back to standard in a long deck
])
def test_the_strip_in_every_format(tmp_path, fmt, suffix, header, free):
    check_strip(read_deck(write(tmp_path, deck(fmt, suffix, header, free))))


def test_fields_that_fill_their_columns(tmp_path):
    """Fixed columns with no blank between the values: 8-digit ids, 16-character reals."""
    text = deck().replace(card(NODES[6], [8, 16, 16, 16]),
                          "12345678-1.000000000e+00 2.000000000e+00 2.500000000e-01")
    text = text.replace(card(SHELLS[2], [8] * 6), "      20       2       4       512345678"
                                                  "12345678")
    d = read_deck(write(tmp_path, text))
    assert d.mesh.nodes[6].tolist() == [-1.0, 2.0, 0.25] and d.node_ids[6] == 12345678


def test_fortran_reals_and_lower_case_keywords(tmp_path):
    text = deck().replace("*NODE", "*node").replace(
        card(NODES[6], [8, 16, 16, 16]), card((7, "1.0", "2.D0", "2.5-1"), [8, 16, 16, 16]))
    assert read_deck(write(tmp_path, text)).mesh.nodes[6].tolist() == [1.0, 2.0, 0.25]


def test_element_thickness_cards(tmp_path):
    """*ELEMENT_SHELL_THICKNESS: each element's own THIC1–THIC4 (blank THIC2–4 take THIC1;
    a blank card, the section's)."""
    rows = [card(SHELLS[0], [8] * 6), card((0.7, 0.7, 0.7, 0.7), [16] * 4),
            card(SHELLS[1], [8] * 6), "",
            card(SHELLS[2], [8] * 6), card((0.9,), [16])]
    text = deck().replace("*ELEMENT_SHELL\n" + "\n".join(card(e, [8] * 6) for e in SHELLS),
                          "*ELEMENT_SHELL_THICKNESS\n" + "\n".join(rows))
    assert read_deck(write(tmp_path, text)).thickness.tolist() == [0.7, 0.5, 0.9]


def test_include_relative_to_the_including_file(tmp_path):
    text = deck()
    nodes = "\n".join(["*NODE"] + [card(n, [8, 16, 16, 16]) for n in NODES])
    (tmp_path / "mesh").mkdir()
    write(tmp_path / "mesh", "*KEYWORD\n" + nodes + "\n*END\n", "nodes.k")
    write(tmp_path / "mesh", "*KEYWORD\n*INCLUDE\nnodes.k\n*END\n", "inner.k")
    main = write(tmp_path, text.replace(nodes, "*INCLUDE\nmesh/inner.k"))
    check_strip(read_deck(main))


def test_keywords_not_read_are_named_in_one_warning(tmp_path):
    text = deck().replace("*END", "*MAT_ELASTIC\n         1      7.85     210.0       0.3\n"
                                  "*CONTROL_TERMINATION\n     0.001\n*MAT_ELASTIC\n         2"
                                  "\n*END")
    text = text.replace(card(NODES[0], [8, 16, 16, 16]),
                        card(NODES[0] + (7, 0), [8, 16, 16, 16, 8, 8]))
    with pytest.warns(InputWarning, match=r"not read .*\*CONTROL_TERMINATION, \*MAT_ELASTIC "
                                          r"\(2\), \*NODE TC"):
        check_strip(read_deck(write(tmp_path, text)))


def test_nodes_of_no_shell_are_left_out(tmp_path):
    """Nodes only a skipped element uses (a beam, a mass) are not in the mesh."""
    text = deck().replace("*ELEMENT_SHELL", card((99, 5.0, 5.0, 5.0), [8, 16, 16, 16])
                          + "\n*ELEMENT_BEAM\n       1       3      99       1\n*ELEMENT_SHELL")
    with pytest.warns(InputWarning, match="ELEMENT_BEAM"):
        d = read_deck(write(tmp_path, text))
    assert d.mesh.n_nodes == 7 and 99 not in d.node_ids


def test_real_text_is_exact_where_the_field_allows():
    def read(s):
        m = REAL.match(s)
        return float(f"{m.group(1)}e{m.group(2) or m.group(3) or 0}")

    for x in (0.25, -0.25, 250.0, 4.991836734693878e-4, -0.25023456789012344, 1e-300, 0.0,
              -7.25e12, 2 / 3):
        assert read(real_text(x, 20)) == x and len(real_text(x, 20)) <= 20
    assert len(real_text(-1.5308084989341915e-17, 20)) == 20  # 17 digits: the closest
    assert read(real_text(-1.5308084989341915e-17, 20)) == pytest.approx(
        -1.5308084989341915e-17, rel=1e-15)
    assert read(real_text(1 / 3, 10)) == pytest.approx(1 / 3, rel=1e-8)


# ------------------------------------------------------------------- decks with errors

N7 = card(NODES[6], [8, 16, 16, 16])
E20 = card(SHELLS[2], [8] * 6)
PART2 = card((2, 12, 1), [10] * 3)
SEC1 = card((0.5,) * 4, [10] * 4)
SET7 = card((1, 4), [10] * 2)


@pytest.mark.parametrize("old, new, words", [
    # a missing node, part or section
    (E20, card((20, 2, 4, 5, 77, 77), [8] * 6),
     r"deck.k:\d+: \*ELEMENT_SHELL: element 20's N3 is node 77, which no \*NODE defines"),
    (E20, card((20, 3, 4, 5, 7, 7), [8] * 6),
     r"element 20 is in part 3, which no \*PART defines \(parts: \[1, 2\]\)"),
    (PART2, card((2, 13, 1), [10] * 3),
     r"deck.k:\d+: \*PART: part 2 has SECID 13, which no \*SECTION_SHELL defines"),
    # a bad field: not a number, a spilled value, a free-format value wider than its field
    (N7, card((7, "1.0", "two", "0.25"), [8, 16, 16, 16]),
     r"deck.k:10: \*NODE: Y is not a number \(got 'two'"),
    (N7, "123456789       1.0             2.0            0.25",
     r"deck.k:10: \*NODE: X is not a number \(got '9       1.0'"),
    (N7, "7,1.0,2.0,0.25000000000000000001",
     r"deck.k:10: \*NODE: Z '0.25000000000000000001' is 22 characters, more than its "
     r"field's 16"),
    (N7, N7 + card((0, 0), [8, 8]) + "   extra",
     r"deck.k:10: \*NODE: text beyond column 72 \('extra'\)"),
    (N7, card((7, "1.0", "2.0", "&zz"), [8, 16, 16, 16]),
     r"\*NODE: Z is the parameter '&zz'; \*PARAMETER references are not read"),
    (N7, "7\t1.0\t2.0\t0.25", r"deck.k:10: \*NODE: a tab character"),
    (N7, card((7, "1.0", "2.0", "inf"), [8, 16, 16, 16]), r"Z is not a number \(got 'inf'"),
    (E20, card((20, 2, 4, 5, 7, 7, 8), [8] * 7), r"element 20 has mid-side nodes N5–N8"),
    (E20, card((20, 2, 4, 5, 7), [8] * 5), r"element 20 has no N4 .*a triangle repeats N3"),
    (E20, card((20, 2, 4, 4, 5, 7), [8] * 6), r"element 20 has nodes \[4, 4, 5, 7\]"),
    # ids given twice
    (N7, N7 + "\n" + card((1, 0, 0, 0), [8, 16, 16, 16]),
     r"deck.k:11: \*NODE: node 1 is defined again \(first at .*deck.k:4\)"),
    (E20, E20 + "\n" + card((10, 2, 4, 5, 7, 7), [8] * 6), r"element 10 is defined again"),
    (SET7, SET7 + "\n*SET_NODE_LIST\n         7\n         2", r"node set 7 is defined again"),
    # sets that list what the deck lacks
    (SET7, card((1, 44), [10] * 2), r"\*SET_NODE: set 7 lists node 44, which the deck "
                                    r"does not define"),
    (card((1, 3), [10] * 2), card((100, 300), [10] * 2),
     r"\*SET_NODE: set 9's range 100–300 holds no node of the deck"),
    # thicknesses
    (SEC1, card((0.5, 0.6, 0.5, 0.5), [10] * 4),
     r"\*SECTION_SHELL 1 \(part 1\): thicknesses \[0.5, 0.6, 0.5, 0.5\] differ; a tapered "
     r"shell is not modelled"),
    (SEC1, "", r"\*SECTION_SHELL 1 \(part 1\): T1 = 0 \(valid: a thickness > 0\)"),
    (card((1, 2, 0.8333, 3), [10] * 4), card((1, 2, 0.8333, 3, 0, 0, 1), [10] * 7),
     r"section 1 has ICOMP = 1: layered \(composite\) sections are not read"),
    # keywords that would change the mesh if skipped
    ("*END", "*ELEMENT_SOLID\n       1       1       1       2       3       4\n*END",
     r"\*ELEMENT_SOLID: not read: solid elements"),
    ("*END", "*NODE_TRANSFORM\n         1         1\n*END", r"\*NODE_TRANSFORM: not read"),
    ("*END", "*PART_MOVE\n         1       0.1\n*END", r"\*PART_MOVE: not read"),
    ("*ELEMENT_SHELL\n", "*ELEMENT_SHELL_BETA\n", r"\*ELEMENT_SHELL_BETA: not read"),
    ("*SET_NODE_LIST\n", "*SET_NODE_ADD\n", r"\*SET_NODE_ADD: not read"),
    ("*END", "*INCLUDE\nnowhere.k\n*END",
     r"deck.k:\d+: \*INCLUDE: file 'nowhere.k' not found"),
    ("*END", "*INCLUDE\nnowhere.k\nelsewhere.k\n*END", r"\*INCLUDE: 2 file names"),
    ("*KEYWORD", "a stray line\n*KEYWORD", r"deck.k:1: data before the first keyword"),
    ("*NODE\n", "*NODE ten\n", r"deck.k:3: \*NODE: unexpected text after the keyword 'ten'"),
])
def test_decks_with_errors(tmp_path, old, new, words):
    text = deck()
    assert old in text
    with pytest.raises(InputError, match=words):
        read_deck(write(tmp_path, text.replace(old, new, 1)))


def test_an_include_that_loops_back(tmp_path):
    write(tmp_path, "*KEYWORD\n*INCLUDE\ndeck.k\n", "other.k")
    path = write(tmp_path, deck().replace("*END", "*INCLUDE\nother.k\n*END"))
    with pytest.raises(InputError, match=r"\*INCLUDE loops back to a file that includes it"):
        read_deck(path)


def test_a_deck_without_shells(tmp_path):
    text = re.sub(r"\*ELEMENT_SHELL\n(.*\n){3}", "", deck())
    with pytest.raises(InputError, match=r"deck.k: no shell elements \(\*ELEMENT_SHELL\)"):
        read_deck(write(tmp_path, text))


def test_a_missing_file():
    with pytest.raises(InputError, match="mesh file 'nowhere.k' not found"):
        read_deck("nowhere.k")


# ------------------------------------------------------------- [mesh] kind = "lsdyna"

MATERIALS = Path(__file__).resolve().parents[2] / "examples" / "materials"


def case_doc(path: Path, sections: dict, parts: dict, **mesh) -> dict:
    return {"case": {"name": "strip deck"},
            "materials": {"al": str(MATERIALS / "aluminium.toml")},
            "sections": {name: {"material": "al", **keys} for name, keys in sections.items()},
            "mesh": {"kind": "lsdyna", "file": str(path), "sections": parts, **mesh},
            "boundary": [{"nodes": "SET_NODE_7", "type": "clamped"}],
            "run": {"end_time": "1 us"}}


def mesh_of(doc: dict, tmp_path: Path):
    """make_mesh of the case, and its sections as the compiler makes them."""
    from wovenimpact.model.model import Section
    from wovenimpact.setup.compile import make_mesh
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.spec.material import load_material

    spec = case_from_dict(doc, "case.toml")
    al = load_material(MATERIALS / "aluminium.toml")
    sections = {name: Section(material=al, thickness=s.thickness)
                for name, s in spec.sections.items()}
    mesh, names = make_mesh(spec, tmp_path, sections)
    return mesh, names, sections


def test_sections_take_the_decks_thickness(tmp_path):
    """A section without thickness takes its parts' (in the file's length unit); the
    parts map to sections as an Abaqus file's element sets do."""
    path = write(tmp_path, deck())
    doc = case_doc(path, {"thin": {}, "thick": {}}, {"PART_1": "thin", "PART_2": "thick"},
                   length_unit="1 mm")
    mesh, names, sections = mesh_of(doc, tmp_path)
    assert names == ["thin", "thin", "thick"]
    assert sections["thin"].thickness == pytest.approx(0.5e-3, rel=1e-15)
    assert sections["thick"].thickness == pytest.approx(1.5e-3, rel=1e-15)
    assert mesh.nodes[6].tolist() == pytest.approx([1e-3, 2e-3, 0.25e-3], rel=1e-15)
    # the case's own thickness, when it agrees with the deck's, is kept
    doc["sections"]["thin"]["thickness"] = "0.5 mm"
    assert mesh_of(doc, tmp_path)[2]["thin"].thickness == pytest.approx(0.5e-3)


@pytest.mark.parametrize("change, words", [
    (lambda d: d["sections"]["thin"].update(thickness="0.6 mm"),
     r"mesh.sections: sections.thin.thickness is 0.0006 m, the deck .*deck.k gives its "
     r"elements 0.0005 m \(element 10, part 1: .*remove sections.thin.thickness"),
    (lambda d: d["mesh"]["sections"].update(PART_2="thin"),
     r"mesh.sections: section 'thin' is given to elements of .*deck.k of thickness "
     r"0.0005 m \(element 10, part 1\) and 0.0015 m \(element 20, part 2\)"),
    (lambda d: d["mesh"]["sections"].update(PART_3="thin"),
     r"mesh.sections: element set 'PART_3' is not in .*deck.k; sets there: \['PART_1', "
     r"'PART_2', 'SET_SHELL_8'\]"),
    (lambda d: d["boundary"].append({"nodes": "SET_NODE_70", "type": "clamped"}),
     r"boundary\[1\].nodes: node set 'SET_NODE_70' does not exist"),
])
def test_a_case_that_does_not_fit_its_deck(tmp_path, change, words):
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.spec.case import case_from_dict

    path = write(tmp_path, deck())
    doc = case_doc(path, {"thin": {}, "thick": {}}, {"PART_1": "thin", "PART_2": "thick"},
                   length_unit="1 mm")
    change(doc)
    with pytest.raises(InputError, match=words):
        compile_case(case_from_dict(doc, "case.toml"), tmp_path)


def test_an_empty_set_named_by_the_case(tmp_path):
    """An empty *SET_NODE_LIST is read (a deck may hold unused ones); a boundary on it is
    refused naming it."""
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.spec.case import case_from_dict

    path = write(tmp_path, deck().replace(SET7 + "\n", ""))
    assert read_deck(path).mesh.node_sets["SET_NODE_7"].size == 0
    doc = case_doc(path, {"thin": {}, "thick": {}}, {"PART_1": "thin", "PART_2": "thick"},
                   length_unit="1 mm")
    with pytest.raises(InputError, match=r"boundary\[0\].nodes: node set 'SET_NODE_7' holds "
                                         r"no node"):
        compile_case(case_from_dict(doc, "case.toml"), tmp_path)
