"""Solid elements through the solver (docs/solid.md §4): 8-node hexahedra of the yarn of
thesis Table 5-2 in the Model / State / ``step`` of the shells.

- patch test: an irregular patch whose boundary is driven along a linear velocity field
  and whose interior nodes are free: every element carries the same stress, the interior
  nodes stay on the field, and the stress is the material's own at the field's F;
- a free bar's first longitudinal mode: its wave speed against √(E/ρ), along the fibre
  and across it, from a case file (``[mesh] kind = "block"``, ``[solid_sections]``);
- a free vibration of a distorted block (hourglass modes excited): the energy balance
  and the internal work against the stored and hourglass energies booked;
- a stretched block turned rigidly by the solver's rotating constraint: its stress turns
  with it and nothing else changes.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from tests.verification.hex_driver import THESIS_YARN, box_mesh
from tests.verification.test_hex8_patch import distorted_2x2x2, macneal_harder
from wovenimpact.kernels import solid_layout as L
from wovenimpact.kernels.integrate import PRESCRIBED
from wovenimpact.materials.transverse_isotropic import initial_state as ti_state
from wovenimpact.materials.transverse_isotropic import update_points
from wovenimpact.model.model import BoundaryConditions, build_model
from wovenimpact.model.solid import SolidSection, block_mesh, solid_part
from wovenimpact.setup.compile import compile_case
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver.explicit import Workspace, step
from wovenimpact.spec.case import case_from_dict
from wovenimpact.state import initial_state

ROOT = Path(__file__).resolve().parents[2]
YARN_FILE = ROOT / "examples" / "materials" / "kevlar_yarn_solid.toml"
EXACT = 1e-10
SIG = slice(L.H_SIG, L.H_SIG + 6)
NO_SHELLS = np.zeros((0, 4), dtype=np.int64)
# the fibre oblique to every mesh, and a2 fixed (the yarn is square-symmetric about a1)
OBLIQUE = SolidSection(THESIS_YARN, fibre_direction=(1.0, 2.0, 3.0),
                       second_direction=(0.0, 0.0, 1.0))
# a velocity gradient (1/s): a strain of about 1e-3 in 0.5 µs
RATE = 4e3 * np.array([[1.0, 0.3, -0.2], [0.1, -0.5, 0.4], [0.25, 0.2, 0.7]])


def solid_model(nodes, hexes, section=OBLIQUE, bcs=None):
    part = solid_part(nodes, hexes, {"yarn": section}, np.zeros(len(hexes), dtype=np.int64))
    return build_model(nodes, NO_SHELLS, {}, np.zeros(0, dtype=np.int64), bcs=bcs, solid=part)


def driven(nodes, boundary):
    """Constraints driving the ``boundary`` nodes at the linear field v = RATE x."""
    bcs = BoundaryConditions(len(nodes))
    bcs.code[boundary, :3] = PRESCRIBED
    bcs.velocity[boundary, :3] = (nodes @ RATE.T)[boundary]
    return bcs


@pytest.mark.parametrize("patch", ["MacNeal-Harder", "distorted 2x2x2"])
def test_patch_test_through_the_solver(patch):
    """The outer nodes are driven at v = L x, the interior ones start on that field and are
    free: the exact solution is the homogeneous motion, every element at F = I + t L, so
    every element has one stress (to 1e-10 of it), the interior nodes keep to the field
    (to 1e-10 of its displacement) with no net force (to 1e-10 of σ h²), and the stress is
    the material's own along the same F^n (materials.transverse_isotropic.update_points)."""
    h = 1e-3
    if patch == "MacNeal-Harder":
        nodes, hexes = macneal_harder(h)
        boundary = np.arange(8)
    else:
        nodes, hexes = distorted_2x2x2(h)
        on_face = np.any((np.abs(nodes) < 1e-12 * h) | (np.abs(nodes - h) < 1e-12 * h), axis=1)
        boundary = np.flatnonzero(on_face)
    interior = np.setdiff1d(np.arange(len(nodes)), boundary)
    assert interior.size  # the patch has free nodes
    model = solid_model(nodes, hexes, bcs=driven(nodes, boundary))
    st = initial_state(model, velocity=nodes @ RATE.T)
    ws = Workspace.for_model(model, st)
    times = []
    while st.t < 0.5e-6:
        times.append(st.t)  # x^n, the positions the element stage of this step reads
        step(model, st, ws)
    sig = st.hex[:, SIG]  # the stress at x^n of the last step
    scale = np.abs(sig).max()
    spread = np.abs(sig - sig[0]).max() / scale
    field = nodes + st.t * (nodes @ RATE.T)
    off_field = np.abs(st.x[interior] - field[interior]).max() / (np.abs(RATE).max() * st.t * h)
    force = np.abs(st.f_int[interior, :3]).max() / (scale * h * h)
    f_seq = np.eye(3) + np.multiply.outer(np.array(times[1:]), RATE)
    rows = ti_state(1)
    for f in f_seq:
        rows = update_points(THESIS_YARN, OBLIQUE.frame(), f, rows)
    material = np.abs(sig - rows[0, SIG]).max() / scale
    print(f"\n{patch}: {st.step} steps, strain {np.abs(RATE).max() * st.t:.2e}, |σ| "
          f"{scale:.3e} Pa; stress spread {spread:.1e}, interior nodes off the field "
          f"{off_field:.1e}, interior force / (σ h²) {force:.1e}, against the material "
          f"alone {material:.1e}")
    assert st.step > 10
    assert spread < EXACT
    assert off_field < EXACT
    assert force < EXACT
    assert material < EXACT
    assert np.abs(st.hex[:, L.H_W_HG]).max() < EXACT * np.abs(st.hex[:, L.H_W]).max()


def yarn_bar(fibre, second, n=40, length=20e-3, width=1e-3):
    """A free bar of n × 1 × 1 hexahedra along x, compiled from a case."""
    doc = {
        "case": {"name": "yarn bar"},
        "materials": {"yarn": YARN_FILE.as_posix()},
        "solid_sections": {"yarn": {"material": "yarn", "fibre_direction": fibre,
                                    "second_direction": second}},
        "mesh": {"kind": "block", "size": [f"{length * 1e3:g} mm", f"{width * 1e3:g} mm",
                                           f"{width * 1e3:g} mm"],
                 "elements": [n, 1, 1], "section": "yarn"},
        "run": {"end_time": "10 us"},
    }
    return compile_case(case_from_dict(doc), ROOT).model


@pytest.mark.parametrize("axis, modulus", [("fibre", 96e9), ("across", 3.28e9)])
def test_a_bars_longitudinal_wave_speed_is_that_of_its_modulus(axis, modulus):
    """The first free–free mode of a bar of 40 elements, started from its velocity shape
    v = V cos(π x / L): the end's velocity changes sign at T/4 and 3T/4, T = 2L/c, so c =
    L / (t₂ − t₁). Within 1 % of √(E/ρ) (ν = 0: no lateral inertia), E = E11 with the
    fibre along the bar, E22 across it."""
    fibre, second = ([1, 0, 0], [0, 1, 0]) if axis == "fibre" else ([0, 1, 0], [1, 0, 0])
    model = yarn_bar(fibre, second)
    length = 20e-3
    x = model.x0[:, 0]
    v = np.zeros((model.n_nodes, 3))
    v[:, 0] = 0.1 * np.cos(np.pi * x / length)
    st = initial_state(model, velocity=v)
    ws = Workspace.for_model(model, st)
    end = np.flatnonzero(x == x.max())
    c0 = math.sqrt(modulus / THESIS_YARN.density)
    period = 2.0 * length / c0
    t, vel = [0.0], [float(st.v[end, 0].mean())]
    while st.t < 0.85 * period:
        step(model, st, ws)
        t.append(st.t - 0.5 * st.dt)  # v^{n+1/2} belongs to t^{n+1/2}
        vel.append(float(st.v[end, 0].mean()))
    t, vel = np.array(t), np.array(vel)
    i = np.flatnonzero(np.sign(vel[1:]) != np.sign(vel[:-1]))
    assert i.size == 2
    zeros = t[i] - vel[i] * (t[i + 1] - t[i]) / (vel[i + 1] - vel[i])
    c = length / (zeros[1] - zeros[0])
    error = c / c0 - 1.0
    print(f"\nbar, modulus {modulus:.3g} Pa ({axis}): c = {c:.6g} m/s, √(E/ρ) = {c0:.6g} m/s, "
          f"error {error:+.2e} ({st.step} steps)")
    assert abs(error) < 0.01


def test_a_free_vibration_keeps_its_energy_and_books_its_hourglass_work():
    """A distorted 8 × 4 × 2 block, fibre oblique, started from a rough velocity field (its
    hourglass modes excited), 1000 steps free: the energy balance error stays below 1 %
    and the internal work of the nodal forces equals the stored plus hourglass energy the
    elements book (to 1 % of it)."""
    mesh = block_mesh((4e-3, 2e-3, 1e-3), (8, 4, 2))
    rng = np.random.default_rng(3)
    nodes = mesh.nodes + rng.uniform(-0.05e-3, 0.05e-3, mesh.nodes.shape)
    model = solid_model(nodes, mesh.hexes)
    x = nodes / np.array([4e-3, 2e-3, 1e-3])
    v = 0.5 * rng.normal(size=nodes.shape) + np.stack(
        [np.sin(np.pi * x[:, 0]), x[:, 0], np.cos(3.0 * x[:, 1])], axis=1)
    st = initial_state(model, velocity=v - v.mean(axis=0))
    ws = Workspace.for_model(model, st)
    worst = 0.0
    for n in range(1000):
        step(model, st, ws)
        if n % 50 == 49:
            worst = max(worst, energy_balance(model, st)["error_fraction"])
    eb = energy_balance(model, st)
    booked = eb["stored_J"] + eb["hourglass_J"]
    mismatch = abs(eb["internal_work_J"] - booked) / booked
    print(f"\nfree block: {st.step} steps, energy error ≤ {worst:.1e}; internal work "
          f"{eb['internal_work_J']:.4e} J, stored {eb['stored_J']:.4e} J + hourglass "
          f"{eb['hourglass_J']:.3e} J (mismatch {mismatch:.1e}); kinetic {eb['kinetic_J']:.3e} "
          f"of {eb['initial_kinetic_J']:.3e} J")
    assert worst < 0.01
    assert eb["internal_work_J"] > 0.1 * eb["initial_kinetic_J"]  # it vibrates
    assert eb["hourglass_J"] > 0.0
    assert mismatch < 1e-2  # (the hourglass energy alone is 7 % of it)


def test_a_rigid_rotation_changes_no_stress():
    """A block stretched along v = L x (all nodes driven), then turned rigidly by the
    solver's rotating constraint (every node on its circle, kernels.integrate
    ``rotation_step``) about an oblique axis by about 90°: its Cauchy stress becomes
    Q σ Qᵀ (to 1e-10 of |σ|), its stored and hourglass energies and its volumes do not
    change (to 1e-10), and an unstressed block turned alike stays unstressed."""
    nodes, hexes = box_mesh(3, 2, 2, 1.5e-3, 1e-3, 1e-3)
    rng = np.random.default_rng(7)
    nodes = nodes + rng.uniform(-0.05e-3, 0.05e-3, nodes.shape)
    everything = np.arange(len(nodes))
    centre = nodes.mean(axis=0)
    omega = 1.2e5 * np.array([1.0, -2.0, 2.0]) / 3.0  # rad/s
    turn = BoundaryConditions(len(nodes)).rotate(everything, omega, centre)
    for stretch in (True, False):
        stretched = solid_model(nodes, hexes, bcs=driven(nodes, everything))
        st = initial_state(stretched, velocity=nodes @ RATE.T)
        ws = Workspace.for_model(stretched, st)
        while stretch and st.t < 0.4e-6:
            step(stretched, st, ws)
        model = solid_model(nodes, hexes, bcs=turn)
        ws = Workspace.for_model(model, st)
        step(model, st, ws)  # the last stretch increment; the nodes begin to turn
        before = st.hex.copy()  # (the elements at x^n, at t0)
        t0 = st.t - st.dt
        while st.t < t0 + 0.5 * math.pi / np.linalg.norm(omega):
            step(model, st, ws)
        step(model, st, ws)  # the element stage sees x^n of the last rotation step
        q = Rotation.from_rotvec(omega * (st.t - st.dt - t0)).as_matrix()
        sig0 = full(before[:, SIG])
        expected = np.einsum("ij,njk,lk->nil", q, sig0, q)
        scale = max(np.abs(sig0).max(), 1e-30)
        turned = np.abs(full(st.hex[:, SIG]) - expected).max()
        energy = np.abs(st.hex[:, [L.H_W, L.H_W_HG]] - before[:, [L.H_W, L.H_W_HG]]).max()
        volume = np.abs(st.hex[:, L.H_VOL] / before[:, L.H_VOL] - 1.0).max()
        if stretch:
            print(f"\nstretched block turned {np.degrees(np.linalg.norm(omega) * (st.t - st.dt - t0)):.1f}°: "
                  f"|σ − Q σ0 Qᵀ| / |σ0| {turned / scale:.1e}, energies changed by "
                  f"{energy / np.abs(before[:, L.H_W]).max():.1e}, volumes {volume:.1e}")
            assert turned < EXACT * scale
            assert energy < EXACT * np.abs(before[:, L.H_W]).max()
            assert np.abs(q - np.eye(3)).max() > 0.5  # it did turn
        else:
            unstressed = np.abs(st.hex[:, SIG]).max() / THESIS_YARN.e11
            print(f"unstressed block turned: |σ| / E11 {unstressed:.1e}")
            assert unstressed < EXACT * 1e-2
        assert volume < EXACT


def full(voigt):
    """(n, 6) Voigt 11, 22, 33, 23, 13, 12 → (n, 3, 3)."""
    s = np.empty((len(voigt), 3, 3))
    for k, (i, j) in enumerate(((0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1))):
        s[:, i, j] = s[:, j, i] = voigt[:, k]
    return s


def cantilever_stiffness(layers: int, length=5e-3, depth=1e-3, width=1e-3,
                         tip=0.05e-3, periods=10.0):
    """A cantilever of hexahedra, 2 × ``layers`` elements per depth along it, ``layers``
    through its depth and one across, of an isotropic solid (E = 200 GPa, ν = 0, G = E/2),
    clamped at x = 0 (every node held) and its tip face driven along z to ``tip`` by a
    smooth step over ``periods`` of its first bending period (quasi-static). Returns (the
    tip force over the tip deflection, kinetic over internal work, hourglass over internal
    work) at the end."""
    from wovenimpact.materials.transverse_isotropic import TransverseIsotropicParameters

    e, rho = 200e9, 7850.0
    mat = TransverseIsotropicParameters(e11=e, e22=e, g12=e / 2, g23=e / 2, nu12=0.0,
                                        nu23=0.0, density=rho, name="isotropic")
    nodes, hexes = box_mesh(2 * layers * round(length / depth), 1, layers, length, width, depth)
    inertia = width * depth**3 / 12
    omega = 1.875**2 * math.sqrt(e * inertia / (rho * width * depth * length**4))
    t_end = periods * 2 * math.pi / omega
    bcs = BoundaryConditions(len(nodes), ramp_time=t_end)
    bcs.fix(np.flatnonzero(nodes[:, 0] == 0.0), (0, 1, 2))
    tip_nodes = np.flatnonzero(np.isclose(nodes[:, 0], length))
    bcs.prescribe(tip_nodes, 2, 2.0 * tip / t_end)  # the smooth step's mean is half
    model = solid_model(nodes, hexes, SolidSection(mat, hourglass=0.05, fibre_direction=(1, 0, 0),
                                                   second_direction=(0, 1, 0)), bcs)
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    while st.t < t_end:
        step(model, st, ws)
    w = float(np.mean(st.x[tip_nodes, 2] - model.x0[tip_nodes, 2]))
    force = float(np.sum(st.f_ext[tip_nodes, 2]))
    b = energy_balance(model, st)
    return force / w, b["kinetic_J"] / b["internal_work_J"], b["hourglass_J"] / b["internal_work_J"]


@pytest.mark.slow
def test_a_cantilevers_tip_stiffness_converges_to_timoshenkos():
    """A cantilever 5 deep long (about 20 s): its tip stiffness on 4 and 8 elements through
    the depth against Timoshenko's beam, 1 / (L³/3EI + L/κGA) with κ = 5/6. One-point
    hexahedra bend by their layers' membrane strains (the hourglass stiffness r = 0.05 adds
    little), so a mesh of n layers has 1 − 1/n² of the bending stiffness: the error falls
    by about 4 from 4 to 8 layers (second order; measured 5.84 → 1.42 %), the 8-layer
    mesh is within 2 %, and the Richardson extrapolation of the two within 1 % of
    Timoshenko's (measured +0.05 %; on a cantilever 10 deep, 80 × 8: −1.5 % and +0.03 %,
    docs/solid.md §4.5); quasi-static (kinetic energy below 1 % of the internal work) with
    the hourglass energy below 1 % of it."""
    e, length, depth, width = 200e9, 5e-3, 1e-3, 1e-3
    inertia, area = width * depth**3 / 12, width * depth
    exact = 1.0 / (length**3 / (3 * e * inertia) + length / (5 / 6 * e / 2 * area))
    (k4, kin4, hg4), (k8, kin8, hg8) = (cantilever_stiffness(n) for n in (4, 8))
    richardson = k8 + (k8 - k4) / 3.0
    print(f"\nk4 {k4 / exact - 1:+.4f}, k8 {k8 / exact - 1:+.4f}, Richardson "
          f"{richardson / exact - 1:+.5f} (Timoshenko {exact:.6g} N/m); kinetic {kin8:.1e}, "
          f"hourglass {hg8:.1e}")
    assert 3.0 < (exact - k4) / (exact - k8) < 5.0
    assert abs(k8 / exact - 1.0) < 0.02
    assert abs(richardson / exact - 1.0) < 0.01
    assert max(kin4, kin8) < 0.01 and max(hg4, hg8) < 0.01
