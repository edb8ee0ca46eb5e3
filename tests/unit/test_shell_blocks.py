"""The element stage in blocks of 8 (kernels.shell_blocks) against ``shell_force``.

The block stage must give bitwise the same element and material state, corner forces and
steps as the scalar kernel — on sound fabric, and where lanes leave the default path and
go to ``shell_force`` (yarns breaking, elements eroding, points outside the table), in
both stable-step options, with a last block that is not full. A test fails if one bit of
the state differs after the steps (docs/theory.md §4.6, "SIMD element pass").
"""

from __future__ import annotations

import copy
import dataclasses
import math

import numpy as np
import pytest

from wovenimpact.benchmark import REFERENCE_FABRIC, REFERENCE_METAL, plate_model
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels.vecmath import atan2_upper, sqrt as vsqrt
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.model.mesh import plate_mesh
from wovenimpact.solver import Workspace, step
from wovenimpact.solver.element_blocks import LANES, block_plan
from wovenimpact.spec import load_material
from wovenimpact.state import initial_state


def fabric_plate(per_edge: int, ultimate_tension: float | None = None, stable_step="isotropic",
                 metal_rows: int = 0, crossover: str = "table", elastic_rows: int = 0,
                 kinematic_fraction: float = SL.KINEMATIC_FRACTION):
    """A fabric plate (the benchmark's, 0.94 mm cells) struck by a velocity bump; its
    yarns' T_u lowered to make them break; optionally its first rows of elements J2
    metal (they stay with shell_force) and its last rows elastic steel (a resultant
    section with the one-point membrane: blocks of their own)."""
    fabric = load_material(REFERENCE_FABRIC)
    if ultimate_tension is not None:
        fabric = dataclasses.replace(
            fabric, warp=dataclasses.replace(fabric.warp, ultimate_tension=ultimate_tension),
            fill=dataclasses.replace(fabric.fill, ultimate_tension=ultimate_tension))
    fabric = dataclasses.replace(
        fabric, options=dataclasses.replace(fabric.options, crossover=crossover))
    size = 0.94e-3
    mesh = plate_mesh(per_edge * size, size)
    sections = {"fabric": Section(fabric, bending_modulus=1e9, transverse_shear_modulus=3.28e9)}
    which = np.zeros(mesh.n_elems, int)
    if metal_rows:
        sections["metal"] = Section(load_material(REFERENCE_METAL), thickness=1e-3)
        which[: metal_rows * per_edge] = 1
    if elastic_rows:
        sections["steel"] = Section(STEEL, thickness=1e-3)
        which[mesh.n_elems - elastic_rows * per_edge:] = len(sections) - 1
    bc = BoundaryConditions(mesh.n_nodes).fix(mesh.node_sets["edge_outer"])
    model = build_model(mesh.nodes, mesh.quads, sections, which, bcs=bc,
                        stable_step=stable_step, kinematic_fraction=kinematic_fraction)
    r = np.linalg.norm(mesh.nodes[:, :2], axis=1) / (0.5 * per_edge * size)
    v0 = np.zeros((mesh.n_nodes, 3))
    v0[:, 2] = -400.0 * np.clip(1.0 - 2.0 * r, 0.0, None) ** 2
    st = initial_state(model, velocity=v0)
    st.x[:, :2] *= 1.02
    return model, st


STEEL = MetalParameters(name="steel", kind="elastic", density=7850.0, modulus=210e9,
                        poisson=0.3)


def run_both(model, st, steps: int):
    """Step copies of the state with and without the block stage; the two states and
    the number of lanes the block stage left to shell_force."""
    a, b = st, copy.deepcopy(st)
    wa, wb = Workspace.for_model(model, a), Workspace.for_model(model, b)
    assert wa.plan is not None
    wb.plan = None
    pending = 0
    for _ in range(steps):
        step(model, a, wa)
        step(model, b, wb)
        pending += int(wa.scratch.pending.sum())
    return a, b, wa, wb, pending


def assert_same(a, b, wa, wb):
    for name in ("x", "v", "omega", "elem", "mat", "energy"):
        got, want = getattr(a, name), getattr(b, name)
        assert np.array_equal(got, want, equal_nan=True), f"state.{name} differs"
    assert np.array_equal(wa.blocks, wb.blocks)
    assert a.dt == b.dt


def test_sound_fabric_bitwise():
    """Every lane on the default path (no yarn near T_u), a partial last block."""
    model, st = fabric_plate(13)
    assert model.n_elems % LANES != 0
    a, b, wa, wb, pending = run_both(model, st, 12)
    assert wa.plan.lanes[-1] == model.n_elems % LANES
    assert pending == 0, "lanes left to shell_force: the blocks would not be what is compared"
    assert_same(a, b, wa, wb)


@pytest.mark.parametrize("stable_step", ["isotropic", "yarn"])
def test_breaking_yarns_bitwise(stable_step):
    """Yarns reach a lowered T_u and elements erode: those lanes go to shell_force,
    and the state stays bitwise the scalar kernel's."""
    model, st = fabric_plate(12, ultimate_tension=10.0, stable_step=stable_step)
    a, b, wa, wb, pending = run_both(model, st, 40)
    rows = a.mat.reshape(-1, model.point_width)
    assert np.any(rows[:, FL.S_DAMAGE] >= 1.0), "no yarn broke: the test would not see it"
    assert 0 < pending < 40 * model.n_elems  # both paths taken
    assert_same(a, b, wa, wb)


def test_both_paths_read_the_kinematic_fraction():
    """run.kinematic_fraction (η of the yarn step's kinematic bound) reaches the block
    stage and shell_force alike. The plate is squeezed in its plane (v_x = −r x, r = 2e6
    /s: every pair along x closes at the rate r, faster next to the held edge, so the
    bound η/r, 2.5e-8 s at the default, sets the step): the two paths stay bitwise
    equal for either η, each inner element's kinematic bound is η/r, and with η = 0.25
    the run's step is longer."""
    rate = 2.0e6
    times = {}
    for eta in (SL.KINEMATIC_FRACTION, 0.25):
        model, st = fabric_plate(12, stable_step="yarn", kinematic_fraction=eta)
        free = model.bc_code[:, 0] == 0
        st.v[free, 0] = -rate * st.x[free, 0]
        a, b, wa, wb, _ = run_both(model, st, 1)
        assert_same(a, b, wa, wb)
        inner = np.all(model.bc_code[model.quads, 0] == 0, axis=1)  # all four corners free
        assert np.allclose(a.elem[inner, SL.E_DT_KIN], eta / rate, rtol=1e-9)
        a, b, wa, wb, _ = run_both(model, a, 3)
        assert_same(a, b, wa, wb)
        times[eta] = a.dt
    assert times[0.25] > 1.5 * times[SL.KINEMATIC_FRACTION]


def test_mixed_sections_and_exact_crossover():
    """Metal elements and a fabric section solved exactly stay with shell_force; the
    tabulated fabric beside them in blocks; the whole state bitwise the scalar one."""
    model, st = fabric_plate(10, metal_rows=3)
    plan = block_plan(model)
    metal = np.flatnonzero(model.elem_section == 1)
    assert set(metal) <= set(plan.others) and not set(metal) & set(plan.elems)
    a, b, wa, wb, _ = run_both(model, st, 10)
    assert_same(a, b, wa, wb)
    model, _ = fabric_plate(6, crossover="exact")
    assert block_plan(model) is None


@pytest.mark.parametrize("stable_step", ["isotropic", "yarn"])
def test_elastic_plate_bitwise(stable_step):
    """The benchmark's elastic steel plate (resultant section, one-point membrane with
    hourglass springs) in blocks of its own, every lane on the block path, bitwise the
    scalar kernel's state after the steps; in both stable-step options."""
    model, st = plate_model("elastic", 170)  # 13 × 13
    model = dataclasses.replace(model, stable_step=stable_step)
    assert model.n_elems % LANES != 0
    a, b, wa, wb, pending = run_both(model, st, 15)
    assert wa.plan.others.size == 0
    assert pending == 0, "lanes left to shell_force: the blocks would not be what is compared"
    assert np.any(a.elem[:, SL.E_HG] != 0.0), "no hourglass force: the test would not see it"
    assert_same(a, b, wa, wb)


def test_fabric_elastic_and_j2_sections_together():
    """Fabric and elastic blocks and J2 elements (shell_force) in one model: the plan
    takes the fabric and the elastic sections, and the state is bitwise the scalar one."""
    model, st = fabric_plate(10, metal_rows=2, elastic_rows=3, stable_step="yarn")
    plan = block_plan(model)
    for s in (0, 2):  # fabric, steel
        ids = np.flatnonzero(model.elem_section == s)
        assert set(ids) <= set(plan.elems) and not set(ids) & set(plan.others)
    assert set(np.flatnonzero(model.elem_section == 1)) <= set(plan.others)
    a, b, wa, wb, _ = run_both(model, st, 12)
    assert_same(a, b, wa, wb)
    # the steel lanes all stayed on the block path (the struck fabric may leave it)
    steel = model.elem_section[plan.elems] == 2
    step(model, a, wa)
    assert steel.any() and not wa.scratch.pending[steel].any()


def test_blocks_can_be_switched_off(monkeypatch):
    model, _ = fabric_plate(4)
    monkeypatch.setenv("WOVENIMPACT_BLOCKS", "0")
    assert block_plan(model) is None


def test_atan2_upper_within_one_ulp():
    """Cephes' atan as selects (vecmath) against libm's atan2 on (0, π)."""
    rng = np.random.default_rng(5)
    theta = rng.uniform(1e-6, math.pi - 1e-6, 20_000)
    radius = rng.uniform(1e-3, 1e3, theta.size)
    for t, r in zip(theta, radius):
        y, x = r * math.sin(t), r * math.cos(t)
        want = math.atan2(y, x)
        assert abs(atan2_upper(y, x) - want) <= math.ulp(want)
    assert atan2_upper(1.0, 0.0) == 0.5 * math.pi
    assert atan2_upper(1.0, -0.0) == 0.5 * math.pi


def test_vector_sqrt_is_math_sqrt():
    from numba import njit

    @njit
    def both(x):
        return vsqrt(x), math.sqrt(x)

    for x in (0.0, 1e-300, 2.0, 3.7e12, math.inf):
        got, want = both(x)
        assert got == want
    assert math.isnan(both(-1.0)[0]) and math.isnan(both(math.nan)[0])
