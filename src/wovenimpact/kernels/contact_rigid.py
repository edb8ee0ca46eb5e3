"""Penalty contact of shell nodes against a rigid body of revolution (docs/model.md §4).

The body is its meridian profile (a polyline (ζ_i, ρ_i) from the tip on the axis to
the tail on the axis, ζ along the unit axis a from the tip at c). A node at p has
axial coordinate ζ = (p − c)·a and radius ρ = |p − c − ζ a|; its signed distance to
the body is the 2-D distance from (ζ, ρ) to the profile, negative inside. With the
shell half-thickness h as offset, the node is in contact when d < h and receives the
penalty force f = k (h − d) n along the outward surface normal n, a dashpot on the
normal relative velocity and optional Coulomb friction (``rigid_contact_forces``).
``profile_distance`` is one point; ``rigid_contact_forces`` loops over the nodes
(each writes its own row; the body's resultant is summed by the caller).
"""

from __future__ import annotations

import math

from numba import prange

from wovenimpact.jit import kernel, loop_kernel
from wovenimpact.kernels.contact_law import pair_force


@kernel
def profile_distance(zeta, rho, prof_z, prof_r):
    """Signed distance from (ζ, ρ ≥ 0) to the closed meridian profile, and the outward
    unit normal (n_ζ, n_ρ) at the closest point. Inside: ρ below the profile segment
    that spans ζ (half-open in ζ, so flat faces at the tip and tail are handled)."""
    best = math.inf
    bz = 0.0
    br = 0.0
    seg_nz = 0.0
    seg_nr = 1.0
    inside = False
    n = prof_z.shape[0]
    for i in range(n - 1):
        z0, r0, z1, r1 = prof_z[i], prof_r[i], prof_z[i + 1], prof_r[i + 1]
        dz, dr = z1 - z0, r1 - r0
        ll = dz * dz + dr * dr
        t = 0.0 if ll == 0.0 else ((zeta - z0) * dz + (rho - r0) * dr) / ll
        t = min(max(t, 0.0), 1.0)
        cz, cr = z0 + t * dz, r0 + t * dr
        d2 = (zeta - cz) ** 2 + (rho - cr) ** 2
        if d2 < best:
            best = d2
            bz, br = cz, cr
            inv = 1.0 / math.sqrt(ll) if ll > 0.0 else 0.0
            seg_nz, seg_nr = -dr * inv, dz * inv  # outward: the profile runs tip → tail
        if z0 <= zeta < z1 and dz > 0.0:
            if rho < r0 + (zeta - z0) / dz * dr:
                inside = True
    d = math.sqrt(best)
    if d > 1e-15:
        nz, nr = (zeta - bz) / d, (rho - br) / d
        if inside:
            nz, nr = -nz, -nr
    else:
        nz, nr = seg_nz, seg_nr
    return (-d if inside else d), nz, nr


@kernel
def node_gap(x, i, offset, tip, axis, prof_z, prof_r, reach, length):
    """Gap g = h − d of node i against the body (≤ 0: no contact) and the body's outward
    unit normal (n_x, n_y, n_z) at the node's closest point."""
    px, py, pz = x[i, 0] - tip[0], x[i, 1] - tip[1], x[i, 2] - tip[2]
    zeta_ax = px * axis[0] + py * axis[1] + pz * axis[2]
    if zeta_ax < -reach or zeta_ax > length + reach:
        return 0.0, 0.0, 0.0, 0.0
    qx, qy, qz = px - zeta_ax * axis[0], py - zeta_ax * axis[1], pz - zeta_ax * axis[2]
    rho = math.sqrt(qx * qx + qy * qy + qz * qz)
    if rho > reach:
        return 0.0, 0.0, 0.0, 0.0
    d, nz, nr = profile_distance(zeta_ax, rho, prof_z, prof_r)
    gap = offset[i] - d
    if gap <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    if rho > 1e-15:
        ex, ey, ez = qx / rho, qy / rho, qz / rho
    else:  # on the axis: only the axial part of the normal is defined
        ex = ey = ez = 0.0
    return (gap, nz * axis[0] + nr * ex, nz * axis[1] + nr * ey, nz * axis[2] + nr * ez)


@loop_kernel
def rigid_contact_forces(nodes, body, dt, out):
    """Penalty, damping and friction forces on the nodes from a rigid body of revolution.

    For a node with gap g = h − d > 0 (h its offset, d its signed distance to the body),
    outward normal n and velocity relative to the body's surface point
    v_r = v − (V + ω × (p − c)), split into v_n = v_r·n and v_t = v_r − v_n n:

        k = β m / Δt²,  c = min(2 ζ √β, 1) m_r / Δt,   m_r = m / (1 + m_c / M)
                                (ζ: fraction of critical; the cap removes at most the
                                 whole relative normal velocity in one step, counting
                                 the body's recoil: m_c is the mass of all the nodes in
                                 contact, M the body's; m_r = m for a heavy body)
        f_n = k g − c v_n                  (along n; the dashpot also acts while the
                                            node recedes inside the gap: no rebound)
        f_t = −min(μ |f_n|, ½ m |v_t| / Δt) v_t/|v_t|   (Coulomb, capped near sticking)

    (theory §6.2). With ζ ≥ 1 a node struck by a face comes to rest on it (a plastic
    impact, the face's speed) instead of leaving at twice its speed. Two passes: the
    gaps (parallel), the contact mass m_c (a serial sum, deterministic), the forces.

    Args:
        nodes: the nodes (kernels.bundles.ContactNodes): positions x^n, velocities
            v^{n−1/2}, ``active`` (0 for nodes that take no contact, eroded), lumped
            masses (kg) and contact offsets h (m).
        body: the body (kernels.bundles.BodyContact): tip position and unit axis (tip →
            tail), velocity V, global spin ω and centre of mass c, meridian profile
            polyline, reach (bounding radius about the tip plus the largest offset, m:
            nodes farther are skipped), its mass in the model M (kg; its share in a
            symmetry model) and its law: penalty scale β, damping ζ, friction μ.
        dt: the step the forces are for (s).
        out: written (kernels.bundles.BodyContactOut):
            force: (n, 3) contact force on each node (N).
            energy: (n,) penalty energy ½ k g² of each node (J).
            parts: (n, 11) written for the nodes in contact: the normal forces of the
                spring k g and of the dashpot −c v_n (N), the normal n, the force f, and
                the powers of the spring, the dashpot and friction (W) with the node's
                velocity relative to the body's translation, v − V (what the energy
                books split the pair's work by, kernels.contact_energy; the friction
                power 0 if μ = 0).
            contact_list: (n,) int64, its first ``count`` entries written: the nodes in
                contact, in node order.

    Returns:
        count: the nodes in contact.
    """
    # the bundles' members as locals, one per statement, before the parallel loops
    x = nodes.x
    v = nodes.v
    node_active = nodes.active
    node_mass = nodes.mass
    offset = nodes.offset
    tip = body.tip
    axis = body.axis
    body_v = body.velocity
    body_w = body.spin
    body_c = body.centre
    prof_z = body.prof_z
    prof_r = body.prof_r
    reach = body.reach
    body_mass = body.mass
    beta = body.beta
    zeta = body.zeta
    mu = body.mu
    force = out.force
    energy = out.energy
    parts = out.parts
    contact_list = out.contact_list
    n = x.shape[0]
    length = prof_z[prof_z.shape[0] - 1]
    # pass 1: gaps (in energy[i]) and normals (in force[i])
    for i in prange(n):
        energy[i] = 0.0
        force[i, 0] = 0.0
        force[i, 1] = 0.0
        force[i, 2] = 0.0
        if node_active[i] == 0:
            continue
        g, nx, ny, nz = node_gap(x, i, offset, tip, axis, prof_z, prof_r, reach, length)
        if g > 0.0:
            energy[i] = g
            force[i, 0] = nx
            force[i, 1] = ny
            force[i, 2] = nz
    m_contact = 0.0
    count = 0
    for i in range(n):
        if energy[i] > 0.0:
            m_contact += node_mass[i]
            contact_list[count] = i
            count += 1
    c_factor = min(2.0 * zeta * math.sqrt(beta), 1.0) / (1.0 + m_contact / body_mass)
    # pass 2: forces
    for i in prange(n):
        gap = energy[i]
        if gap <= 0.0:
            continue
        nx, ny, nzz = force[i, 0], force[i, 1], force[i, 2]
        m = node_mass[i]
        k = beta * m / (dt * dt)
        c = c_factor * m / dt
        # velocity of the node relative to the body's material point at it
        ax_, ay_, az_ = x[i, 0] - body_c[0], x[i, 1] - body_c[1], x[i, 2] - body_c[2]
        vrx = v[i, 0] - (body_v[0] + body_w[1] * az_ - body_w[2] * ay_)
        vry = v[i, 1] - (body_v[1] + body_w[2] * ax_ - body_w[0] * az_)
        vrz = v[i, 2] - (body_v[2] + body_w[0] * ay_ - body_w[1] * ax_)
        fx, fy, fz = pair_force(k * gap, c, vrx, vry, vrz, nx, ny, nzz, mu, m, dt)
        force[i, 0] = fx
        force[i, 1] = fy
        force[i, 2] = fz
        energy[i] = 0.5 * k * gap * gap
        parts[i, 0] = k * gap
        parts[i, 1] = -(c * (vrx * nx + vry * ny + vrz * nzz))
        parts[i, 2] = nx
        parts[i, 3] = ny
        parts[i, 4] = nzz
        parts[i, 5] = fx
        parts[i, 6] = fy
        parts[i, 7] = fz
        # the powers with v − V (the solver books the body's work with its translation)
        tx, ty, tz = v[i, 0] - body_v[0], v[i, 1] - body_v[1], v[i, 2] - body_v[2]
        vn = tx * nx + ty * ny + tz * nzz
        parts[i, 8] = parts[i, 0] * vn
        parts[i, 9] = parts[i, 1] * vn
        parts[i, 10] = (fx * tx + fy * ty + fz * tz - (parts[i, 0] + parts[i, 1]) * vn
                        if mu > 0.0 else 0.0)
    return count


@kernel
def add_body_forces(x, centre, f_body, f_con):
    """f_con += f_body (the body's forces on the nodes), and the resultant force and
    torque about ``centre`` of the nodes' forces on the body, −Σ f_i and
    −Σ (x_i − c) × f_i: one serial pass in node order (deterministic), no temporaries."""
    fx = fy = fz = tx = ty = tz = 0.0
    for i in range(x.shape[0]):
        gx, gy, gz = f_body[i, 0], f_body[i, 1], f_body[i, 2]
        if gx == 0.0 and gy == 0.0 and gz == 0.0:
            continue
        f_con[i, 0] += gx
        f_con[i, 1] += gy
        f_con[i, 2] += gz
        ax, ay, az = x[i, 0] - centre[0], x[i, 1] - centre[1], x[i, 2] - centre[2]
        fx -= gx
        fy -= gy
        fz -= gz
        tx -= ay * gz - az * gy
        ty -= az * gx - ax * gz
        tz -= ax * gy - ay * gx
    return fx, fy, fz, tx, ty, tz
