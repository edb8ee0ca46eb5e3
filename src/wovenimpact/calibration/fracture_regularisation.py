"""Calibration of the element-size regularisation of metal fracture (docs/theory.md §7.3).

The fracture strain of a J2 material (constant, or Johnson–Cook) holds as given on one
element size, the reference length l_ref; on an element of length l_e = √A0 the point
fails at s(l_e/l_ref) ε_f (J15). The table s is fitted here on the material's own
test, simulated: a quasi-static uniaxial tension test of a flat shell coupon, run on
several meshes; each mesh's row is the scale with which that mesh fractures at the
elongation of the finest mesh (a 1-D root find, the model re-run at each trial scale).
Nothing ballistic enters the fit.

The coupon (:class:`Coupon`; lengths in multiples of its thickness t, defaults for
t = 1 mm, the casing layers' and the 2024-T3 plate's):

- a flat strip 32 t long and 8 t wide, its width reduced by 1 % at the middle (a cosine
  dip 8 t long) so that fracture starts there; 5 Simpson points through the thickness,
  one-point membrane (the metal examples' section);
- one end held along the pull (x), the other pulled along x at a constant speed V; both
  ends held out of plane and against rotation but free to contract across (frictionless
  grips: one node of each end holds y against rigid motion), so that away from the dip
  the strip stretches uniformly;
- it starts with the velocity field of that uniform stretch, v_x = V (x − x_0)/L: the
  exact motion of a uniform strip, so no wave is sent along it and its kinetic energy
  stays m V²/6 (≈ 0.2 % of the work to fracture of the aluminium at 10 m/s) — no ramp,
  no mass scaling;
- the material is evaluated at a quasi-static rate: the Johnson–Cook rate factors
  (strength C, failure D4) are 1, as they are for every test at ε̇ ≤ ε̇0 = 1/s (the
  pull itself runs at ~300/s: at 1/s it would take 300 × the steps).

Measured per run (:class:`CouponResult`): the elongation at fracture — the end
displacement at which the force has fallen to half its peak (the load drop an
experimenter reads) —, the elongation at the first eroded element (onset) and at
separation (force below 1 % of the peak), the work done to separation (the reaction
work of the pulled end), the peak force, and the energy balance.

:func:`calibrate` runs every mesh without the regularisation, fits the table, runs
every mesh again with it, and :func:`shipped_table` re-expresses the table about the
element size a material file's examples use (s = 1 there). :func:`regularisation_block`
words the ``[material.regularisation]`` table with the origin of each number;
:func:`write_calibration` writes it into a copy of the material file, a CSV and a figure.
"""

from __future__ import annotations

import csv
import math
import re
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np
from scipy.optimize import brentq

from wovenimpact.errors import InputError, SimulationError
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.materials.metal import FractureRegularisation, MetalParameters
from wovenimpact.model import BoundaryConditions, Section, build_model
from wovenimpact.results.metal_state import plastic_work
from wovenimpact.results.energy import energy_balance
from wovenimpact.solver import Workspace, step
from wovenimpact.state import initial_state

DEFAULT_SIZES = (0.25, 0.5, 1.0, 2.0, 4.0)  # element sizes, multiples of the thickness
LOAD_DROP = 0.5  # fracture: the force has fallen to this fraction of its peak
SEPARATED = 0.01  # separation: the force has fallen below this fraction of its peak
SCALE_TOLERANCE = 2e-4  # elongations matched to this fraction (or a time step's travel)
MAX_STRETCH = 0.6  # a run stops unfractured once the end has moved this × the length


@dataclass(frozen=True)
class Coupon:
    """The simulated tension test (SI; module docstring). Plan dimensions are multiples
    of the thickness, so that a thicker material's coupon is the same test scaled.

    Attributes:
        material: the J2 material, with its fracture strain or Johnson–Cook damage; its
            own regularisation is not used (:meth:`material_for` replaces it).
        thickness: t (m).
        length, width: the strip's length and width over t.
        reduction: the width's relative reduction at the middle.
        reduction_length: the length of the cosine dip over t.
        speed: V, the pulled end's speed (m/s).
        points: Simpson points through the thickness.
        quasi_static_rate: drop the Johnson–Cook rate factors (module docstring).
        plane_strain: hold the long edges across the pull (ε_yy = 0): the plane-strain
            tension test, the stress state of a sheet stretched over a long edge
            (stress triaxiality 1/√3 instead of 1/3).
    """

    material: MetalParameters
    thickness: float = 1e-3
    length: float = 32.0
    width: float = 8.0
    reduction: float = 0.01
    reduction_length: float = 8.0
    speed: float = 10.0
    points: int = 5
    quasi_static_rate: bool = True
    plane_strain: bool = False

    @property
    def length_m(self) -> float:
        return self.length * self.thickness

    @property
    def width_m(self) -> float:
        return self.width * self.thickness

    def check_size(self, element_size: float) -> tuple[int, int]:
        """Elements along and across the strip for ``element_size`` (m).

        Raises:
            InputError: the size does not divide the length and the width, or leaves
                fewer than 2 elements across.
        """
        counts = []
        for name, side in (("length", self.length_m), ("width", self.width_m)):
            n = side / element_size
            if abs(n - round(n)) > 1e-6 * n:
                raise InputError(
                    f"element size {element_size * 1e3:.6g} mm does not divide the coupon's "
                    f"{name} {side * 1e3:.6g} mm (valid: {side * 1e3:.6g} mm / n)")
            counts.append(int(round(n)))
        if counts[1] < 2:
            raise InputError(
                f"element size {element_size * 1e3:.6g} mm leaves {counts[1]} element across "
                f"the coupon's width {self.width_m * 1e3:.6g} mm (valid: at most "
                f"{self.width_m * 0.5e3:.6g} mm, two elements across)")
        return counts[0], counts[1]

    def half_width(self, x: np.ndarray) -> np.ndarray:
        """Half the width at x (m; x = 0 at the middle): the cosine dip."""
        w = np.full_like(x, 0.5 * self.width_m)
        a = 0.5 * self.reduction_length * self.thickness
        inside = np.abs(x) < a
        w[inside] *= 1.0 - 0.5 * self.reduction * (1.0 + np.cos(math.pi * x[inside] / a))
        return w

    def mesh(self, element_size: float):
        """Nodes, quads, the end node sets (held, pulled) and the long edges' nodes of a
        structured mesh."""
        nx, ny = self.check_size(element_size)
        half_l = 0.5 * self.length_m
        xs = np.linspace(-half_l, half_l, nx + 1)
        gx, ge = np.meshgrid(xs, np.linspace(-1.0, 1.0, ny + 1), indexing="ij")
        gy = ge * self.half_width(gx.ravel()).reshape(gx.shape)
        nodes = np.stack([gx.ravel(), gy.ravel(), np.zeros(gx.size)], axis=1)
        idx = np.arange(gx.size).reshape(nx + 1, ny + 1)
        quads = np.stack([idx[:-1, :-1].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel(),
                          idx[:-1, 1:].ravel()], axis=1)
        return nodes, quads, idx[0].copy(), idx[-1].copy(), np.concatenate([idx[:, 0],
                                                                           idx[:, -1]])

    def material_for(self, regularisation: FractureRegularisation | None) -> MetalParameters:
        """The coupon's material: the quasi-static rate (if asked) and ``regularisation``
        in place of the file's own."""
        m = replace(self.material, regularisation=regularisation)
        if not self.quasi_static_rate:
            return m
        damage = m.damage
        if damage is not None:
            damage = replace(damage, d=(*damage.d[:3], 0.0, damage.d[4]))
        return replace(m, rate=None, damage=damage)

    def model(self, element_size: float,
              regularisation: FractureRegularisation | None = None):
        """The model, its pulled nodes and the initial velocity field."""
        nodes, quads, held, pulled, edges = self.mesh(element_size)
        bc = BoundaryConditions(len(nodes))
        bc.fix(held, (0, 2, 3, 4, 5))
        bc.fix(pulled, (2, 3, 4, 5))
        bc.fix(edges if self.plane_strain else [held[len(held) // 2], pulled[len(pulled) // 2]],
               (1,))
        bc.prescribe(pulled, 0, self.speed)
        sec = Section(self.material_for(regularisation), thickness=self.thickness,
                      points=self.points)
        model = build_model(nodes, quads, {"coupon": sec}, np.zeros(len(quads), int), bcs=bc)
        v0 = np.zeros((len(nodes), 3))
        v0[:, 0] = self.speed * (nodes[:, 0] + 0.5 * self.length_m) / self.length_m
        return model, pulled, v0


@dataclass
class CouponResult:
    """One coupon run (SI).

    Attributes:
        element_size: the mesh's element size (m).
        elongation_at_fracture: end displacement at which the force has fallen to
            ``LOAD_DROP`` of its peak (m); NaN if it never did.
        onset_elongation: end displacement at the first eroded element (m).
        separation_elongation: end displacement at which the force fell below
            ``SEPARATED`` of its peak (m).
        work_to_fracture: work of the pulled end up to separation (J).
        peak_force: N.
        kinetic_fraction: kinetic energy / internal work at the onset.
        energy_error: the run's largest energy-balance error fraction.
        first_failure_at: (x, y) of the first eroded element's centre (m).
        plastic_work: the points' plastic work at the end (J).
        elements, steps, wall_s: size and cost.
        elongation, force: sampled force–elongation curve (m, N).
    """

    element_size: float
    elongation_at_fracture: float
    onset_elongation: float
    separation_elongation: float
    work_to_fracture: float
    peak_force: float
    kinetic_fraction: float
    energy_error: float
    first_failure_at: tuple[float, float]
    plastic_work: float
    elements: int
    steps: int
    wall_s: float
    elongation: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))
    force: np.ndarray = field(repr=False, default_factory=lambda: np.zeros(0))


def run_coupon(coupon: Coupon, element_size: float,
               regularisation: FractureRegularisation | None = None,
               samples: int = 400) -> CouponResult:
    """Pull the coupon meshed at ``element_size`` (m) until it separates (module
    docstring); ``samples`` about as many points of the force–elongation curve kept."""
    model, pulled, v0 = coupon.model(element_size, regularisation)
    st = initial_state(model, velocity=v0)
    ws = Workspace.for_model(model, st)
    x_end = model.x0[pulled[0], 0]
    u_max = MAX_STRETCH * coupon.length_m
    # steps to the end of the stretch limit: sample every ~u_max/samples of elongation
    c = coupon.material.plane_stress_wave_speed
    every = max(1, int(u_max / coupon.speed / (0.9 * element_size / c) / samples))
    us, fs = [0.0], [0.0]
    peak = 0.0
    onset = fracture = separation = work = math.nan
    kinetic_fraction = math.nan
    first_at = (math.nan, math.nan)
    error = 0.0
    # a load drop counts once the coupon has yielded: the force of the table's first
    # flow stress on the dip's section (the first steps' forces are elastic transients)
    armed_at = 0.9 * coupon.material.hardening[0][1] * coupon.thickness * 2.0 * float(
        coupon.half_width(np.zeros(1))[0])
    t0 = time.perf_counter()
    u = force = 0.0
    while True:
        try:
            step(model, st, ws)
        except SimulationError:
            if np.any(ws.elem[:, SL.E_ALIVE] != 0.0):
                raise
            # every element failed in the last step (a strip without its dip): no step
            # is left to take; the coupon separated at the last whole step
            if math.isnan(onset):
                onset = u
                eb = energy_balance(model, st)
                kinetic_fraction = eb["kinetic_J"] / eb["internal_work_J"]
            fracture = u if math.isnan(fracture) else fracture
            separation = u
            break
        u = float(st.x[pulled[0], 0] - x_end)
        force = float(np.sum(st.f_ext[pulled, 0]))
        peak = max(peak, force)
        if st.step % every == 0:
            us.append(u)
            fs.append(force)
        if st.step % 500 == 0:
            error = max(error, energy_balance(model, st)["error_fraction"])
        if math.isnan(onset):
            dead = st.elem[:, SL.E_ALIVE] == 0.0
            if dead.any():
                onset = u
                e = int(np.flatnonzero(dead)[0])
                c = model.x0[model.quads[e]].mean(axis=0)
                first_at = (float(c[0]), float(c[1]))
                eb = energy_balance(model, st)
                kinetic_fraction = eb["kinetic_J"] / eb["internal_work_J"]
        if math.isnan(fracture) and peak > armed_at and force < LOAD_DROP * peak:
            fracture = u
        if not math.isnan(fracture) and force < SEPARATED * peak:
            separation = u
            break
        if u > u_max:
            break
    eb = energy_balance(model, st)
    if not math.isnan(separation):
        work = eb["reaction_work_J"]
    us.append(u)
    fs.append(force)
    return CouponResult(
        element_size=element_size, elongation_at_fracture=fracture, onset_elongation=onset,
        separation_elongation=separation, work_to_fracture=work, peak_force=peak,
        kinetic_fraction=kinetic_fraction, energy_error=max(error, eb["error_fraction"]),
        first_failure_at=first_at, plastic_work=plastic_work(model, st),
        elements=model.n_elems, steps=st.step, wall_s=time.perf_counter() - t0,
        elongation=np.array(us), force=np.array(fs))


# --- the fit ---------------------------------------------------------------------------
@dataclass
class MeshCalibration:
    """One mesh of the calibration: its run without regularisation, its fitted scale and
    its run with the whole fitted table."""

    element_size: float
    before: CouponResult
    scale: float
    after: CouponResult
    trials: int  # runs of the root find (0 for the reference mesh)


@dataclass
class Calibration:
    """The fitted table (rows (l_e/l_ref, s), l_ref = ``reference_size``, the finest
    mesh) and every mesh's runs."""

    coupon: Coupon
    reference_size: float
    failure_displacement: float
    meshes: list[MeshCalibration]
    wall_s: float

    @property
    def rows(self) -> tuple[tuple[float, float], ...]:
        return tuple((m.element_size / self.reference_size, m.scale) for m in self.meshes)

    @property
    def reference(self) -> CouponResult:
        return self.meshes[0].before

    def regularisation(self, reference_length: float | None = None) -> FractureRegularisation:
        """The fitted law, about ``reference_length`` (default: the finest mesh)."""
        l_ref = self.reference_size if reference_length is None else reference_length
        return FractureRegularisation(
            reference_length=l_ref, fracture_scale=shipped_table(self, l_ref),
            failure_displacement=self.failure_displacement)


def _regularisation(l_ref: float, rows, failure_displacement: float):
    return FractureRegularisation(reference_length=l_ref, fracture_scale=tuple(rows),
                                  failure_displacement=failure_displacement)


def fit_scale(run: Callable[[float], CouponResult], target: float, at_one: CouponResult,
              tolerance: float) -> tuple[float, CouponResult, int]:
    """The scale s with which ``run(s)`` fractures at the elongation ``target`` (m),
    to ``tolerance`` (m).

    The elongation at fracture moves with s in steps of the end's travel in one time
    step (the failing point crosses s ε_f in some step), so it is matched to within
    ``tolerance`` (a residual inside it counts as zero), not to round-off. The root is
    bracketed from s = 1 (``at_one``, already run) and the guess that the elongation is
    proportional to s, pushed half as far again (widened until the sign changes), then
    found by Brent's method. Returns s, the run at s and the number of runs made.
    """
    cache: dict[float, CouponResult] = {1.0: at_one}

    def evaluate(s: float) -> CouponResult:
        if s not in cache:
            cache[s] = run(s)
        return cache[s]

    def residual(s: float) -> float:
        u = evaluate(s).elongation_at_fracture
        r = (u if math.isfinite(u) else math.inf) - target
        return 0.0 if abs(r) <= tolerance else r

    r1 = residual(1.0)
    if r1 == 0.0:
        return 1.0, at_one, 0
    guess = target / at_one.elongation_at_fracture
    step_size = 1.5 * (guess - 1.0)
    lo, hi = 1.0, 1.0 + step_size
    for _ in range(12):
        if not hi > 0.0:
            hi = 0.5 * lo  # a scale stays positive
        r = residual(hi)
        if r == 0.0:
            return hi, evaluate(hi), len(cache) - 1
        if r * r1 < 0.0:
            break
        lo, r1 = hi, r
        step_size *= 1.6
        hi = lo + step_size
    else:
        raise RuntimeError(f"no fracture scale found that brings the elongation at fracture "
                           f"to {target * 1e3:.4g} mm (tried s = 1 … {hi:.4g})")
    s = brentq(residual, min(lo, hi), max(lo, hi), xtol=1e-6)
    return s, evaluate(s), len(cache) - 1


def calibrate(coupon: Coupon, sizes: Sequence[float], failure_displacement: float = 0.0,
              progress: Callable[[str], None] | None = None) -> Calibration:
    """Fit s(l_e/l_ref) on the coupon meshed at ``sizes`` (m; the finest is the
    reference, s = 1): each coarser mesh, finest first, gets the scale with which it
    fractures at the reference's elongation, the table of the finer rows already in
    place (the dip's elements are a little smaller than the mesh's size and take their
    scale between rows). With ``failure_displacement`` (m) every run, the reference's
    included, softens after onset (J16). Every mesh is then run again with the whole
    table.
    """
    say = progress or (lambda _msg: None)
    sizes = sorted(float(h) for h in sizes)
    if len(sizes) < 2 or len(set(sizes)) != len(sizes):
        raise InputError(f"element sizes {[h * 1e3 for h in sizes]} mm: give at least two "
                         "different sizes (the finest is the reference)")
    for h in sizes:
        coupon.check_size(h)
    t_start = time.perf_counter()
    l_ref = sizes[0]
    reg0 = (_regularisation(l_ref, [(1.0, 1.0)], failure_displacement)
            if failure_displacement > 0.0 else None)
    before = []
    for h in sizes:
        r = run_coupon(coupon, h, reg0)
        say(f"{h * 1e3:g} mm without regularisation: elongation at fracture "
            f"{r.elongation_at_fracture * 1e3:.4f} mm ({r.steps} steps, {r.wall_s:.1f} s)")
        before.append(r)
    target = before[0].elongation_at_fracture
    if not math.isfinite(target):
        raise RuntimeError(f"the reference mesh ({l_ref * 1e3:g} mm) did not fracture "
                           f"within an elongation of {MAX_STRETCH:g} × the length")
    rows: list[tuple[float, float]] = [(1.0, 1.0)]
    meshes = [MeshCalibration(l_ref, before[0], 1.0, before[0], 0)]
    for h, b in zip(sizes[1:], before[1:]):
        x = h / l_ref

        def trial(s: float, rows=tuple(rows), x=x, h=h) -> CouponResult:
            return run_coupon(coupon, h, _regularisation(l_ref, (*rows, (x, s)),
                                                         failure_displacement))

        # a time step's travel of the end on this mesh and the reference's
        tolerance = max(SCALE_TOLERANCE * target, 1.5 * coupon.speed * 0.9 * h
                        / coupon.material.plane_stress_wave_speed)
        s, after, n = fit_scale(trial, target, b, tolerance)
        rows.append((x, s))
        say(f"{h * 1e3:g} mm: s = {s:.5f} ({n} runs), elongation at fracture "
            f"{after.elongation_at_fracture * 1e3:.4f} mm")
        meshes.append(MeshCalibration(h, b, s, after, n))
    return Calibration(coupon=coupon, reference_size=l_ref,
                       failure_displacement=failure_displacement, meshes=meshes,
                       wall_s=time.perf_counter() - t_start)


def shipped_table(cal: Calibration, reference_length: float,
                  digits: int = 4) -> tuple[tuple[float, float], ...]:
    """The fitted table about ``reference_length`` (m): rows (h/l, s_h/s(l)), with
    s(l) interpolated in the fitted rows (flat beyond them), so that the material's own
    fracture strain holds at l — the element size its examples use — and each mesh keeps
    its scale relative to the others. A row (1, 1) is added if l is not a calibrated
    size. Scales rounded to ``digits`` decimals."""
    xs = np.array([m.element_size for m in cal.meshes])
    ss = np.array([m.scale for m in cal.meshes])
    s_at = float(np.interp(reference_length, xs, ss))
    rows = {round(float(h / reference_length), 6): round(float(s / s_at), digits)
            for h, s in zip(xs, ss)}
    rows[1.0] = 1.0
    return tuple(sorted(rows.items()))


# --- files -----------------------------------------------------------------------------
def _mm(x: float) -> str:
    return f"{x * 1e3:.6g} mm"


def regularisation_block(cal: Calibration, reference_length: float, source: str) -> str:
    """The ``[material.regularisation]`` table, with comments saying where each number
    comes from (inside the table, so that replacing the table replaces them)."""
    c = cal.coupon
    ref = cal.reference
    table = shipped_table(cal, reference_length)
    by_ratio = {round(m.element_size / reference_length, 6): m for m in cal.meshes}
    lines = [
        "[material.regularisation]",
        "# Element-size regularisation of fracture (docs/theory.md §7.3, J15): an element",
        "# of length l_e = √A0 fails at s(l_e/l_ref) times the file's fracture strain.",
        f"# Fitted by `wovenimpact calibrate fracture {source}` on a simulated",
        "# quasi-static tension test of this material (nothing ballistic enters): a flat",
        f"# coupon {_mm(c.length_m)} × {_mm(c.width_m)} × {_mm(c.thickness)}, its width "
        f"{c.reduction * 100:g} % smaller at the middle,",
        f"# pulled at {c.speed:g} m/s with the rate factors 1 (quasi-static), on meshes of "
        f"{', '.join(f'{m.element_size * 1e3:g}' for m in cal.meshes)} mm.",
        "# Each row's s makes its mesh fracture (the force down to half its peak) at the",
        f"# elongation of the finest, {ref.elongation_at_fracture * 1e3:.4f} mm; "
        f"s = 1 at reference_length.",
        f'reference_length = "{reference_length * 1e3:.6g} mm"',
        "fracture_scale = [  # [l_e/l_ref, s], flat beyond the first and last rows",
    ]
    for x, s in table:
        m = by_ratio.get(round(x, 6))
        if m is None:
            note = "the reference length (between calibrated meshes)"
        else:
            note = (f"{_mm(m.element_size)}: fractures at "
                    f"{m.before.elongation_at_fracture * 1e3:.4f} mm without the table, "
                    f"{m.after.elongation_at_fracture * 1e3:.4f} mm with it")
        lines.append(f"    [{x:.6g}, {s:.6g}],  # {note}")
    lines.append("]")
    if cal.failure_displacement > 0.0:
        lines.append(f'failure_displacement = "{cal.failure_displacement * 1e3:.6g} mm"'
                     "  # softening after onset, given (not fitted)")
    return "\n".join(lines) + "\n"


_TABLE_HEADER = re.compile(r"^\[\[?\s*[A-Za-z_][\w.\-\s]*\]\]?\s*(#.*)?$")


def replace_regularisation(text: str, block: str) -> str:
    """``text`` (a material file) with its ``[material.regularisation]`` table, if any,
    replaced by ``block`` (else ``block`` appended)."""
    lines = text.splitlines()
    start = next((i for i, ln in enumerate(lines)
                  if re.match(r"^\[\s*material\.regularisation\s*\]\s*(#.*)?$", ln)), None)
    if start is None:
        return text.rstrip("\n") + "\n\n" + block
    end = next((i for i in range(start + 1, len(lines)) if _TABLE_HEADER.match(lines[i])),
               len(lines))
    kept = lines[:start] + block.rstrip("\n").splitlines() + [""] + lines[end:]
    return "\n".join(kept).rstrip("\n") + "\n"


CSV_COLUMNS = (
    "element_size_mm", "scale", "root_find_runs",
    "elongation_at_fracture_before_mm", "elongation_at_fracture_after_mm",
    "error_before", "error_after",
    "onset_elongation_before_mm", "onset_elongation_after_mm",
    "work_to_fracture_before_J", "work_to_fracture_after_J",
    "peak_force_before_N", "kinetic_fraction_before", "energy_error_before",
    "energy_error_after", "elements", "steps_before", "wall_before_s",
)


def calibration_rows(cal: Calibration) -> list[dict]:
    """One dict per mesh, the CSV's columns (errors relative to the reference's
    elongation at fracture)."""
    target = cal.reference.elongation_at_fracture
    out = []
    for m in cal.meshes:
        b, a = m.before, m.after
        out.append({
            "element_size_mm": m.element_size * 1e3, "scale": m.scale,
            "root_find_runs": m.trials,
            "elongation_at_fracture_before_mm": b.elongation_at_fracture * 1e3,
            "elongation_at_fracture_after_mm": a.elongation_at_fracture * 1e3,
            "error_before": b.elongation_at_fracture / target - 1.0,
            "error_after": a.elongation_at_fracture / target - 1.0,
            "onset_elongation_before_mm": b.onset_elongation * 1e3,
            "onset_elongation_after_mm": a.onset_elongation * 1e3,
            "work_to_fracture_before_J": b.work_to_fracture,
            "work_to_fracture_after_J": a.work_to_fracture,
            "peak_force_before_N": b.peak_force,
            "kinetic_fraction_before": b.kinetic_fraction,
            "energy_error_before": b.energy_error, "energy_error_after": a.energy_error,
            "elements": b.elements, "steps_before": b.steps, "wall_before_s": b.wall_s,
        })
    return out


def write_csv(cal: Calibration, path: Path) -> Path:
    from wovenimpact.io.atomic import atomic_path

    with atomic_path(path) as tmp, open(tmp, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=CSV_COLUMNS)
        w.writeheader()
        for row in calibration_rows(cal):
            w.writerow({k: (repr(float(v)) if isinstance(v, float) else v)
                        for k, v in row.items()})
    return path


def calibration_figure(cal: Calibration, path: Path, title: str) -> Path:
    """Elongation at fracture and work to fracture against the element size, before
    and after the regularisation, and the force–elongation curves."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from wovenimpact.io.atomic import save_png

    h = np.array([m.element_size for m in cal.meshes]) * 1e3
    target = cal.reference.elongation_at_fracture * 1e3
    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(14, 4.2))
    a1.plot(h, [m.before.elongation_at_fracture * 1e3 for m in cal.meshes], "o-",
            label="fracture strain as given")
    a1.plot(h, [m.after.elongation_at_fracture * 1e3 for m in cal.meshes], "s--",
            label="with the fitted s(l_e/l_ref)")
    a1.axhline(target, color="k", lw=0.7, ls=":", label=f"reference ({h[0]:g} mm)")
    a1.set_xscale("log", base=2)
    a1.set_xlabel("element size (mm)")
    a1.set_ylabel("elongation at fracture (mm)")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    a2.plot(h, [m.before.work_to_fracture for m in cal.meshes], "o-", label="as given")
    a2.plot(h, [m.after.work_to_fracture for m in cal.meshes], "s--", label="fitted")
    a2.set_xscale("log", base=2)
    a2.set_xlabel("element size (mm)")
    a2.set_ylabel("work to separation (J)")
    a2.legend(fontsize=8, loc="center left")
    a2.grid(alpha=0.3)
    a2b = a2.twinx()
    a2b.plot(h, [m.scale for m in cal.meshes], "^:", color="C2")
    a2b.set_ylabel("fitted scale s", color="C2")
    for m, col in zip(cal.meshes, plt.rcParams["axes.prop_cycle"].by_key()["color"]):
        a3.plot(m.before.elongation * 1e3, m.before.force, color=col, lw=0.8,
                label=f"{m.element_size * 1e3:g} mm")
        a3.plot(m.after.elongation * 1e3, m.after.force, color=col, lw=0.8, ls="--")
    u_f = [m.before.elongation_at_fracture * 1e3 for m in cal.meshes]
    if all(math.isfinite(u) for u in u_f):  # the hardening's end and the load drops
        a3.set_xlim(0.8 * min(u_f), 1.03 * max(u_f))
    a3.set_ylim(bottom=0.0)
    a3.set_xlabel("elongation (mm)")
    a3.set_ylabel("force (N)")
    a3.legend(fontsize=7, title="solid: as given, dashed: fitted", title_fontsize=7)
    a3.grid(alpha=0.3)
    for ax in (a1, a2):
        ax.set_xticks(h, [f"{x:g}" for x in h])
        ax.minorticks_off()
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return save_png(fig, path)


def write_calibration(cal: Calibration, material_file: Path, out: Path,
                      reference_length: float | None = None) -> dict[str, Path]:
    """Write into ``out``: ``<stem>_regularised.toml`` (the material file with the fitted
    ``[material.regularisation]`` in place of any it had), ``<stem>_fracture.csv`` and
    ``<stem>_fracture.png``. Returns the paths."""
    from wovenimpact.io.atomic import atomic_write_text

    l_ref = cal.reference_size if reference_length is None else reference_length
    stem = material_file.stem
    block = regularisation_block(cal, l_ref, material_file.name)
    text = replace_regularisation(material_file.read_text(encoding="utf-8"), block)
    toml_path = out / f"{stem}_regularised.toml"
    atomic_write_text(toml_path, text)
    csv_path = write_csv(cal, out / f"{stem}_fracture.csv")
    png = calibration_figure(
        cal, out / f"{stem}_fracture.png",
        f"{cal.coupon.material.name}: tension coupon {_mm(cal.coupon.length_m)} × "
        f"{_mm(cal.coupon.width_m)} × {_mm(cal.coupon.thickness)}, elongation at fracture "
        f"and work to separation against the element size")
    return {"material": toml_path, "csv": csv_path, "figure": png}
