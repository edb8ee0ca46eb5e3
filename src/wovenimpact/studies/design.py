"""Design search: the fewest plies that stop the impactor, by actual runs.

``design_plies`` takes a plate-impact case (``mesh.kind = "plate"`` with an
``[impactor]``), re-runs it with N plies (the impactor keeps its clearance above the
top ply) and searches N: first by doubling until a pack stops the impactor, then by
bisection between the largest pack that is perforated and the smallest that stops it.
On a containment case (``mesh.kind = "containment"``) N is ``mesh.casing.layers`` (fabric
plies of a hybrid casing, aluminium layers of an all-metal one) and the answer is the
fewest layers that contain the fragment, with the casing's mass (inner shell counted).
Each round runs its candidates in parallel (local processes): two packs with two workers or
more, one with one worker. Only decided runs count:
a pack whose run ends ``undecided`` (still in contact, or intact plies ahead of the
impactor, at the end time) or ``no contact`` is continued from its last checkpoint to
twice the end time (in ``plies_N_end2x``, saying so through ``log``; :func:`continue_from`);
if it is still not decided the search stops with advice to run longer.
"""

from __future__ import annotations

import copy
import json
import traceback
from collections.abc import Callable
from pathlib import Path

from wovenimpact.errors import InputError
from wovenimpact.jit import process_pool
from wovenimpact.kernels.shell_layout import C_AREAL_MASS
from wovenimpact.spec.fields import apply_overrides, read_toml
from wovenimpact.studies.ballistics import DECIDED
from wovenimpact.units import to_si

MAX_PLIES = 64
HELD = ("stopped", "contained")  # the pack held: the impactor or fragment did not pass
DECIDED_ANY = DECIDED + ("contained", "escaped")


def is_containment(doc: dict) -> bool:
    """Whether a case document is a containment case (its N is mesh.casing.layers)."""
    return doc.get("mesh", {}).get("kind") == "containment"


def search_plies(stops: Callable[[list[int]], dict[int, bool]], start: int = 1,
                 max_plies: int = MAX_PLIES, unit: str = "plies",
                 goal: str = "stops the impactor", batch_size: int = 2,
                 ) -> tuple[int, dict[int, bool]]:
    """Smallest N ≥ 1 with stops(N), assuming more plies never do worse.

    ``stops`` evaluates a batch of ply counts (in parallel) and returns N → stopped.
    With ``batch_size`` 2 a round runs two packs (N and 2N while doubling, the two
    thirds of the bracket while bisecting); with 1, one pack (N, then 2N only if N did
    not hold; the bracket's middle), so that a single worker never runs a pack — often
    the largest and slowest — that the other's outcome makes needless.
    Returns (N, every evaluation made). ``unit`` and ``goal`` word the error when no N
    up to ``max_plies`` holds ("layers", "contains the fragment" for a casing).
    """
    if batch_size not in (1, 2):
        raise InputError(f"batch_size = {batch_size!r}; valid: 1 or 2")
    seen: dict[int, bool] = {}
    lo, hi = 0, None  # lo: largest known perforated (0: none), hi: smallest known stopped
    n = max(1, start)
    while hi is None:
        batch = [k for k in (n, 2 * n)[:batch_size] if k <= max_plies and k not in seen]
        if not batch:
            raise InputError(f"no pack of up to {max_plies} {unit} {goal} (searched from "
                             f"{max(1, start)}: {sorted(seen) or 'none run'})")
        seen.update(stops(batch))
        for k in sorted(seen):
            if seen[k] and (hi is None or k < hi):
                hi = k
            if not seen[k]:
                lo = max(lo, k)
        n *= 2 * batch_size
    while hi - lo > 1:
        third = max(1, (hi - lo) // 3)
        batch = [] if batch_size == 1 else sorted(
            {k for k in (lo + third, hi - third) if lo < k < hi and k not in seen})
        if not batch:
            batch = [(lo + hi) // 2]
        seen.update(stops(batch))
        for k in batch:
            if seen[k]:
                hi = min(hi, k)
            else:
                lo = max(lo, k)
    return hi, seen


def _case_with_plies(doc: dict, n: int) -> dict:
    """The case document with n plies (the impactor keeps its clearance above the top
    ply), or, for a containment case, with n casing layers."""
    d = copy.deepcopy(doc)
    mesh = d.get("mesh", {})
    if is_containment(d):
        mesh["casing"]["layers"] = n
        return d
    if mesh.get("kind") != "plate" or "impactor" not in d:
        raise InputError("design plies needs a plate case (mesh.kind = 'plate') with an [impactor]")
    n0 = int(mesh.get("plies", 1))
    spacing = to_si(mesh.get("spacing", "0 m"), "length", "mesh.spacing", ge=0)
    if n > 1 and spacing <= 0:
        raise InputError("mesh.spacing: give the distance between plies to vary their number")
    pos = d["impactor"]["position"]
    z = to_si(pos[2], "length", "impactor.position[2]")
    pos[2] = f"{(z + (n - n0) * spacing) * 1e3!r} mm"
    mesh["plies"] = n
    if n > 1:
        mesh["spacing"] = f"{spacing * 1e3!r} mm"
    return d


def _run_one(doc: dict, base: str, out: str) -> str:
    """Outcome of one pack, resuming: a finished run of the same case document, files
    and code (provenance digest) is read back, an interrupted one restarts from its last
    checkpoint if that was written for the same (a search survives a crash), anything
    else runs from the start. Never raises: a pack whose run fails returns
    ``"failed: <reason>"`` (written to its ``error.txt``), so the other packs of the
    batch finish and stay reusable."""
    from wovenimpact.io.atomic import atomic_write_text
    from wovenimpact.spec.case import case_from_dict
    from wovenimpact.studies.sweep import finished, outcome_of, run_resuming, start_or_resume

    out_dir = Path(out)
    done, _ = finished(out_dir, doc, doc, base)  # the sweep's test: parameters and digest
    if done is not None:
        return _pack_outcome(done)
    resume = start_or_resume(out_dir, doc)
    try:
        spec = case_from_dict(doc, source=out)
        summary = run_resuming(spec, base, out_dir, resume)
        return _pack_outcome(outcome_of(summary))
    except Exception as err:  # one failing pack is reported, the others finish
        message = f"{type(err).__name__}: {err}"
        atomic_write_text(out_dir / "error.txt", message + "\n\n" + traceback.format_exc())
        return f"failed: {message}"


def _pack_outcome(result: dict) -> str:
    """The outcome of a pack's result, or ``"failed: <reason>"`` (an energy check)."""
    if result["status"] != "done":
        return f"failed: {result['error']}"
    return result["outcome"]


def _run_batch(docs: list[dict], base: str, dirs: list[str], workers: int) -> list[str]:
    """Outcomes of the case documents ``docs`` run (or resumed) in ``dirs``, in parallel."""
    with process_pool(min(workers, len(docs)), threads=1) as pool:
        return list(pool.map(_run_one, docs, [base] * len(docs), dirs))


def _quiet(message: str) -> None:
    """The default ``log`` of :func:`design_plies`: says nothing."""


def continue_from(src: Path, dst: Path, doc: dict) -> None:
    """Seed ``dst`` with the run in ``src`` so that running ``doc`` there (its case with a
    later ``run.end_time``) resumes from the checkpoint ``src`` ended with instead of
    starting again: its newest checkpoint, history.csv and fields/ are copied and
    ``doc`` is written as the run's parameters (:func:`sweep.start_or_resume` then
    resumes; a restart may change ``run.end_time``, theory §9). A ``dst`` already
    holding a run of ``doc`` (a search resumed after a crash) is left as it is; a
    ``src`` without a checkpoint seeds nothing, and the run starts from t = 0."""
    import shutil

    from wovenimpact.io.atomic import atomic_write_text
    from wovenimpact.io.checkpoint import latest_checkpoint
    from wovenimpact.studies.sweep import parameters_text

    params = parameters_text(doc)
    try:
        if json.loads((dst / "parameters.json").read_text(encoding="utf-8")) == json.loads(params):
            return
    except (OSError, ValueError):
        pass
    last = latest_checkpoint(src / "checkpoints")
    if last is None or not (src / "history.csv").exists():
        return
    if dst.exists():
        shutil.rmtree(dst)
    (dst / "checkpoints").mkdir(parents=True)
    shutil.copy2(last, dst / "checkpoints" / last.name)
    shutil.copy2(src / "history.csv", dst / "history.csv")
    if (src / "fields").is_dir():
        shutil.copytree(src / "fields", dst / "fields")
    atomic_write_text(dst / "parameters.json", params)


def _longer(doc: dict) -> dict:
    """The case document with twice its ``run.end_time``."""
    d = copy.deepcopy(doc)
    run = d.setdefault("run", {})
    if "end_time" not in run:
        raise InputError("design plies: the case has no run.end_time to lengthen")
    end = to_si(run["end_time"], "time", "run.end_time", gt=0)
    run["end_time"] = f"{2e6 * end!r} us"
    return d


def design_plies(case_path: str | Path, out_dir: str | Path, workers: int = 2,
                 start: int | None = None, overrides=(), check: int = 0,
                 log: Callable[[str], None] = _quiet) -> dict:
    """Fewest plies that stop the impactor of a plate-impact case (with the ``KEY=VALUE``
    ``overrides`` of ``--set``); runs in out_dir/plies_N. ``check`` > 0 also runs the
    ``check`` packs just above the answer that the search did not run, so that a
    non-monotonic outcome near the limit shows in the warning. A pack whose run is not
    decided is run again with twice the end time (out_dir/plies_N_end2x), and ``log``
    is told so; the result lists these under ``reruns``."""
    if isinstance(check, bool) or not isinstance(check, int) or check < 0:
        raise InputError(f"check = {check!r}; valid: a whole number of packs ≥ 0")
    path = Path(case_path)
    doc = apply_overrides(read_toml(path, "case file"), overrides)
    base = str(path.resolve().parent)
    out = Path(out_dir)
    outcomes: dict[int, str] = {}
    reruns: dict[str, str] = {}

    def run_batch(docs: list[dict], dirs: list[str]) -> list[str]:
        return _run_batch(docs, base, dirs, workers)

    def stops(batch: list[int]) -> dict[int, bool]:
        docs = [_case_with_plies(doc, n) for n in batch]
        results = dict(zip(batch, run_batch(docs, [str(out / f"plies_{n}") for n in batch])))
        refuse_failed(results, out, unit)
        again = [n for n in batch if results[n] not in DECIDED_ANY]
        if again:
            longer = [_longer(d) for n, d in zip(batch, docs) if n in again]
            for n, d in zip(again, longer):
                log(f"{n} {unit}: {results[n]} at run.end_time = {docs[batch.index(n)]['run']['end_time']}"
                    f"; continuing it to {d['run']['end_time']} (plies_{n}_end2x)")
                continue_from(out / f"plies_{n}", out / f"plies_{n}_end2x", d)
            for n, r in zip(again, run_batch(longer, [str(out / f"plies_{n}_end2x")
                                                      for n in again])):
                reruns[str(n)] = f"{results[n]} → {r} with twice the end time"
                results[n] = r
            refuse_failed({n: results[n] for n in again}, out, unit, "_end2x")
        for n in batch:
            outcomes[n] = results[n]
            if results[n] not in DECIDED_ANY:
                raise InputError(
                    f"{n} {unit}: {results[n]} even with twice run.end_time (the impactor is "
                    "still in contact or intact plies are ahead of it): lengthen run.end_time "
                    "in the case and search again")
        return {n: results[n] in HELD for n in batch}

    from wovenimpact.spec.case import case_from_dict

    # the case as given, validated before any run: a clear error for a bad case, and its
    # N with the defaults filled in
    given = case_from_dict(doc, source=str(path))
    if is_containment(doc):
        unit, goal = "layers", "contains the fragment"
        n0 = given.mesh.casing.layers
    else:
        unit, goal = "plies", "stops the impactor"
        n0 = getattr(given.mesh, "plies", 1)
    plies, seen = search_plies(stops, start=start or n0, unit=unit, goal=goal,
                               batch_size=min(workers, 2))
    extra = [k for k in range(plies + 1, plies + 1 + check) if k not in seen]
    if extra:
        seen.update(stops(extra))
    if unit == "layers":
        rerun = out / f"plies_{plies}_end2x"
        answer = json.loads(((rerun if str(plies) in reruns else out / f"plies_{plies}")
                             / "summary.json").read_text())
        return {
            "layers_to_contain": plies,
            "casing_mass_kg": answer["casing_mass_kg"],
            "casing_mass_per_area_kg_per_m2": answer["casing_mass_per_area_kg_per_m2"],
            "runs": {str(k): v for k, v in sorted(outcomes.items())},
            "reruns": reruns,
            "warning": monotonic_warning(plies, seen, "layers", "contain the fragment"),
        }
    from wovenimpact.setup.compile import compile_case

    spec = case_from_dict(_case_with_plies(doc, plies), source=str(path))
    model = compile_case(spec, Path(base)).model
    areal = float(model.sections[model.elem_section[0], C_AREAL_MASS])
    side = spec.mesh.side
    width = side if spec.mesh.width is None else spec.mesh.width
    return {
        "plies_to_stop": plies,
        "areal_mass_kg_per_m2": plies * areal,
        "pack_mass_kg": plies * areal * side * width,
        "runs": {str(k): v for k, v in sorted(outcomes.items())},
        "reruns": reruns,
        "warning": monotonic_warning(plies, seen),
    }


def refuse_failed(results: dict[int, str], out: Path, unit: str = "plies",
                  suffix: str = "") -> None:
    """An :class:`InputError` naming every pack whose run failed (``"failed: …"``) and
    where its error.txt is; the packs that ran are kept in ``out`` for the next search."""
    failed = [n for n, r in results.items() if r.startswith("failed")]

    def where(n: int) -> Path:
        """The pack's error.txt (a run that raised), else its summary.json (a run that
        finished but failed its energy check)."""
        pack = out / f"plies_{n}{suffix}"
        return pack / "error.txt" if (pack / "error.txt").exists() else pack / "summary.json"

    if failed:
        raise InputError(
            "; ".join(f"{n} {unit}: the run {results[n]} (see {where(n)})" for n in failed)
            + ". The packs that ran are kept: fix the case and search again to reuse them")


def monotonic_warning(plies: int, seen: dict[int, bool], unit: str = "plies",
                      verb: str = "stop the impactor") -> str:
    """"" if every larger pack that ran stopped the impactor (or contained the fragment),
    else a warning naming the packs that did not: the search assumes more plies never do
    worse, and near a ballistic limit the simulated outcome need not be monotonic."""
    worse = sorted(k for k, stopped in seen.items() if k > plies and not stopped)
    if not worse:
        return ""
    return (f"{', '.join(map(str, worse))} {unit} did not {verb} although "
            f"{plies} did: the outcome is not monotonic in the {unit} near this limit; "
            "take a margin and run the packs around the answer")
