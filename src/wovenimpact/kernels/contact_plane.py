"""Penalty contact of nodes against a rigid plane with a prescribed motion (a rigid
plate that presses or holds; docs/solid.md §6).

The plane passes through c with unit normal n toward the side where its nodes are. A
node p with contact offset h (a shell's half thickness; 0 on a solid) has the gap

    g = h − (p − c) · n,

in contact when g > 0, and takes the force of an impactor's face of infinite mass
(kernels.contact_rigid, theory §6.2) along n, with v_r = v − V its velocity relative
to the plane's V:

    k = β m / Δt²,  c = min(2 ζ √β, 1) m / Δt,
    f_n = k g − c v_n,   f_t = −min(μ |f_n|, ½ m |v_t| / Δt) v_t/|v_t|.

Each node writes its own rows (parallel); the list of the nodes in contact is a serial
pass in node order, the force on the plane a serial sum (``plane_resultant``):
deterministic for any thread count.
"""

from __future__ import annotations

import math

from numba import prange

from wovenimpact.jit import kernel, loop_kernel
from wovenimpact.kernels.contact_law import pair_force

# columns of a row of State.planes: position c of its point, velocity V^{n−1/2} of the
# last step, force F^n of the nodes on the plane
PL_X, PL_V, PL_F, N_PLANE_STATE = 0, 3, 6, 9


@loop_kernel
def plane_contact_forces(nodes, point, normal, velocity, meets, beta, zeta, mu, dt, out):
    """Penalty, dashpot and friction forces on the nodes from a rigid plane (module
    docstring).

    Args:
        nodes: kernels.bundles.ContactNodes: positions x^n, velocities v^{n−1/2},
            ``active``, lumped masses (kg) and contact offsets h (m).
        point, normal, velocity: (3,) the plane's point c^n, unit normal n, velocity V.
        meets: (n_nodes,) int8: the nodes the plane meets.
        beta, zeta, mu: penalty scale β, damping ζ (fraction of critical), friction μ.
        dt: the step the forces are for (s).
        out: kernels.bundles.BodyContactOut, written as by
            ``contact_rigid.rigid_contact_forces``: the force on each node, its penalty
            energy ½ k g², the parts (spring, dashpot, normal, force, powers with v − V)
            of the nodes in contact and their list.

    Returns:
        count: the nodes in contact.
    """
    x = nodes.x
    v = nodes.v
    node_active = nodes.active
    node_mass = nodes.mass
    offset = nodes.offset
    force = out.force
    energy = out.energy
    parts = out.parts
    contact_list = out.contact_list
    n = x.shape[0]
    nx, ny, nz = normal[0], normal[1], normal[2]
    c_factor = min(2.0 * zeta * math.sqrt(beta), 1.0)
    for i in prange(n):
        energy[i] = 0.0
        force[i, 0] = 0.0
        force[i, 1] = 0.0
        force[i, 2] = 0.0
        if node_active[i] == 0 or meets[i] == 0:
            continue
        gap = offset[i] - ((x[i, 0] - point[0]) * nx + (x[i, 1] - point[1]) * ny
                           + (x[i, 2] - point[2]) * nz)
        if not gap > 0.0:
            continue
        m = node_mass[i]
        k = beta * m / (dt * dt)
        c = c_factor * m / dt
        vrx = v[i, 0] - velocity[0]
        vry = v[i, 1] - velocity[1]
        vrz = v[i, 2] - velocity[2]
        fx, fy, fz = pair_force(k * gap, c, vrx, vry, vrz, nx, ny, nz, mu, m, dt)
        force[i, 0] = fx
        force[i, 1] = fy
        force[i, 2] = fz
        energy[i] = 0.5 * k * gap * gap
        vn = vrx * nx + vry * ny + vrz * nz
        parts[i, 0] = k * gap
        parts[i, 1] = -(c * vn)
        parts[i, 2] = nx
        parts[i, 3] = ny
        parts[i, 4] = nz
        parts[i, 5] = fx
        parts[i, 6] = fy
        parts[i, 7] = fz
        parts[i, 8] = parts[i, 0] * vn
        parts[i, 9] = parts[i, 1] * vn
        parts[i, 10] = (fx * vrx + fy * vry + fz * vrz - (parts[i, 0] + parts[i, 1]) * vn
                        if mu > 0.0 else 0.0)
    count = 0
    for i in range(n):
        if energy[i] > 0.0 or force[i, 0] != 0.0 or force[i, 1] != 0.0 or force[i, 2] != 0.0:
            contact_list[count] = i
            count += 1
    return count


@kernel
def plane_resultant(f_plane, contact_list, count, f_con):
    """f_con += the plane's forces on its nodes in contact; returns the force of those
    nodes on the plane, −Σ f_i (a serial sum in node order)."""
    fx = fy = fz = 0.0
    for j in range(count):
        i = contact_list[j]
        f_con[i, 0] += f_plane[i, 0]
        f_con[i, 1] += f_plane[i, 1]
        f_con[i, 2] += f_plane[i, 2]
        fx -= f_plane[i, 0]
        fy -= f_plane[i, 1]
        fz -= f_plane[i, 2]
    return fx, fy, fz
