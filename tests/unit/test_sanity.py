"""Physical sanity of a case at compile time (setup/sanity.py, issue 12): each check
refuses (or warns of) the input it is for, with the key and the figure named, and
lets the sane base cases through. Small meshes, compile only (no time steps)."""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import pytest

from tests.corpus.generate import IMPACT, INP_CASE, METAL, PLATE, _set, dumps, plate_inp
from wovenimpact.errors import InputError, InputWarning
from wovenimpact.setup.compile import compile_case
from wovenimpact.setup.sanity import first_step
from wovenimpact.spec.case import DEFAULT_MAX_STEPS, case_from_dict

ROOT = Path(__file__).resolve().parents[2]
MATERIALS = ROOT / "examples" / "materials"
BASE = {"kevlar": str(MATERIALS / "kevlar_thesis.toml"), "al": str(MATERIALS / "aluminium.toml")}


def compiled(doc: dict, tmp_path: Path | None = None):
    doc = _set(doc, "materials", {k: BASE[k] for k in doc["materials"]})
    spec = case_from_dict(doc, source="case.toml")
    return spec, compile_case(spec, tmp_path or ROOT)


def assert_accepted(doc: dict):
    """Compiling ``doc`` gives a model with elements (an InputError fails the test)."""
    spec, c = compiled(doc)
    assert c.model.n_elems > 0
    return spec, c


def assert_refused(doc: dict, *fragments: str, tmp_path=None) -> str:
    """Compiling ``doc`` raises a one-line InputError naming every fragment; its text."""
    with pytest.raises(InputError) as err:
        compiled(doc, tmp_path)
    text = str(err.value)
    for f in fragments:
        assert f in text, text
    assert "\n" not in text
    return text


@pytest.mark.parametrize("doc", [PLATE, IMPACT, METAL], ids=["fabric", "impact", "metal"])
def test_the_sane_base_cases_compile_without_warnings(doc):
    with warnings.catch_warnings():
        warnings.simplefilter("error", InputWarning)  # a warning fails the test
        assert_accepted(doc)


def test_the_predicted_step_count_is_end_time_over_the_first_step():
    spec, c = compiled(PLATE)
    dt, e = first_step(c.model, c.state)
    assert 0 <= e < c.model.n_elems
    # a 0.94 mm Kevlar element: L/c with c = √(E A (1+c)/(2ℓ) / μ) ~ 8 km/s, times α
    assert 1e-8 < dt < 2e-7
    steps = spec.run.end_time / dt
    limit = math.floor(steps) - 1
    assert_refused(_set(PLATE, "run.max_steps", limit), "run.max_steps", f"Δt = {dt:.3g} s",
            "the step is normal")
    assert_accepted(_set(PLATE, "run.max_steps", math.ceil(steps) + 1))
    assert spec.run.max_steps == DEFAULT_MAX_STEPS


@pytest.mark.parametrize("key, value", [
    ("sections.fabric.bending_modulus", "1e30 GPa"),
    ("sections.fabric.areal_mass", "1e-30 kg/m^2"),
])
def test_a_collapsed_first_step_is_refused_naming_the_section(key, value):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)  # the areal-mass warning
        text = assert_refused(_set(PLATE, key, value), "wave speed", "section 'fabric'",
                       "material 'kevlar'", "governed by element")
    assert "far above any material's" in text


def test_a_metal_of_no_density_is_refused_by_its_step():
    doc = _set(METAL, "materials.al", {"file": "al.toml", "set": {"density": "1e-30 kg/m^3"}})
    doc["materials"] = {"al": {"file": BASE["al"], "set": {"density": "1e-30 kg/m^3"}}}
    spec = case_from_dict(doc, source="case.toml")
    with pytest.raises(InputError, match="far above any material's"):
        compile_case(spec, ROOT)


def test_a_long_end_time_is_refused_as_long_not_as_stiff():
    assert_refused(_set(PLATE, "run.end_time", "1e6 s"), "run.end_time = 1e+06 s", "is long")


def test_overlapping_plies_are_refused_and_touching_plies_accepted():
    assert_refused(_set(IMPACT, "mesh.spacing", "0.3 mm"), "mesh.spacing", "the plies overlap")
    assert_accepted(IMPACT)  # spacing = one shell thickness (0.4992 mm): touching


def test_a_clamp_and_a_velocity_on_the_same_dof_contradict():
    extra = {"nodes": "edge_outer", "type": "velocity", "dof": "uz", "velocity": "1 m/s"}
    assert_refused(_set(PLATE, "boundary", PLATE["boundary"] + [extra]), "boundary[3]",
            "contradicts boundary[0]", "uz")
    # a velocity on a DOF the symmetry planes leave free is no contradiction
    free = {"nodes": "centre", "type": "velocity", "dof": "uz", "velocity": "1 m/s"}
    assert_accepted(_set(PLATE, "boundary", PLATE["boundary"] + [free]))


def test_a_section_thicker_than_the_mesh_is_refused():
    assert_refused(_set(PLATE, "sections.fabric.thickness", "1 m"), "larger than the whole mesh")


@pytest.mark.parametrize("position, direction, fragment", [
    (["0 mm", "0 mm", "-10 mm"], [0, 0, -1], "behind the nose"),
    (["50 mm", "50 mm", "0.85 mm"], [0, 0, -1], "no node lies within"),
])
def test_an_impactor_whose_path_misses_the_plies_is_refused(position, direction, fragment):
    doc = _set(_set(IMPACT, "impactor.position", position), "impactor.direction", direction)
    doc = _set(doc, "mesh.quarter", False)
    doc = _set(doc, "boundary", [IMPACT["boundary"][0]])
    assert_refused(doc, "the impactor's path misses the structure", fragment)


def test_an_impactor_arriving_after_the_end_is_warned_of_with_gap_and_time():
    doc = _set(IMPACT, "impactor.position", ["0 mm", "0 mm", "1 m"])
    with pytest.warns(InputWarning, match=r"reaches it at t = 0.0083\d* s .*after run.end_time"):
        compiled(doc)


def test_an_impactor_far_lighter_than_what_it_strikes_is_refused():
    assert_refused(_set(IMPACT, "impactor.mass", "1e-20 g"), "impactor.mass", "times lighter")


def test_an_impactor_crossing_elements_in_one_step_is_refused():
    assert_refused(_set(IMPACT, "impactor.velocity", "1e30 m/s"), "impactor.velocity",
            "contact would be missed")


def test_duplicate_node_and_element_ids_in_an_inp_are_refused(tmp_path):
    for kw, fragment in (("dup_node", "node 1 is defined again"),
                         ("dup_elem", "element 1 is defined again")):
        (tmp_path / "plate.inp").write_text(plate_inp(**{kw: True}))
        assert_refused(_set(INP_CASE, "mesh.file", "plate.inp"), fragment, tmp_path=tmp_path)


@pytest.mark.parametrize("element_size, ok", [("3.3 mm", True), ("3.4 mm", False),
                                              ("6 mm", False)])
def test_a_quarter_plate_needs_two_elements_along_its_half_side(element_size, ok):
    doc = _set(PLATE, "mesh.element_size", element_size)
    doc = _set(doc, "initial_velocity.0.radius", "10 mm")
    if ok:
        compiled(doc)
    else:
        assert_refused(doc, "mesh.element_size", "the quarter plate's edge (0.005 m)")


@pytest.mark.parametrize("key, value", [("mesh.side", "1e30 mm"),
                                        ("mesh.element_size", "1e-300 mm")])
def test_absurd_mesh_sizes_are_refused_before_meshing(key, value):
    with pytest.raises(InputError, match="elements in the mesh"):
        case_from_dict(_set(PLATE, key, value), source="case.toml")


def test_an_output_at_every_step_is_warned_of_only_when_there_are_many():
    doc = _set(PLATE, "run.field_interval", "1e-30 s")
    with warnings.catch_warnings():
        warnings.simplefilter("error", InputWarning)  # a warning fails the test
        assert_accepted(doc)  # 2 µs: about 13 steps, a frame each is fine
    with pytest.warns(InputWarning, match=r"run.field_interval = 1e-30 s is shorter than "
                      r"the first step .*about 1.2\d*e\+03 of them"):
        compiled(_set(doc, "run.end_time", "200 us"))


@pytest.mark.parametrize("value, fragment", [("1e30 mm", "fewer than 2 elements along"),
                                             ("1e-300 mm", "elements in the mesh")])
def test_a_containment_mesh_of_absurd_element_size_is_refused(value, fragment):
    from wovenimpact.spec.case import load_case

    with pytest.raises(InputError, match=fragment):
        load_case(ROOT / "examples" / "containment" / "hybrid_4.toml",
                  [f'mesh.element_size="{value}"'])


def test_the_case_writer_round_trips():  # the corpus and these tests write TOML with it
    import tomllib

    assert tomllib.loads(dumps(IMPACT)) == IMPACT


def test_a_mesh_in_millimetres_read_as_metres_is_refused(tmp_path):
    """A 1 mm plate drawn in mm and read as m has 1 m elements, 2000 thicknesses of its
    0.5 mm fabric: refused with the length_unit hint; read with length_unit = '1 mm' it
    is the plate it was drawn as."""
    (tmp_path / "plate.inp").write_text(plate_inp(h=1.0))
    doc = _set(INP_CASE, "mesh.file", "plate.inp")
    doc = _set(doc, "materials", {"kevlar": BASE["kevlar"]})
    with pytest.raises(InputError, match=r"more than 1000.*length_unit = '1 mm'"):
        compile_case(case_from_dict(doc, source="case.toml"), tmp_path)
    spec = case_from_dict(_set(doc, "mesh.length_unit", "1 mm"), source="case.toml")
    assert compile_case(spec, tmp_path).model.n_elems == 9
