"""Running a case: the time loop with outputs, checkpoints and restart.

:func:`run_case` compiles a case file, steps it to ``run.end_time`` (a containment
case with ``run.stop_when_decided``: until its outcome has held that long) and writes

- ``OUT/history.csv``: energies and time-step data every ``history_interval``. A
  column's name says its scope: ``*_part_J`` energies are of the modelled part (a
  quarter of the problem in a quarter model), ``*_full_*`` values (the contact force)
  of the whole problem; summary.json gives every energy for the whole problem
  (modelled part × ``symmetry_factor``);
- ``OUT/fields/step_*.vtu`` + ``fields.pvd``: ParaView series every ``field_interval``;
- ``OUT/checkpoints/checkpoint_*.npz``: the State every ``checkpoint_interval``
  (history.csv is rewritten atomically at each checkpoint, so a killed run leaves
  consistent files); ``restart=True`` resumes from the newest one and the run ends
  bitwise identical to an uninterrupted one (the output schedule is a function of
  the State alone);
- ``OUT/plots/energy.png``, ``OUT/summary.json`` and ``OUT/report.html`` (one page: the
  answer, how far to trust it, the summary grouped in engineering units, plots, case,
  provenance; :mod:`wovenimpact.io.report`) at the end.

summary.json carries the ``provenance`` digests (:mod:`wovenimpact.provenance`) by which
studies reuse a finished run, and ``energy_check``: a run whose energy balance fails
``run.energy_tolerance`` still writes every output; the CLI then exits with code 4.
A checkpoint also records the history rows and field frames written so far, which a
restart checks against history.csv and fields.pvd (:func:`resume`).
"""

from __future__ import annotations

import json
import math
import time
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np

from wovenimpact.errors import InputError, InputWarning, SimulationError
from wovenimpact.interfaces import booked_totals, interface_energies
from wovenimpact.io.atomic import atomic_write_text
from wovenimpact.io.checkpoint import (
    checkpoint_meta,
    latest_checkpoint,
    load_checkpoint,
    save_checkpoint,
)
from wovenimpact.io.fields import FieldWriter
from wovenimpact.io.history import History
from wovenimpact.io.report import write_run_report
from wovenimpact.kernels import shell_layout as SL
from wovenimpact.kernels.contact_energy import DAMPING, FRICTION
from wovenimpact.provenance import changed_parts, digest_of, provenance, restart_parts
from wovenimpact.results.containment import (
    CASING_ENERGY_COLUMNS,
    CONTAINMENT_COLUMNS,
    CasingWatch,
    casing_energy_row,
    casing_inner_radius,
    casing_outer_radius,
    casing_summary,
    decided_since,
    fragment_row,
    is_containment,
    layer_columns,
    layer_elements,
    layer_materials,
    layer_row,
    layer_sets,
    speed_settled,
)
from wovenimpact.results.mesh_verdict import SUMMARY_KEY as MESH_VERDICT_KEY
from wovenimpact.results.mesh_verdict import mesh_verdict
from wovenimpact.results.metal_state import has_metal, plastic_work
from wovenimpact.results.quantities import (
    REACTION_COLUMNS,
    impactor_row,
    intact_material_ahead,
    outcome_decided_at,
    ply_columns,
    ply_contact_work,
    ply_deflections,
    ply_energies,
    ply_perforation_times,
    ply_row,
    reaction_row,
    residual_velocity,
    symmetry_factor,
)
from wovenimpact.setup.compile import CompiledCase, compile_case
from wovenimpact.solver import Workspace, energy_balance, step
from wovenimpact.solver.explicit import error_fraction
from wovenimpact.spec.case import load_case
from wovenimpact.state import KINETIC0, MASS_SCALING, State

HISTORY_COLUMNS = (
    "time_s", "step", "dt_s", "structure_kinetic_energy_part_J", "internal_work_part_J",
    "stored_energy_part_J", "hourglass_energy_part_J", "external_work_part_J",
    "eroded_kinetic_energy_part_J", "eroded_internal_energy_part_J", "contact_energy_part_J",
    "contact_dissipated_part_J", "contact_damping_energy_part_J",
    "contact_friction_energy_part_J", "body_force_work_part_J", "reaction_work_part_J",
    "energy_drift_part_J", "energy_error_fraction", "energy_normaliser_part_J",
    "max_displacement_m", "eroded_elements",
)
IMPACT_COLUMNS = ("impactor_velocity_m_per_s", "impactor_displacement_m", "contact_force_full_N",
                  "impactor_nose_ahead_of_intact_m", "intact_material_ahead",
                  "impactor_kinetic_energy_part_J")
METAL_COLUMNS = ("plastic_work_part_J",)  # models with a J2 (metal) section
MASS_SCALING_COLUMNS = ("added_mass_part_kg", "mass_scaling_energy_part_J", "mass_scaled_elements")
SUMMARY_VERSION = 4  # 2: issue 9's outcome rule and energy keys; 3: issue 12's energy
#                     normalisation and provenance; 4: a casing layer's absorbed energy is
#                     the contact work it received (held_energy_per_layer_J the old
#                     figure); older summaries are re-run
DEFAULT_OUTPUTS = {"history": 1000, "field": 20, "checkpoint": 10}  # per run, if not given


def history_columns(model) -> tuple[str, ...]:
    """history.csv columns: energies etc., plus the impactor's if there is one.

    Scope in the name: ``*_part_J`` is of the modelled part (a quarter of the problem
    in a quarter model; × ``symmetry_factor`` of summary.json gives the whole), ``*_full_*``
    of the whole problem; velocities, displacements, fractions and counts need neither.
    ``energy_drift_part_J`` is the balance's drift (solver.explicit.energy_balance),
    ``energy_normaliser_part_J`` the largest energy put into the model so far (the running
    maximum of its ``scale_J`` over the rows up to this one) and ``energy_error_fraction``
    = |drift| / normaliser (0 while the normaliser is 0: no energy put in); summary.json's
    figure is the largest |drift| over the last (largest) normaliser.
    ``body_force_work_part_J`` and ``reaction_work_part_J`` (supports and prescribed
    motions) are the two parts of ``external_work_part_J``.
    ``contact_energy_part_J`` is −(work of the contact forces): the penalty springs' energy
    plus ``contact_dissipated_part_J``, what contact dashpots and friction dissipated;
    of it, ``contact_damping_energy_part_J`` and ``contact_friction_energy_part_J`` are
    the dashpots' and friction's own work, booked pair by pair (wovenimpact.interfaces;
    the rest is the penalty's discretisation: k follows Δt, docs/theory.md §6).
    ``plastic_work_part_J`` (models with a metal section): the plastic work of the J2
    points (metal_state.plastic_work), a part of the internal work. With mass scaling
    (``run.mass_scaling_fraction``): ``added_mass_part_kg``, ``mass_scaling_energy_part_J``
    (the kinetic energy the added mass brought, an input of the balance) and
    ``mass_scaled_elements``. A containment model's rows add the fragment's and the
    casing's columns (containment.fragment_row, containment.casing_energy_row: the
    fragment's kinetic energy and the casing's kinetic, element and absorbed energies).

    Last come the columns of each layer or ply (appended after all the others, so the
    columns before them keep their places): a containment model's
    ``casing_layer{k}_absorbed_energy_part_J`` and ``casing_layer{k}_intact_outside``
    (containment.layer_row), a plate impact's ``ply{p}_contact_work_part_J`` and
    ``ply{p}_intact_ahead`` (quantities.ply_row). After them, appended later still,
    ``reaction_force_{x,y,z}_part_N``: the summed reaction force of the supports (nodes with
    all three translations fixed) in global axes, the force whose work
    ``reaction_work_part_J`` books (quantities.support_reaction)."""
    return (HISTORY_COLUMNS + (IMPACT_COLUMNS if model.body_params.shape[0] else ())
            + (METAL_COLUMNS if has_metal(model) else ())
            + (MASS_SCALING_COLUMNS if model.mass_scaling_fraction > 0.0 else ())
            + (CONTAINMENT_COLUMNS + CASING_ENERGY_COLUMNS if is_containment(model) else ())
            + per_layer_columns(model) + REACTION_COLUMNS)


def per_layer_columns(model) -> tuple[str, ...]:
    """The layer or ply columns ending a history row (:func:`history_columns`)."""
    if is_containment(model):
        return layer_columns(len(layer_sets(model)))
    if model.body_params.shape[0]:
        return ply_columns(model)
    return ()


def history_row(model, state: State, normaliser: float = 0.0,
                watch: CasingWatch | None = None) -> dict:
    """One history.csv row of ``state`` (columns :func:`history_columns`); ``normaliser``
    is the previous row's ``energy_normaliser_part_J`` (0 for the first row); ``watch``
    the run's :class:`~wovenimpact.results.containment.CasingWatch` (containment models; made
    for the row when not given)."""
    eb = energy_balance(model, state)
    booked = booked_totals(state.contact_books[0])
    scale = max(normaliser, eb["scale_J"])
    disp = np.sqrt(np.max(np.sum((state.x - model.x0) ** 2, axis=1)))
    impact = {}
    if model.body_params.shape[0]:
        impact = {**impactor_row(model, state), **intact_material_ahead(model, state),
                  "impactor_kinetic_energy_part_J": eb["impactor_kinetic_J"]}
    if is_containment(model):
        watch = CasingWatch(model) if watch is None else watch
        impact.update(fragment_row(model, state, watch))
        impact.update(casing_energy_row(model, state, watch))
        impact.update(layer_row(model, state, watch))
    elif model.body_params.shape[0]:
        impact.update(ply_row(model, state))
    if has_metal(model):
        impact["plastic_work_part_J"] = plastic_work(model, state)
    if model.mass_scaling_fraction > 0.0:
        impact.update(mass_scaling_row(state))
    impact.update(reaction_row(model, state))
    return {
        **impact,
        "time_s": float(state.t), "step": int(state.step), "dt_s": float(state.dt),
        "structure_kinetic_energy_part_J": eb["kinetic_J"],
        "internal_work_part_J": eb["internal_work_J"], "stored_energy_part_J": eb["stored_J"],
        "hourglass_energy_part_J": eb["hourglass_J"],
        "external_work_part_J": eb["external_work_J"],
        "eroded_kinetic_energy_part_J": eb["eroded_kinetic_J"],
        "eroded_internal_energy_part_J": eb["eroded_internal_J"],
        "contact_energy_part_J": eb["contact_energy_J"],
        "contact_dissipated_part_J": eb["contact_dissipated_J"],
        "contact_damping_energy_part_J": booked["damping"],
        "contact_friction_energy_part_J": booked["friction"],
        "body_force_work_part_J": eb["body_force_work_J"],
        "reaction_work_part_J": eb["reaction_work_J"], "energy_drift_part_J": eb["drift_J"],
        "energy_error_fraction": error_fraction(eb["drift_J"], scale),
        "energy_normaliser_part_J": scale, "max_displacement_m": float(disp),
        "eroded_elements": int(np.sum(state.elem[:, SL.E_ALIVE] == 0.0)),
    }


def mass_scaling_row(state: State) -> dict:
    """Mass added by mass scaling so far (modelled part), the kinetic energy it brought
    and the number of elements that carry some."""
    return {"added_mass_part_kg": float(np.sum(state.added_mass)),
            "mass_scaling_energy_part_J": float(state.energy[MASS_SCALING]),
            "mass_scaled_elements": int(np.count_nonzero(state.mass_ratio))}


class Schedule:
    """Output times k·Δ (k = 1, 2, …): due when the simulated time has reached the next one."""

    def __init__(self, interval: float, t: float):
        self.interval = interval
        self.next = self.following(t)

    def following(self, t: float) -> float:
        return (math.floor(t / self.interval) + 1) * self.interval

    def due(self, t: float) -> bool:
        if t >= self.next:
            self.next = self.following(t)
            return True
        return False


def _interval(value: float | None, end: float, per_run: int) -> float:
    return value if value is not None else end / per_run


def run_case(
    case_path: str | Path,
    out_dir: str | Path,
    *,
    restart: bool = False,
    threads: int | None = None,
    progress: Callable[[State, float], None] | None = None,
    max_steps: int | None = None,
    overrides=(),
) -> dict:
    """Run a case file and write its outputs; returns the summary (also in summary.json).

    Args:
        case_path: the case TOML.
        out_dir: output directory (created).
        restart: resume from the newest checkpoint in ``out_dir/checkpoints``.
        threads: threads for the kernels (default: the case's ``run.threads``, else all).
        progress: called as ``progress(state, end_time)`` about every 0.2 s of wall time.
        max_steps: stop after this many steps of this invocation without final outputs
            (as a crash would; used to test restarts).
        overrides: ``KEY=VALUE`` changes to the case (``--set``; spec.fields.parse_override).
    """
    spec, base = load_case(case_path, overrides)
    source = {"case_text": Path(case_path).read_text(encoding="utf-8"), "case_path": case_path,
              "overrides": tuple(overrides or ())}
    return run_spec(spec, base, out_dir, restart=restart, threads=threads, progress=progress,
                    max_steps=max_steps, source=source)


def _json_scalar(value):
    """json.dumps's fallback for summary.json: numpy scalars become Python numbers;
    anything else is still refused (a summary is numbers, strings, lists and dicts)."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"summary value of type {type(value).__name__} is not JSON: {value!r}")


def run_spec(
    spec,
    base: str | Path,
    out_dir: str | Path,
    *,
    restart: bool = False,
    threads: int | None = None,
    progress: Callable[[State, float], None] | None = None,
    max_steps: int | None = None,
    source: dict | None = None,
) -> dict:
    """:func:`run_case` for a validated :class:`~wovenimpact.spec.case.CaseSpec` whose
    relative paths (materials, mesh) are relative to ``base``. ``source`` (case_text,
    case_path, overrides) is what report.html shows as the case; without it, the spec.

    A fresh run first removes the outputs an earlier run left in ``out_dir`` (checkpoints,
    VTU frames, plots, history, summary, report; :func:`clear_outputs`, warning how many),
    so no file of another case survives beside the new ones. A restart resumes only a
    checkpoint written for this case, its files and this code (provenance.restart_parts)
    whose history.csv and fields.pvd hold the rows and frames the checkpoint counted
    (:func:`resume`); the frame and row numbering continue from the checkpoint's counts.
    """
    compiled = compile_case(spec, Path(base))
    model = compiled.model
    watch = decision_watch(model, spec.run.stop_when_decided)
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    n_threads = threads or spec.run.threads
    if n_threads is not None:
        from wovenimpact.jit import capped_threads, set_threads

        set_threads(capped_threads(n_threads, "--threads" if threads else "run.threads"))
    digest = model.digest()
    prov = provenance(spec, base)
    parts = restart_parts(spec, base)
    meta = {"restart_digest": digest_of(parts), "restart_parts": parts,
            "wall_time_s": 0.0, "restarted_from_step": None}
    run = spec.run
    ckpt_dir = out / "checkpoints"
    casing_watch = CasingWatch(model) if is_containment(model) else None
    if restart:
        state, history, fields, wall_before = resume(out, model, digest, parts, run.end_time)
        meta["restarted_from_step"] = state.step
    else:
        clear_outputs(out)
        state, wall_before = compiled.state, 0.0
        history = History(history_columns(model))
        fields = FieldWriter(out / "fields", model)
        history.append(history_row(model, state, watch=casing_watch))
        fields.write(state)
    h_sched = Schedule(_interval(run.history_interval, run.end_time, DEFAULT_OUTPUTS["history"]), state.t)
    f_sched = Schedule(_interval(run.field_interval, run.end_time, DEFAULT_OUTPUTS["field"]), state.t)
    c_sched = Schedule(_interval(run.checkpoint_interval, run.end_time, DEFAULT_OUTPUTS["checkpoint"]), state.t)
    ws = Workspace.for_model(model, state)
    wall0 = time.perf_counter()
    last_report = wall0
    normaliser = float(history.arrays()["energy_normaliser_part_J"][-1])

    def checkpoint() -> None:
        meta.update(history_rows=len(history), field_frames=fields.frames,
                    wall_time_s=wall_before + time.perf_counter() - wall0)
        history.write_csv(out / "history.csv")
        save_checkpoint(ckpt_dir, state, digest, meta=meta)

    decided = watch(history) if watch else None
    taken = 0
    while state.t < run.end_time and not decided:
        if max_steps is not None and taken >= max_steps:
            return {"interrupted_at_step": state.step, "time_s": state.t}
        try:
            step(model, state, ws)
        except SimulationError:
            # the history up to the failure is what explains it: write it (rows beyond
            # the last checkpoint are dropped again by a restart, resume → keep_first)
            history.write_csv(out / "history.csv")
            raise
        taken += 1
        if h_sched.due(state.t) or state.t >= run.end_time:
            row = history_row(model, state, normaliser, casing_watch)
            normaliser = row["energy_normaliser_part_J"]
            history.append(row)
            decided = watch(history) if watch else None
        if f_sched.due(state.t) or state.t >= run.end_time or decided:
            fields.write(state)
        if c_sched.due(state.t):
            checkpoint()
        if progress is not None and time.perf_counter() - last_report > 0.2:
            last_report = time.perf_counter()
            progress(state, run.end_time)
    if progress is not None:
        progress(state, run.end_time)
    checkpoint()
    summary = summarise(spec, compiled, state, meta["wall_time_s"], history.arrays())
    summary["restarted_from_step"] = meta["restarted_from_step"]
    if is_containment(model):  # the outcome that ended the run early (None: end_time)
        summary["stopped_when_decided"] = decided
    summary["provenance"] = prov
    write_plots(out, spec.case.name, model, state, history.arrays(), summary)
    # numpy scalars as Python numbers: a summary key computed with numpy must not end an
    # hour's run with a TypeError after its last step (it did: numpy's bool_)
    atomic_write_text(out / "summary.json",
                      json.dumps(summary, indent=2, default=_json_scalar) + "\n")
    from wovenimpact.io.pictures import write_pictures

    write_pictures(out, history.arrays())  # after summary.json: the page shows them
    write_run_report(out, spec=spec, model_digest=digest, **(source or {}))  # report.html
    return summary


def write_plots(out: Path, title: str, model, state: State, h: dict, summary: dict) -> None:
    """The plots of a finished run in ``OUT/plots``: energies; a containment run's fragment
    plot, a plate's deflection profile and impactor plot, each with the instants its
    layers (plies) were first perforated and its outcome decided; the energy each layer
    or ply absorbed over time."""
    from wovenimpact.io.plots import (
        deflection_plot,
        energy_plot,
        event_markers,
        fragment_plot,
        impactor_plot,
        layer_energy_plot,
    )

    plots = out / "plots"
    factor = symmetry_factor(model)
    energy_plot(h, plots / "energy.png", title=title, symmetry_factor=factor)
    if is_containment(model):  # a plate's deflection along y = 0 means nothing on a casing
        names = [f"layer {k} ({m})" for k, m in enumerate(layer_materials(model))]
        markers = event_markers(summary.get("layer_perforated_at_s", []),
                                summary.get("outcome_decided_at_s"), names)
        fragment_plot(h, plots / "fragment.png", title=title,
                      outcome=summary.get("outcome", ""), markers=markers)
    else:
        if model.n_elems:  # (a model of hexahedra has no plies)
            deflection_plot(model, state, plots / "ply_deflection.png", title=title)
        numbers = np.unique(model.ply)
        names = [f"ply {p}" for p in numbers]
        markers = event_markers(summary.get("ply_perforated_at_s", []),
                                summary.get("outcome_decided_at_s"), names)
    if "impactor_velocity_m_per_s" in h:
        impactor_plot(h, plots / "impactor.png", title=title, markers=markers)
    layer_energy_plot(h, plots / "layer_energy.png", title=title, symmetry_factor=factor,
                      names=names, markers=markers)


OUTPUT_PATTERNS = ("checkpoints/checkpoint_*.npz", "fields/step_*.vtu", "fields/fields.pvd",
                   "fields/element_sets.json",
                   "plots/*.png", "pictures/frame_*.png", "pictures/pictures.json",
                   "history.csv", "summary.json", "report.html",
                   "error.txt")  # error.txt: a failed run of a sweep or design search


def clear_outputs(out: Path) -> None:
    """Remove what an earlier run wrote into ``out`` (:data:`OUTPUT_PATTERNS`, nothing
    else), saying how many files go before they go: a new run's outputs never mix with
    another's."""
    old = [p for pattern in OUTPUT_PATTERNS for p in out.glob(pattern) if p.is_file()]
    if old:
        warnings.warn(f"{out}: removing {len(old)} output files of an earlier run "
                      "(checkpoints, fields, plots, history, summary, report, error) before "
                      "this one (to keep them, give another --out)",
                      InputWarning, stacklevel=3)
    for p in old:
        p.unlink()


def decision_watch(model, hold: float | None):
    """``run.stop_when_decided``: None if it is not set; else a function of the history
    that returns the outcome (``"contained"`` or ``"escaped"``) once every row of the
    last ``hold`` seconds has read it (containment.decided_since) and, for ``escaped``,
    the fragment's speed has settled over that hold (containment.speed_settled: its exit
    speed is known), else None."""
    if hold is None:
        return None
    if not is_containment(model):
        raise InputError(f"run.stop_when_decided = {hold!r} s: only a containment case "
                         "(a blade fragment and casing layers) has an outcome to decide; "
                         "remove it")
    inner, outer = casing_inner_radius(model), casing_outer_radius(model)
    columns = CONTAINMENT_COLUMNS + ("time_s",)

    def watch(history: History) -> str | None:
        h = history.arrays(columns)
        outcome, since = decided_since(h, inner, outer)
        t_last = h["time_s"][-1]
        if outcome == "undecided" or t_last - since < hold:
            return None
        if outcome == "escaped" and not speed_settled(h, t_last - hold):
            return None
        return outcome

    return watch


def resume(out: Path, model, digest: str, parts: dict, end_time: float):
    """State, History, FieldWriter and earlier wall time of a restart from the newest
    checkpoint in ``out/checkpoints``, after checking that it belongs to this case and
    code and that history.csv and fields.pvd hold what it counted; otherwise an
    :class:`InputError` saying what is wrong (nothing is written before the checks)."""
    last = latest_checkpoint(out / "checkpoints")
    if last is None:
        raise InputError(f"--restart: no checkpoint in {out / 'checkpoints'}; run without "
                         "--restart")
    meta = checkpoint_meta(last)
    hint = "; run without --restart to start again"
    if "history_rows" not in meta:
        raise InputError(f"--restart: checkpoint {last} was written by an older wovenimpact "
                         f"(no record of its history rows and field frames){hint}")
    if meta.get("restart_digest") != digest_of(parts):
        what = changed_parts(meta.get("restart_parts") or {}, parts)
        raise InputError(f"--restart: checkpoint {last} was written before a change of {what} "
                         f"(provenance digest differs){hint}")
    state = load_checkpoint(last, digest)
    if state.t - state.dt >= end_time:  # this run would have ended steps before it
        raise InputError(f"--restart: checkpoint {last} is at t = {state.t!r} s, past "
                         f"run.end_time = {end_time!r} s; give run.end_time ≥ {state.t!r} s"
                         f"{hint}")
    path = out / "history.csv"
    if not path.exists():
        raise InputError(f"--restart: {path} is missing (the checkpoint counts "
                         f"{meta['history_rows']} rows before it){hint}")
    history = History.from_csv(path)
    n_rows = int(meta["history_rows"])
    if history.columns != history_columns(model) or len(history) < n_rows:
        raise InputError(f"--restart: {path} does not hold the {n_rows} rows of "
                         f"{len(history_columns(model))} columns written before the checkpoint"
                         f"{hint}")
    history.keep_first(n_rows)
    if not history.arrays()["time_s"][-1] <= state.t:
        raise InputError(f"--restart: {path} has rows after the checkpoint's time among its "
                         f"first {n_rows}; it belongs to another run{hint}")
    fields = FieldWriter.resume(out / "fields", model, int(meta["field_frames"]))
    return state, history, fields, float(meta["wall_time_s"])


def summarise(spec, compiled: CompiledCase, state: State, wall: float, h: dict) -> dict:
    """The numbers a user wants from a finished run (summary.json). Energies here are
    of the whole problem (the modelled part's × ``symmetry_factor``):

    - ``structure_kinetic_energy_J`` (nodes), ``impactor_kinetic_energy_J`` (rigid
      bodies) and ``total_kinetic_energy_J`` (both) at the end;
      ``initial_total_kinetic_energy_J`` (both, t = 0) with its parts
      ``initial_structure_kinetic_energy_J`` and ``initial_impactor_kinetic_energy_J``;
    - ``internal_work_J`` = stored (live elements) + hourglass (live elements) + eroded
      internal (energies of eroded elements at erosion) + dissipated, each joule once;
    - ``hourglass_fraction`` = (``hourglass_energy_J`` of live elements +
      ``eroded_hourglass_energy_J``, what eroded ones held at erosion) / internal work
      (docs/theory.md §5), None while the internal work is not positive;
    - ``energy_error_fraction``: the largest |drift| of the history over the largest
      energy put into the model (its last ``energy_normaliser_part_J``), and ``energy_check``
      "pass" if it is at most ``energy_tolerance`` (``run.energy_tolerance``), else "fail"
      (the CLI then exits with code 4);
    - ``contact_damping_energy_J`` and ``contact_friction_energy_J``: what the contact
      dashpots and friction dissipated, and the same per interface
      (``*_by_interface_J``, :func:`contact_damping_summary`);
    - ``element_cycles``, ``wall_time_s`` and ``ns_per_element_cycle`` of every
      invocation that made this result (a restarted run's included).
    """
    model = compiled.model
    eb = energy_balance(model, state)
    cycles = state.step * (model.n_elems + model.n_hexes)
    error = error_fraction(np.max(np.abs(h["energy_drift_part_J"])),
                           h["energy_normaliser_part_J"][-1])
    factor = symmetry_factor(model)
    impact = {}
    if is_containment(model):
        impact = casing_summary(model, state, h)
    ke_body0 = 0.0
    if model.body_params.shape[0]:
        ke_body0 = factor * float(h["impactor_kinetic_energy_part_J"][0])
        ke1 = factor * eb["impactor_kinetic_J"]
        per_ply = ply_energies(model, state)
        impact = {
            **residual_velocity(h),
            "ply_perforated_at_s": ply_perforation_times(h),
            "outcome_decided_at_s": outcome_decided_at(h),
            "initial_velocity_m_per_s": float(h["impactor_velocity_m_per_s"][0]),
            "absorbed_energy_J": ke_body0 - ke1,
            "absorbed_energy_per_ply_J": per_ply,
            "contact_work_per_ply_J": ply_contact_work(model, state),
            "max_deflection_m": max(ply_deflections(model, state)),
            "max_deflection_per_ply_m": ply_deflections(model, state),
            "peak_contact_force_N": float(np.max(h["contact_force_full_N"])),
        }
    w_int = eb["internal_work_J"]
    hg_all = eb["hourglass_J"] + eb["eroded_hourglass_J"]
    return {**impact,
        "summary_version": SUMMARY_VERSION,
        # when this summary was written (UTC): a report that reuses the run can say so
        "finished_utc": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime()),
        "case": spec.case.name,
        "end_time_s": float(state.t),
        "steps": int(state.step),
        "elements": int(model.n_elems + model.n_hexes),
        "nodes": int(model.n_nodes),
        "first_time_step_s": float(state.dt_first),
        "last_time_step_s": float(state.dt),
        "wall_time_s": wall,
        "element_cycles": int(cycles),
        "ns_per_element_cycle": wall / cycles * 1e9 if cycles else None,
        "structure_kinetic_energy_J": factor * eb["kinetic_J"],
        "impactor_kinetic_energy_J": factor * eb["impactor_kinetic_J"],
        "total_kinetic_energy_J": factor * (eb["kinetic_J"] + eb["impactor_kinetic_J"]),
        "initial_total_kinetic_energy_J": factor * float(state.energy[KINETIC0]),
        "initial_structure_kinetic_energy_J": factor * float(state.energy[KINETIC0]) - ke_body0,
        "initial_impactor_kinetic_energy_J": ke_body0,
        "internal_work_J": factor * w_int,
        "stored_energy_J": factor * eb["stored_J"],
        "hourglass_energy_J": factor * eb["hourglass_J"],
        "eroded_internal_energy_J": factor * eb["eroded_internal_J"],
        "eroded_hourglass_energy_J": factor * eb["eroded_hourglass_J"],
        "eroded_kinetic_energy_J": factor * eb["eroded_kinetic_J"],
        **({"plastic_work_J": factor * plastic_work(model, state)} if has_metal(model) else {}),
        **(mass_scaling_summary(model, state, factor) if model.mass_scaling_fraction > 0.0
           else {}),
        # undefined (None, "n/a" on the page) while no positive internal work was done,
        # e.g. a spun blade that has only given back part of its pre-stress energy
        "hourglass_fraction": hg_all / w_int if w_int > 0.0 else None,
        "external_work_J": factor * eb["external_work_J"],
        "body_force_work_J": factor * eb["body_force_work_J"],
        "reaction_work_J": factor * eb["reaction_work_J"],
        "contact_energy_J": factor * eb["contact_energy_J"],
        **contact_damping_summary(model, state, factor),
        "eroded_elements": int(np.sum(state.elem[:, SL.E_ALIVE] == 0.0)),
        "energy_error_fraction": error,
        "energy_tolerance": spec.run.energy_tolerance,
        "energy_check": "pass" if error <= spec.run.energy_tolerance else "fail",
        "symmetry_factor": factor,
        # each failing material's element lengths against its calibrated range (theory §1.4)
        MESH_VERDICT_KEY: mesh_verdict(model, state),
        **element_sizes(spec, model),
        "max_displacement_m": float(np.sqrt(np.max(np.sum((state.x - model.x0) ** 2, axis=1)))),
    }


def element_sizes(spec, model) -> dict:
    """summary.json's element sizes (m), the first thing a reader of a result asks:
    ``element_size_m``, the case's ``mesh.element_size`` (a containment casing's: the fine
    sector's in a graded ring) and, for a containment case, ``blade_element_size_m``, the
    blade's (``mesh.blade.element_size``, else the casing's). An imported mesh has no
    such key: there each is the median √(element area) of the elements it stands for
    (the casing layers' and the rest, the blade, in an imported containment mesh), and a
    mesh of hexahedra only (``mesh.kind = "block"`` or imported) has the median
    ∛(hexahedron volume)."""
    mesh = spec.mesh
    if model.n_hexes and not model.n_elems:
        return {"element_size_m": float(np.median(np.cbrt(model.solid.vol0)))}
    if mesh.kind == "plate":
        return {"element_size_m": float(mesh.element_size)}
    if mesh.kind == "containment":
        return {"element_size_m": float(mesh.element_size),
                "blade_element_size_m": float(mesh.blade_element_size)}

    def median_size(elems) -> float | None:
        return float(np.sqrt(np.median(model.area0[elems]))) if len(elems) else None

    if not is_containment(model):
        return {"element_size_m": median_size(np.arange(model.n_elems))}
    casing = np.concatenate(layer_elements(model))
    blade = np.setdiff1d(np.arange(model.n_elems), casing)
    return {"element_size_m": median_size(casing), "blade_element_size_m": median_size(blade)}


def contact_damping_summary(model, state: State, factor: float) -> dict:
    """summary.json keys of the energy the contact dashpots and friction dissipated (J,
    whole problem): in all and per interface, {"layer0-layer1": J, "ply0-impactor": J,
    …} over the interfaces where contact acted (wovenimpact.interfaces; docs/theory.md
    §6, "Contact energy per interface")."""
    books = state.contact_books[0]
    totals = booked_totals(books)
    return {
        "contact_damping_energy_J": factor * totals["damping"],
        "contact_friction_energy_J": factor * totals["friction"],
        "contact_damping_energy_by_interface_J": interface_energies(model, books, DAMPING,
                                                                    factor),
        "contact_friction_energy_by_interface_J": interface_energies(model, books, FRICTION,
                                                                     factor),
    }


def mass_scaling_summary(model, state: State, factor: float) -> dict:
    """summary.json keys of a run with mass scaling: the added mass (whole problem), its
    fraction of the model's mass, the kinetic energy it brought and the elements scaled."""
    row = mass_scaling_row(state)
    return {"added_mass_kg": factor * row["added_mass_part_kg"],
            "added_mass_fraction": row["added_mass_part_kg"] / float(np.sum(model.node_mass)),
            "mass_scaling_energy_J": factor * row["mass_scaling_energy_part_J"],
            "mass_scaled_elements": row["mass_scaled_elements"]}


IMPACT_SUMMARY_KEYS = ("outcome", "perforated", "residual_velocity_m_per_s",
                       "rebound_velocity_m_per_s", "ply_perforated_at_s",
                       "outcome_decided_at_s", "initial_velocity_m_per_s",
                       "absorbed_energy_J", "absorbed_energy_per_ply_J",
                       "contact_work_per_ply_J", "max_deflection_m",
                       "max_deflection_per_ply_m", "peak_contact_force_N")
CONTAINMENT_SUMMARY_KEYS = ("outcome", "contained", "fragment_exit_speed_m_per_s",
                            "fragment_speed_at_end_m_per_s", "fragment_exit_speed_settled", "fragment_mass_kg", "fragment_initial_speed_m_per_s", "max_bulge_m",
                            "casing_mass_kg", "casing_mass_per_area_kg_per_m2", "casing_layers",
                            "absorbed_energy_per_layer_J", "casing_absorbed_energy_J",
                            "held_energy_per_layer_J",
                            "absorbed_energy_per_material_J", "stopped_when_decided",
                            "layer_perforated_at_s", "outcome_decided_at_s",
                            "blade_element_size_m")
COMMON_SUMMARY_KEYS = (
    "summary_version", "case", "end_time_s", "steps", "elements", "nodes", "first_time_step_s",
    "last_time_step_s", "wall_time_s", "element_cycles", "ns_per_element_cycle",
    "structure_kinetic_energy_J", "impactor_kinetic_energy_J", "total_kinetic_energy_J",
    "initial_total_kinetic_energy_J", "initial_structure_kinetic_energy_J",
    "initial_impactor_kinetic_energy_J", "internal_work_J", "stored_energy_J",
    "hourglass_energy_J", "eroded_internal_energy_J", "eroded_hourglass_energy_J",
    "eroded_kinetic_energy_J", "hourglass_fraction", "external_work_J", "body_force_work_J",
    "reaction_work_J", "contact_energy_J", "contact_damping_energy_J",
    "contact_friction_energy_J", "contact_damping_energy_by_interface_J",
    "contact_friction_energy_by_interface_J", "eroded_elements", "energy_error_fraction",
    "energy_tolerance", "energy_check", "symmetry_factor", "max_displacement_m",
    "restarted_from_step", "provenance", "finished_utc", "mesh_verdict", "element_size_m",
    "plastic_work_J",  # runs with a metal section only
    # runs with mass scaling only
    "added_mass_kg", "added_mass_fraction", "mass_scaling_energy_J", "mass_scaled_elements",
)


def summary_keys(spec) -> tuple[str, ...]:
    """The keys summary.json will have for a case (the metrics a study may ask for)."""
    from wovenimpact.spec.case import is_containment_spec

    extra = (CONTAINMENT_SUMMARY_KEYS if is_containment_spec(spec)
             else IMPACT_SUMMARY_KEYS if spec.impactor is not None else ())
    return tuple(dict.fromkeys(COMMON_SUMMARY_KEYS + extra))


def reused_or_run(case_path: str | Path, out: str | Path, log=None, label: str = "case") -> dict:
    """The summary of the case file ``case_path`` run in ``out``: the one there if it is
    a finished run of exactly this case, its files and this code
    (:func:`reusable_summary`), else a new run — ``log(message)`` is told so, with the
    reason the old one could not be reused."""
    from wovenimpact.spec.case import load_case

    s, why = reusable_summary(out, *load_case(case_path))
    if s is None:
        if log is not None:
            log(f"{label} {Path(case_path).stem} → {out}"
                + (f" (run again: {why})" if why else ""))
        s = run_case(case_path, out)
    return s


def reusable_summary(out: str | Path, spec, base: str | Path,
                     older_code: bool = False) -> tuple[dict | None, str]:
    """The summary.json in ``out`` if it is a finished run of exactly this case, its
    files and this code (provenance digest, current ``summary_version``; any code with
    ``older_code``), else None with the reason ("" when there is no summary at all)."""
    from wovenimpact.provenance import stale_reason

    try:
        summary = json.loads((Path(out) / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None, ""
    if not isinstance(summary, dict) or summary.get("summary_version", 1) < SUMMARY_VERSION:
        return None, "its summary was written by an older wovenimpact (summary_version)"
    reason = stale_reason(summary, provenance(spec, base), older_code)
    return (None, reason) if reason else (summary, "")
