"""The mesh verdict of a run (src/wovenimpact/mesh_verdict.py, docs/theory.md §1.4): each
failing material's element lengths against its reference size or the range its failure
table was calibrated on, and the report's box that shows it."""

from __future__ import annotations

from dataclasses import replace

import pytest

from wovenimpact.benchmark import REFERENCE_FABRIC, REFERENCE_METAL
from wovenimpact.io.report import mesh_box
from wovenimpact.materials.fabric import FailureRegularisation
from wovenimpact.materials.metal import FractureRegularisation
from wovenimpact.mesh_verdict import mesh_verdict
from wovenimpact.model import Section, build_model
from wovenimpact.model.mesh import plate_mesh
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
