"""Verification of the one-point hexahedron (kernels/hex8.py, docs/solid.md): the
constant-strain patch test on irregular meshes, and the wave speed and energy of a bar of
hexahedra under explicit central differences (tests/verification/hex_driver.py).

The yarn of thesis Table 5-2 throughout, with its fibre axis oblique to the meshes: the
strongest anisotropy the element is meant for (E11/E22 ≈ 29).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.verification.hex_driver import PARENT, THESIS_YARN, HexModel, box_mesh
from wovenimpact.kernels import solid_layout as L
from wovenimpact.materials.transverse_isotropic import (
    initial_state,
    material_frame,
    update_points,
)

EXACT = 1e-10  # acceptance of the patch test (relative)
SIG = slice(L.H_SIG, L.H_SIG + 6)

# interior corners of MacNeal & Harder's irregular 7-element patch in the unit cube
# (Finite Elements in Analysis and Design 1 (1985) 3–20, doi:10.1016/0168-874X(85)90003-4),
# in the order of the outer corners (solid_layout node order)
MACNEAL_HARDER_INNER = np.array([
    [0.249, 0.342, 0.192], [0.826, 0.288, 0.288], [0.850, 0.649, 0.263],
    [0.273, 0.750, 0.230], [0.320, 0.186, 0.643], [0.677, 0.305, 0.683],
    [0.788, 0.693, 0.644], [0.165, 0.745, 0.702],
])


def macneal_harder(size: float):
    """Nodes (outer corners 0–7, inner 8–15) and the 7 hexahedra: the inner one and one
    between each face of the cube and the inner face facing it."""
    nodes = np.vstack([0.5 * (PARENT + 1.0), MACNEAL_HARDER_INNER]) * size
    hexes = [list(range(8, 16))]
    for axis in range(3):
        for side in (-1.0, 1.0):
            face = [c for c in range(8) if PARENT[c, axis] == side]
            elem = []
            for corner in range(8):
                s = PARENT[corner].copy()
                outer_side = s[axis] == side  # the element's own side on the cube's face
                s[axis] = side
                c = next(f for f in face if np.array_equal(PARENT[f], s))
                elem.append(c if outer_side else c + 8)
            hexes.append(elem)
    return nodes, np.array(hexes, dtype=np.int64)


def distorted_2x2x2(size: float, seed: int = 4):
    """A 2 × 2 × 2 block with its nodes moved at random, those on the cube's faces within
    their faces (elements warped, the cube kept)."""
    nodes, hexes = box_mesh(2, 2, 2, size, size, size)
    rng = np.random.default_rng(seed)
    on_face = np.isclose(nodes, 0.0) | np.isclose(nodes, size)
    move = 0.15 * size * rng.uniform(-1, 1, nodes.shape)
    return nodes + np.where(on_face, 0.0, move), hexes


MESHES = {"macneal_harder": macneal_harder, "distorted_2x2x2": distorted_2x2x2}
SIZE = 1e-3  # m


def boundary_nodes(nodes, size):
    return np.any(np.isclose(nodes, 0.0, atol=1e-12 * size)
                  | np.isclose(nodes, size, atol=1e-12 * size), axis=1)


def linear_field(nodes):
    """x = X + A X + c: a general finite gradient (stretches, shears, some rotation)."""
    grad = np.array([[2.0, 0.7, -0.4], [-0.3, -1.1, 0.9], [0.5, 0.2, 1.5]]) * 1e-3
    return nodes + nodes @ grad.T + np.array([1e-6, -2e-6, 3e-6]), grad


FIBRE_FRAME = material_frame([1.0, 0.6, 0.3], [0.0, 1.0, -0.2])


@pytest.mark.parametrize("mesh", sorted(MESHES))
def test_patch_in_a_linear_field_is_in_uniform_stress_and_equilibrium(mesh):
    """All nodes on the linear field: every element has the same stress (the material's at
    that F), no hourglass force, and the interior nodes carry no force."""
    nodes, hexes = MESHES[mesh](SIZE)
    model = HexModel(nodes, hexes, THESIS_YARN, FIBRE_FRAME, hourglass=0.05)
    x, grad = linear_field(nodes)
    el_out = model.state()
    f, _, _ = model.forces(x, x - nodes, 1.0, model.state(), el_out)
    point = update_points(THESIS_YARN, FIBRE_FRAME, np.eye(3) + grad, initial_state(1))[0]
    scale = np.abs(point[SIG]).max()
    assert np.abs(el_out[:, SIG] - point[SIG]).max() <= EXACT * scale
    k = model.mesh.hg_stiffness.max()
    assert np.abs(el_out[:, L.H_HG:L.H_HG + 12]).max() <= EXACT * k * 1e-3 * SIZE
    interior = ~boundary_nodes(nodes, SIZE)
    assert interior.sum() in (1, 8)
    assert np.abs(f[interior]).max() <= EXACT * scale * SIZE**2
    # the boundary forces are the tractions σ n of the faces: they sum to zero
    assert np.abs(f.sum(axis=0)).max() <= EXACT * scale * SIZE**2


def perturbed_start(nodes, amount, seed=9):
    """The linear field with the interior nodes moved off it by up to ``amount`` SIZE."""
    x_exact, _ = linear_field(nodes)
    interior = ~boundary_nodes(nodes, SIZE)
    x0 = x_exact.copy()
    x0[interior] += amount * SIZE * np.random.default_rng(seed).uniform(
        -1, 1, (interior.sum(), 3))
    return x0, x_exact, np.repeat(~interior[:, None], 3, axis=1)


@pytest.mark.parametrize("mesh", sorted(MESHES))
def test_patch_relaxes_to_the_linear_field(mesh):
    """Boundary nodes held on the linear field, interior nodes started off it: damped
    central differences on the element equations (each force that of the elements taken
    from the reference to x in one increment, so a function of x alone) bring them onto
    it, to 1e-10 of the field's displacement."""
    nodes, hexes = MESHES[mesh](SIZE)
    model = HexModel(nodes, hexes, THESIS_YARN, FIBRE_FRAME, hourglass=0.05)
    x0, x_exact, fixed = perturbed_start(nodes, 2e-3)
    _, dt_min, _ = model.forces(x0, x0 - nodes, 1.0, model.state(), model.state())
    dt = 0.9 * dt_min
    x, _, _, _, _ = model.run(x0, np.zeros_like(x0), dt, 4000, fixed=fixed,
                              damping=0.02 / dt, every=4000, path_free=True)
    scale = np.abs(x_exact - nodes).max()
    assert np.abs(x - x_exact).max() <= EXACT * scale


@pytest.mark.parametrize("mesh", sorted(MESHES))
def test_rate_form_relaxation_differs_only_by_its_path_effect(mesh):
    """The same relaxation with the step's own rate forms (Green–Naghdi stress, incremental
    hourglass forces) ends off the linear field by their path dependence, of the order of
    the field's strain times the excursion (measured 0.43 of that bound on the
    MacNeal–Harder patch, 0.003 on the 2 × 2 × 2 block)."""
    nodes, hexes = MESHES[mesh](SIZE)
    model = HexModel(nodes, hexes, THESIS_YARN, FIBRE_FRAME, hourglass=0.05)
    amount = 2e-3
    x0, x_exact, fixed = perturbed_start(nodes, amount)
    _, dt_min, _ = model.forces(x0, x0 - nodes, 1.0, model.state(), model.state())
    dt = 0.9 * dt_min
    x, _, _, _, _ = model.run(x0, np.zeros_like(x0), dt, 4000, fixed=fixed,
                              damping=0.02 / dt, every=4000)
    _, grad = linear_field(nodes)
    bound = np.abs(grad).max() * amount * SIZE
    assert np.abs(x - x_exact).max() <= bound


# --- bar of hexahedra: wave speed and energy ------------------------------------------
BAR_LENGTH = 20e-3  # m
BAR_SECTION = 0.5e-3  # m: one element across, cubes along
BAR_ELEMENTS = 40
BAR_TURN = Rotation.from_rotvec([0.3, -0.5, 0.8]).as_matrix()  # the bar lies obliquely
WAVE_TOL = 1e-3  # first-mode frequency against the continuum π c / L, relative
DISCRETE_TOL = 1e-5  # against the lumped-mass, central-difference dispersion relation
ENERGY_TOL = 1e-7  # kinetic + strain + hourglass energy kept, fraction of the total


def bar(fibre_along_bar: bool):
    nodes, hexes = box_mesh(BAR_ELEMENTS, 1, 1, BAR_LENGTH, BAR_SECTION, BAR_SECTION)
    axis = BAR_TURN[:, 0]
    across = BAR_TURN[:, 1]
    frame = (material_frame(axis, across) if fibre_along_bar
             else material_frame(across, axis))  # a2 along the bar: E22
    return HexModel(nodes @ BAR_TURN.T, hexes, THESIS_YARN, frame, hourglass=0.05), axis


def bar_vibration(fibre_along_bar: bool, periods: float = 3.0, threads=None):
    """Free–free bar started in its first longitudinal mode u = A cos(π s / L) at rest.
    Returns (ω measured, ω continuum, ω discrete, energy history, Δt, final x, state)."""
    model, axis = bar(fibre_along_bar)
    modulus = THESIS_YARN.e11 if fibre_along_bar else THESIS_YARN.e22
    c = math.sqrt(modulus / THESIS_YARN.density)
    s = model.nodes @ axis
    amp = 1e-6 * BAR_LENGTH
    x0 = model.nodes + np.outer(amp * np.cos(math.pi * s / BAR_LENGTH), axis)
    _, dt_min, _ = model.forces(x0, x0 - model.nodes, 1.0, model.state(), model.state())
    dt = 0.9 * dt_min
    omega = math.pi * c / BAR_LENGTH
    n_steps = int(periods * 2.0 * math.pi / omega / dt)
    end = np.isclose(s, s.max())
    x, v, state, hist, rec = model.run(
        x0, np.zeros_like(x0), dt, n_steps,
        record=lambda x, v: float(((x[end] - model.nodes[end]) @ axis).mean()))
    u = np.array(rec)
    k = np.flatnonzero(np.sign(u[:-1]) != np.sign(u[1:]))
    times = (k + u[k] / (u[k] - u[k + 1])) * dt
    omega_measured = math.pi / np.mean(np.diff(times))
    h = BAR_LENGTH / BAR_ELEMENTS
    omega_h = 2.0 * c / h * math.sin(math.pi * h / (2.0 * BAR_LENGTH))
    omega_cd = 2.0 / dt * math.asin(omega_h * dt / 2.0)
    return omega_measured, omega, omega_cd, hist, dt, x, state


@pytest.mark.parametrize("fibre_along_bar", [True, False], ids=["E11", "E22"])
def test_bar_of_hexahedra_carries_the_wave_speed_and_keeps_its_energy(fibre_along_bar):
    """c = √(E/ρ) with E = E11 (fibre along the bar) or E22 (across), from the first
    longitudinal mode's frequency ω = π c / L of a free bar of 40 elements under explicit
    central differences at 0.9 of the elements' stable step; the energy is kept, and no
    hourglass mode is excited."""
    omega_measured, omega, omega_cd, hist, dt, _, state = bar_vibration(fibre_along_bar)
    assert omega_measured == pytest.approx(omega, rel=WAVE_TOL)
    assert omega_measured == pytest.approx(omega_cd, rel=DISCRETE_TOL)
    total = hist[:, 1] + hist[:, 2] + hist[:, 3]
    assert np.abs(total - total[0]).max() <= ENERGY_TOL * total[0]
    assert np.abs(hist[:, 3]).max() <= 1e-9 * total[0]
    assert np.all(np.isfinite(state))


def test_explicit_run_is_bitwise_the_same_on_1_and_2_threads():
    import numba

    from wovenimpact.jit import set_threads

    before = numba.get_num_threads()
    try:
        set_threads(1)
        one = bar_vibration(True, periods=1.0)
        set_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        two = bar_vibration(True, periods=1.0)
    finally:
        set_threads(before)
    assert np.array_equal(one[3], two[3])
    assert np.array_equal(one[5], two[5])
    assert np.array_equal(one[6], two[6])
