"""A shortened run just runs (output intervals are clipped to the end time, with a
warning naming each key), and a quarter plate without its symmetry constraints is
warned of, naming the missing node sets."""

from __future__ import annotations

import warnings
from pathlib import Path

import pytest

from wovenimpact.errors import InputWarning
from wovenimpact.spec.case import load_case

ROOT = Path(__file__).resolve().parents[2]
# intervals: field 10 µs, history 0.5 µs, checkpoint 25 µs
TOUR = ROOT / "examples" / "cases" / "fabric_plate_impulse.toml"


def test_intervals_longer_than_a_shortened_end_time_are_clipped_with_a_warning():
    with pytest.warns(InputWarning) as record:
        spec, _ = load_case(TOUR, ['run.end_time="5 us"'])
    messages = [str(w.message) for w in record]
    assert spec.run.end_time == pytest.approx(5e-6)
    assert spec.run.checkpoint_interval == spec.run.end_time
    assert spec.run.field_interval == spec.run.end_time
    assert spec.run.history_interval == pytest.approx(0.5e-6)  # shorter: kept
    assert len(messages) == 2
    assert any("run.checkpoint_interval = 25 us" in m and "clipped" in m for m in messages)
    assert any("run.field_interval = 10 us" in m for m in messages)
    assert all("run.end_time" in m and "5 us" in m for m in messages)


def test_the_example_case_as_written_loads_without_warnings():
    with warnings.catch_warnings():
        warnings.simplefilter("error", InputWarning)
        spec, _ = load_case(TOUR)
    assert spec.run.checkpoint_interval == pytest.approx(25e-6)


@pytest.mark.parametrize("dropped, missing", [
    (("symmetry_x",), "symmetry_x"),
    (("symmetry_y",), "symmetry_y"),
    (("symmetry_x", "symmetry_y"), "symmetry_x and symmetry_y"),
])
def test_a_quarter_plate_without_symmetry_constraints_names_the_missing_sets(
        tmp_path, dropped, missing):
    text = TOUR.read_text()
    for name in dropped:
        block = f'[[boundary]]\nnodes = "{name}"\ntype = "{name}"\n'
        assert block in text
        text = text.replace(block, "")
    text = text.replace('"../materials/', f'"{(ROOT / "examples" / "materials").as_posix()}/')
    case = tmp_path / "quarter.toml"
    case.write_text(text)
    with pytest.warns(InputWarning, match=f"no boundary constrains {missing} ") as record:
        load_case(case)
    assert len(record) == 1
    assert str(case) in str(record[0].message)


def test_a_full_plate_needs_no_symmetry_sets():
    """A full plate (quarter = false) without symmetry constraints warns of nothing."""
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always", InputWarning)
        spec, _ = load_case(TOUR, ["mesh.quarter=false", "boundary.1.nodes=edge_outer",
                                   "boundary.2.nodes=edge_outer"])
    assert not spec.mesh.quarter
    assert [w for w in record if issubclass(w.category, InputWarning)] == []


def test_a_study_tells_each_input_warning_once_not_once_per_variant(tmp_path):
    """Variants run in worker processes: their warnings come back with the result and the
    study repeats each distinct one once, with the number of variants it concerns."""
    from wovenimpact.spec.fields import apply_overrides, read_toml
    from wovenimpact.studies.sweep import run_variant, warn_once

    doc = apply_overrides(read_toml(TOUR, "case"), ['run.end_time="1 us"', 'mesh.side="10 mm"',
                                                     'mesh.element_size="2.5 mm"'])
    with warnings.catch_warnings():
        warnings.simplefilter("error", InputWarning)  # nothing escapes the variant
        result = run_variant(doc, str(TOUR.parent), str(tmp_path / "v1"), {"k": 1})
    assert result["status"] == "done"
    assert len(result["warnings"]) == 2
    assert result["warnings"][0].startswith("run.field_interval = 10 us is longer")
    with pytest.warns(InputWarning) as record:
        warn_once({"a": result, "b": result, "c": {"status": "done"}}, 3)
    assert sorted(str(w.message)[:31] for w in record) == [
        "2 of 3 variants: run.checkpoint", "2 of 3 variants: run.field_inte"]


def test_a_boundary_on_an_empty_node_set_is_an_error_naming_it():
    """A sector case's clamped cut edges kept on the full ring (the containment
    example, a ring, given that boundary): the set exists but holds no node, so the
    boundary would do nothing. It was warned of; a boundary that constrains nothing is
    never the model meant (the run's answer is that of the model without it), so it is
    refused, naming the key, the set and the way out (issue 38, item 6)."""
    from wovenimpact.errors import InputError
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.spec.fields import read_toml, set_dotted

    path = ROOT / "examples" / "containment" / "hybrid_4.toml"
    doc = read_toml(path, "case")
    set_dotted(doc, "mesh.element_size", "10 mm")
    set_dotted(doc, "mesh.casing.layers", 1)
    doc["boundary"].append({"nodes": "casing.cut_edges", "type": "clamped"})
    spec, base = case_from_dict(doc, str(path)), path.parent
    with pytest.raises(InputError, match=r"^boundary\[1\]\.nodes: node set 'casing\.cut_edges' "
                                         r"holds no node, so this boundary would constrain "
                                         r"nothing \(valid: a set that holds nodes; a full "
                                         r"casing ring \(mesh\.casing\.sector = 360 deg\) has "
                                         r"no cut edges: remove this boundary, or model a "
                                         r"sector\)$"):
        compile_case(spec, base)


def test_a_material_given_as_a_path_takes_set_overrides_and_a_value_is_no_table():
    """``--set materials.NAME.set.KEY=V`` on a case whose material is ``NAME = "path"``
    (the short form of ``{file = "path"}``) sets the override; a key under a value is an
    InputError naming it, not a TypeError traceback."""
    from wovenimpact.errors import InputError
    from wovenimpact.spec.fields import set_dotted

    doc = {"materials": {"kevlar": "k.toml"}, "run": {"end_time": "1 ms"}}
    set_dotted(doc, "materials.kevlar.set.options.erode_intact_crush", 0.1, label="--set")
    assert doc["materials"]["kevlar"] == {"file": "k.toml",
                                          "set": {"options": {"erode_intact_crush": 0.1}}}
    for key in ("run.end_time.unit", "run.end_time.unit.name"):
        with pytest.raises(InputError, match=r"'run.end_time' is a value \('1 ms'\), not a table"):
            set_dotted(doc, key, "s", label="--set")


def test_an_override_of_an_optional_table_the_case_omits_sets_it_and_a_typo_is_named():
    """``--set contact.damping=0.1`` on a case without ``[contact]`` (a table whose every
    key has a default) sets the value; a misspelt table, or one with required keys
    (``[impactor]``), is an InputError naming what the base case lacks."""
    from wovenimpact.errors import InputError

    spec, _ = load_case(TOUR)
    assert spec.contact.damping == pytest.approx(0.3)  # the default
    spec, _ = load_case(TOUR, ["contact.damping=0.1", 'contact.damping_mode="approach"'])
    assert spec.contact.damping == pytest.approx(0.1)
    assert spec.contact.damping_mode == "approach"
    for key in ("contatc", "impactor"):
        with pytest.raises(InputError, match=f"the base case has no '{key}'"):
            load_case(TOUR, [f"{key}.damping=0.1"])


def test_a_study_may_set_an_omitted_default_table_before_any_case_is_read():
    """The tables an override may create are known to ``set_dotted`` on its own, in a
    fresh interpreter that has imported nothing but spec.fields (a sweep sets its
    parameters before it validates a case)."""
    import subprocess
    import sys

    code = ("from wovenimpact.spec.fields import set_dotted\n"
            "d = {'run': {}}\nset_dotted(d, 'contact.damping', 0.1)\nprint(d['contact'])")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "{'damping': 0.1}"


def test_the_tables_an_override_may_create_are_the_cases_defaulted_tables():
    """``spec.fields.DEFAULT_TABLES`` (known below the case schema, so that spec.fields
    imports nothing above it) are exactly the top-level tables of ``CaseSpec`` whose
    every key has a default."""
    from pydantic import BaseModel

    from wovenimpact.spec.case import CaseSpec
    from wovenimpact.spec.fields import DEFAULT_TABLES

    assert DEFAULT_TABLES == {name for name, f in CaseSpec.model_fields.items()
                              if isinstance(f.default, BaseModel)}
