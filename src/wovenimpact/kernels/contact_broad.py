"""Broad phase of the shell–shell contact: hashed-grid search with per-node skins (docs/model.md §4).

Candidates are (node, segment) pairs, a segment being the quad of a live element that
takes part in contact. The narrow phase (:mod:`contact_narrow`) can only make a pair
act when the node p (offset h_p, half its shell's thickness) lies within
r = h_p + h_s + m of segment s (offset h_s, margin m): its gap g = d − (h_p + h_s − o_p)
is then negative only if d < r. The search lists every such pair, and keeps listing it
while each node i moves no more than its own skin σ_i (Euclidean) from where it was at
the search (Verlet lists; :mod:`contact_update` re-queries only around the nodes that
leave their skins). Node p is a candidate of s
when, at the search,

1. box: p lies in the segment's axis-aligned box inflated by r + σ_p + σ_s,
   σ_s = max σ_I over the segment's nodes;
2. plane: |n_s · p − d_s| ≤ r + σ_p + σ_s + w_s, with n_s the unit normal
   (x3 − x1) × (x4 − x2) / |…|, d_s = n_s · x̄_s (x̄_s the centroid) and
   w_s = max_I |n_s · x_I − d_s| the warp of the quad;
3. p is neither a node of s nor of an element of the same ply as s (with
   ``self_contact`` on: of an element of the same ply sharing a node with s).

Both tests hold for every pair the narrow phase could make act before a node has left
its skin: a point q of the bilinear segment is a convex combination of its nodes, so q
moves by at most σ_s, and |n_s · (q − x̄_s)| ≤ w_s. The plane test is what keeps a stack
of curved plies cheap: a quad's axis-aligned box, tilted 45° on a cylinder, holds the
nodes of the plies several thicknesses away, its plane test only the next one.

Search (cost linear in nodes + segments):

1. ``segment_boxes``: per segment its box padded by h_s + σ_s + m, its plane and
   slack w_s + h_s + σ_s + m; ``cell_edge``: the cell edge L, the mean of the padded
   boxes' largest extents (at least 1/64 of the largest, so that no segment covers
   more than 65 cells per axis);
2. ``bin_segments``: each segment goes into every cell its padded box overlaps; cells
   are hashed into a table of 2^k buckets (Teschner et al. 2003) and a counting sort
   in segment order builds the bucket CSR (deterministic);
3. ``query_candidates``: a node p visits the cells of its box x_p ± (h_p + σ_p), checks
   each bucket entry against the entry's true cell (hash collisions cost time, never
   duplicates) and takes a segment in one cell only, the cell of the lower corner of
   the overlap of the two boxes. A counting pass, a serial prefix sum and a writing
   pass give the node-major CSR ``pair_ptr``/``pair_seg``, each node's segments in
   increasing order: the same list for any thread count, any cell edge, and any
   search that finds the same pairs. When the total exceeds the capacity of
   ``pair_seg`` nothing is written and the total is returned: the caller grows the
   buffer and calls again.
"""

from __future__ import annotations

import math

import numpy as np
from numba import prange

from wovenimpact.jit import inline_kernel, kernel, loop_kernel

# multipliers of the cell hash (Teschner et al. 2003, "optimized spatial hashing")
_P1 = 73856093
_P2 = 19349663
_P3 = 83492791
# columns of the segment tables: padded box (lower, upper corner) and plane (unit
# normal, offset d = n·x̄, slack w + h_s + σ_s + m)
SB_LO, SB_HI, N_SEG_BOX = 0, 3, 6
SP_N, SP_D, SP_SLACK, N_SEG_PLANE = 0, 3, 4, 5
MAX_CELLS_PER_AXIS = 64  # the cell edge is at least the largest padded extent / 64
TOLERANCE = 1e-9  # of the cell edge: added to every node's reach (rounding of the tests)
# default node skins σ_p = max(SKIN_FLOOR h_p, REUSE_STEPS |v_p| Δt) (contact.ShellContact)
SKIN_FLOOR = 0.5
REUSE_STEPS = 8.0


@inline_kernel
def cell_bucket(ix, iy, iz, mask):
    """Bucket of cell (ix, iy, iz): (ix P1 ⊕ iy P2 ⊕ iz P3) & mask (int64 wraparound)."""
    return ((ix * _P1) ^ (iy * _P2) ^ (iz * _P3)) & mask


@inline_kernel
def cell_of(value, inv_edge):
    """Cell index floor(value / L) along one axis, as floor(value · (1/L)): a
    multiplication, monotone in value like the division, is what binning and queries
    both use."""
    return np.int64(math.floor(value * inv_edge))


@loop_kernel
def segment_boxes(x, quads, seg_on, h_seg, sigma, margin, seg_box, seg_plane):
    """Per live segment s: seg_box[s] = its axis-aligned box padded by
    h_s + σ_s + m; seg_plane[s] = (n_s, d_s, w_s + h_s + σ_s + m) (module docstring;
    a degenerate quad, no normal, gets n = 0 and an infinite slack: no plane test)."""
    for s in prange(quads.shape[0]):
        if seg_on[s] == 0:
            continue
        q0, q1, q2, q3 = quads[s, 0], quads[s, 1], quads[s, 2], quads[s, 3]
        sig = max(max(sigma[q0], sigma[q1]), max(sigma[q2], sigma[q3]))
        pad = h_seg[s] + sig + margin
        for d in range(3):
            lo = min(min(x[q0, d], x[q1, d]), min(x[q2, d], x[q3, d]))
            hi = max(max(x[q0, d], x[q1, d]), max(x[q2, d], x[q3, d]))
            seg_box[s, SB_LO + d] = lo - pad
            seg_box[s, SB_HI + d] = hi + pad
        ax, ay, az = x[q2, 0] - x[q0, 0], x[q2, 1] - x[q0, 1], x[q2, 2] - x[q0, 2]
        bx, by, bz = x[q3, 0] - x[q1, 0], x[q3, 1] - x[q1, 1], x[q3, 2] - x[q1, 2]
        nx, ny, nz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
        length = math.sqrt(nx * nx + ny * ny + nz * nz)
        if not length > 0.0:
            seg_plane[s, SP_N] = 0.0
            seg_plane[s, SP_N + 1] = 0.0
            seg_plane[s, SP_N + 2] = 0.0
            seg_plane[s, SP_D] = 0.0
            seg_plane[s, SP_SLACK] = math.inf
            continue
        nx, ny, nz = nx / length, ny / length, nz / length
        h0 = nx * x[q0, 0] + ny * x[q0, 1] + nz * x[q0, 2]
        h1 = nx * x[q1, 0] + ny * x[q1, 1] + nz * x[q1, 2]
        h2 = nx * x[q2, 0] + ny * x[q2, 1] + nz * x[q2, 2]
        h3 = nx * x[q3, 0] + ny * x[q3, 1] + nz * x[q3, 2]
        dist = 0.25 * (h0 + h1 + h2 + h3)
        warp = max(max(abs(h0 - dist), abs(h1 - dist)), max(abs(h2 - dist), abs(h3 - dist)))
        seg_plane[s, SP_N] = nx
        seg_plane[s, SP_N + 1] = ny
        seg_plane[s, SP_N + 2] = nz
        seg_plane[s, SP_D] = dist
        seg_plane[s, SP_SLACK] = warp + pad


@kernel
def cell_edge(seg_on, seg_box):
    """Cell edge L: the mean over the live segments of their padded box's largest
    extent, at least 1/MAX_CELLS_PER_AXIS of the largest one and 2^-40 of the largest
    coordinate (cell indices stay far inside int64); 1.0 with no live segment."""
    total = 0.0
    largest = 0.0
    reach = 0.0
    count = 0
    for s in range(seg_on.shape[0]):
        if seg_on[s] == 0:
            continue
        e = 0.0
        for d in range(3):
            e = max(e, seg_box[s, SB_HI + d] - seg_box[s, SB_LO + d])
            reach = max(reach, abs(seg_box[s, SB_LO + d]), abs(seg_box[s, SB_HI + d]))
        total += e
        largest = max(largest, e)
        count += 1
    if count == 0:
        return 1.0
    return max(total / count, largest / MAX_CELLS_PER_AXIS, reach * 2.0**-40, 1e-300)


@kernel
def bin_segments(seg_on, seg_box, ply, inv_edge, bucket_ptr, entry_seg, entry_cell, entry_box,
                 entry_ply):
    """Every live segment into every cell its padded box overlaps, bucketed by the
    cell hash: entries of bucket b are entry_seg/entry_cell/entry_box/entry_ply[
    bucket_ptr[b]:bucket_ptr[b + 1]] (segment, cell, padded box, ply: a bucket is scanned
    as one stream), in segment order. Returns the number of entries; when it exceeds the
    capacity of entry_seg nothing but the count is written (the caller grows and calls
    again)."""
    n_buckets = bucket_ptr.shape[0] - 1
    mask = n_buckets - 1
    for b in range(n_buckets + 1):
        bucket_ptr[b] = 0
    n = 0
    # pass 0 counts per bucket; pass 1 fills in segment order, bucket_ptr[b] serving as
    # the cursor of bucket b (it ends at the end of b, i.e. the start of b + 1)
    for fill in range(2):
        for s in range(seg_on.shape[0]):
            if seg_on[s] == 0:
                continue
            for cx in range(cell_of(seg_box[s, 0], inv_edge), cell_of(seg_box[s, 3], inv_edge) + 1):
                for cy in range(cell_of(seg_box[s, 1], inv_edge),
                                cell_of(seg_box[s, 4], inv_edge) + 1):
                    for cz in range(cell_of(seg_box[s, 2], inv_edge),
                                    cell_of(seg_box[s, 5], inv_edge) + 1):
                        b = cell_bucket(cx, cy, cz, mask)
                        if fill == 0:
                            bucket_ptr[b + 1] += 1
                            n += 1
                            continue
                        k = bucket_ptr[b]
                        entry_seg[k] = s
                        entry_cell[k, 0] = cx
                        entry_cell[k, 1] = cy
                        entry_cell[k, 2] = cz
                        for c in range(N_SEG_BOX):
                            entry_box[k, c] = seg_box[s, c]
                        entry_ply[k] = ply[s]
                        bucket_ptr[b] = k + 1
        if fill == 0:
            if n > entry_seg.shape[0]:
                return n
            for b in range(n_buckets):
                bucket_ptr[b + 1] += bucket_ptr[b]
    for b in range(n_buckets, 0, -1):  # shift back: bucket_ptr[b] = start of b
        bucket_ptr[b] = bucket_ptr[b - 1]
    bucket_ptr[0] = 0
    return n


@kernel
def excluded_pair(p, s, quads, ply, node_ptr, node_elem, self_contact):
    """True when node p may not touch segment s: p is a node of s, or p belongs to an
    element e of the same ply as s (with ``self_contact``: only if e shares a node with s)."""
    for k in range(node_ptr[p], node_ptr[p + 1]):
        e = node_elem[k]
        if e == s:
            return True
        if ply[e] == ply[s]:
            if not self_contact:
                return True
            for a in range(4):
                for b in range(4):
                    if quads[e, a] == quads[s, b]:
                        return True
    return False


@inline_kernel
def overlap_in_cell(lo, hi, box_lo, box_hi, several, cell, inv_edge):
    """The node's interval [lo, hi] meets the segment's [box_lo, box_hi] along one axis,
    and the lower end of the overlap lies in ``cell`` (each pair is taken in one cell;
    when the node's interval lies in one cell, ``several`` false, it is that cell)."""
    if hi < box_lo or box_hi < lo:
        return False
    return not several or cell_of(max(lo, box_lo), inv_edge) == cell


@kernel
def running_total(ptr, n):
    """ptr[1:n + 1] holds n counts: turn ptr[:n + 1] into their running total (ptr[0] = 0,
    the CSR offsets) and return the total ptr[n]."""
    ptr[0] = 0
    for i in range(n):
        ptr[i + 1] += ptr[i]
    return ptr[n]


@kernel
def sort_ascending(a, start, stop):
    """Insertion sort of a[start:stop] in place (a node's few candidates)."""
    for i in range(start + 1, stop):
        v = a[i]
        j = i - 1
        while j >= start and a[j] > v:
            a[j + 1] = a[j]
            j -= 1
        a[j + 1] = v


# keeps its long signature: a stage called in the loop of ``query_candidates`` and ``scan_twice``,
# its arguments that loop's locals (a bundle written through in a parallel loop's body can lose
# its writes: kernels/bundles.py)
@kernel
def scan_node(p, x, quads, ply, node_ply, h_node, sigma, self_contact, node_ptr, node_elem,
              seg_plane, edge, bucket_ptr, entry_seg, entry_cell, entry_box, entry_ply,
              skip, out, start, room):
    """Node p's candidates (module docstring, step 3) among the binned segments not
    marked in ``skip`` (int8 per segment; all 0 in a full search, the re-boxed segments
    in an incremental one, :mod:`contact_update`): their number; the first ``room`` of
    them are written to out[start:], in scan order."""
    mask = bucket_ptr.shape[0] - 2
    inv = 1.0 / edge
    px, py, pz = x[p, 0], x[p, 1], x[p, 2]
    a = h_node[p] + sigma[p] + TOLERANCE * edge
    x0, x1 = px - a, px + a
    y0, y1 = py - a, py + a
    z0, z1 = pz - a, pz + a
    i0, i1 = cell_of(x0, inv), cell_of(x1, inv)
    j0, j1 = cell_of(y0, inv), cell_of(y1, inv)
    k0, k1 = cell_of(z0, inv), cell_of(z1, inv)
    # a node whose elements all lie in one ply is excluded from that ply's segments
    # (and only from them) unless surfaces meet themselves: a comparison of plies
    own_ply = node_ply[p] if self_contact == 0 else -1
    count = 0
    for cx in range(i0, i1 + 1):
        for cy in range(j0, j1 + 1):
            for cz in range(k0, k1 + 1):
                b = cell_bucket(cx, cy, cz, mask)
                for k in range(bucket_ptr[b], bucket_ptr[b + 1]):
                    if not (overlap_in_cell(x0, x1, entry_box[k, 0], entry_box[k, 3],
                                            i1 > i0, cx, inv)
                            and overlap_in_cell(y0, y1, entry_box[k, 1], entry_box[k, 4],
                                                j1 > j0, cy, inv)
                            and overlap_in_cell(z0, z1, entry_box[k, 2], entry_box[k, 5],
                                                k1 > k0, cz, inv)):
                        continue
                    if (entry_cell[k, 0] != cx or entry_cell[k, 1] != cy
                            or entry_cell[k, 2] != cz):
                        continue  # another cell hashed into this bucket
                    if own_ply >= 0 and entry_ply[k] == own_ply:
                        continue
                    s = entry_seg[k]
                    if skip[s] != 0:
                        continue
                    height = (seg_plane[s, 0] * px + seg_plane[s, 1] * py
                              + seg_plane[s, 2] * pz - seg_plane[s, SP_D])
                    if abs(height) > a + seg_plane[s, SP_SLACK]:
                        continue
                    if own_ply < 0 and excluded_pair(p, s, quads, ply, node_ptr, node_elem,
                                                     self_contact):
                        continue
                    if count < room:
                        out[start + count] = s
                    count += 1
    return count


@loop_kernel
def query_candidates(surfaces, search, node_on, bins, skip, slots, out):
    """Candidate (node, segment) pairs of the binned segments (module docstring, step 3).

    Args:
        surfaces: kernels.bundles.ContactSurfaces: segments (quads) and their plies;
            node_ply, the ply of all of a node's elements, −1 if they are of several
            plies (or it has none); node offsets h_p (m); self_contact (False: no pair
            within one ply; True: pairs within a ply unless the node's element shares a
            node with the segment); the node → element CSR (Model).
        search: kernels.bundles.ContactSearch: positions, node skins σ_p (m), the
            planes of :func:`segment_boxes` and the cell edge L.
        node_on: (n_nodes,) nonzero for a node taking part now (active and selected).
        bins: kernels.bundles.SegmentBinTables, the bins of :func:`bin_segments`.
        skip: (n_segments,) int8: binned segments to pass over (all 0 in a search).
        slots: (n_nodes, m) int64 scratch: the first m candidates of each node, kept
            from the counting pass (a node with more is scanned again to write).
        out: kernels.bundles.Candidates, written: ``ptr`` (n_nodes + 1,), candidates of
            node p are seg[ptr[p]:ptr[p + 1]], in increasing segment order; ``seg``
            (capacity,) written when the total fits.

    Returns:
        the number of candidates (> capacity: overflow, ``out.seg`` not written).
    """
    # the bundles' members as locals, one per statement, before the parallel loops
    x = search.x
    sigma = search.sigma
    seg_plane = search.seg_plane
    edge = search.edge
    quads = surfaces.quads
    ply = surfaces.ply
    node_ply = surfaces.node_ply
    h_node = surfaces.h_node
    self_contact = surfaces.self_contact
    node_ptr = surfaces.node_ptr
    node_elem = surfaces.node_elem
    bucket_ptr = bins.bucket_ptr
    entry_seg = bins.entry_seg
    entry_cell = bins.entry_cell
    entry_box = bins.entry_box
    entry_ply = bins.entry_ply
    pair_ptr = out.ptr
    pair_seg = out.seg
    n_nodes = x.shape[0]
    room = slots.shape[1]
    flat = slots.reshape(-1)
    for p in prange(n_nodes):
        count = 0
        if node_on[p] != 0:
            count = scan_node(p, x, quads, ply, node_ply, h_node, sigma, self_contact,
                              node_ptr, node_elem, seg_plane, edge, bucket_ptr, entry_seg,
                              entry_cell, entry_box, entry_ply, skip, flat, p * room, room)
        pair_ptr[p + 1] = count
    if running_total(pair_ptr, n_nodes) > pair_seg.shape[0]:
        return pair_ptr[n_nodes]
    for p in prange(n_nodes):
        base, count = pair_ptr[p], pair_ptr[p + 1] - pair_ptr[p]
        if count <= room:
            for i in range(count):
                pair_seg[base + i] = slots[p, i]
        else:
            scan_node(p, x, quads, ply, node_ply, h_node, sigma, self_contact, node_ptr,
                      node_elem, seg_plane, edge, bucket_ptr, entry_seg, entry_cell,
                      entry_box, entry_ply, skip, pair_seg, base, count)
        sort_ascending(pair_seg, base, base + count)
    return pair_ptr[n_nodes]


def bucket_count(n_entries: int) -> int:
    """Hash-table size for ``n_entries`` bin entries: the power of two ≥ 2 n (at least 64)."""
    return 1 << max(6, int(math.ceil(math.log2(max(2 * n_entries, 1)))))


@loop_kernel
def contact_masks(elem_alive, elem_part, node_active, node_part, seg_on, node_on):
    """seg_on = (element alive) ∧ (element takes part); node_on = (node active) ∧ (node
    takes part): eroded elements leave the surfaces, inactive nodes are skipped."""
    for e in prange(seg_on.shape[0]):
        seg_on[e] = 1 if (elem_alive[e] != 0 and elem_part[e] != 0) else 0
    for n in prange(node_on.shape[0]):
        node_on[n] = 1 if (node_active[n] != 0 and node_part[n] != 0) else 0


@loop_kernel
def node_skins(v, dt, steps, h_node, floor, sigma):
    """Node skins σ_p = max(floor · h_p, steps · |v_p| Δt): what a node at its speed
    covers in ``steps`` steps, at least a fraction of its offset (m)."""
    for p in prange(v.shape[0]):
        speed = math.sqrt(v[p, 0] * v[p, 0] + v[p, 1] * v[p, 1] + v[p, 2] * v[p, 2])
        sigma[p] = max(floor * h_node[p], steps * speed * dt)
