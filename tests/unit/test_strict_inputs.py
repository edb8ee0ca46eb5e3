"""Inputs as strict as a deck (issue 38, item 6): TOML's types are kept (a string "4" is
not 4 plies, 1 or "yes" is not true, ["1", "0", "0"] is not a direction), each refusal
naming the key, the type given and what is valid; a node set or radius that selects
nothing is an error naming it; a fabric without crimp and a compaction limit at or above
the crossover's height are refused with the reason; a mesh that would take minutes to
build asks for run.allow_large_mesh first."""

from __future__ import annotations

import copy
import time
import warnings
from pathlib import Path

import pytest

from tests.corpus.generate import INP_CASE, plate_inp
from wovenimpact.errors import InputError, InputWarning
from wovenimpact.spec.case import case_from_dict, load_case
from wovenimpact.spec.fields import read_toml, set_dotted
from wovenimpact.spec.material import material_from_dict

ROOT = Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
PLATE = EXAMPLES / "plate_impact" / "plies4_120.toml"
CASING = EXAMPLES / "containment" / "hybrid_4.toml"
KEVLAR = EXAMPLES / "materials" / "kevlar_thesis.toml"


def refusal(path: Path, *overrides: str) -> str:
    """The one-line message of the InputError that loading ``path`` with ``overrides``
    raises (with the case file's name and the --set stripped)."""
    with pytest.raises(InputError) as err:
        load_case(path, list(overrides))
    text = str(err.value)
    assert "\n" not in text, text  # one problem, one line
    return text.split(": ", 1)[1]


# --- TOML's types ------------------------------------------------------------------------

STRICT_CASES = [
    # (case, --set, message)
    (PLATE, 'mesh.plies="4"', "mesh.plies: is a string, not an integer (got '4'; valid: an "
                              "integer ≥ 1 such as 4, not quoted)"),
    (PLATE, "mesh.plies=4.0", "mesh.plies: is a float, not an integer (got 4.0; valid: an "
                              "integer ≥ 1"),
    (PLATE, "mesh.plies=true", "mesh.plies: is a boolean, not an integer (got True;"),
    (PLATE, 'mesh.quarter="yes"', "mesh.quarter: is a string, not a boolean (got 'yes'; "
                                  "valid: true or false, not quoted)"),
    (PLATE, "mesh.quarter=1", "mesh.quarter: is an integer, not a boolean (got 1; valid: "
                              "true or false, not quoted)"),
    (PLATE, 'mesh.quarter="true"', "mesh.quarter: is a string, not a boolean (got 'true';"),
    (PLATE, 'mesh.warp_direction=["1", "0", "0"]',
     "mesh.warp_direction: has a string at [0] ('1'), not a number (got ['1', '0', '0']; "
     "valid: three numbers, not all zero, such as [0, 0, -1], not quoted)"),
    (PLATE, "impactor.direction=[0, true, -1]",
     "impactor.direction: has a boolean at [1] (True), not a number (got [0, True, -1];"),
    (PLATE, 'impactor.direction="down"',
     "impactor.direction: is a string, not an array of 3 numbers (got 'down';"),
    (PLATE, "impactor.direction=[0, -1]", "impactor.direction: has 2 items, not 3"),
    (PLATE, 'run.threads="2"', "run.threads: is a string, not an integer (got '2'; valid: an "
                               "integer ≥ 1 such as 2, not quoted)"),
    (PLATE, "run.max_steps=1e7", "run.max_steps: is a float, not an integer (got 10000000.0;"),
    (PLATE, 'sections.fabric.points="3"', "sections.fabric.points: is a string, not an "
                                          "integer (got '3'; valid: an integer ≥ 1"),
    (PLATE, 'contact.self_contact="false"', "contact.self_contact: is a string, not a "
                                            "boolean (got 'false';"),
    (PLATE, "run.erode_inverted=0", "run.erode_inverted: is an integer, not a boolean"),
    (PLATE, 'run.allow_large_mesh="yes"', "run.allow_large_mesh: is a string, not a boolean"),
    (PLATE, 'initial_erosion=[{radius = "1 mm", plies = ["1"]}]',
     "initial_erosion[0].plies[0]: is a string, not an integer (got '1'; valid: an integer "
     "≥ 0 such as 0, not quoted)"),
    (CASING, 'mesh.casing.layers="4"', "mesh.casing.layers: is a string, not an integer "
                                       "(got '4'; valid: an integer ≥ 1 and ≤ 200"),
    (CASING, "mesh.casing.offset_layers=1", "mesh.casing.offset_layers: is an integer, not "
                                            "a boolean (got 1;"),
]


@pytest.mark.parametrize("case, override, message", STRICT_CASES,
                         ids=[o for _, o, _ in STRICT_CASES])
def test_a_value_of_another_toml_type_is_refused_naming_key_type_and_valid(
        case, override, message):
    assert refusal(case, override).startswith(message)


def test_the_same_keys_take_their_own_toml_types():
    """The controls: integers, booleans and arrays of integers or floats are taken as
    before; quantities stay strings with units, dimensionless ones plain numbers."""
    spec, _ = load_case(PLATE, ["mesh.plies=3", "mesh.quarter=false", "run.threads=1",
                                "run.max_steps=10_000_000", "impactor.direction=[0, 0.0, -1]",
                                "mesh.warp_direction=[1.0, 0, 0]", "contact.self_contact=true",
                                "contact.damping=0.1", 'contact.friction="0.2"',
                                "sections.fabric.hourglass=0.05", "run.allow_large_mesh=false",
                                'boundary.1.nodes="edge_outer"', 'boundary.2.nodes="edge_outer"'])
    assert (spec.mesh.plies, spec.mesh.quarter, spec.run.threads) == (3, False, 1)
    assert spec.run.max_steps == 10_000_000
    assert spec.impactor.direction == (0.0, 0.0, -1.0)
    assert spec.mesh.warp_direction == (1.0, 0.0, 0.0)
    assert spec.contact.self_contact is True
    assert (spec.contact.damping, spec.contact.friction) == (0.1, 0.2)
    assert spec.impactor.velocity == 120.0  # "120 m/s", a quantity string as always


def imported_doc(tmp_path: Path, **mesh) -> dict:
    """The corpus's 3×3 Abaqus plate case, with the example Kevlar, ``mesh`` keys set."""
    (tmp_path / "kevlar.toml").write_text(KEVLAR.read_text())
    (tmp_path / "plate.inp").write_text(
        plate_inp() + "*NSET, NSET=empty\n*ELSET, ELSET=none\n")
    doc = copy.deepcopy(INP_CASE)
    doc["mesh"].update(mesh)
    return doc


@pytest.mark.parametrize("value, message", [
    ("radial", "mesh.warp_direction: is a string, not 'circumferential' or three numbers "
               "(got 'radial'; valid: 'circumferential' (the hoop direction about mesh.axis), "
               "or three numbers"),
    (["1", 0, 0], "mesh.warp_direction: has a string at [0] ('1'), not a number"),
])
def test_an_imported_meshs_warp_direction_is_one_message_not_one_per_union_member(
        tmp_path, value, message):
    with pytest.raises(InputError) as err:
        case_from_dict(imported_doc(tmp_path, warp_direction=value), "case.toml")
    assert str(err.value) == "case.toml: " + message + str(err.value).split(message, 1)[1]
    assert str(err.value).count("\n") == 0
    spec = case_from_dict(imported_doc(tmp_path, warp_direction=[0, 1, 0]), "case.toml")
    assert spec.mesh.warp == (0.0, 1.0, 0.0)


# --- sets and radii that select nothing ----------------------------------------------------


def compile_doc(doc: dict, base: Path):
    from wovenimpact.setup.compile import compile_case

    return compile_case(case_from_dict(doc, "case.toml"), base)


def test_a_boundary_on_an_empty_node_set_of_an_imported_mesh_is_an_error_naming_it(tmp_path):
    doc = imported_doc(tmp_path)
    doc["boundary"].append({"nodes": "empty", "type": "pinned"})
    with pytest.raises(InputError, match=r"^boundary\[1\]\.nodes: node set 'empty' holds no "
                                         r"node, so this boundary would constrain nothing"):
        compile_doc(doc, tmp_path)


def test_an_initial_velocity_on_an_empty_node_set_is_an_error_naming_it(tmp_path):
    doc = imported_doc(tmp_path)
    doc["initial_velocity"][0]["nodes"] = "empty"
    with pytest.raises(InputError, match=r"^initial_velocity\[0\]\.nodes: node set 'empty' "
                                         r"holds no node, so this velocity would move nothing"):
        compile_doc(doc, tmp_path)


def test_an_initial_velocity_radius_that_reaches_no_node_is_an_error_naming_it(tmp_path):
    doc = imported_doc(tmp_path)
    doc["initial_velocity"][0].update(centre=["10 mm", "10 mm", "0 mm"], radius="1 mm")
    with pytest.raises(InputError, match=r"^initial_velocity\[0\]\.radius: no node of 'all' "
                                         r"lies within 0\.001 m of \[0\.01, 0\.01, 0\.0\]"):
        compile_doc(doc, tmp_path)


def test_an_element_set_of_mesh_sections_that_holds_no_element_is_an_error(tmp_path):
    doc = imported_doc(tmp_path, sections={"plate": "fabric", "none": "fabric"})
    with pytest.raises(InputError, match=r"^mesh\.sections: element set 'none' of plate\.inp "
                                         r"holds no element"):
        compile_doc(doc, tmp_path)


# --- a fabric without crimp; compaction against the crossover's height ---------------------


def kevlar(**changes) -> dict:
    doc = read_toml(KEVLAR, "material file")
    for key, value in changes.items():
        set_dotted(doc, "material." + key.replace("__", "."), value)
    return doc


def material_refusal(doc: dict) -> str:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # refused, not warned of (nor a RuntimeWarning)
        with pytest.raises(InputError) as err:
            material_from_dict(doc, "kevlar.toml")
    return str(err.value)


@pytest.mark.parametrize("changes, key", [
    ({"warp__crimp": 0}, "material.warp.crimp"),
    ({"fill__crimp": "0 %"}, "material.fill.crimp"),
    ({"warp__h0": "0 mm"}, "material.warp.h0"),
])
def test_a_fabric_without_crimp_is_refused_with_the_reason(changes, key):
    text = material_refusal(kevlar(**changes))
    assert text.startswith(f"kevlar.toml: {key}: is 0: a straight ")
    assert "outside the crossover model" in text and "docs/theory.md §1.9" in text
    valid = "valid: a crimp > 0 and ≤ 0.5" if key.endswith("crimp") else "valid: a length > 0"
    assert valid in text


def test_both_families_without_crimp_name_both_and_nothing_else():
    lines = material_refusal(kevlar(warp__crimp=0, fill__crimp=0)).splitlines()
    assert [line.split(": ")[1] for line in lines] == ["material.warp.crimp",
                                                       "material.fill.crimp"]


def test_a_small_crimp_or_a_given_h0_with_crimp_0_is_taken():
    """A nearly straight family is a fabric; a crimp of 0 with h0 given uses the h0 (and
    the existing note that it is off eq. 5.5)."""
    notes: list[str] = []
    p = material_from_dict(kevlar(warp__crimp=0.001), collect_warnings=notes)
    assert p.warp.h0 > 0.0 and notes == []
    p = material_from_dict(kevlar(warp__crimp=0, warp__h0="0.12 mm"), collect_warnings=notes)
    assert p.warp.h0 == pytest.approx(0.12e-3) and "material.warp.h0" in notes[0]


@pytest.mark.parametrize("a", ["0.2496 mm", "0.3 mm", "0.45 mm"])
def test_a_compaction_limit_at_or_above_the_crossover_height_is_refused(a):
    """h_w0 + h_f0 = 2 × 0.124795 mm = 0.24959 mm (eq. 5.5); the old bound, the two yarn
    thicknesses (0.4998 mm), let 0.3 and 0.45 mm through."""
    text = material_refusal(kevlar(compaction__a=a))
    assert text.startswith("kevlar.toml: material.compaction.a: is not below the crossover's "
                           "height h_w0 + h_f0 = 0.24959 mm")
    assert f"(got '{a}'; valid: a length < 0.24959 mm" in text


def test_a_compaction_limit_below_the_height_is_taken_and_follows_a_given_h0():
    assert material_from_dict(kevlar(compaction__a="0.2495 mm")).compaction_a == 0.2495e-3
    # h0 given: the height is h_w0 + h_f0 = 0.1 + 0.124795 mm
    text = material_refusal(kevlar(warp__h0="0.1 mm", compaction__a="0.23 mm"))
    assert "h_w0 + h_f0 = 0.2248 mm" in text


# --- a mesh that would take minutes to build -------------------------------------------------


def test_a_mesh_that_would_take_minutes_is_refused_at_once_unless_allowed():
    """0.05 mm elements on the 97 mm quarter plate of plies1_100: 970² = 941 000
    elements, 21 s and 3.5 GB to build before the first step; said at validation, with
    the element size that would do and the key that allows it."""
    case = EXAMPLES / "plate_impact" / "plies1_100.toml"
    start = time.perf_counter()
    text = refusal(case, 'mesh.element_size="0.05 mm"')
    assert time.perf_counter() - start < 5.0
    assert text.startswith("mesh.element_size: gives about 9.41e+05 elements (side 0.097 m, "
                           "1 plies), more than 500,000: a mesh that takes minutes")
    assert "valid: mesh.element_size ≥ about 0.0686 mm, or run.allow_large_mesh = true" in text
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)
        spec, _ = load_case(case, ['mesh.element_size="0.05 mm"', "run.allow_large_mesh=true"])
    assert spec.run.allow_large_mesh is True
    load_case(case, ['mesh.element_size="0.07 mm"'])  # 693² = 480 000: no flag needed


def test_a_large_casing_names_the_key_that_sets_its_size():
    text = refusal(CASING, 'mesh.element_size="1 mm"')
    assert text.startswith("mesh.element_size: gives about 5.53e+05 elements (casing and "
                           "blade, 4 layers), more than 500,000")


def test_a_large_imported_mesh_is_refused_once_read(tmp_path, monkeypatch):
    import wovenimpact.setup.compile as compile_module

    monkeypatch.setattr(compile_module, "LARGE_MESH", 8)  # the 3×3 plate has 9 elements
    doc = imported_doc(tmp_path)
    with pytest.raises(InputError, match=r"^mesh\.file: 'plate\.inp' holds 9 elements, more "
                                         r"than 8: .*run\.allow_large_mesh = true"):
        compile_module.make_mesh(case_from_dict(doc, "case.toml"), tmp_path)
    doc["run"]["allow_large_mesh"] = True
    mesh, _ = compile_module.make_mesh(case_from_dict(doc, "case.toml"), tmp_path)
    assert mesh.n_elems == 9


def test_a_kinematic_fraction_without_the_yarn_step_is_refused_naming_both_keys():
    """run.kinematic_fraction is η of the yarn step's kinematic bound: given with the
    isotropic step it would be ignored, so it is refused (and outside 0 < η ≤ 0.5 too)."""
    text = refusal(PLATE, "run.kinematic_fraction=0.25")
    assert "kinematic_fraction" in text and "stable_step" in text and "'isotropic'" in text
    assert "0.5" in refusal(CASING, "run.kinematic_fraction=0.6")
    spec, _ = load_case(CASING, ["run.kinematic_fraction=0.25"])
    assert spec.run.stable_step == "yarn" and spec.run.kinematic_fraction == 0.25
