"""In-plane shear of the 3-D crossover cell by a pin-jointed frame (issue 39's picture-frame
virtual test; thesis §5.3.3, which could not get it to work): the shear stress against the
shear angle, run until the yarns jam, its locking angle and the trellis law the shell uses
(docs/theory.md §1.6, eqs. 3.13–3.16) beside it. Manual: docs/solid.md §6.7.

*Kinematics of the frame* (:func:`end_motion`). A picture frame of pin-jointed sides shears
the fabric homogeneously: with the shear angle γ (the loss of the right angle between the
families) the warp direction turns by +γ/2 and the fill direction by −γ/2 about z,

  F(γ) = [[cos γ/2, sin γ/2], [sin γ/2, cos γ/2]]  (F e_x = R(+γ/2) e_x, F e_y = R(−γ/2) e_y),

a pure shear without rotation, no fibre stretched. The yarns follow it as a pin-jointed net:
each yarn turns rigidly with its family while the crossings follow F. The end faces of a
yarn whose axis passes through c (its end faces' mean in-plane position: (0, y_j) for a
warp, (x_i, 0) for a fill) are therefore driven as a rigid body,

  x(γ) = F(γ) c + R(±γ/2) (X − c),

+ for the warp, − for the fill: the yarn's end section stays square to the yarn (the yarn is
not sheared in its plane by its clamp), its centre on the frame's homogeneous motion. For
the single crossover (c = 0) this is a rigid rotation of each yarn about the cell's centre;
in the 2 × 2 repeat (model.crossover_cell, ``repeat = 2``) it moves the parallel yarns toward
each other, pitch × cos γ apart, until they jam. Which end-face nodes are driven and what
holds them along z are the *End conditions* below; nothing else touches the cell, the yarns meet
through their contact (docs/solid.md §6.1), frictionless unless stated.

*End conditions* (``ends``; the in-plane drive x(γ) above is the same in each):

- ``"held"`` (default): every node of both end faces driven in x, y and held in z. The end
  section is clamped: it can neither rise nor tilt.
- ``"free_z"``: every node of both end faces driven in x, y, free in z: the end section can
  rise or sink (each node on its own), not tilt (its nodes' in-plane positions fix its
  plane). Nothing outside acts on the cell along z, and it starts at rest, so its momentum
  along z stays zero and its centre of mass keeps its height: the rigid vertical motion is
  removed by momentum, not by a support (``CellShear.centre_z`` reports it). But a yarn's
  two end faces can then part vertically, one up and one down (the yarn tilts and climbs
  through the cell), which a periodic fabric forbids (they are one section, a repeat
  apart): it shows where the crossings' misfit goes when nothing holds the yarns. (On the
  single crossover nothing then holds the two yarns together at all.)
- ``"hinged"``: only the line of each end face at mid-height across the yarn (its
  centreline's level: z = 0 at the inflection point) is driven in x, y and held in z; the
  rest of the face is free. The end section turns about that line — the yarn's slope at its
  inflection point is free, so its crimp can grow and the crossing open, the fabric
  thickening — while the inflection point keeps the mid-plane height that the weave's
  symmetries give it (a glide by one pitch with z → −z and a half turn about z, both
  kept by the frame's pure shear, make a periodic yarn's inflection points stay at z = 0).
  It needs an even number of elements through the yarn.

*The drive.* γ(t) = γ̇ ∫₀ᵗ A(s) ds, A the smooth step of thesis Fig. 8-3 over ``ramp`` (the
rate rises smoothly to γ̇). Each step, every driven node gets the velocity that takes it
from where it is to x(γ(t + Δt)) in one step (Δt capped at the first step's stable
increment, so the target is hit exactly while the step holds): the ends follow the
kinematics without drift.

*What is read* (:func:`shear_cell`):

- the frame's moment T, the generalised force conjugate to γ: T = Σ_a f_a · ∂x_a/∂γ over
  the driven nodes (f_a their reactions), so that T dγ is the work the frame puts in;
- the shear resultant N_s = T / A0 (N/m, A0 the cell's reference area in the plane) and
  the shear stress τ = N_s / t (Pa, t the cell's thickness, the shell's): τ dγ is the work
  per unit reference volume, the conjugate the shell's trellis law τ(γ) = G(|γ|) γ has
  (theory §1.6; its energy e(γ) = ∫ τ dγ is per unit reference volume too);
- the contact force between parallel yarns (the magnitude of the force warp 1 exerts on
  warp 0, and fill 1 on fill 0: the jamming force) and the crossing yarns' (warp on fill:
  their net force, and the sum of the four crossings' magnitudes);
- the cell's thickening (how far the crossings open), its centre of mass's and each end
  face's vertical displacement;
- the kinetic energy over the internal work (quasi-static when small), hourglass energy
  over internal work, and the energy error.

*Locking angle* (:func:`locking_angle`): the intersection of the tangents of the initial
and final branches of τ(γ), each a least-squares line over a stated window of the angle
range, the rule picture-frame tests use; and :func:`stiffening_angle`, where the tangent
first exceeds k times the initial one. :func:`trellis_law` evaluates the shell's law for a
fabric's parameters over the same angles, so both rules can be applied to both curves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from wovenimpact.calibration.crossover_cell import cell_solid
from wovenimpact.errors import InputError, SimulationError
from wovenimpact.interfaces import n_parts, part_names
from wovenimpact.kernels.fabric import shear_modulus_true
from wovenimpact.materials.fabric import trellis_locking_angles
from wovenimpact.model.crossover_cell import (
    centreline,
    crossover_cell,
    section_profile,
    trimmed_extent,
)
from wovenimpact.model.model import BoundaryConditions, ShellContactParams, build_model
from wovenimpact.results.contact_forces import interface_forces
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver.explicit import Workspace, step
from wovenimpact.state import initial_state

# windows of the locking rule, as fractions of the largest angle reached
INITIAL_WINDOW = (0.05, 0.25)
FINAL_WINDOW = (0.85, 1.0)
MIN_STIFFENING = 3.0  # final tangent over initial tangent below which nothing locked


def smooth_ramp_integral(t: float, ramp: float) -> float:
    """∫₀ᵗ A(s) ds of the smooth step A = ξ³(10 − 15ξ + 6ξ²), ξ = t / ramp (thesis Fig. 8-3):
    ramp (2.5 ξ⁴ − 3 ξ⁵ + ξ⁶) while ξ < 1, then ramp / 2 + (t − ramp)."""
    if ramp <= 0.0:
        return max(t, 0.0)
    if t >= ramp:
        return 0.5 * ramp + (t - ramp)
    xi = max(t, 0.0) / ramp
    return ramp * xi**4 * (2.5 - 3.0 * xi + xi * xi)


def frame_gradient(gamma: float) -> np.ndarray:
    """F(γ) of the pin-jointed frame (module docstring), 2 × 2."""
    c, s = math.cos(0.5 * gamma), math.sin(0.5 * gamma)
    return np.array([[c, s], [s, c]])


def _rotation(phi: float) -> np.ndarray:
    c, s = math.cos(phi), math.sin(phi)
    return np.array([[c, -s], [s, c]])


def end_motion(gamma: float, X: np.ndarray, centre: np.ndarray, turn: float) -> np.ndarray:
    """In-plane positions x(γ) = F(γ) c + R(turn γ/2)(X − c) of a yarn's end nodes at their
    reference positions X (n × 2); turn +1 for a warp, −1 for a fill (module docstring)."""
    return frame_gradient(gamma) @ centre + (X - centre) @ _rotation(0.5 * turn * gamma).T


def end_motion_rate(gamma: float, X: np.ndarray, centre: np.ndarray, turn: float) -> np.ndarray:
    """∂x/∂γ of :func:`end_motion` (n × 2): the virtual motion T is conjugate to."""
    c, s = math.cos(0.5 * gamma), math.sin(0.5 * gamma)
    dF = 0.5 * np.array([[-s, c], [c, -s]])
    phi = 0.5 * turn * gamma
    dR = 0.5 * turn * np.array([[-math.sin(phi), -math.cos(phi)],
                                [math.cos(phi), -math.sin(phi)]])
    return dF @ centre + (X - centre) @ dR.T


@dataclass(frozen=True)
class DrivenEnd:
    """One yarn's two end faces under the frame: node indices, reference in-plane
    positions, the yarn's axis point c and its turn (+1 warp, −1 fill)."""

    name: str
    nodes: np.ndarray
    X: np.ndarray
    centre: np.ndarray
    turn: float


END_CONDITIONS = ("held", "free_z", "hinged")


def mid_height_nodes(nodes: np.ndarray, xyz: np.ndarray) -> np.ndarray:
    """Those of an end face's ``nodes`` (coordinates ``xyz``) at mid-height of their
    column — the nodes sharing their in-plane position — i.e. on the yarn's centreline
    level across the face: one line across the yarn when the face has an even number of
    elements through the thickness, none when it is odd."""
    key = np.round(xyz[nodes, :2] / 1e-12).astype(np.int64)
    _, col = np.unique(key, axis=0, return_inverse=True)
    col = col.ravel()
    z = xyz[nodes, 2]
    keep = np.zeros(len(nodes), dtype=bool)
    for c in range(int(col.max()) + 1):
        m = np.flatnonzero(col == c)
        lo, hi = z[m].min(), z[m].max()
        keep[m] = np.abs(z[m] - 0.5 * (lo + hi)) <= 1e-9 * max(hi - lo, 1e-300)
    return nodes[keep]


def end_faces(cell, name: str) -> list[np.ndarray]:
    """The node sets of a yarn's two end faces (x_min, x_max for a warp, y_min, y_max for a
    fill), the face at the lower coordinate first."""
    sets = cell.mesh.node_sets
    lo, hi = ("x_min", "x_max") if name.startswith("warp") else ("y_min", "y_max")
    return [sets[f"{name}.{lo}"], sets[f"{name}.{hi}"]]


def driven_ends(cell, ends: str = "held") -> list[DrivenEnd]:
    """The driven nodes of each yarn of the cell (the single crossover's two yarns or the
    repeat's four): its two end faces (``ends`` "held" or "free_z"), or the line of each
    end face at mid-height across the yarn ("hinged"); c is the mean in-plane position of
    the yarn's end-face nodes in every case (the yarn's axis, the same point)."""
    if ends not in END_CONDITIONS:
        raise InputError(f"ends = {ends!r}: valid are {', '.join(END_CONDITIONS)}")
    out = []
    for name in cell.yarn_names:
        warp = name.startswith("warp")
        faces = end_faces(cell, name)
        centre = cell.mesh.nodes[np.concatenate(faces), :2].mean(axis=0)
        if ends == "hinged":
            faces = [mid_height_nodes(f, cell.mesh.nodes) for f in faces]
            if any(len(f) == 0 for f in faces):
                raise InputError("ends = 'hinged' needs an end face's mid-height line: "
                                 "valid is an even mesh.through (elements through a yarn)")
        nodes = np.concatenate(faces)
        X = cell.mesh.nodes[nodes, :2].copy()
        out.append(DrivenEnd(name=name, nodes=nodes, X=X, centre=centre,
                             turn=1.0 if warp else -1.0))
    return out


def cell_in_shear(cell_spec, material, *, hourglass: float = 0.05, contact=None,
                  ends: str = "held"):
    """(cell, model, ends): the crossover cell of a geometry spec (spec.crossover) of the
    transversely isotropic ``material`` with the frame's end conditions ``ends`` (module
    docstring, *End conditions*): the driven nodes prescribed in x, y (their velocities
    set each step by :func:`shear_cell`); held in z ("held", "hinged") or free ("free_z")."""
    cell, part = cell_solid(cell_spec, material, hourglass)
    mesh = cell.mesh
    driven = driven_ends(cell, ends)
    bcs = BoundaryConditions(len(mesh.nodes), ramp_time=0.0)
    for e in driven:
        if ends != "free_z":
            bcs.fix(e.nodes, (2,))
        bcs.prescribe(e.nodes, 0, 0.0).prescribe(e.nodes, 1, 0.0)
    model = build_model(mesh.nodes, np.zeros((0, 4), dtype=np.int64), {},
                        np.zeros(0, dtype=np.int64), bcs=bcs, solid=part,
                        node_sets=mesh.node_sets,
                        shell_contact=contact or ShellContactParams())
    return cell, model, driven


@dataclass(frozen=True)
class CellShear:
    """The curves of :func:`shear_cell` (SI; angles in rad).

    Attributes:
        gamma: the frame's shear angle at each sample.
        moment: T, the generalised force conjugate to γ (N·m).
        resultant: N_s = T / A0 (N/m); stress: τ = N_s / t (Pa).
        parallel_force: the contact force between parallel yarns, warp 1 on warp 0 plus
            fill 1 on fill 0 (magnitudes, N; zero in the single crossover).
        crossing_force: the magnitude of the force the warps exert on the fills (N): their
            net force, in which the crossings that press a fill up and those that press it
            down cancel.
        crossing_contact: Σ |F warp on fill| over the warp–fill pairs (N), each pair
            meeting at one crossing of the repeat: how hard the crossings press, summed.
        work: the frame's work ∫ T dγ (J), by the trapezoid rule over the samples.
        kinetic: kinetic energy over internal work at each sample.
        area, thickness: A0 (m²) and t (m).
        kinetic_fraction: the largest kinetic energy over internal work in the second half
            of the run (samples with γ above half the last; as calibration.cell_compression).
        hourglass_fraction, energy_error: at the end.
        stopped: why the run ended ("angle", or the solver's message).
        steps, elements, repeat.
        thickening: the cell's thickness (highest less lowest node) less its initial
            thickness at each sample (m): how far the crossings open vertically.
        centre_z: the vertical displacement of the cell's centre of mass at each sample
            (m): zero (to round-off) when nothing outside acts along z ("free_z").
        end_z: the mean vertical displacement of each end face (m), samples × yarns × 2
            (the yarns in ``cell.yarn_names`` order; the face at the lower coordinate
            first): a yarn whose two ends part vertically climbs through the cell.
        ends: the end conditions (module docstring).
    """

    gamma: np.ndarray
    moment: np.ndarray
    resultant: np.ndarray
    stress: np.ndarray
    parallel_force: np.ndarray
    crossing_force: np.ndarray
    crossing_contact: np.ndarray
    work: np.ndarray
    kinetic: np.ndarray
    area: float
    thickness: float
    kinetic_fraction: float
    hourglass_fraction: float
    energy_error: float
    stopped: str
    steps: int
    elements: int
    repeat: int
    thickening: np.ndarray
    centre_z: np.ndarray
    end_z: np.ndarray
    ends: str


def _part_index(names: list[str], name: str) -> int | None:
    return names.index(name) if name in names else None


def shear_cell(cell_spec, material, *, angle: float = math.radians(30.0), rate: float = 2e3,
               ramp: float = 5e-6, samples: int = 100, hourglass: float = 0.05,
               contact=None, max_kinetic: float = 0.05, ends: str = "held") -> CellShear:
    """Shear the cell in the pin-jointed frame (module docstring) to the shear angle
    ``angle`` (rad) at ``rate`` γ̇ (rad/s, ramped in over ``ramp`` s), sampling ``samples``
    times. The run stops early, saying why in ``stopped``, when it leaves quasi-statics —
    the kinetic energy, once it has fallen below a fifth of ``max_kinetic`` of the internal
    work after the ramp, rising above ``max_kinetic`` at a sample (dropped: something gave
    way and the cell moves on its own; the curve ends at the last quasi-static sample) — or
    when its time step collapses (a crushed element).
    ``ends``: the frame's end conditions, "held" (default), "free_z" or "hinged" (module
    docstring, *End conditions*)."""
    if not 0.0 < angle < 0.5 * math.pi:
        raise InputError(f"angle = {angle!r} rad: valid is 0 < angle < π/2")
    if not rate > 0.0:
        raise InputError(f"rate = {rate!r} rad/s: valid is a rate > 0")
    if not ramp >= 0.0:
        raise InputError(f"ramp = {ramp!r} s: valid is ramp ≥ 0")
    if not (isinstance(samples, int) and samples >= 4):
        raise InputError(f"samples = {samples!r}: valid is an integer ≥ 4")
    if not max_kinetic > 0.0:
        raise InputError(f"max_kinetic = {max_kinetic!r}: valid is a fraction > 0")
    cell, model, driven = cell_in_shear(cell_spec, material, hourglass=hourglass,
                                        contact=contact, ends=ends)
    names = part_names(model)
    parts = n_parts(model)
    pairs = [(_part_index(names, a), _part_index(names, b))
             for a, b in (("warp0", "warp1"), ("fill0", "fill1"))]
    pairs = [p for p in pairs if None not in p]
    warps = [i for i, n in enumerate(names) if n.startswith("warp")]
    fills = [i for i, n in enumerate(names) if n.startswith("fill")]
    state = initial_state(model)
    ws = Workspace.for_model(model, state)
    sx, sy = cell.size
    area, thickness = sx * sy, cell.thickness
    z0 = model.x0[:, 2].copy()
    height0 = float(np.ptp(z0))
    mass = np.asarray(ws.node_mass, float)
    faces = [end_faces(cell, n) for n in cell.yarn_names]
    end_rows = []

    def gamma_at(t: float) -> float:
        return rate * smooth_ramp_integral(t, ramp)

    step(model, state, ws)  # at rest: the stable increment of the undeformed cell
    dt_cap = state.dt
    rows, stopped, settled = [], "angle", False
    every = angle / samples
    next_sample = every
    while True:
        t_next = state.t + dt_cap
        g_next = gamma_at(t_next)
        for e in driven:
            target = end_motion(g_next, e.X, e.centre, e.turn)
            model.bc_velocity[e.nodes, :2] = (target - state.x[e.nodes, :2]) / dt_cap
        try:
            step(model, state, ws, dt_cap=dt_cap)
        except SimulationError as err:
            stopped = str(err)
            break
        g = gamma_at(state.t)
        if g < next_sample and g < angle:
            continue
        next_sample += every
        moment = 0.0
        for e in driven:
            moment += float(np.sum(state.f_ext[e.nodes, :2]
                                   * end_motion_rate(g, e.X, e.centre, e.turn)))
        f = interface_forces(ws.contact, parts)
        parallel = sum(float(np.linalg.norm(f[a, b])) for a, b in pairs)
        crossing = float(np.linalg.norm(sum(f[a, b] for a in warps for b in fills)))
        pressing = sum(float(np.linalg.norm(f[a, b])) for a in warps for b in fills)
        balance = energy_balance(model, state)
        z = state.x[:, 2]
        rows.append((g, moment, parallel, crossing, balance["kinetic_J"],
                     balance["internal_work_J"], balance["hourglass_J"],
                     balance["error_fraction"], state.t, float(np.ptp(z)) - height0,
                     float(np.sum(mass * (z - z0)) / np.sum(mass)), pressing))
        end_rows.append([[float(np.mean(z[f] - z0[f])) for f in pair] for pair in faces])
        if g >= angle:
            break
        ke, wi = balance["kinetic_J"], balance["internal_work_J"]
        # hysteresis: settled below a fifth of the limit, left above the limit
        settled = settled or (state.t >= ramp and ke <= 0.2 * max_kinetic * max(wi, 1e-300))
        if settled and ke > max_kinetic * max(wi, 1e-300):
            stopped = (f"kinetic energy {ke / max(wi, 1e-300):.3g} of the internal work at "
                       f"γ = {math.degrees(g):.2f}° (above max_kinetic = {max_kinetic:g})")
            rows.pop()
            end_rows.pop()
            break
    if not rows:
        raise SimulationError(f"the shear test stopped before its first sample: {stopped}")
    arr = np.array(rows)
    gam, moment, parallel, crossing, ke, wint, hg, err, t, thick, zc, pressing = arr.T
    work = np.concatenate([[0.0], np.cumsum(0.5 * (moment[1:] + moment[:-1]) * np.diff(gam))])
    kin = ke / np.maximum(wint, 1e-300)
    late = gam >= 0.5 * gam[-1]
    kinetic_fraction = float(np.max(kin[late]))
    return CellShear(
        gamma=gam, moment=moment, resultant=moment / area, stress=moment / (area * thickness),
        parallel_force=parallel, crossing_force=crossing, crossing_contact=pressing,
        work=work, kinetic=kin, area=area, thickness=thickness, kinetic_fraction=kinetic_fraction,
        hourglass_fraction=float(hg[-1] / max(wint[-1], 1e-300)),
        energy_error=float(err[-1]), stopped=stopped, steps=int(state.step),
        elements=int(model.n_hexes), repeat=int(cell.repeat), thickening=thick,
        centre_z=zc, end_z=np.array(end_rows), ends=ends)


def _line(x: np.ndarray, y: np.ndarray) -> tuple[float, float]:
    """(slope, intercept) of the least-squares line through (x, y)."""
    if len(x) < 2 or np.ptp(x) == 0.0:
        raise InputError(f"a tangent needs two distinct angles in its window, got {len(x)}")
    slope, intercept = np.polyfit(x, y, 1)
    return float(slope), float(intercept)


def locking_angle(gamma, tau, initial=INITIAL_WINDOW, final=FINAL_WINDOW,
                  min_ratio: float = MIN_STIFFENING) -> float:
    """The locking angle by the tangent rule: the intersection of the least-squares lines
    of τ(γ) over the initial window and the final window, each given as fractions of the
    largest angle (default 5–25 % and 85–100 %). NaN when the final tangent is less than
    ``min_ratio`` times the initial one (default 3: no locking in the range)."""
    gamma, tau = np.asarray(gamma, float), np.asarray(tau, float)
    top = float(gamma.max())
    a = (gamma >= initial[0] * top) & (gamma <= initial[1] * top)
    b = (gamma >= final[0] * top) & (gamma <= final[1] * top)
    s1, c1 = _line(gamma[a], tau[a])
    s2, c2 = _line(gamma[b], tau[b])
    if not (s2 > s1 and s2 >= min_ratio * abs(s1)):
        return float("nan")
    return (c1 - c2) / (s2 - s1)


def stiffening_angle(gamma, tau, factor: float = 10.0, initial=INITIAL_WINDOW) -> float:
    """The first angle where the tangent dτ/dγ (central differences) reaches ``factor``
    times the initial tangent (the least-squares slope over the initial window, fractions
    of the largest angle); NaN if it never does or the initial tangent is not positive."""
    gamma, tau = np.asarray(gamma, float), np.asarray(tau, float)
    top = float(gamma.max())
    a = (gamma >= initial[0] * top) & (gamma <= initial[1] * top)
    s1, _ = _line(gamma[a], tau[a])
    if not s1 > 0.0:
        return float("nan")
    tangent = np.gradient(tau, gamma)
    above = np.flatnonzero((tangent >= factor * s1) & (gamma > initial[1] * top))
    return float(gamma[above[0]]) if above.size else float("nan")


def trellis_law(gamma, g1: float, g2: float, gamma1: float, gamma2: float) -> np.ndarray:
    """The shell's trellis shear stress τ = G(|γ|) γ (eq. 3.16 on the true angle, theory
    §1.6: G1 up to γ1, rising linearly to G2 at γ2, G2 beyond) at the angles ``gamma``."""
    return np.array([shear_modulus_true(abs(float(g)), g1, g2, gamma1, gamma2)[0] * float(g)
                     for g in np.atleast_1d(gamma)])


def trellis_angles(width: float, pitch: float, c_max: float) -> tuple[float, float]:
    """(γ1, γ2) of eqs. 3.13–3.14 as the shell computes them
    (:func:`materials.fabric.trellis_locking_angles`) for yarns of width b ``pitch``
    apart — the meshed width, say, which a fabric file's parameters do not give."""
    return trellis_locking_angles(width / pitch, c_max)


def meshed_trellis_angles(cell_spec, c_max: float) -> tuple[float, float]:
    """(γ1, γ2) of eqs. 3.13–3.14 for the yarns of a geometry spec as meshed: the warps'
    trimmed width (:func:`meshed_width`) over their pitch (the cell's side along y over its
    repeat) — the angle at which the meshed parallel yarns would meet, and the one the law
    ends at."""
    cell = crossover_cell(cell_spec)
    return trellis_angles(meshed_width(cell), cell.size[1] / cell.repeat, c_max)


def meshed_width(cell, family: str = "warp") -> float:
    """The width of a family's yarns as meshed: the trimmed section's u_t W (the
    lenticular section's tips are cut where it is ``trim`` of its thickness)."""
    return trimmed_extent(cell.shape, cell.trim) * cell.yarns[family].width


def crossing_misfit(cell, gamma: float, points: int = 401) -> float:
    """The depth (m) by which the two yarns of one crossing would overlap if the frame
    turned them rigidly, the warp by +γ/2 and the fill by −γ/2 about the crossing: the
    largest height of the fill's upper surface above the warp's lower surface where both
    are, on a ``points`` × ``points`` grid over the single cell's area (the yarns'
    undeformed sections and centrelines, model.crossover_cell). Zero at γ = 0 for the
    thesis's yarns, which meet without overlapping; what the crossing must take up by
    compressing or lifting the yarns as the trellis turns."""
    w, f = cell.yarns["warp"], cell.yarns["fill"]
    ut = trimmed_extent(cell.shape, cell.trim)
    half = max(w.half_length, f.half_length, 0.5 * w.width, 0.5 * f.width)
    g = np.linspace(-half, half, points)
    X, Y = np.meshgrid(g, g, indexing="ij")
    a = 0.5 * gamma
    # each yarn's own coordinates (along, across) of a point: turn the point back
    xw, yw = math.cos(a) * X + math.sin(a) * Y, -math.sin(a) * X + math.cos(a) * Y
    xf, yf = math.cos(a) * X - math.sin(a) * Y, math.sin(a) * X + math.cos(a) * Y
    uw = yw / (0.5 * w.width)
    uf = -xf / (0.5 * f.width)
    on_w = (np.abs(uw) <= ut) & (np.abs(xw) <= w.half_length)
    on_f = (np.abs(uf) <= ut) & (np.abs(yf) <= f.half_length)
    warp_low = (centreline(w, xw, 1.0)[0]
                - 0.5 * w.thickness * section_profile(cell.shape, np.clip(uw, -1.0, 1.0)))
    fill_up = (centreline(f, yf, -1.0)[0]
               + 0.5 * f.thickness * section_profile(cell.shape, np.clip(uf, -1.0, 1.0)))
    both = on_w & on_f
    return float(max(0.0, np.max((fill_up - warp_low)[both]))) if both.any() else 0.0
