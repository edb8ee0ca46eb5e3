"""Broad phase of the shell–shell contact: hashed uniform-grid search (MODEL.md §4).

Candidates are (node, segment) pairs, a segment being the quad of a live element
that takes part in contact. A node p (offset h_p, the half-thickness of its shell) is
a candidate of segment s (offset h_s) when it lies in the segment's axis-aligned box
inflated by the two offsets and a margin m:

    min_I x_I,d − r ≤ p_d ≤ max_I x_I,d + r,    r = h_s + h_p + m,   d = x, y, z,

and is neither a node of s nor of an element of the same ply as s (with
``self_contact`` on: of an element of the same ply sharing a node with s). The
narrow phase (:mod:`contact_narrow`) then measures the exact gap.

Search (cost linear in nodes + segments, independent of the thickest section):

1. boxes: per segment its raw box [b_min, b_max]; the cell edge L_d along each axis is
   the mean over the live segments of their box inflated by their own offset and the
   margin, b_max − b_min + 2 (h_s + m) (at least ``cell_min`` and a quarter of the
   largest node offset, so that a node visits at most ~9 cells per axis); the grid's
   origin is offset by a fraction of a cell so that a regular mesh's edges do not fall
   on cell edges;
2. cells: each segment is entered in every cell its box inflated by h_s + m overlaps
   (usually 1–8), the cells hashed into a table of 2^k buckets; a counting sort over
   bucket indices (segments in increasing order inside a bucket) builds the bucket
   CSR — deterministic;
3. queries: a node p visits the cells its own interval [p − h_p, p + h_p] overlaps
   (usually one). A pair (p, s) passes the box test only if that interval and the
   segment's inflated box overlap, so it is met in at least one common cell; it is
   taken only in the first of them (per axis the larger of the two lower cell indices),
   so never twice. Each bucket entry is checked against its true cell (hash collisions
   cost time, never duplicates), then the exact box test and the exclusion test. A
   counting pass gives each node's number of candidates, a serial prefix sum their
   offsets, and a writing pass fills them, each node's in increasing segment order: the
   output is node-major (a CSR ``pair_ptr``/``pair_seg``), the same for any thread count
   and for any cell size. When the pairs exceed the capacity of ``pair_seg``, or the
   cell entries that of the bucket arrays, nothing more is written and the needs are
   returned: the caller grows the buffers and calls again.

Before issue 13 the cell was the largest inflated box of any segment, padded with the
largest node offset: a casing's plies were scanned in cubes as wide as the blade is
thick (20 mm cells, ~300 segments per node, more with every ply).
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
CELL_SLACK = 1e-9  # cell ranges widened by this fraction of the cell edge (rounding)


@inline_kernel
def cell_bucket(ix, iy, iz, mask):
    """Bucket of cell (ix, iy, iz): (ix P1 ⊕ iy P2 ⊕ iz P3) & mask (int64 wraparound)."""
    return ((ix * _P1) ^ (iy * _P2) ^ (iz * _P3)) & mask


CELL_OFFSET = 0.3819660112501051  # grid origin at this fraction of a cell (2 − φ): a
# mesh whose nodes sit on round coordinates does not put its segments' edges on cell edges


@inline_kernel
def cell_range(lo, hi, length):
    """Cells floor((lo − o)/L) … floor((hi − o)/L), o = CELL_OFFSET · L, of the interval
    [lo, hi] widened by CELL_SLACK · L at both ends."""
    slack = CELL_SLACK * length
    origin = CELL_OFFSET * length
    return (np.int64(math.floor((lo - slack - origin) / length)),
            np.int64(math.floor((hi + slack - origin) / length)))


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
def in_inflated_box(x, p, box, k, r):
    """Node p inside the box [b_min − r, b_max + r] of row k (rows: b_min, b_max)."""
    return (
        box[k, 0] - r <= x[p, 0] <= box[k, 3] + r
        and box[k, 1] - r <= x[p, 1] <= box[k, 4] + r
        and box[k, 2] - r <= x[p, 2] <= box[k, 5] + r
    )


@kernel
def sort_segments(pair_seg, start, count):
    """Sort pair_seg[start : start + count] in increasing order (insertion sort: a node
    has a few tens of candidates at most)."""
    for i in range(start + 1, start + count):
        v = pair_seg[i]
        j = i - 1
        while j >= start and pair_seg[j] > v:
            pair_seg[j + 1] = pair_seg[j]
            j -= 1
        pair_seg[j + 1] = v


@loop_kernel
def find_candidates(
    x, quads, ply, seg_on, node_on, h_node, h_seg, margin, cell_min, self_contact,
    node_ptr, node_elem, box, seg_cells, bucket_ptr, bucket_seg, bucket_cell, pair_ptr,
    pair_seg,
):
    """Candidate (node, segment) pairs by the hashed-grid search of the module docstring.

    Args:
        x: (n_nodes, 3) current positions.
        quads: (n_elems, 4) segment nodes; ply: (n_elems,) ply of each element.
        seg_on: (n_elems,) nonzero for a segment taking part now (live and selected).
        node_on: (n_nodes,) nonzero for a node taking part now (active and selected).
        h_node: (n_nodes,) node offsets h_p; h_seg: (n_elems,) segment offsets h_s (m).
        margin: extra inflation m of the boxes (m, ≥ 0).
        cell_min: smallest cell edge (m); 0: the mean inflated box alone.
        self_contact: 0: no pair within one ply; 1: pairs within a ply unless the node's
            element shares a node with the segment.
        node_ptr, node_elem: node → element CSR (Model).
        box: (n_elems, 6) scratch: b_min, b_max of each segment.
        seg_cells: (n_elems, 6) int64 scratch: each segment's lower and upper cells.
        bucket_ptr: (n_buckets + 1,) int64 scratch, n_buckets a power of two ≥ 2 entries.
        bucket_seg: (entry capacity,) int64 and bucket_cell: (entry capacity, 3) int64
            scratch: the cell entries (segment, cell) in bucket order.
        pair_ptr: (n_nodes + 1,) int64 written: candidates of node p are
            pair_seg[pair_ptr[p]:pair_ptr[p + 1]], in increasing segment order.
        pair_seg: (capacity,) int64 written when the total fits.

    Returns:
        (n_pairs, n_entries, L_x, L_y, L_z): total candidates (> capacity: overflow,
        pair_seg not written; −1 when the entries did not fit), the cell entries (more
        than bucket_seg holds, or more than half the buckets: grow them and call again)
        and the cell edges used.
    """
    n_nodes = x.shape[0]
    n_el = quads.shape[0]
    # 1. raw boxes of the live segments and the mean inflated box
    for s in prange(n_el):
        if seg_on[s] == 0:
            continue
        for d in range(3):
            lo = hi = x[quads[s, 0], d]
            for a in range(1, 4):
                q = quads[s, a]
                lo = min(lo, x[q, d])
                hi = max(hi, x[q, d])
            box[s, d] = lo
            box[s, 3 + d] = hi
    sum0 = sum1 = sum2 = 0.0
    n_live = 0
    for s in range(n_el):
        if seg_on[s] == 0:
            continue
        pad = 2.0 * (h_seg[s] + margin)
        sum0 += box[s, 3] - box[s, 0] + pad
        sum1 += box[s, 4] - box[s, 1] + pad
        sum2 += box[s, 5] - box[s, 2] + pad
        n_live += 1
    n_live = max(n_live, 1)
    # a node visits the cells of [p − h_p, p + h_p]: at most ~9 per axis
    h_max = 0.0
    for p in range(n_nodes):
        if node_on[p] != 0 and h_node[p] > h_max:
            h_max = h_node[p]
    floor_len = max(cell_min, 0.25 * h_max, 1e-9 * max(sum0, sum1, sum2) / n_live, 1e-300)
    l0 = max(sum0 / n_live, floor_len)
    l1 = max(sum1 / n_live, floor_len)
    l2 = max(sum2 / n_live, floor_len)
    # 2. cell ranges, entries, bucket lists (counting sort by bucket; segment order)
    n_entries = 0
    for s in range(n_el):
        if seg_on[s] == 0:
            continue
        pad = h_seg[s] + margin
        a0, b0 = cell_range(box[s, 0] - pad, box[s, 3] + pad, l0)
        a1, b1 = cell_range(box[s, 1] - pad, box[s, 4] + pad, l1)
        a2, b2 = cell_range(box[s, 2] - pad, box[s, 5] + pad, l2)
        seg_cells[s, 0], seg_cells[s, 1], seg_cells[s, 2] = a0, a1, a2
        seg_cells[s, 3], seg_cells[s, 4], seg_cells[s, 5] = b0, b1, b2
        n_entries += (b0 - a0 + 1) * (b1 - a1 + 1) * (b2 - a2 + 1)
    n_buckets = bucket_ptr.shape[0] - 1
    if n_entries > bucket_seg.shape[0] or 2 * n_entries > n_buckets:
        return -1, n_entries, l0, l1, l2
    mask = n_buckets - 1
    for b in range(n_buckets + 1):
        bucket_ptr[b] = 0
    for s in range(n_el):
        if seg_on[s] == 0:
            continue
        for cx in range(seg_cells[s, 0], seg_cells[s, 3] + 1):
            for cy in range(seg_cells[s, 1], seg_cells[s, 4] + 1):
                for cz in range(seg_cells[s, 2], seg_cells[s, 5] + 1):
                    bucket_ptr[cell_bucket(cx, cy, cz, mask) + 1] += 1
    for b in range(n_buckets):
        bucket_ptr[b + 1] += bucket_ptr[b]
    # fill in segment order, bucket_ptr[b] serving as the cursor of bucket b (it ends
    # at the end of b, i.e. the start of b + 1), then shift back by one
    for s in range(n_el):
        if seg_on[s] == 0:
            continue
        for cx in range(seg_cells[s, 0], seg_cells[s, 3] + 1):
            for cy in range(seg_cells[s, 1], seg_cells[s, 4] + 1):
                for cz in range(seg_cells[s, 2], seg_cells[s, 5] + 1):
                    b = cell_bucket(cx, cy, cz, mask)
                    k = bucket_ptr[b]
                    bucket_seg[k] = s
                    bucket_cell[k, 0] = cx
                    bucket_cell[k, 1] = cy
                    bucket_cell[k, 2] = cz
                    bucket_ptr[b] = k + 1
    for b in range(n_buckets, 0, -1):  # shift back: bucket_ptr[b] = start of b
        bucket_ptr[b] = bucket_ptr[b - 1]
    bucket_ptr[0] = 0
    # 3. queries: count, prefix sum, write (each node's candidates sorted)
    capacity = pair_seg.shape[0]
    for sweep in range(2):
        write = sweep == 1
        for p in prange(n_nodes):
            count = 0
            if node_on[p] != 0:
                base = pair_ptr[p] if write else 0
                hp = h_node[p]
                i0, j0 = cell_range(x[p, 0] - hp, x[p, 0] + hp, l0)
                i1, j1 = cell_range(x[p, 1] - hp, x[p, 1] + hp, l1)
                i2, j2 = cell_range(x[p, 2] - hp, x[p, 2] + hp, l2)
                for cx in range(i0, j0 + 1):
                    for cy in range(i1, j1 + 1):
                        for cz in range(i2, j2 + 1):
                            b = cell_bucket(cx, cy, cz, mask)
                            for k in range(bucket_ptr[b], bucket_ptr[b + 1]):
                                if (bucket_cell[k, 0] != cx or bucket_cell[k, 1] != cy
                                        or bucket_cell[k, 2] != cz):
                                    continue  # another cell hashed into this bucket
                                s = bucket_seg[k]
                                # the first common cell of node and segment only
                                if (cx != max(i0, seg_cells[s, 0])
                                        or cy != max(i1, seg_cells[s, 1])
                                        or cz != max(i2, seg_cells[s, 2])):
                                    continue
                                r = h_seg[s] + hp + margin
                                if not in_inflated_box(x, p, box, s, r):
                                    continue
                                if excluded_pair(p, s, quads, ply, node_ptr, node_elem,
                                                 self_contact):
                                    continue
                                if write:
                                    pair_seg[base + count] = s
                                count += 1
                if write:
                    sort_segments(pair_seg, base, count)
            if not write:
                pair_ptr[p + 1] = count
        if not write:
            pair_ptr[0] = 0
            for p in range(n_nodes):
                pair_ptr[p + 1] += pair_ptr[p]
            if pair_ptr[n_nodes] > capacity:
                break
    return pair_ptr[n_nodes], n_entries, l0, l1, l2


def bucket_count(n_entries: int) -> int:
    """Hash-table size for ``n_entries`` cell entries: the power of two ≥ 2 n (at least 64)."""
    return 1 << max(6, int(math.ceil(math.log2(max(2 * n_entries, 1)))))


@loop_kernel
def contact_masks(elem_alive, elem_part, node_active, node_part, seg_on, node_on):
    """seg_on = (element alive) ∧ (element takes part); node_on = (node active) ∧ (node
    takes part): eroded elements leave the surfaces, inactive nodes are skipped."""
    for e in prange(seg_on.shape[0]):
        seg_on[e] = 1 if (elem_alive[e] != 0 and elem_part[e] != 0) else 0
    for n in prange(node_on.shape[0]):
        node_on[n] = 1 if (node_active[n] != 0 and node_part[n] != 0) else 0


@kernel
def candidates_still_valid(x, x_search, node_on, node_on_search, seg_on, seg_on_search,
                           skin):
    """Whether the candidates of a search at x_search with margin m + skin still hold
    every pair of a search at x with margin m (Verlet-list reuse).

    A segment's box moves by at most d = max over the nodes and axes of
    |x − x_search|, a node by at most d, so a pair inside the inflated box now was
    inside it, inflated by 2d more, at the search: valid while 2d ≤ skin. The masks
    must also be unchanged (an eroded segment or a deactivated node leaves the lists).
    Serial with an early exit: one pass over the nodes at most.
    """
    for e in range(seg_on.shape[0]):
        if seg_on[e] != seg_on_search[e]:
            return False
    half = 0.5 * skin
    for p in range(x.shape[0]):
        if node_on[p] != node_on_search[p]:
            return False
        for d in range(3):
            if abs(x[p, d] - x_search[p, d]) > half:
                return False
    return True
