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

Both halves are booked after the node update, in one call per step: the powers at the
velocities the forces were computed with are written by the force kernels themselves
(``penalty_forces``, ``rigid_contact_forces``: they have the relative velocity), those at
the velocities after the update are computed here — for the shells in parallel when the
pairs are many (each pair its own row of compact tables: the interface and both halves'
powers), then summed into the books serially in pair order (deterministic for any
thread count), or in one serial pass with the sums when they are few (a parallel launch
costs more than their work; bitwise the same books);
for a body, one serial pass over its nodes in contact. No allocation.
"""

from __future__ import annotations

from numba import prange

from wovenimpact.jit import kernel, loop_kernel
from wovenimpact.kernels.contact_narrow import GEO_N

SPRING, DAMPING, FRICTION = 0, 1, 2  # kinds of the books: books[kind, a, b]
N_KINDS = 3


@kernel
def relative_velocity(v, quads, pair_w, geo, p, k, s):
    """(v_x, v_y, v_z, v_n) of node p relative to the point of segment s it touches in pair
    k (the segment's node velocities weighted by pair_w[k]), v_n along the pair's normal —
    the expressions of ``penalty_forces``."""
    q0, q1, q2, q3 = quads[s, 0], quads[s, 1], quads[s, 2], quads[s, 3]
    w0, w1, w2, w3 = pair_w[k, 0], pair_w[k, 1], pair_w[k, 2], pair_w[k, 3]
    vx = v[p, 0] - (w0 * v[q0, 0] + w1 * v[q1, 0] + w2 * v[q2, 0] + w3 * v[q3, 0])
    vy = v[p, 1] - (w0 * v[q0, 1] + w1 * v[q1, 1] + w2 * v[q2, 1] + w3 * v[q3, 1])
    vz = v[p, 2] - (w0 * v[q0, 2] + w1 * v[q1, 2] + w2 * v[q2, 2] + w3 * v[q3, 2])
    vn = vx * geo[k, GEO_N] + vy * geo[k, GEO_N + 1] + vz * geo[k, GEO_N + 2]
    return vx, vy, vz, vn


@loop_kernel
def shell_pair_powers(v, quads, pair_seg, pairs, active, n_active, friction, node_part,
                      seg_part, n_parts, act_if, act_pw):
    """For each active pair j (node active[j, 0], pair k = active[j, 1]: the list of
    ``assemble_contact_forces``), in rows j of compact tables: act_if[j] = a · n_parts + b,
    a the part of the node and b of the segment, and act_pw[j] = the powers (P_spring,
    P_damping, P_friction) at the velocities of the forces (``pair_pw``, written by
    ``penalty_forces``) and then at velocities v, from its force and weights as
    ``penalty_forces`` left them (the same expressions as its own; P_friction = 0 unless
    ``friction``: with μ = 0, f = (s + d) n and the difference is round-off). Parallel,
    each pair its own row: the pairs' scattered rows are read here, and the serial sum
    (:func:`book_compact`) reads the compact tables in order. ``pairs``: the narrow
    phase's tables (kernels.bundles.PairTables)."""
    pair_w = pairs.weights
    geo = pairs.geo
    pair_f = pairs.force
    pair_sd = pairs.spring_damper
    pair_pw = pairs.power
    for j in prange(n_active):
        p = active[j, 0]
        k = active[j, 1]
        s = pair_seg[k]
        vx, vy, vz, vn = relative_velocity(v, quads, pair_w, geo, p, k, s)
        sp, dp = pair_sd[k, 0], pair_sd[k, 1]
        act_if[j] = node_part[p] * n_parts + seg_part[s]
        act_pw[j, 0] = pair_pw[k, SPRING]
        act_pw[j, 1] = pair_pw[k, DAMPING]
        act_pw[j, 2] = pair_pw[k, FRICTION]
        act_pw[j, 3 + SPRING] = sp * vn
        act_pw[j, 3 + DAMPING] = dp * vn
        if friction:
            act_pw[j, 3 + FRICTION] = (pair_f[k, 0] * vx + pair_f[k, 1] * vy
                                       + pair_f[k, 2] * vz - (sp + dp) * vn)
        else:
            act_pw[j, 3 + FRICTION] = 0.0


@kernel
def book_compact(act_if, act_pw, n_active, n_parts, books):
    """books_before[kind, a, b] −= w_before · act_pw[j, kind] for the rows j in order,
    then books_after[kind, a, b] −= w_after · act_pw[j, 3 + kind] (a, b from act_if[j] =
    a · n_parts + b; :func:`shell_pair_powers`). Serial: deterministic. ``books``:
    kernels.bundles.EnergyBooks."""
    w_before = books.w_before
    books_before = books.before
    w_after = books.w_after
    books_after = books.after
    for j in range(n_active):
        a = act_if[j] // n_parts
        b = act_if[j] - a * n_parts
        for kind in range(N_KINDS):
            books_before[kind, a, b] -= w_before * act_pw[j, kind]
    for j in range(n_active):
        a = act_if[j] // n_parts
        b = act_if[j] - a * n_parts
        for kind in range(N_KINDS):
            books_after[kind, a, b] -= w_after * act_pw[j, 3 + kind]


@kernel
def book_shell_pairs(v, quads, pair_seg, pairs, active, n_active, friction, node_part,
                     seg_part, books):
    """Both halves of a step's shell pairs in one serial pass each, for a few pairs (a
    parallel launch costs more than their work): the powers at the velocities of the
    forces (``pair_pw``, written by ``penalty_forces``) times ``w_before`` into
    ``books_before``, then those at v (:func:`shell_pair_powers`) times ``w_after`` into
    ``books_after`` — the same sums in the same order as :func:`shell_pair_powers` with
    :func:`book_compact`, so bitwise the books of that parallel route. ``pairs``:
    kernels.bundles.PairTables; ``books``: kernels.bundles.EnergyBooks."""
    pair_w = pairs.weights
    geo = pairs.geo
    pair_f = pairs.force
    pair_sd = pairs.spring_damper
    pair_pw = pairs.power
    w_before = books.w_before
    books_before = books.before
    w_after = books.w_after
    books_after = books.after
    for j in range(n_active):
        k = active[j, 1]
        a = node_part[active[j, 0]]
        b = seg_part[pair_seg[k]]
        for kind in range(N_KINDS):
            books_before[kind, a, b] -= w_before * pair_pw[k, kind]
    for j in range(n_active):
        p = active[j, 0]
        k = active[j, 1]
        s = pair_seg[k]
        vx, vy, vz, vn = relative_velocity(v, quads, pair_w, geo, p, k, s)
        sp, dp = pair_sd[k, 0], pair_sd[k, 1]
        pf = 0.0
        if friction:
            pf = (pair_f[k, 0] * vx + pair_f[k, 1] * vy + pair_f[k, 2] * vz - (sp + dp) * vn)
        a = node_part[p]
        b = seg_part[s]
        books_after[SPRING, a, b] -= w_after * (sp * vn)
        books_after[DAMPING, a, b] -= w_after * (dp * vn)
        books_after[FRICTION, a, b] -= w_after * pf


@kernel
def book_body_pairs(v, body_v, parts, contact_list, count, friction, node_part, body_part,
                    books):
    """Both halves of a step's pairs of the nodes i = contact_list[j] in contact with a
    body (a the part of the node), their forces as ``rigid_contact_forces`` left them in
    ``parts``: the powers it wrote at the velocities of the forces times ``w_before``
    into ``books_before[kind, a, body_part]``, then those at v and the body's velocity
    body_v times ``w_after`` into ``books_after``: P_spring = s v_n, P_damping = d v_n,
    P_friction = f · v_r − (s + d) v_n (0 without friction), v_r = v_i − V — the solver
    books the work of the force on the body with its translation only
    (solver.contact_stage.advance_bodies). Serial, in node order: the nodes in contact
    with a body are few. ``books``: kernels.bundles.EnergyBooks."""
    w_before = books.w_before
    books_before = books.before
    w_after = books.w_after
    books_after = books.after
    for j in range(count):
        i = contact_list[j]
        a = node_part[i]
        for kind in range(N_KINDS):
            books_before[kind, a, body_part] -= w_before * parts[i, 8 + kind]
    for j in range(count):
        i = contact_list[j]
        vx = v[i, 0] - body_v[0]
        vy = v[i, 1] - body_v[1]
        vz = v[i, 2] - body_v[2]
        vn = vx * parts[i, 2] + vy * parts[i, 3] + vz * parts[i, 4]
        sp, dp = parts[i, 0], parts[i, 1]
        pf = 0.0
        if friction:
            pf = parts[i, 5] * vx + parts[i, 6] * vy + parts[i, 7] * vz - (sp + dp) * vn
        a = node_part[i]
        books_after[SPRING, a, body_part] -= w_after * (sp * vn)
        books_after[DAMPING, a, body_part] -= w_after * (dp * vn)
        books_after[FRICTION, a, body_part] -= w_after * pf
