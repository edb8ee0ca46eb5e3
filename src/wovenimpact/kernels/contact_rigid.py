"""Penalty contact of shell nodes against a rigid body of revolution (MODEL.md §4).

The body is its meridian profile (a polyline (ζ_i, ρ_i) from the tip on the axis to
the tail on the axis, ζ along the unit axis a from the tip at c). A node at p has
axial coordinate ζ = (p − c)·a and radius ρ = |p − c − ζ a|; its signed distance to
the body is the 2-D distance from (ζ, ρ) to the profile, negative inside. With the
shell half-thickness h as offset, the node is in contact when d < h and receives the
penalty force f = k (h − d) n along the outward surface normal n (frictionless).
``profile_distance`` is one point; ``rigid_contact_forces`` loops over the nodes
(each writes its own row; the body's resultant is summed by the caller).
"""

from __future__ import annotations

import math

from numba import prange

from wovenimpact.jit import kernel, loop_kernel


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


@loop_kernel
def rigid_contact_forces(
    x, node_active, offset, stiffness, tip, axis, prof_z, prof_r, reach, force, energy
):
    """Penalty forces on the nodes from a rigid body of revolution.

    Args:
        x: (n, 3) node positions; node_active: (n,) 0 for eroded nodes.
        offset: (n,) contact offset of each node (shell half-thickness, m).
        stiffness: (n,) penalty stiffness of each node (N/m).
        tip, axis: (3,) nose-tip position and unit axis (tip → tail).
        prof_z, prof_r: meridian profile polyline.
        reach: bounding radius of the body about its tip plus the largest offset (m),
            nodes farther are skipped.
        force: (n, 3) written: contact force on each node (N).
        energy: (n,) written: penalty energy ½ k g² of each node (J).
    """
    n = x.shape[0]
    length = prof_z[prof_z.shape[0] - 1]
    for i in prange(n):
        force[i, 0] = 0.0
        force[i, 1] = 0.0
        force[i, 2] = 0.0
        energy[i] = 0.0
        if node_active[i] == 0:
            continue
        px, py, pz = x[i, 0] - tip[0], x[i, 1] - tip[1], x[i, 2] - tip[2]
        zeta = px * axis[0] + py * axis[1] + pz * axis[2]
        if zeta < -reach or zeta > length + reach:
            continue
        qx, qy, qz = px - zeta * axis[0], py - zeta * axis[1], pz - zeta * axis[2]
        rho = math.sqrt(qx * qx + qy * qy + qz * qz)
        if rho > reach:
            continue
        d, nz, nr = profile_distance(zeta, rho, prof_z, prof_r)
        gap = offset[i] - d
        if gap <= 0.0:
            continue
        if rho > 1e-15:
            ex, ey, ez = qx / rho, qy / rho, qz / rho
        else:  # on the axis: only the axial part of the normal is defined
            ex = ey = ez = 0.0
        f = stiffness[i] * gap
        force[i, 0] = f * (nz * axis[0] + nr * ex)
        force[i, 1] = f * (nz * axis[1] + nr * ey)
        force[i, 2] = f * (nz * axis[2] + nr * ez)
        energy[i] = 0.5 * stiffness[i] * gap * gap
