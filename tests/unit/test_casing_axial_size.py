"""``mesh.casing.axial_element_size``: the casing's element edge along the axis apart from
the one around it (theory §8.8, "What moves with the mesh"). With it, the ring keeps its
divisions around and takes ⌈length / axial size⌉ along the axis; the blade is untouched;
absent, the model is today's bit for bit; a bad value is refused naming the key. On the
coarse 2-ply ring of test_containment_checks (12 mm, 150 mm long)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.unit.test_blade_element_size import blade_part, compiled, same_bits
from tests.unit.test_containment_checks import CASE
from wovenimpact.errors import InputError


@pytest.fixture(scope="module")
def rings():
    return {"today": compiled(), "fine axially": compiled(mesh__casing__axial_element_size="4 mm"),
            "same": compiled(mesh__casing__axial_element_size="12 mm")}


def casing_columns(c):
    """The innermost layer's distinct axial positions and angles of its nodes."""
    x = c.model.x0[c.model.node_sets["casing.layer0"]]
    return np.unique(np.round(x[:, 2], 12)), np.unique(np.round(np.arctan2(x[:, 1], x[:, 0]), 12))


def test_the_axial_size_sets_the_rows_along_the_axis_only(rings):
    today, fine = rings["today"], rings["fine axially"]
    z_today, angles_today = casing_columns(today)
    z_fine, angles_fine = casing_columns(fine)
    # 150 mm in ⌈150/4⌉ = 38 rows (today ⌈150/12⌉ = 13), the same columns around
    assert len(z_fine) - 1 == math.ceil(150 / 4) == 38
    assert len(z_today) - 1 == 13
    assert np.allclose(np.diff(z_fine), 0.15 / 38, rtol=0, atol=1e-12)
    assert same_bits(angles_fine, angles_today)
    # the casing's elements scale with the rows, the blade is the same bit for bit
    n_blade = len(today.model.elem_sets["blade.blade"])
    assert (fine.model.n_elems - n_blade) * 13 == (today.model.n_elems - n_blade) * 38
    for a, b in zip(blade_part(today), blade_part(fine)):
        assert same_bits(a, b)


def test_the_key_equal_to_the_element_size_is_todays_model(rings):
    today, same = rings["today"], rings["same"]
    assert today.model.digest() == same.model.digest()
    for name in ("x", "v", "omega"):
        assert same_bits(getattr(today.state, name), getattr(same.state, name)), name


@pytest.mark.parametrize("value, message", [
    ("0 mm", r"mesh\.casing\.axial_element_size: .*must be > 0"),
    ("3", r"mesh\.casing\.axial_element_size: has no unit"),
    ("3 s", r"mesh\.casing\.axial_element_size: .*length"),
    ("100 mm", r"mesh\.casing\.axial_element_size: gives fewer than 2 elements along the "
               r"casing's length \(0\.15 m\)"),
    ("1e-300 mm", r"gives about .* elements in the mesh"),
])
def test_a_bad_axial_size_is_refused_naming_the_key(value, message):
    from wovenimpact.spec.case import load_case

    with pytest.raises(InputError, match=message):
        load_case(CASE, [f"mesh.casing.axial_element_size={value}"])


def test_the_summary_and_the_report_name_the_axial_size(rings):
    """summary.json's casing_axial_element_size_m where the key is given (not otherwise),
    and the report's element-size line reads both sizes of the casing."""
    from wovenimpact.io.report import element_size_text
    from wovenimpact.results.summary import element_sizes
    from wovenimpact.spec.case import load_case

    fine, _ = load_case(CASE, ["mesh.casing.axial_element_size=4 mm"])
    sizes = element_sizes(fine, rings["fine axially"].model)
    assert sizes == {"element_size_m": 0.005, "blade_element_size_m": 0.005,
                     "casing_axial_element_size_m": 0.004}
    assert element_size_text(sizes) == "casing 5 mm around × 4 mm along the axis, blade 5 mm"
    plain, _ = load_case(CASE)
    assert "casing_axial_element_size_m" not in element_sizes(plain, rings["today"].model)
