"""``mesh.ply_sections``: a section per ply of a plate case, the plies stacked touching
by their own thicknesses when no spacing is given (examples/metal_impact/hybrid_coupon)."""

from __future__ import annotations

import copy
import tomllib
from pathlib import Path

import numpy as np
import pytest

from wovenimpact.errors import InputError
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.setup.compile import compile_case
from wovenimpact.spec.case import case_from_dict

HYBRID = Path(__file__).resolve().parents[2] / "examples" / "metal_impact" / "hybrid_coupon.toml"


def hybrid_doc() -> dict:
    return tomllib.loads(HYBRID.read_text(encoding="utf-8"))


def test_touching_plies_are_stacked_by_their_own_thicknesses():
    """Four Kevlar plies (shell thickness t_f = 4 h0 ≈ 0.4992 mm) under 1 mm of
    aluminium: mid-planes at 0, t_f, 2 t_f, 3 t_f and 3 t_f + (t_f + 1 mm)/2; each ply's
    elements have its section, and a node's contact offset is half its own ply's
    thickness (each ply has its own nodes)."""
    model = compile_case(case_from_dict(hybrid_doc()), HYBRID.parent).model
    thick = model.sections[model.elem_section, SL.C_THICK]
    t_f = float(thick[0])
    assert t_f == pytest.approx(0.4992e-3, rel=1e-3)
    assert np.all(thick[model.ply < 4] == t_f) and np.all(thick[model.ply == 4] == 1e-3)
    z = [np.unique(model.x0[model.quads[model.ply == k].ravel(), 2]) for k in range(5)]
    assert all(len(zk) == 1 for zk in z)
    expected = [0.0, t_f, 2 * t_f, 3 * t_f, 3 * t_f + 0.5 * (t_f + 1e-3)]
    assert np.allclose([zk[0] for zk in z], expected, rtol=0, atol=1e-15)
    top = np.unique(model.quads[model.ply == 4])
    assert np.all(model.node_offset[top] == 0.5e-3)
    assert np.all(model.node_offset[np.unique(model.quads[model.ply == 0])] == 0.5 * t_f)


@pytest.mark.parametrize(
    ("value", "expect"),
    [
        (["fabric", "plate"], "mesh.ply_sections: has 2 entries"),
        (["fabric", "fabric", "fabric", "fabric", "steel"],
         "mesh.ply_sections[4]: names no section"),
    ],
)
def test_bad_ply_sections_name_the_key(value, expect):
    doc = copy.deepcopy(hybrid_doc())
    doc["mesh"]["ply_sections"] = value
    with pytest.raises(InputError) as err:
        case_from_dict(doc, source="hybrid.toml")
    assert expect in str(err.value)
