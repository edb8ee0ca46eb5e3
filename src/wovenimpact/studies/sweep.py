"""Parameter studies: many variants of one case, on local processes or a Dask cluster.

A study file (TOML) names a base case and the values to try for any key of it,
addressed by its dotted path in the case document::

    [study]
    name = "striking velocity"
    case = "../cases/fabric_plate_impulse.toml"    # relative to the study file
    combine = "grid"                               # or "zip"
    metrics = ["max_displacement_m", "energy_error_fraction"]

    [parameters]
    "initial_velocity.0.velocity" = [["0 m/s", "0 m/s", "-40 m/s"], ["0 m/s", "0 m/s", "-60 m/s"]]
    "mesh.element_size" = ["0.94 mm", "1.88 mm"]

``grid`` runs every combination, ``zip`` the i-th value of every parameter together.
Every variant is validated like a case file (a bad value fails that variant, with the
key named, and the others still run), run in ``OUT/runs/<id>/`` and summarised in
``OUT/results.csv`` (and ``OUT/report.html``, linking each run's page). A variant
whose ``summary.json`` exists with the same parameters and the provenance digest its
case would have now (case, material and mesh files, code: wovenimpact.provenance) is
not run again (the study resumes); one whose digest differs runs again, with a warning
saying what changed (``sweep --keep-older-code`` keeps a run whose case and files are
the same but whose code differs: after a change known not to touch the results, a long
study need not start over; results.csv then names each run's code). Variants with the same values are run once (a warning says so);
``metrics`` that no summary has are an error before anything runs. A variant whose
energy balance fails ``run.energy_tolerance`` is reported as failed (with its figures).
For impact runs results.csv always records the ``outcome`` (perforated,
stopped, undecided, no contact), which the ballistic fits require to be decided. Runs
go to a local process pool by default, or
to a Dask cluster when a scheduler address is given.

The local pool's workers are spawned (:func:`wovenimpact.jit.process_pool`), so a
script that calls :func:`run_study` must guard its top level with
``if __name__ == "__main__":`` (the workers import the main module). On a Dask
cluster, start the workers with ``NUMBA_NUM_THREADS`` equal to the threads each run
should use (one by default).
"""

from __future__ import annotations

import copy
import csv
import hashlib
import io
import itertools
import json
import traceback
import warnings
from concurrent.futures import as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Annotated, Any, Literal

from pydantic import BaseModel, Field, ValidationError

from wovenimpact.errors import InputError, InputWarning
from wovenimpact.jit import process_pool
from wovenimpact.provenance import code_version
from wovenimpact.io.atomic import atomic_write_text
from wovenimpact.io.report import write_study_report
from wovenimpact.spec.fields import (
    STRICT,
    apply_overrides,
    input_error,
    problems_from_validation,
    read_toml,
    set_dotted,
)


class StudyInfo(BaseModel):
    """``[study]``."""

    model_config = STRICT
    name: str = Field(min_length=1)
    case: str = Field(min_length=1)
    combine: Literal["grid", "zip"] = "grid"
    metrics: list[str] = ["energy_error_fraction", "max_displacement_m"]


class StudyFile(BaseModel):
    model_config = STRICT
    study: StudyInfo
    parameters: dict[str, Annotated[list[Any], Field(min_length=1)]] = Field(min_length=1)


@dataclass
class Variant:
    """One case of a study: its id, the parameter values and the case document."""

    id: str
    values: dict[str, Any]
    document: dict = field(repr=False)


def variant_id(values: dict) -> str:
    """A stable short id for a set of parameter values."""
    text = json.dumps(values, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:10]


def load_study(path: str | Path, overrides=()) -> tuple[StudyInfo, list[Variant], Path]:
    """Read a study file; returns its header, its variants and the base case's directory.
    ``overrides`` (``--set KEY=VALUE``) change the base case before the parameters do."""
    path = Path(path)
    doc = read_toml(path, "study file")
    try:
        spec = StudyFile.model_validate(doc)
    except ValidationError as err:
        raise input_error(problems_from_validation(err, StudyFile), str(path)) from None
    case_path = (path.parent / spec.study.case).resolve()
    base_doc = apply_overrides(read_toml(case_path, "case file named by study.case"), overrides)
    keys = list(spec.parameters)
    columns = [spec.parameters[k] for k in keys]
    if spec.study.combine == "zip":
        lengths = {len(c) for c in columns}
        if len(lengths) != 1:
            raise InputError(f"{path}: combine = 'zip' needs lists of equal length, got "
                             + ", ".join(f"{k}: {len(c)}" for k, c in zip(keys, columns)))
        rows = list(zip(*columns))
    else:
        rows = list(itertools.product(*columns))
    variants: dict[str, Variant] = {}
    for row in rows:
        values = dict(zip(keys, row))
        document = copy.deepcopy(base_doc)
        for k, v in values.items():
            set_dotted(document, k, v)
        variants.setdefault(variant_id(values), Variant(variant_id(values), values, document))
    if len(variants) < len(rows):
        warnings.warn(f"{path}: {len(rows) - len(variants)} of the {len(rows)} variants repeat "
                      "the values of another; each distinct variant runs once",
                      InputWarning, stacklevel=2)
    check_metrics(path, spec.study.metrics, list(variants.values()))
    return spec.study, list(variants.values()), case_path.parent


def check_metrics(path: Path, metrics: list[str], variants: list[Variant]) -> None:
    """An :class:`InputError` naming every metric that no variant's summary will have
    (results.summary.summary_keys of the variants that validate; all kinds of case if
    none does)."""
    from wovenimpact.results.summary import (
        COMMON_SUMMARY_KEYS,
        CONTAINMENT_SUMMARY_KEYS,
        IMPACT_SUMMARY_KEYS,
        summary_keys,
    )

    valid: dict[str, None] = {}
    for v in variants:
        spec = quiet_spec(v.document, v.id)
        if spec is not None:  # else that variant fails when it runs, with its own message
            valid.update(dict.fromkeys(summary_keys(spec)))
    if not valid:
        valid = dict.fromkeys(COMMON_SUMMARY_KEYS + IMPACT_SUMMARY_KEYS
                              + CONTAINMENT_SUMMARY_KEYS)
    bad = [m for m in metrics if m not in valid]
    if bad:
        raise InputError(f"{path}: study.metrics {bad}: no summary of this study has "
                         f"{'it' if len(bad) == 1 else 'them'}; valid: {sorted(valid)}")


def quiet_spec(document: dict, source: str):
    """The validated case of a variant, or None if it is invalid, without its input
    warnings: the run itself tells them (once per study, :func:`warn_once`)."""
    from wovenimpact.spec.case import case_from_dict

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)
        try:
            return case_from_dict(document, source=source)
        except InputError:
            return None


def parameters_text(values: dict) -> str:
    """A run's ``parameters.json``: the values (or case document) it was run with."""
    return json.dumps(values, indent=2, default=str) + "\n"


def start_or_resume(out: Path, values: dict) -> bool:
    """Prepare ``out`` for a run of ``values`` (written to its ``parameters.json``); True
    if the run may resume: an earlier run of the same values left a checkpoint there (it
    was interrupted: a crash, a killed job, a session that ended). A summary or error of
    an earlier run is removed first, so that nothing stale outlives this run."""
    from wovenimpact.io.checkpoint import latest_checkpoint

    params = out / "parameters.json"
    text = parameters_text(values)
    try:
        same = json.loads(params.read_text(encoding="utf-8")) == json.loads(text)
    except (OSError, ValueError):
        same = False
    resume = same and latest_checkpoint(out / "checkpoints") is not None
    out.mkdir(parents=True, exist_ok=True)
    (out / "summary.json").unlink(missing_ok=True)
    (out / "error.txt").unlink(missing_ok=True)
    atomic_write_text(params, text)
    return resume


def run_resuming(spec, base: str | Path, out: Path, resume: bool, threads: int = 1) -> dict:
    """``run_spec`` in ``out``, from its newest checkpoint if ``resume``; a checkpoint
    written for another case, file or code (``--restart`` refuses it) runs from the start."""
    from wovenimpact.runs import run_spec

    if resume:
        try:
            return run_spec(spec, base, out, threads=threads, restart=True)
        except InputError as err:
            if not str(err).startswith("--restart"):
                raise
    return run_spec(spec, base, out, threads=threads)


def run_variant(document: dict, base: str, out_dir: str, values: dict, threads: int = 1) -> dict:
    """Run one variant (in a worker process), resuming an interrupted run of the same
    values from its last checkpoint (:func:`start_or_resume`); never raises: failures
    are reported."""
    from wovenimpact.spec.case import case_from_dict

    out = Path(out_dir)
    resume = start_or_resume(out, values)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InputWarning)
        try:
            spec = case_from_dict(document, source=f"variant {out.name}")
            result = outcome_of(run_resuming(spec, base, out, resume, threads=threads))
        except Exception as err:  # one failing case is reported, the others finish
            message = f"{type(err).__name__}: {err}"
            atomic_write_text(out / "error.txt", message + "\n\n" + traceback.format_exc())
            result = {"status": "failed", "error": message}
    notes = [str(w.message).split(": ", 1)[-1] for w in caught
             if issubclass(w.category, InputWarning)]
    for w in caught:
        if not issubclass(w.category, InputWarning):
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if notes:  # told once per study by run_study, not once per variant and worker
        result["warnings"] = list(dict.fromkeys(notes))
    return result


def warn_once(results: dict[str, dict], total: int) -> None:
    """Each distinct input warning of the variants (``warnings`` of their results) as one
    :class:`~wovenimpact.errors.InputWarning` saying how many variants it concerns."""
    seen: dict[str, int] = {}
    for r in results.values():
        for note in r.get("warnings", ()):
            seen[note] = seen.get(note, 0) + 1
    for note, count in seen.items():
        warnings.warn(f"{count} of {total} variants: {note}", InputWarning, stacklevel=3)


def outcome_of(summary: dict) -> dict:
    """A finished run's result: ``status`` "done", or "failed" with the reason when its
    energy balance failed ``run.energy_tolerance`` (the figures are kept)."""
    if summary.get("energy_check") == "fail":
        return {**summary, "status": "failed",
                "error": f"energy balance failed: energy_error_fraction "
                         f"{summary['energy_error_fraction']:.3g} > run.energy_tolerance "
                         f"{summary['energy_tolerance']:.3g}"}
    return {"status": "done", **summary}


def finished(out: Path, values: dict, document: dict, base: str | Path,
             older_code: bool = False) -> tuple[dict | None, str]:
    """The result of a variant already run in ``out`` with these ``values`` whose summary's
    provenance digest is the one ``document`` (its paths relative to ``base``) would have
    now (runs.reusable_summary; the code's part ignored with ``older_code``), else None
    and why it cannot be reused ("" if it never finished)."""
    from wovenimpact.runs import reusable_summary

    try:
        same = json.loads((out / "parameters.json").read_text(encoding="utf-8")) == json.loads(
            json.dumps(values, default=str))
    except (OSError, ValueError):
        return None, ""
    if not same or not (out / "summary.json").exists():
        return None, ""
    spec = quiet_spec(document, str(out))
    if spec is None:
        return None, ""
    summary, why = reusable_summary(out, spec, base, older_code)
    return (outcome_of(summary), "") if summary is not None else (None, why)


def run_study(
    study_path: str | Path,
    out_dir: str | Path,
    *,
    scheduler: str | None = None,
    workers: int = 2,
    threads_per_run: int = 1,
    progress=None,
    overrides=(),
    keep_older_code: bool = False,
) -> list[dict]:
    """Run every variant of a study (resuming), write results.csv and plots; returns the rows.

    ``progress(done, total, variant_id, result)`` is called as each variant finishes
    (resumed ones count as done from the start). ``overrides`` (``--set KEY=VALUE``)
    change the base case of every variant; a variant is resumed only if it was run with
    the same ones. With ``keep_older_code`` a finished variant made by other code is kept
    if its case and files are the same (a warning counts them; results.csv then has a
    ``code`` column: each run's source digest)."""
    progress = progress or (lambda done, total, vid, result: None)
    info, variants, base = load_study(study_path, overrides)
    extra = {"--set": list(overrides)} if overrides else {}
    out = Path(out_dir)
    (out / "runs").mkdir(parents=True, exist_ok=True)
    results: dict[str, dict] = {}
    todo = []
    stale: dict[str, int] = {}
    for v in variants:
        done, why = finished(out / "runs" / v.id, {**v.values, **extra}, v.document, base,
                             keep_older_code)
        if done is not None:
            results[v.id] = {**done, "resumed": True}
        else:
            todo.append(v)
            if why:
                stale[why] = stale.get(why, 0) + 1
    for why, count in stale.items():
        warnings.warn(f"{count} of {len(variants)} variants run again: {why}", InputWarning,
                      stacklevel=2)
    current = code_version()["source_digest"]
    older = sum(bool(r.get("resumed")) and _source_digest(r) != current for r in results.values())
    if older:
        warnings.warn(f"{older} of {len(variants)} variants kept from runs made by other code "
                      "(--keep-older-code; results.csv's code column names each run's)",
                      InputWarning, stacklevel=2)
    if results:
        progress(len(results), len(variants), "", {"status": "finished earlier"})
    args = [(v.document, str(base), str(out / "runs" / v.id), {**v.values, **extra},
             threads_per_run)
            for v in todo]
    if todo and scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler needs dask.distributed: pip install 'dask[distributed]'") from None
        from distributed import as_completed as dask_completed

        with _connect(Client, scheduler) as client:
            futures = {client.submit(run_variant, *a, pure=False): v for a, v in zip(args, todo)}
            for fut in dask_completed(futures):
                results[futures[fut].id] = fut.result()
                progress(len(results), len(variants), futures[fut].id, results[futures[fut].id])
    elif todo:
        with process_pool(workers, threads_per_run) as pool:
            futures = {pool.submit(run_variant, *a): v for a, v in zip(args, todo)}
            for fut in as_completed(futures):
                results[futures[fut].id] = fut.result()
                progress(len(results), len(variants), futures[fut].id, results[futures[fut].id])
    warn_once(results, len(variants))
    rows = []
    impact = any("outcome" in r for r in results.values())
    for v in variants:
        r = results[v.id]
        row = {"id": v.id, **{k: _short(val) for k, val in v.values.items()},
               "status": r.get("status"), "error": r.get("error", "")}
        if impact:  # the outcome of an impact run, always recorded (the fits need it)
            row["outcome"] = r.get("outcome", "")
        if keep_older_code:
            row["code"] = _source_digest(r) or current
        for m in info.metrics:
            row[m] = r.get(m, "")
        rows.append(row)
    _write_csv(out / "results.csv", rows)
    atomic_write_text(out / "results.json", json.dumps(rows, indent=2, default=str) + "\n")
    from wovenimpact.studies.plots import study_plots

    study_plots(info, variants, rows, out)
    write_study_report(out, info.name, rows)  # OUT/report.html: variants linked, plots
    return rows


SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "ucx")
CONNECT_TIMEOUT = "10s"  # an unreachable scheduler is an error after this, not a hang


def check_scheduler(address: str) -> None:
    """``--scheduler``: ``scheme://host:port`` (or ``host:port``, TCP) with a port 1–65535,
    or an ``inproc://`` address; an InputError naming the address and what is valid
    otherwise."""
    valid = "valid: the address of a running Dask scheduler, e.g. tcp://host:8786"
    scheme, sep, rest = address.strip().rpartition("://")
    if scheme == "inproc" and rest:  # a scheduler in this process (tests, notebooks)
        return
    host, colon, port = rest.rpartition(":")
    if (sep and scheme not in SCHEDULER_SCHEMES) or not colon or not host or " " in rest:
        raise InputError(f"--scheduler {address!r}: not a scheduler address ({valid})")
    if not port.isdigit() or not 1 <= int(port) <= 65535:
        raise InputError(f"--scheduler {address!r}: port {port!r} is not 1 to 65535 ({valid})")


def _connect(client_class, address: str):
    """A Dask client of ``address``; an InputError if none answers within CONNECT_TIMEOUT."""
    check_scheduler(address)
    try:
        return client_class(address, timeout=CONNECT_TIMEOUT)
    except (OSError, TimeoutError, ValueError) as err:
        raise InputError(f"--scheduler {address!r}: no scheduler answers ({type(err).__name__}: "
                         f"{err}; valid: the address of a running Dask scheduler, e.g. "
                         "tcp://host:8786)") from None


def _source_digest(result: dict) -> str:
    """The source digest of the code that made a finished run ("" if it has none)."""
    prov = result.get("provenance")
    return prov.get("source_digest", "") if isinstance(prov, dict) else ""


def _short(value: Any) -> str:
    return value if isinstance(value, str) else json.dumps(value)


def _write_csv(path: Path, rows: list[dict]) -> None:
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=list(rows[0]))
    writer.writeheader()
    writer.writerows(rows)
    atomic_write_text(path, buf.getvalue())
