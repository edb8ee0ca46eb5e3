"""Central-difference update of the nodes (thesis eq. 4.4–4.7; docs/theory.md §3).

v^{n+1/2} = v^{n−1/2} + Δt^n M⁻¹ (f_ext^n − f_int^n), Δt^n = ½(Δt^{n−1/2} + Δt^{n+1/2}),
x^{n+1} = x^n + Δt^{n+1/2} v^{n+1/2}, with the lumped translational mass and an
isotropic lumped rotary inertia for the spins. Constrained degrees of freedom
get their prescribed velocity (or, for a node turning rigidly about an axis, the chord
velocity that keeps it on its circle, ``rotation_step``); the force that imposes it is
the support reaction,
which enters the external work. Work is integrated by the trapezoid rule,
W += ½ (f^{n−1} + f^n) · (x^n − x^{n−1}), per node; the caller sums the per-node
terms (a deterministic reduction). The kinetic energy at t^n is the leapfrog form
½ v^{n−1/2} · M v^{n+1/2}: with trapezoidal work it makes the energy balance exact
for a linear system at constant Δt (the quantity central differences conserve);
½ M ((v^{n−1/2} + v^{n+1/2})/2)² misreads modes near the stability limit by up
to (ωΔt/2)².

``gather_and_update`` is the explicit step's one pass over the nodes: each node
gathers its internal force (``gather.node_force_sum``, then the corner forces of the
hexahedra it belongs to), then takes the update of ``update_node``; it also counts nodes left at a non-finite position, so the
caller checks one integer instead of scanning x.

A node that loses its last live element either leaves the model with its kinetic
energy (``ke_eroded``; v = ω = 0, ``node_active`` 0: the default) or, with
``NodeModel.keep_free`` (``run.eroded_nodes = "keep"``, LS-DYNA's ENMASS = 2), flies on
as a free node: the same update with f_int = 0 (no element is left to gather), so it
keeps its mass, momentum and spin (no moment acts on it: ω stays constant), takes its
body load, constraints and contact forces, and its kinetic energy stays in ``ke``. A
node without mass (in no element from the start) leaves the model either way.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from wovenimpact.jit import inline_kernel, kernel, loop_kernel
from wovenimpact.kernels.gather import node_force_sum

# boundary-condition codes per degree of freedom (Model.bc_code; model.model uses these)
FREE = 0
FIXED = 1
PRESCRIBED = 2
ROTATING = 3  # the node turns rigidly: bc_velocity holds ω (0–2, rad/s) and the centre (3–5)


@kernel
def rotation_step(bc_velocity, n, x, amplitude, dt_new):
    """The chord velocity (x^{n+1} − x^n)/Δt of a node turning rigidly by θ = A |ω| Δt
    about the axis ω/|ω| through c (Rodrigues), so that it stays on its circle:
    x^{n+1} = c + R(θ)(x^n − c). Returns (v_x, v_y, v_z, ω_x, ω_y, ω_z) with ω × A."""
    wx, wy, wz = bc_velocity[n, 0] * amplitude, bc_velocity[n, 1] * amplitude, (
        bc_velocity[n, 2] * amplitude)
    rate = math.sqrt(wx * wx + wy * wy + wz * wz)
    if rate == 0.0 or dt_new <= 0.0:
        return 0.0, 0.0, 0.0, wx, wy, wz
    kx, ky, kz = wx / rate, wy / rate, wz / rate
    px = x[n, 0] - bc_velocity[n, 3]
    py = x[n, 1] - bc_velocity[n, 4]
    pz = x[n, 2] - bc_velocity[n, 5]
    th = rate * dt_new
    c, s = math.cos(th), math.sin(th)
    kp = kx * px + ky * py + kz * pz
    qx = px * c + (ky * pz - kz * py) * s + kx * kp * (1.0 - c)
    qy = py * c + (kz * px - kx * pz) * s + ky * kp * (1.0 - c)
    qz = pz * c + (kx * py - ky * px) * s + kz * kp * (1.0 - c)
    return (qx - px) / dt_new, (qy - py) / dt_new, (qz - pz) / dt_new, wx, wy, wz


@kernel
def smooth_step(t, ramp_time):
    """Amplitude of thesis Fig. 8-3: ξ³(10 − 15ξ + 6ξ²), ξ = min(t/ramp, 1); 1 if ramp = 0."""
    if ramp_time <= 0.0:
        return 1.0
    xi = min(max(t / ramp_time, 0.0), 1.0)
    return xi * xi * xi * (10.0 - 15.0 * xi + 6.0 * xi * xi)


@kernel
def force_pair_power(f_old, f_new, v, dt, node_work):
    """Σ_a ½ (f_a^{n−1} + f_a^n) · v_a: the trapezoid-rule power of a nodal force over a
    step, times Δt its work (serial sum, deterministic); each node's share of the work,
    ½ (f_a^{n−1} + f_a^n) · v_a Δt, is added to ``node_work[a]`` (the contact work a
    node's part has received: theory §8.3). A kernel rather than ``np.vdot``: on arrays
    of more than 10 000 entries OpenBLAS hands vdot to its threads, which then spin
    between steps and take a core from the element loops (measured: 4 plies at 120 m/s,
    56.6 s → 32.9 s wall on 2 cores)."""
    s = 0.0
    for a in range(v.shape[0]):
        p = 0.0
        for j in range(3):
            t = (f_old[a, j] + f_new[a, j]) * v[a, j]
            s += t
            p += t
        node_work[a] += 0.5 * p * dt
    return 0.5 * s


# keeps its long signature: a stage inlined into ``gather_and_update``, its arguments that loop's
# locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@inline_kernel
def update_node(
    n, mass, inertia, bc_code, bc_velocity, body_accel, keep_free, f_con, amplitude, dt_old,
    dt_mid, dt_new, f_int, f_int_old, f_ext_old, live, x, v, omega, node_active, f_ext, w_int,
    w_ext, ke, ke_eroded,
):
    """Central-difference update of node n (in place: x, v, omega, node_active; written:
    f_ext[n], w_int[n], w_ext[n], ke[n], ke_eroded[n]). ``live``: its live elements
    (0 → the node has no element: it leaves the model now, or with ``keep_free`` and a
    mass it flies on as a free node, f_int = 0); dt_mid = ½(Δt^{n−1/2} + Δt^{n+1/2}).
    The arguments are those of :func:`gather_and_update`.
    """
    # the sums accumulate in locals (stored once: the arrays may alias as far as the
    # compiler knows, so += on them goes through memory); same order as ever
    if node_active[n] == 0:
        w_int[n] = 0.0
        w_ext[n] = 0.0
        ke[n] = 0.0
        ke_eroded[n] = 0.0
        for d in range(6):
            f_ext[n, d] = 0.0
        return
    m = mass[n]
    inert = inertia[n]
    # work over [x^{n−1}, x^n]: displacement Δt^{n−1/2} v^{n−1/2}
    wi = 0.0
    for d in range(6):
        vel = v[n, d] if d < 3 else omega[n, d - 3]
        du = dt_old * vel
        wi += 0.5 * (f_int_old[n, d] + f_int[n, d]) * du
    w_int[n] = wi
    we = 0.0
    if live == 0 and not (keep_free and m > 0.0):
        # the loads of the last step still did work over [x^{n−1}, x^n]
        for d in range(6):
            vel = v[n, d] if d < 3 else omega[n, d - 3]
            we += 0.5 * f_ext_old[n, d] * dt_old * vel
        w_ext[n] = we
        # the node has lost its last element: it leaves the model with its energy
        e = 0.0
        for d in range(3):
            e += 0.5 * m * v[n, d] * v[n, d] + 0.5 * inert * omega[n, d] * omega[n, d]
            v[n, d] = 0.0
            omega[n, d] = 0.0
        ke[n] = 0.0
        ke_eroded[n] = e
        node_active[n] = 0
        for d in range(6):
            f_ext[n, d] = 0.0
        return
    k = 0.0
    turning = bc_code[n, 0] == ROTATING
    if turning:
        r0, r1, r2, r3, r4, r5 = rotation_step(bc_velocity, n, x, amplitude, dt_new)
    else:
        r0 = r1 = r2 = r3 = r4 = r5 = 0.0
    for d in range(6):
        m_d = m if d < 3 else inert
        old = v[n, d] if d < 3 else omega[n, d - 3]
        load = m_d * body_accel[n, d] + f_con[n, d] if d < 3 else 0.0
        code = bc_code[n, d]
        if code == FIXED:
            new = 0.0
        elif code == PRESCRIBED:
            new = bc_velocity[n, d] * amplitude
        elif code == ROTATING:
            new = (r0 if d == 0 else r1 if d == 1 else r2 if d == 2 else r3 if d == 3
                   else r4 if d == 4 else r5)
        else:
            new = old + dt_mid * (load - f_int[n, d]) / m_d
        if code != 0 and dt_mid > 0.0:
            # reaction R with m (v_new − v_old)/Δt^n = load + R − f_int
            ext = m_d * (new - old) / dt_mid + f_int[n, d]
        else:
            ext = load
        f_ext[n, d] = ext
        we += 0.5 * (f_ext_old[n, d] + ext) * dt_old * old
        k += 0.5 * m_d * old * new
        if d < 3:
            v[n, d] = new
            x[n, d] += dt_new * new
        else:
            omega[n, d - 3] = new
    w_ext[n] = we
    ke[n] = k
    ke_eroded[n] = 0.0


@loop_kernel
def gather_and_update(node_map, elements, solids, nodes, f_con, amplitude, dt_old, dt_new,
                      forces, motion, node_active, energies):
    """Gather the internal forces of every node and advance it by one step.

    Args:
        node_map: ``bundles.NodeMap`` (Model).
        elements: ``bundles.ElementResults`` of the element stage: its ``blocks``
            (n_elems, 4, 6) corner forces and moments at x^n and ``alive`` bytes are read.
        solids: ``bundles.HexGather``: the hexahedra's corner forces at x^n, added after
            the shells' in the map's order (each corner counts as a live element; a node
            of shells only has no entry, so its sum is the shells' bitwise).
        nodes: ``bundles.NodeModel``: masses, rotary inertias, constraints, body loads,
            and what becomes of a node that loses its last element (``keep_free``).
        f_con: (n, 3) contact forces at x^n (external loads of the shells).
        amplitude: prescribed-velocity amplitude at t^{n+1/2}.
        dt_old, dt_new: Δt^{n−1/2}, Δt^{n+1/2}.
        forces: ``bundles.NodeForces``: f_int written (gathered from the blocks),
            f_int_old and f_ext_old at x^{n−1} read, f_ext written (body forces plus
            reactions at x^n).
        motion: ``bundles.Motion``: x, v, omega advanced in place.
        node_active: (n,) advanced in place (0 once a node has left the model: it lost
            its last element, and ``nodes.keep_free`` is off or it has no mass).
        energies: ``bundles.NodeEnergies``, written: per-node internal and external work
            increments over [x^{n−1}, x^n], kinetic energy at t^n (½ m v^{n−1/2} ·
            v^{n+1/2}, see the module docstring; free nodes included), and kinetic
            energy removed with nodes that left the model this step.

    Returns:
        the number of nodes whose position x^{n+1} is not finite (0 when all is well).
    """
    # one bundle member per statement, read before the parallel loop (a prange body that
    # writes through a bundle can lose its writes: theory §4.6)
    node_ptr = node_map.node_ptr
    node_elem = node_map.node_elem
    node_corner = node_map.node_corner
    blocks = elements.blocks
    alive = elements.alive
    h_ptr = solids.node_ptr
    h_elem = solids.node_elem
    h_corner = solids.node_corner
    h_blocks = solids.blocks
    mass = nodes.mass
    inertia = nodes.inertia
    bc_code = nodes.bc_code
    bc_velocity = nodes.bc_velocity
    body_accel = nodes.body_accel
    keep_free = nodes.keep_free
    f_int = forces.f_int
    f_int_old = forces.f_int_old
    f_ext_old = forces.f_ext_old
    f_ext = forces.f_ext
    x = motion.x
    v = motion.v
    omega = motion.omega
    w_int = energies.w_int
    w_ext = energies.w_ext
    ke = energies.ke
    ke_eroded = energies.ke_eroded
    nn = x.shape[0]
    dt_mid = 0.5 * (dt_old + dt_new)
    n_bad = 0
    for i in prange(nn):
        n = np.uint64(i)
        f0, f1, f2, f3, f4, f5, live = node_force_sum(
            n, node_ptr, node_elem, node_corner, blocks, alive
        )
        for k in range(h_ptr[n], h_ptr[n + 1]):
            e = np.uint64(h_elem[k])
            c = np.uint64(h_corner[k])
            f0 += h_blocks[e, c, 0]
            f1 += h_blocks[e, c, 1]
            f2 += h_blocks[e, c, 2]
            live += 1
        f_int[n, 0] = f0
        f_int[n, 1] = f1
        f_int[n, 2] = f2
        f_int[n, 3] = f3
        f_int[n, 4] = f4
        f_int[n, 5] = f5
        update_node(
            n, mass, inertia, bc_code, bc_velocity, body_accel, keep_free, f_con, amplitude,
            dt_old, dt_mid, dt_new, f_int, f_int_old, f_ext_old, live, x, v, omega, node_active,
            f_ext, w_int, w_ext, ke, ke_eroded,
        )
        if not (math.isfinite(x[n, 0]) and math.isfinite(x[n, 1]) and math.isfinite(x[n, 2])):
            n_bad += 1
    return n_bad
