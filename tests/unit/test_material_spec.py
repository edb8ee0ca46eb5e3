"""spec/material.py: material TOML files → FabricParameters / MetalParameters (SI)."""

from __future__ import annotations

import copy
import dataclasses
import math
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from wovenimpact.errors import InputError
from wovenimpact.materials.fabric import FabricParameters
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.materials.transverse_isotropic import TransverseIsotropicParameters
from wovenimpact.spec import InputWarning, load_material, material_from_dict

ROOT = Path(__file__).resolve().parents[2]
MATERIALS = ROOT / "examples" / "materials"
KEVLAR = MATERIALS / "kevlar_thesis.toml"
INCH = 0.0254
H0_TABLE_5_1 = 0.12495e-3  # m, thesis Table 5-1
H0_EXACT = 0.12480e-3  # m, eq. (5.5) solved exactly
ELL0 = 0.47037e-3  # m, 1/(2 × 27/in); Table 7-2 prints 0.47035
AREAL_MASS = 0.477  # kg/m², docs/model.md §1.8


def kevlar_doc() -> dict:
    return tomllib.loads(KEVLAR.read_text(encoding="utf-8"))


def edited(doc: dict, path: str, value) -> dict:
    """Copy of ``doc`` with ``material.<path>`` set to ``value`` (``...`` deletes it)."""
    doc = copy.deepcopy(doc)
    *parents, last = ["material", *path.split(".")]
    table = doc
    for key in parents:
        table = table[key]
    if value is ...:
        del table[last]
    else:
        table[last] = value
    return doc


def error_of(doc: dict, source: str = "case.toml") -> str:
    with pytest.raises(InputError) as err:
        material_from_dict(doc, source=source)
    return str(err.value)


# --- the shipped files ---------------------------------------------------------------


def test_kevlar_reference_file():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the reference file must be warning-free
        p = load_material(KEVLAR)
    assert isinstance(p, FabricParameters)
    for y in (p.warp, p.fill):
        assert y.half_length == pytest.approx(ELL0, rel=1e-5)
        assert y.h0 == pytest.approx(H0_TABLE_5_1, rel=5e-3)
        assert y.h0 == pytest.approx(H0_EXACT, abs=0.000005e-3)
        assert y.crimp == 0.0421
        assert y.area == pytest.approx(0.149664e-6, rel=1e-12)
        assert y.modulus == pytest.approx(96e9, rel=1e-12)
        assert y.ultimate_tension == pytest.approx(315.0, rel=1e-12)
        assert y.width == pytest.approx(0.9407e-3, rel=1e-12)
        assert y.thickness == pytest.approx(0.2499e-3, rel=1e-12)
    assert p.compaction_a == pytest.approx(0.12389e-3, rel=1e-12)
    assert p.compaction_b == pytest.approx(0.98432, rel=1e-12)
    assert p.shear_g1 == pytest.approx(0.0824e9, rel=1e-12)
    assert p.shear_g2 == pytest.approx(8.24e9, rel=1e-12)
    assert p.shear_c_max == 0.65
    assert p.fibre_density == pytest.approx(1440.0, rel=1e-12)
    assert p.areal_mass == pytest.approx(AREAL_MASS, rel=0.01)
    assert p.shell_thickness == pytest.approx(4 * p.warp.h0, rel=1e-15)
    o = p.options
    assert (o.homogenisation, o.shear, o.frame, o.failure) == ("virial", "true", "fibre", "instant")


def test_published_yarn_file_differs_only_in_ultimate_tension():
    ref = load_material(KEVLAR)
    alt = load_material(MATERIALS / "kevlar_published_yarn.toml")
    assert alt.warp.ultimate_tension == pytest.approx(3.4e9 * 0.149664e-6, rel=1e-3)
    assert alt.fill.ultimate_tension == alt.warp.ultimate_tension
    for family in ("warp", "fill"):
        yarn = dataclasses.replace(getattr(alt, family), ultimate_tension=315.0)
        assert yarn == getattr(ref, family)
    assert dataclasses.replace(alt, warp=ref.warp, fill=ref.fill) == ref


@pytest.mark.parametrize("path", sorted(MATERIALS.glob("*.toml")), ids=lambda p: p.name)
def test_every_shipped_material_file_loads_without_warnings(path):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        p = load_material(path)
    assert isinstance(p, FabricParameters | MetalParameters | TransverseIsotropicParameters)


@pytest.mark.parametrize(
    ("name", "kind", "density", "modulus", "poisson", "hardening", "fracture"),
    [
        ("aluminium", "j2_plastic", 2780.0, 72e9, 0.32, ((0, 77.951e6), (0.18, 213.78e6)), 0.18),
        ("titanium", "j2_plastic", 4424.0, 115.1424e9, 0.35, ((0, 827.3709e6),), 0.25),
        ("steel", "elastic", 7922.0, 210e9, 0.3, (), None),
    ],
)
def test_metal_files_hold_model_md_section_5_values(
    name, kind, density, modulus, poisson, hardening, fracture
):
    m = load_material(MATERIALS / f"{name}.toml")
    assert isinstance(m, MetalParameters)
    assert (m.name, m.kind, m.poisson, m.fracture_strain) == (name, kind, poisson, fracture)
    assert m.density == pytest.approx(density, rel=1e-12)
    assert m.modulus == pytest.approx(modulus, rel=1e-12)
    assert len(m.hardening) == len(hardening)
    for (e, s), (e_ref, s_ref) in zip(m.hardening, hardening):
        assert e == e_ref and s == pytest.approx(s_ref, rel=1e-12)


# --- geometry rules ------------------------------------------------------------------


def test_half_length_uses_the_crossing_family_thread_count():
    doc = edited(kevlar_doc(), "fill.thread_count", "20 1/in")
    doc = edited(doc, "fill.width", "1.2 mm")  # fill pitch 1/n_fill = 1.27 mm
    p = material_from_dict(doc, collect_warnings=[])
    assert p.warp.half_length == pytest.approx(0.5 * INCH / 20, rel=1e-12)  # 1/(2 n_fill)
    assert p.fill.half_length == pytest.approx(0.5 * INCH / 27, rel=1e-12)  # 1/(2 n_warp)


def test_given_h0_replaces_eq_5_5_and_is_checked_against_the_crimp():
    doc = edited(kevlar_doc(), "warp.h0", "0.12495 mm")
    notes: list[str] = []
    p = material_from_dict(doc, collect_warnings=notes)
    assert p.warp.h0 == pytest.approx(0.12495e-3, rel=1e-12)
    assert p.fill.h0 == pytest.approx(H0_EXACT, abs=0.000005e-3)
    assert notes == []  # 0.12495 vs 0.12480 mm: within 1 %
    with pytest.warns(InputWarning, match=r"material\.warp\.h0: '0\.15 mm'"):
        material_from_dict(edited(doc, "warp.h0", "0.15 mm"))


def test_optional_thickness_and_areal_density_override_the_defaults():
    doc = edited(kevlar_doc(), "thickness", "0.6 mm")
    doc = edited(doc, "areal_density", "0.5 kg/m^2")
    p = material_from_dict(doc)
    assert p.shell_thickness == pytest.approx(0.6e-3, rel=1e-12)
    assert p.areal_mass == pytest.approx(0.5, rel=1e-12)


def test_area_far_from_the_lenticular_section_warns():
    doc = edited(kevlar_doc(), "fill.area", "0.2 mm^2")
    with pytest.warns(InputWarning, match=r"material\.fill\.area.*lenticular"):
        material_from_dict(doc)
    notes: list[str] = []
    material_from_dict(doc, collect_warnings=notes)
    assert len(notes) == 1 and "(2/π)·width·thickness" in notes[0]


def test_progressive_failure_with_softening_strain():
    doc = edited(kevlar_doc(), "options.failure", "progressive")
    p = material_from_dict(edited(doc, "options.softening_strain", 0.01))
    assert (p.options.failure, p.options.softening_strain) == ("progressive", 0.01)


def test_softening_strain_with_instant_failure_warns_that_it_is_ignored():
    doc = edited(kevlar_doc(), "options.softening_strain", 0.01)
    with pytest.warns(InputWarning, match="ignored"):
        p = material_from_dict(doc)
    assert p.options.softening_strain == 0.0


def test_width_may_exceed_the_pitch_by_the_rounding_tolerance_only():
    pitch_mm = INCH / 27 * 1e3  # 0.940741 mm
    material_from_dict(
        edited(kevlar_doc(), "warp.width", f"{pitch_mm * 1.0009:.6f} mm"), collect_warnings=[]
    )
    too_wide = f"{pitch_mm * 1.0011:.6f} mm"
    msg = error_of(edited(kevlar_doc(), "warp.width", too_wide))
    assert msg.startswith("case.toml: material.warp.width: is wider than") and too_wide in msg


# --- errors: each names the dotted field and the offending value ----------------------


@pytest.mark.parametrize(
    ("path", "value", "expect"),
    [
        ("warp.modulus", "96", "has no unit"),
        ("fill.area", "0.149664", "has no unit"),
        ("warp.modulus", "96 mm", "wrong dimension ([length])"),
        ("warp.crimp", -0.01, "must be ≥ 0"),
        ("compaction.a", "0 mm", "must be > 0"),
        ("compaction.a", "-0.12389 mm", "must be > 0"),
        ("compaction.b", "-1 N", "must be > 0"),
        ("fill.thread_count", "0 1/in", "must be > 0"),
        ("warp.thread_count", "27", "has no unit"),
        ("warp.ultimate_tension", "0 N", "must be > 0"),
        ("fill.ultimate_tension", "-315 N", "must be > 0"),
        ("shear.c_max", 1.2, "must be > 0 and ≤ 1"),
        ("shear.c_max", 0, "must be > 0 and ≤ 1"),
        ("shear.g1", "0 GPa", "must be > 0"),
        ("shear.g2", "0.01 GPa", "smaller than g1"),
        ("fibre_density", "-1.44 g/cm^3", "must be ≥ 1 and ≤ 100000"),
        ("warp.width", "0.95 mm", "wider than the spacing of parallel warp yarns"),
        ("fill.width", "1 mm", "0.1% allowed for rounding in printed tables"),
        ("warp.thickness", "0 mm", "must be > 0"),
        ("options.frame", "lagrangian", "not one of the allowed values"),
        ("options.failure", "gradual", "not one of the allowed values"),
        ("options.homogenisation", "average", "not one of the allowed values"),
        ("options.shear", True, "not one of the allowed values"),
        ("options.softening_strain", -0.01, "must be > 0"),
        ("warp.h0", "-0.1 mm", "must be ≥ 0"),
        ("name", 5, "is an integer, not a string"),
        ("kind", "woven", "not a known material kind"),
    ],
)
def test_bad_value_names_field_and_value(path, value, expect):
    msg = error_of(edited(kevlar_doc(), path, value))
    assert msg.startswith(f"case.toml: material.{path}: ")
    assert expect in msg
    assert f"got {value!r}" in msg
    assert "valid:" in msg
    assert msg.count("\n") == 0  # exactly one problem


def test_unknown_key_names_the_key_and_the_allowed_ones():
    msg = error_of(edited(kevlar_doc(), "warp.modulu", "96 GPa"))
    assert "material.warp.modulu: unknown key 'modulu'" in msg
    for allowed in ("thread_count", "crimp", "area", "modulus", "ultimate_tension", "h0"):
        assert allowed in msg.split("valid:")[1]


def test_unknown_table_and_top_level_key():
    msg = error_of(edited(kevlar_doc(), "damping", {"alpha": 0.1}))
    assert "material.damping: unknown key 'damping'" in msg
    assert "compaction" in msg.split("valid:")[1]
    doc = kevlar_doc()
    doc["case"] = {}
    assert "case.toml: case: unknown key 'case' (got {}; valid: one of the keys material)" in (
        error_of(doc)
    )


def test_missing_key_says_what_is_expected():
    msg = error_of(edited(kevlar_doc(), "warp.area", ...))
    assert msg == (
        "case.toml: material.warp.area: is missing (valid: an area > 0 such as '0.149664 mm^2')"
    )
    msg = error_of(edited(kevlar_doc(), "compaction", ...))
    assert "material.compaction: is missing" in msg and "keys a, b" in msg


def test_progressive_failure_requires_softening_strain():
    msg = error_of(edited(kevlar_doc(), "options.failure", "progressive"))
    assert msg.startswith("case.toml: material.options.softening_strain: is required when")
    assert "'progressive'" in msg


def test_all_problems_of_a_file_are_reported_together():
    doc = edited(kevlar_doc(), "warp.modulus", "96")
    doc = edited(doc, "fill.crimp", -1)
    doc = edited(doc, "shear.extra", 1)
    lines = error_of(doc).splitlines()
    assert [line.split(":")[1].strip() for line in lines] == [
        "material.warp.modulus",
        "material.fill.crimp",
        "material.shear.extra",
    ]
    assert all(line.startswith("case.toml: ") for line in lines)


@pytest.mark.parametrize(
    ("doc", "expect"),
    [
        ({}, "material: is missing or not a table"),
        ({"material": 3}, "material: is missing or not a table"),
        ({"material": {"name": "x"}}, "material.kind: is missing"),
        ({"material": {"kind": ["elastic"]}}, "material.kind: is not a known material kind"),
    ],
)
def test_documents_without_a_material_table_or_kind(doc, expect):
    assert expect in error_of(doc)


def test_load_material_reports_file_problems(tmp_path):
    with pytest.raises(InputError, match="cannot read the material file"):
        load_material(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[material\nname = 1\n")
    with pytest.raises(InputError, match=r"bad\.toml: not valid TOML"):
        load_material(bad)
    unitless = tmp_path / "unitless.toml"
    unitless.write_text(KEVLAR.read_text().replace('"96 GPa"', '"96"', 1))
    with pytest.raises(InputError) as err:
        load_material(unitless)
    assert str(err.value).startswith(f"{unitless}: material.warp.modulus: has no unit (got '96'")


# --- metals --------------------------------------------------------------------------


def aluminium_doc() -> dict:
    return tomllib.loads((MATERIALS / "aluminium.toml").read_text(encoding="utf-8"))


@pytest.mark.parametrize(
    ("table", "where", "expect"),
    [
        ([["0.01", "77 MPa"], ["0.18", "213 MPa"]], "hardening[0][0]", "must be 0"),
        ([["0", "77 MPa"], ["0", "213 MPa"]], "hardening[1][0]", "strictly increase"),
        ([["0", "277 MPa"], ["0.18", "213 MPa"]], "hardening[1][1]", "must not decrease"),
        ([["0", "277"]], "hardening[0][1]", "has no unit"),
        ([["-0.1", "77 MPa"]], "hardening[0][0]", "must be ≥ 0"),
        ([], "hardening", "at least 1 item"),
    ],
)
def test_bad_hardening_tables(table, where, expect):
    msg = error_of(edited(aluminium_doc(), "plasticity.hardening", table))
    assert msg.startswith(f"case.toml: material.plasticity.{where}: ")
    assert expect in msg


@pytest.mark.parametrize(
    ("path", "value", "expect"),
    [
        ("poisson", 0.5, "must be ≥ 0 and < 0.5"),
        ("poisson", -0.1, "must be ≥ 0 and < 0.5"),
        ("density", "2.78", "has no unit"),
        ("modulus", "72 GPa/m", "wrong dimension"),
        ("plasticity.fracture_strain", 0, "must be > 0"),
    ],
)
def test_bad_metal_values(path, value, expect):
    msg = error_of(edited(aluminium_doc(), path, value))
    assert msg.startswith(f"case.toml: material.{path}: ")
    assert expect in msg and f"got {value!r}" in msg


def jc_doc(name: str = "al2024t3_johnson_cook") -> dict:
    return tomllib.loads((MATERIALS / f"{name}.toml").read_text(encoding="utf-8"))


@pytest.mark.parametrize(
    ("name", "a", "b", "n", "c", "d", "table_gap"),
    [
        # Lesuer (2000), UCRL-ID-138586; table gaps as stated in the files' comments
        ("al2024t3_johnson_cook", 369e6, 684e6, 0.73, 0.0083, (0.13, 0.13, -1.5, 0.011, 0.0),
         1.33e-4),
        ("ti6al4v_johnson_cook", 1098e6, 1092e6, 0.93, 0.014, (-0.09, 0.25, -0.5, 0.014, 3.87),
         1.85e-5),
    ],
)
def test_johnson_cook_files_tabulate_a_plus_b_eps_n(name, a, b, n, c, d, table_gap):
    m = load_material(MATERIALS / f"{name}.toml")
    assert m.kind == "j2_plastic" and m.fracture_strain is None
    assert (m.rate.c, m.rate.reference_rate) == (c, 1.0)
    assert m.damage.d == d and m.damage.reference_rate == 1.0
    eps = np.array([r[0] for r in m.hardening])
    assert eps[-1] == 1.0 and len(eps) == 48
    exact = a + b * eps**n
    assert np.max(np.abs(np.array([r[1] for r in m.hardening]) - exact)) <= 0.0005e6
    grid = np.linspace(0.0, 1.0, 200001)
    gap = np.max(np.abs(m.flow_stress(grid) - (a + b * grid**n)) / (a + b * grid**n))
    assert gap <= table_gap


@pytest.mark.parametrize(
    ("path", "value", "expect"),
    [
        ("rate.c", -0.01, "must be ≥ 0"),
        ("rate.reference_rate", "0 1/s", "must be > 0"),
        ("rate.reference_rate", "1", "has no unit"),
        ("rate.reference_rate", "1 m/s", "wrong dimension"),
        ("damage.d2", "nan", "could not be read"),
        ("damage.d4", -0.1, "makes the rate term"),
        ("plasticity.fracture_strain", -0.1, "must be > 0"),
    ],
)
def test_bad_johnson_cook_values(path, value, expect):
    msg = error_of(edited(jc_doc(), path, value))
    assert msg.startswith(f"case.toml: material.{path}: ")
    assert expect in msg and repr(value) in msg


def test_jc_fracture_strain_must_stay_positive_over_plane_stress_triaxialities():
    doc = edited(jc_doc("ti6al4v_johnson_cook"), "damage.d1", -0.2)  # ε_f(2/3) = −0.02
    msg = error_of(doc)
    assert msg.startswith("case.toml: material.damage: gives a fracture strain")
    assert "η = +0.6667" in msg and "'d1': -0.2" in msg


def test_jc_rate_term_needs_a_reference_rate():
    doc = edited(jc_doc(), "rate", ...)
    msg = error_of(doc)
    assert msg.startswith("case.toml: material.damage.reference_rate: is required when d4 ≠ 0")
    doc = edited(doc, "damage.reference_rate", "10 1/s")
    assert material_from_dict(doc).damage.reference_rate == 10.0
    doc = edited(edited(jc_doc(), "rate", ...), "damage.d4", 0)
    assert material_from_dict(doc).damage.reference_rate == 1.0  # irrelevant without d4


def test_unknown_key_in_the_johnson_cook_tables():
    assert "material.damage.d6: unknown key 'd6'" in error_of(edited(jc_doc(), "damage.d6", 1))
    assert "material.rate.m: unknown key 'm'" in error_of(edited(jc_doc(), "rate.m", 1.7))


def test_missing_hardening_table_names_the_key():
    msg = error_of(edited(aluminium_doc(), "plasticity.hardening", ...))
    assert msg.startswith("case.toml: material.plasticity.hardening: is missing")
    msg = error_of(edited(aluminium_doc(), "plasticity", ...))
    assert msg.startswith("case.toml: material.plasticity: is missing")


def test_hardening_table_longer_than_the_kernel_takes():
    rows = [[f"{k * 0.01:g}", f"{100 + k} MPa"] for k in range(70)]
    msg = error_of(edited(aluminium_doc(), "plasticity.hardening", rows))
    assert msg.startswith("case.toml: material.plasticity.hardening: has 70 rows, more than")


def test_elastic_material_has_no_plasticity_table():
    doc = tomllib.loads((MATERIALS / "steel.toml").read_text(encoding="utf-8"))
    doc["material"]["plasticity"] = {"hardening": [["0", "1 GPa"]]}
    assert "material.plasticity: unknown key 'plasticity'" in error_of(doc)


# --- property: values round-trip through the file format ------------------------------


@given(st.floats(min_value=1e-3, max_value=2e3, allow_nan=False, allow_infinity=False))
def test_any_positive_modulus_round_trips(gpa):
    p = material_from_dict(edited(kevlar_doc(), "warp.modulus", f"{gpa!r} GPa"))
    assert p.warp.modulus == pytest.approx(gpa * 1e9, rel=1e-14)
    assert p.fill.modulus == pytest.approx(96e9, rel=1e-14)


def test_a_modulus_stiffer_than_any_material_is_refused():
    # 2 TPa bound (diamond is 1.2 TPa): a unit slip such as "96e3 GPa" is an error
    assert "material.warp.modulus: must be > 0 and ≤ 2e+12" in error_of(
        edited(kevlar_doc(), "warp.modulus", "96e3 GPa"))


@given(st.floats(min_value=0.0, max_value=0.3, exclude_min=True), st.sampled_from(["", " %"]))
def test_crimp_round_trips_as_fraction_or_percent(c, unit):
    # crimp 0 (a straight fill) is refused: tests/unit/test_strict_inputs.py
    text = f"{c * 100!r}{unit}" if unit else c
    p = material_from_dict(edited(kevlar_doc(), "fill.crimp", text), collect_warnings=[])
    assert p.fill.crimp == pytest.approx(c, rel=1e-13, abs=1e-300)
    assert math.isfinite(p.fill.h0) and p.fill.h0 >= 0.0


def test_the_solid_yarn_file_holds_table_5_2_and_g23_defaults_to_the_isotropic_value():
    """kind = "transversely_isotropic" (solid sections, docs/solid.md §4.1): thesis Table
    5-2 in SI; without g23 the material is isotropic across its fibre; constants that
    leave the stiffness indefinite are refused naming the file and the constant."""
    p = load_material(MATERIALS / "kevlar_yarn_solid.toml")
    assert (p.e11, p.e22, p.g12, p.g23, p.nu12, p.nu23, p.density) == (
        96e9, 3.28e9, 3.28e9, 3.28e9, 0.0, 0.0, 1440.0)
    doc = tomllib.loads((MATERIALS / "kevlar_yarn_solid.toml").read_text(encoding="utf-8"))
    del doc["material"]["g23"]
    doc["material"]["nu23"] = 0.25
    p = material_from_dict(doc)
    assert p.g23 == pytest.approx(3.28e9 / 2.5) and p.is_isotropic_across
    doc["material"]["nu12"] = 4.0  # |ν12| < √((1 − ν23) E11 / (2 E22)) = 3.3
    with pytest.raises(InputError, match=r"yarn\.toml: .*nu12"):
        material_from_dict(doc, source="yarn.toml")
    doc["material"]["e11"] = "96"
    with pytest.raises(InputError, match="material.e11"):
        material_from_dict(doc)
