"""Incremental update of the contact candidate lists (theory §6, "incremental search").

The broad phase (:mod:`contact_broad`) lists, for every node p, the segments whose padded
box and plane meet p's box x_search,p ± (h_p + σ_p), and the lists are reused while every
node stays within its skin: |x_p − x_search,p| ≤ σ_p. When a few nodes F leave their
skins, a full search re-bins every segment and re-queries every node. This module does
only what their leaving requires:

1. ``nodes_beyond_skins``: F, the nodes on the surfaces farther than σ_p from x_search,p,
   and with them, once one is, those that would leave within a few steps at their
   speed (re-anchoring a node early is always allowed).
2. ``refresh_far_nodes``: each q ∈ F gets x_search,q = x_q and a new skin σ_q; the live
   segments with a node in F (S_F, ``seg_new``) get new padded boxes and planes
   (:func:`contact_broad.segment_boxes` at x_search, with their other nodes' old
   x_search and σ: each of those is still within its σ of its x_search, so the box
   still bounds the segment until one of them leaves too). ``seg_moved`` accumulates
   S_F over the updates since the last full search.
3. ``mark_requery``: R = F ∪ {nodes whose box meets the new box and plane of a segment
   of S_F}. A node outside R keeps a complete list: every segment that was not
   re-boxed has the box it had when that node was last queried, and a re-boxed one
   that meets its box would have put it in R.
4. ``requery_candidates``: the nodes of R are queried at x_search against the bins of
   the last full search, passing over the moved segments (their binned boxes are
   stale), plus the moved segments binned alone with their current boxes (the same
   cell edge, so the one-cell rule still takes each pair once).
5. ``splice_candidates``: the node-major CSR with R's new lists in place of their old
   ones, every list still in increasing segment order.

A list may now hold segments that a fresh search would not (one that moved away from a
node outside R): the narrow phase repeats the box and plane tests at x without skins
and breaks ties by the lower segment index, so it keeps the same pairs from any list
that holds them, and the forces stay bitwise those of a search at every step.
"""

from __future__ import annotations

import math

from numba import prange

from wovenimpact.jit import kernel, loop_kernel
from wovenimpact.kernels.contact_broad import (
    SB_HI,
    SB_LO,
    SP_D,
    SP_SLACK,
    TOLERANCE,
    cell_bucket,
    cell_of,
    running_total,
    scan_node,
    sort_ascending,
)


@loop_kernel
def nodes_beyond_skins(x, x_search, sigma, node_on, v, ahead, far):
    """far[p] = 1 for every node on the surfaces with |x_p − x_search,p| > σ_p; 2 for one
    within σ_p that would leave at its speed within ``ahead`` steps of Δt,
    |x_p − x_search,p| + ahead |v_p| Δt > σ_p (``ahead`` is steps × Δt, s); else 0.
    Returns the number of the first kind. An update takes the second kind along: nodes
    moving together, such as a flying fragment's, then leave their skins together
    again, one update for all instead of one at each step."""
    count = 0
    for p in prange(x.shape[0]):
        out = 0
        if node_on[p] != 0:
            dx = x[p, 0] - x_search[p, 0]
            dy = x[p, 1] - x_search[p, 1]
            dz = x[p, 2] - x_search[p, 2]
            d = math.sqrt(dx * dx + dy * dy + dz * dz)
            if d > sigma[p]:
                out = 1
            else:
                speed = math.sqrt(v[p, 0] * v[p, 0] + v[p, 1] * v[p, 1] + v[p, 2] * v[p, 2])
                if d + ahead * speed > sigma[p]:
                    out = 2
        far[p] = out
        count += 1 if out == 1 else 0
    return count


@kernel
def surfaces_joined(node_on, node_on_search, seg_on, seg_on_search):
    """True when a segment or a node is on the surfaces now and was not at the last full
    search: its pairs may be missing from every list (one that left, eroded, is passed
    over by the narrow phase)."""
    for e in range(seg_on.shape[0]):
        if seg_on[e] != 0 and seg_on_search[e] == 0:
            return True
    for p in range(node_on.shape[0]):
        if node_on[p] != 0 and node_on_search[p] == 0:
            return True
    return False


@kernel
def refresh_far_nodes(x, sigma_new, far, node_ptr, node_elem, seg_on, x_search, sigma,
                      seg_new, seg_moved, seg_side):
    """Step 2 of the module docstring: x_search and σ of the nodes of F (``far``) take
    their current position and the new skin ``sigma_new``; seg_new marks S_F (the live
    segments with a node in F), seg_moved accumulates it, and seg_side = seg_moved ∧
    seg_on (the segments to bin alone). Returns (|S_F|, number of seg_side)."""
    for e in range(seg_new.shape[0]):
        seg_new[e] = 0
    for p in range(far.shape[0]):
        if far[p] == 0:
            continue
        x_search[p, 0] = x[p, 0]
        x_search[p, 1] = x[p, 1]
        x_search[p, 2] = x[p, 2]
        sigma[p] = sigma_new[p]
        for k in range(node_ptr[p], node_ptr[p + 1]):
            e = node_elem[k]
            if seg_on[e] != 0:
                seg_new[e] = 1
                seg_moved[e] = 1
    n_new = 0
    n_side = 0
    for e in range(seg_new.shape[0]):
        n_new += seg_new[e]
        side = 1 if (seg_moved[e] != 0 and seg_on[e] != 0) else 0
        seg_side[e] = side
        n_side += side
    return n_new, n_side


@kernel
def widest_box(seg_mask, seg_box):
    """The largest extent, over the axes and the segments of ``seg_mask``, of their
    padded boxes (m)."""
    widest = 0.0
    for s in range(seg_mask.shape[0]):
        if seg_mask[s] == 0:
            continue
        for d in range(3):
            widest = max(widest, seg_box[s, SB_HI + d] - seg_box[s, SB_LO + d])
    return widest


@kernel
def meets_binned_segment(px, py, pz, reach, edge, seg_plane, bucket_ptr, entry_seg,
                         entry_cell, entry_box):
    """Whether the box p ± reach meets the padded box and the plane slab of a segment in
    the bins (any cell: only the answer matters, not which pair)."""
    mask = bucket_ptr.shape[0] - 2
    inv = 1.0 / edge
    for cx in range(cell_of(px - reach, inv), cell_of(px + reach, inv) + 1):
        for cy in range(cell_of(py - reach, inv), cell_of(py + reach, inv) + 1):
            for cz in range(cell_of(pz - reach, inv), cell_of(pz + reach, inv) + 1):
                b = cell_bucket(cx, cy, cz, mask)
                for k in range(bucket_ptr[b], bucket_ptr[b + 1]):
                    if (entry_cell[k, 0] != cx or entry_cell[k, 1] != cy
                            or entry_cell[k, 2] != cz):
                        continue
                    if (px + reach < entry_box[k, 0] or entry_box[k, 3] < px - reach
                            or py + reach < entry_box[k, 1] or entry_box[k, 4] < py - reach
                            or pz + reach < entry_box[k, 2] or entry_box[k, 5] < pz - reach):
                        continue
                    s = entry_seg[k]
                    height = (seg_plane[s, 0] * px + seg_plane[s, 1] * py
                              + seg_plane[s, 2] * pz - seg_plane[s, SP_D])
                    if abs(height) <= reach + seg_plane[s, SP_SLACK]:
                        return True
    return False


@kernel
def bounding_box(seg_mask, seg_box, out):
    """out = (lower corner, upper corner) of the padded boxes of the segments of
    ``seg_mask`` (empty, lower > upper, when there is none)."""
    for d in range(3):
        out[d] = math.inf
        out[3 + d] = -math.inf
    for s in range(seg_mask.shape[0]):
        if seg_mask[s] == 0:
            continue
        for d in range(3):
            out[d] = min(out[d], seg_box[s, SB_LO + d])
            out[3 + d] = max(out[3 + d], seg_box[s, SB_HI + d])


@loop_kernel
def mark_requery(surfaces, search, node_on, far, bounds, bins, req_pos, req_list):
    """Step 3: R = F ∪ {nodes on whose box x_search,p ± (h_p + σ_p) meets a segment of
    the bins of S_F} (``bounds``: the box around those segments, a first test).
    req_pos[p] = position of p in req_list (−1 outside R); req_list holds R in
    increasing node order. Returns |R|. ``surfaces``: kernels.bundles.ContactSurfaces
    (h_p); ``search``: kernels.bundles.ContactSearch of the last full search (x_search,
    σ); ``bins``: kernels.bundles.SegmentBinTables of S_F."""
    # the bundles' members as locals, one per statement, before the parallel loop
    x_search = search.x
    sigma = search.sigma
    seg_plane = search.seg_plane
    edge = search.edge
    h_node = surfaces.h_node
    bucket_ptr = bins.bucket_ptr
    entry_seg = bins.entry_seg
    entry_cell = bins.entry_cell
    entry_box = bins.entry_box
    n = x_search.shape[0]
    for p in prange(n):
        flag = -1
        if node_on[p] != 0:
            reach = h_node[p] + sigma[p] + TOLERANCE * edge
            px, py, pz = x_search[p, 0], x_search[p, 1], x_search[p, 2]
            if far[p] != 0:
                flag = 0
            elif (px + reach < bounds[0] or bounds[3] < px - reach
                  or py + reach < bounds[1] or bounds[4] < py - reach
                  or pz + reach < bounds[2] or bounds[5] < pz - reach):
                flag = -1
            else:
                if meets_binned_segment(x_search[p, 0], x_search[p, 1], x_search[p, 2],
                                        reach, edge, seg_plane, bucket_ptr, entry_seg,
                                        entry_cell, entry_box):
                    flag = 0
        req_pos[p] = flag
    count = 0
    for p in range(n):
        if req_pos[p] == 0:
            req_pos[p] = count
            req_list[count] = p
            count += 1
    return count


# keeps its long signature: a stage called in the loop of ``requery_candidates``, its arguments
# that loop's locals (a bundle written through in a parallel loop's body can lose its writes:
# kernels/bundles.py)
@kernel
def scan_twice(p, x, quads, ply, node_ply, h_node, sigma, self_contact, node_ptr, node_elem,
               seg_plane, edge, main_bins, skip, side_bins, no_skip, out, start, room):
    """Node p's candidates from the main bins (passing over segments marked in ``skip``)
    and the side bins; their number, the first ``room`` written to out[start:]."""
    c1 = scan_node(p, x, quads, ply, node_ply, h_node, sigma, self_contact, node_ptr,
                   node_elem, seg_plane, edge, main_bins[0], main_bins[1], main_bins[2],
                   main_bins[3], main_bins[4], skip, out, start, room)
    c2 = scan_node(p, x, quads, ply, node_ply, h_node, sigma, self_contact, node_ptr,
                   node_elem, seg_plane, edge, side_bins[0], side_bins[1], side_bins[2],
                   side_bins[3], side_bins[4], no_skip, out, start + c1, max(room - c1, 0))
    return c1 + c2


@loop_kernel
def requery_candidates(req_list, n_req, surfaces, search, main_bins, skip, side_bins, no_skip,
                       slots, out):
    """Step 4: the candidates of the nodes req_list[:n_req] at the search's positions,
    node-major in ``out`` (kernels.bundles.Candidates, req_ptr/req_seg; each list in
    increasing segment order). ``surfaces``: kernels.bundles.ContactSurfaces;
    ``search``: kernels.bundles.ContactSearch of the last full search; ``main_bins`` and
    ``side_bins``: kernels.bundles.SegmentBinTables. Returns the total; when it exceeds
    req_seg's size nothing is written but req_ptr (the caller grows req_seg and calls
    again)."""
    # the bundles' members as locals, one per statement, before the parallel loops
    x_search = search.x
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
    req_ptr = out.ptr
    req_seg = out.seg
    room = slots.shape[1]
    flat = slots.reshape(-1)
    for i in prange(n_req):
        req_ptr[i + 1] = scan_twice(req_list[i], x_search, quads, ply, node_ply, h_node,
                                    sigma, self_contact, node_ptr, node_elem, seg_plane,
                                    edge, main_bins, skip, side_bins, no_skip, flat,
                                    i * room, room)
    if running_total(req_ptr, n_req) > req_seg.shape[0]:
        return req_ptr[n_req]
    for i in prange(n_req):
        base, count = req_ptr[i], req_ptr[i + 1] - req_ptr[i]
        if count <= room:
            for j in range(count):
                req_seg[base + j] = slots[i, j]
        else:
            scan_twice(req_list[i], x_search, quads, ply, node_ply, h_node, sigma,
                       self_contact, node_ptr, node_elem, seg_plane, edge, main_bins, skip,
                       side_bins, no_skip, req_seg, base, count)
        sort_ascending(req_seg, base, base + count)
    return req_ptr[n_req]


@loop_kernel
def splice_candidates(pair_ptr, pair_seg, req_pos, req_ptr, req_seg, new_ptr, new_seg):
    """Step 5: new_ptr/new_seg = the lists of pair_ptr/pair_seg with those of the nodes of
    R (req_pos[p] ≥ 0) replaced by req_ptr/req_seg's. Returns the total; when it exceeds
    new_seg's size only new_ptr is written."""
    n = req_pos.shape[0]
    for p in prange(n):
        i = req_pos[p]
        if i >= 0:
            new_ptr[p + 1] = req_ptr[i + 1] - req_ptr[i]
        else:
            new_ptr[p + 1] = pair_ptr[p + 1] - pair_ptr[p]
    if running_total(new_ptr, n) > new_seg.shape[0]:
        return new_ptr[n]
    for p in prange(n):
        i = req_pos[p]
        dst = new_ptr[p]
        if i >= 0:
            src, count = req_ptr[i], req_ptr[i + 1] - req_ptr[i]
            for j in range(count):
                new_seg[dst + j] = req_seg[src + j]
        else:
            src, count = pair_ptr[p], pair_ptr[p + 1] - pair_ptr[p]
            for j in range(count):
                new_seg[dst + j] = pair_seg[src + j]
    return new_ptr[n]
