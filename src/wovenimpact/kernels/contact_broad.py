"""Broad phase of the shell–shell contact: hashed uniform-grid bucket search (MODEL.md §4).

Candidates are (node, segment) pairs, a segment being the quad of a live element
that takes part in contact. A node p (offset h_p, the half-thickness of its shell) is
a candidate of segment s (offset h_s) when it lies in the segment's axis-aligned box
inflated by the two offsets and a margin m:

    min_I x_I,d − r ≤ p_d ≤ max_I x_I,d + r,    r = h_s + h_p + m,   d = x, y, z,

and is neither a node of s nor of an element of the same ply as s (with
``self_contact`` on: of an element of the same ply sharing a node with s). The
narrow phase (:mod:`contact_narrow`) then measures the exact gap.

Search (cost linear in nodes + segments):

1. boxes: per segment, its raw box [b_min, b_max] and its bin corner
   c_s = b_min − (h_s + H + m), H = max h_p; the largest inflated box along each
   axis E_d = (1 + 1e-9) · max_s (b_max − b_min + 2 (h_s + H + m))_d and the cell
   edge L_d = E_d (at least ``cell_min``);
2. buckets: each segment goes into the cell floor(c_s / L), and cells are hashed
   into a table of 2^k buckets; a counting sort over bucket indices (segments in
   increasing order inside a bucket) builds the bucket CSR — deterministic;
3. queries: a node p can only be a candidate of segments with p − E ≤ c_s ≤ p,
   binned in the cells floor((p − E)/L) … floor(p/L) per axis (at most 2 per axis
   when L = E: 8 cells). Each bucket entry is checked against the
   segment's true cell (so hash collisions cost time, never duplicates), then the
   exact box test and the exclusion test. A counting pass gives each node's
   number of candidates, a serial prefix sum their offsets, and a writing pass
   fills them: the output is node-major (a CSR ``pair_ptr``/``pair_seg``) and the
   same for any thread count. When the total exceeds the capacity of
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
CELL_SLACK = 1e-9  # relative margin over the largest inflated box E
CELL_FRACTION = 1.0  # cell edge L = E: 2 cells per axis to visit (E/2: 3 smaller cells
# per axis scan fewer segments but measured ~15 % slower, the 27 hash lookups dominate)


@inline_kernel
def cell_bucket(ix, iy, iz, mask):
    """Bucket of cell (ix, iy, iz): (ix P1 ⊕ iy P2 ⊕ iz P3) & mask (int64 wraparound)."""
    return ((ix * _P1) ^ (iy * _P2) ^ (iz * _P3)) & mask


@inline_kernel
def segment_cell(box, s, pad, l0, l1, l2):
    """Cell of segment s: floor((b_min − pad) / L) per axis, pad = h_s + H + m."""
    return (
        np.int64(math.floor((box[s, 0] - pad) / l0)),
        np.int64(math.floor((box[s, 1] - pad) / l1)),
        np.int64(math.floor((box[s, 2] - pad) / l2)),
    )


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


@loop_kernel
def find_candidates(
    x, quads, ply, seg_on, node_on, h_node, h_seg, margin, cell_min, self_contact,
    node_ptr, node_elem, box, bucket_ptr, bucket_seg, bucket_cell, bucket_box, pair_ptr,
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
        cell_min: smallest cell edge (m); by default (0) the largest inflated box.
        self_contact: 0: no pair within one ply; 1: pairs within a ply unless the node's
            element shares a node with the segment.
        node_ptr, node_elem: node → element CSR (Model).
        box: (n_elems, 6) scratch: b_min, b_max of each segment.
        bucket_ptr: (n_buckets + 1,) int64 scratch, n_buckets a power of two.
        bucket_seg: (n_elems,) int64 scratch: segments in bucket order, with
        bucket_cell: (n_elems, 3) int64 and bucket_box: (n_elems, 6) scratch: their
            cells and boxes in the same order (a bucket is scanned contiguously).
        pair_ptr: (n_nodes + 1,) int64 written: candidates of node p are
            pair_seg[pair_ptr[p]:pair_ptr[p + 1]].
        pair_seg: (capacity,) int64 written when the total fits.

    Returns:
        (n_pairs, L_x, L_y, L_z): total candidates (> capacity: overflow, pair_seg not
        written) and the cell edges used.
    """
    n_nodes = x.shape[0]
    n_el = quads.shape[0]
    n_buckets = bucket_ptr.shape[0] - 1
    mask = n_buckets - 1
    h_max = 0.0
    for p in range(n_nodes):
        if node_on[p] != 0 and h_node[p] > h_max:
            h_max = h_node[p]
    # 1. raw boxes of the live segments
    for s in prange(n_el):
        if seg_on[s] == 0:
            continue
        lo0 = hi0 = x[quads[s, 0], 0]
        lo1 = hi1 = x[quads[s, 0], 1]
        lo2 = hi2 = x[quads[s, 0], 2]
        for a in range(1, 4):
            q = quads[s, a]
            lo0 = min(lo0, x[q, 0])
            hi0 = max(hi0, x[q, 0])
            lo1 = min(lo1, x[q, 1])
            hi1 = max(hi1, x[q, 1])
            lo2 = min(lo2, x[q, 2])
            hi2 = max(hi2, x[q, 2])
        box[s, 0] = lo0
        box[s, 1] = lo1
        box[s, 2] = lo2
        box[s, 3] = hi0
        box[s, 4] = hi1
        box[s, 5] = hi2
    # cell size: the largest inflated box along each axis
    ext0 = ext1 = ext2 = 0.0
    for s in range(n_el):
        if seg_on[s] == 0:
            continue
        pad = 2.0 * (h_seg[s] + h_max + margin)
        ext0 = max(ext0, box[s, 3] - box[s, 0] + pad)
        ext1 = max(ext1, box[s, 4] - box[s, 1] + pad)
        ext2 = max(ext2, box[s, 5] - box[s, 2] + pad)
    ext0 *= 1.0 + CELL_SLACK
    ext1 *= 1.0 + CELL_SLACK
    ext2 *= 1.0 + CELL_SLACK
    floor_len = max(cell_min, 1e-9 * max(ext0, ext1, ext2), 1e-300)
    l0 = max(CELL_FRACTION * ext0, floor_len)
    l1 = max(CELL_FRACTION * ext1, floor_len)
    l2 = max(CELL_FRACTION * ext2, floor_len)
    # 2. bucket lists (counting sort by bucket; segments in increasing order)
    for b in range(n_buckets + 1):
        bucket_ptr[b] = 0
    for s in range(n_el):
        if seg_on[s] == 0:
            continue
        ix, iy, iz = segment_cell(box, s, h_seg[s] + h_max + margin, l0, l1, l2)
        bucket_ptr[cell_bucket(ix, iy, iz, mask) + 1] += 1
    for b in range(n_buckets):
        bucket_ptr[b + 1] += bucket_ptr[b]
    # fill in segment order, bucket_ptr[b] serving as the cursor of bucket b (it ends
    # at the end of b, i.e. the start of b + 1), then shift back by one
    for s in range(n_el):
        if seg_on[s] == 0:
            continue
        ix, iy, iz = segment_cell(box, s, h_seg[s] + h_max + margin, l0, l1, l2)
        b = cell_bucket(ix, iy, iz, mask)
        k = bucket_ptr[b]
        bucket_seg[k] = s
        bucket_cell[k, 0] = ix
        bucket_cell[k, 1] = iy
        bucket_cell[k, 2] = iz
        for c in range(6):
            bucket_box[k, c] = box[s, c]
        bucket_ptr[b] = k + 1
    for b in range(n_buckets, 0, -1):  # shift back: bucket_ptr[b] = start of b
        bucket_ptr[b] = bucket_ptr[b - 1]
    bucket_ptr[0] = 0
    # 3. queries: count, prefix sum, write
    capacity = pair_seg.shape[0]
    for sweep in range(2):
        write = sweep == 1
        for p in prange(n_nodes):
            count = 0
            if node_on[p] != 0:
                base = pair_ptr[p] if write else 0
                jx = np.int64(math.floor(x[p, 0] / l0))
                jy = np.int64(math.floor(x[p, 1] / l1))
                jz = np.int64(math.floor(x[p, 2] / l2))
                ix = np.int64(math.floor((x[p, 0] - ext0) / l0))
                iy = np.int64(math.floor((x[p, 1] - ext1) / l1))
                iz = np.int64(math.floor((x[p, 2] - ext2) / l2))
                for cx in range(ix, jx + 1):
                    for cy in range(iy, jy + 1):
                        for cz in range(iz, jz + 1):
                            b = cell_bucket(cx, cy, cz, mask)
                            for k in range(bucket_ptr[b], bucket_ptr[b + 1]):
                                if (bucket_cell[k, 0] != cx or bucket_cell[k, 1] != cy
                                        or bucket_cell[k, 2] != cz):
                                    continue  # another cell hashed into this bucket
                                s = bucket_seg[k]
                                r = h_seg[s] + h_node[p] + margin
                                if not in_inflated_box(x, p, bucket_box, k, r):
                                    continue
                                if excluded_pair(p, s, quads, ply, node_ptr, node_elem,
                                                 self_contact):
                                    continue
                                if write:
                                    pair_seg[base + count] = s
                                count += 1
            if not write:
                pair_ptr[p + 1] = count
        if not write:
            pair_ptr[0] = 0
            for p in range(n_nodes):
                pair_ptr[p + 1] += pair_ptr[p]
            if pair_ptr[n_nodes] > capacity:
                break
    return pair_ptr[n_nodes], l0, l1, l2


def bucket_count(n_segments: int) -> int:
    """Hash-table size for ``n_segments`` segments: the power of two ≥ 2 n (at least 64)."""
    return 1 << max(6, int(math.ceil(math.log2(max(2 * n_segments, 1)))))


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
