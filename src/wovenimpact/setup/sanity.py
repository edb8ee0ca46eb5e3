"""Physical sanity of a compiled case, checked before the first step (issue 12).

A case can pass every per-key check and still describe a run that means nothing or
never ends. :func:`check_case` looks at the compiled Model and State as a careful
analyst would before pressing "run" (the list, and what is a warning rather than an
error, is in docs/inputs.md):

- the run's size: the first stable step Δt₁ = α min_e L_e/c_e (eq. 4.8) from one pass of
  the element kernel, and the predicted step count ``end_time / Δt₁``, refused above
  ``run.max_steps``, naming Δt₁, the governing element, its section and material, and
  why the step is small (a wave speed L_e/Δt_e above that of any material means a
  stiffness far too high or a mass far too low);
- motion per step: no node (initial velocity), impactor or body-force displacement may
  cross more than half the smallest element in one step (penalty contact and the
  element kinematics both assume small increments);
- geometry: plies whose mid-planes are closer than a shell thickness overlap; a section
  thicker than the whole mesh is not a shell, and elements more than 1000 thicknesses
  across are a unit slip (a mesh in mm read as m);
- constraints: one degree of freedom both held and driven, or driven at two speeds;
- the impactor: its path must cross the structure ahead of its nose; a contact later
  than ``run.end_time`` is a warning with the gap and the arrival time; an impactor
  lighter than a thousandth of the material under its face is refused;
- a section's areal mass far (×10) from its material's is warned of.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from wovenimpact.errors import InputError, InputWarning
from wovenimpact.kernels import rigid_body as RB
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.model.mesh import node_set
from wovenimpact.model.model import DOF_NAMES, flies_sideways, sideways_shadow
from wovenimpact.spec.case import SYMMETRY_AXIS, PlateMeshSpec

MAX_WAVE_SPEED = 2.0e4  # m/s: above any engineering material's (diamond ~18 km/s)
MAX_CROSSING = 0.5  # of the smallest element length moved in one step
MIN_IMPACTOR_MASS_RATIO = 1e-3  # impactor mass / mass of the structure under its face
MIN_THICKNESS = 1e-6  # m
MAX_EXTENT = 1e3  # m: a structure a kilometre across is a unit slip in an impact model
MAX_RADIUS_EXTENTS = 10.0  # impactor radius / largest extent of the mesh
MIN_RADIUS_ELEMENTS = 0.1  # impactor radius / largest element edge (thesis study: 2.78/6 mm)
MAX_QUIET_OUTPUTS = 1000  # outputs at every step beyond this many are warned of
AREAL_MASS_FACTOR = 10.0  # a section's areal mass this far from its material's is warned of
# element edge / thickness: casing rings at 21 mm over 0.25 mm plies are ~100; a mesh in mm
# read as m gives thousands
MAX_SIZE_TO_THICKNESS = 1000.0


def _text(seconds: float) -> str:
    return f"{seconds:.3g} s"


def first_step(model, state) -> tuple[float, int]:
    """Δt₁ = α min_e L_e/c_e at the initial state and the governing element (one pass of
    the element kernels; nothing in ``state`` changes). The shells are elements 0 …
    n_elems − 1; element n_elems + h is hexahedron h (:func:`element_name`)."""
    from wovenimpact.kernels.solid_layout import H_DT
    from wovenimpact.solver.explicit import Workspace, element_steps, shell_forces
    from wovenimpact.solver.solid_stage import solid_forces

    ws = Workspace.for_model(model, state)
    shell_forces(model, state, ws)
    dt_el = element_steps(ws.elem)
    if model.n_hexes:
        solid_forces(model, state, ws.hex, ws.solid)
        dt_el = np.concatenate([dt_el, ws.hex[:, H_DT]])
    e = int(np.argmin(dt_el))
    return model.alpha * float(dt_el[e]), e


def element_name(model, e: int) -> str:
    """"element e" for a shell, "hexahedron h" for element n_elems + h (first_step)."""
    return f"element {e}" if e < model.n_elems else f"hexahedron {e - model.n_elems}"


def element_length(model, e: int) -> float:
    """L_e = area / longest edge of element ``e`` at t = 0 (the kernel's length); for a
    hexahedron (e ≥ n_elems) its shortest edge."""
    if e >= model.n_elems:
        return float(_hex_edges(model, [e - model.n_elems]).min())
    p = model.x0[model.quads[e]]
    edges = np.linalg.norm(np.roll(p, -1, axis=0) - p, axis=1)
    return float(model.area0[e] / edges.max())


def _section_text(model, e: int, spec) -> str:
    """The section and material of element ``e`` with the values that set its step."""
    if e >= model.n_elems:
        from wovenimpact.kernels import solid_layout as HL

        s = model.solid
        h = e - model.n_elems
        p = s.params[s.mat[h]]
        return (f"solid section {s.section_names[s.section[h]]!r} (material "
                f"{s.material_names[s.mat[h]]!r}): E11 {p[HL.TI_E11]:.3g} Pa, E22 "
                f"{p[HL.TI_E22]:.3g} Pa, density {p[HL.TI_RHO]:.3g} kg/m^3")
    sec = int(model.elem_section[e])
    row = model.sections[sec]
    name = model.section_names[sec] if sec < len(model.section_names) else str(sec)
    material = spec.sections[name].material if name in spec.sections else "?"
    return (f"section {name!r} (material {material!r}): thickness {row[SL.C_THICK]:.3g} m, "
            f"areal mass {row[SL.C_AREAL_MASS]:.3g} kg/m^2, bending modulus "
            f"{row[SL.C_BEND_E]:.3g} Pa, transverse shear modulus {row[SL.C_SHEAR_G]:.3g} Pa")


def check_step_count(model, state, spec) -> float:
    """Refuse a run whose predicted step count ``end_time / Δt₁`` exceeds
    ``run.max_steps``; returns Δt₁."""
    end_time, max_steps = spec.run.end_time, spec.run.max_steps
    dt, e = first_step(model, state)
    if not (math.isfinite(dt) and dt > 0.0):
        return dt  # the solver names a non-finite step at the first step
    steps = end_time / dt
    if steps < 1.0:
        warnings.warn(
            f"run.end_time = {_text(end_time)} is shorter than the first step (Δt = {dt:.3g} s, "
            f"{element_name(model, e)}): the run is one step", InputWarning, stacklevel=3)
    if steps <= max_steps:
        return dt
    length = element_length(model, e)
    speed = length / (dt / model.alpha)
    if speed > MAX_WAVE_SPEED:
        why = (f"its wave speed L_e/Δt_e = {speed:.3g} m/s is far above any material's "
               f"(≤ {MAX_WAVE_SPEED:g} m/s): a stiffness far too high or a mass far too "
               f"low in {_section_text(model, e, spec)}")
    else:
        why = (f"the step is normal for elements of {length:.3g} m (wave speed "
               f"{speed:.3g} m/s): run.end_time = {_text(end_time)} is long for this model")
    raise InputError(
        f"run: the run would take {steps:.3g} steps (run.end_time = {_text(end_time)} / first "
        f"Δt = {dt:.3g} s, governed by {element_name(model, e)}), more than run.max_steps = "
        f"{max_steps:g}; "
        f"{why} (valid: fewer steps, or a larger run.max_steps if this is meant)")


def check_motion_per_step(model, state, dt: float, spec) -> None:
    """Nothing may cross more than MAX_CROSSING of the smallest element in one step."""
    if not (math.isfinite(dt) and dt > 0.0):
        return
    h = smallest_edge(model)
    if h <= 0.0:
        return
    limit = MAX_CROSSING * h
    speed = float(np.sqrt(np.max(np.sum(state.v**2, axis=1)))) if state.v.size else 0.0
    if speed * dt > limit:
        raise InputError(
            f"initial_velocity: a node at {speed:.3g} m/s moves {speed * dt:.3g} m in one step "
            f"(Δt = {dt:.3g} s), more than half the smallest element ({h:.3g} m) (valid: "
            f"speeds below {limit / dt:.3g} m/s)")
    if spec.impactor is not None and spec.impactor.velocity * dt > limit:
        v = spec.impactor.velocity
        raise InputError(
            f"impactor.velocity = {v:.3g} m/s moves the impactor {v * dt:.3g} m in one step "
            f"(Δt = {dt:.3g} s), more than half the smallest element ({h:.3g} m): contact "
            f"would be missed (valid: below {limit / dt:.3g} m/s)")
    if spec.body_force is not None:
        a = float(np.linalg.norm(spec.body_force.acceleration))
        if 0.5 * a * dt * dt > limit:
            raise InputError(
                f"body_force.acceleration: {a:.3g} m/s^2 moves a free node "
                f"{0.5 * a * dt * dt:.3g} m in one step (Δt = {dt:.3g} s), more than half "
                f"the smallest element ({h:.3g} m) (valid: below {2 * limit / dt**2:.3g} m/s^2)")


def warn_output_intervals(spec, dt: float) -> None:
    """An output interval shorter than the first step writes at every step: warned of
    when that is more than MAX_QUIET_OUTPUTS outputs."""
    if not (math.isfinite(dt) and dt > 0.0) or spec.run.end_time / dt <= MAX_QUIET_OUTPUTS:
        return
    for key in ("field_interval", "history_interval", "checkpoint_interval"):
        value = getattr(spec.run, key)
        if value is not None and value < dt:
            warnings.warn(
                f"run.{key} = {_text(value)} is shorter than the first step (Δt = {dt:.3g} s): "
                f"an output at every step, about {spec.run.end_time / dt:.3g} of them",
                InputWarning, stacklevel=3)


def check_plies(spec, model) -> None:
    """Plies of a plate whose mid-planes are closer than their shell thicknesses (the
    mean of two neighbours') overlap."""
    m = spec.mesh
    if not (isinstance(m, PlateMeshSpec) and m.plies > 1 and m.spacing is not None):
        return  # without spacing (ply_sections) the plies are stacked by their thicknesses
    first = [int(np.flatnonzero(model.ply == k)[0]) for k in range(m.plies)]
    t = [float(model.sections[model.elem_section[e], SL.C_THICK]) for e in first]
    need = max(0.5 * (a + b) for a, b in zip(t[:-1], t[1:]))
    if m.spacing < need * (1.0 - 1e-9):
        raise InputError(
            f"mesh.spacing = {m.spacing:.4g} m is less than the shell thickness {need:.4g} m of "
            "the plies: the plies overlap (valid: spacing ≥ "
            f"{need:.4g} m; plies that touch are one thickness apart)")


def check_thickness(model, spec) -> None:
    """A mesh larger than MAX_EXTENT is a unit slip; a section thicker than the whole
    mesh is not a shell, one thinner than MIN_THICKNESS no structure."""
    extent = float(np.max(np.ptp(model.x0, axis=0))) if model.n_nodes else 0.0
    if extent > MAX_EXTENT:
        raise InputError(
            f"mesh: the structure is {extent:.3g} m across, more than {MAX_EXTENT:g} m (valid: "
            "an impact model; check the units of the mesh, coordinates are in metres)")
    for sec in np.unique(model.elem_section):
        t = float(model.sections[sec, SL.C_THICK])
        if t < MIN_THICKNESS:
            e = int(np.flatnonzero(model.elem_section == sec)[0])
            raise InputError(
                f"sections: thickness {t:.3g} m is below {MIN_THICKNESS:g} m in "
                f"{_section_text(model, e, spec)} (valid: a structural shell, foil and "
                "fabric are 10 µm and thicker)")
        edge = _median_edge(model, sec)
        if edge > MAX_SIZE_TO_THICKNESS * t:
            e = int(np.flatnonzero(model.elem_section == sec)[0])
            unit = ("; a mesh drawn in millimetres read as metres? give mesh.length_unit = "
                    "'1 mm'" if hasattr(spec.mesh, "length_unit") else "")
            raise InputError(
                f"sections: elements {edge:.3g} m across (median edge) are "
                f"{edge / t:.3g} times their thickness {t:.3g} m in "
                f"{_section_text(model, e, spec)}, more than {MAX_SIZE_TO_THICKNESS:g} (valid: "
                f"an impact model's elements, a few to a few hundred thicknesses{unit})")
        if extent > 0.0 and t > extent:
            e = int(np.flatnonzero(model.elem_section == sec)[0])
            raise InputError(
                f"sections: thickness {t:.3g} m is larger than the whole mesh ({extent:.3g} m "
                f"across) in {_section_text(model, e, spec)} (valid: a shell thinner than the "
                "structure it models)")


def _edges(model, elems=slice(None)) -> np.ndarray:
    """The non-zero reference edge lengths (m) of ``elems`` (a triangle's repeated
    corner gives a zero edge, left out)."""
    p = model.x0[model.quads[elems]]
    edges = np.linalg.norm(np.roll(p, -1, axis=1) - p, axis=2)
    return edges[edges > 0]


def _hex_edges(model, hexes=slice(None)) -> np.ndarray:
    """The 12 reference edge lengths (m) of each of ``hexes`` (n, 12)."""
    p = model.x0[model.solid.hexes[hexes]]  # (n, 8, 3): two faces of 4, 4 → 8 above
    ring = np.linalg.norm(np.roll(p[:, :4], -1, axis=1) - p[:, :4], axis=2)
    top = np.linalg.norm(np.roll(p[:, 4:], -1, axis=1) - p[:, 4:], axis=2)
    up = np.linalg.norm(p[:, 4:] - p[:, :4], axis=2)
    return np.concatenate([ring, top, up], axis=1)


def smallest_edge(model) -> float:
    """The smallest reference edge length of the model, shells and hexahedra (m; 0
    without elements)."""
    edges = _edges(model)
    if model.n_hexes:
        edges = np.concatenate([edges, _hex_edges(model).ravel()])
    return float(edges.min()) if edges.size else 0.0


def _median_edge(model, sec: int) -> float:
    """The median edge length (m) of the elements of section ``sec``."""
    edges = _edges(model, model.elem_section == sec)
    return float(np.median(edges)) if edges.size else 0.0


def check_constraints(spec, mesh) -> None:
    """Refuse a degree of freedom both held and driven, or driven at two speeds."""
    code = np.zeros((mesh.n_nodes, 6), dtype=np.int8)  # 0 free, 1 held, 2 driven
    value = np.zeros((mesh.n_nodes, 6))
    owner = np.full((mesh.n_nodes, 6), -1, dtype=np.int64)
    for i, b in enumerate(spec.boundary):
        nodes = node_set(mesh, b.nodes, f"boundary[{i}].nodes")
        if b.type == "clamped":
            dofs, kind, v = range(6), 1, 0.0
        elif b.type == "pinned":
            dofs, kind, v = range(3), 1, 0.0
        elif b.type in SYMMETRY_AXIS:
            a = SYMMETRY_AXIS[b.type]
            dofs, kind, v = [a] + [3 + k for k in range(3) if k != a], 1, 0.0
        else:
            dofs, kind, v = [DOF_NAMES.index(b.dof)], 2, b.velocity
        for d in dofs:
            clash = nodes[(code[nodes, d] != 0)
                          & ((code[nodes, d] != kind) | (value[nodes, d] != v))]
            if clash.size:
                n = int(clash[0])
                j = int(owner[n, d])
                raise InputError(
                    f"boundary[{i}] ({b.type} on {b.nodes!r}) contradicts boundary[{j}] "
                    f"({spec.boundary[j].type} on {spec.boundary[j].nodes!r}) at {clash.size} "
                    f"nodes (first: node {n}, {DOF_NAMES[d]}): a degree of freedom is either "
                    "held or driven at one velocity (valid: disjoint node sets, or the same "
                    "constraint)")
            code[nodes, d] = kind
            value[nodes, d] = v
            owner[nodes, d] = i


def check_impactor(spec, model, state) -> None:
    """The impactor's path must meet the structure ahead of its nose, in time, and the
    impactor must not be negligible against what it strikes."""
    im = spec.impactor
    if im is None or not model.body_params.shape[0]:
        return
    p = model.body_params[0]
    st = model.body_state0[0]
    axis = st[RB.B_R:RB.B_R + 9].reshape(3, 3)[:, 0]
    tip = st[RB.B_X:RB.B_X + 3] - p[RB.BP_TIP] * axis
    direction = np.asarray(im.direction, dtype=float)
    direction = direction / np.linalg.norm(direction)
    if flies_sideways(model, 0):  # ahead of its leading line, within its shadow
        ahead, outside = sideways_shadow(model, st, 0, model.x0)
        beside = outside <= 0.0
    else:
        rel = model.x0 - tip
        ahead = rel @ direction
        radial = np.linalg.norm(rel - np.outer(ahead, direction), axis=1)
        beside = radial <= im.radius
    under = beside & (ahead > 0.0)
    if not under.any():
        behind = beside & (ahead <= 0.0)
        where = ("the structure is behind the nose (it moves away from it)" if behind.any()
                 else "no node lies within the impactor's radius of its line of flight")
        raise InputError(
            f"impactor.position / impactor.direction: the impactor's path misses the "
            f"structure: {where} (nose tip at {np.round(tip, 6).tolist()} m, direction "
            f"{np.round(direction, 6).tolist()}) (valid: the nose ahead of the plies, "
            "travelling towards them)")
    extent = float(np.max(np.ptp(model.x0, axis=0)))
    if im.radius > MAX_RADIUS_EXTENTS * extent:
        raise InputError(
            f"impactor.radius = {im.radius:.3g} m is more than {MAX_RADIUS_EXTENTS:g} times the "
            f"whole structure ({extent:.3g} m across) (valid: an impactor the mesh resolves)")
    p_face = model.x0[model.quads]
    h = float(np.linalg.norm(np.roll(p_face, -1, axis=1) - p_face, axis=2).max(initial=0.0))
    if model.n_hexes:
        h = max(h, float(_hex_edges(model).max()))
    if im.radius < MIN_RADIUS_ELEMENTS * h:
        raise InputError(
            f"impactor.radius = {im.radius:.3g} m is less than {MIN_RADIUS_ELEMENTS:g} of the "
            f"largest element edge ({h:.3g} m): a needle between the nodes, which the "
            f"node-on-body contact cannot see (valid: a radius ≥ {MIN_RADIUS_ELEMENTS * h:.3g} "
            "m, or a finer mesh)")
    gap = float(ahead[under].min() - model.node_offset[under].max())
    arrival = max(gap, 0.0) / im.velocity
    if arrival > spec.run.end_time:
        warnings.warn(
            f"impactor.position: the nose is {gap:.4g} m from the structure and reaches it at "
            f"t = {_text(arrival)} (at {im.velocity:g} m/s), after run.end_time = "
            f"{_text(spec.run.end_time)}: the run ends before any contact",
            InputWarning, stacklevel=3)
    struck = float(model.node_mass[under].sum())
    mass = float(p[RB.BP_MASS])
    if mass < MIN_IMPACTOR_MASS_RATIO * struck:
        raise InputError(
            f"impactor.mass: the impactor ({mass / p[RB.BP_FRACTION]:.3g} kg) is "
            f"{struck / mass:.3g} times lighter than the structure under its face "
            f"({struck / p[RB.BP_FRACTION]:.3g} kg): it cannot load the plies, and its "
            f"energy balance is round-off (valid: at least {MIN_IMPACTOR_MASS_RATIO:g} of "
            "the mass it strikes)")


def warn_areal_mass(spec, sections) -> None:
    """A section's areal mass far from its material's (a unit slip, an extra zero)."""
    for name, s in spec.sections.items():
        if s.areal_mass is None:
            continue
        m = sections[name].material
        own = getattr(m, "areal_mass", None)
        if own is None and s.thickness is not None and hasattr(m, "density"):
            own = m.density * s.thickness
        if own and not (own / AREAL_MASS_FACTOR <= s.areal_mass <= own * AREAL_MASS_FACTOR):
            warnings.warn(
                f"sections.{name}.areal_mass = {s.areal_mass:.3g} kg/m^2 is {s.areal_mass / own:.3g} "
                f"times its material's {own:.3g} kg/m^2", InputWarning, stacklevel=3)


def check_case(spec, model, state, mesh, sections) -> float:
    """Every check of this module, cheapest first (see the module docstring); returns
    the first stable step Δt₁ (inf when none is known)."""
    check_constraints(spec, mesh)
    check_plies(spec, model)
    check_thickness(model, spec)
    warn_areal_mass(spec, sections)
    check_impactor(spec, model, state)
    dt = check_step_count(model, state, spec)
    warn_output_intervals(spec, dt)
    check_motion_per_step(model, state, dt, spec)
    return dt
