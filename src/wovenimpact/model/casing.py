"""Containment geometry (thesis ch. 8, docs/model.md §6): coaxial casing layers and a fan blade.

``casing_mesh`` builds N coaxial cylindrical layers about the z axis (an inner metal
shell and fabric plies, or metal layers), each on its own nodes; ``blade_mesh`` a flat
tapered blade in the plane of the axis, split along a crack radius into a hub part and
the released fragment joined by one row of "release" elements. Both return a
:class:`~wovenimpact.model.mesh.Mesh`; ``join`` puts meshes side by side.
"""

from __future__ import annotations

import math

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.model.mesh import Mesh


def _divisions(extent: float, size: float, label: str, size_key: str = "element_size") -> int:
    """Elements along an edge of length ``extent`` at target size ``size`` (``size_key``
    names it in messages)."""
    if not (math.isfinite(extent) and extent > 0.0):
        raise InputError(f"{label} = {extent:.6g} m must be > 0")
    if not (math.isfinite(size) and size > 0.0):
        raise InputError(f"{size_key} = {size:.6g} m must be > 0")
    n = int(math.ceil(extent / size - 1e-9))
    if n > 20000:
        raise InputError(f"{label} / {size_key} = {extent / size:.3g} elements along one "
                         f"edge; choose a larger {size_key}")
    return max(n, 1)


def casing_mesh(
    radii,
    length: float,
    element_size: float,
    sector: float = 360.0,
    centre_angle: float = 0.0,
    fine_sector: float | None = None,
    coarse_size: float | None = None,
    offset_layers: bool = False,
    axial_size: float | None = None,
) -> Mesh:
    """Coaxial cylindrical layers about the z axis, z ∈ [−length/2, length/2].

    Args:
        radii: mid-surface radius of each layer (m), innermost first.
        length: axial length (m).
        element_size: target element edge (m), along the circumference of the
            innermost layer and along z; every layer has the same divisions (its
            elements are slightly longer circumferentially the further out it is).
        sector: angular extent (degrees); 360 is the full ring (periodic, no seam).
        centre_angle: angle of the sector's middle (degrees, from +x towards +y).
        fine_sector, coarse_size: a graded ring (:func:`graded_angles`): ``element_size``
            around the circumference within ``fine_sector`` degrees centred on
            ``centre_angle`` (the impact zone), growing by about 20 % per element
            to ``coarse_size`` outside it; axially the same size everywhere. Both
            or neither.
        offset_layers: on a full ring, every second layer's node columns sit half-way
            between those of the layer inside it (the angle of each column the mean of
            two neighbouring ones), so a node of one layer faces the middle of an
            element edge of the next instead of a corner shared by four of its elements
            (docs/theory.md §8, "Offset layers"). A sector keeps its cut edges radial:
            InputError.
        axial_size: the element edge along z (m); None: ``element_size``. Elements
            longer around than along the axis resolve the casing's axial bending (its
            boundary layer under a radial load, 0.78 √(R t) long; docs/theory.md §8.8)
            at a fraction of the elements of a uniformly fine ring.

    Elements are counter-clockwise about the outward normal (first edge along the
    circumference, second along +z). Node sets: ``ends`` (z = ±length/2, every layer),
    ``end_low``, ``end_high``, ``cut_edges`` (the two straight edges of a sector;
    empty for a full ring), ``layer{k}``; element sets ``layer{k}``; ``ply`` = k.
    """
    radii = np.asarray(radii, dtype=float).ravel()
    if radii.size == 0 or not np.all(np.isfinite(radii)) or np.any(radii <= 0.0):
        raise InputError(f"casing layer radii {radii.tolist()} must be positive numbers")
    if np.any(np.diff(radii) <= 0.0):
        raise InputError(f"casing layer radii {radii.tolist()} must increase outwards")
    # "360 deg" read through radians comes back as 360.0000000000002
    if not (0.0 < sector <= 360.0 + 1e-9):
        raise InputError(f"casing sector = {sector:.6g}°; valid: 0 < sector ≤ 360")
    full = sector >= 360.0 - 1e-9
    sector = 360.0 if full else sector
    span = math.radians(sector)
    if axial_size is None:
        n_z = _divisions(length, element_size, "casing length")
    else:
        n_z = _divisions(length, axial_size, "casing length", "casing.axial_element_size")
    t0 = math.radians(centre_angle) - 0.5 * span
    if fine_sector is None and coarse_size is None:
        n_t = _divisions(radii[0] * span, element_size, "casing circumference")
        if full:
            n_t = max(n_t, 8)
        theta = t0 + span * np.arange(n_t + 1) / n_t
    else:
        theta = t0 + graded_angles(radii[0], span, element_size, fine_sector, coarse_size)
        n_t = theta.size - 1
    n_tn = n_t if full else n_t + 1  # node columns around
    if offset_layers and not full:
        raise InputError(f"casing.offset_layers needs the full ring (sector = {sector:.6g}°): "
                         "a sector's cut edges are radial lines through every layer")
    # the offset columns: the mean angle of each pair of neighbours (the last pair wraps)
    theta_offset = 0.5 * (theta[:n_tn] + theta[1:n_tn + 1]) if offset_layers else None
    theta = theta[:n_tn]
    z = np.linspace(-0.5 * length, 0.5 * length, n_z + 1)
    per_layer = n_tn * (n_z + 1)
    nodes, quads, ply = [], [], []
    node_sets: dict[str, np.ndarray] = {}
    elem_sets: dict[str, np.ndarray] = {}
    jj, kk = np.meshgrid(np.arange(n_t), np.arange(n_z), indexing="ij")
    jj, kk = jj.ravel(), kk.ravel()
    for layer, r in enumerate(radii):
        tt, zz = np.meshgrid(theta if layer % 2 == 0 or theta_offset is None else theta_offset,
                             z, indexing="ij")
        nodes.append(np.stack([r * np.cos(tt).ravel(), r * np.sin(tt).ravel(), zz.ravel()],
                              axis=1))
        base = layer * per_layer

        def nid(j, k):
            return base + (j % n_tn) * (n_z + 1) + k

        q = np.stack([nid(jj, kk), nid(jj + 1, kk), nid(jj + 1, kk + 1), nid(jj, kk + 1)],
                     axis=1)
        elem_sets[f"layer{layer}"] = np.arange(len(q)) + sum(len(a) for a in quads)
        quads.append(q)
        ply.append(np.full(len(q), layer))
        node_sets[f"layer{layer}"] = base + np.arange(per_layer)
    nodes = np.concatenate(nodes)
    idx = np.arange(len(nodes))
    col = (idx % per_layer) // (n_z + 1)
    row = idx % (n_z + 1)
    node_sets["end_low"] = idx[row == 0]
    node_sets["end_high"] = idx[row == n_z]
    node_sets["ends"] = idx[(row == 0) | (row == n_z)]
    node_sets["cut_edges"] = idx[(col == 0) | (col == n_tn - 1)] if not full else idx[:0]
    return Mesh(nodes=nodes, quads=np.concatenate(quads), ply=np.concatenate(ply),
                node_sets=node_sets, elem_sets=elem_sets)


GROWTH = 1.2  # largest ratio of neighbouring element widths in a graded ring


def graded_angles(radius: float, span: float, size: float, fine_sector, coarse_size,
                  ) -> np.ndarray:
    """Node angles (rad, from 0 to ``span``) of a ring graded about its middle.

    Within ``fine_sector`` (degrees) about the middle the arc ``radius``·Δθ is at most
    ``size``; outside it the target width s(ξ) = min(size + (GROWTH − 1) ξ, coarse_size)
    grows with the arc ξ from the fine zone's edge — on a full ring from both edges,
    meeting half-way — which is geometric growth by GROWTH per element. Each outer
    stretch gets ⌈∫dξ/s⌉ elements, placed where ∫dξ/s takes equal steps, so no element
    is wider than its target and neighbours differ by about GROWTH at most.
    """
    if fine_sector is None or coarse_size is None:
        raise InputError("a graded casing needs both casing.fine_sector and "
                         f"casing.coarse_element_size (got {fine_sector!r}° and {coarse_size!r} m)")
    fine = math.radians(fine_sector)
    if not (0.0 < fine <= span + 1e-12):
        raise InputError(f"casing.fine_sector = {fine_sector:.6g}° must be > 0 and at most "
                         f"casing.sector ({math.degrees(span):.6g}°)")
    if not (math.isfinite(coarse_size) and coarse_size >= size):
        raise InputError(f"casing.coarse_element_size = {coarse_size * 1e3:.6g} mm must be at "
                         f"least element_size ({size * 1e3:.6g} mm)")
    fine = min(fine, span)
    n_f = _divisions(radius * fine, size, "casing fine sector")
    full = span >= 2.0 * math.pi - 1e-12
    rest = radius * (span - fine)  # arc outside the fine zone

    def stretch(arc: float, both_ends: bool) -> np.ndarray:
        """Node arcs 0 … arc of one outer stretch, graded away from ξ = 0 (and ξ = arc)."""
        if arc <= 1e-12 * radius:
            return np.array([0.0])
        xi = np.linspace(0.0, arc, max(4001, int(20.0 * arc / size) + 1))  # ≥ 20 per element
        d = np.minimum(xi, arc - xi) if both_ends else xi
        count = np.concatenate([[0.0], np.cumsum(
            0.5 * np.diff(xi) * (1.0 / np.minimum(size + (GROWTH - 1.0) * d[1:], coarse_size)
                                 + 1.0 / np.minimum(size + (GROWTH - 1.0) * d[:-1],
                                                    coarse_size)))])
        n = max(int(math.ceil(count[-1] - 1e-9)), 1)
        return np.interp(np.linspace(0.0, count[-1], n + 1), count, xi)

    fine_arcs = radius * fine * np.arange(n_f + 1) / n_f
    if full:
        outer = stretch(rest, both_ends=True)
        arcs = np.concatenate([fine_arcs, fine_arcs[-1] + outer[1:]])
        # the fine zone centred in 0 … 2π; the last node is the first one again
        return arcs / radius + 0.5 * (span - fine)
    side = stretch(0.5 * rest, both_ends=False)
    arcs = np.concatenate([side[-1] - side[::-1], side[-1] + fine_arcs[1:],
                           side[-1] + fine_arcs[-1] + side[1:]])
    return arcs / radius


def circumferential_directions(mesh: Mesh, axis=(0.0, 0.0, 1.0)) -> np.ndarray:
    """(n_elems, 3) unit hoop direction e_θ = a × c/|a × c| at each element's centroid c
    about the unit axis a through the origin: the warp of a fabric wrapped on a
    cylinder. An element whose centroid is on the axis has none: InputError."""
    c = mesh.nodes[mesh.quads].mean(axis=1)
    t = np.cross(np.asarray(axis, dtype=float), c)
    norm = np.linalg.norm(t, axis=1)
    bad = np.flatnonzero(~(norm > 1e-9 * max(1.0, float(np.abs(c).max()))))
    if bad.size:
        raise InputError(f"mesh.warp_direction = 'circumferential': element {int(bad[0])} "
                         f"has its centroid on the axis {list(axis)}; the hoop direction is "
                         "not defined there (give mesh.axis, or a vector warp_direction)")
    return t / norm[:, None]


def blade_mesh(
    root_radius: float,
    tip_radius: float,
    crack_radius: float,
    root_chord: float,
    tip_chord: float,
    element_size: float,
    angle: float = 0.0,
    stagger: float = 0.0,
    twist: float = 0.0,
    tip_curve: float = 0.0,
    size_key: str = "element_size",
) -> Mesh:
    """A tapered blade from ``root_radius`` to ``tip_radius`` along the radial
    direction at ``angle`` (degrees from +x), its chord along z (linear taper from
    ``root_chord`` to ``tip_chord``), turned by ``stagger`` (degrees) about its radial
    axis; it spins about the z axis.

    Twisted planform: the stagger grows linearly along the span, s(r) = stagger +
    twist (r − r_root)/(r_tip − r_root) (degrees; 0: a flat blade); each radial
    station is a straight chord through the radial axis, so the surface between two
    stations is a ruled (slightly warped) one.

    Curved tip (the thesis's ch. 8.2: its blade's outer edge is a curve, so that no
    sharp corner strikes the casing first): the tip edge is a circular arc in the
    chord's coordinate u ∈ [−½, ½] whose mid-chord point lies at ``tip_radius`` and
    whose corners lie ``tip_curve`` (m) inboard of it,
    r_tip(u) = r_tip − ρ + √(ρ² − (u c_tip)²), ρ = (c_tip²/4 + d²)/(2d); the fragment's
    stations between the crack line and the tip are spaced in proportion along each
    chordwise line, so the crack line stays straight (0: a straight tip).

    The radial divisions put a node row exactly at ``crack_radius``; the row of
    elements just outboard of it is the element set ``release`` (eroded at release:
    the fragment then flies free, the hub part keeps turning). Sets: nodes ``root``
    (r = root_radius), ``hub``, ``fragment``; elements ``hub``, ``fragment``
    (``release`` included in neither), ``blade``.

    ``element_size`` is the blade's own (a containment case's ``mesh.blade.element_size``,
    or its casing's size when that is not given); ``size_key`` names it in messages.
    """
    if not (0.0 < root_radius < crack_radius < tip_radius):
        raise InputError(f"blade radii: need 0 < root_radius ({root_radius:.6g}) < crack_radius "
                         f"({crack_radius:.6g}) < tip_radius ({tip_radius:.6g}) (m)")
    for label, c in (("root_chord", root_chord), ("tip_chord", tip_chord)):
        if not (math.isfinite(c) and c > 0.0):
            raise InputError(f"blade {label} = {c:.6g} m must be > 0")
    if not (math.isfinite(tip_curve) and 0.0 <= tip_curve <= 0.5 * (tip_radius - crack_radius)):
        raise InputError(f"blade tip_curve = {tip_curve:.6g} m: need 0 ≤ tip_curve ≤ half the "
                         f"fragment's span, (tip_radius − crack_radius)/2 = "
                         f"{0.5 * (tip_radius - crack_radius):g} m")
    for label, a in (("stagger", stagger), ("stagger + twist", stagger + twist)):
        if not (math.isfinite(a) and abs(a) <= 90.0 + 1e-9):  # "90 deg" read through radians
            raise InputError(f"blade {label} = {a:.6g} deg must lie within [−90, 90] deg (the "
                             "chord turned from the axial direction towards the tangential)")
    n_in = _divisions(crack_radius - root_radius, element_size, "blade hub length", size_key)
    n_out = _divisions(tip_radius - crack_radius, element_size, "blade fragment length",
                       size_key)
    n_c = _divisions(min(root_chord, tip_chord), element_size, "blade chord", size_key)
    r = np.concatenate([np.linspace(root_radius, crack_radius, n_in + 1),
                        np.linspace(crack_radius, tip_radius, n_out + 1)[1:]])
    u = np.linspace(-0.5, 0.5, n_c + 1)
    rr, uu = np.meshgrid(r, u, indexing="ij")
    span = (rr - root_radius) / (tip_radius - root_radius)
    chord = root_chord + span * (tip_chord - root_chord)
    rad = rr.copy()
    if tip_curve > 0.0:
        rho = (0.25 * tip_chord**2 + tip_curve**2) / (2.0 * tip_curve)
        r_tip = tip_radius - rho + np.sqrt(rho**2 - (u * tip_chord) ** 2)
        frag = rr > crack_radius
        xi = (rr - crack_radius) / (tip_radius - crack_radius)
        rad[frag] = (crack_radius + xi * (r_tip[None, :] - crack_radius))[frag]
    a = math.radians(angle)
    e_r = np.array([math.cos(a), math.sin(a), 0.0])
    e_t = np.array([-math.sin(a), math.cos(a), 0.0])
    e_z = np.array([0.0, 0.0, 1.0])
    if twist == 0.0:  # one chord direction
        s = math.radians(stagger)
        e_c = math.cos(s) * e_z + math.sin(s) * e_t
    else:  # the chord direction of each station
        s = np.radians(stagger + twist * span).ravel()[:, None]
        e_c = np.cos(s) * e_z + np.sin(s) * e_t
    nodes = rad.ravel()[:, None] * e_r + (uu * chord).ravel()[:, None] * e_c
    n_r = len(r) - 1
    ii, jj = np.meshgrid(np.arange(n_r), np.arange(n_c), indexing="ij")
    ii, jj = ii.ravel(), jj.ravel()

    def nid(i, j):
        return i * (n_c + 1) + j

    quads = np.stack([nid(ii, jj), nid(ii + 1, jj), nid(ii + 1, jj + 1), nid(ii, jj + 1)], axis=1)
    e = np.arange(len(quads))
    release = e[ii == n_in]
    hub = e[ii < n_in]
    fragment = e[ii > n_in]
    idx = np.arange(len(nodes))
    ring = idx // (n_c + 1)
    return Mesh(
        nodes=nodes, quads=quads, ply=np.zeros(len(quads), dtype=np.int64),
        node_sets={"root": idx[ring == 0], "hub": idx[ring <= n_in],
                   "fragment": idx[ring >= n_in + 1]},
        elem_sets={"hub": hub, "fragment": fragment, "release": release, "blade": e},
    )


def join(*meshes: Mesh, prefixes=None) -> Mesh:
    """The meshes side by side (nodes renumbered, plies offset so that every mesh keeps
    its own surfaces); sets are prefixed (``prefixes[i]``, default none)."""
    prefixes = prefixes or [""] * len(meshes)
    nodes, quads, ply = [], [], []
    node_sets: dict[str, np.ndarray] = {}
    elem_sets: dict[str, np.ndarray] = {}
    n_off = e_off = p_off = 0
    for m, pre in zip(meshes, prefixes):
        nodes.append(m.nodes)
        quads.append(m.quads + n_off)
        ply.append(m.ply + p_off)
        for k, v in m.node_sets.items():
            node_sets[pre + k] = v + n_off
        for k, v in m.elem_sets.items():
            elem_sets[pre + k] = v + e_off
        n_off += m.n_nodes
        e_off += m.n_elems
        p_off += int(m.ply.max()) + 1 if m.n_elems else 0
    return Mesh(nodes=np.concatenate(nodes), quads=np.concatenate(quads),
                ply=np.concatenate(ply), node_sets=node_sets, elem_sets=elem_sets)
