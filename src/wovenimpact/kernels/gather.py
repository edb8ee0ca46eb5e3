"""Nodal forces gathered from element blocks through the node → element CSR map.

Each node sums its elements' corner blocks in a fixed order, so the sum is the
same bitwise for any thread count (no scatter-add races). docs/theory.md §3.
"""

from __future__ import annotations

import numpy as np
from numba import prange

from wovenimpact.jit import loop_kernel
from wovenimpact.kernels.shell_layout import E_ALIVE


@loop_kernel
def gather_nodal_forces(node_ptr, node_elem, node_corner, blocks, elem, out, live_count):
    """out[n] = Σ blocks[e, c] over the (e, c) of node n; live_count[n] = its live elements.

    Args:
        node_ptr, node_elem, node_corner: CSR map (Model).
        blocks: (n_elems, 4, 6) element corner forces and moments.
        elem: (n_elems, N_ELEM_STATE) element state (for the alive flag).
        out: (n_nodes, 6) written.
        live_count: (n_nodes,) written.
    """
    nn = node_ptr.shape[0] - 1
    for n in prange(nn):
        acc0 = acc1 = acc2 = acc3 = acc4 = acc5 = 0.0
        live = 0
        for k in range(node_ptr[n], node_ptr[n + 1]):
            e = np.uint64(node_elem[k])  # unsigned: no negative-index wraparound
            c = np.uint64(node_corner[k])
            acc0 += blocks[e, c, 0]
            acc1 += blocks[e, c, 1]
            acc2 += blocks[e, c, 2]
            acc3 += blocks[e, c, 3]
            acc4 += blocks[e, c, 4]
            acc5 += blocks[e, c, 5]
            if elem[e, E_ALIVE] != 0.0:
                live += 1
        out[n, 0] = acc0
        out[n, 1] = acc1
        out[n, 2] = acc2
        out[n, 3] = acc3
        out[n, 4] = acc4
        out[n, 5] = acc5
        live_count[n] = live
