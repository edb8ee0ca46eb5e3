"""Shell–shell general contact ("plies on plies"), and the solids' faces (docs/solid.md §6):
the Python driver of the contact kernels.

:class:`ShellContact` owns the buffers and parameters; :mod:`wovenimpact.kernels.
contact_broad` finds candidate (node, segment) pairs, :mod:`wovenimpact.kernels.
contact_narrow` turns them into penalty (and friction) forces. docs/model.md §4.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels.bundles import (
    Candidates,
    ContactLaw,
    ContactSearch,
    ContactSurfaces,
    EnergyBooks,
    PairTables,
    SegmentBinTables,
)
from wovenimpact.kernels.contact_broad import (
    N_SEG_BOX,
    N_SEG_PLANE,
    REUSE_STEPS,
    SKIN_FLOOR,
    bin_segments,
    MAX_CELLS_PER_AXIS,
    bucket_count,
    cell_edge,
    contact_masks,
    node_skins,
    query_candidates,
    segment_boxes,
)
from wovenimpact.kernels.contact_update import (
    bounding_box,
    mark_requery,
    nodes_beyond_skins,
    refresh_far_nodes,
    requery_candidates,
    splice_candidates,
    surfaces_joined,
    widest_box,
)
from wovenimpact.kernels.contact_energy import (
    N_KINDS,
    book_compact,
    book_shell_pairs,
    shell_pair_powers,
)
from wovenimpact.kernels.contact_narrow import (
    N_GEO,
    N_SEG_GEO,
    assemble_contact_forces,
    initial_overlap,
    penalty_forces,
    segment_geometry,
)


CANDIDATE_SLOTS = 16  # candidates per node kept from the search's counting pass
CONTACT_CHUNK = 512  # iterations (nodes, segments) per chunk of the contact's parallel loops
# an incremental update (contact_update) instead of a full search while the nodes that
# left their skins, and the segments re-boxed since the last full search, are at most
# INCREMENTAL_FRACTION of those on the surfaces, or INCREMENTAL_FLOOR (small models)
INCREMENTAL_FRACTION = 0.125
INCREMENTAL_FLOOR = 256
# an update also re-anchors the nodes that would leave their skins within this many
# steps at their speed
AHEAD_STEPS = 4.0
# the laws of the pair dashpot (theory §6): on the relative normal velocity whenever the
# pair overlaps, or only while it closes
DAMPING_MODES = ("always", "approach")
# the energy books recompute the acting pairs' powers in parallel from this many pairs on,
# below in one serial pass with the sum (a parallel launch, 10–50 µs on a loaded 2-core
# machine, costs more than a few hundred pairs' work; the books are bitwise the same)
PARALLEL_BOOK_PAIRS = 4096


class SegmentBins:
    """Hashed-grid bins of a subset of the segments (``contact_broad.bin_segments``),
    growing on overflow: ``arrays``, a kernels.bundles.SegmentBinTables."""

    def __init__(self, capacity: int = 64) -> None:
        self._alloc(capacity)

    def _alloc(self, capacity: int) -> None:
        cap = max(64, int(capacity))
        self.arrays = SegmentBinTables(
            bucket_ptr=np.zeros(bucket_count(cap) + 1, dtype=np.int64),
            entry_seg=np.zeros(cap, dtype=np.int64),
            entry_cell=np.zeros((cap, 3), dtype=np.int64),
            entry_box=np.zeros((cap, N_SEG_BOX)), entry_ply=np.zeros(cap, dtype=np.int64))

    def fill(self, seg_mask, seg_box, ply, inv_edge: float) -> int:
        """Bin the segments of ``seg_mask``; returns the number of entries."""
        while True:
            n = bin_segments(seg_mask, seg_box, ply, inv_edge, *self.arrays)
            if n <= self.arrays[1].shape[0]:
                return n
            self._alloc(int(1.5 * n))


# a solid's face reaches this fraction of its hexahedron's depth V0 / A_face behind it: a
# node deeper than that is not pushed back out through it (the far faces of a body)
SOLID_REACH = 0.5


def solid_segments(model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The solids' contact segments (docs/solid.md §6): (faces, body, reach) — the
    exterior faces of the hexahedra (outward-ordered), the solid body of each (its
    contact surface) and its reach D = SOLID_REACH V0 / A, A the face's area at x0."""
    sp = model.solid
    faces = np.ascontiguousarray(sp.faces, dtype=np.int64)
    p = model.x0[faces]
    area = np.linalg.norm(np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]), axis=1) * 0.5
    reach = SOLID_REACH * sp.vol0[sp.face_hex] / np.maximum(area, 1e-300)
    return faces, np.ascontiguousarray(sp.body[sp.face_hex]), reach


def node_segment_map(quads: np.ndarray, n_nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """CSR map node → segments, in increasing order per node (the Model's node →
    element map, over the shells' and the solids' segments)."""
    order = np.argsort(quads.ravel(), kind="stable")
    ptr = np.zeros(n_nodes + 1, dtype=np.int64)
    np.cumsum(np.bincount(quads.ravel(), minlength=n_nodes), out=ptr[1:])
    return ptr, (order // 4).astype(np.int64)


def node_plies(node_ptr, node_elem, ply) -> np.ndarray:
    """(n_nodes,) the ply of all of a node's elements, −1 where they are of several plies
    or there are none (the broad phase's quick exclusion test)."""
    n = node_ptr.shape[0] - 1
    counts = np.diff(node_ptr)
    owner = np.repeat(np.arange(n), counts)
    plies = ply[node_elem]
    low = np.full(n, np.iinfo(np.int64).max)
    high = np.full(n, np.iinfo(np.int64).min)
    np.minimum.at(low, owner, plies)
    np.maximum.at(high, owner, plies)
    return np.where((counts > 0) & (low == high), low, -1).astype(np.int64)


def check_law(beta, damping, friction, damping_mode, margin) -> None:
    """Raise InputError unless the contact law's parameters and the search margin are
    valid (the ranges of ShellContact's keyword parameters)."""
    if not (math.isfinite(beta) and 0.0 < beta <= 0.5):
        raise InputError(f"contact beta = {beta!r}; valid: 0 < β ≤ 0.5 (default 0.1)")
    if not (math.isfinite(damping) and 0.0 <= damping <= 2.0):
        raise InputError(f"contact damping = {damping!r}; valid: 0 ≤ ζ ≤ 2 (a fraction of "
                         "critical damping; default 1)")
    if not (math.isfinite(friction) and friction >= 0.0):
        raise InputError(f"contact friction = {friction!r}; valid: a coefficient μ ≥ 0")
    if damping_mode not in DAMPING_MODES:
        raise InputError(f"contact damping_mode = {damping_mode!r}; valid: "
                         f"{' or '.join(map(repr, DAMPING_MODES))}")
    if not (math.isfinite(margin) and margin >= 0.0):
        raise InputError(f"contact margin = {margin!r} m; valid: ≥ 0")


def check_skin(skin) -> None:
    """Raise InputError unless ``skin`` is None (per-node skins) or a length ≥ 0."""
    if skin is not None and not (math.isfinite(skin) and skin >= 0.0):
        raise InputError(f"contact skin = {skin!r} m; valid: ≥ 0, or unset for the "
                         "per-node skins that follow the speed")


def shells_taking_part(model, elements, plies) -> np.ndarray:
    """(n_shells,) int8 flags of the shells taking part in contact: the ``elements``
    given, else those of the ``plies`` given, else all; InputError on an unknown one."""
    ne = model.quads.shape[0]
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
    return part


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

    Candidate reuse (Verlet lists): ``forces`` searches with every node given a skin
    σ_p and keeps those candidates while no node has moved farther than its skin since
    that search and no segment or node has joined the surfaces (one that left them,
    eroded, is passed over by the narrow phase); they then hold
    every pair that could act (the narrow phase repeats the box test of a fresh search
    and keeps the closest segment per ply and side, so the same pairs give the same
    forces, bitwise: each node's candidates are listed in segment order whatever the
    search). The default skin follows each node's speed at the search, σ_p =
    max(σ_min,p, REUSE_STEPS |v_p| Δt), σ_min,p = SKIN_FLOOR · h_p: a node at rest gets
    a quarter of its shell's thickness, a moving one what it would cover in
    REUSE_STEPS steps, so a fast blade and a casing at rest are both searched rarely
    and the lists hold the next ply, not the whole stack. ``searches`` counts the
    searches. When a few nodes have left their skins (at most INCREMENTAL_FRACTION of
    those on the surfaces, or 256), only they (with those that would leave within
    AHEAD_STEPS steps at their speed) and the nodes within reach of their segments are
    re-queried (:mod:`~wovenimpact.kernels.contact_update`, theory §6), with the same
    forces, bitwise; ``updates`` counts these incremental updates, and a segment or node
    joining the surfaces, too many nodes out or too many segments re-boxed since the
    last full search still force one (``search_causes`` counts why). The
    persistent state is ``overlap``, computed once from the initial
    configuration (deterministic, so a restart rebuilding this object from the same
    Model gets the same one), and the reused candidates, which do not change the forces.

    Model (positional): uses ``quads``, ``ply``, ``node_mass``, ``node_ptr``,
    ``node_elem``, ``sections[:, C_THICK]``, ``elem_section`` and ``x0``.

    Keyword parameters:
        beta: penalty scale β of k = β min(m_node, m̄_segment) / Δt² (0 < β ≤ 0.5; 0.1).
        damping: ζ, the pair dashpot as a fraction of critical 2 √(k m_red) (0–2;
            default 0.3: struck plies part at about 15 % of their closing speed,
            theory §6.3).
        damping_mode: "always" (default): the dashpot acts on the relative normal
            velocity while the pair overlaps, closing or separating; "approach": only
            while it closes (v_n < 0), so that a rebound is not damped (theory §6).
        friction: Coulomb coefficient μ ≥ 0 (0: frictionless, the default).
        plies: the plies taking part (default all); or
        elements: the element indices taking part (overrides ``plies``).
        self_contact: also pair a ply's nodes with its own non-adjacent segments
            (default False: only different plies meet).
        margin: extra inflation of the search boxes (m, default 0).
        skin: a uniform Verlet skin of candidate reuse: every node may move skin/2
            (m, ≥ 0; 0 searches at every call). Default (None): the per-node skins
            that follow the speed (above).
        remove_initial_overlap: measure the initial penetration of each node
            (``overlap``, m) and subtract it from its offset, so that the initial gaps
            are ≥ 0 and no force acts at t = 0 (default True). Kept constant.
        x_initial: the configuration of that measure (default ``model.x0``).
        capacity: initial pair capacity (default 8 per contact node).

    Offsets: segment offset h_s = t_e / 2 of its element; node offset h_p = the largest
    t_e / 2 of the taking-part elements around it.

    Solids (docs/solid.md §6): the exterior faces of the Model's hexahedra are segments
    after the shells' (``n_shells`` of them first), one-sided (``one_sided``), each
    connected body a surface labelled after the shells' plies; a face's h_s is its reach
    SOLID_REACH · V0 / A, a node of solids only has h_p = 0 (its skins follow its faces'
    reach). ``elements``/``plies`` select among the shells; the faces always take part.
    """

    def __init__(
        self,
        model,
        *,
        beta: float = 0.1,
        damping: float = 0.3,
        friction: float = 0.0,
        damping_mode: str = "always",
        plies=None,
        elements=None,
        self_contact: bool = False,
        margin: float = 0.0,
        skin: float | None = None,
        remove_initial_overlap: bool = True,
        x_initial=None,
        capacity: int | None = None,
    ) -> None:
        check_law(beta, damping, friction, damping_mode, margin)
        self.beta = float(beta)
        self.damping = float(damping)
        self.friction = float(friction)
        self.damping_mode = str(damping_mode)
        self.approach = damping_mode == "approach"
        self.self_contact = bool(self_contact)
        self.margin = float(margin)
        self._build_surfaces(model, shells_taking_part(model, elements, plies))
        self.law = ContactLaw(beta=self.beta, zeta=self.damping, mu=self.friction,
                              approach=self.approach)
        check_skin(skin)
        self.skin = None if skin is None else float(skin)
        nn, ne = self.node_part.shape[0], self.quads.shape[0]
        self._alloc_search_state(nn, ne)
        self._alloc_scratch(nn, ne)
        if capacity is None:
            capacity = max(64, 8 * int(self.node_part.sum()))
        self._alloc_pairs(capacity)
        if remove_initial_overlap:
            x = model.x0 if x_initial is None else np.ascontiguousarray(x_initial, dtype=float)
            self._measure_overlap(x)

    def _build_surfaces(self, model, part: np.ndarray) -> None:
        """The segments table and the surfaces the kernels read (fixed): the shells'
        segments (``quads``, ``ply``, half thicknesses ``h_seg``), then the solids'
        exterior faces (one-sided, their reach as ``h_seg``, each body a surface labelled
        after the shells' plies); the node → segment map, the nodes' offsets ``h_node``
        and skin floors ``h_skin``, ``node_ply``, the taking-part flags ``elem_part`` (from
        ``part``, the shells') and ``node_part``, ``seg_alive``, and ``surfaces``."""
        quads = np.ascontiguousarray(model.quads, dtype=np.int64)
        n_shells, nn = quads.shape[0], model.x0.shape[0]
        self.n_shells = n_shells
        self.ply = np.ascontiguousarray(model.ply, dtype=np.int64)
        self.node_mass = np.ascontiguousarray(model.node_mass, dtype=float)
        self.node_ptr = np.ascontiguousarray(model.node_ptr, dtype=np.int64)
        self.node_elem = np.ascontiguousarray(model.node_elem, dtype=np.int64)
        self.h_seg = 0.5 * model.sections[model.elem_section, SL.C_THICK].astype(float)
        self.one_sided = np.zeros(n_shells, dtype=np.int8)
        ne = n_shells
        if getattr(model, "n_hexes", 0):
            # the solids' exterior faces after the shells: one-sided segments without
            # offset, each body a surface labelled after the shells' plies
            faces, body, reach = solid_segments(model)
            first = int(self.ply.max()) + 1 if n_shells else 0
            quads = np.concatenate([quads, faces])
            self.ply = np.concatenate([self.ply, first + body])
            self.h_seg = np.concatenate([self.h_seg, reach])
            self.one_sided = np.concatenate([self.one_sided, np.ones(len(faces), np.int8)])
            part = np.concatenate([part, np.ones(len(faces), np.int8)])
            ne = quads.shape[0]
            self.node_ptr, self.node_elem = node_segment_map(quads, nn)
        self.quads = quads
        self.elem_part = part
        self.seg_alive = np.ones(ne, dtype=np.int8)  # shells' alive flags, then the faces'
        self.h_node = np.zeros(nn)
        on = part != 0
        shell_on = on & (self.one_sided == 0)
        for c in range(4):
            np.maximum.at(self.h_node, quads[shell_on, c], self.h_seg[shell_on])
        # the skins' floor follows a node's offset, or on a solid its faces' reach
        self.h_skin = self.h_node
        if self.one_sided.any():
            self.h_skin = self.h_node.copy()
            for c in range(4):
                np.maximum.at(self.h_skin, quads[on, c], self.h_seg[on])
        self.node_ply = node_plies(self.node_ptr, self.node_elem, self.ply)
        # what the kernels read of the surfaces (fixed)
        self.surfaces = ContactSurfaces(
            quads=self.quads, ply=self.ply, node_ply=self.node_ply, node_ptr=self.node_ptr,
            node_elem=self.node_elem, node_mass=self.node_mass, h_node=self.h_node,
            h_seg=self.h_seg, margin=self.margin, self_contact=self.self_contact,
            one_sided=self.one_sided)
        self.node_part = np.zeros(nn, dtype=np.int8)
        self.node_part[quads[on].ravel()] = 1

    def _alloc_search_state(self, nn: int, ne: int) -> None:
        """The state of candidate reuse for ``nn`` nodes and ``ne`` segments: the skins
        and configuration of the last full search (none yet), the search counters and
        their causes, and the buffers of the incremental updates (contact_update)."""
        self.sigma = np.zeros(nn)  # node skins of the last search (m)
        self.no_skin = np.zeros(nn)  # zero skins: a search that is not reused
        # the configuration and masks of the last search of forces(); no search yet
        self.x_search = np.zeros((nn, 3))
        self.seg_on_search = np.zeros(ne, dtype=np.int8)
        self.node_on_search = np.zeros(nn, dtype=np.int8)
        self.searched = False
        self.searches = 0
        self.updates = 0
        # why each full search of forces() was made (diagnostics)
        self.search_causes = {"first": 0, "surfaces joined": 0, "many nodes out": 0,
                              "many segments re-boxed": 0, "wide segment": 0}
        # incremental updates (contact_update): nodes out of their skins, the re-queried
        # nodes and their lists, segments re-boxed this update and since the last search
        self.far = np.zeros(nn, dtype=np.int8)
        self.sigma_new = np.zeros(nn)
        self.req_pos = np.zeros(nn, dtype=np.int64)
        self.req_list = np.zeros(nn, dtype=np.int64)
        self.req_ptr = np.zeros(nn + 1, dtype=np.int64)
        self.req_seg = np.zeros(64, dtype=np.int64)
        self.seg_new = np.zeros(ne, dtype=np.int8)
        self.seg_moved = np.zeros(ne, dtype=np.int8)
        self.seg_side = np.zeros(ne, dtype=np.int8)
        self.no_skip = np.zeros(ne, dtype=np.int8)
        self.new_bounds = np.zeros(6)
        self.new_bins = SegmentBins()
        self.side_bins = SegmentBins()

    def _alloc_scratch(self, nn: int, ne: int) -> None:
        """The fixed-size scratch for ``nn`` nodes and ``ne`` segments (masks, segment
        boxes, planes and geometry, the search's slots and bin entries, the pair
        pointers, node forces, ``overlap``), the counters of forces() and the energy
        books' compact tables (grown on demand); the pair buffers are _alloc_pairs'."""
        self.slots = np.zeros((nn, CANDIDATE_SLOTS), dtype=np.int64)
        self.seg_on = np.zeros(ne, dtype=np.int8)
        self.node_on = np.zeros(nn, dtype=np.int8)
        self.seg_box = np.zeros((ne, N_SEG_BOX))
        self.seg_plane = np.zeros((ne, N_SEG_PLANE))
        self.seg_geo = np.zeros((ne, N_SEG_GEO))  # the narrow phase's segment table at x
        self._alloc_entries(8 * ne)
        self.pair_ptr = np.zeros(nn + 1, dtype=np.int64)
        self.pair_ptr_alt = np.zeros(nn + 1, dtype=np.int64)  # the splice's output
        self.seg_ptr = np.zeros(nn + 1, dtype=np.int64)
        self.cursor = np.zeros(nn, dtype=np.int64)
        self.node_f = np.zeros((nn, 3))
        self.overlap = np.zeros(nn)
        self.grow_count = 0
        self.n_pairs = 0
        self.n_active = 0  # pairs acting at the last forces() (rows of self.active)
        # the energy books' compact tables of the acting pairs (book; grown on demand)
        self.act_if = np.zeros(0, dtype=np.int64)
        self.act_pw = np.zeros((0, 2 * N_KINDS))
        self.cell = 0.0

    def _measure_overlap(self, x) -> None:
        """``overlap``: each taking-part node's initial penetration (m) in the
        configuration ``x``, from a search without skins (remove_initial_overlap)."""
        ne, nn = self.quads.shape[0], self.node_part.shape[0]
        contact_masks(np.ones(ne, dtype=np.int8), self.elem_part, np.ones(nn, dtype=np.int8),
                      self.node_part, self.seg_on, self.node_on)
        self._search(x, self.no_skin)
        segment_geometry(x, self.quads, self.seg_on, self.seg_geo)
        initial_overlap(x, self.surfaces, self.seg_geo, self.seg_on, self.candidates_now,
                        self.pair_tables, self.overlap)

    @property
    def candidates_now(self) -> Candidates:
        """The candidate lists (pair_ptr, pair_seg) as the kernels take them."""
        return Candidates(ptr=self.pair_ptr, seg=self.pair_seg)

    @property
    def pair_tables(self) -> PairTables:
        """The narrow phase's pair tables as the kernels take them."""
        return PairTables(geo=self.geo, on=self.pair_on, force=self.pair_f,
                          weights=self.pair_w, energy=self.pair_e, spring_damper=self.pair_sd,
                          power=self.power)

    @property
    def bins(self) -> SegmentBinTables:
        """The bins of the last full search as the kernels take them."""
        return SegmentBinTables(bucket_ptr=self.bucket_ptr, entry_seg=self.entry_seg,
                                entry_cell=self.entry_cell, entry_box=self.entry_box,
                                entry_ply=self.entry_ply)

    @property
    def capacity(self) -> int:
        """Pairs the buffers hold before growing."""
        return self.pair_seg.shape[0]

    def _alloc_pairs(self, capacity: int, keep: int = 0) -> None:
        """Pair buffers of ``capacity`` pairs; the first ``keep`` candidates of pair_seg
        are carried over."""
        cap = int(capacity)
        old = self.pair_seg[:keep] if keep else None
        self.pair_seg = np.zeros(cap, dtype=np.int64)
        if old is not None:
            self.pair_seg[:keep] = old
        self.pair_seg_alt = np.zeros(cap, dtype=np.int64)
        self.geo = np.zeros((cap, N_GEO))
        self.pair_on = np.zeros(cap, dtype=np.int8)
        self.pair_f = np.zeros((cap, 3))
        self.pair_w = np.zeros((cap, 4))
        self.pair_e = np.zeros(cap)
        self.pair_sd = np.zeros((cap, 2))  # spring and dashpot normal forces (energy books)
        self.active = np.zeros((cap, 2), dtype=np.int64)  # (node, pair) of the acting pairs
        self.power = np.zeros((cap, N_KINDS))  # and their powers (book)
        self.seg_entry = np.zeros(4 * cap, dtype=np.int64)

    def _alloc_entries(self, capacity: int) -> None:
        cap = max(64, int(capacity))
        self.entry_seg = np.zeros(cap, dtype=np.int64)
        self.entry_cell = np.zeros((cap, 3), dtype=np.int64)
        self.entry_box = np.zeros((cap, N_SEG_BOX))
        self.entry_ply = np.zeros(cap, dtype=np.int64)
        self.bucket_ptr = np.zeros(bucket_count(cap) + 1, dtype=np.int64)

    def _bin(self, edge: float) -> None:
        """The live segments (seg_on) into the bins at their padded boxes (seg_box), on
        cells of edge ``edge``; the bins grow on overflow."""
        while True:
            n = bin_segments(self.seg_on, self.seg_box, self.ply, 1.0 / edge, *self.bins)
            if n <= self.entry_seg.shape[0]:
                break
            self._alloc_entries(int(1.5 * n))
            self.grow_count += 1

    def _search(self, x, sigma) -> int:
        """Candidates at x with node skins ``sigma`` into pair_ptr/pair_seg (seg_on and
        node_on set); the bins and the pair buffers grow on overflow."""
        segment_boxes(x, self.quads, self.seg_on, self.h_seg, sigma, self.margin,
                      self.seg_box, self.seg_plane)
        edge = cell_edge(self.seg_on, self.seg_box)
        self._bin(edge)
        search = ContactSearch(x=x, sigma=sigma, seg_plane=self.seg_plane, edge=edge)
        while True:
            n = query_candidates(self.surfaces, search, self.node_on, self.bins, self.no_skip,
                                 self.slots, self.candidates_now)
            if n <= self.capacity:
                break
            self._alloc_pairs(int(1.5 * n) + 64)
            self.grow_count += 1
        self.n_pairs = int(n)
        self.cell = edge
        return self.n_pairs

    def node_skins(self, v, dt: float, out=None) -> np.ndarray:
        """The skins σ_p of a search (class docstring) into ``out`` (default
        ``self.sigma``)."""
        out = self.sigma if out is None else out
        if self.skin is not None:
            out[:] = 0.5 * self.skin
        else:
            node_skins(v, dt, REUSE_STEPS, self.h_skin, SKIN_FLOOR, out)
        return out

    def _full_search(self, x, v, dt: float) -> None:
        """A search at x with new skins for every node; forgets the updates."""
        self._search(x, self.node_skins(v, dt))
        self.x_search[:] = x
        self.seg_on_search[:] = self.seg_on
        self.node_on_search[:] = self.node_on
        self.seg_moved[:] = 0
        self.searched = self.skin is None or self.skin > 0.0
        self.searches += 1

    def _update(self, x, v, dt: float, n_far: int) -> bool:
        """The incremental update of the lists (kernels.contact_update, steps 2–5) after
        ``n_far`` nodes (``self.far``) left their skins; False, with nothing to keep,
        when it would not pay (too many nodes or segments) or could not bin the
        re-boxed segments on the search's cells: the caller then searches afresh."""
        n_on = int(np.count_nonzero(self.node_on_search))
        if n_far > max(INCREMENTAL_FLOOR, INCREMENTAL_FRACTION * n_on):
            self.search_causes["many nodes out"] += 1
            return False
        self.node_skins(v, dt, self.sigma_new)
        _, n_side = refresh_far_nodes(
            x, self.sigma_new, self.far, self.node_ptr, self.node_elem, self.seg_on,
            self.x_search, self.sigma, self.seg_new, self.seg_moved, self.seg_side)
        segment_boxes(self.x_search, self.quads, self.seg_new, self.h_seg, self.sigma,
                      self.margin, self.seg_box, self.seg_plane)
        if widest_box(self.seg_new, self.seg_box) > MAX_CELLS_PER_AXIS * self.cell:
            self.search_causes["wide segment"] += 1
            return False
        n_seg = np.count_nonzero(self.seg_on_search)
        if n_side > max(INCREMENTAL_FLOOR, INCREMENTAL_FRACTION * n_seg):
            self.search_causes["many segments re-boxed"] += 1
            return False
        inv = 1.0 / self.cell
        self.new_bins.fill(self.seg_new, self.seg_box, self.ply, inv)
        self.side_bins.fill(self.seg_side, self.seg_box, self.ply, inv)
        bounding_box(self.seg_new, self.seg_box, self.new_bounds)
        search = ContactSearch(x=self.x_search, sigma=self.sigma, seg_plane=self.seg_plane,
                               edge=self.cell)
        n_req = mark_requery(self.surfaces, search, self.node_on, self.far, self.new_bounds,
                             self.new_bins.arrays, self.req_pos, self.req_list)
        while True:
            n = requery_candidates(
                self.req_list, n_req, self.surfaces, search, self.bins, self.seg_moved,
                self.side_bins.arrays, self.no_skip, self.slots,
                Candidates(ptr=self.req_ptr, seg=self.req_seg))
            if n <= self.req_seg.shape[0]:
                break
            self.req_seg = np.zeros(int(1.5 * n) + 64, dtype=np.int64)
        while True:
            total = splice_candidates(self.pair_ptr, self.pair_seg, self.req_pos,
                                      self.req_ptr, self.req_seg, self.pair_ptr_alt,
                                      self.pair_seg_alt)
            if total <= self.capacity:
                break
            self._alloc_pairs(int(1.5 * total) + 64, keep=self.n_pairs)
            self.grow_count += 1
        self.pair_ptr, self.pair_ptr_alt = self.pair_ptr_alt, self.pair_ptr
        self.pair_seg, self.pair_seg_alt = self.pair_seg_alt, self.pair_seg
        self.n_pairs = int(total)
        self.updates += 1
        return True

    def candidates(self, x, elem_alive=None, node_active=None) -> tuple[np.ndarray, np.ndarray]:
        """Candidate pairs (node, segment) at x, node-major (copies; for tests/diagnostics)."""
        ne, nn = self.quads.shape[0], self.node_part.shape[0]
        alive = (np.ones(ne, dtype=np.int8) if elem_alive is None
                 else self.segments_alive(elem_alive))
        active = np.ones(nn, dtype=np.int8) if node_active is None else node_active
        contact_masks(alive, self.elem_part, active, self.node_part, self.seg_on, self.node_on)
        n = self._search(np.ascontiguousarray(x, dtype=float), self.no_skin)
        self.searched = False  # the lists of forces() are gone
        self.n_active = 0  # and with them the pairs of the last forces() call
        nodes = np.repeat(np.arange(nn, dtype=np.int64), np.diff(self.pair_ptr))
        return nodes, self.pair_seg[:n].copy()

    def forces(self, x, v, dt, elem_alive, node_active, out_force, accumulate=False):
        """Contact forces at (x, v) for a step dt into ``out_force[:, :3]``; returns
        (energy J, active pairs). See the class docstring."""
        if not dt > 0.0:
            raise ValueError(f"contact forces need a time step dt > 0, got {dt!r}")
        # the nodes' work is uneven (candidates gather where surfaces touch): chunks
        # handed out as threads free up, not one static half each (theory §6)
        with numba.parallel_chunksize(CONTACT_CHUNK):
            return self._forces(x, v, dt, elem_alive, node_active, out_force, accumulate)

    def segments_alive(self, elem_alive):
        """The segments' alive flags: the shells' ``elem_alive``, then the solids' faces
        (always live): ``elem_alive`` itself in a model of shells only."""
        if self.quads.shape[0] == self.n_shells:
            return elem_alive
        self.seg_alive[:self.n_shells] = elem_alive
        return self.seg_alive

    def _forces(self, x, v, dt, elem_alive, node_active, out_force, accumulate):
        """:meth:`forces` (its arguments checked)."""
        elem_alive = self.segments_alive(elem_alive)
        contact_masks(elem_alive, self.elem_part, node_active, self.node_part,
                      self.seg_on, self.node_on)
        joined = self.searched and surfaces_joined(self.node_on, self.node_on_search,
                                                   self.seg_on, self.seg_on_search)
        if not self.searched or joined:
            self.search_causes["surfaces joined" if joined else "first"] += 1
            self._full_search(x, v, dt)
        else:
            n_far = nodes_beyond_skins(x, self.x_search, self.sigma, self.node_on, v,
                                       AHEAD_STEPS * dt, self.far)
            if n_far and not self._update(x, v, dt, n_far):
                self._full_search(x, v, dt)
        segment_geometry(x, self.quads, self.seg_on, self.seg_geo)
        candidates, pairs = self.candidates_now, self.pair_tables
        penalty_forces(x, v, float(dt), self.surfaces, self.law, self.overlap, self.seg_geo,
                       self.seg_on, self.node_on, candidates, pairs, self.node_f)
        energy, n_active = assemble_contact_forces(
            self.quads, candidates, pairs, self.node_f, self.seg_ptr, self.seg_entry,
            self.cursor, out_force, bool(accumulate), self.active)
        self.n_active = int(n_active)
        return float(energy), int(n_active)

    def book(self, v, w_before: float, books_before, w_after: float, books_after,
             node_part, seg_part) -> None:
        """Book the work of the pairs of the last :meth:`forces` call in the energy books
        (kernels.contact_energy): books[kind, a, b] −= w · P_kind (kind SPRING, DAMPING,
        FRICTION; a = node_part[node], b = seg_part[segment]), with the powers at the
        velocities the forces were computed with (written by the narrow phase) into
        ``books_before`` and with those at ``v`` into ``books_after``. With the weights ½ Δt
        of the solver's trapezoid rule — the step before the forces and the step after,
        ``v`` the velocities after it — the books hold what the solver's contact work
        holds, split by part and by pair. Few pairs (below PARALLEL_BOOK_PAIRS) are booked
        in one serial pass, more with the powers computed in parallel into compact
        tables and summed serially: the same books, bitwise."""
        n = self.n_active
        if n == 0:
            return
        books = EnergyBooks(w_before=float(w_before), before=books_before,
                            w_after=float(w_after), after=books_after)
        if n < PARALLEL_BOOK_PAIRS:
            book_shell_pairs(v, self.quads, self.pair_seg, self.pair_tables, self.active, n,
                             self.friction > 0.0, node_part, seg_part, books)
            return
        if self.act_if.shape[0] < n:  # the compact tables grow with the acting pairs
            self.act_if = np.zeros(int(1.5 * n), dtype=np.int64)
            self.act_pw = np.zeros((int(1.5 * n), 2 * N_KINDS))
        n_parts = books_before.shape[1]
        shell_pair_powers(v, self.quads, self.pair_seg, self.pair_tables, self.active, n,
                          self.friction > 0.0, node_part, seg_part, n_parts, self.act_if,
                          self.act_pw)
        book_compact(self.act_if, self.act_pw, n, n_parts, books)
