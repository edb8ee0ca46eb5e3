"""The plain-weave crossover cell of thesis §5.2.1 as a structured mesh of 8-node hexahedra.

Two yarns cross at the origin, the warp along x over the fill along y. With ℓ_w = 1/(2 n_f)
and ℓ_f = 1/(2 n_w) the in-plane half-lengths between crossings (n the thread counts, eq.
5.2), the cell is [−ℓ_w, ℓ_w] × [−ℓ_f, ℓ_f] and

- the centrelines are the cosines of eq. (5.1): z = h_w cos(π x / 2ℓ_w) for the warp,
  z = −h_f cos(π y / 2ℓ_f) for the fill, h the amplitude of eq. (5.5) (materials/crimp.py)
  unless given;
- a yarn of width W and thickness t has the vertical section
  z = c ± (t/2) s(u), u = 2 (across) / W ∈ [−u_t, u_t], with s(u) = cos(π u / 2)
  (lenticular: two cosine arcs, the thesis's) or √(1 − u²) (elliptical), cut at the tips
  where s(u_t) = ``trim`` (thesis Fig. 5-3: sharp tips make degenerate elements);
- the mesh is swept: nodes at ``along`` + 1 stations over the cell, ``across`` + 1 across
  the trimmed width (uniform in u) and ``through`` + 1 through the thickness (uniform in
  the section's own height), so every element is a hexahedron of positive volume in C3D8
  order and the volume of a yarn is 2ℓ times its (polygonal) section area exactly (a
  vertical shift that varies linearly between stations keeps volumes);
- each element's material axes follow its yarn: a1 the centreline's tangent at the
  element's mid-station, a2 across the yarn in the plane (+y for the warp, −x for the fill),
  a3 = a1 × a2 (upwards).

With the thesis's values (Table 5-1: W = 1/n, t = 2h of the crossing family, lenticular)
the warp's lower surface h_w cos(πx/2ℓ_w) − h_f cos(πy/2ℓ_f) is the fill's upper surface:
the yarns meet over the whole cell without overlapping (zero gap). Other values are checked
for overlap on a fine grid (:func:`yarn_clearance`) and refused when the yarns overlap.
Each yarn has its own nodes (their contact is not a shared node).

*The 2 × 2 repeat* (``[cell] repeat = 2``): the plain weave's periodic unit of two warp
yarns and two fill yarns, [−2ℓ_w, 2ℓ_w] × [−2ℓ_f, 2ℓ_f] — what an in-plane shear test
needs, a yarn with a parallel neighbour to jam against (calibration/cell_shear.py). Warp j
(j = 0, 1) lies along y = (2j − 1) ℓ_f, fill i along x = (2i − 1) ℓ_w, and

  z_warp j = σ_j h_w cos(π (x + ℓ_w) / 2ℓ_w),  σ_j = +1, −1,
  z_fill i = −σ_i h_f cos(π (y + ℓ_f) / 2ℓ_f),

so warp 0 passes over fill 0 and under fill 1, warp 1 under fill 0 and over fill 1, every
yarn's end faces lie at its inflection points (z = 0, as the single cell's) and the
repeat is periodic: a copy shifted by 4ℓ along either axis continues every centreline.
Each quarter of the repeat is the one-crossover cell, shifted, and mirrored in z where
the fill is on top; the clearance of the crossing yarns is therefore the single cell's
(:func:`yarn_clearance`), and parallel yarns, each within its pitch (width + gap ≤ pitch),
do not overlap. Each yarn has its own nodes, hexahedron set ("warp0", "warp1", "fill0",
"fill1", besides "warp" and "fill") and end faces. ``[mesh] along`` counts the elements
over 2ℓ (one crossing), so a yarn of the repeat has 2 × along.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wovenimpact.errors import InputError
from wovenimpact.kernels import solid_layout as HL
from wovenimpact.materials.crimp import crimp_amplitude, crimp_of_amplitude
from wovenimpact.model.mesh import Mesh

FAMILIES = ("warp", "fill")
CLEARANCE_GRID = 201  # points per direction of the overlap check
OVERLAP_TOLERANCE = 1e-9  # of the yarn thickness: round-off of surfaces that coincide


@dataclass(frozen=True)
class YarnShape:
    """One yarn of the cell in SI (module docstring).

    Attributes:
        half_length: ℓ, the cell's half-length along the yarn, 1/(2 n_crossing) (m).
        amplitude: h, the centreline's amplitude (m).
        width: W (m). thickness: t (m).
        crimp: the crimp of the centreline of amplitude h over ±ℓ (eq. 5.3–5.4).
    """

    half_length: float
    amplitude: float
    width: float
    thickness: float
    crimp: float


@dataclass
class CrossoverCell:
    """A generated cell.

    Attributes:
        mesh: nodes, hexahedra (``Mesh.hexes``; the warp's first) and sets: hexahedron
            sets "warp", "fill"; node sets "all", "warp", "fill", each yarn's end faces
            ("warp.x_min", "warp.x_max", "fill.y_min", "fill.y_max") and its upper and
            lower surfaces ("warp.top", "warp.bottom", "fill.top", "fill.bottom"). In the
            2 × 2 repeat (``repeat`` 2) the same sets name each family's union, and each
            yarn has its own: hexahedron sets "warp0", "warp1", "fill0", "fill1" and node
            sets "warp0", "warp0.x_min", "warp0.x_max", "warp0.top", "warp0.bottom", ….
        frames: (n_hexes, 3, 3) material axes, rows a1 (along the yarn), a2, a3 (also
            ``mesh.hex_frames``).
        yarns: {"warp": YarnShape, "fill": YarnShape}.
        shape, trim: the section's shape and trim.
        repeat: crossings along each yarn, 1 (the single crossover) or 2 (the 2 × 2
            plain-weave repeat).
    """

    mesh: Mesh
    frames: np.ndarray
    yarns: dict
    shape: str
    trim: float
    repeat: int = 1

    @property
    def size(self) -> tuple[float, float]:
        """The cell's extent along x and y (m): 2ℓ × repeat each."""
        return (2.0 * self.repeat * self.yarns["warp"].half_length,
                2.0 * self.repeat * self.yarns["fill"].half_length)

    @property
    def yarn_names(self) -> tuple[str, ...]:
        """The yarns' own set names: ("warp", "fill"), or ("warp0", "warp1", "fill0",
        "fill1") in the 2 × 2 repeat."""
        if self.repeat == 1:
            return FAMILIES
        return tuple(f"{f}{j}" for f in FAMILIES for j in range(self.repeat))

    @property
    def thickness(self) -> float:
        """The cell's extent along z: the shell thickness (4 h0 in the thesis, m)."""
        z = self.mesh.nodes[:, 2]
        return float(z.max() - z.min())


def section_profile(shape: str, u):
    """s(u): the section's half-height over its half-thickness at u ∈ [−1, 1]."""
    u = np.asarray(u, dtype=float)
    if shape == "lenticular":
        return np.cos(0.5 * np.pi * u)
    return np.sqrt(np.maximum(0.0, 1.0 - u * u))


def trimmed_extent(shape: str, trim: float) -> float:
    """u_t, where the section's height falls to ``trim`` of its thickness."""
    if shape == "lenticular":
        return 2.0 / math.pi * math.acos(trim)
    return math.sqrt(1.0 - trim * trim)


def section_area(shape: str, trim: float, width: float, thickness: float) -> float:
    """The exact area of the trimmed section (m²): t (W/2) ∫ s(u) du over [−u_t, u_t]."""
    ut = trimmed_extent(shape, trim)
    if shape == "lenticular":
        integral = 4.0 / math.pi * math.sin(0.5 * math.pi * ut)
    else:
        integral = ut * math.sqrt(1.0 - ut * ut) + math.asin(ut)
    return thickness * 0.5 * width * integral


def yarn_shapes(spec) -> dict[str, YarnShape]:
    """Each family's ℓ, h, W, t and crimp from a geometry spec (spec/crossover.py),
    defaults filled in (the spec's comments); an InputError naming the key for a width
    wider than the pitch."""
    warp, fill = spec.families
    out = {}
    for name, own, crossing in (("warp", warp, fill), ("fill", fill, warp)):
        half = 0.5 / crossing.thread_count
        h = own.h0 if own.h0 is not None else crimp_amplitude(half, own.crimp)
        out[name] = (own, half, h)
    shapes = {}
    for name, other in (("warp", "fill"), ("fill", "warp")):
        own, half, h = out[name]
        pitch = 1.0 / own.thread_count
        width = own.width if own.width is not None else pitch - own.gap
        if not width > 0.0:
            raise InputError(f"{name}.gap = {own.gap:g} m leaves no yarn: the pitch is "
                             f"{pitch:g} m (valid: a gap below the pitch)")
        if width + own.gap > pitch * (1.0 + 1e-9):
            raise InputError(f"{name}.width = {width:g} m and gap {own.gap:g} m exceed the "
                             f"pitch 1 / thread_count = {pitch:g} m: neighbouring yarns "
                             "would overlap (valid: width + gap ≤ pitch)")
        thickness = own.thickness if own.thickness is not None else 2.0 * out[other][2]
        shapes[name] = YarnShape(half_length=half, amplitude=h, width=width,
                                 thickness=thickness, crimp=crimp_of_amplitude(h, half))
    return shapes


def centreline(yarn: YarnShape, s, sign: float):
    """(z, dz/ds) of a centreline at ``s`` along its yarn (sign +1 warp, −1 fill)."""
    k = 0.5 * math.pi / yarn.half_length
    return sign * yarn.amplitude * np.cos(k * s), -sign * yarn.amplitude * k * np.sin(k * s)


def _yarn_nodes(yarn: YarnShape, shape: str, trim: float, n, sign: float, axis: int,
                place=None):
    """Nodes (k slowest, then j, i fastest) of one yarn: i along it, j across (u), k up.
    ``place`` (the 2 × 2 repeat): (half-span, phase, offset) — the yarn runs over
    [−half-span, half-span], its centreline the cosine about s = ``phase`` and its axis at
    ``offset`` across; None: the single cell's yarn over [−ℓ, ℓ] about 0."""
    along, across, through = n
    if place is None:
        s = np.linspace(-yarn.half_length, yarn.half_length, along + 1)
    else:
        s = np.linspace(-place[0], place[0], along + 1)
    ut = trimmed_extent(shape, trim)
    u = np.linspace(-ut, ut, across + 1)
    zeta = np.linspace(-1.0, 1.0, through + 1)
    k3, j3, i3 = np.meshgrid(zeta, u, s, indexing="ij")
    c, _ = centreline(yarn, i3 if place is None else i3 - place[1], sign)
    z = c + k3 * 0.5 * yarn.thickness * section_profile(shape, j3)
    across_coord = j3 * 0.5 * yarn.width
    if place is not None:
        across_coord = across_coord + (place[2] if axis == 0 else -place[2])
    if axis == 0:  # warp: along x, across +y
        xyz = (i3, across_coord, z)
    else:  # fill: along y, across −x (right-handed: the elements keep C3D8 order)
        xyz = (-across_coord, i3, z)
    return np.stack([a.ravel() for a in xyz], axis=1)


def _grid_hexes(n, offset: int) -> np.ndarray:
    """Hexahedra of an (along × across × through) grid of nodes numbered i fastest."""
    along, across, through = n

    def nid(i, j, k):
        return offset + i + (along + 1) * (j + (across + 1) * k)

    k, j, i = np.meshgrid(np.arange(through), np.arange(across), np.arange(along),
                          indexing="ij")
    i, j, k = i.ravel(), j.ravel(), k.ravel()
    corners = [(HL.HEX_XI[c] > 0, HL.HEX_ETA[c] > 0, HL.HEX_ZETA[c] > 0) for c in range(8)]
    return np.stack([nid(i + a, j + b, k + c) for a, b, c in corners], axis=1).astype(np.int64)


def _frames(yarn: YarnShape, n, sign: float, axis: int, place=None) -> np.ndarray:
    """Each element's axes: a1 the centreline's tangent at its mid-station, a2 across
    (``place`` as :func:`_yarn_nodes`)."""
    along, across, through = n
    if place is None:
        s = np.linspace(-yarn.half_length, yarn.half_length, along + 1)
    else:
        s = np.linspace(-place[0], place[0], along + 1)
    mid = 0.5 * (s[1:] + s[:-1])
    _, slope = centreline(yarn, mid if place is None else mid - place[1], sign)
    norm = np.sqrt(1.0 + slope**2)
    a1 = np.zeros((along, 3))
    a2 = np.zeros((along, 3))
    a1[:, axis] = 1.0 / norm
    a1[:, 2] = slope / norm
    if axis == 0:
        a2[:, 1] = 1.0
    else:
        a2[:, 0] = -1.0
    per_station = np.stack([a1, a2, np.cross(a1, a2)], axis=1)
    return np.ascontiguousarray(np.tile(per_station, (across * through, 1, 1)))


def yarn_clearance(yarns: dict, shape: str, trim: float, points: int = CLEARANCE_GRID):
    """The smallest vertical clearance (m) between the warp's lower surface and the fill's
    upper surface where both are (negative: they overlap), and where it is."""
    w, f = yarns["warp"], yarns["fill"]
    ut = trimmed_extent(shape, trim)
    x = np.linspace(-ut * 0.5 * f.width, ut * 0.5 * f.width, points)
    y = np.linspace(-ut * 0.5 * w.width, ut * 0.5 * w.width, points)
    x = x[np.abs(x) <= w.half_length]
    y = y[np.abs(y) <= f.half_length]
    X, Y = np.meshgrid(x, y, indexing="ij")
    warp_low = (centreline(w, X, 1.0)[0]
                - 0.5 * w.thickness * section_profile(shape, Y / (0.5 * w.width)))
    fill_up = (centreline(f, Y, -1.0)[0]
               + 0.5 * f.thickness * section_profile(shape, -X / (0.5 * f.width)))
    gap = warp_low - fill_up
    at = np.unravel_index(int(np.argmin(gap)), gap.shape)
    return float(gap[at]), (float(X[at]), float(Y[at]))


def crossover_cell(spec) -> CrossoverCell:
    """The cell of a geometry spec (spec/crossover.py; module docstring): one crossover,
    or the 2 × 2 plain-weave repeat with ``[cell] repeat = 2``.

    Raises:
        InputError: a yarn wider than its pitch, or yarns that overlap (thicker than
            twice the crossing family's amplitude, or elliptical sections as wide as
            the pitch), naming the keys to change.
    """
    yarns = yarn_shapes(spec)
    shape, trim = spec.section.shape, float(spec.section.trim)
    gap, where = yarn_clearance(yarns, shape, trim)
    scale = max(y.thickness for y in yarns.values())
    if gap < -OVERLAP_TOLERANCE * scale:
        raise InputError(
            f"the yarns overlap by {-gap * 1e3:.4g} mm at (x, y) = ({where[0] * 1e3:.4g}, "
            f"{where[1] * 1e3:.4g}) mm: the warp's lower surface is below the fill's upper "
            "one (valid: warp.thickness ≤ 2 fill.h0 and fill.thickness ≤ 2 warp.h0 with "
            "section.shape = 'lenticular', the thesis's; an elliptical section needs "
            "yarns narrower than the pitch, a width or a gap, where the cell's corners "
            "leave it room)")
    n = (spec.mesh.along, spec.mesh.across, spec.mesh.through)
    if spec.cell.repeat == 2:  # (the spec allows 1 or 2)
        return _repeat_cell(yarns, shape, trim, n)
    per_yarn = (n[0] + 1) * (n[1] + 1) * (n[2] + 1)
    nodes = np.vstack([_yarn_nodes(yarns["warp"], shape, trim, n, 1.0, 0),
                       _yarn_nodes(yarns["fill"], shape, trim, n, -1.0, 1)])
    hexes = np.vstack([_grid_hexes(n, 0), _grid_hexes(n, per_yarn)])
    frames = np.vstack([_frames(yarns["warp"], n, 1.0, 0), _frames(yarns["fill"], n, -1.0, 1)])
    grid = np.stack(np.meshgrid(np.arange(n[2] + 1), np.arange(n[1] + 1), np.arange(n[0] + 1),
                                indexing="ij"), axis=-1).reshape(-1, 3)  # (k, j, i)
    node_sets = {"all": np.arange(2 * per_yarn)}
    for y, (name, lo, hi) in enumerate((("warp", "x_min", "x_max"), ("fill", "y_min", "y_max"))):
        base = y * per_yarn
        node_sets[name] = base + np.arange(per_yarn)
        node_sets[f"{name}.{lo}"] = base + np.flatnonzero(grid[:, 2] == 0)
        node_sets[f"{name}.{hi}"] = base + np.flatnonzero(grid[:, 2] == n[0])
        node_sets[f"{name}.bottom"] = base + np.flatnonzero(grid[:, 0] == 0)
        node_sets[f"{name}.top"] = base + np.flatnonzero(grid[:, 0] == n[2])
    per_hexes = n[0] * n[1] * n[2]
    mesh = Mesh(nodes=nodes, quads=np.zeros((0, 4), dtype=np.int64),
                ply=np.zeros(0, dtype=np.int64), node_sets=node_sets, hexes=hexes,
                hex_sets={"warp": np.arange(per_hexes),
                          "fill": per_hexes + np.arange(per_hexes)}, hex_frames=frames)
    return CrossoverCell(mesh=mesh, frames=frames, yarns=yarns, shape=shape, trim=trim)


def repeat_placement(yarns: dict):
    """The 2 × 2 repeat's yarns (module docstring) in node order: (name, family, sign,
    axis, place) with ``place`` = (half-span 2ℓ, phase −ℓ, offset (2j − 1) ℓ of the crossing
    family) as :func:`_yarn_nodes` takes it."""
    w, f = yarns["warp"], yarns["fill"]
    out = []
    for j, sigma in enumerate((1.0, -1.0)):
        out.append((f"warp{j}", "warp", sigma, 0,
                    (2.0 * w.half_length, -w.half_length, (2 * j - 1) * f.half_length)))
    for i, sigma in enumerate((1.0, -1.0)):
        out.append((f"fill{i}", "fill", -sigma, 1,
                    (2.0 * f.half_length, -f.half_length, (2 * i - 1) * w.half_length)))
    return out


def _repeat_cell(yarns: dict, shape: str, trim: float, n) -> CrossoverCell:
    """The 2 × 2 plain-weave repeat (module docstring): four yarns of 2 × along elements
    each, the warps' first."""
    m = (2 * n[0], n[1], n[2])
    per_yarn = (m[0] + 1) * (m[1] + 1) * (m[2] + 1)
    per_hexes = m[0] * m[1] * m[2]
    grid = np.stack(np.meshgrid(np.arange(m[2] + 1), np.arange(m[1] + 1), np.arange(m[0] + 1),
                                indexing="ij"), axis=-1).reshape(-1, 3)  # (k, j, i)
    nodes, hexes, frames = [], [], []
    node_sets: dict = {}
    hex_sets: dict = {}
    for y, (name, family, sign, axis, place) in enumerate(repeat_placement(yarns)):
        yarn = yarns[family]
        nodes.append(_yarn_nodes(yarn, shape, trim, m, sign, axis, place))
        hexes.append(_grid_hexes(m, y * per_yarn))
        frames.append(_frames(yarn, m, sign, axis, place))
        base = y * per_yarn
        lo, hi = ("x_min", "x_max") if axis == 0 else ("y_min", "y_max")
        node_sets[name] = base + np.arange(per_yarn)
        node_sets[f"{name}.{lo}"] = base + np.flatnonzero(grid[:, 2] == 0)
        node_sets[f"{name}.{hi}"] = base + np.flatnonzero(grid[:, 2] == m[0])
        node_sets[f"{name}.bottom"] = base + np.flatnonzero(grid[:, 0] == 0)
        node_sets[f"{name}.top"] = base + np.flatnonzero(grid[:, 0] == m[2])
        hex_sets[name] = y * per_hexes + np.arange(per_hexes)
    for family, lo, hi in (("warp", "x_min", "x_max"), ("fill", "y_min", "y_max")):
        for key in ("", f".{lo}", f".{hi}", ".bottom", ".top"):
            node_sets[f"{family}{key}"] = np.concatenate(
                [node_sets[f"{family}{j}{key}"] for j in range(2)])
        hex_sets[family] = np.concatenate([hex_sets[f"{family}{j}"] for j in range(2)])
    nodes = np.vstack(nodes)
    node_sets["all"] = np.arange(len(nodes))
    frames = np.vstack(frames)
    mesh = Mesh(nodes=nodes, quads=np.zeros((0, 4), dtype=np.int64),
                ply=np.zeros(0, dtype=np.int64), node_sets=node_sets, hexes=np.vstack(hexes),
                hex_sets=hex_sets, hex_frames=frames)
    return CrossoverCell(mesh=mesh, frames=frames, yarns=yarns, shape=shape, trim=trim,
                         repeat=2)
