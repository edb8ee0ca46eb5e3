"""Fuzz of the case schema (issue 12): any value at any of these keys of the small
base cases gives a clean InputError (one line per problem, naming the key) or a case
that compiles and steps sanely (finite state, no failure) for a few steps. Hypothesis
draws quantities over 600 orders of magnitude, wrong units, NaN/inf, wrong types."""

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

ROOT = Path(__file__).resolve().parents[2]
KEVLAR = str(ROOT / "examples" / "materials" / "kevlar_thesis.toml")
STEPS = 15
# an error line: the file (the schema's errors; the compiler's physical checks name the key
# only), a dotted key of the case (list items by index; two keys "a / b"), what is wrong
KEY = r"[a-z_]+(?:\.\w+|\[\d+\])*"
PROBLEM_LINE = re.compile(rf"(?:fuzz\.toml: )?(?P<key>{KEY}(?: / {KEY})*)(?::| =) \S")

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
            for line in lines:  # one line per problem, naming the key
                m = PROBLEM_LINE.match(line)
                assert m, f"names no key of the case: {line!r}"
                for key in m["key"].split(" / "):
                    assert re.split(r"[.\[]", key)[0] in CaseSpec.model_fields, line
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
