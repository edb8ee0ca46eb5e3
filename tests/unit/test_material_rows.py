"""The packed material rows (``Model.mat_row``, ``State.mat``; theory §4.6, §7.6): each
element owns as many rows as its section has points — not the widest section's count —
and each row starts as its material's initial point state."""

from __future__ import annotations

import numpy as np

from wovenimpact.benchmark import REFERENCE_FABRIC, REFERENCE_METAL
from wovenimpact.materials.fabric import initial_state as fabric_point_state
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.materials.metal import initial_state as metal_point_state
from wovenimpact.model import Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.spec import load_material
from wovenimpact.state import initial_state

STEEL = MetalParameters(name="steel", kind="elastic", density=7850.0, modulus=210e9,
                        poisson=0.3)


def test_each_element_owns_its_sections_points_and_starts_at_its_materials_state():
    """Fabric (2×2 membrane, one point through the thickness), J2 metal (2×2 membrane,
    5 points) and elastic steel in one model, mixed along the element order: 4, 20 and 1
    rows each — a padded table would give every element 20 — every row of the fabric
    and metal elements their material's initial point state, padded to the row width."""
    fabric = load_material(REFERENCE_FABRIC)
    metal = load_material(REFERENCE_METAL)
    mesh = plate_mesh(0.02, 0.01)
    sections = {"fabric": Section(fabric, bending_modulus=1e9, transverse_shear_modulus=3.28e9),
                "metal": Section(metal, thickness=1e-3, membrane="full"),
                "steel": Section(STEEL, thickness=1e-3)}
    pattern = ["fabric", "metal", "steel", "metal", "fabric", "fabric", "steel", "metal"]
    which = np.array([pattern[e % len(pattern)] for e in range(mesh.n_elems)])
    model = build_model(mesh.nodes, mesh.quads, sections, which)
    rows = {"fabric": 4, "metal": 20, "steel": 1}
    assert np.diff(model.mat_row).tolist() == [rows[s] for s in which]
    state = initial_state(model)
    width = model.point_width
    assert state.mat.shape == (sum(rows[s] for s in which), width)
    for e, name in enumerate(which):  # the initial state for the element's lengths (§1.4, §7.3)
        start = {"fabric": fabric_point_state(fabric, lengths=model.elem_length[e:e + 1])[0],
                 "metal": metal_point_state(metal, lengths=model.elem_length[e, :1])[0]}
        own = state.mat[model.mat_row[e]:model.mat_row[e + 1]]
        if name == "steel":
            assert not own.any()
            continue
        want = np.zeros(width)
        want[:start[name].size] = start[name]
        assert np.array_equal(own, np.tile(want, (rows[name], 1))), f"element {e} ({name})"
