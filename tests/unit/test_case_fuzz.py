"""Fuzz of the case schema (issue 12): any value at any of these keys of the small
base cases gives a clean InputError or a case that compiles and steps sanely (finite
state, no failure) for a few steps. Hypothesis draws quantities over 600 orders of
magnitude, wrong units, NaN/inf, wrong types.

A clean error is one line per problem, and each line says three things: the key (a key
of the case), the value it refused, and what is valid. The schema's lines end in
``(got VALUE; valid: …)``, VALUE the value as given at that key (or its SI magnitude);
the compiler's physical checks name the key with the figures they compared and end in
``(valid: …)`` or say what to change (``…; move the nose tip further away``)."""

from __future__ import annotations

import math
import re
import warnings
from pathlib import Path

import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from tests.corpus.generate import IMPACT, PLATE, _set
from wovenimpact.errors import InputError, InputWarning
from wovenimpact.setup.compile import compile_case
from wovenimpact.solver import Workspace, step
from wovenimpact.spec.case import CaseSpec, case_from_dict
from wovenimpact.units import ureg

ROOT = Path(__file__).resolve().parents[2]
KEVLAR = str(ROOT / "examples" / "materials" / "kevlar_thesis.toml")
STEPS = 15
# an error line: the file (the schema's errors; the compiler's physical checks name the key
# only), a dotted key of the case (list items by index; two keys "a / b"), what is wrong
KEY = r"[a-z_]+(?:\.\w+|\[\d+\])*"
PROBLEM_LINE = re.compile(rf"(?:fuzz\.toml: )?(?P<key>{KEY}(?: / {KEY})*)(?::| =) \S")
# the end of a schema error line: the value refused and what is valid
GOT_VALID = re.compile(r"\(got (?P<got>.+); valid: (?P<valid>\S.*)\)$")
# the compiler's lines: what is valid, or what to change
VALID_OR_REMEDY = re.compile(r"\(valid: \S[^)]*|; (?:move|use|give|set|lower|raise) \S")
# a figure the line compared (the value refused, or what it gives)
FIGURE = re.compile(r"\d(?:\.\d+)?(?:e[+-]?\d+)?|\b(?:nan|inf)\b")

KEYS = {  # key: its unit
    "mesh.side": "mm", "mesh.element_size": "mm", "mesh.spacing": "mm", "mesh.plies": None,
    "run.end_time": "us", "run.max_steps": None, "run.alpha": "",
    "sections.fabric.bending_modulus": "GPa", "sections.fabric.areal_mass": "kg/m^2",
    "sections.fabric.thickness": "mm", "sections.fabric.transverse_shear_modulus": "GPa",
    "sections.fabric.hourglass": "", "impactor.mass": "g", "impactor.velocity": "m/s",
    "impactor.radius": "mm", "impactor.position.2": "mm", "impactor.direction.2": None,
    "mesh.warp_direction.0": None,
}
UNITS = ["mm", "m", "us", "s", "GPa", "kg/m^2", "g", "m/s", "N", ""]

magnitudes = st.one_of(  # half of them of a sane size, half anything
    st.sampled_from([0.3, 0.5, 1.0, 2.0, 3.0, 10.0]),
    st.floats(0.05, 20.0),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(-300, 300).map(lambda e: 10.0 ** e),
    st.integers(-300, 300).map(lambda e: -(10.0 ** e)),
)


@st.composite
def values(draw, unit):
    x = draw(magnitudes)
    kind = draw(st.sampled_from(["right unit", "right unit", "any unit", "number", "other"]))
    if kind == "right unit" and unit is not None:
        return f"{x!r} {unit}".strip()
    if kind == "any unit":
        return f"{x!r} {draw(st.sampled_from(UNITS))}".strip()
    if kind == "number":
        return draw(st.one_of(st.just(x), st.integers(-10**12, 10**12)))
    return draw(st.one_of(st.booleans(), st.text(max_size=8), st.lists(st.integers(), max_size=3)))


@st.composite
def cases(draw):
    doc = draw(st.sampled_from([PLATE, IMPACT]))
    doc = _set(doc, "materials", {"kevlar": KEVLAR})
    for key in draw(st.lists(st.sampled_from(sorted(KEYS)), min_size=1, max_size=2,
                             unique=True)):
        if key.startswith("impactor") and "impactor" not in doc:
            continue
        if key == "mesh.spacing" and doc["mesh"].get("plies", 1) == 1:
            continue
        doc = _set(doc, key, draw(values(KEYS[key])))
    return doc


def given_at(doc: dict, key: str):
    """The value at ``key`` of the case's document (``impactor.position[2]``, and a key
    the fuzz set to a table, ``mesh.warp_direction.0``); KeyError if it has none."""
    value = doc
    for part in re.findall(r"\w+", key):
        value = value[int(part)] if isinstance(value, list) else value[part]
    return value


def shows_value(got: str, value) -> bool:
    """Whether the ``got`` of an error shows ``value``: as written, or its SI magnitude
    (a quantity the schema converted before a check of the mesh it gives)."""
    if repr(value) in got or str(value) in got:
        return True
    try:
        si = ureg.Quantity(value).to_base_units().magnitude
        return math.isclose(float(got), si, rel_tol=1e-9)
    except Exception:  # noqa: BLE001 - not a quantity, or got is not one number
        return False


def check_error_line(line: str, doc: dict) -> None:
    """One line of an InputError names a key of the case, the value refused and what is
    valid (module docstring)."""
    m = PROBLEM_LINE.match(line)
    assert m, f"names no key of the case: {line!r}"
    keys = m["key"].split(" / ")
    for key in keys:
        assert re.split(r"[.\[]", key)[0] in CaseSpec.model_fields, line
    if line.startswith("fuzz.toml: "):  # the schema's
        end = GOT_VALID.search(line)
        assert end, f"says not what it got and what is valid: {line!r}"
        try:
            value = given_at(doc, keys[0])
        except (KeyError, IndexError, TypeError):
            return  # a key the fuzz did not set (its base value is refused with it)
        assert shows_value(end["got"], value), f"shows not the value {value!r}: {line!r}"
    else:  # the compiler's physical checks
        assert FIGURE.search(line[m.end():]), f"states no figure: {line!r}"
        assert VALID_OR_REMEDY.search(line), f"says not what is valid: {line!r}"


def sane_steps(compiled) -> None:
    model, state = compiled.model, compiled.state
    ws = Workspace.for_model(model, state)
    for _ in range(STEPS):
        step(model, state, ws)
        if state.t >= 1e-6:
            break
    assert np.all(np.isfinite(state.x)) and np.all(np.isfinite(state.v))
    assert math.isfinite(state.dt) and state.dt > 0.0


@settings(max_examples=80, deadline=None, derandomize=True,
          suppress_health_check=[HealthCheck.too_slow])
@given(cases())
def test_any_case_value_gives_a_clean_error_or_a_sane_run(doc):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)
        try:
            spec = case_from_dict(doc, source="fuzz.toml")
            compiled = compile_case(spec, ROOT)
        except InputError as err:
            event("refused")
            lines = str(err).splitlines()
            assert lines, "an InputError without a message"
            for line in lines:  # one line per problem: the key, the value, what is valid
                check_error_line(line, doc)
            return
    event("accepted and run")
    sane_steps(compiled)  # accepted: it must run (a SimulationError fails the test)


def test_an_unknown_key_under_a_mesh_kind_lists_the_keys_of_that_kind():
    """pydantic puts the tagged union's tag in the error path (mesh.containment.blade.x);
    the message names mesh.blade.x and lists the blade's keys, not an empty list."""
    import pytest

    from wovenimpact.spec.case import load_case

    case = Path(__file__).resolve().parents[2] / "examples" / "containment" / "hybrid_4.toml"
    with pytest.raises(InputError) as err:
        load_case(case, ["mesh.blade.twistt=3 deg", "mesh.sizee=3"])
    msg = str(err.value)
    assert "mesh.blade.twistt: unknown key 'twistt'" in msg
    assert "one of the keys section, root_radius" in msg and "tip_curve" in msg
    assert ("mesh.sizee: unknown key 'sizee' (got 3; valid: one of the keys kind, "
            "element_size") in msg


def test_an_error_line_must_say_the_key_the_value_and_what_is_valid():
    """The check of the fuzz fails for the right reason: a line without the value it
    refused, without what is valid, or naming no key of the case."""
    import pytest

    doc = {"mesh": {"side": "abc"}}
    check_error_line("fuzz.toml: mesh.side: could not be read as a number with a unit "
                     "(got 'abc'; valid: a length > 0 such as '0.94 mm')", doc)
    check_error_line("fuzz.toml: mesh.side: gives 1 element(s) (got 0.00094; valid: ≤ 1 m)",
                     {"mesh": {"side": "0.94 mm"}})
    check_error_line("mesh.spacing = 0.0003 m is less than the shell thickness (valid: "
                     "spacing ≥ 0.0005 m)", doc)
    for bad in ["fuzz.toml: mesh.side: could not be read as a number with a unit",
                "fuzz.toml: mesh.side: wrong (got 'xyz'; valid: a length)",
                "fuzz.toml: mesh.side: wrong (got 'abc'; valid: )",
                "mesh.spacing = 0.0003 m is less than the shell thickness",
                "mesh.spacing: the plies overlap (valid: spacing above the thickness)",
                "meshes.side: wrong (got 'abc'; valid: a length)",
                "the case is wrong"]:
        with pytest.raises(AssertionError):
            check_error_line(bad, doc)
