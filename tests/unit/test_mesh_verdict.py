"""The mesh verdict of a run (src/wovenimpact/results/mesh_verdict.py, docs/theory.md §1.4): each
failing material's element lengths against its reference size or the range its failure
table was calibrated on, and the report's box that shows it."""

from __future__ import annotations

from dataclasses import replace

import pytest

from wovenimpact.benchmark import REFERENCE_FABRIC, REFERENCE_METAL
from wovenimpact.io.report import mesh_box
from wovenimpact.materials.fabric import FailureRegularisation
from wovenimpact.materials.metal import FractureRegularisation
from wovenimpact.model import Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.results.mesh_verdict import mesh_verdict
from wovenimpact.spec import load_material
from wovenimpact.state import initial_state

CELL = 2.0 * 0.5 * 0.0254 / 27  # the Kevlar's crossover cell 2ℓ0 at 27 threads per inch (m)


def verdict(material, size, **section):
    mesh = plate_mesh(16 * size, size)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(material, **section)},
                        ["s"] * mesh.n_elems)
    found = mesh_verdict(model, initial_state(model))
    return found[material.name], {"mesh_verdict": found}


def fabric(**reg):
    kevlar = load_material(REFERENCE_FABRIC)
    return kevlar if not reg else replace(kevlar, regularisation=FailureRegularisation(**reg))


FABRIC_SECTION = dict(bending_modulus=1e9, transverse_shear_modulus=3.28e9)


def test_an_unregularised_fabric_holds_at_its_crossover_size_only():
    at_cell, summary = verdict(fabric(), CELL, **FABRIC_SECTION)
    assert at_cell["verdict"] == "at the reference size" and at_cell["ok"]
    assert at_cell["element_length_mm"] == pytest.approx([CELL * 1e3] * 2, rel=1e-9)
    assert mesh_box(summary).status == "pass"
    coarse, summary = verdict(fabric(), 4 * CELL, **FABRIC_SECTION)
    assert coarse["verdict"] == "not regularised" and not coarse["ok"]
    box = mesh_box(summary)
    assert box.status == "fail" and "not regularised" in box.value and "3.76 mm" in box.value


def test_a_regularised_fabric_holds_within_its_table_and_not_beyond():
    table = ((1.0, 1.0), (4.0, 0.8), (8.0, 0.7))
    inside, _ = verdict(fabric(strength_scale=table), 4 * CELL, **FABRIC_SECTION)
    assert inside["verdict"] == "within the calibrated range" and inside["ok"]
    assert inside["calibrated_range_mm"] == pytest.approx([CELL * 1e3, 8 * CELL * 1e3])
    beyond, _ = verdict(fabric(strength_scale=table[:2]), 6 * CELL, **FABRIC_SECTION)
    assert beyond["verdict"] == "coarser than the calibrated range" and not beyond["ok"]
    below, _ = verdict(fabric(strength_scale=((2.0, 0.9), (4.0, 0.8))), CELL, **FABRIC_SECTION)
    assert below["verdict"] == "finer than the calibrated range" and not below["ok"]


def test_a_metal_without_a_reference_length_is_not_regularised_and_an_elastic_one_not_judged():
    aluminium = load_material(REFERENCE_METAL)
    plain, _ = verdict(aluminium, 1e-3, thickness=1e-3)
    assert plain["verdict"] == "not regularised" and plain["reference_length_mm"] is None
    reg = replace(aluminium, regularisation=FractureRegularisation(
        reference_length=1e-3, fracture_scale=((0.5, 1.2), (1.0, 1.0), (4.0, 0.7))))
    held, _ = verdict(reg, 2e-3, thickness=1e-3)
    assert held["verdict"] == "within the calibrated range"
    steel = replace(aluminium, kind="elastic", hardening=(), fracture_strain=None, name="steel")
    mesh = plate_mesh(0.02, 1e-3)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(steel, thickness=1e-3)},
                        ["s"] * mesh.n_elems)
    assert mesh_verdict(model, initial_state(model)) == {}


def test_the_edge_radius_is_what_strikes_first():
    """Sphere: its radius; a flat nose: its fillet (0, sharp); hemispherical: the radius;
    conical: a point; any cylinder flying sideways: its shank radius."""
    from wovenimpact.impactor import Impactor

    assert Impactor("sphere", 3e-3).edge_radius() == 3e-3
    flat = Impactor("cylinder", 5e-3, length=20e-3, fillet=0.5e-3)
    assert flat.edge_radius() == 0.5e-3 and flat.edge_radius(sideways=True) == 5e-3
    assert Impactor("cylinder", 5e-3, length=20e-3).edge_radius() == 0.0
    assert Impactor("cylinder", 5e-3, length=20e-3, nose="hemispherical").edge_radius() == 5e-3
    cone = Impactor("cylinder", 5e-3, length=20e-3, nose="conical", nose_length=8e-3)
    assert cone.edge_radius() == 0.0


def struck(size, radius, sideways=False):
    """An at-reference-size fabric plate (one crossover cell, so its own law passes)
    struck by a sphere of ``radius``, or a cylinder of that radius flying sideways."""
    from wovenimpact.impactor import Impactor
    from wovenimpact.model.model import RigidBody

    imp = (Impactor("cylinder", radius, length=10 * radius) if sideways
           else Impactor("sphere", radius))
    body = RigidBody(imp, tip=(0.0, 0.0, 2 * radius), axis=(0.0, 1.0, 0.0) if sideways else None)
    mesh = plate_mesh(16 * size, size)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(fabric(), **FABRIC_SECTION)},
                        ["s"] * mesh.n_elems, bodies=[body])
    found = mesh_verdict(model, initial_state(model))
    return found["kevlar_thesis"], {"mesh_verdict": found}


def test_a_struck_material_passes_only_on_elements_up_to_half_the_strikers_edge_radius():
    """Elements of one crossover cell (0.94 mm) under a 2 mm sphere (0.94 ≤ 0.5 × 2 mm)
    resolve it; under a 1.5 mm sphere (0.94 > 0.75 mm) they do not, and the
    box goes red even though the fabric is at its reference size. A cylinder flying sideways
    is judged by its shank radius."""
    ok, summary = struck(CELL, 2.0e-3)
    assert ok["striker_resolved"] is True and ok["ok"] and ok["striking_radius_mm"] == 2.0
    assert mesh_box(summary).status == "pass" and "(radius 2 mm) resolved" in mesh_box(summary).value
    bad, summary = struck(CELL, 1.5e-3)
    assert bad["verdict"] == "at the reference size" and bad["striker_resolved"] is False
    assert not bad["ok"] and mesh_box(summary).status == "fail"
    assert "its contact is not resolved" in mesh_box(summary).value
    side, _ = struck(CELL, 2.0e-3, sideways=True)
    assert side["striking_radius_mm"] == 2.0 and side["striker_resolved"] is True


def test_without_a_striker_nothing_is_said_of_one():
    alone, summary = verdict(fabric(), CELL, **FABRIC_SECTION)
    assert alone["striker_resolved"] is None and alone["striking_radius_mm"] is None
    assert "striker" not in mesh_box(summary).value


def test_a_sharp_striker_is_never_resolved_and_the_box_says_so():
    """A flat nose without a fillet strikes with a radius-0 rim: red on any mesh, and the
    box says what to do."""
    from wovenimpact.impactor import Impactor
    from wovenimpact.model.model import RigidBody

    body = RigidBody(Impactor("cylinder", 2.78e-3, length=5e-3), tip=(0.0, 0.0, 1e-3))
    mesh = plate_mesh(16 * CELL, CELL)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(fabric(), **FABRIC_SECTION)},
                        ["s"] * mesh.n_elems, bodies=[body])
    found = mesh_verdict(model, initial_state(model))
    assert found["kevlar_thesis"]["striker_resolved"] is False
    box = mesh_box({"mesh_verdict": found})
    assert box.status == "fail" and "sharp edge (radius 0)" in box.value and "fillet" in box.value


def casing_verdict(axial_size):
    """A 30° sector of the 1 mm aluminium inner shell (mid-surface R = 250.5 mm, 150 mm
    long), 7 mm around and ``axial_size`` along the axis, its elements the set
    ``casing.layer0`` as a compiled containment case names them."""
    from wovenimpact.model.casing import casing_mesh

    aluminium = load_material(REFERENCE_METAL)
    mesh = casing_mesh([0.2505], 0.15, 7e-3, sector=30.0, centre_angle=90.0,
                      axial_size=axial_size)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(aluminium, thickness=1e-3)},
                        ["s"] * mesh.n_elems,
                        elem_sets={f"casing.{k}": v for k, v in mesh.elem_sets.items()})
    found = mesh_verdict(model, initial_state(model))
    return aluminium, found[aluminium.name], {"mesh_verdict": found}


@pytest.mark.parametrize("axial_size, edge_mm, resolved", [(7e-3, 150 / 22, False),
                                                           (1e-3, 1.0, True)])
def test_a_metal_casing_is_judged_on_its_edge_along_the_axis(axial_size, edge_mm, resolved):
    """ℓ = √(R t)/[3(1 − ν²)]^{1/4} = 12.36 mm for the 1 mm shell at R = 250.5 mm: 150 mm
    in ⌈150/7⌉ = 22 rows (6.82 mm) is coarser than ℓ/10, in 150 rows (1 mm) finer."""
    aluminium, v, summary = casing_verdict(axial_size)
    ell = (0.2505 * 1e-3) ** 0.5 / (3.0 * (1.0 - aluminium.poisson**2)) ** 0.25
    assert v["casing_bending_length_mm"] == pytest.approx(ell * 1e3, rel=1e-9)
    assert 12.3 < v["casing_bending_length_mm"] < 12.4
    assert v["casing_axial_edge_mm"] == pytest.approx(edge_mm, rel=1e-9)
    assert v["casing_bending_resolved"] is resolved
    # the fracture law is not regularised, so the box fails either way; its text says why
    box = mesh_box(summary)
    assert box.status == "fail"
    said = "resolved" if resolved else "not resolved (needs ≤ 1.24 mm"
    assert f"along the casing's axis, its bending length 12.4 mm {said}" in box.value


def test_a_plate_says_nothing_of_a_casings_bending():
    v, _ = verdict(load_material(REFERENCE_METAL), 1e-3, thickness=1e-3)
    assert v["casing_bending_resolved"] is None and v["casing_bending_length_mm"] is None
