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

This module is the loop, its checkpoints and restart, and the clearing of an earlier
run's outputs; what it writes is computed elsewhere: history.csv's columns and rows in
:mod:`wovenimpact.results.history_rows`, summary.json's numbers in
:mod:`wovenimpact.results.summary`, the plots in :func:`wovenimpact.io.plots.write_run_plots`.
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
from wovenimpact.provenance import changed_parts, digest_of, provenance, restart_parts
from wovenimpact.results.containment import (
    CONTAINMENT_COLUMNS,
    CasingWatch,
    casing_inner_radius,
    casing_outer_radius,
    decided_since,
    is_containment,
    speed_settled,
)
from wovenimpact.results.history_rows import history_columns, history_row
from wovenimpact.results.summary import SUMMARY_VERSION, summarise
from wovenimpact.setup.compile import compile_case
from wovenimpact.solver import Workspace, step
from wovenimpact.spec.case import load_case
from wovenimpact.state import State

DEFAULT_OUTPUTS = {"history": 1000, "field": 20, "checkpoint": 10}  # per run, if not given


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
            row = history_row(model, state, normaliser, casing_watch, ws.contact)
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
    summary = summarise(spec, model, state, meta["wall_time_s"], history.arrays())
    summary["restarted_from_step"] = meta["restarted_from_step"]
    if is_containment(model):  # the outcome that ended the run early (None: end_time)
        summary["stopped_when_decided"] = decided
    summary["provenance"] = prov
    from wovenimpact.io.plots import write_run_plots

    write_run_plots(out, spec.case.name, model, state, history.arrays(), summary)
    # numpy scalars as Python numbers: a summary key computed with numpy must not end an
    # hour's run with a TypeError after its last step (it did: numpy's bool_)
    atomic_write_text(out / "summary.json",
                      json.dumps(summary, indent=2, default=_json_scalar) + "\n")
    from wovenimpact.io.pictures import write_pictures

    write_pictures(out, history.arrays())  # after summary.json: the page shows them
    write_run_report(out, spec=spec, model_digest=digest, **(source or {}))  # report.html
    return summary


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
