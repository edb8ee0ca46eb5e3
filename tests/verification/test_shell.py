"""Shell element and explicit integration against analytic solutions (issue 3, point 6)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.verification.meshes import elastic, rect_grid
from wovenimpact.kernels import shell_layout as S
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.solver import Workspace, energy_balance, step
from wovenimpact.solver.explicit import element_forces
from wovenimpact.state import initial_state


def distorted_square(n=4, amplitude=0.25, seed=3):
    nodes, quads = rect_grid(n, n, 1.0, 1.0)
    rng = np.random.default_rng(seed)
    inner = (nodes[:, 0] > 0) & (nodes[:, 0] < 1) & (nodes[:, 1] > 0) & (nodes[:, 1] < 1)
    nodes[inner, :2] += rng.uniform(-amplitude, amplitude, (inner.sum(), 2)) / n
    return nodes, quads, inner


def forces_at(model, x, state=None):
    """Element forces of ``model`` with nodes at x (no rates)."""
    st = initial_state(model) if state is None else state
    st.x = np.array(x, dtype=float)
    ws = Workspace.for_model(model, st)
    element_forces(model, st, ws)
    return st, ws


def test_membrane_patch_test_on_a_distorted_mesh_is_exact():
    """A linear displacement field gives the same F, N in every element of a distorted
    mesh, and zero net force on every interior node, to round-off."""
    nodes, quads, inner = distorted_square()
    mat = elastic()
    t = 1e-3
    model = build_model(nodes, quads, {"s": Section(mat, thickness=t)}, np.zeros(len(quads), int))
    grad = np.array([[1e-3, 4e-4], [-2e-4, -5e-4]])
    x = nodes.copy()
    x[:, :2] += nodes[:, :2] @ grad.T
    _, ws = forces_at(model, x)
    f = np.eye(2) + grad
    # the corotational frame turns with side 1-2: compare invariants of N and F
    F_el = ws.elem[:, S.E_F:S.E_F + 4].reshape(-1, 2, 2)
    C_el = np.einsum("nki,nkj->nij", F_el, F_el)
    c_err = np.max(np.abs(C_el - f.T @ f))
    n_el = ws.elem[:, S.E_N:S.E_N + 3]
    tr = n_el[:, 0] + n_el[:, 1]
    det = n_el[:, 0] * n_el[:, 1] - n_el[:, 2] ** 2
    scale = mat.modulus * t * 1e-3
    f_scale = scale * 0.25
    f_inner = np.max(np.abs(ws.f_int[inner, :3]))
    print(f"\npatch test: max |C − C_exact| = {c_err:.1e}, spread of tr N = "
          f"{np.ptp(tr) / scale:.1e}, interior force {f_inner / f_scale:.1e} (relative)")
    assert c_err < 1e-14
    assert np.ptp(tr) < 1e-10 * scale and np.ptp(det) < 1e-10 * scale**2
    assert f_inner < 1e-10 * f_scale


@pytest.mark.parametrize("axis", [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (1.0, 2.0, 2.0)])
def test_rigid_rotation_by_90_degrees_leaves_no_stress(axis):
    """Nodes driven through a 90° rigid rotation in 200 steps: membrane, bending,
    shear and hourglass resultants stay below 1e-10 E (as stresses).

    Velocities are the chords (x^n − x^{n−1})/Δt and the spins the midpoint-rule
    spin of the same rotation increment Δφ, 2 tan(Δφ/2)/Δt (Hughes–Winget), which
    is what central differences give a rigidly rotating body."""
    nodes, quads, _ = distorted_square(n=3)
    mat = elastic()
    t = 1e-3
    model = build_model(nodes, quads, {"s": Section(mat, thickness=t)}, np.zeros(len(quads), int))
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    a = np.asarray(axis) / np.linalg.norm(axis)
    n_steps, dt = 200, 1e-6
    rate = 0.5 * math.pi / (n_steps * dt)

    def rot(phi):
        k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
        return np.eye(3) + math.sin(phi) * k + (1 - math.cos(phi)) * k @ k

    for k in range(1, n_steps + 1):
        x_new = (nodes - 0.5) @ rot(k * rate * dt).T + 0.5
        st.v = (x_new - st.x) / dt
        spin = 2.0 * math.tan(0.5 * rate * dt) / dt
        st.omega = np.broadcast_to(spin * a, st.x.shape).copy()
        st.x = x_new
        st.dt = dt
        element_forces(model, st, ws)
        st.elem, ws.elem = ws.elem, st.elem
        st.mat, ws.mat = ws.mat, st.mat
    stress = max(np.max(np.abs(st.elem[:, S.E_N:S.E_N + 3])) / t,
                 np.max(np.abs(st.elem[:, S.E_M:S.E_M + 3])) * 6 / t**2,
                 np.max(np.abs(st.elem[:, S.E_Q:S.E_Q + 2])) / t,
                 np.max(np.abs(st.elem[:, S.E_HG:S.E_HG + 5])) / (t * 1e-3))
    print(f"\n90° rigid rotation about {axis}: max stress {stress / mat.modulus:.1e} E")
    assert stress < 1e-10 * mat.modulus


def cantilever(nx, thickness, length=0.1, width=0.01):
    nodes, quads = rect_grid(nx, 2, length, width)
    bc = BoundaryConditions(len(nodes)).fix(np.flatnonzero(nodes[:, 0] == 0.0))
    mat = elastic(poisson=0.0)  # ν = 0: the plate strip is exactly a beam
    model = build_model(nodes, quads, {"s": Section(mat, thickness=thickness)},
                        np.zeros(len(quads), int), bcs=bc)
    return nodes, model, mat


def test_cantilever_first_bending_frequency_matches_beam_theory():
    """f1 = (1.875²/2π) √(E I/(ρ A L⁴)) for a clamped–free strip, ν = 0 (within 3 %);
    total energy is also conserved over the run."""
    length, t = 0.1, 5e-3
    nodes, model, mat = cantilever(10, t, length)
    f_beam = 1.875**2 / (2 * math.pi) * math.sqrt(mat.modulus * t**2 / 12 / (mat.density * length**4))
    xi = nodes[:, 0] / length
    b = 1.875
    shape = np.cosh(b * xi) - np.cos(b * xi) - 0.7341 * (np.sinh(b * xi) - np.sin(b * xi))
    v0 = np.zeros((len(nodes), 3))
    v0[:, 2] = 0.05 * shape
    st = initial_state(model, velocity=v0)
    ws = Workspace.for_model(model, st)
    tip = np.flatnonzero(nodes[:, 0] == length)
    times, w = [], []
    while st.t < 2.6 / f_beam:
        step(model, st, ws)
        times.append(st.t)
        w.append(st.x[tip, 2].mean())
    times, w = np.array(times), np.array(w)
    crossings = times[1:][np.sign(w[:-1]) != np.sign(w[1:])]
    f_fe = 1.0 / (2.0 * np.mean(np.diff(crossings)))
    eb = energy_balance(model, st)
    print(f"\ncantilever (10 × 2 elements, L/t = 20): f1 = {f_fe:.2f} Hz vs beam theory "
          f"{f_beam:.2f} Hz ({f_fe / f_beam - 1:+.2%}); energy error {eb['error_fraction']:.1e}")
    assert f_fe == pytest.approx(f_beam, rel=0.03)
