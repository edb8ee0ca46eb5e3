"""Quantities with units in input files, converted once to SI (docs/model.md, units).

Every dimensioned number a user writes carries its unit as a string: ``"96 GPa"``,
``"27 1/in"``, ``"1.44 g/cm^3"``, ``"0.98432 N"``. :func:`to_si` checks the string
against the expected physical dimension and returns the SI magnitude (m, kg, s,
N, Pa, ...). A bare number is accepted only for a dimensionless quantity: units
are never guessed.

Strings are split into a plain decimal number and a unit expression; only the
unit expression goes to pint's parser (which does not use ``eval``), so input
such as ``"2**10 GPa"`` or ``"nan GPa"`` is rejected rather than evaluated.
"""

from __future__ import annotations

import math
import re
import tokenize
from dataclasses import dataclass

import pint

from wovenimpact.errors import InputError

ureg = pint.UnitRegistry()
"""The one unit registry of the package (pint knows ``in``/``inch``, ``mN``, ``GPa``...)."""


@dataclass(frozen=True)
class Dimension:
    """A named kind of quantity: its SI unit, a phrase for messages and an example."""

    si_unit: str
    phrase: str
    example: str


DIMENSIONS: dict[str, Dimension] = {
    "dimensionless": Dimension("dimensionless", "a dimensionless number", "0.0421"),
    "length": Dimension("m", "a length", "0.94 mm"),
    "area": Dimension("m^2", "an area", "0.149664 mm^2"),
    "inverse_length": Dimension("1/m", "a count per length", "27 1/in"),
    "pressure": Dimension("Pa", "a pressure", "96 GPa"),
    "force": Dimension("N", "a force", "315 N"),
    "density": Dimension("kg/m^3", "a density", "1.44 g/cm^3"),
    "areal_density": Dimension("kg/m^2", "an areal density", "0.477 kg/m^2"),
    "velocity": Dimension("m/s", "a velocity", "120 m/s"),
    "acceleration": Dimension("m/s^2", "an acceleration", "9.81 m/s^2"),
    "time": Dimension("s", "a time", "60 us"),
    "strain_rate": Dimension("1/s", "a strain rate", "1 1/s"),
    "angular_velocity": Dimension("rad/s", "an angular velocity", "1047 rad/s"),
    "angle": Dimension("rad", "an angle", "90 deg"),
    "energy": Dimension("J", "an energy", "12 J"),
    "mass": Dimension("kg", "a mass", "1.1 g"),
}

_NUMBER = r"[+-]?(?:\d+(?:\.\d*)?|\.\d+)(?:[eE][+-]?\d+)?"
_QUANTITY_RE = re.compile(rf"^\s*(?P<number>{_NUMBER})\s*(?P<unit>.*?)\s*$")
_MAX_LEN = 200
# What pint's unit parser raises on malformed text (found by fuzzing; it is not one class).
_PARSE_ERRORS = (
    pint.errors.PintError,
    tokenize.TokenError,
    AssertionError,
    AttributeError,
    IndexError,
    KeyError,
    SyntaxError,
    TypeError,
    ValueError,
    ZeroDivisionError,
)


class QuantityError(InputError):
    """A quantity could not be converted; the message names the field and value.

    Attributes:
        field: dotted name of the input (``material.warp.modulus``) or CLI option.
        value: the value as given.
        problem: what is wrong (``has no unit``).
        valid: what would be valid (``a pressure such as '96 GPa'``).
    """

    def __init__(self, field: str, value: object, problem: str, valid: str, *, expected: bool):
        self.field, self.value, self.problem, self.valid = field, value, problem, valid
        joiner = "; expected" if expected else ": give"
        super().__init__(f"{field} = {value!r} {problem}{joiner} {valid}")


def describe(dimension: str, bound: str = "", example: str | None = None) -> str:
    """Phrase for messages: ``a pressure > 0 such as '96 GPa'``."""
    d = _dimension(dimension)
    bound = f" {bound}" if bound else ""
    return f"{d.phrase}{bound} such as '{example or d.example}'"


def _dimension(dimension: str) -> Dimension:
    try:
        return DIMENSIONS[dimension]
    except KeyError:
        raise ValueError(
            f"unknown dimension {dimension!r}; known: {', '.join(sorted(DIMENSIONS))}"
        ) from None


def bounds_text(gt=None, ge=None, lt=None, le=None) -> str:
    """Bounds for messages: ``> 0``, ``≥ 0 and < 0.5``."""
    parts = [
        f"{op} {v:g}" for op, v in ((">", gt), ("≥", ge), ("<", lt), ("≤", le)) if v is not None
    ]
    return " and ".join(parts)


def _check_bounds(x: float, gt, ge, lt, le) -> bool:
    return not (
        (gt is not None and not x > gt)
        or (ge is not None and not x >= ge)
        or (lt is not None and not x < lt)
        or (le is not None and not x <= le)
    )


def to_si(
    value: str | float,
    dimension: str,
    field: str,
    *,
    gt: float | None = None,
    ge: float | None = None,
    lt: float | None = None,
    le: float | None = None,
    example: str | None = None,
) -> float:
    """Convert ``value`` to its SI magnitude, checking its dimension (and optional bounds).

    Args:
        value: a string with a unit (``"96 GPa"``); a plain number or a unit-less
            string only if ``dimension`` is ``"dimensionless"`` (``"4.21 %"`` works too).
        dimension: one of :data:`DIMENSIONS` (``"pressure"``, ``"length"``, ...).
        field: name used in messages (dotted path or CLI option).
        gt, ge, lt, le: optional bounds on the SI value.
        example: a valid value shown in messages (default: one per dimension).

    Returns:
        The magnitude in the SI unit of the dimension (m, Pa, N, kg/m³, rad/s, ...).

    Raises:
        QuantityError (an InputError): no unit, wrong dimension, unreadable, out of bounds.
    """
    dim = _dimension(dimension)
    bounds = bounds_text(gt, ge, lt, le)
    valid = describe(dimension, bounds, example)
    si = _magnitude(value, dimension, dim, field, valid)
    if not _check_bounds(si, gt, ge, lt, le):
        nonzero = any(b not in (None, 0.0) for b in (gt, ge, lt, le))
        shown = f" (= {si:g} {dim.si_unit})" if nonzero and dimension != "dimensionless" else ""
        raise QuantityError(field, value, f"must be {bounds}{shown}", valid, expected=True)
    return si


def _magnitude(value, dimension: str, dim: Dimension, field: str, valid: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (str, int, float)):
        raise QuantityError(field, value, "is not a quantity", valid, expected=True)
    if not isinstance(value, str):
        if dimension != "dimensionless":
            raise QuantityError(field, value, "has no unit", valid, expected=False)
        if not math.isfinite(value):
            raise QuantityError(field, value, "is not a finite number", valid, expected=True)
        return float(value)
    m = _QUANTITY_RE.match(value) if len(value) <= _MAX_LEN else None
    if m is None:
        raise QuantityError(
            field, value, "could not be read as a number with a unit", valid, expected=True
        )
    number, unit_text = float(m["number"]), m["unit"]
    if not unit_text:
        if dimension == "dimensionless":
            return number
        raise QuantityError(field, value, "has no unit", valid, expected=False)
    try:
        unit = ureg.Unit(unit_text)
    except _PARSE_ERRORS:
        raise QuantityError(
            field, value, f"has a unit pint cannot read ({unit_text!r})", valid, expected=True
        ) from None
    quantity = ureg.Quantity(number, unit)
    try:
        si = float(quantity.to(dim.si_unit).magnitude)
    except pint.errors.DimensionalityError:
        raise QuantityError(
            field,
            value,
            f"has the wrong dimension ({_dimensionality_text(unit)})",
            valid,
            expected=True,
        ) from None
    if not math.isfinite(si):
        raise QuantityError(field, value, "is not a finite number", valid, expected=True)
    if dimension in ANGULAR and _radian_power(unit) != 1:
        # pint counts the radian as dimensionless: "166.6 Hz" would pass as 166.6 rad/s,
        # a 2π error if cycles per second were meant
        raise QuantityError(field, value, f"has no angle in its unit ({unit_text!r}: cycles "
                            "or radians?)", f"{valid} (rad, deg, turn or rpm)",
                            expected=True)
    # pint's factors carry ~1 ulp of rounding (1 g/cm^3 → 999.9999999999999 kg/m^3);
    # 15 significant digits give back the decimal the user wrote.
    return float(f"{si:.15g}")


ANGULAR = ("angle", "angular_velocity")  # quantities whose unit must name an angle


def _radian_power(unit: pint.Unit) -> float:
    """The power of the radian in ``unit``'s root units: 1 for 'rad/s', 'rpm', 'deg'; 0
    for 'Hz' and '1/s', which pint also converts to rad/s."""
    return dict(ureg.Quantity(1.0, unit).to_root_units().unit_items()).get("radian", 0)


def _dimensionality_text(unit: pint.Unit) -> str:
    text = str(unit.dimensionality)
    return "dimensionless" if text == "dimensionless" else text
