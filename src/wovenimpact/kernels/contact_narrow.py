"""Narrow phase of the shell–shell contact: node-to-segment penalty (docs/model.md §4).

Input: the node-major candidate list of :mod:`contact_broad` (``pair_ptr``,
``pair_seg``). Every node of every ply is tested against the segments of the other
plies, so each ply is both master and slave (two-pass contact).

Projection (``closest_point_on_quad``): the closest point of the node p on the
bilinear segment x(ξ, η) = x̄ + ξ a + η b + ξη c, (ξ, η) ∈ [−1, 1]²,
a = ¼(−x1 + x2 + x3 − x4), b = ¼(−x1 − x2 + x3 + x4), c = ¼(x1 − x2 + x3 − x4).
Newton on ½|p − x(ξ, η)|² (Hessian [[x,ξ·x,ξ, x,ξ·x,η − r·c], [·, x,η·x,η]],
r = p − x; Gauss–Newton where it is not positive; exact in one step for a flat
parallelogram); if the
stationary point lies in the square it is the projection and the contact normal is
the surface normal n = x,ξ × x,η / |…| there, turned toward the node; otherwise the
closest point is on one of the four straight edges (exact segment projections) and
the normal is (p − x_c)/|p − x_c| — the shell edge is rounded, and the normal turns
continuously as a node slides off a segment.

Selection: per node, candidates are grouped by (ply of the segment, side of the node
with respect to the surface normal); only the closest candidate of a group is kept
(ties: the lower segment index). A node sliding across a segment boundary thus sees
one contact whose closest point moves continuously from one segment to the next.

Gap and penalty, for a kept pair of node p and segment s:

    g = d − (h_p + h_s − o_p),    d = |p − x_c|,
    k = β · min(m_p, m̄_s) / Δt²,  m̄_s = ¼ Σ_I m_I (mean nodal mass of s),
    c = min(2 ζ √(k m_red), ½ m_red/Δt),   m_red = m_p m̄_s / (m_p + m̄_s),
    f_n = (−k g − c v_n) n  on the node when g < 0,  energy ½ k g²,

h the half-thicknesses (shell offsets) and o_p the node's initial-overlap
allowance (``initial_overlap``; 0 if unused).

A solid's exterior face (``one_sided`` 1; docs/solid.md §6) has no offset and an inside:
n is its outward normal x,ξ × x,η (never turned), the gap is the signed distance
g = (p − x_c)·n − (h_p − o_p), and only a projection inside the face, no deeper than
the face's reach h_s behind it, makes a candidate. All the faces of one body form one
group whatever the node's side: the closest decides whether the node is inside. With β ≤ ½ the pair's frequency obeys
ω² Δt² = β min(m_p, m̄_s)(1/m_p + 1/m̄_s) ≤ 2β ≤ 1 < 4: contact never limits the
stable step.

with v_n = v_r · n the normal part of the velocity of the node relative to the closest
point, v_r = v_p − Σ N_I(ξ, η) v_I, and ζ the damping as a fraction of critical (the
dashpot acts while the pair overlaps, also as it separates: with ζ ≥ 1 struck
surfaces come to rest on each other, a plastic impact, instead of bouncing apart at
twice the speed; with ``approach`` — ``[contact] damping_mode = "approach"`` — only
while the pair closes, v_n < 0: c = 0 while it separates, docs/theory.md §6). The cap
keeps the explicit dashpot stable: a node and a segment
over it are paired twice (both passes), and together the two pairs then remove at most
the relative normal velocity in one step — the plastic impact.

Friction (Coulomb, optional, stateless): with the tangential part v_t of v_r,

    f_t = −min(μ |f_n|, ½ m_red |v_t| / Δt) v_t / |v_t|:

kinetic friction, regularised near sticking by a cap that removes at most half the
relative tangential velocity in one step (no spring memory, so no true stick).
The friction force is applied at the closest point of the mid-surface: it leaves a
couple |p − x_c| |f_t| that a shell with rotational offsets would carry.

Reaction: the segment nodes get −N_I(ξ, η) f (Σ_I N_I = 1, so the pair's forces sum
to zero; for a frictionless pair f ∥ p − x_c, so their moment vanishes too).

Assembly without scatter (``assemble_contact_forces``): each pair k stores its force
f_k and weights N_I in its own rows; a node sums its own pairs (node-major already);
the segment side is gathered through a CSR (segment node → (pair, corner)) built by
a serial counting sort in pair order. Energy and active count are summed serially
in pair order, and the active pairs listed (node, pair) in that order for the energy
books (``kernels.contact_energy``: each pair's spring, dashpot and friction forces,
``pair_sd``, give the work of each per interface). Results are bitwise independent of
the thread count.
"""

from __future__ import annotations

import math

from numba import prange

from wovenimpact.jit import block_kernel, kernel, loop_kernel
from wovenimpact.kernels.contact_law import pair_force

GEO_XI, GEO_ETA, GEO_DIST, GEO_N, GEO_SIDE = 0, 1, 2, 3, 6  # columns of the pair table
N_GEO = 7
INSIDE_TOL = 1e-10  # |ξ|, |η| ≤ 1 + tol counts as inside the segment
# codes in ``keep`` while ``evaluate_node_pairs`` selects: a projected candidate's side of
# the surface (0: not projected), and the flag of the closest of its group
PROJECTED_ABOVE, PROJECTED_BELOW, SIDE_BITS, CLOSEST = 1, 2, 3, 4
GN_ITERATIONS = 12


# columns of the per-segment table of ``segment_geometry``: the raw box (b_min, b_max),
# the centre x̄ of the bilinear form x(ξ, η) = x̄ + ξ a + η b + ξη c (module docstring),
# the centre normal n̄ = a × b / |a × b| and the warp |n̄ · c| (the plane bound of
# ``evaluate_node_pairs``), then a, b, c. The box and plane tests read the first 13
# columns only; rows of 24 (192 B, three cache lines of a page-aligned table) keep those
# in two lines. No gain was measurable on the 10-ply casing (penalty stage 42.7 ms per
# step before, 43.5 after, loaded machine): at 7 mm 98.6 % of its candidates pass the
# box test and are projected anyway (plies one thickness apart touch everywhere).
SG_BOX, SG_MID, SG_NORMAL, SG_WARP, SG_A, SG_B, SG_C = 0, 6, 9, 12, 13, 16, 19
N_SEG_GEO = 24


@loop_kernel
def segment_geometry(x, quads, seg_on, seg):
    """Per live segment s (seg_on[s] ≠ 0; other rows untouched), at x: its raw box
    b_min, b_max (the narrow phase's box test), x̄, a, b, c of its bilinear form, and
    the centre normal n̄ with the warp |n̄ · c| (its plane bound; n̄ = 0 for a degenerate
    segment, which turns the bound off) — computed once per segment and step instead of
    once per candidate pair."""
    for s in prange(quads.shape[0]):
        if seg_on[s] == 0:
            continue
        q0, q1, q2, q3 = quads[s, 0], quads[s, 1], quads[s, 2], quads[s, 3]
        for d in range(3):
            x1, x2, x3, x4 = x[q0, d], x[q1, d], x[q2, d], x[q3, d]
            seg[s, SG_BOX + d] = min(x1, x2, x3, x4)
            seg[s, SG_BOX + 3 + d] = max(x1, x2, x3, x4)
            seg[s, SG_MID + d] = 0.25 * (x1 + x2 + x3 + x4)
            seg[s, SG_A + d] = 0.25 * (x2 + x3 - x1 - x4)
            seg[s, SG_B + d] = 0.25 * (x3 + x4 - x1 - x2)
            seg[s, SG_C + d] = 0.25 * (x1 + x3 - x2 - x4)
        ax, ay, az = seg[s, SG_A], seg[s, SG_A + 1], seg[s, SG_A + 2]
        bx, by, bz = seg[s, SG_B], seg[s, SG_B + 1], seg[s, SG_B + 2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        nn = math.sqrt(nx * nx + ny * ny + nz * nz)
        inv = 1.0 / nn if nn > 0.0 else 0.0
        nx, ny, nz = nx * inv, ny * inv, nz * inv
        seg[s, SG_NORMAL] = nx
        seg[s, SG_NORMAL + 1] = ny
        seg[s, SG_NORMAL + 2] = nz
        seg[s, SG_WARP] = abs(nx * seg[s, SG_C] + ny * seg[s, SG_C + 1] + nz * seg[s, SG_C + 2])


@kernel
def closest_point_on_quad(px, py, pz, x, quads, seg, s):
    """Closest point of (px, py, pz) on the bilinear segment s (module docstring);
    ``seg``: the segments' table at x (:func:`segment_geometry`).

    Returns (ξ, η, c_x, c_y, c_z, n_x, n_y, n_z, inside): natural coordinates and
    position of the closest point, the unit surface normal x,ξ × x,η there (its
    orientation follows the node order of s) and 1 if the point is inside the square.
    """
    mx, my, mz = seg[s, SG_MID], seg[s, SG_MID + 1], seg[s, SG_MID + 2]
    ax, ay, az = seg[s, SG_A], seg[s, SG_A + 1], seg[s, SG_A + 2]
    bx, by, bz = seg[s, SG_B], seg[s, SG_B + 1], seg[s, SG_B + 2]
    cx, cy, cz = seg[s, SG_C], seg[s, SG_C + 1], seg[s, SG_C + 2]
    xi = 0.0
    eta = 0.0
    for _ in range(GN_ITERATIONS):
        rx = px - (mx + xi * ax + eta * bx + xi * eta * cx)
        ry = py - (my + xi * ay + eta * by + xi * eta * cy)
        rz = pz - (mz + xi * az + eta * bz + xi * eta * cz)
        t1x, t1y, t1z = ax + eta * cx, ay + eta * cy, az + eta * cz
        t2x, t2y, t2z = bx + xi * cx, by + xi * cy, bz + xi * cz
        g1 = rx * t1x + ry * t1y + rz * t1z
        g2 = rx * t2x + ry * t2y + rz * t2z
        a11 = t1x * t1x + t1y * t1y + t1z * t1z
        a22 = t2x * t2x + t2y * t2y + t2z * t2z
        a12 = t1x * t2x + t1y * t2y + t1z * t2z - (rx * cx + ry * cy + rz * cz)  # Newton
        det = a11 * a22 - a12 * a12
        if not det > 0.0:  # far from a warped quad: Gauss–Newton (drop r · x,ξη)
            a12 = t1x * t2x + t1y * t2y + t1z * t2z
            det = a11 * a22 - a12 * a12
            if not det > 0.0:
                break
        dxi = (a22 * g1 - a12 * g2) / det
        deta = (a11 * g2 - a12 * g1) / det
        xi = min(max(xi + dxi, -2.0), 2.0)
        eta = min(max(eta + deta, -2.0), 2.0)
        if abs(dxi) + abs(deta) < 1e-14:
            break
    inside = abs(xi) <= 1.0 + INSIDE_TOL and abs(eta) <= 1.0 + INSIDE_TOL
    if inside:
        xi = min(max(xi, -1.0), 1.0)
        eta = min(max(eta, -1.0), 1.0)
        ox = mx + xi * ax + eta * bx + xi * eta * cx
        oy = my + xi * ay + eta * by + xi * eta * cy
        oz = mz + xi * az + eta * bz + xi * eta * cz
    else:  # closest point on the boundary: the four straight edges, exactly
        best = math.inf
        ox = oy = oz = 0.0
        for e in range(4):
            qa, qb = quads[s, e], quads[s, (e + 1) % 4]
            ex, ey, ez = x[qb, 0] - x[qa, 0], x[qb, 1] - x[qa, 1], x[qb, 2] - x[qa, 2]
            ll = ex * ex + ey * ey + ez * ez
            t = 0.0
            if ll > 0.0:
                t = ((px - x[qa, 0]) * ex + (py - x[qa, 1]) * ey + (pz - x[qa, 2]) * ez) / ll
                t = min(max(t, 0.0), 1.0)
            kx, ky, kz = x[qa, 0] + t * ex, x[qa, 1] + t * ey, x[qa, 2] + t * ez
            d2 = (px - kx) ** 2 + (py - ky) ** 2 + (pz - kz) ** 2
            if d2 < best:
                best = d2
                ox, oy, oz = kx, ky, kz
                # corners (−1,−1), (1,−1), (1,1), (−1,1): edge e runs from corner e to e+1
                xa = -1.0 if e == 0 or e == 3 else 1.0
                ya = -1.0 if e <= 1 else 1.0
                xb = -1.0 if e == 2 or e == 3 else 1.0
                yb = -1.0 if e == 0 or e == 3 else 1.0
                xi = xa + t * (xb - xa)
                eta = ya + t * (yb - ya)
    t1x, t1y, t1z = ax + eta * cx, ay + eta * cy, az + eta * cz
    t2x, t2y, t2z = bx + xi * cx, by + xi * cy, bz + xi * cz
    nx, ny, nz = t1y * t2z - t1z * t2y, t1z * t2x - t1x * t2z, t1x * t2y - t1y * t2x
    nn = math.sqrt(nx * nx + ny * ny + nz * nz)
    scale = ax * ax + ay * ay + az * az + bx * bx + by * by + bz * bz
    if not nn > 1e-12 * scale:  # collapsed corner of a triangle: the centre normal
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        nn = math.sqrt(nx * nx + ny * ny + nz * nz)
    inv = 1.0 / nn
    return xi, eta, ox, oy, oz, nx * inv, ny * inv, nz * inv, 1 if inside else 0


@kernel
def shape_functions(xi, eta):
    """Bilinear N_I(ξ, η), corners (−1,−1), (1,−1), (1,1), (−1,1)."""
    return (
        0.25 * (1.0 - xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 - eta),
        0.25 * (1.0 + xi) * (1.0 + eta),
        0.25 * (1.0 - xi) * (1.0 + eta),
    )


# keeps its long signature: a stage inlined into ``initial_overlap`` and ``penalty_forces``, its
# arguments that loop's locals (a bundle written through in a parallel loop's body can lose its
# writes: kernels/bundles.py)
@block_kernel
def evaluate_node_pairs(p, x, quads, ply, h_node, h_seg, one_sided, margin, seg, seg_on,
                        pair_ptr, pair_seg, geo, keep):
    """Project node p on each of its candidate segments and keep the closest per group.

    Writes, for k in pair_ptr[p] … pair_ptr[p + 1] − 1: keep[k] = 1 for the closest
    projected candidate of each (ply, side) group, else 0; and for every projected
    candidate geo[k] = (ξ, η, d, n_x, n_y, n_z, side) with d = |p − x_c|, n the unit
    contact normal pointing from the segment to the node, side = ±1 the node's side of
    the surface normal (the rows of the others are not written: most candidates fail
    the box test).

    A candidate whose node is outside the segment's box (``seg``, by
    :func:`segment_geometry` at x) inflated by r = h_p + h_s + margin (the broad phase's
    test, contact_broad) is passed over (keep 0, not projected): a fresh search at x
    would not have listed it, so candidates kept from an earlier search with a skin
    (ShellContact) give the same result. So is one farther than r from the segment by
    its plane bound: every point of the bilinear segment lies within the warp |n̄ · c|
    of the plane through x̄ normal to n̄ (n̄ · (x(ξ, η) − x̄) = ξη n̄ · c), so
    d ≥ |n̄ · (p − x̄)| − |n̄ · c|; such a pair could not act (g > margin + o_p ≥ 0), and
    on plies of one thickness the closest pair of its group, if it was that one, could
    not either, so the forces are unchanged — the projection is spared (on the flagship
    case, 6 % of the candidates at 20 µs, 22 % at 100 µs, beside the box test's 73–76 %).
    So is a candidate whose segment is off (``seg_on`` 0: eroded since the search that
    listed it; its row of ``seg`` is stale): a fresh search would not list it either.
    """
    px, py, pz = x[p, 0], x[p, 1], x[p, 2]
    k0, k1 = pair_ptr[p], pair_ptr[p + 1]
    for k in range(k0, k1):
        s = pair_seg[k]
        r = h_node[p] + h_seg[s] + margin
        lo, hi = SG_BOX, SG_BOX + 3
        if not (seg_on[s] != 0
                and seg[s, lo] - r <= px <= seg[s, hi] + r
                and seg[s, lo + 1] - r <= py <= seg[s, hi + 1] + r
                and seg[s, lo + 2] - r <= pz <= seg[s, hi + 2] + r
                and abs(seg[s, SG_NORMAL] * (px - seg[s, SG_MID])
                        + seg[s, SG_NORMAL + 1] * (py - seg[s, SG_MID + 1])
                        + seg[s, SG_NORMAL + 2] * (pz - seg[s, SG_MID + 2]))
                - seg[s, SG_WARP] <= r):
            keep[k] = 0
            continue
        xi, eta, ox, oy, oz, sx, sy, sz, inside = closest_point_on_quad(
            px, py, pz, x, quads, seg, s)
        rx, ry, rz = px - ox, py - oy, pz - oz
        dn = rx * sx + ry * sy + rz * sz
        side = 1.0 if dn >= 0.0 else -1.0
        d = math.sqrt(rx * rx + ry * ry + rz * rz)
        if one_sided[s] != 0:  # a solid's face: its outward normal, the signed distance
            # beyond its edges, or deeper than its reach: no pair
            if inside == 0 or h_node[p] - dn > h_seg[s]:
                keep[k] = 0
                continue
            nx, ny, nz = sx, sy, sz
            d = abs(dn)
        elif inside == 1 or not d > 0.0:  # the surface normal, turned toward the node
            nx, ny, nz = side * sx, side * sy, side * sz
            d = abs(dn) if inside == 1 else d
        else:  # beyond an edge: along p − x_c
            nx, ny, nz = rx / d, ry / d, rz / d
        geo[k, GEO_XI] = xi
        geo[k, GEO_ETA] = eta
        geo[k, GEO_DIST] = d
        geo[k, GEO_N] = nx
        geo[k, GEO_N + 1] = ny
        geo[k, GEO_N + 2] = nz
        geo[k, GEO_SIDE] = side
        # a solid's faces form one group whatever the side: the closest face of a body
        # decides whether the node is inside it (behind that face) or not
        keep[k] = PROJECTED_ABOVE if side > 0.0 or one_sided[s] != 0 else PROJECTED_BELOW
    # the closest of each (ply, side) group, flagged CLOSEST in keep (its side code stays
    # readable for the comparisons of the candidates after it), then keep = 1 / 0
    for k in range(k0, k1):
        side_k = keep[k] & SIDE_BITS
        if side_k == 0:
            continue
        sk = pair_seg[k]
        best = True
        for j in range(k0, k1):
            # the side first: most candidates failed the box test (code 0), and it is
            # read in order, while ply[pair_seg[j]] is a scattered load
            if j == k or (keep[j] & SIDE_BITS) != side_k:
                continue
            sj = pair_seg[j]
            if ply[sj] != ply[sk]:
                continue
            dj, dk = geo[j, GEO_DIST], geo[k, GEO_DIST]
            if dj < dk or (dj == dk and sj < sk):
                best = False
                break
        if best:
            keep[k] |= CLOSEST
    for k in range(k0, k1):
        keep[k] = 1 if keep[k] & CLOSEST else 0


@loop_kernel
def penalty_forces(x, v, dt, surfaces, law, overlap, seg, seg_on, node_on, candidates, pairs,
                   node_f):
    """Penalty (and friction) force of every candidate pair (module docstring).

    Args:
        x, v: (n_nodes, 3) positions x^n and velocities (v^{n−1/2} in the solver).
        dt: the time step the forces are for (s), > 0.
        surfaces: kernels.bundles.ContactSurfaces: segments and their plies, lumped
            masses, node and segment offsets (m), the search margin m (m).
        law: kernels.bundles.ContactLaw: penalty scale β, damping ζ (fraction of
            critical), friction coefficient μ (0: frictionless), and ``approach``: the
            dashpot acts only while the pair closes (v_n < 0; the ``damping_mode =
            "approach"`` law), not while it separates.
        overlap: (n_nodes,) o_p (m).
        seg: (n_elems, N_SEG_GEO) the segments' table at x (:func:`segment_geometry`).
        seg_on, node_on: (n_elems,), (n_nodes,) int8: the segments and nodes taking part
            now; the candidates may be of a search when more did (Verlet reuse): pairs
            of a node or segment that is off no longer act.
        candidates: kernels.bundles.Candidates (contact_broad.query_candidates).
        pairs: kernels.bundles.PairTables, (capacity, …) each:
            geo: (capacity, N_GEO), on: (capacity,) int8: scratch / written.
            force: (capacity, 3) written for the active pairs (on ≠ 0): force on the
                node of each pair (N); rows of the other pairs are left as they were
                (no reader looks at them).
            weights: (capacity, 4) written for the active pairs: N_I(ξ, η) of each pair.
            energy: (capacity,) written for the active pairs: ½ k g² of each pair (J).
            spring_damper: (capacity, 2) written for the active pairs: the normal force
                of the spring, −k g, and of the dashpot, −c v_n, on the node (N; the rest
                of the force is friction): what the energy books split the pair's work
                by (kernels.contact_energy).
            power: (capacity, 3) written for the active pairs: the powers of the spring,
                the dashpot and friction at v (W; kernels.contact_energy, where the same
                are computed at other velocities).
        node_f: (n_nodes, 3) written: Σ of each node's own pair forces (N).
    """
    # the bundles' members as locals, one per statement, before the parallel loop
    quads = surfaces.quads
    ply = surfaces.ply
    node_mass = surfaces.node_mass
    h_node = surfaces.h_node
    h_seg = surfaces.h_seg
    one_sided = surfaces.one_sided
    margin = surfaces.margin
    beta = law.beta
    zeta = law.zeta
    mu = law.mu
    approach = law.approach
    pair_ptr = candidates.ptr
    pair_seg = candidates.seg
    geo = pairs.geo
    pair_on = pairs.on
    pair_f = pairs.force
    pair_w = pairs.weights
    pair_e = pairs.energy
    pair_sd = pairs.spring_damper
    pair_pw = pairs.power
    n_nodes = x.shape[0]
    inv_dt2 = 1.0 / (dt * dt)
    for p in prange(n_nodes):
        fx = fy = fz = 0.0
        k0, k1 = pair_ptr[p], pair_ptr[p + 1]
        if node_on[p] == 0:
            for k in range(k0, k1):
                pair_on[k] = 0
            k1 = k0
        elif k1 > k0:
            evaluate_node_pairs(p, x, quads, ply, h_node, h_seg, one_sided, margin, seg,
                                seg_on, pair_ptr, pair_seg, geo, pair_on)
        for k in range(k0, k1):
            if pair_on[k] == 0:
                continue
            s = pair_seg[k]
            if one_sided[s] != 0:  # a solid's face: the signed distance along its normal
                g = geo[k, GEO_SIDE] * geo[k, GEO_DIST] - (h_node[p] - overlap[p])
            else:
                g = geo[k, GEO_DIST] - (h_node[p] + h_seg[s] - overlap[p])
            if not g < 0.0:
                pair_on[k] = 0
                continue
            n1, n2, n3, n4 = shape_functions(geo[k, GEO_XI], geo[k, GEO_ETA])
            pair_w[k, 0] = n1
            pair_w[k, 1] = n2
            pair_w[k, 2] = n3
            pair_w[k, 3] = n4
            q0, q1, q2, q3 = quads[s, 0], quads[s, 1], quads[s, 2], quads[s, 3]
            m_p = node_mass[p]
            m_s = 0.25 * (node_mass[q0] + node_mass[q1] + node_mass[q2] + node_mass[q3])
            k_pen = beta * min(m_p, m_s) * inv_dt2
            m_red = m_p * m_s / (m_p + m_s)
            nx, ny, nz = geo[k, GEO_N], geo[k, GEO_N + 1], geo[k, GEO_N + 2]
            # the relative velocity (the dashpot's, friction's and the energy books'; with
            # neither a dashpot nor friction it only books the spring's work)
            vx = v[p, 0] - (n1 * v[q0, 0] + n2 * v[q1, 0] + n3 * v[q2, 0] + n4 * v[q3, 0])
            vy = v[p, 1] - (n1 * v[q0, 1] + n2 * v[q1, 1] + n3 * v[q2, 1] + n4 * v[q3, 1])
            vz = v[p, 2] - (n1 * v[q0, 2] + n2 * v[q1, 2] + n3 * v[q2, 2] + n4 * v[q3, 2])
            # at most ½ m_red/Δt: the two passes of a pair then remove at most its whole
            # relative normal velocity in one step (a stable explicit dashpot)
            c_pen = min(2.0 * zeta * math.sqrt(k_pen * m_red), 0.5 * m_red / dt)
            vn = vx * nx + vy * ny + vz * nz
            if approach and vn > 0.0:  # separating: no dashpot in the approach-only law
                c_pen = 0.0
            gx, gy, gz = pair_force(-k_pen * g, c_pen, vx, vy, vz, nx, ny, nz, mu, m_red, dt)
            pair_f[k, 0] = gx
            pair_f[k, 1] = gy
            pair_f[k, 2] = gz
            pair_e[k] = 0.5 * k_pen * g * g
            # the spring's and the dashpot's normal forces (their sum is pair_force's f_n
            # bitwise: s − c v_n = s + (−(c v_n)))
            sp = -k_pen * g
            dp = -(c_pen * vn)
            pair_sd[k, 0] = sp
            pair_sd[k, 1] = dp
            # their powers at v (kernels.contact_energy.shell_pair_powers at other v)
            pair_pw[k, 0] = sp * vn
            pair_pw[k, 1] = dp * vn
            pair_pw[k, 2] = (gx * vx + gy * vy + gz * vz - (sp + dp) * vn) if mu > 0.0 else 0.0
            fx += gx
            fy += gy
            fz += gz
        node_f[p, 0] = fx
        node_f[p, 1] = fy
        node_f[p, 2] = fz


@loop_kernel
def initial_overlap(x, surfaces, seg, seg_on, candidates, pairs, overlap):
    """Initial-overlap allowance o_p = max(0, max over kept pairs of h_p + h_s − d).

    With it the gap g = d − (h_p + h_s − o_p) of every kept pair is ≥ 0 in the
    configuration x (the deepest pair of each node at exactly 0): overlaps present at
    the start are removed rather than pushed apart. o_p is kept constant during the
    run (the plies then contact at their nested distance again after separating).

    Args:
        x: (n_nodes, 3) initial positions; surfaces: kernels.bundles.ContactSurfaces.
        seg: the segments' table at x (:func:`segment_geometry`); seg_on: the
            segments taking part.
        candidates: kernels.bundles.Candidates at x.
        pairs: kernels.bundles.PairTables: ``geo`` and ``on`` (the pairs kept) are
            scratch as in ``penalty_forces``.
        overlap: (n_nodes,) written (m).
    """
    # the bundles' members as locals, one per statement, before the parallel loop
    quads = surfaces.quads
    ply = surfaces.ply
    h_node = surfaces.h_node
    h_seg = surfaces.h_seg
    one_sided = surfaces.one_sided
    margin = surfaces.margin
    pair_ptr = candidates.ptr
    pair_seg = candidates.seg
    geo = pairs.geo
    keep = pairs.on
    for p in prange(x.shape[0]):
        o = 0.0
        k0, k1 = pair_ptr[p], pair_ptr[p + 1]
        if k1 > k0:
            evaluate_node_pairs(p, x, quads, ply, h_node, h_seg, one_sided, margin, seg,
                                seg_on, pair_ptr, pair_seg, geo, keep)
            for k in range(k0, k1):
                if keep[k] == 0:
                    continue
                s = pair_seg[k]
                if one_sided[s] != 0:
                    o = max(o, h_node[p] - geo[k, GEO_SIDE] * geo[k, GEO_DIST])
                else:
                    o = max(o, h_node[p] + h_seg[s] - geo[k, GEO_DIST])
        overlap[p] = o


@loop_kernel
def assemble_contact_forces(quads, candidates, pairs, node_f, seg_ptr, seg_entry, cursor,
                            out, accumulate, active):
    """Nodal contact forces: out[n] (=, or += with ``accumulate``) node_f[n] − Σ N_I f_k
    over the pairs k whose segment has n as its corner I; the segment side is gathered
    through a CSR built by a serial counting sort in pair order (no scatter-add).

    Args:
        quads, candidates, pairs (kernels.bundles.PairTables), node_f: as written by
            ``penalty_forces``.
        seg_ptr: (n_nodes + 1,) int64, seg_entry: (4 capacity,) int64, cursor:
            (n_nodes,) int64: scratch.
        out: (n_nodes, ≥ 3) columns 0–2 written (or added to).
        accumulate: add to out instead of overwriting it.
        active: (capacity, 2) int64, rows 0 … n_active − 1 written: (node, pair) of the
            active pairs in pair order (the energy books read them,
            kernels.contact_energy).

    Returns:
        (energy, n_active): Σ ½ k g² (J), summed in pair order, and the active pairs.
    """
    # the bundles' members as locals, one per statement, before the parallel loop
    pair_ptr = candidates.ptr
    pair_seg = candidates.seg
    pair_on = pairs.on
    pair_f = pairs.force
    pair_w = pairs.weights
    pair_e = pairs.energy
    n_nodes = pair_ptr.shape[0] - 1
    for n in range(n_nodes + 1):
        seg_ptr[n] = 0
    energy = 0.0
    n_active = 0
    for p in range(n_nodes):  # the pairs in order, node by node
        for k in range(pair_ptr[p], pair_ptr[p + 1]):
            if pair_on[k] != 0:
                energy += pair_e[k]
                active[n_active, 0] = p
                active[n_active, 1] = k
                n_active += 1
                s = pair_seg[k]
                for c in range(4):
                    seg_ptr[quads[s, c] + 1] += 1
    for n in range(n_nodes):
        seg_ptr[n + 1] += seg_ptr[n]
        cursor[n] = seg_ptr[n]
    for j in range(n_active):
        k = active[j, 1]
        s = pair_seg[k]
        for c in range(4):
            q = quads[s, c]
            seg_entry[cursor[q]] = 4 * k + c
            cursor[q] += 1
    for n in prange(n_nodes):
        fx, fy, fz = node_f[n, 0], node_f[n, 1], node_f[n, 2]
        for j in range(seg_ptr[n], seg_ptr[n + 1]):
            k = seg_entry[j] // 4
            w = pair_w[k, seg_entry[j] % 4]
            fx -= w * pair_f[k, 0]
            fy -= w * pair_f[k, 1]
            fz -= w * pair_f[k, 2]
        if accumulate:
            out[n, 0] += fx
            out[n, 1] += fy
            out[n, 2] += fz
        else:
            out[n, 0] = fx
            out[n, 1] = fy
            out[n, 2] = fz
    return energy, n_active
