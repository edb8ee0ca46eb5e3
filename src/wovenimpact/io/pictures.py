"""Pictures of the deformed structure at a few instants, for report.html.

Drawn off-screen from the VTU frames a run writes (``OUT/fields``, :mod:`.fields`), read
back with meshio, as matplotlib 3-D polygons (``mpl_toolkits.mplot3d``'s
Poly3DCollection, the Agg backend: no display, nothing beyond matplotlib and meshio,
which the package needs anyway). Eroded elements (cell data ``alive`` = 0) are not drawn;
the edges they shared with drawn elements are, in magenta: the rims of the holes.

- **Which instants** (:func:`choose_frames`): up to four frames — the first written at
  or after first contact (:func:`first_contact_time`: the first history row at which the
  casing's absorbed energy, or the contact force on the impactor, exceeds 1 % of its
  largest value), the last, and two evenly spaced between them.
- **What is drawn** (:func:`frame_view`): a containment run's casing near the fragment —
  the casing elements within :data:`CASING_WINDOW_DEG` either side of the blade's
  outermost node, below the fragment's mid-height (a cut, so that every layer's edge
  shows), seen from the axis — with the blade in grey; a plate impact's plies round the
  impact point (the node displaced most at the frame), drawn apart along the impact
  axis so each ply shows (an exploded view; the gap is named in the caption).
  Elements are chosen by their reference position (alive or not), then the eroded ones
  left out, so ``drawn`` = the alive elements of the view; at most
  :data:`MAX_POLYGONS` (the nearest to the impact point) keep a picture to about a
  second.
- **Colour**: fabric elements by damage (the larger of ``damage_warp`` and
  ``damage_fill``, 0–1), metal elements (the casing's shell, a metal plate) by their
  plastic strain (``plastic_strain``); the blade in grey.

:func:`write_pictures` writes ``OUT/pictures/frame_{k:06d}.png`` and
``OUT/pictures/pictures.json`` (per picture: its file, frame, time, the VTU files it was
drawn from, the elements in view, alive and drawn); report.html shows them
(:mod:`.report`).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import matplotlib
import meshio
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import colormaps  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

from wovenimpact.io.atomic import atomic_path, atomic_write_text  # noqa: E402
from wovenimpact.io.fields import PVD_NAME, _frame_index, _part_name, read_pvd  # noqa: E402

PICTURES = "pictures"
INDEX = "pictures.json"
N_FRAMES = 4
MAX_POLYGONS = 6000
CASING_WINDOW_DEG = 30.0
DAMAGE_MAP, STRAIN_MAP, BLADE_GREY = "YlOrRd", "viridis", (0.62, 0.62, 0.66, 1.0)
RIM_COLOUR = (0.85, 0.0, 0.45, 1.0)  # the holes' rims: magenta, apart from both colour maps


@dataclass
class Part:
    """One VTU file of a frame as polygons: corner coordinates (n, 4, 3; a triangle
    repeats its last corner), reference centroids, the cell arrays by name, the points and
    their displacements, and the cells' point indices (n, 4)."""

    name: str
    corners: np.ndarray
    centroid0: np.ndarray
    cells: dict[str, np.ndarray]
    points: np.ndarray
    displacement: np.ndarray
    connectivity: np.ndarray | None = None


def read_part(path: str | Path, name: str = "") -> Part:
    """A VTU frame of :class:`~wovenimpact.io.fields.FieldWriter` as polygons (its quad
    and triangle blocks, in file order)."""
    mesh = meshio.read(path)
    x = np.asarray(mesh.points, dtype=float)
    u = np.asarray(mesh.point_data.get("displacement", np.zeros_like(x)), dtype=float)
    x0 = x - u
    conn = []
    for block in mesh.cells:
        c = np.asarray(block.data, dtype=np.int64)
        if c.shape[1] == 3:
            c = np.concatenate([c, c[:, 2:3]], axis=1)
        conn.append(c)
    conn = np.concatenate(conn) if conn else np.zeros((0, 4), dtype=np.int64)
    cells = {k: np.concatenate([np.asarray(a) for a in v]) for k, v in mesh.cell_data.items()}
    return Part(name, x[conn], x0[conn].mean(axis=1), cells, x, u, conn)


def frames_of(fields: str | Path) -> list[tuple[int, float, list[tuple[str, Path]]]]:
    """(frame k, time, [(part, path), …]) of the series in ``fields`` (``fields.pvd``)."""
    fields = Path(fields)
    frames: dict[int, tuple[float, list]] = {}
    for t, name in read_pvd(fields / PVD_NAME):
        k = _frame_index(name)
        if k is not None:
            frames.setdefault(k, (t, []))[1].append((_part_name(name), fields / name))
    return [(k, t, parts) for k, (t, parts) in sorted(frames.items())]


CONTACT_SHARE = 0.01  # "contact": above this share of the column's largest value


def first_contact_time(h: dict) -> float | None:
    """The time of the first history row with contact: the energy absorbed by a casing,
    the contact force on an impactor, or else the contact energy, above
    :data:`CONTACT_SHARE` of its largest value over the run (the layers' light contact
    with each other before the fragment arrives is not it); None if none."""
    t = np.asarray(h["time_s"], dtype=float)
    for c in ("casing_absorbed_energy_part_J", "contact_force_full_N", "contact_energy_part_J"):
        if c in h:
            y = np.abs(np.asarray(h[c], dtype=float))
            rows = np.flatnonzero((y > CONTACT_SHARE * y.max()) & (y > 0.0)) if y.size else []
            return float(t[rows[0]]) if len(rows) else None
    return None


def choose_frames(times, t_contact: float | None, n: int = N_FRAMES) -> list[int]:
    """Indices (into ``times``, the frames' times in order) of up to ``n`` frames: the
    first at or after ``t_contact`` (the first frame without contact), the last, and
    evenly spaced times between them (each the nearest frame), without repeats."""
    times = np.asarray(times, dtype=float)
    if times.size == 0:
        return []
    start = 0
    if t_contact is not None:
        after = np.flatnonzero(times >= t_contact)
        start = int(after[0]) if after.size else times.size - 1
    last = times.size - 1
    targets = np.linspace(times[start], times[last], max(n, 1)) if n > 1 else [times[last]]
    chosen = [start] + [int(np.argmin(np.abs(times - x))) for x in targets[1:-1]] + [last]
    return sorted(dict.fromkeys(i for i in chosen if start <= i <= last))


@dataclass
class View:
    """What a picture shows: per part, the mask of its cells in view (alive or not), the
    z shift of each cell (an exploded ply stack), the camera and a caption."""

    in_view: dict[str, np.ndarray]
    shift: dict[str, np.ndarray]
    elev: float
    azim: float
    caption: str
    radial: dict[str, np.ndarray] | None = None  # an outward shift of each cell (m)


def _nearest(centroid0: np.ndarray, centre: np.ndarray, budget: int) -> np.ndarray:
    """Mask of the ``budget`` cells nearest ``centre`` (in x, y) by reference centroid."""
    d = np.hypot(centroid0[:, 0] - centre[0], centroid0[:, 1] - centre[1])
    if d.size <= budget:
        return np.ones(d.size, dtype=bool)
    return d <= np.partition(d, budget - 1)[budget - 1]


def frame_view(parts: dict[str, Part], max_polygons: int = MAX_POLYGONS) -> View:
    """The :class:`View` of a frame (module docstring): a containment run's casing near
    the fragment, cut at its mid-height, with the blade; a plate's plies round the
    impact point, drawn apart."""
    if "casing" in parts and "blade" in parts:
        return _casing_view(parts["casing"], parts["blade"], max_polygons)
    in_view, shift = {}, {}
    for name, part in parts.items():
        u = np.linalg.norm(part.displacement, axis=1)
        centre = part.points[int(np.argmax(u))] - part.displacement[int(np.argmax(u))]
        in_view[name] = _nearest(part.centroid0, centre, max_polygons)
        ply = part.cells.get("ply", np.zeros(part.corners.shape[0], dtype=np.int64))
        plies = np.unique(ply)
        # the ply on top (largest reference z) first, each next one lowered by a gap
        top = sorted(plies, key=lambda p: -float(np.mean(part.centroid0[ply == p, 2])))
        c = part.centroid0[in_view[name]]
        extent = float(max(np.ptp(c[:, 0]), np.ptp(c[:, 1]))) if c.size else 0.0
        gap = 0.25 * extent if len(plies) > 1 else 0.0
        rank = {p: i for i, p in enumerate(top)}
        shift[name] = -gap * np.array([rank[p] for p in ply], dtype=float)
    n_plies = len(np.unique(np.concatenate(
        [p.cells.get("ply", np.zeros(1, dtype=np.int64)) for p in parts.values()])))
    caption = "plies round the impact point"
    if n_plies > 1:
        caption += f", drawn {gap * 1e3:.3g} mm apart along z (an exploded view)"
    return View(in_view, shift, elev=25.0, azim=-60.0, caption=caption)


def _casing_view(casing: Part, blade: Part, max_polygons: int) -> View:
    """A containment frame's view: the casing within :data:`CASING_WINDOW_DEG` of the
    blade's outermost node, below the fragment's mid-height, its layers drawn apart
    radially (layer k moved out by k gaps) so each shows; the blade's outer half."""
    r = np.hypot(blade.points[:, 0], blade.points[:, 1])
    tip = blade.points[int(np.argmax(r))]
    phi0 = math.atan2(tip[1], tip[0])
    c0 = casing.centroid0
    phi = np.arctan2(c0[:, 1], c0[:, 0])
    dphi = np.abs(np.angle(np.exp(1j * (phi - phi0))))
    # the fragment: the blade's nodes beyond half its outermost radius; its mid-height cuts
    frag = blade.points[r >= 0.5 * r.max()]
    z_cut = 0.5 * (frag[:, 2].min() + frag[:, 2].max())
    in_casing = (dphi <= math.radians(CASING_WINDOW_DEG)) & (c0[:, 2] <= z_cut)
    if in_casing.sum() > max_polygons // 2:
        cand = np.flatnonzero(in_casing)
        keep = cand[np.argsort(dphi[cand], kind="stable")[:max_polygons // 2]]
        in_casing = np.zeros_like(in_casing)
        in_casing[keep] = True
    rb = np.hypot(*blade.corners.mean(axis=1)[:, :2].T)
    near_blade = rb >= 0.5 * r.max()
    if near_blade.sum() > max_polygons // 2:  # the cells nearest the tip
        d = np.linalg.norm(blade.corners.mean(axis=1) - tip, axis=1)
        near_blade &= d <= np.partition(d, max_polygons // 2 - 1)[max_polygons // 2 - 1]
    layer = casing.cells.get("ply", np.zeros(c0.shape[0], dtype=np.int64))
    rank = np.searchsorted(np.unique(layer), layer)
    gap = 0.04 * float(np.min(np.hypot(c0[:, 0], c0[:, 1])))
    return View({"casing": in_casing, "blade": near_blade},
                {"casing": np.zeros(c0.shape[0]), "blade": np.zeros(blade.corners.shape[0])},
                elev=50.0, azim=math.degrees(phi0) + 180.0,
                caption=f"casing within {CASING_WINDOW_DEG:.0f}° of the fragment, cut at "
                        f"its mid-height (z = {z_cut * 1e3:.0f} mm), seen from the axis, "
                        f"its layers drawn {gap * 1e3:.3g} mm apart radially (an exploded "
                        "view); the blade's outer half in grey",
                radial={"casing": gap * rank})


@dataclass
class Polygons:
    """What a picture draws: corners (n, 4, 3), face colours (n, 4), the drawn cells'
    ``element`` ids, counts of the view (cells, alive, drawn), and the rim of the holes
    (m, 2, 3): the drawn cells' edges that eroded cells share (:func:`rim_edges`)."""

    corners: np.ndarray
    colours: np.ndarray
    elements: np.ndarray
    in_view: int
    alive: int
    strain_max: float
    fabric: bool
    metal: bool
    rim: np.ndarray = field(default_factory=lambda: np.zeros((0, 2, 3)))


def rim_edges(connectivity: np.ndarray, drawn: np.ndarray, eroded: np.ndarray) -> np.ndarray:
    """(m, 2) (row of ``drawn``, local edge c) of the edges of the drawn cells that an
    eroded cell shares: the rim of a hole. ``connectivity`` (n, 4) point indices of all
    cells (a triangle repeats its last corner: that edge is skipped); ``drawn`` and
    ``eroded`` the indices of the drawn and the eroded cells."""
    if not (drawn.size and eroded.size):
        return np.zeros((0, 2), dtype=np.int64)

    def keys(cells):
        a = connectivity[cells]
        b = np.roll(a, -1, axis=1)
        lo, hi = np.minimum(a, b), np.maximum(a, b)
        return lo * (int(connectivity.max()) + 1) + hi, a != b

    gone, real = keys(eroded)
    gone = np.unique(gone[real])
    mine, real = keys(drawn)
    row, edge = np.nonzero(real & np.isin(mine, gone))
    return np.stack([row, edge], axis=1)


def frame_polygons(parts: dict[str, Part], view: View) -> Polygons:
    """The polygons of the alive cells in ``view`` (eroded ones left out), coloured: fabric
    by damage, metal by plastic strain (on one scale over the picture), the blade grey."""
    rows, rims = [], []
    for name, part in parts.items():
        sel = view.in_view[name]
        alive = np.asarray(part.cells.get("alive", np.ones(sel.size)), dtype=float) != 0.0
        draw = sel & alive
        corners = part.corners[draw].copy()
        corners[:, :, 2] += view.shift[name][draw][:, None]
        if view.radial and name in view.radial:  # out along the cell's own radius
            c = corners.mean(axis=1)
            rc = np.maximum(np.hypot(c[:, 0], c[:, 1]), 1e-12)
            corners[:, :, :2] += (view.radial[name][draw] / rc)[:, None, None] * c[:, None, :2]
        n = corners.shape[0]
        damage = np.maximum(part.cells.get("damage_warp", np.zeros(sel.size)),
                            part.cells.get("damage_fill", np.zeros(sel.size)))[draw]
        strain = np.asarray(part.cells.get("plastic_strain", np.zeros(sel.size)))[draw]
        fabric = np.asarray(part.cells.get("fabric", damage > 0.0), dtype=bool)
        fabric = fabric[draw] if fabric.shape[0] == sel.size else fabric
        rows.append((name, corners, damage, strain, fabric, part.cells.get(
            "element", np.arange(sel.size))[draw], int(sel.sum()), int(draw.sum()), n))
        if part.connectivity is not None and name != "blade":
            rim = rim_edges(part.connectivity, np.flatnonzero(draw), np.flatnonzero(sel & ~alive))
            rims.append(np.stack([corners[rim[:, 0], rim[:, 1]],
                                  corners[rim[:, 0], (rim[:, 1] + 1) % 4]], axis=1))
    strain_max = max([float(np.max(r[3], initial=0.0)) for r in rows if r[0] != "blade"]
                     + [1e-3])
    dmap, smap = colormaps[DAMAGE_MAP], colormaps[STRAIN_MAP]
    colours = []
    for name, corners, damage, strain, fabric, *_ in rows:
        c = np.where(fabric[:, None], dmap(np.clip(damage, 0.0, 1.0)),
                     smap(np.clip(strain / strain_max, 0.0, 1.0)))
        if name == "blade":
            c = np.tile(BLADE_GREY, (corners.shape[0], 1))
        colours.append(c.reshape(-1, 4))
    has = [(r[4].any(), (~r[4]).any()) for r in rows if r[0] != "blade"]
    return Polygons(np.concatenate([r[1] for r in rows]) if rows else np.zeros((0, 4, 3)),
                    np.concatenate(colours) if colours else np.zeros((0, 4)),
                    np.concatenate([r[5] for r in rows]) if rows else np.zeros(0, int),
                    sum(r[6] for r in rows), sum(r[7] for r in rows), strain_max,
                    any(f for f, _ in has), any(m for _, m in has),
                    np.concatenate(rims) if rims else np.zeros((0, 2, 3)))


def draw(polygons: Polygons, view: View, path: str | Path, title: str) -> Poly3DCollection:
    """Render ``polygons`` off-screen to a PNG at ``path``; returns the collection drawn
    (one: matplotlib sorts the faces of one collection by depth)."""
    fig = plt.figure(figsize=(7.0, 5.2))
    ax = fig.add_subplot(projection="3d")
    coll = Poly3DCollection(polygons.corners, facecolors=polygons.colours,
                            edgecolors=(0, 0, 0, 0.15), linewidths=0.15)
    ax.add_collection3d(coll)
    if polygons.rim.shape[0]:  # the holes' rims, over the faces
        ax.add_collection3d(Line3DCollection(polygons.rim, colors=RIM_COLOUR, linewidths=1.4))
    pts = polygons.corners.reshape(-1, 3)
    if pts.size:
        # one scale on every axis (true shape), an axis at least 5 % of the longest
        lo, hi = pts.min(axis=0), pts.max(axis=0)
        span = np.maximum(hi - lo, 0.05 * max(float(np.max(hi - lo)), 1e-9))
        mid = 0.5 * (lo + hi)
        ax.set_xlim(mid[0] - span[0] / 2, mid[0] + span[0] / 2)
        ax.set_ylim(mid[1] - span[1] / 2, mid[1] + span[1] / 2)
        ax.set_zlim(mid[2] - span[2] / 2, mid[2] + span[2] / 2)
        ax.set_box_aspect(tuple(span / span.max()))
    ax.view_init(elev=view.elev, azim=view.azim)
    ax.set_axis_off()
    ax.set_title(title, fontsize=9)
    if polygons.fabric:
        fig.colorbar(plt.cm.ScalarMappable(Normalize(0.0, 1.0), DAMAGE_MAP), ax=ax,
                     shrink=0.55, pad=0.0, label="fabric damage (largest of warp, fill)")
    if polygons.metal:
        fig.colorbar(plt.cm.ScalarMappable(Normalize(0.0, polygons.strain_max), STRAIN_MAP),
                     ax=ax, shrink=0.55, pad=0.08, label="metal plastic strain ε̄p")
    fig.subplots_adjust(left=0.0, right=1.0, bottom=0.0, top=0.93)
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    with atomic_path(Path(path)) as tmp:
        fig.savefig(tmp, dpi=100, format="png")
    plt.close(fig)
    return coll


def write_pictures(out_dir: str | Path, h: dict, n: int = N_FRAMES) -> list[dict]:
    """Draw up to ``n`` frames of the run in ``out_dir`` (:func:`choose_frames`) into
    ``OUT/pictures`` and list them in ``pictures.json``; returns that list. A run without
    field frames writes none."""
    out = Path(out_dir)
    folder = out / PICTURES
    for old in folder.glob("frame_*.png"):
        old.unlink()
    frames = frames_of(out / "fields")
    index = []
    for i in choose_frames([t for _, t, _ in frames], first_contact_time(h), n):
        k, t, files = frames[i]
        parts = {name: read_part(path, name) for name, path in files}
        view = frame_view(parts)
        polygons = frame_polygons(parts, view)
        eroded = polygons.in_view - polygons.alive
        title = (f"t = {t * 1e6:.1f} µs (frame {k}): {polygons.alive} elements drawn"
                 + (f", {eroded} eroded hidden" if eroded else ""))
        name = f"frame_{k:06d}.png"
        draw(polygons, view, folder / name, title)
        index.append({"file": name, "frame": k, "time_s": t,
                      "vtu": [p.name for _, p in files], "caption": view.caption,
                      "elements_in_view": polygons.in_view, "alive_in_view": polygons.alive,
                      "drawn": int(polygons.corners.shape[0])})
    if index or (folder / INDEX).exists():
        folder.mkdir(parents=True, exist_ok=True)
        atomic_write_text(folder / INDEX, json.dumps(index, indent=2) + "\n")
    return index
