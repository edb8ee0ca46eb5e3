"""``mesh.blade.element_size``: the generated blade's own element size (theory §8, "The
blade's own element size"). With it fixed, a casing mesh study changes the casing only
(the blade's nodes, elements, fragment mass and spun speed stay bit for bit); absent, the
blade takes ``mesh.element_size`` and the model is today's bit for bit; a bad value is
refused naming the key. On the coarse 2-ply ring of test_containment_checks."""

from __future__ import annotations

import dataclasses
import warnings

import numpy as np
import pytest

from tests.unit.test_containment_checks import CASE, COARSE, compile_with
from wovenimpact.errors import InputError, InputWarning

CASING = COARSE["mesh.element_size"]  # 12 mm: the coarse ring's size


def compiled(**changes):
    """compile_with, any InputWarning an error (the ring warns of nothing)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", InputWarning)
        return compile_with(**changes)


@pytest.fixture(scope="module")
def rings():
    """The coarse ring: today's (no key), the key equal to the casing's size, the casing
    coarser (20 mm) around the same 12 mm blade, and a blade coarser (20 mm) than the
    casing."""
    return {
        "today": compiled(),
        "same": compiled(mesh__blade__element_size=CASING),
        "coarse casing": compiled(mesh__element_size="20 mm", mesh__blade__element_size=CASING),
        "coarse blade": compiled(mesh__blade__element_size="20 mm"),
    }


def blade_part(c):
    """The blade's reference nodes, its quads numbered from its first node, and its
    spun positions and velocities (the blade is the mesh's last part)."""
    elems = c.model.elem_sets["blade.blade"]
    nodes = np.unique(c.model.quads[elems])
    assert np.array_equal(nodes, np.arange(nodes[0], c.model.n_nodes))
    return (c.model.x0[nodes], c.model.quads[elems] - nodes[0], c.state.x[nodes],
            c.state.v[nodes], c.model.node_mass[nodes])


def fragment(c):
    """The released fragment's mass and the speed of its centre of mass at t = 0."""
    nodes = c.model.node_sets["blade.fragment"]
    m = c.model.node_mass[nodes]
    mass = m.sum()
    return mass, np.linalg.norm((m[:, None] * c.state.v[nodes]).sum(axis=0) / mass)


def same_bits(a, b) -> bool:
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


def test_a_casing_mesh_study_leaves_the_blade_bit_for_bit(rings):
    fixed, coarser = rings["same"], rings["coarse casing"]
    for a, b in zip(blade_part(fixed), blade_part(coarser)):
        assert same_bits(a, b)
    for a, b in zip(fragment(fixed), fragment(coarser)):
        assert same_bits(a, b)
    # the fragment spins with the blade: ω r_cm at 1047 rad/s, ~150 m/s (theory §8.1)
    assert 140.0 < fragment(fixed)[1] < 160.0
    n_blade = len(fixed.model.elem_sets["blade.blade"])
    assert len(coarser.model.elem_sets["blade.blade"]) == n_blade
    # while the casing is coarser: fewer elements, its axial edges 150/8 = 18.75 mm
    casing = fixed.model.n_elems - n_blade
    assert coarser.model.n_elems - n_blade < casing / 2
    z = np.unique(coarser.model.x0[coarser.model.node_sets["casing.layer0"], 2])
    assert np.allclose(np.diff(z), 0.15 / 8)


def test_the_blade_takes_its_own_size_not_the_casings(rings):
    """A 20 mm blade in the 12 mm ring: the fragment's 185 mm in ⌈185/20⌉ = 10 rows and
    the 40 mm tip chord in 2; the casing as the ring without the key."""
    today, coarse = rings["today"], rings["coarse blade"]
    assert len(coarse.model.elem_sets["blade.fragment"]) == 9 * 2  # release row apart
    assert len(coarse.model.elem_sets["blade.release"]) == 2
    n_today = len(today.model.elem_sets["blade.blade"])
    n_coarse = len(coarse.model.elem_sets["blade.blade"])
    assert same_bits(coarse.model.quads[:-n_coarse], today.model.quads[:-n_today])
    assert same_bits(coarse.model.x0[:coarse.model.quads[-n_coarse:].min()],
                     today.model.x0[:today.model.quads[-n_today:].min()])


def test_the_key_absent_is_todays_model_bit_for_bit(rings):
    today, same = rings["today"], rings["same"]
    for f in dataclasses.fields(today.model):
        a, b = getattr(today.model, f.name), getattr(same.model, f.name)
        if isinstance(a, np.ndarray):
            assert same_bits(a, b), f.name
        elif isinstance(a, dict):
            assert a.keys() == b.keys(), f.name
            assert all(same_bits(a[k], b[k]) for k in a), f.name
        else:
            assert a == b, f.name
    assert today.model.digest() == same.model.digest()
    for name in ("x", "v", "omega", "elem", "mat", "energy"):
        assert same_bits(getattr(today.state, name), getattr(same.state, name)), name


@pytest.mark.parametrize("value, message", [
    ("0 mm", r"mesh\.blade\.element_size: .*must be > 0"),
    ("-3 mm", r"mesh\.blade\.element_size: .*must be > 0"),
    ("3", r"mesh\.blade\.element_size: has no unit"),
    ("3 s", r"mesh\.blade\.element_size: .*length"),
    ("100 mm", r"mesh\.blade\.element_size: gives fewer than 2 elements along the released "
               r"fragment \(0\.185 m\)"),
    ("1e-300 mm", r"mesh\.blade\.element_size: gives about .* elements in the mesh"),
])
def test_a_bad_blade_element_size_is_refused_naming_the_key(value, message):
    from wovenimpact.spec.case import load_case

    with pytest.raises(InputError, match=message):
        load_case(CASE, [f"mesh.blade.element_size={value}"])


def test_the_casing_size_is_checked_against_the_casing_only():
    """On a 300 mm long casing a 100 mm casing size is more than half the 185 mm fragment:
    refused while the blade takes it, accepted with the blade's own 5 mm."""
    from wovenimpact.spec.case import load_case

    casing = ["mesh.casing.length=300 mm", "mesh.element_size=100 mm",
              "mesh.casing.coarse_element_size=100 mm"]
    with pytest.raises(InputError, match=r"mesh\.element_size: gives fewer than 2 elements "
                       r"along the casing's length or the released fragment \(0\.185 m\)"):
        load_case(CASE, casing)
    spec, _ = load_case(CASE, casing + ["mesh.blade.element_size=5 mm"])
    assert (spec.mesh.element_size, spec.mesh.blade_element_size) == (0.1, 0.005)
