"""Shell–shell general contact ("plies on plies"): the Python driver of the contact kernels.

:class:`ShellContact` owns the buffers and parameters; :mod:`wovenimpact.kernels.
contact_broad` finds candidate (node, segment) pairs, :mod:`wovenimpact.kernels.
contact_narrow` turns them into penalty (and friction) forces. MODEL.md §4.
"""

from __future__ import annotations

import math

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels.contact_broad import (
    bucket_count,
    candidates_still_valid,
    contact_masks,
    find_candidates,
)
from wovenimpact.kernels.contact_narrow import (
    N_GEO,
    N_SEG_GEO,
    assemble_contact_forces,
    initial_overlap,
    penalty_forces,
    segment_geometry,
)


class ShellContact:
    """Node-to-segment penalty contact between shell plies, both passes, with offsets.

    Usage in a time loop (nothing is written to the State; ``out_force`` is the
    caller's array)::

        contact = ShellContact(model, beta=0.1, damping=0.3, friction=0.0)  # once
        ...
        energy, n_active = contact.forces(state.x, state.v, dt,
                                          state.elem[:, E_ALIVE], state.node_active,
                                          f_contact)                 # every step
        # f_contact[:, :3]: contact force on each node (N); add it to the external
        # forces before the central-difference update.

    ``forces(x, v, dt, elem_alive, node_active, out_force, accumulate=False)
    -> (energy, n_active)``

    - x: (n_nodes, 3) positions x^n; v: (n_nodes, 3) velocities (v^{n−1/2}: only
      used by friction, for the relative tangential velocity).
    - dt: the step the forces are for (Δt^{n+1/2}, or the last step if the new one is
      not known yet: it only scales the penalty stiffness k = β m / Δt²), > 0.
    - elem_alive: (n_elems,) nonzero for live elements (e.g. ``state.elem[:, E_ALIVE]``);
      eroded elements are no longer segments.
    - node_active: (n_nodes,) nonzero for active nodes; inactive nodes are skipped.
    - out_force: (n_nodes, ≥ 3) float array: columns 0–2 are overwritten with the
      contact force on every node (zero away from contact), or added to with
      ``accumulate=True`` (e.g. straight into ``f_ext``); other columns are untouched.
    - returns the contact energy Σ ½ k g² (J, summed in a fixed order) and the number
      of active (penetrating) pairs.

    The forces of every pair sum to zero (momentum), frictionless pairs carry no
    moment, and the result is bitwise independent of the thread count. No array is
    allocated unless the pair buffers overflow: they then grow (×1.5 the need) and
    the search is redone inside the same call, so the caller never redoes a step;
    ``grow_count`` counts these events.

    Candidate reuse (Verlet lists): ``forces`` searches with the boxes inflated by a
    ``skin`` on top of the margin and keeps those candidates while no node has moved
    more than skin/2 along any axis since that search and no segment or node has left
    the surfaces (:func:`~wovenimpact.kernels.contact_broad.candidates_still_valid`);
    they are then a superset of a fresh search's, and the narrow phase first repeats
    the fresh search's box test, so the same pairs give the same forces (bitwise but
    for the order in which a node's or a segment's pair forces are summed, which
    follows the search's bucket order; the 4-ply 120 m/s history is identical). ``searches``
    counts the searches. The persistent state is ``overlap``, computed once from the
    initial configuration (deterministic, so a restart rebuilding this object from
    the same Model gets the same one), and the reused candidates, which do not change
    the forces.

    Model (positional): uses ``quads``, ``ply``, ``node_mass``, ``node_ptr``,
    ``node_elem``, ``sections[:, C_THICK]``, ``elem_section`` and ``x0``.

    Keyword parameters:
        beta: penalty scale β of k = β min(m_node, m̄_segment) / Δt² (0 < β ≤ 0.5; 0.1).
        damping: ζ, the pair dashpot as a fraction of critical 2 √(k m_red) (0–2;
            default 0.3: struck plies part at about 15 % of their closing speed,
            theory §6.3).
        friction: Coulomb coefficient μ ≥ 0 (0: frictionless, the default).
        plies: the plies taking part (default all); or
        elements: the element indices taking part (overrides ``plies``).
        self_contact: also pair a ply's nodes with its own non-adjacent segments
            (default False: only different plies meet).
        margin: extra inflation of the search boxes (m, default 0).
        skin: the Verlet skin of candidate reuse (m, ≥ 0; 0 searches at every call).
            Default: the largest offset h_s, half a shell thickness. Measured on 4
            plies at 120 m/s (plies one thickness apart, ms per step, 2 threads):
            skin 0: 14.9; t/5: 11.0; t/2: 9.5; t: 14.2 (the boxes then reach the
            next ply but one and the candidates grow fivefold).
        remove_initial_overlap: measure the initial penetration of each node
            (``overlap``, m) and subtract it from its offset, so that the initial gaps
            are ≥ 0 and no force acts at t = 0 (default True). Kept constant.
        x_initial: the configuration of that measure (default ``model.x0``).
        capacity: initial pair capacity (default 8 per contact node).

    Offsets: segment offset h_s = t_e / 2 of its element; node offset h_p = the largest
    t_e / 2 of the taking-part elements around it.
    """

    def __init__(
        self,
        model,
        *,
        beta: float = 0.1,
        damping: float = 0.3,
        friction: float = 0.0,
        plies=None,
        elements=None,
        self_contact: bool = False,
        margin: float = 0.0,
        skin: float | None = None,
        remove_initial_overlap: bool = True,
        x_initial=None,
        capacity: int | None = None,
    ) -> None:
        if not (math.isfinite(beta) and 0.0 < beta <= 0.5):
            raise InputError(f"contact beta = {beta!r}; valid: 0 < β ≤ 0.5 (default 0.1)")
        if not (math.isfinite(damping) and 0.0 <= damping <= 2.0):
            raise InputError(f"contact damping = {damping!r}; valid: 0 ≤ ζ ≤ 2 (a fraction of "
                             "critical damping; default 1)")
        if not (math.isfinite(friction) and friction >= 0.0):
            raise InputError(f"contact friction = {friction!r}; valid: a coefficient μ ≥ 0")
        if not (math.isfinite(margin) and margin >= 0.0):
            raise InputError(f"contact margin = {margin!r} m; valid: ≥ 0")
        self.beta = float(beta)
        self.damping = float(damping)
        self.friction = float(friction)
        self.self_contact = bool(self_contact)
        self.margin = float(margin)
        quads = np.ascontiguousarray(model.quads, dtype=np.int64)
        ne, nn = quads.shape[0], model.x0.shape[0]
        part = np.zeros(ne, dtype=np.int8)
        if elements is not None:
            idx = np.asarray(elements, dtype=np.int64).ravel()
            if idx.size and (idx.min() < 0 or idx.max() >= ne):
                raise InputError(f"contact elements refer to element {int(idx.max())}; "
                                 f"valid: 0 ≤ index < {ne}")
            part[idx] = 1
        elif plies is not None:
            wanted = np.asarray(plies, dtype=np.int64).ravel()
            unknown = sorted(set(wanted.tolist()) - set(np.unique(model.ply).tolist()))
            if unknown:
                raise InputError(f"contact plies {unknown} do not exist; the model has plies "
                                 f"{np.unique(model.ply).tolist()}")
            part[np.isin(model.ply, wanted)] = 1
        else:
            part[:] = 1
        self.quads = quads
        self.ply = np.ascontiguousarray(model.ply, dtype=np.int64)
        self.elem_part = part
        self.node_mass = np.ascontiguousarray(model.node_mass, dtype=float)
        self.node_ptr = np.ascontiguousarray(model.node_ptr, dtype=np.int64)
        self.node_elem = np.ascontiguousarray(model.node_elem, dtype=np.int64)
        self.h_seg = 0.5 * model.sections[model.elem_section, SL.C_THICK].astype(float)
        self.h_node = np.zeros(nn)
        on = part != 0
        for c in range(4):
            np.maximum.at(self.h_node, quads[on, c], self.h_seg[on])
        self.node_part = np.zeros(nn, dtype=np.int8)
        self.node_part[quads[on].ravel()] = 1
        if skin is None:
            skin = float(self.h_seg[on].max()) if on.any() else 0.0
        if not (math.isfinite(skin) and skin >= 0.0):
            raise InputError(f"contact skin = {skin!r} m; valid: ≥ 0")
        self.skin = float(skin)
        # the configuration and masks of the last search of forces(); no search yet
        self.x_search = np.zeros((nn, 3))
        self.seg_on_search = np.zeros(ne, dtype=np.int8)
        self.node_on_search = np.zeros(nn, dtype=np.int8)
        self.searched = False
        self.searches = 0
        # fixed-size scratch
        self.seg_on = np.zeros(ne, dtype=np.int8)
        self.node_on = np.zeros(nn, dtype=np.int8)
        self.box = np.zeros((ne, 6))
        self.seg_geo = np.zeros((ne, N_SEG_GEO))  # the narrow phase's segment table at x
        self.bucket_ptr = np.zeros(bucket_count(ne) + 1, dtype=np.int64)
        self.bucket_seg = np.zeros(ne, dtype=np.int64)
        self.bucket_cell = np.zeros((ne, 3), dtype=np.int64)
        self.bucket_box = np.zeros((ne, 6))
        self.pair_ptr = np.zeros(nn + 1, dtype=np.int64)
        self.seg_ptr = np.zeros(nn + 1, dtype=np.int64)
        self.cursor = np.zeros(nn, dtype=np.int64)
        self.node_f = np.zeros((nn, 3))
        self.overlap = np.zeros(nn)
        self.grow_count = 0
        self.n_pairs = 0
        self.cell = (0.0, 0.0, 0.0)
        if capacity is None:
            capacity = max(64, 8 * int(self.node_part.sum()))
        self._alloc_pairs(capacity)
        if remove_initial_overlap:
            x = model.x0 if x_initial is None else np.ascontiguousarray(x_initial, dtype=float)
            contact_masks(np.ones(ne, dtype=np.int8), part, np.ones(nn, dtype=np.int8),
                          self.node_part, self.seg_on, self.node_on)
            self._search(x, self.margin)
            segment_geometry(x, self.quads, self.seg_on, self.seg_geo)
            initial_overlap(x, self.quads, self.ply, self.h_node, self.h_seg, self.margin,
                            self.seg_geo, self.pair_ptr, self.pair_seg, self.geo,
                            self.pair_on, self.overlap)

    @property
    def capacity(self) -> int:
        """Pairs the buffers hold before growing."""
        return self.pair_seg.shape[0]

    def _alloc_pairs(self, capacity: int) -> None:
        cap = int(capacity)
        self.pair_seg = np.zeros(cap, dtype=np.int64)
        self.geo = np.zeros((cap, N_GEO))
        self.pair_on = np.zeros(cap, dtype=np.int8)
        self.pair_f = np.zeros((cap, 3))
        self.pair_w = np.zeros((cap, 4))
        self.pair_e = np.zeros(cap)
        self.seg_entry = np.zeros(4 * cap, dtype=np.int64)

    def _search(self, x, margin: float) -> int:
        """Candidates at x with boxes inflated by ``margin`` on top of the offsets into
        pair_ptr/pair_seg (seg_on/node_on set); grows on overflow."""
        while True:
            n, l0, l1, l2 = find_candidates(
                x, self.quads, self.ply, self.seg_on, self.node_on, self.h_node, self.h_seg,
                margin, 0.0, self.self_contact, self.node_ptr, self.node_elem, self.box,
                self.bucket_ptr, self.bucket_seg, self.bucket_cell, self.bucket_box,
                self.pair_ptr, self.pair_seg,
            )
            if n <= self.capacity:
                break
            self._alloc_pairs(int(1.5 * n) + 64)
            self.grow_count += 1
        self.n_pairs = int(n)
        self.cell = (l0, l1, l2)
        return self.n_pairs

    def candidates(self, x, elem_alive=None, node_active=None) -> tuple[np.ndarray, np.ndarray]:
        """Candidate pairs (node, segment) at x, node-major (copies; for tests/diagnostics)."""
        ne, nn = self.quads.shape[0], self.node_part.shape[0]
        alive = np.ones(ne, dtype=np.int8) if elem_alive is None else elem_alive
        active = np.ones(nn, dtype=np.int8) if node_active is None else node_active
        contact_masks(alive, self.elem_part, active, self.node_part, self.seg_on, self.node_on)
        n = self._search(np.ascontiguousarray(x, dtype=float), self.margin)
        self.searched = False  # the lists of forces() are gone
        nodes = np.repeat(np.arange(nn, dtype=np.int64), np.diff(self.pair_ptr))
        return nodes, self.pair_seg[:n].copy()

    def forces(self, x, v, dt, elem_alive, node_active, out_force, accumulate=False):
        """Contact forces at (x, v) for a step dt into ``out_force[:, :3]``; returns
        (energy J, active pairs). See the class docstring."""
        if not dt > 0.0:
            raise ValueError(f"contact forces need a time step dt > 0, got {dt!r}")
        contact_masks(elem_alive, self.elem_part, node_active, self.node_part,
                      self.seg_on, self.node_on)
        if not (self.searched and candidates_still_valid(
                x, self.x_search, self.node_on, self.node_on_search, self.seg_on,
                self.seg_on_search, self.skin)):
            self._search(x, self.margin + self.skin)
            self.x_search[:] = x
            self.seg_on_search[:] = self.seg_on
            self.node_on_search[:] = self.node_on
            self.searched = self.skin > 0.0
            self.searches += 1
        segment_geometry(x, self.quads, self.seg_on, self.seg_geo)
        penalty_forces(
            x, v, self.quads, self.ply, self.node_mass, self.h_node, self.h_seg, self.margin,
            self.overlap, self.beta, self.damping, self.friction, float(dt), self.seg_geo,
            self.pair_ptr, self.pair_seg,
            self.geo, self.pair_on, self.pair_f, self.pair_w, self.pair_e, self.node_f,
        )
        energy, n_active = assemble_contact_forces(
            self.quads, self.pair_ptr, self.pair_seg, self.pair_on, self.pair_f, self.pair_w,
            self.pair_e, self.node_f, self.seg_ptr, self.seg_entry, self.cursor,
            out_force, bool(accumulate),
        )
        return float(energy), int(n_active)
