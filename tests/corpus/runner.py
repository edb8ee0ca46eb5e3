"""Run the acceptance corpus (issue 12) through the CLI, in this process, and classify.

    python -m tests.corpus.runner [--dir out/corpus] [--only SUBSTRING] [--timeout S]

Each item of :mod:`tests.corpus.generate` is invoked with typer's ``CliRunner`` (in
process, so ~300 items take minutes) under a wall-clock alarm and an address-space
limit, and classified:

- ``clean``: what the label asks: exit code 2 with an ``error: …`` message (any item),
  or exit 0 with its ``warning: …`` (``warn`` items: the warning must say what
  ``Item.warns`` gives), or exit 0 (``ok`` items);
- ``traceback``: an exception escaped the CLI (or a traceback was printed);
- ``hang``: no answer within the item's timeout;
- ``nonsense``: a bad input accepted: exit 0 without error (or without the warning a
  ``warn`` item needs), or a failure other than a clean input error (exit 1 / 3: the
  bad input was not caught before the run; a sweep's exit 1 counts as clean when its
  failed variants name their InputError, as a study reports bad variants and runs the
  others);
- ``refused``: an ``ok`` control that did not run.

Writes ``DIR/results.csv`` and prints the counts.
"""

from __future__ import annotations

import argparse
import csv
import os
import resource
import signal
import sys
import time
import warnings
from pathlib import Path

from tests.corpus.generate import Item, write_corpus

CLASSES = ("clean", "traceback", "hang", "nonsense", "refused")
MEMORY_LIMIT = 6 * 2**30  # bytes of address space: a MemoryError, not a swapping machine


class Timeout(BaseException):
    """Raised by the alarm (a BaseException, so no ``except Exception`` swallows it)."""


def _alarm(signum, frame):
    _stop_children(join=False)  # else a process pool's shutdown waits for its workers
    raise Timeout()


def classify(item: Item, exit_code: int | None, output: str, exception) -> str:
    """The class of one result (see the module docstring)."""
    if isinstance(exception, Timeout):
        return "hang"
    if exception is not None and not isinstance(exception, SystemExit):
        return "traceback"
    if "Traceback (most recent call last)" in output:
        return "traceback"
    if item.expect == "ok":
        return "clean" if exit_code == 0 else "refused"
    if exit_code == 2 and ("error:" in output or "Error" in output or "Usage:" in output):
        return "clean"
    if exit_code == 0 and item.expect == "warn" and "warning:" in output \
            and item.warns in " ".join(output.split()):
        return "clean"  # the run went on, with the warning this item is about
    if exit_code == 1 and item.argv[0] == "sweep" and "InputError: " in output:
        return "clean"  # the study ran; its failed variants name their input error
    return "nonsense"


def _stop_children(join: bool = True) -> None:
    """End the process-pool workers an interrupted item left (sweep, design)."""
    import multiprocessing

    for child in multiprocessing.active_children():
        child.terminate()
        if join:
            child.join(5)


def run_item(item: Item, timeout: float | None = None) -> dict:
    """Invoke one item; returns its row (id, kind, expect, class, exit, seconds, message)."""
    from typer.testing import CliRunner

    from wovenimpact.cli import app

    runner = CliRunner()
    old = signal.signal(signal.SIGALRM, _alarm)
    start = time.perf_counter()
    # --timeout shortens the bad items' limit; the ok controls keep theirs (they compile)
    signal.setitimer(signal.ITIMER_REAL,
                     item.timeout if item.expect == "ok" or not timeout else timeout)
    exit_code, output, exception = None, "", None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("always")
            result = runner.invoke(app, item.argv, catch_exceptions=True)
        exit_code, output, exception = result.exit_code, result.output, result.exception
        if isinstance(exception, Timeout):
            pass
    except Timeout as err:
        exception = err
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
        _stop_children()
    seconds = time.perf_counter() - start
    cls = classify(item, exit_code, output, exception)
    lines = [ln for ln in output.splitlines() if ln.strip()]
    message = next((ln for ln in lines if "error" in ln.lower() or "warning" in ln.lower()),
                   lines[-1] if lines else "")
    if cls == "traceback" and exception is not None and not isinstance(exception, SystemExit):
        message = f"{type(exception).__name__}: {exception}"
    return {"id": item.id, "kind": item.kind, "expect": item.expect, "class": cls,
            "exit": exit_code, "seconds": round(seconds, 2), "message": message[:300]}


def run_corpus(root: Path, only: str = "", timeout: float | None = None, log=print) -> list[dict]:
    """Write the corpus under ``root`` and run it there; returns one row per item."""
    items = write_corpus(root)
    if only:
        items = [i for i in items if only in i.id]
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, hard))
    cwd = os.getcwd()
    os.chdir(root)
    rows = []
    try:
        for n, item in enumerate(items, 1):
            row = run_item(item, timeout)
            rows.append(row)
            log(f"[{n}/{len(items)}] {row['class']:9s} {row['seconds']:6.1f}s {item.id}: "
                f"{row['message'][:140]}")
    finally:
        os.chdir(cwd)
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
    with open(root / "results.csv", "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return rows


def counts(rows: list[dict]) -> dict[str, int]:
    return {c: sum(r["class"] == c for r in rows) for c in CLASSES}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--dir", default="out/corpus", help="where the corpus is written and run")
    parser.add_argument("--only", default="", help="only items whose id contains this")
    parser.add_argument("--timeout", type=float, default=None,
                        help="seconds per bad item (default: each item's own, 60-120 s)")
    args = parser.parse_args(argv)
    rows = run_corpus(Path(args.dir).resolve(), args.only, args.timeout)
    total = counts(rows)
    print(f"{len(rows)} items: " + ", ".join(f"{k} {v}" for k, v in total.items()))
    for r in rows:
        if r["class"] != "clean":
            print(f"  {r['class']}: {r['id']}: {r['message']}")
    return 0 if total["clean"] == len(rows) else 1


if __name__ == "__main__":
    sys.exit(main())
