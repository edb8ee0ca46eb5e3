"""docs/case_keys.md is the key reference generated from the input schemas
(``python -m wovenimpact.spec.reference --write docs/case_keys.md``): it must be current,
and it must list every key of every table the schemas have."""

from __future__ import annotations

import re
import typing
from pathlib import Path

from pydantic import BaseModel

from wovenimpact.spec import case, material
from wovenimpact.spec.reference import reference

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "case_keys.md"


def test_the_committed_page_is_the_generated_one():
    assert PAGE.read_text(encoding="utf-8") == reference(), (
        "docs/case_keys.md is stale: run python -m wovenimpact.spec.reference --write "
        "docs/case_keys.md")


def tables(model: type[BaseModel], seen: list) -> list[type[BaseModel]]:
    """Every model reachable from ``model`` through its fields' annotations."""
    if model in seen:
        return seen
    seen.append(model)
    stack = [f.annotation for f in model.model_fields.values()]
    while stack:
        a = stack.pop()
        if isinstance(a, type) and issubclass(a, BaseModel):
            tables(a, seen)
        stack.extend(typing.get_args(a))
    return seen


def keys_by_section(text: str) -> list[set[str]]:
    """The key column of each table on the page."""
    out = []
    for block in re.split(r"\n#+ ", text):
        keys = set(re.findall(r"^\| `(\w+)` \|", block, re.M))
        if keys:
            out.append(keys)
    return out


def test_every_key_of_every_table_is_listed():
    models = tables(case.CaseSpec, [])
    for file_model in material._FILE_MODELS.values():
        models = tables(file_model, models)
    sections = keys_by_section(reference())
    for model in models:
        if model in material._FILE_MODELS.values():
            continue  # a material file's one key is its [material] table
        fields = set(model.model_fields)
        assert fields in sections, f"{model.__name__}: keys {sorted(fields)} not one table"


def test_the_keys_a_user_needs_are_there_with_default_and_range():
    text = PAGE.read_text(encoding="utf-8")
    rows = {m[0]: m[1] for m in re.findall(r"^\| `(\w+)` \| (.*) \|$", text, re.M)}
    assert "`\"isotropic\"`" in rows["stable_step"] and "`\"yarn\"`" in rows["stable_step"]
    assert rows["energy_tolerance"].startswith("dimensionless number > 0 and ≤ 1 | `0.01`")
    assert rows["stop_when_decided"].startswith("time (s) > 0 | —")
    assert "`\"remove\"`" in rows["eroded_nodes"] and "`\"keep\"`" in rows["eroded_nodes"]
    assert "`\"approach\"`" in rows["damping_mode"]
    for table in ("[material.regularisation]", "[mesh.blade]", "[run]", "[contact]"):
        assert f"`{table}`" in text, table
    assert "fracture_scale" in rows and "strength_scale" in rows and "element_size" in rows
