"""Building blocks of the input schemas: quantity fields and readable error reports.

:func:`quantity` makes a pydantic field type that accepts ``"96 GPa"`` and stores
the SI float (via :func:`wovenimpact.units.to_si`); :func:`integer`, :func:`boolean` and
:func:`vector` take TOML's own types and nothing else (a string ``"4"`` is not 4, ``1`` or
``"yes"`` is not ``true``, ``["1", "0", "0"]`` is not a direction), as a keyword deck
would. :func:`problems_from_validation`
turns a pydantic ``ValidationError`` into :class:`Problem` records, and
:func:`raise_problems` raises them as ONE :class:`InputError` whose lines read

    <file>: material.warp.modulus: has no unit (got '96'; valid: a pressure > 0 such as '96 GPa')
"""

from __future__ import annotations

import tomllib
import types
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Annotated, Any

import annotated_types
from pydantic import BaseModel, BeforeValidator, ConfigDict, Strict, ValidationError
from pydantic_core import PydanticCustomError

# InputWarning is re-exported here: one class for every input warning, which the CLI
# prints as a `warning:` line
from wovenimpact.errors import InputError, InputWarning  # noqa: F401
from wovenimpact.units import QuantityError, bounds_text, describe, to_si

STRICT = ConfigDict(extra="forbid", frozen=True)
"""Model config of every input table: unknown keys are errors."""

_MISSING = object()


@dataclass(frozen=True)
class Valid:
    """Annotation metadata: what a valid value of the field looks like (for messages)."""

    text: str


@dataclass(frozen=True)
class _ToSI:
    """Before-validator converting a quantity string to its SI float."""

    dimension: str
    gt: float | None = None
    ge: float | None = None
    lt: float | None = None
    le: float | None = None
    example: str | None = None

    def __call__(self, value: Any) -> float:
        try:
            return to_si(
                value,
                self.dimension,
                "",
                gt=self.gt,
                ge=self.ge,
                lt=self.lt,
                le=self.le,
                example=self.example,
            )
        except QuantityError as err:
            raise PydanticCustomError(
                "quantity", "{problem}", {"problem": err.problem, "valid": err.valid}
            ) from None


def quantity(dimension: str, *, gt=None, ge=None, lt=None, le=None, example=None) -> Any:
    """Field type for a quantity with units, stored as an SI float.

    Args:
        dimension: a name from :data:`wovenimpact.units.DIMENSIONS`.
        gt, ge, lt, le: bounds on the SI value.
        example: a valid value for messages (default: the dimension's example).
    """
    valid = describe(dimension, bounds_text(gt, ge, lt, le), example)
    to_si_validator = _ToSI(dimension, gt, ge, lt, le, example)
    return Annotated[float, BeforeValidator(to_si_validator), Valid(valid)]


def toml_type(value: Any) -> str:
    """The TOML type of a parsed value, for messages: "a string", "an integer", …"""
    if isinstance(value, bool):
        return "a boolean"
    for kinds, name in ((int, "an integer"), (float, "a float"), (str, "a string"),
                        ((list, tuple), "an array"), (dict, "a table")):
        if isinstance(value, kinds):
            return name
    return "a date or time" if hasattr(value, "isoformat") else f"a {type(value).__name__}"


def _is_number(value: Any) -> bool:
    """A TOML integer or float (a boolean is neither)."""
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def integer(*, ge: int | None = None, le: int | None = None, example: int) -> Any:
    """Field type for a count: a TOML integer within the bounds, never coerced (``"4"``,
    ``4.0`` and ``true`` are refused, naming the type given)."""
    bound = bounds_text(ge=ge, le=le)
    valid = f"an integer{' ' + bound if bound else ''} such as {example}, not quoted"
    bounds = [b for b in (annotated_types.Ge(ge) if ge is not None else None,
                          annotated_types.Le(le) if le is not None else None) if b is not None]
    return Annotated[int, Strict(), *bounds, Valid(valid)]


def boolean() -> Any:
    """Field type for a switch: TOML's ``true`` or ``false``, never coerced (``1``,
    ``"yes"``, ``"true"`` are refused, naming the type given)."""
    return Annotated[bool, Strict(), Valid("true or false, not quoted")]


def type_error(problem: str, valid: str) -> PydanticCustomError:
    """The validation error of a value of the wrong TOML type (rendered by
    :func:`problems_from_validation` as ``key: problem (got …; valid: …)``)."""
    return PydanticCustomError("toml_type", "{problem}", {"problem": problem, "valid": valid})


def check_numbers(value: Any, n: int, valid: str) -> Any:
    """``value`` if it is an array of ``n`` TOML numbers (integers or floats), else the
    :func:`type_error` naming what it is, or its first item that is not a number."""
    if not isinstance(value, (list, tuple)):
        problem = f"is {toml_type(value)}, not an array of {n} numbers"
    elif len(value) != n:
        problem = f"has {len(value)} items, not {n}"
    else:
        bad = [(i, c) for i, c in enumerate(value) if not _is_number(c)]
        if not bad:
            return value
        i, c = bad[0]
        problem = f"has {toml_type(c)} at [{i}] ({c!r}), not a number"
    raise type_error(problem, valid)


@dataclass(frozen=True)
class _Numbers:
    """Before-validator of :func:`vector`: :func:`check_numbers`."""

    n: int
    valid: str

    def __call__(self, value: Any) -> Any:
        return check_numbers(value, self.n, self.valid)


def vector(valid: str, n: int = 3) -> Any:
    """Field type for ``n`` plain numbers (a direction): an array of TOML integers or
    floats, stored as floats; strings and booleans are refused (``valid`` says what is)."""
    return Annotated[tuple[(float,) * n], BeforeValidator(_Numbers(n, valid)), Valid(valid)]


@dataclass(frozen=True)
class Problem:
    """One thing wrong with an input: where, what, the value found and what is valid."""

    path: str
    what: str
    got: Any = _MISSING
    valid: str = ""

    def text(self, source: str) -> str:
        extra = []
        if self.got is not _MISSING:
            extra.append(f"got {_short(self.got)}")
        if self.valid:
            extra.append(f"valid: {self.valid}")
        tail = f" ({'; '.join(extra)})" if extra else ""
        return f"{source}: {self.path}: {self.what}{tail}"


def read_text(path, what: str) -> str:
    """The text of the input file at ``path``, decoded as UTF-8 (a byte-order mark is
    accepted); an InputError naming the file and ``what`` it is ("case file",
    "material file", …) if it cannot be read, is binary or is not UTF-8 (the byte and
    its line named, UTF-16 recognised by its byte-order mark)."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as err:
        raise InputError(f"{path}: cannot read the {what} ({err.strerror})") from None
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise InputError(f"{path}: the {what} is UTF-16 (valid: UTF-8 text; save it as UTF-8)")
    if b"\x00" in data:
        at = data.index(b"\x00")
        line = data.count(b"\n", 0, at) + 1
        raise InputError(f"{path}: the {what} is not text (a NUL byte at offset {at}, line "
                         f"{line}; valid: UTF-8 text)")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        raise InputError(f"{path}: the {what} is not UTF-8 (byte {data[err.start]:#04x} at "
                         f"offset {err.start}, line {line}; valid: UTF-8 text, e.g. save "
                         "it as UTF-8 in the editor)") from None


def read_toml(path, what: str) -> dict:
    """The parsed TOML document at ``path`` (:func:`read_text`); an InputError naming
    the file and ``what`` it is ("case file", "material file", …) if it cannot be read
    or parsed."""
    path = Path(path)
    text = read_text(path, what)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(f"{path}: not valid TOML: {err}") from None


# the case's top-level tables whose every key has a default: a dotted key may create one
# the case omits (tests/unit/test_case_warnings.py checks this against spec.case.CaseSpec)
DEFAULT_TABLES = frozenset({"amplitude", "contact"})


def set_dotted(doc: dict, key: str, value: Any, label: str = "parameters") -> None:
    """doc["a"]["b"][0]["c"] = value for key "a.b.0.c" (list items by index). Missing
    tables under a ``set`` table (material overrides) are created, and a top-level table
    of :data:`DEFAULT_TABLES` (``contact.damping`` on a case without ``[contact]``);
    elsewhere the key must exist in the base case except for its last part (a new
    optional key). ``label`` names where the key came from in error messages (a study's
    ``parameters``, ``--set``)."""
    parts = key.split(".")
    node: Any = doc
    for i, part in enumerate(parts[:-1]):
        creatable = ("set" in parts[:i] or (part == "set" and parts[0] == "materials")
                     or (i == 0 and part in DEFAULT_TABLES))
        if isinstance(node, dict) and part not in node and creatable:
            node[part] = {}
        if (i == 1 and parts[0] == "materials" and parts[2:3] == ["set"]
                and isinstance(node, dict) and isinstance(node.get(part), str)):
            node[part] = {"file": node[part]}  # `name = "path"` is `name = {file = "path"}`
        if not isinstance(node, (dict, list)):
            raise _not_a_table(label, key, parts[:i], node)
        try:
            node = node[int(part)] if isinstance(node, list) else node[part]
        except (KeyError, IndexError, ValueError):
            where = ".".join(parts[: i + 1])
            raise InputError(f"{label} {key!r}: the base case has no {where!r}") from None
    last = parts[-1]
    if isinstance(node, list):
        try:
            node[int(last)] = value
        except (IndexError, ValueError):
            raise InputError(f"{label} {key!r}: no item {last!r} in that list") from None
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise _not_a_table(label, key, parts[:-1], node)


def _not_a_table(label: str, key: str, path: list[str], node: Any) -> InputError:
    """The error of a dotted ``key`` that goes on under ``path``, a plain value."""
    return InputError(f"{label} {key!r}: {'.'.join(path)!r} is a value ({node!r}), not a "
                      "table; valid: a key under a table of the base case")


def parse_override(text: str) -> tuple[str, Any]:
    """``KEY=VALUE`` of a command line ``--set``: the dotted key and the value read as a
    TOML value (``true``, ``3``, ``[0, 0, -1]``, ``"200 m/s"``), else as the plain text
    (``200 m/s``)."""
    key, sep, raw = text.partition("=")
    key, raw = key.strip(), raw.strip()
    if not sep or not key or not raw:
        raise InputError(f"--set {text!r}: expected KEY=VALUE, e.g. impactor.velocity=200 m/s")
    try:
        return key, tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        return key, raw


def apply_overrides(doc: dict, overrides) -> dict:
    """``doc`` with each ``KEY=VALUE`` of ``overrides`` set (in place; returned)."""
    for text in overrides or ():
        key, value = parse_override(text)
        set_dotted(doc, key, value, label="--set")
    return doc


def input_error(problems: list[Problem], source: str) -> InputError:
    """One InputError listing every problem, one per line."""
    return InputError("\n".join(p.text(source) for p in problems))


def raise_problems(problems: list[Problem], source: str) -> None:
    """Raise :func:`input_error` of ``problems`` unless the list is empty."""
    if problems:
        raise input_error(problems, source)


def dotted(loc: tuple) -> str:
    """``('material', 'plasticity', 'hardening', 1, 0)`` → ``material.plasticity.hardening[1][0]``."""
    out = ""
    for part in loc:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def problems_from_validation(err: ValidationError, root: type[BaseModel]) -> list[Problem]:
    """One :class:`Problem` per pydantic error, with dotted paths and valid alternatives."""
    return [_problem(e, root) for e in err.errors(include_url=False)]


# pydantic's error types of a strict field given another type, and what the field takes
TYPE_ERRORS = {"int_type": "an integer", "bool_type": "a boolean",
               "float_type": "a number", "string_type": "a string", "list_type": "an array",
               "tuple_type": "an array"}
BOUND_ERRORS = {"greater_than_equal": ("≥", "ge"), "greater_than": (">", "gt"),
                "less_than_equal": ("≤", "le"), "less_than": ("<", "lt")}


def _problem(e: dict, root: type[BaseModel]) -> Problem:
    loc, kind, ctx = tuple(e["loc"]), e["type"], e.get("ctx") or {}
    path = dotted(loc)
    got = e.get("input", _MISSING)
    if kind in ("quantity", "toml_type"):
        return Problem(path, ctx["problem"], got, ctx["valid"])
    if kind in TYPE_ERRORS:  # a strict field given another TOML type ("4" for 4)
        return Problem(path, f"is {toml_type(got)}, not {TYPE_ERRORS[kind]}", got,
                       _valid_for(root, loc))
    if kind in BOUND_ERRORS:
        op, key = BOUND_ERRORS[kind]
        return Problem(path, f"must be {op} {ctx.get(key)}", got, _valid_for(root, loc))
    if kind == "missing":
        return Problem(path, "is missing", valid=_valid_for(root, loc))
    if kind == "extra_forbidden":
        parent = _model_at(root, loc[:-1])
        keys = ", ".join(parent.model_fields) if parent is not None else ""
        return Problem(path, f"unknown key {loc[-1]!r}", got, f"one of the keys {keys}")
    if kind == "literal_error":
        return Problem(path, "is not one of the allowed values", got, ctx.get("expected", ""))
    if kind in ("model_type", "model_attributes_type", "dict_type"):
        return Problem(path, "must be a table", got, _valid_for(root, loc))
    msg = e["msg"].removeprefix("Value error, ")  # a model's own check: its words
    msg = msg[:1].lower() + msg[1:]
    return Problem(path, msg, got, _valid_for(root, loc))


def _union_members(annotation: Any) -> list[type[BaseModel]]:
    """The models an annotation admits: itself, or the members of a union, in order."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [annotation]
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        return [m for arg in typing.get_args(annotation) for m in _union_members(arg)]
    return []


def _submodel(annotation: Any) -> type[BaseModel] | None:
    """The first model an annotation admits (None if it admits none)."""
    members = _union_members(annotation)
    return members[0] if members else None


def _model_at(root: type[BaseModel], loc: tuple) -> type[BaseModel] | None:
    """The model at ``loc`` below root. A tagged union (``Field(discriminator=...)``)
    puts its member's tag in pydantic's error path (``mesh.containment.blade.x``): the
    tag selects that member."""
    model: type[BaseModel] | None = root
    members: list[type[BaseModel]] = []  # a tagged union's members, while its tag may follow
    discriminator: str | None = None
    item: type[BaseModel] | None = None  # the table of a list's or dict's items, next part
    for part in loc:
        tagged = [m for m in members if _tag_of(m, discriminator) == part] if members else []
        if tagged:
            model, members = tagged[0], []
            continue
        if item is not None:  # [[boundary]] 0, [sections.NAME] fabric: the item's table
            model, item = item, None
            continue
        if model is None or isinstance(part, int) or part not in model.model_fields:
            return None
        info = model.model_fields[part]
        model = _submodel(info.annotation)
        item = _container_item(info.annotation)
        discriminator = info.discriminator if isinstance(info.discriminator, str) else None
        members = _union_members(info.annotation) if discriminator else []
    return model


def _container_item(annotation: Any) -> type[BaseModel] | None:
    """The table of the items of a ``list[Model]`` or ``dict[str, Model]`` annotation
    (through ``X | None``), or None."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        rest = [a for a in typing.get_args(annotation) if a is not type(None)]
        return _container_item(rest[0]) if len(rest) == 1 else None
    args = typing.get_args(annotation)
    if typing.get_origin(annotation) in (list, dict) and args:
        return _submodel(args[-1])
    return None


def _tag_of(model: type[BaseModel], discriminator: str | None) -> Any:
    """The Literal value of a tagged-union member's discriminator field (or None)."""
    info = model.model_fields.get(discriminator) if discriminator else None
    if info is None or typing.get_origin(info.annotation) is not typing.Literal:
        return None
    args = typing.get_args(info.annotation)
    return args[0] if len(args) == 1 else None


def _valid_meta(annotation: Any) -> str:
    """The :class:`Valid` text inside an annotation (through Annotated and unions such as
    ``X | None``), or ""."""
    if typing.get_origin(annotation) is typing.Annotated:
        for meta in typing.get_args(annotation)[1:]:
            if isinstance(meta, Valid):
                return meta.text
        return _valid_meta(typing.get_args(annotation)[0])
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        for arg in typing.get_args(annotation):
            text = _valid_meta(arg)
            if text:
                return text
    return ""


def _item_annotation(annotation: Any, index: int) -> Any:
    """The annotation of item ``index`` of a list or tuple annotation (through
    Annotated and ``X | None``), or None."""
    while typing.get_origin(annotation) is typing.Annotated:
        annotation = typing.get_args(annotation)[0]
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        rest = [a for a in typing.get_args(annotation) if a is not type(None)]
        return _item_annotation(rest[0], index) if len(rest) == 1 else None
    args = typing.get_args(annotation)
    if typing.get_origin(annotation) is list and args:
        return args[0]
    if typing.get_origin(annotation) is tuple and args:
        return args[index] if index < len(args) else (args[0] if args[-1] is Ellipsis else None)
    return None


def _valid_for(root: type[BaseModel], loc: tuple) -> str:
    items = 0  # an item of a list or tuple key (initial_erosion[0].plies[1]): its type's text
    while items < len(loc) and isinstance(loc[len(loc) - 1 - items], int):
        items += 1
    if items and len(loc) > items:
        field_loc = loc[:len(loc) - items]
        parent = _model_at(root, field_loc[:-1])
        if parent is None or field_loc[-1] not in parent.model_fields:
            return ""
        annotation = parent.model_fields[field_loc[-1]].annotation
        for index in loc[len(loc) - items:]:
            annotation = _item_annotation(annotation, index)
        if annotation is None:
            return ""
        return _valid_meta(annotation) or PLAIN_VALID.get(annotation, "")
    parent = _model_at(root, loc[:-1]) if loc else None
    if parent is None or isinstance(loc[-1], int) or loc[-1] not in parent.model_fields:
        return ""
    info = parent.model_fields[loc[-1]]
    for meta in info.metadata:
        if isinstance(meta, Valid):
            return meta.text
    text = _valid_meta(info.annotation)
    if text:
        return text
    sub = _submodel(info.annotation)
    if sub is not None:
        return f"a [{dotted(loc)}] table with keys {', '.join(sub.model_fields)}"
    if typing.get_origin(info.annotation) is typing.Literal:
        return ", ".join(repr(a) for a in typing.get_args(info.annotation))
    return PLAIN_VALID.get(info.annotation, "")


# what a key of a plain type takes, where its schema says nothing more
PLAIN_VALID = {str: "a string", int: "an integer, not quoted", float: "a number, not quoted",
               bool: "true or false, not quoted"}


def _short(value: Any, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else text[: limit - 3] + "..."
