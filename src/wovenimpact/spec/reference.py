"""The key reference of case and material files, generated from their pydantic schemas.

Every table of a case file (:class:`~wovenimpact.spec.case.CaseSpec`) and of the three
kinds of material file (:mod:`wovenimpact.spec.material`), every key of each with what it
takes (a quantity's dimension and SI unit, a choice's values, a count's range), its
default and the comment the schema's source gives it. docs/case_keys.md is this text;
``tests/docs/test_case_keys.py`` fails when the page and the schemas part.

    python -m wovenimpact.spec.reference                          # print it
    python -m wovenimpact.spec.reference --write docs/case_keys.md
"""

from __future__ import annotations

import inspect
import io
import math
import re
import sys
import tokenize
import types
import typing
from pathlib import Path

import annotated_types
from pydantic import BaseModel
from pydantic.fields import FieldInfo
from pydantic_core import PydanticUndefined

from wovenimpact.spec import case, material
from wovenimpact.spec.fields import _ToSI
from wovenimpact.units import DIMENSIONS, bounds_text

HEADER = """\
# Case and material keys

Generated from the input schemas (`src/wovenimpact/spec/case.py`, `spec/material.py`) by
`python -m wovenimpact.spec.reference --write docs/case_keys.md`; `tests/docs/test_case_keys.py`
fails when this page and the schemas part. Every quantity carries its unit in the file
(`"0.94 mm"`, `"120 m/s"`); the *takes* column names its dimension, the SI unit it is
stored in and the bounds it must meet (in that unit). A key without a default must be
given; "—" means not given (the key's comment says what that means). A key on the command
line (`--set KEY=VALUE`) is dotted: `run.end_time`, `mesh.casing.layers`,
`initial_velocity.0.radius`. A whole number, a switch or a list of plain numbers is
written as TOML writes it — `plies = 4`, `quarter = true`, `direction = [0, 0, -1]` — and
`"4"`, `4.0`, `1` for true or `["1", "0", "0"]` are errors naming the key. What a valid
file may still not say, and what is only warned of: [inputs.md](inputs.md). The model
behind the keys: [theory.md](theory.md).
"""


def _comments(cls: type) -> dict[str, str]:
    """Field name → the comment lines right above its line in the class body, and the
    comment at the end of its line (the schema's own words)."""
    try:
        source = inspect.getsource(cls)
    except (OSError, TypeError):
        return {}
    out: dict[str, str] = {}
    pending: list[str] = []
    lines = source.splitlines()
    tokens = list(tokenize.generate_tokens(io.StringIO(source).readline))
    inline = {t.start[0]: t.string for t in tokens if t.type == tokenize.COMMENT
              and lines[t.start[0] - 1].strip() != t.string}
    for number, text in enumerate(lines, start=1):
        stripped = text.strip()
        if stripped.startswith("#"):
            pending.append(stripped.lstrip("#").strip())
            continue
        name = stripped.split(":", 1)[0].strip() if ":" in stripped else ""
        if name.isidentifier() and not stripped.startswith(("def ", "class ", "@")):
            words = pending + ([inline[number].lstrip("#").strip()] if number in inline else [])
            if words:
                out[name] = " ".join(words)
        pending = []
    return out


def _doc(cls: type) -> str:
    """The first paragraph of a class's docstring, on one line, in markdown."""
    doc = inspect.getdoc(cls) or ""
    text = " ".join(doc.split("\n\n", 1)[0].split())
    text = re.sub(r":\w+:`~?(?:[\w.]*\.)?(\w+)`", r"`\1`", text)  # :class:`~a.b.C` → `C`
    return text.replace("``", "`")


def _strip_optional(annotation):
    """(annotation without None, whether None was allowed)."""
    args = typing.get_args(annotation)
    if typing.get_origin(annotation) in (typing.Union, types.UnionType) and type(None) in args:
        rest = [a for a in args if a is not type(None)]
        return (rest[0] if len(rest) == 1 else typing.Union[tuple(rest)]), True
    return annotation, False


def _metadata(annotation, extra=()) -> tuple[object, list]:
    """(the bare type, its Annotated metadata plus ``extra``)."""
    meta = list(extra)
    while typing.get_origin(annotation) is typing.Annotated:
        args = typing.get_args(annotation)
        annotation, meta = args[0], meta + list(args[1:])
    return annotation, meta


def _quantity(meta) -> _ToSI | None:
    for m in meta:
        if isinstance(getattr(m, "func", None), _ToSI):
            return m.func
    return None


def _bounds(meta) -> str:
    b = {}
    for m in meta:
        for name in ("gt", "ge", "lt", "le"):
            if isinstance(m, getattr(annotated_types, name.capitalize())):
                b[name] = getattr(m, name)
        if isinstance(m, annotated_types.MinLen) and m.min_length:
            b["min_length"] = m.min_length
    length = b.pop("min_length", None)
    text = bounds_text(**b)
    if length:
        text = (text + ", " if text else "") + ("not empty" if length == 1 else
                                                 f"at least {length} items")
    return text


def _quantity_text(q: _ToSI) -> str:
    d = DIMENSIONS[q.dimension]
    bound = bounds_text(q.gt, q.ge, q.lt, q.le)
    unit = "" if q.dimension == "dimensionless" else f" ({d.si_unit})"
    name = d.phrase.split(" ", 1)[1] if " " in d.phrase else d.phrase
    return f"{name}{unit}" + (f" {bound}" if bound else "")


def _display_unit(dimension: str, value: float) -> str:
    """A default in the unit a case file would write it in."""
    if dimension == "length" and 0 < abs(value) < 1:
        return f"{value * 1e3:.10g} mm"
    if dimension == "angle":
        return f"{math.degrees(value):.10g} deg"
    if dimension == "time" and 0 < abs(value) < 1e-3:
        return f"{value * 1e6:.10g} us"
    if dimension == "dimensionless":
        return f"{value:.10g}"
    return f"{value:.10g} {DIMENSIONS[dimension].si_unit}"


def _takes(annotation, meta) -> str:
    """What a value of this type looks like, in words."""
    annotation, meta = _metadata(annotation, meta)
    q = _quantity(meta)
    if q is not None:
        return _quantity_text(q)
    origin, args = typing.get_origin(annotation), typing.get_args(annotation)
    if origin is typing.Literal:
        return "one of " + ", ".join(f'`"{a}"`' for a in args)
    if origin in (typing.Union, types.UnionType):
        return " or ".join(dict.fromkeys(_takes(a, []) for a in args))
    if origin is tuple:
        inner = {_takes(a, []) for a in args}
        return (f"[{len(args)} × {inner.pop()}]" if len(inner) == 1
                else "[" + ", ".join(_takes(a, []) for a in args) + "]")
    if origin is list:
        bound = _bounds(meta)
        return f"list of {_takes(args[0], [])}" + (f", {bound}" if bound else "")
    if origin is dict:
        return f"table of NAME = {_takes(args[1], [])}"
    if annotation is typing.Any:
        return "value"
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return "table"
    bound = _bounds(meta)
    name = {bool: "true or false", int: "whole number", float: "number", str: "text"}.get(
        annotation, getattr(annotation, "__name__", str(annotation)))
    return name + (f" {bound}" if bound else "")


def _default(field: FieldInfo, annotation) -> str:
    if field.default is PydanticUndefined and field.default_factory is None:
        return "(required)"
    value = field.default_factory() if field.default_factory is not None else field.default
    if value is None:
        return "—"
    bare, meta = _metadata(_strip_optional(annotation)[0], field.metadata)
    q = _quantity(meta)
    if isinstance(value, BaseModel):
        return "(table defaults)"
    if q is not None and isinstance(value, (int, float)) and not isinstance(value, bool):
        return f"`{_display_unit(q.dimension, float(value))}`"
    if isinstance(value, bool):
        return f"`{str(value).lower()}`"
    if isinstance(value, str):
        return f'`"{value}"`'
    if isinstance(value, (list, dict)) and not value:
        return "empty"
    if isinstance(value, tuple):
        inner = [_metadata(a)[1] for a in typing.get_args(bare)]
        q = _quantity(inner[0]) if inner else None
        numbers = ", ".join(f"{v:.10g}" for v in value)
        unit = "" if q is None or q.dimension == "dimensionless" else \
            f" {DIMENSIONS[q.dimension].si_unit}"
        return f"`[{numbers}]`{unit}"
    return f"`{value}`"


def _models_of(annotation) -> list[type[BaseModel]]:
    """The tables (models) a field's annotation holds: itself, list or dict items, union
    members."""
    annotation, _ = _metadata(_strip_optional(annotation)[0])
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    out = []
    for a in typing.get_args(annotation):
        out += _models_of(a)
    return out


def _holds(annotation, model: type[BaseModel]) -> bool:
    """Whether ``model`` is a table a key of this annotation holds (a dict's values count;
    its keys do not)."""
    return model in _models_of(annotation)


def _table_name(prefix: str, name: str, annotation) -> str:
    bare = _metadata(_strip_optional(annotation)[0])[0]
    origin = typing.get_origin(bare)
    if origin is list:
        return f"[[{prefix}{name}]]"
    if origin is dict:
        return f"[{prefix}{name}.NAME]"
    return f"[{prefix}{name}]"


def _kind(model: type[BaseModel]) -> str:
    field = model.model_fields.get("kind")
    if field is None:
        return ""
    values = typing.get_args(_strip_optional(field.annotation)[0])
    return " or ".join(f'`kind = "{v}"`' for v in values)


def _rows(model: type[BaseModel], prefix: str) -> list[str]:
    """One markdown row per key of ``model``; a key that holds tables points to them."""
    notes = _comments(model)
    rows = []
    for name, field in model.model_fields.items():
        annotation, _ = _strip_optional(field.annotation)
        takes = _takes(annotation, field.metadata)
        if _models_of(field.annotation):
            takes += f" (see `{_table_name(prefix, name, field.annotation)}`)"
        what = notes.get(name, "").replace("|", "\\|")
        rows.append(f"| `{name}` | {takes} | {_default(field, field.annotation)} | {what} |")
    return rows


def _section(model: type[BaseModel], title: str, prefix: str, level: int) -> list[str]:
    """A table's heading, its docstring's first paragraph, its keys, then its sub-tables."""
    out = ["#" * level + f" `{title}`" + (f" with {_kind(model)}" if _kind(model) else ""), ""]
    doc = _doc(model)
    if doc:
        out += [doc, ""]
    out += ["| key | takes | default | what |", "|---|---|---|---|"] + _rows(model, prefix) + [""]
    for name, field in model.model_fields.items():
        bare = _metadata(_strip_optional(field.annotation)[0])[0]
        origin = typing.get_origin(bare)
        for sub in _models_of(field.annotation):
            key_prefix = prefix + name + {list: ".N.", dict: ".NAME."}.get(origin, ".")
            out += _section(sub, _table_name(prefix, name, field.annotation), key_prefix,
                            min(level + 1, 4))
    return out


def reference() -> str:
    """The whole reference page (markdown)."""
    out = [HEADER, "## Case files", "",
           "A case file is these tables; each is described below.", "",
           "| table | takes | default | what |", "|---|---|---|---|"]
    out += [r.replace("| `", "| `[", 1).replace("` |", "]` |", 1) if False else r
            for r in _rows(case.CaseSpec, "")]
    out.append("")
    for name, field in case.CaseSpec.model_fields.items():
        bare = _metadata(_strip_optional(field.annotation)[0])[0]
        origin = typing.get_origin(bare)
        for model in _models_of(field.annotation):
            prefix = name + {list: ".N.", dict: ".NAME."}.get(origin, ".")
            out += _section(model, _table_name("", name, field.annotation), prefix, 3)
    out += ["## Material files", "",
            "A material file is one `[material]` table whose `kind` selects its keys.", ""]
    for file_model in material._FILE_MODELS.values():
        spec = file_model.model_fields["material"].annotation
        out += _section(spec, "[material]", "material.", 3)
    return "\n".join(out).rstrip("\n") + "\n"


def main(argv: list[str]) -> None:
    text = reference()
    if argv[:1] == ["--write"] and len(argv) == 2:
        Path(argv[1]).write_text(text, encoding="utf-8")
        print(f"wrote {argv[1]}")
    elif not argv:
        sys.stdout.write(text)
    else:
        raise SystemExit("usage: python -m wovenimpact.spec.reference [--write PATH]")


if __name__ == "__main__":
    main(sys.argv[1:])
