"""Shell element and explicit integration against analytic solutions (issue 3, point 6)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tests.verification.meshes import elastic, rect_grid
from wovenimpact.kernels import fabric_layout as FL
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver import Workspace, step
from wovenimpact.kernels.gather import gather_nodal_forces
from wovenimpact.solver.explicit import shell_forces
from wovenimpact.state import KINETIC0, initial_state


def element_forces(model, state, ws) -> None:
    """The element forces at x^n and their nodal sums (into ws), without a step."""
    shell_forces(model, state, ws)
    gather_nodal_forces(model.node_ptr, model.node_elem, model.node_corner, ws.blocks, ws.alive,
                        ws.f_int, ws.live)


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
    F_el = ws.elem[:, SL.E_F:SL.E_F + 4].reshape(-1, 2, 2)
    C_el = np.einsum("nki,nkj->nij", F_el, F_el)
    c_err = np.max(np.abs(C_el - f.T @ f))
    n_el = ws.elem[:, SL.E_N:SL.E_N + 3]
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
    stress = max(np.max(np.abs(st.elem[:, SL.E_N:SL.E_N + 3])) / t,
                 np.max(np.abs(st.elem[:, SL.E_M:SL.E_M + 3])) * 6 / t**2,
                 np.max(np.abs(st.elem[:, SL.E_Q:SL.E_Q + 2])) / t,
                 np.max(np.abs(st.elem[:, SL.E_HG:SL.E_HG + 5])) / (t * 1e-3))
    print(f"\n90° rigid rotation about {axis}: max stress {stress / mat.modulus:.1e} E")
    assert stress < 1e-10 * mat.modulus


def cantilever(nx, thickness, length=0.1, width=0.01):
    nodes, quads = rect_grid(nx, 2, length, width)
    bc = BoundaryConditions(len(nodes)).fix(np.flatnonzero(nodes[:, 0] == 0.0))
    mat = elastic(poisson=0.0)  # ν = 0: the plate strip is exactly a beam
    model = build_model(nodes, quads, {"s": Section(mat, thickness=thickness)},
                        np.zeros(len(quads), int), bcs=bc)
    return nodes, model, mat


def first_mode_velocity(nodes, length, amplitude=0.05):
    """Transverse velocities in the shape of a clamped–free beam's first mode."""
    xi = nodes[:, 0] / length
    b = 1.875
    shape = np.cosh(b * xi) - np.cos(b * xi) - 0.7341 * (np.sinh(b * xi) - np.sin(b * xi))
    v0 = np.zeros((len(nodes), 3))
    v0[:, 2] = amplitude * shape
    return v0


def beam_frequency(mat, t, length):
    """f1 = (1.875²/2π) √(E I/(ρ A L⁴)) of a clamped–free beam of thickness t."""
    return 1.875**2 / (2 * math.pi) * math.sqrt(mat.modulus * t**2 / 12 / (mat.density * length**4))


def measured_frequency(model, nodes, length, t_end):
    """Run the cantilever in its first mode until t_end; the tip's zero crossings give f1."""
    st = initial_state(model, velocity=first_mode_velocity(nodes, length))
    ws = Workspace.for_model(model, st)
    tip = np.flatnonzero(nodes[:, 0] == length)
    times, w = [], []
    while st.t < t_end:
        step(model, st, ws)
        times.append(st.t)
        w.append(st.x[tip, 2].mean())
    times, w = np.array(times), np.array(w)
    crossings = times[1:][np.sign(w[:-1]) != np.sign(w[1:])]
    return 1.0 / (2.0 * np.mean(np.diff(crossings))), st


def test_cantilever_first_bending_frequency_matches_beam_theory():
    """f1 = (1.875²/2π) √(E I/(ρ A L⁴)) for a clamped–free strip, ν = 0 (within 3 %);
    the energy balance of the run holds to round-off at its end (2.6 periods)."""
    length, t = 0.1, 5e-3
    nodes, model, mat = cantilever(10, t, length)
    f_beam = beam_frequency(mat, t, length)
    f_fe, st = measured_frequency(model, nodes, length, 2.6 / f_beam)
    eb = energy_balance(model, st)
    print(f"\ncantilever (10 × 2 elements, L/t = 20): f1 = {f_fe:.2f} Hz vs beam theory "
          f"{f_beam:.2f} Hz ({f_fe / f_beam - 1:+.2%}); energy error {eb['error_fraction']:.1e}")
    assert f_fe == pytest.approx(f_beam, rel=0.03)
    # leapfrog kinetic energy with trapezoidal work balances a linear system at constant
    # Δt exactly: what is left is round-off (measured 1.2e-15)
    assert st.energy[KINETIC0] > 0.0 and eb["error_fraction"] < 1e-9


def test_longitudinal_wave_travels_at_the_plate_speed():
    """A velocity step at one end of a strip held laterally (ε_yy = 0) travels at
    c = √(E/(ρ(1 − ν²))); the front (half the driven velocity) is timed at two
    stations (within 2 %)."""
    length, n = 0.2, 200
    nodes, quads = rect_grid(n, 1, length, length / n)
    mat = elastic()
    bc = BoundaryConditions(len(nodes), ramp_time=4e-6)
    bc.fix(np.arange(len(nodes)), dofs=(1, 2, 3, 4, 5))
    bc.prescribe(np.flatnonzero(nodes[:, 0] == 0.0), 0, 1.0)
    model = build_model(nodes, quads, {"s": Section(mat, thickness=1e-3)},
                        np.zeros(len(quads), int), bcs=bc)
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    stations = [np.flatnonzero(np.isclose(nodes[:, 0], xs)) for xs in (0.05, 0.15)]
    arrival = [None, None]
    t_prev, v_prev = 0.0, [0.0, 0.0]
    while arrival[1] is None:
        step(model, st, ws)
        t_half = st.t - 0.5 * st.dt  # velocities live at half steps
        for k, s in enumerate(stations):
            vk = st.v[s, 0].mean()
            if arrival[k] is None and vk >= 0.5:  # interpolate the crossing in time
                arrival[k] = t_prev + (0.5 - v_prev[k]) / (vk - v_prev[k]) * (t_half - t_prev)
            v_prev[k] = vk
        t_prev = t_half
    c_fe = 0.1 / (arrival[1] - arrival[0])
    c_exact = math.sqrt(mat.modulus / (mat.density * (1 - mat.poisson**2)))
    print(f"\nlongitudinal wave: {c_fe:.1f} m/s vs √(E/(ρ(1−ν²))) = {c_exact:.1f} m/s "
          f"({c_fe / c_exact - 1:+.2%})")
    assert c_fe == pytest.approx(c_exact, rel=0.02)


def test_free_vibration_conserves_energy_over_ten_periods():
    """Cantilever in its first mode for 10 periods: |total energy drift| < 0.5 % of
    the initial kinetic energy."""
    length, t = 0.1, 5e-3
    nodes, model, mat = cantilever(6, t, length)
    f_beam = beam_frequency(mat, t, length)
    st = initial_state(model, velocity=first_mode_velocity(nodes, length))
    ws = Workspace.for_model(model, st)
    worst = 0.0
    while st.t < 10.0 / f_beam:
        step(model, st, ws)
        worst = max(worst, abs(energy_balance(model, st)["drift_J"]))
    ke0 = energy_balance(model, st)
    print(f"\nfree vibration, 10 periods ({st.step} steps): max |drift| = "
          f"{worst / st.energy[5]:.2e} of the initial kinetic energy")
    assert worst < 5e-3 * st.energy[5]
    assert ke0["hourglass_J"] < 1e-3 * st.energy[5]


def test_stable_step_follows_the_formula():
    """Δt = α L_e / c with L_e = A / longest edge and c = √(E/(ρ(1 − ν²))) (eq. 4.8–4.11),
    for a 3 mm × 1 mm element (L_e = 1 mm)."""
    nodes = np.array([[0, 0, 0], [3e-3, 0, 0], [3e-3, 1e-3, 0], [0, 1e-3, 0]], dtype=float)
    mat = elastic()
    model = build_model(nodes, [[0, 1, 2, 3]], {"s": Section(mat, thickness=1e-4)}, [0])
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    step(model, st, ws)
    c = math.sqrt(mat.modulus / (mat.density * (1 - mat.poisson**2)))
    expected = 0.9 * (3e-6 / 3e-3) / c
    print(f"\nstable step {st.dt:.6e} s vs α L_e / c = {expected:.6e} s")
    assert st.dt == pytest.approx(expected, rel=1e-12)


def fabric_element_frequency(model, nodes, sx, sy, shear, h=1e-10):
    """ω_max of a single crossover element whose corners are moved to x = (sx X + shear Y,
    sy Y) from its reference square, and the stable step it reports there: the tangent
    K (24 dofs, translations and rotations) by central differences of the element
    forces, ω² the largest eigenvalue of M⁻¹K with the lumped masses and inertias."""
    xs = nodes.copy()
    xs[:, 0] = sx * nodes[:, 0] + shear * nodes[:, 1]
    xs[:, 1] *= sy

    def forces(v, w, dt):
        st = initial_state(model)
        st.v, st.omega, st.dt = v, w, dt
        st.x = xs + dt * v
        ws = Workspace.for_model(model, st)
        element_forces(model, st, ws)
        return ws.f_int[:, :6].ravel().copy(), ws.elem[0, SL.E_DT]

    k = np.zeros((24, 24))
    for j in range(24):
        u = np.zeros((2, 4, 3))
        u[j % 6 // 3, j // 6, j % 3] = 1.0
        k[:, j] = (forces(u[0], u[1], h)[0] - forces(-u[0], -u[1], h)[0]) / (2.0 * h)
    mass = np.concatenate([[m] * 3 + [i] * 3 for m, i in zip(model.node_mass,
                                                              model.node_inertia)])
    omega = math.sqrt(float(np.max(np.linalg.eigvals(k / mass[:, None]).real)))
    return omega, forces(np.zeros((4, 3)), np.zeros((4, 3)), 0.0)[1]


def test_a_crushed_fabric_elements_stable_step_follows_its_taut_yarns_not_its_width():
    """``run.stable_step = "yarn"``: the stable step of a crossover element against its
    own largest eigenfrequency (theory §4, "Stable step"). Stable: α ω_max Δt_e ≤ 2
    (α = 0.9) in every state — at rest, with the warp taut, crushed across the taut
    warp to 0.5 and 0.2, crushed both ways (both families slack, sheared or not),
    sheared. Not collapsed: the membrane is total-
    Lagrangian, so the taut warp's wave crosses the element's reference length
    whatever its width — crushed to half across it, the element keeps the step it had
    uncrushed (within 1 %; the step was 2.8× smaller when it paired the narrow width
    with the stiffness per current width), and an element crushed with both families
    slack keeps at least its undeformed step."""
    from tests.conftest import reference_fabric
    fab = reference_fabric()
    side = 8.0 * fab.warp.half_length
    nodes = np.array([[0, 0, 0], [side, 0, 0], [side, side, 0], [0, side, 0]], dtype=float)
    sec = Section(fab, bending_modulus=1e9, transverse_shear_modulus=3.28e9)
    model = build_model(nodes, [[0, 1, 2, 3]], {"fabric": sec}, [0], stable_step="yarn")
    states = {"rest": (1.0, 1.0, 0.0), "warp taut": (1.045, 1.0, 0.0),
              "crushed 0.5": (1.045, 0.5, 0.0), "crushed 0.2": (1.045, 0.2, 0.0),
              "both slack": (0.5, 0.5, 0.0), "both slack, sheared": (0.5, 0.5, 0.1),
              "slack, sheared": (0.8, 0.8, 0.2), "sheared": (1.0, 1.0, 0.3),
              "taut, crushed, sheared": (1.045, 0.3, 0.2)}
    res = {name: fabric_element_frequency(model, nodes, *f) for name, f in states.items()}
    for name, (omega, dt_e) in res.items():
        print(f"\n{name:24s} Δt_e = {dt_e:.3e} s, α ω_max Δt_e = {0.9 * omega * dt_e:.3f}",
              end="")
        assert 0.9 * omega * dt_e <= 2.0, name
    assert res["crushed 0.5"][1] == pytest.approx(res["warp taut"][1], rel=0.01)
    assert res["both slack"][1] >= res["rest"][1]
    # and the bound is not loose where the taut warp governs
    assert 0.9 * res["warp taut"][0] * res["warp taut"][1] > 1.5


def titanium_plate(n, side, thickness):
    """An n × n grid of squares of ``side`` in elastic titanium (the blade's E, ν, ρ)."""
    mat = elastic(modulus=115.1424e9, poisson=0.35, density=4424.0)
    nodes, quads = rect_grid(n, n, n * side, n * side)
    return mat, nodes, build_model(nodes, quads, {"s": Section(mat, thickness=thickness)},
                                   np.zeros(len(quads), int))


def test_a_thick_metal_shells_spins_do_not_set_its_step_and_add_no_faster_mode():
    """Rotary inertia (``model.rotary_inertia``, theory §4 "Stable step"): a metal
    element's corner inertia is raised, where it must be, so that its rotational bound
    2 √(I/k_θ) is no shorter than its membrane bound L_e/c_e at the reference geometry.
    A titanium square of 5 mm side and 5 mm thick (the blade's proportions) had its step
    set by its spins, at 0.73 of the membrane's (A0/8 scaling alone). Now its step at
    rest is the membrane's, L_e/c_e, and its largest eigenfrequency ω_max (24 dofs, its
    lumped masses and inertias) times its step is no larger than a thin element's
    (0.5 mm, whose spins are slow anyway) at rest, stretched, crushed and sheared: the
    spins add no faster mode. (A single free element has α ω_max Δt_e ≈ 2.1 whatever
    its thickness: it bounds an assembled mesh's from above; the mesh is tested below.)
    The thin one keeps ¼ m max(t²/12, A0/8) bit for bit."""
    side = 5e-3
    states = {"rest": (1.0, 1.0, 0.0), "stretched": (1.05, 1.0, 0.0),
              "crushed": (0.6, 1.0, 0.0), "sheared": (1.0, 1.0, 0.3)}
    res = {}
    for t in (5e-3, 0.5e-3):
        mat, nodes, model = titanium_plate(1, side, t)
        res[t] = {name: fabric_element_frequency(model, nodes, *f, h=1e-9)
                  for name, f in states.items()}
        m_el = model.sections[0, SL.C_AREAL_MASS] * model.area0[0]  # (the old expression)
        plain = 0.25 * m_el * max(t * t / 12.0, model.area0[0] / 8.0)
        if t < side / 2:
            assert model.elem_rot_inertia[0] == plain
        else:
            assert model.elem_rot_inertia[0] > plain
    c = math.sqrt(mat.modulus / (mat.density * (1 - mat.poisson**2)))
    assert res[5e-3]["rest"][1] == pytest.approx(side / c, rel=1e-12)
    for name in states:
        (w_thick, dt_thick), (w_thin, dt_thin) = res[5e-3][name], res[0.5e-3][name]
        print(f"\n{name:10s} α ω_max Δt_e: 5 mm {0.9 * w_thick * dt_thick:.3f}, "
              f"0.5 mm {0.9 * w_thin * dt_thin:.3f}", end="")
        assert w_thick * dt_thick <= w_thin * dt_thin * (1 + 1e-6), name


def test_a_clamped_thick_titanium_plate_is_stable_at_its_membrane_step():
    """The assembled check behind the rule: a 4 × 4 plate of 5 mm squares, 5 mm thick,
    clamped on its edge, its tangent K (translations and rotations of the 9 free nodes)
    by central differences of the element forces: ω_max Δt₁ ≤ 2, with Δt₁ = α L_e/c_e
    the model's first step (now the membrane's)."""
    mat, nodes, model = titanium_plate(4, 5e-3, 5e-3)
    lo, hi = nodes[:, :2].min(axis=0), nodes[:, :2].max(axis=0)
    inner = np.flatnonzero(np.all((nodes[:, :2] > lo + 1e-9) & (nodes[:, :2] < hi - 1e-9), axis=1))
    dofs = [(n, d) for n in inner for d in range(6)]
    h = 1e-9

    def forces(sign, n, d):
        st = initial_state(model)
        st.dt = h
        (st.v if d < 3 else st.omega)[n, d % 3] = sign
        st.x = st.x + h * st.v
        ws = Workspace.for_model(model, st)
        element_forces(model, st, ws)
        return np.array([ws.f_int[m, e] for m, e in dofs]), ws.elem[:, SL.E_DT].min()

    k = np.zeros((len(dofs), len(dofs)))
    for j, (n, d) in enumerate(dofs):
        k[:, j] = (forces(1.0, n, d)[0] - forces(-1.0, n, d)[0]) / (2.0 * h)
    mass = np.array([model.node_mass[n] if d < 3 else model.node_inertia[n] for n, d in dofs])
    omega = math.sqrt(float(np.max(np.linalg.eigvals(k / mass[:, None]).real)))
    dt1 = 0.9 * forces(0.0, 0, 0)[1]
    c = math.sqrt(mat.modulus / (mat.density * (1 - mat.poisson**2)))
    print(f"\nclamped 4×4, 5 mm thick: Δt₁ = {dt1:.4e} s (α L/c = {0.9 * 5e-3 / c:.4e}), "
          f"ω_max Δt₁ = {omega * dt1:.3f}")
    assert dt1 == pytest.approx(0.9 * 5e-3 / c, rel=1e-12)
    assert omega * dt1 <= 2.0


@pytest.mark.parametrize("stable_step", ["isotropic", "yarn"])
def test_erosion_on_the_stable_step_reads_the_isotropic_bound_under_either_option(stable_step):
    """An element erodes when its isotropic step L_e/c_e falls below the erosion step
    (``run.erode_dt_fraction`` of the first step), whichever step the run takes: the
    yarn option changes the step, not which elements erode. Crushed to 0.1 across its
    taut warp, the element's isotropic bound is ~10× below its yarn-family step; with
    the erosion step between the two it erodes under both options, below both it lives
    under both. (Under the yarn option it read its own yarn step before, and kept
    cells the default eroded; theory §4.)"""
    from tests.conftest import reference_fabric
    fab = reference_fabric()
    side = 8.0 * fab.warp.half_length
    nodes = np.array([[0, 0, 0], [side, 0, 0], [side, side, 0], [0, side, 0]], dtype=float)
    sec = Section(fab, bending_modulus=1e9, transverse_shear_modulus=3.28e9)
    model = build_model(nodes, [[0, 1, 2, 3]], {"fabric": sec}, [0], stable_step=stable_step)
    iso = build_model(nodes, [[0, 1, 2, 3]], {"fabric": sec}, [0])
    yarn = build_model(nodes, [[0, 1, 2, 3]], {"fabric": sec}, [0], stable_step="yarn")
    crushed = nodes.copy()
    crushed[:, 0] *= 1.045
    crushed[:, 1] *= 0.1

    def stage(m, dt_erode):
        st = initial_state(m)
        st.x = crushed.copy()
        st.dt_first = dt_erode * m.alpha / m.erode_dt_fraction
        ws = Workspace.for_model(m, st)
        element_forces(m, st, ws)
        return ws.elem[0, SL.E_ALIVE], ws.elem[0, SL.E_DT]

    _, dt_iso = stage(iso, 0.0)
    _, dt_yarn = stage(yarn, 0.0)
    assert dt_yarn > 5.0 * dt_iso  # the two bounds are far apart here
    between = math.sqrt(dt_iso * dt_yarn)
    assert stage(model, between)[0] == 0.0  # eroded
    assert stage(model, 0.5 * dt_iso)[0] == 1.0  # alive


def test_fabric_strip_pulled_along_the_warp_reproduces_the_single_element_curve():
    """Four crossover elements in a row, pulled slowly along the warp with the fill
    edges free: the warp tension against the displacement per element follows the
    single-element 'uniaxial-free' history (within 3 %), and the yarns break at its
    failure displacement (within 3 %)."""
    from tests.conftest import reference_fabric
    from wovenimpact.calibration.single_element import run_element_test
    fab = reference_fabric()
    cell = 2.0 * fab.warp.half_length
    n = 4
    nodes, quads = rect_grid(n, 1, n * cell, cell)
    left = np.flatnonzero(nodes[:, 0] == 0.0)
    right = np.flatnonzero(np.isclose(nodes[:, 0], n * cell))
    bc = BoundaryConditions(len(nodes), ramp_time=40e-6)
    bc.fix(np.arange(len(nodes)), (2, 3, 4, 5)).fix(left, (0,)).fix(left[:1], (1,))
    bc.prescribe(right, 0, 0.25)
    sec = Section(fab, bending_modulus=1e9, transverse_shear_modulus=3.28e9)
    model = build_model(nodes, quads, {"fabric": sec}, np.zeros(n, int), bcs=bc)
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    u_hist, t_hist = [], []
    first = model.mat_row[:-1]  # each element's first point's material row
    while st.elem[:, SL.E_ALIVE].all() and st.mat[first, FL.S_DAMAGE].max() == 0.0:
        step(model, st, ws)
        u_hist.append((st.x[right, 0].mean() - n * cell) / n)
        t_hist.append(st.mat[first, FL.S_TENSION].mean())
    u_fail = u_hist[-2]
    ref = run_element_test(fab, "uniaxial-free", n_steps=600)
    h = ref.history
    probes = np.array([0.040e-3, 0.045e-3, 0.050e-3])
    t_strip = np.interp(probes, u_hist, t_hist)
    t_cell = np.interp(probes, h["displacement_m"], h["tension_w_N"])
    dev = np.max(np.abs(t_strip / t_cell - 1.0))
    print(f"\nfabric strip: T_w at {probes * 1e3} mm = {np.round(t_strip, 1)} N vs single "
          f"element {np.round(t_cell, 1)} N (max deviation {dev:.1%}); failure at "
          f"{u_fail * 1e3:.4f} mm vs {ref.failure_displacement_m * 1e3:.4f} mm")
    assert dev < 0.03
    assert u_fail == pytest.approx(ref.failure_displacement_m, rel=0.03)


def test_hourglass_energy_stays_small_in_an_impulsively_loaded_plate():
    """Coarse clamped plate, a patch of nodes kicked at 20 m/s (an impact-like
    impulse that excites hourglass modes): hourglass energy < 5 % of internal energy."""
    from wovenimpact.model.mesh import plate_mesh

    mesh = plate_mesh(0.1, 0.01)
    bc = BoundaryConditions(mesh.n_nodes).fix(mesh.node_sets["edge_outer"])
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(elastic(), thickness=1e-3)},
                        np.zeros(mesh.n_elems, int), bcs=bc)
    v0 = np.zeros((mesh.n_nodes, 3))
    near = np.linalg.norm(mesh.nodes[:, :2], axis=1) < 0.011
    v0[near, 2] = 20.0
    st = initial_state(model, velocity=v0)
    ws = Workspace.for_model(model, st)
    worst = 0.0
    while st.t < 100e-6:
        step(model, st, ws)
        eb = energy_balance(model, st)
        if eb["stored_J"] > 0.05 * st.energy[5]:
            worst = max(worst, eb["hourglass_J"] / eb["stored_J"])
    eb = energy_balance(model, st)
    print(f"\nimpulsively loaded plate: hourglass / internal energy max {worst:.2%}, final "
          f"{eb['hourglass_J'] / eb['stored_J']:.2%}; energy error {eb['error_fraction']:.1e}")
    assert worst < 0.05


def test_steps_are_bitwise_identical_with_one_or_two_threads():
    """The same Model and State give bitwise the same State after 30 steps of a
    fabric plate under impact-like loading, with one thread or two, and with the
    element loop handed out in chunks of 256 (the default), 7 or in one share per
    thread (0)."""
    import numba

    from wovenimpact.solver import explicit

    from tests.conftest import reference_fabric
    from wovenimpact.jit import set_threads
    from wovenimpact.model.mesh import plate_mesh

    mesh = plate_mesh(0.01, 0.94e-3, quarter=True)
    bc = BoundaryConditions(mesh.n_nodes).fix(mesh.node_sets["edge_outer"])
    bc.symmetry(mesh.node_sets["symmetry_x"], 0).symmetry(mesh.node_sets["symmetry_y"], 1)
    sec = Section(reference_fabric(), bending_modulus=1e9, transverse_shear_modulus=3.28e9)
    model = build_model(mesh.nodes, mesh.quads, {"f": sec}, np.zeros(mesh.n_elems, int), bcs=bc)
    v0 = np.zeros((mesh.n_nodes, 3))
    v0[np.linalg.norm(mesh.nodes[:, :2], axis=1) < 2e-3, 2] = -100.0
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("NUMBA_NUM_THREADS < 2 here: a second thread count to compare with does "
                    "not exist (run with NUMBA_NUM_THREADS=2 to check determinism)")
    results = []
    before = numba.get_num_threads()
    try:
        for threads, chunk in ((1, 256), (2, 256), (2, 7), (2, 0)):
            set_threads(threads)
            assert numba.get_num_threads() == threads
            explicit.ELEMENT_CHUNK = chunk
            st = initial_state(model, velocity=v0)
            ws = Workspace.for_model(model, st)
            for _ in range(30):
                step(model, st, ws)
            results.append(st)
    finally:
        set_threads(before)
        explicit.ELEMENT_CHUNK = 256
    assert model.n_elems > 2 * 7  # chunks of 7 split the loop
    assert len(results) == 4 and all(r.equals(results[0]) for r in results[1:])
    assert results[0].mat[:, FL.S_TENSION].max() > 0.0  # yarn tensions were exercised


def test_the_element_stage_writes_every_output_it_is_handed():
    """Every element's blocks, status, eroded flag and alive byte, and its end-of-step
    state row, are written by the parallel loop (the outputs reach it in bundles: a
    Numba prange body can lose writes made through a named tuple, theory §4.6)."""
    nodes, quads, _ = distorted_square()
    model = build_model(nodes, quads, {"s": Section(elastic(), thickness=1e-3)},
                        np.zeros(len(quads), int))
    st = initial_state(model)
    st.x = st.x * 1.01  # a uniform stretch: every element carries a force
    ws = Workspace.for_model(model, st)
    ws.blocks[:] = np.nan
    ws.status[:] = 7
    ws.eroded_now[:] = 7
    ws.alive[:] = 7
    ws.elem[:] = np.nan
    element_forces(model, st, ws)
    assert np.isfinite(ws.blocks).all() and np.abs(ws.blocks).max() > 0.0
    assert (ws.status == 0).all() and (ws.eroded_now == 0).all() and (ws.alive == 1).all()
    # every column written (no NaN left); the kinematic bound is ∞ under the isotropic step
    assert not np.isnan(ws.elem).any() and (ws.elem[:, SL.E_ALIVE] == 1.0).all()
    assert np.isfinite(np.delete(ws.elem, SL.E_DT_KIN, axis=1)).all()
    assert np.isinf(ws.elem[:, SL.E_DT_KIN]).all()


def test_the_node_pass_writes_every_output_it_is_handed():
    """The node pass (``gather_and_update``, its arrays in bundles like the element
    stage's) writes every node's internal force, external force, work, kinetic energy and
    velocity: outputs filled with NaN come back finite, and a free node at rest moves off
    with v = Δt^n (−f_int)/m."""
    from wovenimpact.kernels.bundles import Motion, NodeForces, NodeModel
    from wovenimpact.kernels.gather import gather_nodal_forces
    from wovenimpact.kernels.integrate import gather_and_update

    nodes, quads, _ = distorted_square()
    model = build_model(nodes, quads, {"s": Section(elastic(), thickness=1e-3)},
                        np.zeros(len(quads), int))
    st = initial_state(model)
    st.x = st.x * 1.01
    ws = Workspace.for_model(model, st)
    element_forces(model, st, ws)
    expected = np.zeros_like(ws.f_int)
    gather_nodal_forces(model.node_ptr, model.node_elem, model.node_corner, ws.blocks,
                        ws.alive, expected, np.zeros(model.n_nodes, dtype=np.int64))
    for a in (ws.f_int, ws.f_ext, ws.w_int, ws.w_ext, ws.ke, ws.ke_eroded):
        a[:] = np.nan
    dt = 1e-7
    n_bad = gather_and_update(
        ws.node_map, ws.results, ws.solid.gather,  # no hexahedra: nothing added
        NodeModel(mass=ws.node_mass, inertia=ws.node_inertia, bc_code=model.bc_code,
                  bc_velocity=model.bc_velocity, body_accel=model.body_accel),
        np.zeros((model.n_nodes, 3)), 1.0, dt, dt,
        NodeForces(f_int=ws.f_int, f_int_old=st.f_int, f_ext_old=st.f_ext, f_ext=ws.f_ext),
        Motion(x=st.x, v=st.v, omega=st.omega), st.node_active, ws.energies)
    assert n_bad == 0
    assert np.array_equal(ws.f_int, expected) and np.abs(expected[:, :3]).max() > 0.0
    for a in (ws.f_ext, ws.w_int, ws.w_ext, ws.ke, ws.ke_eroded):
        assert np.isfinite(a).all()
    np.testing.assert_allclose(st.v, -dt * expected[:, :3] / ws.node_mass[:, None],
                               rtol=1e-14, atol=0.0)


def test_body_force_accelerates_a_free_plate_uniformly_and_its_work_is_booked():
    """A free plate under a uniform body force a: every node has v = a t (exact for
    central differences), no stress, and the external work equals the kinetic energy."""
    nodes, quads = rect_grid(4, 3, 0.04, 0.03)
    g = np.array([0.0, 3.0, -9.81])
    model = build_model(nodes, quads, {"s": Section(elastic(), thickness=1e-3)},
                        np.zeros(len(quads), int), body_accel=g)
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    for _ in range(200):
        step(model, st, ws)
    t_half = st.t - 0.5 * st.dt
    eb = energy_balance(model, st)
    print(f"\nbody force: velocity error {np.max(np.abs(st.v - g * t_half)):.1e} m/s, "
          f"W_ext − KE = {eb['external_work_J'] - eb['kinetic_J']:.1e} J")
    # exact up to the round-off stresses of x = x0 + u (strains ~1e-15, forces ~1e-9 N)
    assert np.max(np.abs(st.v - g * t_half)) < 1e-6 * np.linalg.norm(g) * t_half
    assert np.max(np.abs(st.elem[:, SL.E_N:SL.E_N + 3])) < 1e-12 * 210e9 * 1e-3
    assert eb["external_work_J"] == pytest.approx(eb["kinetic_J"], rel=1e-9)


def test_eroded_element_gives_no_force_and_its_energy_is_booked():
    """Two separate fabric elements; the corners of the first are driven outwards
    (equibiaxial, 5 m/s after a smooth 10 µs ramp) until both yarn families break at
    T_u: it erodes, its four nodes are left without an element and leave the model;
    their kinetic energy moves to the eroded term and the balance
    KE + W_int + E_eroded,kin − W_ext = KE0 still holds. The second element, at rest,
    is untouched."""
    from tests.conftest import reference_fabric

    fab = reference_fabric()
    c = 2.0 * fab.warp.half_length
    square = np.array([[0, 0, 0], [c, 0, 0], [c, c, 0], [0, c, 0]], dtype=float)
    nodes = np.vstack([square, square + [3 * c, 0, 0]])
    bc = BoundaryConditions(len(nodes), ramp_time=10e-6)
    for i, (sx, sy) in enumerate([(-1, -1), (1, -1), (1, 1), (-1, 1)]):
        bc.prescribe([i], 0, 5.0 * sx).prescribe([i], 1, 5.0 * sy)
    model = build_model(nodes, [[0, 1, 2, 3], [4, 5, 6, 7]], {"f": Section(
        fab, bending_modulus=1e9, transverse_shear_modulus=3.28e9)}, [0, 0], bcs=bc)
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    peak = 0.0
    while st.elem[0, SL.E_ALIVE] == 1.0 and st.step < 20000:
        step(model, st, ws)
        peak = max(peak, float(np.max(st.mat[0, FL.S_TENSION:FL.S_TENSION + 2])))
    assert st.elem[0, SL.E_ALIVE] == 0.0, "the element never eroded"
    for _ in range(5):
        step(model, st, ws)
    eb = energy_balance(model, st)
    print(f"\nerosion at t = {st.t * 1e6:.2f} µs after a peak tension {peak:.1f} N; eroded "
          f"kinetic {eb['eroded_kinetic_J']:.3e} J, external work {eb['external_work_J']:.3e} J, "
          f"balance error {eb['error_fraction']:.1e}")
    # the last intact step is within one load increment (~20 N here) below T_u
    assert 0.9 * fab.warp.ultimate_tension < peak < fab.warp.ultimate_tension
    assert np.all(st.node_active[:4] == 0) and np.all(st.v[:4] == 0.0)
    assert np.all(st.f_int[:4] == 0.0)
    assert np.all(st.node_active[4:] == 1) and st.elem[1, SL.E_ALIVE] == 1.0
    assert eb["eroded_kinetic_J"] > 0.0
    assert eb["error_fraction"] < 1e-3


def test_a_crushed_element_stops_the_run_with_a_message_naming_it():
    """A node driven into its neighbours at 1 km/s (distortion erosion off) crushes an
    element: the run stops (step collapse or inversion) with a SimulationError naming
    the element, its nodes and the time."""
    from wovenimpact.errors import SimulationError

    nodes, quads = rect_grid(3, 3, 0.03, 0.03)
    model = build_model(nodes, quads, {"s": Section(elastic(), thickness=1e-3)},
                        np.zeros(len(quads), int), erode_dt_fraction=0.0)
    v0 = np.zeros((len(nodes), 3))
    v0[5, 0] = 1000.0  # an interior node, towards its neighbour at +x
    st = initial_state(model, velocity=v0)
    ws = Workspace.for_model(model, st)
    with pytest.raises(SimulationError) as err:
        for _ in range(10000):
            step(model, st, ws)
    text = str(err.value)
    print(f"\n{text}")
    assert "element" in text and "t = " in text and "nodes" in text


def test_integrated_elastic_section_bends_like_the_resultant_section():
    """Five Simpson points through the thickness of an elastic section give M = D κ
    exactly for a linear material: the cantilever frequency agrees with the resultant
    section (to 0.1 %) and with beam theory (3 %)."""
    length, t = 0.1, 5e-3
    freqs = []
    for points in (1, 5):
        nodes, quads = rect_grid(10, 2, length, 0.01)
        bc = BoundaryConditions(len(nodes)).fix(np.flatnonzero(nodes[:, 0] == 0.0))
        mat = elastic(poisson=0.0)
        model = build_model(nodes, quads, {"s": Section(mat, thickness=t, points=points)},
                            np.zeros(len(quads), int), bcs=bc)
        f_fe, st = measured_frequency(model, nodes, length, 6e-3)
        freqs.append(f_fe)
        eb = energy_balance(model, st)
        assert eb["error_fraction"] < 1e-3
    f_beam = beam_frequency(mat, t, length)
    print(f"\nintegrated section (5 points): f1 = {freqs[1]:.2f} Hz, resultant {freqs[0]:.2f} Hz, "
          f"beam theory {f_beam:.2f} Hz")
    assert freqs[1] == pytest.approx(freqs[0], rel=1e-3)
    assert freqs[1] == pytest.approx(f_beam, rel=0.03)


def test_integrated_fabric_section_pulled_in_plane_matches_the_resultant_section():
    """With no curvature every through-thickness point of an integrated fabric section
    sees the F of its in-plane point: a strip pulled along the warp gives the same
    tensions with 1 or 5 points (state blocks: 2×2 in-plane points × n through the
    thickness)."""
    from tests.conftest import reference_fabric

    fab = reference_fabric()
    cell = 2.0 * fab.warp.half_length
    curves = []
    for points in (1, 5):
        nodes, quads = rect_grid(2, 1, 2 * cell, cell)
        right = np.flatnonzero(np.isclose(nodes[:, 0], 2 * cell))
        bc = BoundaryConditions(len(nodes), ramp_time=10e-6)
        bc.fix(np.arange(len(nodes)), (2, 3, 4, 5)).fix(np.flatnonzero(nodes[:, 0] == 0.0), (0, 1))
        bc.prescribe(right, 0, 2.0)
        sec = Section(fab, bending_modulus=1e9, transverse_shear_modulus=3.28e9, points=points)
        model = build_model(nodes, quads, {"f": sec}, np.zeros(2, int), bcs=bc)
        st = initial_state(model)
        ws = Workspace.for_model(model, st)
        while st.t < 45e-6:
            step(model, st, ws)
        curves.append(st.mat[model.mat_row[:-1], FL.S_TENSION].copy())  # first points
        if points == 5:
            per_point = st.mat[:, FL.S_TENSION].reshape(len(quads), 4, 5)
            assert np.allclose(per_point, per_point[:, :, :1], rtol=1e-9)
    print(f"\nintegrated fabric section: T_w {curves[1]} N vs resultant {curves[0]} N")
    assert curves[0].max() > 10.0
    assert np.allclose(curves[1], curves[0], rtol=1e-9)


def warped_loop_work(reverse: bool, n: int = 1500) -> tuple[float, float, float]:
    """One 5 mm fabric element driven quasi-statically round a closed loop that changes
    its in-plane crush and its warp together (corner 3 lifted by 0.2 L while the element
    is crushed to 0.6 in both directions): (work of its corner forces, energy it books at
    the end, largest |work| on the way)."""
    from tests.conftest import reference_fabric
    from wovenimpact.solver.explicit import shell_forces

    size = 5e-3
    x0 = np.array([[0, 0, 0], [size, 0, 0], [size, size, 0], [0, size, 0]], float)
    crushed = x0.copy()
    crushed[:, :2] = 0.2 * size + 0.6 * x0[:, :2]
    lifted = crushed.copy()
    lifted[2, 2] += 0.2 * size
    warped = x0.copy()
    warped[2, 2] += 0.2 * size
    corners = [x0, crushed, lifted, warped, x0]
    if reverse:
        corners = corners[::-1]
    sec = Section(reference_fabric(), bending_modulus=1e9, transverse_shear_modulus=3.28e9)
    model = build_model(x0, np.array([[0, 1, 2, 3]]), {"f": sec}, np.zeros(1, int))
    st = initial_state(model)
    ws = Workspace.for_model(model, st)
    dt = 1e-8
    work = peak = 0.0
    f_old, x_old = None, x0
    path = [(1 - s) * a + s * b for a, b in zip(corners[:-1], corners[1:])
            for s in np.linspace(0.0, 1.0, n, endpoint=False)] + [x0]
    for x in path:
        st.v[:] = (x - x_old) / dt
        st.x[:] = x
        shell_forces(model, st, ws)
        f = ws.blocks[0, :, :3].copy()
        if f_old is not None:
            work += 0.5 * float(np.sum((f_old + f) * (x - x_old)))
        peak = max(peak, abs(work))
        st.elem, ws.elem = ws.elem, st.elem
        st.mat, ws.mat = ws.mat, st.mat
        f_old, x_old = f, x.copy()
    booked = float(st.elem[0, SL.E_U_MEMB] + st.elem[0, SL.E_U_BEND] + st.elem[0, SL.E_U_HG])
    return work, booked, peak


def test_a_warped_element_round_a_closed_loop_returns_its_work():
    """The membrane's corner forces are the gradient of its energy also on a warped
    element (the normal forces of ``warp_forces``): round a closed loop of crush and
    warp, in either direction, the work of the corner forces returns to the energy
    booked at the end (zero) but for the path quadrature's error, which falls at second
    order as the increments halve (measured 5.3e-5 → 1.4e-5 → 4.2e-6 of the largest work
    for 750, 1500, 3000 increments per leg). Without the normal forces the loop gave
    ±1.1 % of it whatever the increments, with the sign of the loop's direction: a
    warped, crushed element gave its nodes energy it never had (theory §8.4)."""
    for reverse in (False, True):
        coarse, _, _ = warped_loop_work(reverse, 750)
        work, booked, peak = warped_loop_work(reverse, 1500)
        print(f"\nwarped loop {'backward' if reverse else 'forward'}: work {work:+.3e} J "
              f"(750 increments: {coarse:+.3e}), booked {booked:+.3e} J, largest work "
              f"{peak:.3e} J")
        assert peak > 1e-3  # the loop loads the element
        assert abs(work - booked) < 3e-5 * peak
        assert abs(coarse - booked) > 3.0 * abs(work - booked)  # second order


def test_rotary_inertia_raises_only_thick_metal_elements_of_a_mixed_model():
    """``model.rotary_inertia`` on a hybrid stack (two Kevlar plies under 0.5 mm of
    aluminium on 0.5 mm elements, the mixed-contact test's model): the aluminium, as
    thick as its elements are wide, gets more than ¼ m max(t²/12, A0/8); the fabric keeps
    exactly that (its parameter row is not E, ν, and is not read: no warning either)."""
    import warnings

    from tests.verification.test_mixed_contact import hybrid_model

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model, mesh = hybrid_model()
    sec = model.sections[model.elem_section]
    m_el = sec[:, SL.C_AREAL_MASS] * model.area0
    plain = 0.25 * m_el * np.maximum(sec[:, SL.C_THICK] ** 2 / 12.0, model.area0 / 8.0)
    fabric, metal = mesh.ply < 2, mesh.ply == 2
    np.testing.assert_array_equal(model.elem_rot_inertia[fabric], plain[fabric])
    assert np.all(model.elem_rot_inertia[metal] > plain[metal])
    # and the nodes carry the sum of their elements' corner inertias
    summed = np.zeros(model.n_nodes)
    for c in range(4):
        np.add.at(summed, model.quads[:, c], model.elem_rot_inertia)
    np.testing.assert_allclose(model.node_inertia, summed, rtol=1e-14)
