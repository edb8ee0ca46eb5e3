"""Nodal forces gathered from element blocks through the node → element CSR map.

Each node sums its elements' corner blocks in a fixed order, so the sum is the
same bitwise for any thread count (no scatter-add races). docs/theory.md §3.
The explicit step does this inside the node update (``integrate.gather_and_update``,
one pass over the nodes); ``gather_nodal_forces`` is the gather alone.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from wovenimpact.jit import inline_kernel, kernel, loop_kernel


@inline_kernel
def node_force_sum(n, node_ptr, node_elem, node_corner, blocks, alive):
    """Σ blocks[e, c] over the (e, c) of node n, and the number of its live elements.

    Returns (f0, …, f5, live). Row indices are unsigned (no negative-index wraparound
    check); ``alive`` is the per-element byte the force kernel writes, so the count
    does not touch the (large) element state rows.
    """
    acc0 = acc1 = acc2 = acc3 = acc4 = acc5 = 0.0
    live = 0
    for k in range(node_ptr[n], node_ptr[n + 1]):
        e = np.uint64(node_elem[k])
        c = np.uint64(node_corner[k])
        acc0 += blocks[e, c, 0]
        acc1 += blocks[e, c, 1]
        acc2 += blocks[e, c, 2]
        acc3 += blocks[e, c, 3]
        acc4 += blocks[e, c, 4]
        acc5 += blocks[e, c, 5]
        live += alive[e]
    return acc0, acc1, acc2, acc3, acc4, acc5, live


@loop_kernel
def gather_nodal_forces(node_ptr, node_elem, node_corner, blocks, alive, out, live_count):
    """out[n] = Σ blocks[e, c] over the (e, c) of node n; live_count[n] = its live elements.

    Args:
        node_ptr, node_elem, node_corner: CSR map (Model).
        blocks: (n_elems, 4, 6) element corner forces and moments.
        alive: (n_elems,) uint8, 1 for a live element (written by the force kernel).
        out: (n_nodes, 6) written.
        live_count: (n_nodes,) written.
    """
    nn = node_ptr.shape[0] - 1
    for n in prange(nn):
        f0, f1, f2, f3, f4, f5, live = node_force_sum(
            np.uint64(n), node_ptr, node_elem, node_corner, blocks, alive
        )
        out[n, 0] = f0
        out[n, 1] = f1
        out[n, 2] = f2
        out[n, 3] = f3
        out[n, 4] = f4
        out[n, 5] = f5
        live_count[n] = live


@loop_kernel
def nodes_with_live_elements(node_ptr, node_elem, alive, node_active, out):
    """out[n] = 1 if node n is active and has a live element (``alive``, uint8 per
    element), else 0: the nodes that survive this step's erosion."""
    nn = node_ptr.shape[0] - 1
    for n in prange(nn):
        live = 0
        if node_active[n] != 0:
            for k in range(node_ptr[n], node_ptr[n + 1]):
                live += alive[node_elem[k]]
        out[n] = 1 if live > 0 else 0


@kernel
def node_sum(values):
    """Σ values[n] in node order (serial, deterministic; no BLAS threads)."""
    s = 0.0
    for n in range(values.shape[0]):
        s += values[n]
    return s
