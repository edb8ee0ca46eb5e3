"""setup/containment_checks.py: a containment case whose geometry breaks what the
outcome rule assumes (layers about the z axis, innermost first; the blade inside the
casing; the fragment's path meeting the modelled casing) is refused before the first
step, and the doubtful ones are warned of (docs/inputs.md, "Case: containment")."""

from __future__ import annotations

import copy
import dataclasses
import warnings
from pathlib import Path

import numpy as np
import pytest

from wovenimpact.errors import InputError, InputWarning

CASE = Path(__file__).resolve().parents[2] / "examples" / "containment" / "hybrid_4.toml"
COARSE = {"mesh.element_size": "12 mm", "mesh.casing.coarse_element_size": "30 mm",
          "mesh.casing.layers": 2, "run.end_time": "20 us", "run.field_interval": "20 us",
          "run.checkpoint_interval": "20 us"}


def compile_with(**changes):
    """The 4-ply example, coarse and with 2 plies, with ``changes`` (dotted keys with
    '__' for '.') applied; returns the compiled case."""
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.spec.fields import read_toml, set_dotted

    doc = read_toml(CASE, "case")
    for key, value in {**COARSE, **{k.replace("__", "."): v for k, v in changes.items()}}.items():
        if value is None:
            parent, _, leaf = key.rpartition(".")
            node = doc
            for part in parent.split("."):
                node = node[part]
            node.pop(leaf)
        else:
            set_dotted(doc, key, value)
    return compile_case(case_from_dict(doc, str(CASE)), CASE.parent)


@pytest.fixture(scope="module")
def ring():
    """The coarse ring, compiled once; tests check modified copies of it."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", InputWarning)  # the example itself warns of nothing
        return compile_with()


def checked(ring, spec_changes=None, *, x_shift=None, layers=None, blade_scale=None):
    """Run check_containment on a copy of ``ring`` with its geometry changed; the warnings
    it gave, as text (an error propagates)."""
    from wovenimpact.setup.containment_checks import check_containment
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.spec.fields import read_toml, set_dotted

    model, state, mesh = ring.model, copy.deepcopy(ring.state), copy.deepcopy(ring.mesh)
    if x_shift is not None:
        model = dataclasses.replace(model, x0=model.x0 + np.array([x_shift, 0.0, 0.0]))
        state.x += np.array([x_shift, 0.0, 0.0])
    if layers is not None:
        named = [mesh.node_sets.pop(f"casing.layer{k}") for k in range(3)]
        for k, i in enumerate(layers):
            mesh.node_sets[f"casing.layer{k}"] = named[i]
    if blade_scale is not None:
        blade = np.unique(mesh.quads[mesh.elem_sets["blade.blade"]])
        state.x[blade, :2] *= blade_scale
    doc = read_toml(CASE, "case")
    for key, value in {**COARSE, **(spec_changes or {})}.items():
        set_dotted(doc, key, value)
    spec = case_from_dict(doc, str(CASE))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        check_containment(spec, model, state, mesh)
    return [str(w.message) for w in caught if issubclass(w.category, InputWarning)]


def test_the_example_passes_every_check(ring):
    """Neither an error nor a warning for the example as it is; the same call with the
    blade 1 % larger, its tip through the casing, is refused (so the check does look)."""
    assert checked(ring) == []
    with pytest.raises(InputError, match="would start in contact with, or through"):
        checked(ring, blade_scale=1.01)


def test_free_cut_edges_of_a_sector_are_warned_of(ring):
    """The ring has no cut edges; a sector whose cut edges no boundary clamps is warned of
    (and is the only warning of the otherwise sound example)."""
    ring_sector = copy.deepcopy(ring)
    layer0 = ring.mesh.node_sets["casing.layer0"]
    free = layer0[np.all(ring.model.bc_code[layer0] == 0, axis=1)]
    ring_sector.mesh.node_sets["casing.cut_edges"] = free[:3]
    warned = checked(ring_sector)
    assert len(warned) == 1 and "cut edges (node set casing.cut_edges) are free" in warned[0]


def test_a_layer_listed_twice_is_refused(ring):
    with pytest.raises(InputError, match=r"layer 2\).*shares .* nodes with mesh.casing \(layer 1"):
        checked(ring, layers=[0, 1, 1])


def test_layers_listed_outermost_first_are_refused(ring):
    with pytest.raises(InputError, match="innermost first"):
        checked(ring, layers=[1, 0, 2])


def test_a_casing_off_the_spin_axis_is_refused(ring):
    """Moved 0.1 m along x, the layers are no longer about the z axis the blade spins
    about (an imported mesh with its origin elsewhere): the audit's run reported 215
    m/s for a 160 m/s fragment."""
    with pytest.raises(InputError, match="surface about the z axis"):
        checked(ring, x_shift=0.1)
    assert checked(ring, x_shift=1e-4) == []  # a tenth of a millimetre: no error, no warning


def test_a_blade_reaching_the_casing_is_refused(ring):
    """The spun blade with its half thickness (the contact offset) must start inside the
    casing's inner surface; the example's reach 247.6 mm against 249.5 mm passes."""
    with pytest.raises(InputError, match="would start in contact with, or through"):
        checked(ring, blade_scale=1.01)


def test_casing_elements_in_no_layer_are_warned_of(ring):
    """Listing the inner shell alone (the plies left out of casing_layers) would read
    the outcome from it only: a warning names the elements left out."""
    from wovenimpact.setup.containment_checks import check_layers
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.spec.fields import read_toml

    mesh = copy.deepcopy(ring.mesh)
    for k in (1, 2):
        mesh.node_sets.pop(f"casing.layer{k}")
    spec = case_from_dict(read_toml(CASE, "case"), str(CASE))
    with pytest.warns(InputWarning, match="elements outside the blade are in no casing layer"):
        check_layers(spec, ring.model, mesh, [mesh.node_sets["casing.layer0"]])


def test_coincident_layers_are_refused():
    with pytest.raises(InputError, match="the layers coincide"):
        compile_with(mesh__casing__layer_spacing="1e-6 mm")


def test_a_generated_blade_through_the_casing_is_refused():
    """inner_radius 246 mm: the tip (245.1 mm spun) with its 2.49 mm half thickness is
    in the casing; the mesh check before the spin-up (tip_radius < inner_radius) let
    it through."""
    with pytest.raises(InputError, match=r"reaches r = 247.6 mm.*raise mesh.casing.inner_radius"):
        compile_with(mesh__casing__inner_radius="246 mm")


def test_a_fragment_flying_where_no_casing_is_modelled_is_refused():
    """A 90° sector about 175° with the blade at 300°: the fragment would fly past the
    sector and the run read undecided to its end."""
    with pytest.raises(InputError, match="where no casing is modelled"):
        compile_with(mesh__casing__sector="90 deg", mesh__casing__fine_sector=None,
                     mesh__casing__coarse_element_size=None, mesh__blade__angle="300 deg")


def test_an_impact_outside_the_fine_zone_and_free_cut_edges_are_warned_of():
    with pytest.warns(InputWarning, match="outside the fine zone"):
        compile_with(mesh__blade__angle="300 deg")
    with pytest.warns(InputWarning, match="cut edges .* are free"):
        compile_with(mesh__casing__sector="120 deg", mesh__casing__fine_sector="100 deg",
                     mesh__casing__centre_angle="120 deg")


def test_a_release_after_the_end_time_is_warned_of():
    with pytest.warns(InputWarning, match="the fragment is never released"):
        compile_with(spin__release_time="30 us")


def test_a_spin_rate_whose_tip_crosses_half_an_element_in_a_step_is_refused():
    with pytest.raises(InputError, match=r"spin.rate = 1e\+06 rad/s moves the blade's tip"):
        compile_with(spin__rate="1e6 rad/s")
