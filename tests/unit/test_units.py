"""wovenimpact.units: strings with units → SI floats, and the errors for everything else."""

from __future__ import annotations

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from wovenimpact.errors import InputError
from wovenimpact.units import DIMENSIONS, QuantityError, to_si

REL = 1e-14  # pint factors and the 15-digit rounding are exact to a few ulp


@pytest.mark.parametrize(
    ("text", "dimension", "si"),
    [
        ("27 1/in", "inverse_length", 27 / 0.0254),  # 1062.99 1/m
        ("0.94 mm", "length", 0.94e-3),
        ("96 GPa", "pressure", 96e9),
        ("1.44 g/cm^3", "density", 1440.0),
        ("0.149664 mm^2", "area", 0.149664e-6),
        ("315 N", "force", 315.0),
        ("0.98432 N", "force", 0.98432),
        ("984.32 mN", "force", 0.98432),
        ("0.477 kg/m^2", "areal_density", 0.477),
        ("120 m/s", "velocity", 120.0),
        ("60 us", "time", 60e-6),
        ("1047 rad/s", "angular_velocity", 1047.0),
        ("10000 rpm", "angular_velocity", 10000 * 2 * math.pi / 60),
        ("90 deg", "angle", math.pi / 2),
        ("12 J", "energy", 12.0),
        ("1.1 g", "mass", 1.1e-3),
        ("1 in", "length", 0.0254),
        ("4.21 %", "dimensionless", 0.0421),
        ("0.0421", "dimensionless", 0.0421),
        (0.0421, "dimensionless", 0.0421),
        (3, "dimensionless", 3.0),
        ("-2.5e-3 m", "length", -2.5e-3),
    ],
)
def test_conversion_to_si(text, dimension, si):
    assert to_si(text, dimension, "f") == pytest.approx(si, rel=REL)


def test_thread_count_per_inch_value():
    assert to_si("27 1/in", "inverse_length", "n") == pytest.approx(1062.99, abs=0.005)


@pytest.mark.parametrize("name", sorted(DIMENSIONS))
def test_every_dimension_example_parses_as_that_dimension(name):
    value = to_si(DIMENSIONS[name].example, name, "f")
    assert math.isfinite(value) and value > 0


@pytest.mark.parametrize("value", ["96", 96, 96.0, " 96 "])
def test_bare_number_for_dimensioned_quantity_is_an_error(value):
    with pytest.raises(InputError) as err:
        to_si(value, "pressure", "material.warp.modulus")
    msg = str(err.value)
    assert msg.startswith(f"material.warp.modulus = {value!r} has no unit")
    assert "'96 GPa'" in msg


def test_no_unit_message_is_the_documented_one():
    with pytest.raises(InputError) as err:
        to_si("96", "pressure", "material.warp.modulus")
    assert str(err.value) == (
        "material.warp.modulus = '96' has no unit: give a pressure such as '96 GPa'"
    )


def test_wrong_dimension_message_names_the_dimension_found():
    with pytest.raises(InputError) as err:
        to_si("96 mm", "pressure", "material.warp.modulus")
    assert str(err.value) == (
        "material.warp.modulus = '96 mm' has the wrong dimension ([length]); "
        "expected a pressure such as '96 GPa'"
    )


@pytest.mark.parametrize(
    "text",
    [
        "abc",
        "",
        "GPa",
        "96 GPaa",
        "nan GPa",
        "inf GPa",
        "2**10 GPa",
        "96 GPa)",
        "96 (GPa",
        "96 G Pa ^",
        "1e400 GPa",
        "__import__('os') GPa",
        "96 GPa; rm",
    ],
)
def test_unreadable_strings_are_input_errors(text):
    with pytest.raises(InputError) as err:
        to_si(text, "pressure", "material.warp.modulus")
    msg = str(err.value)
    assert msg.startswith(f"material.warp.modulus = {text!r} ")
    assert "'96 GPa'" in msg


@pytest.mark.parametrize("value", [True, None, [96], {"v": 96}, math.nan, math.inf])
def test_non_quantities_are_input_errors(value):
    with pytest.raises(InputError, match="material.c = "):
        to_si(value, "dimensionless", "material.c")


def test_dimensionless_rejects_a_unit_of_another_dimension():
    with pytest.raises(InputError, match=r"wrong dimension \(\[length\]\)"):
        to_si("0.04 mm", "dimensionless", "material.warp.crimp")


@pytest.mark.parametrize(
    ("value", "dimension", "bounds", "expect"),
    [
        ("-315 N", "force", {"gt": 0.0}, "must be > 0"),
        ("0 1/in", "inverse_length", {"gt": 0.0}, "must be > 0"),
        (0.5, "dimensionless", {"ge": 0.0, "lt": 0.5}, "must be ≥ 0 and < 0.5"),
        (-0.01, "dimensionless", {"ge": 0.0}, "must be ≥ 0"),
    ],
)
def test_bounds(value, dimension, bounds, expect):
    with pytest.raises(InputError) as err:
        to_si(value, dimension, "x.y", **bounds)
    assert f"x.y = {value!r} {expect}" in str(err.value)


def test_unknown_dimension_is_a_programming_error():
    with pytest.raises(ValueError, match="unknown dimension") as err:
        to_si("1 m", "lenght", "f")
    assert not isinstance(err.value, InputError)


@given(st.floats(min_value=1e-280, max_value=1e280, allow_nan=False, allow_infinity=False))
def test_any_positive_modulus_string_round_trips(x):
    assert to_si(f"{x!r} GPa", "pressure", "m", gt=0.0) == pytest.approx(x * 1e9, rel=REL)
    assert to_si(f"{x!r} MPa", "pressure", "m") == pytest.approx(x * 1e6, rel=REL)


@given(st.floats(min_value=-1e6, max_value=1e6, allow_nan=False))
def test_lengths_in_mm_and_m_agree(x):
    assert to_si(f"{x!r} mm", "length", "f") == pytest.approx(
        to_si(f"{x!r} m", "length", "f") * 1e-3, rel=REL, abs=1e-300
    )


@pytest.mark.parametrize("text", ["166.6 Hz", "1047 1/s", "5 kHz", "3 percent"])
def test_an_angular_rate_or_angle_without_an_angle_unit_is_refused(text):
    """pint counts the radian as dimensionless, so '166.6 Hz' converts to 166.6 rad/s: a
    2π error when revolutions per second were meant. An angle or angular velocity must
    name its angle (rad, deg, turn, rpm…)."""
    dimension = "angle" if text.endswith("percent") else "angular_velocity"
    with pytest.raises(QuantityError, match="has no angle in its unit"):
        to_si(text, dimension, "spin.rate")


@pytest.mark.parametrize("text, si", [("1047 rad/s", 1047.0), ("10000 rpm", 10000 * math.pi / 30),
                                      ("360 deg/s", 2 * math.pi), ("1 turn/s", 2 * math.pi)])
def test_angular_rates_with_an_angle_unit_convert(text, si):
    assert to_si(text, "angular_velocity", "spin.rate") == pytest.approx(si, rel=1e-14)
