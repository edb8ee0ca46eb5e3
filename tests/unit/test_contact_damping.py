"""The shell–shell contact dashpot's two laws and the energy books per interface
(docs/theory.md §6, "Contact damping between shells" and "Contact energy per interface").

The pair law is isolated on one small quad (ply 1) over a big one (ply 0) whose nodes
are held (or driven) and weigh 10⁶ times the small quad's, so that the pair's reduced
mass is the node's own (m_red = m (1 − 10⁻⁶)) and each of the small quad's four nodes
is a one-degree-of-freedom oscillator of mass m, spring k = β m/Δt² and dashpot
c = 2 ζ √(k m), stepped by central differences as the solver steps it (force at x^n
from v^{n−1/2}).
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest

from wovenimpact.solver.shell_contact import ShellContact
from wovenimpact.errors import InputError
from wovenimpact.kernels.contact_energy import DAMPING, FRICTION, N_KINDS, SPRING
from wovenimpact.materials.metal import MetalParameters
from wovenimpact.model import Section, build_model

STEEL = MetalParameters(name="steel", kind="elastic", density=7850.0, modulus=210e9, poisson=0.3)
T = 0.2e-3  # both shells' thickness: contact at a mid-plane distance T
DT = 1e-7
SMALL = [4, 5, 6, 7]  # the small quad's nodes
BIG = [0, 1, 2, 3]


def pair_model():
    """The two quads (a 2 mm one at z = 0, ply 0; a 1 mm one centred over it, ply 1) as
    the attributes ShellContact reads, the big quad's nodes 10⁶ times heavier."""
    nodes = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0],
                      [0.5, 0.5, 1], [1.5, 0.5, 1], [1.5, 1.5, 1], [0.5, 1.5, 1]],
                     dtype=float) * 1e-3
    model = build_model(nodes, np.array([[0, 1, 2, 3], [4, 5, 6, 7]]),
                        {"s": Section(STEEL, thickness=T)}, [0, 0], ply=[0, 1])
    mass = model.node_mass.copy()
    mass[BIG] *= 1e6
    keys = ("quads", "ply", "node_ptr", "node_elem", "sections", "elem_section", "x0")
    return SimpleNamespace(**{k: getattr(model, k) for k in keys}, node_mass=mass)


def restitution_exact(zeta: float, mode: str) -> float:
    """Coefficient of restitution of a linear spring–dashpot struck at v₀ (no gravity):
    "always", the dashpot over the whole contact, which ends when the overlap does:
    e = exp(−π ζ/√(1 − ζ²)); "approach", the dashpot during the compression only (to the
    deepest point, ω_d t* = arccos ζ, x_max = (v₀/ω) exp(−ζ arccos ζ/√(1 − ζ²))), then the
    spring alone gives back ½ k x_max²: e = ω x_max/v₀ = exp(−ζ arccos ζ/√(1 − ζ²))."""
    root = math.sqrt(1.0 - zeta * zeta)
    if mode == "always":
        return math.exp(-math.pi * zeta / root)
    return math.exp(-zeta * math.acos(zeta) / root)


def bounce(zeta: float, mode: str, beta: float, speed: float = 1.0) -> float:
    """The small quad dropped at ``speed`` on the held big one: its rebound speed over
    ``speed``. The first contact starts 0.37 of a step's travel after a step (an
    arbitrary phase: the onset of a penalty contact is discrete)."""
    model = pair_model()
    contact = ShellContact(model, beta=beta, damping=zeta, damping_mode=mode,
                           remove_initial_overlap=False)
    x = model.x0.copy()
    x[SMALL, 2] = T + 0.37 * speed * DT
    v = np.zeros_like(x)
    v[SMALL, 2] = -speed
    m = model.node_mass[SMALL, None]
    f = np.zeros_like(x)
    alive, active = np.ones(2), np.ones(8, dtype=np.int8)
    touched = False
    for _ in range(20000):
        _, n_active = contact.forces(x, v, DT, alive, active, f)
        v[SMALL] += DT * f[SMALL] / m
        x[SMALL] += DT * v[SMALL]
        touched |= n_active > 0
        if touched and n_active == 0 and np.all(v[SMALL, 2] > 0.0):
            break
    assert touched and n_active == 0
    assert np.ptp(v[SMALL, 2]) <= 1e-12 * speed  # the four nodes alike: a 1-DOF bounce
    return float(v[SMALL[0], 2] / speed)


@pytest.mark.parametrize("mode", ["always", "approach"])
@pytest.mark.parametrize("zeta", [0.1, 0.3, 0.6])
def test_a_single_bounce_has_the_restitution_of_the_linear_spring_dashpot(zeta, mode):
    """The rebound over the impact speed is the analytic restitution of the law
    (:func:`restitution_exact`: for ζ = 0.1 / 0.3 / 0.6, "always" 0.729 / 0.372 / 0.095,
    "approach" 0.861 / 0.672 / 0.494) within 2 %: the explicit dashpot lags half a step,
    an error of order ζ ω Δt = ζ √β that grows as e falls (β = 10⁻⁴ here, ω Δt = 0.01:
    the scalar leapfrog of this law is within 0.9 % of the exact e at this start, within
    2.1 % whatever the phase of the onset; at β = 10⁻³ it is 4.8 % off at ζ = 0.6, and
    with the default β = 0.1 7.6 % (always) and 2.7 % (approach) at ζ = 0.3 — an error
    of the time discretisation, not of the law)."""
    e = bounce(zeta, mode, beta=1e-4)
    exact = restitution_exact(zeta, mode)
    print(f"\nζ = {zeta}, {mode}: e = {e:.4f}, exact {exact:.4f} ({e / exact - 1:+.2%})")
    assert e == pytest.approx(exact, rel=0.02)


def test_the_approach_law_does_not_damp_the_rebound():
    """Undamped (ζ = 0) both laws bounce elastically; with ζ > 0 the approach law gives
    back the spring's energy in full, so it rebounds faster than the law that also damps
    the separation — a check of which half each law damps, independent of β."""
    assert bounce(0.0, "always", 1e-3) == pytest.approx(1.0, abs=2e-3)
    assert bounce(0.0, "approach", 1e-3) == pytest.approx(1.0, abs=2e-3)
    assert bounce(0.3, "approach", 1e-3) > 1.5 * bounce(0.3, "always", 1e-3)


def driven_contact(mode: str, zeta=0.3, beta=0.01, ratio=0.1, cycles=16):
    """The small quad pressed onto the big one by a steady force F (static overlap
    δ = F/k) while the big one moves harmonically along the normal, z_s = a sin Ω t,
    Ω = ``ratio`` ω, the contact never opening (δ = 10 m a Ω²/k, the relative amplitude's
    tenfold). Books both halves of every step's forces as the solver does
    (ShellContact.book after the update: ½ Δt against v^{n−1/2}, ½ Δt against
    v^{n+1/2}). Returns the
    energy the dashpots took over the last half of the cycles (J, from the books), that
    of the analytic steady state over as many cycles, and the books' spring + damping +
    friction, the direct sum of the trapezoid work of the pair forces and the contact's
    forces over the whole run."""
    model = pair_model()
    contact = ShellContact(model, beta=beta, damping=zeta, damping_mode=mode,
                           remove_initial_overlap=False)
    m = float(model.node_mass[SMALL[0]])
    k = beta * m / DT**2
    omega = math.sqrt(k / m)
    big_omega = ratio * omega
    a = 1e-6
    force = 10.0 * m * a * big_omega**2  # on each small node, towards the big quad
    delta = force / k
    period = 2.0 * math.pi / big_omega
    steps = int(round(cycles * period / DT))
    x = model.x0.copy()
    x[BIG, 2] = 0.0
    x[SMALL, 2] = T - delta
    v = np.zeros_like(x)

    def z_big(n):
        return a * math.sin(big_omega * n * DT)

    v[BIG, 2] = (z_big(0) - z_big(-1)) / DT  # v^{−1/2}
    v[SMALL, 2] = v[BIG[0], 2]
    node_part = np.array([0, 0, 0, 0, 1, 1, 1, 1])
    seg_part = np.array([0, 1])
    books = np.zeros((N_KINDS, 2, 2))
    f = np.zeros_like(x)
    f_old = np.zeros_like(x)
    alive, active = np.ones(2), np.ones(8, dtype=np.int8)
    work = 0.0  # the solver's trapezoid: ½ Δt (f^{n−1} + f^n) · v^{n−1/2}
    half = None
    for n in range(steps):
        if n == steps // 2:
            half = books.copy()
        contact.forces(x, v, DT, alive, active, f)
        work += 0.5 * DT * float(np.sum((f_old + f) * v))
        v[SMALL] += DT * (f[SMALL] - [0.0, 0.0, force]) / m
        v[BIG, 2] = (z_big(n + 1) - z_big(n)) / DT
        x += DT * v
        # f^n against v^{n−1/2} (the powers the narrow phase wrote) and v^{n+1/2}
        contact.book(v, 0.5 * DT, books, 0.5 * DT, books, node_part, seg_part)
        f_old[:] = f
        assert np.all(x[SMALL, 2] - x[BIG[0], 2] < T)  # never apart
    work += 0.5 * DT * float(np.sum(f_old * v))  # the last forces' second half
    dissipated = float(books[DAMPING].sum() - half[DAMPING].sum())
    # steady state of the relative coordinate u: m ü + c u̇ + k u = −m z̈_s (per node)
    c = 2.0 * zeta * math.sqrt(k * m)
    amp = m * a * big_omega**2 / math.hypot(k - m * big_omega**2, c * big_omega)
    per_cycle = math.pi * c * big_omega * amp**2 * len(SMALL)
    return dissipated, per_cycle * (cycles - cycles // 2), float(books.sum()), -work


def test_steady_pressed_contact_dissipates_half_as_much_with_the_approach_law():
    """Two surfaces pressed together that vibrate against each other without parting:
    the "always" dashpot takes the analytic π c Ω u² per cycle (within 3 %, u the
    steady-state relative amplitude of the linear oscillator), the approach-only one
    works on the closing half of each cycle only — for a harmonic relative motion,
    exactly half of it. So "approach" dissipates less than X = 55 % of "always" here
    (50 % by the argument, ±5 % for the discrete steps and the amplitude the weaker
    damping lets grow), and more than 45 %: it halves, it does not remove, the work of
    the dashpot on a sustained contact that vibrates (a contact at rest takes none under
    either law). The books close: spring + damping + friction = −(trapezoid work of the
    pair forces) to round-off."""
    always, exact, booked, minus_work = driven_contact("always")
    approach, _, booked_a, minus_work_a = driven_contact("approach")
    print(f"\ndashpot energy over 8 cycles: always {always:.4e} J (analytic {exact:.4e}), "
          f"approach {approach:.4e} J, ratio {approach / always:.4f}")
    assert always == pytest.approx(exact, rel=0.03)
    assert 0.45 < approach / always < 0.55
    for b, w in ((booked, minus_work), (booked_a, minus_work_a)):
        assert b == pytest.approx(w, rel=1e-9, abs=1e-12 * abs(always))


@pytest.mark.parametrize("mode", ["always", "approach"])
def test_friction_books_the_kinetic_energy_of_a_quad_sliding_to_rest(mode):
    """The small quad pressed onto the held big one by F and sliding at v₀ along it
    (friction μ = 0.3) stops after v₀²/(2 μ F/m) (within 1 %: the cap of the kinetic
    friction near sticking takes the last steps), and the friction book holds the kinetic
    energy it lost, ½ Σ m v₀², to 10⁻⁶ (the leapfrog's kinetic energy changes by exactly
    the trapezoid work booked; the pressed contact's normal motion is round-off)."""
    model = pair_model()
    beta, mu, v0 = 0.1, 0.3, 1.0
    contact = ShellContact(model, beta=beta, damping=0.3, friction=mu, damping_mode=mode,
                           remove_initial_overlap=False)
    m = float(model.node_mass[SMALL[0]])
    decel = v0 / (1000 * DT)  # stops in about 1000 steps
    force = m * decel / mu
    x = model.x0.copy()
    x[SMALL, 2] = T - force / (beta * m / DT**2)  # the static overlap
    v = np.zeros_like(x)
    v[SMALL, 0] = v0
    books = np.zeros((N_KINDS, 2, 2))
    parts = (np.array([0, 0, 0, 0, 1, 1, 1, 1]), np.array([0, 1]))
    f = np.zeros_like(x)
    alive, active = np.ones(2), np.ones(8, dtype=np.int8)
    for _ in range(3000):
        contact.forces(x, v, DT, alive, active, f)
        v[SMALL] += DT * (f[SMALL] - [0.0, 0.0, force]) / m
        x[SMALL] += DT * v[SMALL]
        contact.book(v, 0.5 * DT, books, 0.5 * DT, books, *parts)
    assert np.all(np.abs(v[SMALL, 0]) < 1e-6 * v0)
    slid = x[SMALL[0], 0] - model.x0[SMALL[0], 0]
    assert slid == pytest.approx(v0**2 / (2 * decel), rel=0.01)
    lost = 0.5 * len(SMALL) * m * v0**2
    assert books[FRICTION].sum() == pytest.approx(lost, rel=1e-6)
    assert books[FRICTION, 1, 0] == books[FRICTION].sum()  # nodes of ply 1 on ply 0
    assert abs(books[SPRING].sum()) + abs(books[DAMPING].sum()) < 1e-6 * lost


def test_the_serial_and_parallel_books_agree_bitwise(monkeypatch):
    """ShellContact.book recomputes the acting pairs' powers in one serial pass when they
    are few and in parallel (then a serial sum) when they are many: the same powers
    summed in the same order, so the books are bitwise equal, for any thread count
    (three plies pressed together under a dome and sliding, friction on)."""
    import wovenimpact.solver.shell_contact as contact_module
    from wovenimpact.model.mesh import plate_mesh

    mesh = plate_mesh(20e-3, 1e-3, plies=3, spacing=0.5e-3, quarter=True)
    model = build_model(mesh.nodes, mesh.quads, {"s": Section(STEEL, thickness=0.4998e-3)},
                        np.zeros(mesh.n_elems, int), ply=mesh.ply)
    r = np.linalg.norm(mesh.nodes[:, :2], axis=1) / 10e-3
    level = mesh.nodes[:, 2] / 0.5e-3
    x = model.x0.copy()
    x[:, 2] -= 0.1e-3 * np.clip(1.0 - r, 0.0, None) ** 2 * level
    v = np.zeros_like(x)
    v[:, 0], v[:, 2] = 5.0 * level / 2, -20.0 * level / 2
    contact = ShellContact(model, friction=0.2)
    f = np.zeros_like(x)
    contact.forces(x, v, DT, np.ones(model.n_elems), np.ones(model.n_nodes, np.int8), f)
    assert contact.n_active > 100
    v_after = v + DT * f / model.node_mass[:, None]
    node_part, elem_part = np.minimum(contact.node_ply, 2), model.ply
    out = []
    for limit in (10**9, 0):  # serial, then parallel
        monkeypatch.setattr(contact_module, "PARALLEL_BOOK_PAIRS", limit)
        books = np.zeros((N_KINDS, 3, 3))
        contact.book(v_after, 0.5 * DT, books, 0.5 * DT, books, node_part, elem_part)
        out.append(books)
    assert np.any(out[0] != 0.0) and np.any(out[0][FRICTION] != 0.0)
    assert out[0].tobytes() == out[1].tobytes()


def test_damping_mode_is_checked():
    with pytest.raises(InputError, match="damping_mode = 'sometimes'.*'always' or 'approach'"):
        ShellContact(pair_model(), damping_mode="sometimes")


def test_always_is_the_old_law_bitwise():
    """The default law gives the forces of the contact before the approach option (the
    dashpot over the whole overlap), bitwise: the approach law differs only on pairs
    that separate, and is identical on pairs that close."""
    model = pair_model()
    x = model.x0.copy()
    x[SMALL, 2] = 0.9 * T
    out = {}
    for mode in ("always", "approach"):
        for sign in (-1.0, 1.0):
            contact = ShellContact(model, beta=0.1, damping=0.3, damping_mode=mode,
                                   remove_initial_overlap=False)
            v = np.zeros_like(x)
            v[SMALL, 2] = sign * 3.0
            f = np.zeros_like(x)
            contact.forces(x, v, DT, np.ones(2), np.ones(8, dtype=np.int8), f)
            out[mode, sign] = f.copy()
    assert np.array_equal(out["always", -1.0], out["approach", -1.0])  # closing
    assert not np.array_equal(out["always", 1.0], out["approach", 1.0])  # separating
    m, m_s = model.node_mass[SMALL[0]], model.node_mass[BIG].mean()
    k = 0.1 * m / DT**2
    spring = k * 0.1 * T
    c = 2.0 * 0.3 * math.sqrt(k * m * m_s / (m + m_s))
    assert out["approach", 1.0][SMALL, 2] == pytest.approx(spring, rel=1e-12)
    assert out["always", 1.0][SMALL, 2] == pytest.approx(spring - c * 3.0, rel=1e-9)
