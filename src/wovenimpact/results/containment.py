"""Engineering quantities of a containment run (thesis ch. 8; docs/theory.md §8.3).

A containment model (``[mesh] kind = "containment"``) has node sets ``blade.fragment``
and ``casing.layer{k}``. Per history row: the fragment's centre-of-mass speed, radial
velocity and radius, its outermost node's radius, and whether intact casing material
lies outside it along its path. The outcome is decided from geometry, never from a
speed test alone (:func:`containment_outcome`).
"""

from __future__ import annotations

import math

import numpy as np

from wovenimpact.kernels import shell_layout as SL
from wovenimpact.results.quantities import held_energy

FRAGMENT = "blade.fragment"
WINDOW = 1.5  # half-width of the path window, in fragment half-extents


def is_containment(model) -> bool:
    return FRAGMENT in model.node_sets


def layer_sets(model) -> list[str]:
    """Names of the casing layers' node sets, innermost first."""
    k = 0
    out = []
    while f"casing.layer{k}" in model.node_sets:
        out.append(f"casing.layer{k}")
        k += 1
    return out


def anchored_casing_nodes(model, state, casing: np.ndarray) -> np.ndarray:
    """The nodes of ``casing`` joined through live casing elements to a constrained
    casing node (the clamped ends and cut edges hold the casing): a boolean mask over
    ``casing``. A piece of ply torn free and flying ahead of the fragment holds nothing
    (theory §8.3). A casing with no constrained node (a user's free-standing mesh) has
    nothing to be joined to: then every node with a live element counts."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    in_casing = np.zeros(model.n_nodes, dtype=bool)
    in_casing[casing] = True
    q = model.quads[(state.elem[:, SL.E_ALIVE] != 0.0) & in_casing[model.quads].all(axis=1)]
    live = np.zeros(model.n_nodes, dtype=bool)
    live[q.ravel()] = True
    constrained = in_casing & np.any(model.bc_code != 0, axis=1)
    if not np.any(constrained):
        return live[casing]
    held = constrained & live
    edges = np.concatenate([q[:, [0, 1]], q[:, [1, 2]], q[:, [2, 3]], q[:, [3, 0]]])
    graph = coo_matrix((np.ones(len(edges)), (edges[:, 0], edges[:, 1])),
                       shape=(model.n_nodes, model.n_nodes))
    _, label = connected_components(graph, directed=False)
    anchored = np.zeros(label.max() + 1, dtype=bool)
    anchored[label[held]] = True
    return live[casing] & anchored[label[casing]]


def _angle_from(phi: np.ndarray, phi0: float) -> np.ndarray:
    """|φ − φ₀| wrapped to [0, π]."""
    return np.abs(np.angle(np.exp(1j * (phi - phi0))))


def _within_angle(xy: np.ndarray, phi0: float, half_angle: float) -> np.ndarray:
    """Mask of the points (x, y) whose polar angle is within ``half_angle`` of φ₀
    (:func:`_angle_from`), the trigonometry done only for those the cosine test
    (x, y)·(cos φ₀, sin φ₀) ≥ r cos(half_angle) − 10⁻⁹ r leaves: a bound loose enough that
    it drops no point the exact test would keep."""
    r = np.hypot(xy[:, 0], xy[:, 1])
    maybe = xy[:, 0] * math.cos(phi0) + xy[:, 1] * math.sin(phi0) >= r * (
        math.cos(min(half_angle, math.pi)) - 1e-9)
    out = np.zeros(xy.shape[0], dtype=bool)
    sub = xy[maybe]
    out[maybe] = _angle_from(np.arctan2(sub[:, 1], sub[:, 0]), phi0) <= half_angle
    return out


class CasingWatch:
    """What :func:`fragment_row` reads of a containment model, computed once per run:
    the fragment's nodes and masses, the casing's nodes, the path window's floor (two
    casing elements), the casing's inner radius and the casing nodes' reference
    positions; and the casing's anchored-node mask (:func:`anchored_casing_nodes`),
    recomputed only when a casing element has eroded since it was last computed
    (erosion is permanent, so the count of live casing elements names the live set).
    A history row of the 10-ply casing (57 k elements) took 18 ms with all of it
    recomputed, every 4–5 steps (theory §8.3)."""

    def __init__(self, model):
        self.nodes = model.node_sets[FRAGMENT]
        self.m = model.node_mass[self.nodes]
        self.mass = float(self.m.sum())
        self.casing = np.concatenate([model.node_sets[s] for s in layer_sets(model)])
        self.size = 2.0 * math.sqrt(float(np.median(
            model.area0[np.isin(model.quads[:, 0], self.casing)])))
        r0 = np.hypot(*model.x0[self.casing, :2].T)
        self.r_casing = float(np.min(r0))
        self.x0 = model.x0[self.casing]
        in_casing = np.zeros(model.n_nodes, dtype=bool)
        in_casing[self.casing] = True
        self.casing_elems = np.flatnonzero(in_casing[model.quads].all(axis=1))
        # the layers' elements and their nodes, as the summary's absorbed energies count
        # them (layer_elements, layer_absorbed_energies): the history's casing energies
        self.layer_elems = np.concatenate(layer_elements(model))
        self.layer_nodes = np.unique(model.quads[self.layer_elems])
        self.layer_node_mass = model.node_mass[self.layer_nodes]
        # each layer's nodes (layer_absorbed_energies) and each node's layer (−1: none)
        self.nodes_of_layer = [np.unique(model.quads[e]) for e in layer_elements(model)]
        self.node_layer = np.full(model.n_nodes, -1, dtype=np.int64)
        for k, nodes in enumerate(self.nodes_of_layer):
            self.node_layer[nodes] = k
        self._live = -1
        self._anchored = np.zeros(model.n_nodes, dtype=bool)

    def anchored(self, model, state) -> np.ndarray:
        """(n_nodes,) mask of the casing nodes joined to its supports through live
        elements (:func:`anchored_casing_nodes`); do not modify it."""
        live = int(np.count_nonzero(state.elem[self.casing_elems, SL.E_ALIVE]))
        if live != self._live:
            self._anchored = np.zeros(model.n_nodes, dtype=bool)
            self._anchored[self.casing] = anchored_casing_nodes(model, state, self.casing)
            self._live = live
        return self._anchored


def fragment_row(model, state, watch: CasingWatch | None = None) -> dict:
    """The fragment's kinematics and the intact casing material outside it.

    ``intact_casing_outside``: 1 if a casing node joined to the casing's supports
    through live elements (:func:`anchored_casing_nodes`) lies within the fragment's
    path window (angular and axial extent of the fragment × 1.5 about its centre of
    mass, at least two casing elements either way) at a larger radius than the
    fragment's outermost node. ``watch``: the run's :class:`CasingWatch` (one is made
    when not given).
    """
    w = CasingWatch(model) if watch is None else watch
    k = _path_window(model, state, w)
    cm, r_nodes, v_cm = k["cm"], k["r_nodes"], k["v_cm"]
    r_cm = math.hypot(cm[0], cm[1])
    radial = (v_cm[0] * cm[0] + v_cm[1] * cm[1]) / r_cm if r_cm > 0 else 0.0
    outside = bool(np.any(k["r_window"] > float(r_nodes.max())))
    # is there casing at the fragment's angle and height at all? A sector's cut edges
    # end the model: past them the rest of the ring is missing, not broken
    size, r_casing = w.size, w.r_casing
    x0 = w.x0[np.abs(w.x0[:, 2] - cm[2]) <= size]
    covered = bool(np.any(_within_angle(x0, k["phi_cm"], size / r_casing)))
    return {
        "fragment_speed_m_per_s": float(np.linalg.norm(v_cm)),
        "fragment_radial_velocity_m_per_s": float(radial),
        "fragment_cm_radius_m": float(r_cm),
        "fragment_max_radius_m": float(r_nodes.max()),
        "fragment_min_radius_m": float(r_nodes.min()),
        "intact_casing_outside": int(outside),
        "fragment_beyond_casing": int(not covered),
        "outer_layer_bulge_m": outer_layer_bulge(model, state, k["anchored"]),
    }


def _path_window(model, state, w: CasingWatch) -> dict:
    """The fragment's nodes and centre of mass, and the anchored casing nodes within its
    path window (:func:`fragment_row`): their indices ``window`` and radii ``r_window``."""
    m, mass = w.m, w.mass
    x = state.x[w.nodes]
    cm = (m[:, None] * x).sum(axis=0) / mass
    v_cm = (m[:, None] * state.v[w.nodes]).sum(axis=0) / mass
    r_nodes = np.hypot(x[:, 0], x[:, 1])
    phi = np.arctan2(x[:, 1], x[:, 0])
    phi_cm = math.atan2(cm[1], cm[0])
    # the window is at least two casing elements wide either way (a blade seen edge-on
    # from the axis has no angular extent of its own)
    size, r_casing = w.size, w.r_casing
    half_angle = max(WINDOW * float(np.max(_angle_from(phi, phi_cm))), size / r_casing)
    half_z = max(WINDOW * float(np.max(np.abs(x[:, 2] - cm[2]))), size)
    anchored = w.anchored(model, state)
    # the height and cosine tests first: they are cheap and leave few nodes for the angles
    idx = np.flatnonzero(anchored)
    xc = state.x[idx]
    keep = np.abs(xc[:, 2] - cm[2]) <= half_z
    idx, xc = idx[keep], xc[keep]
    near = _within_angle(xc, phi_cm, half_angle)
    return {"x": x, "cm": cm, "v_cm": v_cm, "r_nodes": r_nodes, "phi_cm": phi_cm,
            "anchored": anchored, "window": idx[near],
            "r_window": np.hypot(xc[near, 0], xc[near, 1])}


def layer_columns(n_layers: int) -> tuple[str, ...]:
    """The per-layer history columns of a casing of ``n_layers`` layers
    (:func:`layer_row`), appended after :data:`CASING_ENERGY_COLUMNS`: every layer's
    absorbed energy, then every layer's intact-outside flag, innermost layer first."""
    return (tuple(f"casing_layer{k}_absorbed_energy_part_J" for k in range(n_layers))
            + tuple(f"casing_layer{k}_intact_outside" for k in range(n_layers)))


def layer_row(model, state, watch: CasingWatch | None = None) -> dict:
    """Each casing layer's share of a history row (:func:`layer_columns`; layer 0 the
    innermost, the inner shell of a hybrid casing):

    - ``casing_layer{k}_absorbed_energy_part_J``: the contact work layer k's nodes received
      so far (J, modelled part), :func:`layer_absorbed_energies` of the row: the summary's
      ``absorbed_energy_per_layer_J`` at the end, and summed over the layers the row's
      ``casing_absorbed_energy_part_J`` (the layers share no node; within round-off);
    - ``casing_layer{k}_intact_outside``: 1 if a node of layer k joined to the casing's
      supports through live elements lies in the fragment's path window at a larger
      radius than the fragment's outermost node — ``intact_casing_outside`` of
      :func:`fragment_row` asked of that layer alone (the row's flag is 1 exactly when one
      of the layers' is). A layer is *perforated* from the first row it reads 0
      (:func:`layer_perforation_times`).
    """
    w = CasingWatch(model) if watch is None else watch
    k = _path_window(model, state, w)
    r_max = float(k["r_nodes"].max())
    layer = w.node_layer[k["window"]]
    out_layers = np.unique(layer[k["r_window"] > r_max])
    n = len(w.nodes_of_layer)
    row = {f"casing_layer{j}_absorbed_energy_part_J": float(np.sum(state.contact_work[nodes]))
           for j, nodes in enumerate(w.nodes_of_layer)}
    row.update({f"casing_layer{j}_intact_outside": int(j in out_layers) for j in range(n)})
    return row


def layer_perforation_times(h: dict, n_layers: int) -> list[float | None]:
    """The time each casing layer was first perforated (s, innermost first; None for a
    layer never perforated): the first history row at which no intact material of that
    layer lies outside the fragment along its path (``casing_layer{k}_intact_outside``
    = 0, :func:`layer_row`) — the geometric test the outcome rule makes of the whole
    casing (``intact_casing_outside``), asked of each layer. A history without the
    per-layer columns (an older run) gives None for every layer."""
    t = np.asarray(h["time_s"], dtype=float)
    out: list[float | None] = []
    for k in range(n_layers):
        flags = h.get(f"casing_layer{k}_intact_outside")
        rows = np.flatnonzero(np.asarray(flags) == 0) if flags is not None else ()
        out.append(float(t[rows[0]]) if len(rows) else None)
    return out


def outcome_decided_at(h: dict, inner_radius: float,
                       outer_radius: float = math.inf) -> float | None:
    """The time from which every history row has read the run's final outcome
    (:func:`decided_since`), None when it is undecided."""
    outcome, since = decided_since(h, inner_radius, outer_radius)
    return None if outcome == "undecided" else since


CONTAINMENT_COLUMNS = ("fragment_speed_m_per_s", "fragment_radial_velocity_m_per_s",
                       "fragment_cm_radius_m", "fragment_max_radius_m", "fragment_min_radius_m",
                       "intact_casing_outside",
                       "fragment_beyond_casing",
                       "outer_layer_bulge_m")


CASING_ENERGY_COLUMNS = ("fragment_kinetic_energy_part_J", "casing_kinetic_energy_part_J",
                         "casing_element_energy_part_J", "casing_absorbed_energy_part_J")


def casing_energy_row(model, state, watch: CasingWatch | None = None) -> dict:
    """The energies of a containment run's two parties (J, modelled part), the history
    columns :data:`CASING_ENERGY_COLUMNS` that the energy plot draws on their own axes
    (the fragment's kinetic energy, kilojoules, would flatten the casing's):

    - ``fragment_kinetic_energy_part_J``: Σ ½ m v² over the fragment's nodes;
    - ``casing_kinetic_energy_part_J``: the same over the casing layers' nodes;
    - ``casing_element_energy_part_J``: the stored and hourglass energy the casing
      layers' elements hold (an eroded element's as it held it at erosion), as
      :func:`layer_energies` counts them — not what broken yarns or plastic flow
      dissipated, which no element holds;
    - ``casing_absorbed_energy_part_J``: the contact work the casing layers' nodes
      received so far, the summary's ``casing_absorbed_energy_J`` at the end
      (:func:`layer_absorbed_energies`).
    """
    w = CasingWatch(model) if watch is None else watch
    v_f = state.v[w.nodes]
    v_c = state.v[w.layer_nodes]
    e = w.layer_elems
    return {
        "fragment_kinetic_energy_part_J": 0.5 * float(np.sum(w.m * np.sum(v_f * v_f, axis=1))),
        "casing_kinetic_energy_part_J": 0.5 * float(np.sum(w.layer_node_mass
                                                           * np.sum(v_c * v_c, axis=1))),
        # three columns gathered, not the elements' whole rows
        "casing_element_energy_part_J": float(np.sum(state.elem[e, SL.E_U_MEMB])
                                              + np.sum(state.elem[e, SL.E_U_BEND])
                                              + np.sum(state.elem[e, SL.E_U_HG])),
        "casing_absorbed_energy_part_J": float(np.sum(state.contact_work[w.layer_nodes])),
    }


def outer_layer_bulge(model, state, anchored: np.ndarray | None = None) -> float:
    """The outermost casing layer's largest outward radial displacement (m): max over its
    nodes still joined to the supports through live elements (:func:`anchored_casing_nodes`)
    of r(x) − r(x0), r the distance from the casing axis (the z axis); 0 once none is.
    Torn-off pieces flying away are not a bulge (a 4-ply run read 330 mm from them); a
    bulge reached before the layer tore stays in the run's maximum (``max_bulge_m``).
    ``anchored``: the caller's (n_nodes,) mask of those nodes, if it has one (the layers
    share no node, so the outer layer's share of the whole casing's mask is its own)."""
    nodes = model.node_sets[layer_sets(model)[-1]]
    if anchored is None:
        nodes = nodes[anchored_casing_nodes(model, state, nodes)]
    else:
        nodes = nodes[anchored[nodes]]
    if nodes.size == 0:
        return 0.0
    r0 = np.hypot(model.x0[nodes, 0], model.x0[nodes, 1])
    r1 = np.hypot(state.x[nodes, 0], state.x[nodes, 1])
    return float(np.max(r1 - r0))


def layer_elements(model) -> list[np.ndarray]:
    """The elements of each casing layer, innermost first: its element set
    ``casing.layer{k}`` where the mesh has one, else the elements whose four nodes are all
    in the layer's node set."""
    out = []
    for name in layer_sets(model):
        elems = model.elem_sets.get(name)
        if elems is None:
            elems = np.flatnonzero(np.isin(model.quads, model.node_sets[name]).all(axis=1))
        out.append(np.asarray(elems, dtype=np.int64))
    return out


def layer_energies(model, state) -> list[float]:
    """Energy each casing layer holds (J, innermost first): the kinetic energy of its
    nodes plus the energy of its elements (stored, hourglass, plastic; for eroded
    elements the energy they held at erosion), as ``quantities.ply_energies`` counts a
    ply's. Not what it absorbed: energy its broken yarns dissipated and the kinetic
    energy of its eroded pieces are gone from it (:func:`layer_absorbed_energies`)."""
    return [held_energy(model, state, elems) for elems in layer_elements(model)]


def layer_absorbed_energies(model, state) -> list[float]:
    """Energy each casing layer absorbed (J, innermost first): the work the contact
    forces did on its nodes, ``State.contact_work`` summed over them (theory §8.3). Energy
    reaches a layer only through contact (its clamped nodes do not move), so this is what
    it holds, what it dissipated and what its eroded pieces carried away; a layer that
    passes energy on to the next one through contact counts only what it kept."""
    return [float(np.sum(state.contact_work[np.unique(model.quads[elems])]))
            for elems in layer_elements(model)]


def layer_materials(model) -> list[str]:
    """The material of each casing layer, innermost first (that of the section most of
    its elements have): the material's own name (the ``name`` of its file), or, for a
    material built without one in code, the name of the case's section."""
    out = []
    for elems in layer_elements(model):
        sec = int(np.bincount(model.elem_section[elems]).argmax()) if elems.size else 0
        name = model.material_names[int(model.sections[sec, SL.C_MAT])]
        out.append(name or model.section_names[sec])
    return out


def energy_per_material(model, state) -> dict[str, float]:
    """:func:`layer_absorbed_energies` summed over the layers of each material (J): what
    the aluminium and what the Kevlar of a hybrid casing absorbed."""
    out: dict[str, float] = {}
    for name, e in zip(layer_materials(model), layer_absorbed_energies(model, state)):
        out[name] = out.get(name, 0.0) + e
    return out


EXIT_SPEED_SETTLED = 0.005  # an escaped fragment's speed over the hold, relative
EXIT_SPEED_WINDOW = 500e-6  # s: the end of a run over which the summary checks it


def containment_outcome(h: dict, inner_radius: float, outer_radius: float = math.inf) -> dict:
    """Outcome of a containment run from its history (geometry first):

    - ``escaped``: no intact casing material outside the fragment along its path at the
      end (it has passed the outermost intact layer) and it still moves outwards; or it
      is *clear of the casing* — its innermost node beyond ``outer_radius``, the casing's
      outermost reference radius — moving outwards, and its speed has stayed within
      :data:`EXIT_SPEED_SETTLED` of its last value over the last
      :data:`EXIT_SPEED_WINDOW` (strips of a metal casing peeled out beside it, still
      joined to the casing, do not hold a fragment that nothing slows; theory §8.5);
    - ``contained``: it reached the casing (its outermost node came within 1 % of the
      inner radius) and at the end moves inwards or along the casing (radial velocity
      ≤ 1 % of its initial speed) with intact material outside it;
    - ``undecided``: anything else (still pushing intact layers outwards, or never
      arrived): run longer — or the fragment has left the modelled casing sideways
      (``fragment_beyond_casing``: past a sector's cut edge, where the rest of the ring
      is not modelled): model more of the ring. A heavy fragment still pushing intact
      layers is never ``escaped``.
    Returns the outcome, ``contained`` (bool), the exit speed — its speed at the end if
    escaped, 0 if contained, None if undecided (no exit speed is known: a fit or a
    verdict must not read the speed of a fragment still in the casing as one) — and
    ``fragment_speed_at_end_m_per_s`` whatever the outcome."""
    speed = np.asarray(h["fragment_speed_m_per_s"], dtype=float)
    outcome = str(row_outcomes(h, inner_radius, outer_radius)[-1])
    exit_speed = {"escaped": float(speed[-1]), "contained": 0.0}.get(outcome)
    return {"outcome": outcome, "contained": outcome == "contained",
            "fragment_exit_speed_m_per_s": exit_speed,
            "fragment_speed_at_end_m_per_s": float(speed[-1])}


def row_outcomes(h: dict, inner_radius: float, outer_radius: float = math.inf) -> np.ndarray:
    """:func:`containment_outcome` of the history up to each row: what the run would
    have read had it ended there (``arrived`` counts the rows up to that one). A history
    without ``fragment_min_radius_m`` or ``time_s`` (an older run) never reads clear of
    the casing."""
    speed = np.asarray(h["fragment_speed_m_per_s"], dtype=float)
    radial = np.asarray(h["fragment_radial_velocity_m_per_s"], dtype=float)
    reach = np.asarray(h["fragment_max_radius_m"], dtype=float)
    outside = np.asarray(h["intact_casing_outside"], dtype=float) != 0.0
    beyond = np.asarray(h.get("fragment_beyond_casing", np.zeros(outside.shape)),
                        dtype=float) != 0.0
    arrived = np.maximum.accumulate(reach >= 0.99 * inner_radius) if reach.size else reach
    v0 = float(speed[0]) if speed.size else 0.0
    out = np.full(speed.shape, "undecided", dtype=object)
    out[arrived & outside & (radial <= 0.01 * v0)] = "contained"
    out[~outside & (radial > 0.0)] = "escaped"
    out[clear_and_unslowed(h, outer_radius, outside & (radial > 0.0))] = "escaped"
    # past a sector's cut edge or the casing's end: the model cannot tell
    out[beyond] = "undecided"
    return out


def clear_and_unslowed(h: dict, outer_radius: float, rows: np.ndarray) -> np.ndarray:
    """Of the history rows flagged in ``rows``, those at which the fragment is clear of
    the casing (innermost node beyond ``outer_radius``) and its speed has stayed within
    :data:`EXIT_SPEED_SETTLED` of that row's over the :data:`EXIT_SPEED_WINDOW` before
    it (the history must span the window): nothing holds it any more. Geometry first —
    a fragment still inside the casing's envelope never qualifies, however steady."""
    out = np.zeros(rows.shape, dtype=bool)
    if "fragment_min_radius_m" not in h or "time_s" not in h or not math.isfinite(outer_radius):
        return out
    t = np.asarray(h["time_s"], dtype=float)
    v = np.asarray(h["fragment_speed_m_per_s"], dtype=float)
    inner_node = np.asarray(h["fragment_min_radius_m"], dtype=float)
    for i in np.flatnonzero(rows & (inner_node > outer_radius)):
        # the history up to row i, read by the one rule of a settled speed
        prefix = {"time_s": t[:i + 1], "fragment_speed_m_per_s": v[:i + 1]}
        out[i] = (t[i] - t[0] >= EXIT_SPEED_WINDOW
                  and speed_settled(prefix, t[i] - EXIT_SPEED_WINDOW))
    return out


def decided_since(h: dict, inner_radius: float,
                  outer_radius: float = math.inf) -> tuple[str, float]:
    """The outcome the history reads at its last row and the time from which every row
    has read it (``run.stop_when_decided`` stops a run once that lasts long enough)."""
    rows = row_outcomes(h, inner_radius, outer_radius)
    t = np.asarray(h["time_s"], dtype=float)
    if rows.size == 0:
        return "undecided", float("nan")
    changed = np.flatnonzero(rows != rows[-1])
    return str(rows[-1]), float(t[changed[-1] + 1] if changed.size else t[0])


def speed_settled(h: dict, start: float, tol: float = EXIT_SPEED_SETTLED) -> bool:
    """Whether the fragment's speed has stayed within ``tol`` of its last value in every
    history row from time ``start`` on. A fragment through the casing can still drag
    torn plies that hang from it (2 plies on the 7 mm ring: 117.7 → 111.5 m/s over the
    500 µs after it passed the outer ply): until its speed settles, the exit speed is
    not known."""
    t = np.asarray(h["time_s"], dtype=float)
    v = np.asarray(h["fragment_speed_m_per_s"], dtype=float)
    window = v[t >= start]
    # a Python bool: summary.json carries it (numpy's bool_ is not JSON)
    return bool(window.size) and bool(np.max(np.abs(window - v[-1])) <= tol * abs(v[-1]))


def exit_speed_settled(h: dict, outcome: str) -> bool | None:
    """For an escaped fragment, whether its speed settled over the last
    :data:`EXIT_SPEED_WINDOW` of the history (:func:`speed_settled`): False means the
    exit speed was still changing when the run ended (run it longer), and a regression
    of exit speeds must not use it. None for any other outcome."""
    if outcome != "escaped":
        return None
    t = np.asarray(h["time_s"], dtype=float)
    return speed_settled(h, float(t[-1]) - EXIT_SPEED_WINDOW)


def casing_inner_radius(model) -> float:
    """The smallest radius of any casing node in the reference configuration (m)."""
    return min(float(np.min(np.hypot(*model.x0[model.node_sets[s], :2].T)))
               for s in layer_sets(model))


def casing_outer_radius(model) -> float:
    """The largest radius of any casing node in the reference configuration (m): a
    fragment whose every node lies beyond it is clear of the casing."""
    return max(float(np.max(np.hypot(*model.x0[model.node_sets[s], :2].T)))
               for s in layer_sets(model))


def casing_summary(model, state, h: dict) -> dict:
    """summary.json keys of a containment run (whole model; symmetry is not used)."""
    nodes = model.node_sets[FRAGMENT]
    layers = layer_sets(model)
    outcome = containment_outcome(h, casing_inner_radius(model), casing_outer_radius(model))
    casing_elems = np.flatnonzero(np.isin(model.quads, np.concatenate(
        [model.node_sets[s] for s in layers])).all(axis=1))
    areal = model.sections[model.elem_section, SL.C_AREAL_MASS]
    mass = float(np.sum(areal[casing_elems] * model.area0[casing_elems]))
    # the wall's mass per unit area: each layer's own (its mass over its area) summed
    # through the wall — the mass over the mean layer area would weigh the heavy inner
    # shell, at the smallest radius, by less than its areal mass (−0.4 % at 16 plies)
    per_area = sum(float(np.sum(areal[e] * model.area0[e]) / np.sum(model.area0[e]))
                   for e in layer_elements(model) if e.size)
    bulge = np.asarray(h.get("outer_layer_bulge_m", ()), dtype=float)
    absorbed = layer_absorbed_energies(model, state)
    return {
        **outcome,
        "layer_perforated_at_s": layer_perforation_times(h, len(layers)),
        "outcome_decided_at_s": outcome_decided_at(h, casing_inner_radius(model),
                                                   casing_outer_radius(model)),
        "fragment_exit_speed_settled": exit_speed_settled(h, outcome["outcome"]),
        "fragment_mass_kg": float(model.node_mass[nodes].sum()),
        "fragment_initial_speed_m_per_s": float(h["fragment_speed_m_per_s"][0]),
        # the largest over the history rows and the end state (a bulge that springs back
        # is still the casing's largest deflection)
        "max_bulge_m": max([outer_layer_bulge(model, state), *bulge.tolist()]),
        "absorbed_energy_per_layer_J": absorbed,
        # the whole casing's, the figure of the mesh-convergence studies (a sweep metric)
        "casing_absorbed_energy_J": float(sum(absorbed)),
        "held_energy_per_layer_J": layer_energies(model, state),
        "absorbed_energy_per_material_J": energy_per_material(model, state),
        "casing_mass_kg": mass,
        "casing_mass_per_area_kg_per_m2": per_area if per_area else None,
        "casing_layers": len(layers),
    }
