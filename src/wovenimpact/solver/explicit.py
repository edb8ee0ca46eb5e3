"""One explicit step, reading like the algorithm (docs/theory.md §3; thesis ch. 4.1).

    1. element forces at x^n: corotational shells, material update F^{n−1} → F^n,
       bending/shear/hourglass rates over Δt^{n−1/2}; min_e L_e/c_e  (kernels.shell)
       and the hexahedra's corner forces, their l_e/c_e            (solver.solid_stage)
    2. nodal forces gathered through the node → element maps   (kernels.gather)
    3. stable step Δt^{n+1/2} = α min_e L_e / c_e               (eq. 4.8–4.11)
    4. central differences for v^{n+1/2}, x^{n+1}; reactions;   (kernels.integrate)
       work and kinetic energy
    5. bookkeeping: erosion, energies, time

Stages 2 and 4 are one pass over the nodes (``gather_and_update``) and the
minimum of stage 3 comes out of the force kernel, so a step launches two
parallel kernels and scans no per-element or per-node array in NumPy, except the
deterministic per-node energy sums; the failure checks read counters the
kernels return and look for the culprit only when one is non-zero.

Contact and rigid bodies will enter as extra force stages between 2 and 4.
``step`` mutates the State in place (its arrays swap with the Workspace's
buffers), so no array is allocated inside the time loop.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numba
import numpy as np

from wovenimpact.errors import SimulationError
from wovenimpact.interfaces import empty_books
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels.bundles import (
    ElementResults,
    ElementTables,
    Motion,
    NodeEnergies,
    NodeForces,
    NodeMap,
    NodeModel,
    ShellMesh,
)
from wovenimpact.kernels.integrate import force_pair_power, gather_and_update, smooth_step
from wovenimpact.kernels.mass_scaling import node_masses, scale_element_masses, scaled_node_masses
from wovenimpact.solver.contact_stage import (
    ContactBuffers,
    advance_bodies,
    book_contact_work,
    contact_forces,
)
from wovenimpact.solver.element_blocks import block_plan, block_scratch
from wovenimpact.solver.solid_stage import (
    SolidBuffers,
    governing_hexahedron,
    solid_forces,
)
from wovenimpact.kernels.shell import internal_force_for_shells
from wovenimpact.kernels.shell_blocks import internal_force_blocks
from wovenimpact.state import (
    BODY_KINETIC,
    CONTACT_PENALTY,
    CONTACT_WORK,
    NODE_CONTACT_WORK,
    ERODED_INTERNAL,
    ERODED_KINETIC,
    KINETIC,
    MASS_SCALING,
    W_EXT,
    W_INT,
    State,
    initial_hex_rows,
)

DT_COLLAPSE = 1e-3  # a step below this fraction of the first one stops the run
# The element loop is handed to the threads in chunks of this many elements, taken in
# turn as each thread finishes one, instead of one equal share per thread: a model's
# elements differ in cost (a 2×2 J2 aluminium shell of 5 Simpson points is ~2.7× a 2×2
# fabric element) and its parts are numbered in blocks, so equal shares left one thread
# idle (10-ply casing, 57 284 elements, 2 threads, idle: 41.0 → 37.5 ms per shell stage;
# no change on one thread or on a uniform plate). Each element writes only its own rows,
# so the results are the same for any chunking.
ELEMENT_CHUNK = 256
BLOCK_CHUNK = 32  # blocks of 8 elements per chunk of the block stage's loops
STATUS_TEXT = {
    SL.EL_INVERTED: "inverted or degenerate (non-positive area or Jacobian)",
    SL.EL_MATERIAL: "material point failed (no converged crimp heights or inadmissible stretch)",
    SL.EL_NAN: "non-finite force or time step (NaN/inf)",
}


@dataclass
class Workspace:
    """Preallocated scratch of one Model: swapped with the State's buffers each step."""

    elem: np.ndarray
    mat: np.ndarray
    blocks: np.ndarray
    status: np.ndarray
    eroded_now: np.ndarray
    alive: np.ndarray
    f_int: np.ndarray
    f_ext: np.ndarray
    live: np.ndarray
    w_int: np.ndarray
    w_ext: np.ndarray
    ke: np.ndarray
    ke_eroded: np.ndarray
    node_mass: np.ndarray  # nodal masses with those added by mass scaling (kg)
    node_inertia: np.ndarray  # rotary inertias, scaled like the masses (kg m²)
    added_ke: np.ndarray  # kinetic energy each node gained with added mass, last step (J)
    mesh: ShellMesh = None  # the Model's tables the element kernel reads
    results: ElementResults = None  # blocks, status, eroded_now, alive (above)
    node_map: NodeMap = None  # the Model's node → (element, corner) map
    energies: NodeEnergies = None  # w_int, w_ext, ke, ke_eroded (above)
    contact: object = None  # solver.contact_stage.ContactBuffers
    hex: np.ndarray = None  # the hexahedra's state at the end of the step (State.hex)
    solid: object = None  # solver.solid_stage.SolidBuffers
    plan: object = None  # kernels.bundles.BlockPlan: the elements taken in blocks, or None
    scratch: object = None  # kernels.bundles.BlockScratch for the block stages
    dt_min: float = math.inf  # min_e L_e/c_e of the last element stage
    n_eroded: int = 0  # elements eroded in the last element stage
    profile: bool = False
    timings: dict = field(default_factory=dict)

    def tick(self, stage: str, since: float) -> float:
        """With ``profile`` on, add the time since ``since`` to ``stage``; returns now."""
        now = time.perf_counter()
        if self.profile:
            self.timings[stage] = self.timings.get(stage, 0.0) + now - since
        return now

    @classmethod
    def for_model(cls, model, state: State) -> Workspace:
        n, ne = model.n_nodes, model.n_elems
        if state.added_mass.shape != (n,):
            state.added_mass = np.zeros(n)
        if state.mass_ratio.shape != (ne,):
            state.mass_ratio = np.zeros(ne)
        if state.contact_work.shape != (n,):
            state.contact_work = np.zeros(n)
        if state.hex.shape[0] != model.n_hexes:  # a State built by hand, without its solids
            state.hex = initial_hex_rows(model.n_hexes)
        mass, inertia = node_masses(model.node_mass, model.node_inertia, state.added_mass)
        ws = cls(
            elem=state.elem.copy(), mat=state.mat.copy(),  # dead rows stay equal (shell_force)
            blocks=np.zeros((ne, 4, 6)), status=np.zeros(ne, dtype=np.int32),
            eroded_now=np.zeros(ne, dtype=np.int32), alive=np.zeros(ne, dtype=np.uint8),
            f_int=np.zeros((n, 6)),
            f_ext=np.zeros((n, 6)), live=np.zeros(n, dtype=np.int64), w_int=np.zeros(n),
            w_ext=np.zeros(n), ke=np.zeros(n), ke_eroded=np.zeros(n),
            node_mass=mass, node_inertia=inertia, added_ke=np.zeros(n),
            contact=ContactBuffers.for_model(model), hex=state.hex.copy(),
            solid=SolidBuffers.for_model(model),
        )
        ws.mesh = ShellMesh(
            quads=model.quads, elem_section=model.elem_section, sections=model.sections,
            mat_kind=model.mat_kind, mat_params=model.mat_params, area0=model.area0,
            ref_grad=model.ref_grad, gauss_grad=model.gauss_grad,
            gauss_weight=model.gauss_weight, rot_inertia=model.elem_rot_inertia,
            mat_row=model.mat_row,
            step_mode=SL.STABLE_STEPS[model.stable_step],
            kinematic_fraction=model.kinematic_fraction)
        ws.plan = block_plan(model)
        ws.scratch = block_scratch(ws.plan) if ws.plan is not None else None
        ws.results = ElementResults(blocks=ws.blocks, status=ws.status,
                                    eroded_now=ws.eroded_now, alive=ws.alive)
        ws.node_map = NodeMap(node_ptr=model.node_ptr, node_elem=model.node_elem,
                              node_corner=model.node_corner)
        ws.energies = NodeEnergies(w_int=ws.w_int, w_ext=ws.w_ext, ke=ws.ke,
                                   ke_eroded=ws.ke_eroded)
        return ws


def shell_forces(model, state: State, ws: Workspace) -> None:
    """Stage 1: element forces at x^n into ws (blocks, element and material state,
    alive bytes, dt_min, n_eroded); stops naming the first failed element."""
    motion = Motion(x=state.x, v=state.v, omega=state.omega)
    tables = ElementTables(el_in=state.elem, el_out=ws.elem, mat_in=state.mat, mat_out=ws.mat)
    dt_erode = model.erode_dt_fraction * state.dt_first / model.alpha
    if ws.plan is not None:  # fabric elements in blocks of 8 (kernels.shell_blocks)
        with numba.parallel_chunksize(BLOCK_CHUNK):
            n_failed, ws.n_eroded, ws.dt_min = internal_force_blocks(
                ws.mesh, motion, state.dt, tables, ws.results, dt_erode, model.erode_inverted,
                ws.plan, ws.scratch)
    else:
        with numba.parallel_chunksize(ELEMENT_CHUNK):
            n_failed, ws.n_eroded, ws.dt_min = internal_force_for_shells(
                ws.mesh, motion, state.dt, tables, ws.results, dt_erode, model.erode_inverted)
    if n_failed:
        bad = np.flatnonzero(ws.status)
        e = int(bad[0])
        raise SimulationError(
            f"element {e} (nodes {model.quads[e].tolist()}) at t = {state.t:.6e} s, step "
            f"{state.step}: {STATUS_TEXT.get(int(ws.status[e]), 'unknown failure')}"
            + (f"; {bad.size} elements in this state" if bad.size > 1 else "")
        )


def scale_masses(model, state: State, ws: Workspace) -> None:
    """Stage 3a, with ``run.mass_scaling_fraction`` f > 0: elements whose step α L_e/c_e
    is below f Δt₁ get mass so that it is f Δt₁ (kernels.mass_scaling); the nodal masses,
    the kinetic energy the added mass brings (booked as an input, ``MASS_SCALING``) and
    ``ws.dt_min`` follow. Stops once the added mass passes ``max_added_mass_fraction``."""
    if model.mass_scaling_fraction <= 0.0 or state.dt_first <= 0.0:
        return
    target = model.mass_scaling_fraction * state.dt_first / model.alpha
    raised, ws.dt_min = scale_element_masses(ws.elem, SL.E_DT, SL.E_DT_KIN, ws.alive,
                                              state.mass_ratio, target)
    if not raised:
        return
    scaled_node_masses(model.node_ptr, model.node_elem, state.mass_ratio, model.elem_mass,
                       model.node_mass, model.node_inertia, state.v, state.omega,
                       state.added_mass, ws.node_mass, ws.node_inertia, ws.added_ke)
    state.energy[MASS_SCALING] += float(np.sum(ws.added_ke))
    added, total = float(np.sum(state.added_mass)), float(np.sum(model.node_mass))
    if added > model.max_added_mass_fraction * total:
        e = int(np.argmax(state.mass_ratio))
        raise SimulationError(
            f"mass scaling added {added:.4g} kg at t = {state.t:.6e} s, {added / total:.2%} of "
            f"the model's {total:.4g} kg, above run.max_added_mass_fraction = "
            f"{model.max_added_mass_fraction:g} (most scaled: element {e}, mass × "
            f"{1.0 + state.mass_ratio[e]:.3g}): too many elements are crushed; refine the "
            "mesh, lower run.mass_scaling_fraction or let them erode"
        )


def stable_step(model, state: State, ws: Workspace, dt_cap: float) -> float:
    """Stage 3: Δt = α min_e L_e/c_e (eq. 4.8), at most dt_cap; stops on collapse.

    The minimum is the force kernel's (``ws.dt_min``), or with mass scaling that of the
    scaled elements (:func:`scale_masses`); the governing element is looked up only for
    an error message.
    """
    scale_masses(model, state, ws)
    dt = min(model.alpha * min(ws.dt_min, ws.solid.dt_min), dt_cap)
    solid_governs = ws.solid.dt_min < ws.dt_min
    if not math.isfinite(dt) or dt <= 0.0:
        if solid_governs or not model.n_elems:
            where = governing_hexahedron(model, ws.hex) if model.n_hexes else "no element"
        else:
            dt_el = element_steps(ws.elem)
            e = int(np.argmin(dt_el))
            where = f"element {e}: {dt_el[e]!r}"
        raise SimulationError(
            f"no stable time step at t = {state.t:.6e} s ({where}); "
            "every element eroded, or a non-finite state"
        )
    if state.dt_first > 0.0 and dt < DT_COLLAPSE * state.dt_first and solid_governs:
        raise SimulationError(
            f"time step collapsed at t = {state.t:.6e} s: Δt = {dt:.3e} s is below "
            f"{DT_COLLAPSE:g} of the first step ({state.dt_first:.3e} s), governed by "
            f"{governing_hexahedron(model, ws.hex)}: it is nearly crushed or distorted"
        )
    if state.dt_first > 0.0 and dt < DT_COLLAPSE * state.dt_first:
        e = int(np.argmin(element_steps(ws.elem)))
        how = ("its corners close too fast (the kinematic bound)"
               if ws.elem[e, SL.E_DT_KIN] < ws.elem[e, SL.E_DT] else
               "it is nearly crushed or distorted")
        raise SimulationError(
            f"time step collapsed at t = {state.t:.6e} s: Δt = {dt:.3e} s is below "
            f"{DT_COLLAPSE:g} of the first step ({state.dt_first:.3e} s), governed by element "
            f"{e} (nodes {model.quads[e].tolist()}): {how}"
        )
    return dt


def element_steps(elem: np.ndarray) -> np.ndarray:
    """Each element's own step before α and mass scaling: the smaller of its wave bound
    (``E_DT``) and its kinematic bound (``E_DT_KIN``)."""
    return np.minimum(elem[:, SL.E_DT], elem[:, SL.E_DT_KIN])


def release(model, state: State) -> None:
    """Erode the model's release elements still alive (a blade's fragment breaking free
    of its hub part at ``model.release_time``); their energies are booked as eroded
    internal energy, once. Their nodes left without a live element leave the model in
    the node update that follows (or, with ``run.eroded_nodes = "keep"``, fly on as free
    nodes)."""
    idx = model.release_elems
    live = idx[state.elem[idx, SL.E_ALIVE] != 0.0]
    if not live.size:
        return
    state.energy[ERODED_INTERNAL] += float(np.sum(
        state.elem[live, SL.E_U_MEMB] + state.elem[live, SL.E_U_BEND]
        + state.elem[live, SL.E_U_HG]))
    state.elem[live, SL.E_ALIVE] = 0.0


def step(model, state: State, ws: Workspace, dt_cap: float = math.inf) -> None:
    """Advance ``state`` from t^n to t^{n+1} in place (stages 1–5 of the module docstring)."""
    if state.t >= model.release_time:
        release(model, state)
    t0 = time.perf_counter()
    if model.n_elems or not model.n_hexes:
        shell_forces(model, state, ws)
        t0 = ws.tick("shell forces", t0)
    else:  # hexahedra only
        ws.dt_min, ws.n_eroded = math.inf, 0
    if model.n_hexes:
        solid_forces(model, state, ws.hex, ws.solid)
        t0 = ws.tick("solid forces", t0)
    dt_new = stable_step(model, state, ws, dt_cap)
    t0 = ws.tick("stable step", t0)
    cb = ws.contact
    resultants = contact_forces(model, state, cb, dt_new, ws.alive, ws.n_eroded)
    # work of the contact forces on the nodes over [x^{n−1}, x^n] (trapezoid), before
    # the velocities move on
    w_con_nodes = 0.0
    if resultants or cb.shells is not None:
        w_con_nodes = force_pair_power(state.f_contact, cb.f_con, state.v, state.dt,
                                       state.contact_work) * state.dt
    t0 = ws.tick("contact", t0)
    amplitude = smooth_step(state.t + 0.5 * dt_new, model.ramp_time)
    n_bad = gather_and_update(
        ws.node_map, ws.results, ws.solid.gather,
        NodeModel(mass=ws.node_mass, inertia=ws.node_inertia, bc_code=model.bc_code,
                  bc_velocity=model.bc_velocity, body_accel=model.body_accel,
                  keep_free=model.eroded_nodes == "keep"),
        cb.f_con, amplitude, state.dt, dt_new,
        NodeForces(f_int=ws.f_int, f_int_old=state.f_int, f_ext_old=state.f_ext,
                   f_ext=ws.f_ext),
        Motion(x=state.x, v=state.v, omega=state.omega), state.node_active, ws.energies,
    )
    t0 = ws.tick("gather + integrate", t0)
    if n_bad:
        n = int(np.flatnonzero(~np.isfinite(state.x).all(axis=1))[0])
        raise SimulationError(f"node {n} has a non-finite position at t = {state.t:.6e} s")
    ke_bodies, w_con_bodies = advance_bodies(model, state, resultants, state.dt, dt_new)
    if resultants or cb.shells is not None:
        # the same work by interface and kind (interfaces, kernels.contact_energy): the
        # last step's forces against v^{n−1/2} (booked after that step into [1]), this
        # step's against v^{n−1/2} — what the trapezoid above counted — and against
        # v^{n+1/2} into [1], for the next step's trapezoid
        t0 = ws.tick("bookkeeping", t0)
        books = state.contact_books
        if books.shape[-1] != cb.n_parts:  # a State built by hand, without its books
            books = state.contact_books = empty_books(model)
        books[0] += books[1]
        books[1] = 0.0
        book_contact_work(model, state, cb, 0.5 * state.dt, books[0], 0.5 * dt_new, books[1])
        t0 = ws.tick("contact energy books", t0)
    en = state.energy
    if state.step == 1:
        first_step_work_correction(model, state)
    state.f_contact[:] = cb.f_con
    en[BODY_KINETIC] = ke_bodies
    en[CONTACT_WORK] += w_con_nodes + w_con_bodies
    en[NODE_CONTACT_WORK] += w_con_nodes
    en[CONTACT_PENALTY] = cb.penalty_energy
    en[W_INT] += float(np.sum(ws.w_int))
    en[W_EXT] += float(np.sum(ws.w_ext))
    en[KINETIC] = float(np.sum(ws.ke))
    en[ERODED_KINETIC] += float(np.sum(ws.ke_eroded))
    if ws.n_eroded:
        # booked once: the energies an element holds at its erosion (ws.elem, the state it
        # keeps frozen from now on), which energy_balance no longer counts as stored or
        # hourglass energy
        gone = ws.eroded_now != 0
        en[ERODED_INTERNAL] += float(np.sum(
            ws.elem[gone, SL.E_U_MEMB] + ws.elem[gone, SL.E_U_BEND] + ws.elem[gone, SL.E_U_HG]
        ))
    state.elem, ws.elem = ws.elem, state.elem
    state.mat, ws.mat = ws.mat, state.mat
    if model.n_hexes:
        state.hex, ws.hex = ws.hex, state.hex
    state.f_int, ws.f_int = ws.f_int, state.f_int
    state.f_ext, ws.f_ext = ws.f_ext, state.f_ext
    if state.dt_first == 0.0:
        state.dt_first = dt_new
    state.t += dt_new
    state.dt = dt_new
    state.step += 1
    ws.tick("bookkeeping", t0)


def first_step_work_correction(model, state: State) -> None:
    """Book the work of the forces at t⁰ with the weight the velocity update gave them.

    The trapezoid rule credits the forces f⁰ at x⁰ with ½ Δt^{1/2} f⁰ · v^{1/2}, but the
    half-step start v^{1/2} = v⁰ + ½ Δt^{1/2} M⁻¹ f⁰_net (Δt⁰ = ½ Δt^{1/2}) gave them only
    half that weight in the leapfrog kinetic energy ½ v^{n−1/2} · M v^{n+1/2}. The
    difference, ¼ Δt^{1/2} f⁰ · (v^{1/2} − v⁰) = ⅛ (Δt^{1/2})² f⁰ · M⁻¹ f⁰_net for each
    force (internal, external, contact on the nodes), is taken off the work here, once,
    in the step from x¹ to x², while ``state.f_int``/``f_ext``/``f_contact`` still hold
    the forces at x⁰ (docs/theory.md §5, "First step"). Without it a plate starting at
    rest under gravity reports a balance error of 25 % of the (tiny) energies of its
    first steps, and a prescribed velocity switched on at t = 0 books twice the kinetic
    energy it gives its nodes (m v² for ½ m v²)."""
    inv = np.zeros((model.n_nodes, 6))
    has = model.node_mass > 0.0
    inv[has, :3] = 1.0 / model.node_mass[has, None]
    spin = model.node_inertia > 0.0
    inv[spin, 3:] = 1.0 / model.node_inertia[spin, None]
    accel = (state.f_ext - state.f_int) * inv  # M⁻¹ f⁰_net, reactions included
    weight = 0.125 * state.dt * state.dt
    en = state.energy
    en[W_EXT] -= weight * float(np.sum(state.f_ext * accel))
    en[W_INT] -= weight * float(np.sum(state.f_int * accel))
    w_con = weight * float(np.sum(state.f_contact * accel[:, :3]))
    en[NODE_CONTACT_WORK] -= w_con
    en[CONTACT_WORK] -= w_con


def advance(model, state: State, ws: Workspace, t_stop: float, max_steps: int | None = None) -> int:
    """Step until ``state.t ≥ t_stop`` (or ``max_steps``); returns the steps taken."""
    taken = 0
    while state.t < t_stop and (max_steps is None or taken < max_steps):
        step(model, state, ws)
        taken += 1
    return taken
