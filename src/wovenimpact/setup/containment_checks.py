"""Checks of a containment case's geometry (issue 11; docs/inputs.md, "Case: containment").

A containment run reads its outcome from geometry (``results/containment.py``): the casing's
layers as surfaces about the z axis, innermost first, and the fragment's path through
them. A generated casing is built that way; an imported one (``[mesh.containment]``)
or a generated one with unusual parameters can break those assumptions and still
run to a confident, wrong answer. These checks refuse that before the first step:

- :func:`check_spin_speed` (before the spin-up): the blade's tip must not cross more
  than half the smallest element in one step (the velocity check of ``setup.sanity``
  runs before the blade spins);
- :func:`check_containment` (on the spun blade): the layers are disjoint, listed
  innermost first, each a surface about the z axis (the spin axis), not coincident;
  the blade, its contact offset counted, starts inside the casing's inner surface; the
  fragment's straight path from release meets the modelled casing; casing elements in
  no layer, a fragment meeting the casing outside a generated casing's fine zone, a
  sector whose cut edges no boundary holds and a release time at or after the end time
  are warned of.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from wovenimpact.errors import InputError, InputWarning
from wovenimpact.results.containment import layer_sets
from wovenimpact.setup.sanity import MAX_CROSSING, smallest_edge

MAX_RADIAL_SPREAD = 0.25  # a layer's (r_max − r_min) / r_mean about the z axis
MIN_GAP_FRACTION = 0.1  # layers closer than this fraction of their thickness coincide


def _layers(mesh) -> list[np.ndarray]:
    """The casing layers' node sets, innermost first (``containment.layer_sets``)."""
    return [np.asarray(mesh.node_sets[name], dtype=np.int64) for name in layer_sets(mesh)]


def _key(spec, k: int | None = None) -> str:
    """The case key that names the casing layers (``[mesh.containment]`` of an imported
    mesh, ``mesh.casing`` of a generated one)."""
    imported = getattr(spec.mesh, "containment", None) is not None
    if imported:
        return "mesh.containment.casing_layers" + ("" if k is None else f"[{k}]")
    return "mesh.casing" + ("" if k is None else f" (layer {k})")


def _radius(x: np.ndarray) -> np.ndarray:
    return np.hypot(x[:, 0], x[:, 1])


def check_spin_speed(spec, model, mesh, dt: float) -> None:
    """The blade's tip speed ω r_max times the first step Δt₁ must stay below half the
    smallest element (contact and element kinematics assume small increments): the
    smallest edge of the whole model, the blade's or the casing's, whichever is finer
    (the blade may have its own size, ``mesh.blade.element_size``)."""
    if spec.spin is None or not (math.isfinite(dt) and dt > 0.0):
        return
    blade = np.unique(mesh.quads[mesh.elem_sets["blade.blade"]])
    r_tip = float(_radius(mesh.nodes[blade]).max())
    tip = spec.spin.rate * r_tip
    h = smallest_edge(model)
    if tip * dt > MAX_CROSSING * h:
        raise InputError(
            f"spin.rate = {spec.spin.rate:.4g} rad/s moves the blade's tip at {tip:.3g} m/s "
            f"{tip * dt:.3g} m in one step (Δt = {dt:.3g} s), more than half the smallest "
            f"element ({h:.3g} m) (valid: below {MAX_CROSSING * h / (dt * r_tip):.4g} rad/s; "
            "a fan's tip moves at a few hundred m/s)")


def check_containment(spec, model, state, mesh) -> None:
    """The checks of the module docstring on the compiled model and the spun state."""
    layers = _layers(mesh)
    check_layers(spec, model, mesh, layers)
    blade_nodes = np.unique(mesh.quads[mesh.elem_sets["blade.blade"]])
    casing = np.concatenate(layers)
    check_blade_clearance(spec, model, state, blade_nodes, casing)
    check_fragment_path(spec, model, state, layers[0])
    cut = mesh.node_sets.get("casing.cut_edges")
    if cut is not None and len(cut) and np.any(np.all(model.bc_code[cut] == 0, axis=1)):
        warnings.warn(
            "mesh.casing: the sector's cut edges (node set casing.cut_edges) are free: the "
            "struck zone's hoop tension unloads through them, as no real casing's does; clamp "
            "them like the ends ([[boundary]] nodes = \"casing.cut_edges\", type = "
            "\"clamped\") or model the full ring", InputWarning, stacklevel=3)
    if spec.spin is not None and spec.spin.release_time >= spec.run.end_time:
        warnings.warn(
            f"spin.release_time = {spec.spin.release_time:.4g} s is not before run.end_time = "
            f"{spec.run.end_time:.4g} s: the fragment is never released in this run, and its "
            "speeds are those of the spinning blade", InputWarning, stacklevel=3)


def check_layers(spec, model, mesh, layers: list[np.ndarray]) -> None:
    """Disjoint layers, each about the z axis and holding whole elements, innermost
    first and not coincident; casing elements in no layer are warned of."""
    x0 = model.x0
    thick = model.node_offset * 2.0  # a node's largest shell thickness
    means = []
    for k, nodes in enumerate(layers):
        for j in range(k):
            shared = np.intersect1d(nodes, layers[j])
            if shared.size:
                raise InputError(
                    f"{_key(spec, k)}: shares {shared.size} nodes with {_key(spec, j)} "
                    "(the same set twice, or a set holding several layers): each layer is "
                    "its own set")
        if not np.isin(model.quads, nodes).all(axis=1).any():
            raise InputError(
                f"{_key(spec, k)}: the set holds no whole element (a node set of edges, such "
                "as the clamped ends?): give each layer's element set")
        r = _radius(x0[nodes])
        mean = float(r.mean())
        if (r.max() - r.min()) > MAX_RADIAL_SPREAD * mean:
            raise InputError(
                f"{_key(spec, k)}: its nodes lie between r = {r.min():.4g} and {r.max():.4g} m "
                "from the z axis; a casing layer must be a surface about the z axis, which "
                "the blade spins about (is the mesh centred on the axis, its axis along z?)")
        if means and mean <= means[-1]:
            raise InputError(
                f"{_key(spec, k)}: at mean radius {mean:.5g} m it does not lie outside layer "
                f"{k - 1} (mean radius {means[-1]:.5g} m): list the layers innermost first")
        if means:
            gap = mean - means[-1]
            t = 0.5 * (float(np.median(thick[nodes])) + float(np.median(thick[layers[k - 1]])))
            if gap < MIN_GAP_FRACTION * t:
                raise InputError(
                    f"{_key(spec, k)}: {gap:.3g} m from layer {k - 1}, less than a tenth of "
                    f"their thickness ({t:.3g} m): the layers coincide (valid: a spacing of "
                    "the order of the thickness; touching layers are one thickness apart)")
        means.append(mean)
    in_blade = np.zeros(model.n_elems, dtype=bool)
    in_blade[mesh.elem_sets["blade.blade"]] = True
    in_layer = np.zeros(model.n_nodes, dtype=bool)
    in_layer[np.concatenate(layers)] = True
    loose = np.flatnonzero(~in_blade & ~in_layer[model.quads].all(axis=1))
    if loose.size:
        warnings.warn(
            f"{_key(spec)}: {loose.size} elements outside the blade are in no casing layer "
            f"(first: element {loose[0]}): the outcome, the casing mass and the per-layer "
            "energies do not count them; list every layer if they are casing",
            InputWarning, stacklevel=4)


def check_blade_clearance(spec, model, state, blade: np.ndarray, casing: np.ndarray) -> None:
    """The spun blade's farthest reach (node radius plus its contact offset, half its
    thickness) must lie inside the casing's inner surface (innermost node radius less
    its offset): otherwise contact acts from the first step, or the blade starts
    through the casing."""
    reach = float(np.max(_radius(state.x[blade]) + model.node_offset[blade]))
    inner = float(np.min(_radius(model.x0[casing]) - model.node_offset[casing]))
    if reach >= inner:
        how = ("lower mesh.blade.tip_radius or raise mesh.casing.inner_radius"
               if getattr(spec.mesh, "containment", None) is None else
               "move the blade's tip inwards in the mesh")
        raise InputError(
            f"{_key(spec)}: the spun blade reaches r = {reach * 1e3:.4g} mm (its farthest node "
            f"and half its thickness), not inside the casing's inner surface at r = "
            f"{inner * 1e3:.4g} mm (its innermost node less half the shell's thickness): the "
            f"blade would start in contact with, or through, the casing ({how})")


def _first_hit(p: np.ndarray, v: np.ndarray, radius: float) -> tuple[int, float] | None:
    """Of the points p (n, 2) moving straight at v (n, 2) in the xy-plane from inside the
    circle of ``radius`` about the origin, the one that meets it first and the azimuth
    (rad) where it does; None when none moves."""
    a = np.sum(v * v, axis=1)
    b = 2.0 * np.sum(p * v, axis=1)
    c = np.sum(p * p, axis=1) - radius * radius
    moving = a > 0.0
    if not np.any(moving):
        return None
    t = np.full(len(p), np.inf)
    disc = np.sqrt(np.maximum(b * b - 4.0 * a * c, 0.0))
    t[moving] = (-b[moving] + disc[moving]) / (2.0 * a[moving])
    i = int(np.argmin(t))
    hit = p[i] + v[i] * t[i]
    return i, math.atan2(hit[1], hit[0])


def check_fragment_path(spec, model, state, inner_layer: np.ndarray) -> None:
    """The fragment must meet the inner layer where the casing is modelled (not in a
    sector's missing part): of its nodes, each flying straight from its spun state, the
    first to reach the layer's radius must reach it there (its tip, for a blade).
    Meeting a generated casing outside its fine zone is warned of."""
    frag = np.asarray(model.node_sets["blade.fragment"], dtype=np.int64)
    r_layer = _radius(model.x0[inner_layer])
    first = _first_hit(state.x[frag, :2], state.v[frag, :2], float(r_layer.mean()))
    if first is None:
        return
    node, phi = first
    p = state.x[frag[node], :2]
    az = np.sort(np.unique(np.round(np.arctan2(model.x0[inner_layer, 1],
                                               model.x0[inner_layer, 0]), 9)))
    gaps = np.diff(np.concatenate([az, [az[0] + 2.0 * math.pi]]))
    wide = max(3.0 * float(np.median(gaps)), math.radians(10.0))
    i = int(np.searchsorted(az, phi)) - 1  # the gap [az[i], az[i + 1]) holding phi
    if gaps[i % az.size] > wide:
        lo, hi = math.degrees(az[(i + 1) % az.size]), math.degrees(az[i % az.size])
        raise InputError(
            f"{_key(spec)}: the fragment's node {int(frag[node])}, flying from r = "
            f"{np.linalg.norm(p) * 1e3:.4g} mm at {math.degrees(math.atan2(p[1], p[0])):.4g}°, "
            "is the first to meet the casing's radius, at "
            f"{math.degrees(phi) % 360:.4g}°, where no casing is modelled (the casing spans "
            f"{lo % 360:.4g}° → {hi % 360:.4g}° counter-clockwise): the run would read undecided; turn "
            "the blade (mesh.blade.angle) or the sector (mesh.casing.centre_angle)")
    c = getattr(spec.mesh, "casing", None)
    if c is not None and getattr(c, "fine_sector", None) is not None:
        off = (phi - c.centre_angle + math.pi) % (2.0 * math.pi) - math.pi
        if abs(off) > 0.5 * c.fine_sector:
            warnings.warn(
                f"mesh.casing: the fragment meets the casing at {math.degrees(phi) % 360:.4g}°, "
                f"outside the fine zone ({math.degrees(c.centre_angle):.4g}° ± "
                f"{math.degrees(0.5 * c.fine_sector):.4g}°): the impact is meshed at "
                "coarse_element_size; move mesh.casing.centre_angle there",
                InputWarning, stacklevel=4)
