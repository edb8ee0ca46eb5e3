"""Energy books of the contact forces, per interface (docs/theory.md §6, "Contact energy
per interface").

The solver books the work of the contact forces on the nodes and bodies by the
trapezoid rule, W += ½ Δt^{n−1/2} (f^{n−1} + f^n) · v^{n−1/2}: each force f^n is
credited twice, with ½ Δt^{n−1/2} against v^{n−1/2} (the step that brings it) and with
½ Δt^{n+1/2} against v^{n+1/2} (the next). The books split that same work by pair and by
part of the pair's force: the spring's normal force s n, the dashpot's d n and the rest,
friction f − (s + d) n (``pair_sd`` of contact_narrow, ``parts`` of contact_rigid). A
pair's force system (f on the node, −N_I f on the segment's corners, or −f on the body)
has the power f · v_r, v_r the node's velocity relative to the segment point (or the
body), so

    P_spring = s v_n,  P_damping = d v_n,  P_friction = f · v_r − (s + d) v_n,

v_n = v_r · n, and the three sum to the pair's share of the solver's work: the books of
all pairs add up to −W_contact to round-off. Each is added, times −½ Δt, to
``books[kind, a, b]``, a the part of the pair's node and b that of its segment or
body: the energy that part of the contact took out of the structure (the dashpot's and
friction's are what they dissipated; the spring's is its stored energy ½ k g² but for
the penalty's discretisation: k follows Δt, and the trapezoid does not integrate the
onset and release of a pair exactly).

Two kernels each for shells and bodies: the powers of the pairs of the last contact
call at given velocities (parallel, each pair its own row; for the shells, at the
velocities the forces were computed with, ``penalty_forces`` writes them itself, from
the relative velocity it has) and their sum into the books (serial, in pair order:
deterministic for any thread count). No allocation.
"""

from __future__ import annotations

from numba import prange

from wovenimpact.jit import kernel, loop_kernel
from wovenimpact.kernels.contact_narrow import GEO_N

SPRING, DAMPING, FRICTION = 0, 1, 2  # kinds of the books: books[kind, a, b]
N_KINDS = 3


@loop_kernel
def shell_pair_powers(v, quads, pair_seg, pair_w, geo, pair_f, pair_sd, active, n_active,
                      friction, power):
    """power[k] = (P_spring, P_damping, P_friction) (W) of each active pair k (the
    active[j] = (node, k) of ``assemble_contact_forces``) at velocities v, its force and
    weights as ``penalty_forces`` left them (the same expressions as its own, at v^{n−1/2});
    P_friction = 0 unless ``friction`` (μ > 0: otherwise f = (s + d) n and the difference
    is round-off)."""
    for j in prange(n_active):
        p = active[j, 0]
        k = active[j, 1]
        s = pair_seg[k]
        q0, q1, q2, q3 = quads[s, 0], quads[s, 1], quads[s, 2], quads[s, 3]
        w0, w1, w2, w3 = pair_w[k, 0], pair_w[k, 1], pair_w[k, 2], pair_w[k, 3]
        vx = v[p, 0] - (w0 * v[q0, 0] + w1 * v[q1, 0] + w2 * v[q2, 0] + w3 * v[q3, 0])
        vy = v[p, 1] - (w0 * v[q0, 1] + w1 * v[q1, 1] + w2 * v[q2, 1] + w3 * v[q3, 1])
        vz = v[p, 2] - (w0 * v[q0, 2] + w1 * v[q1, 2] + w2 * v[q2, 2] + w3 * v[q3, 2])
        vn = vx * geo[k, GEO_N] + vy * geo[k, GEO_N + 1] + vz * geo[k, GEO_N + 2]
        sp, dp = pair_sd[k, 0], pair_sd[k, 1]
        power[k, SPRING] = sp * vn
        power[k, DAMPING] = dp * vn
        if friction:
            power[k, FRICTION] = (pair_f[k, 0] * vx + pair_f[k, 1] * vy + pair_f[k, 2] * vz
                                  - (sp + dp) * vn)
        else:
            power[k, FRICTION] = 0.0


@kernel
def book_shell_powers(power, active, n_active, pair_seg, node_part, seg_part, weight, books):
    """books[kind, a, b] −= weight · power[k, kind] for the active pairs k in order, a the
    part of the pair's node and b of its segment (serial: deterministic)."""
    for j in range(n_active):
        k = active[j, 1]
        a = node_part[active[j, 0]]
        b = seg_part[pair_seg[k]]
        for kind in range(N_KINDS):
            books[kind, a, b] -= weight * power[k, kind]


@loop_kernel
def body_pair_powers(v, body_v, parts, contact_list, count, friction, power):
    """power[j] = (P_spring, P_damping, P_friction) (W) of node i = contact_list[j]
    against a body moving at body_v, its forces as ``rigid_contact_forces`` left them in
    ``parts``. The relative velocity is v_i − V: the solver books the work of the force on
    the body with its translation only (solver.contact_stage.advance_bodies)."""
    for j in prange(count):
        i = contact_list[j]
        vx = v[i, 0] - body_v[0]
        vy = v[i, 1] - body_v[1]
        vz = v[i, 2] - body_v[2]
        vn = vx * parts[i, 2] + vy * parts[i, 3] + vz * parts[i, 4]
        sp, dp = parts[i, 0], parts[i, 1]
        power[j, SPRING] = sp * vn
        power[j, DAMPING] = dp * vn
        if friction:
            power[j, FRICTION] = (parts[i, 5] * vx + parts[i, 6] * vy + parts[i, 7] * vz
                                  - (sp + dp) * vn)
        else:
            power[j, FRICTION] = 0.0


@kernel
def book_body_powers(power, contact_list, count, node_part, body_part, weight, books):
    """books[kind, a, body_part] −= weight · power[j, kind], a the part of node
    contact_list[j] (serial, in node order)."""
    for j in range(count):
        a = node_part[contact_list[j]]
        for kind in range(N_KINDS):
            books[kind, a, body_part] -= weight * power[j, kind]
