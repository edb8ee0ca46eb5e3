"""``wovenimpact bench``: ns per element-cycle of the explicit step (elastic, metal and
fabric plates).

The second of ``make bench``'s three benchmarks (the first is the fabric kernel alone,
benchmarks/bench_fabric_kernel.py; the third the ply-on-ply contact,
benchmarks/bench_contact.py). It prints the machine line first.
"""

from __future__ import annotations

import json

import numba
import typer

from wovenimpact.cli.app import app, console, fail
from wovenimpact.errors import InputError


def _counts(text: str, flag: str, low: int, high: int) -> list[int]:
    """A comma-separated list of integers from ``low`` to ``high`` (an InputError else)."""
    out = []
    for word in text.split(","):
        try:
            n = int(word.strip())
        except ValueError:
            n = None
        if n is None or not low <= n <= high:
            raise InputError(f"{flag} {text!r}: {word.strip()!r} is not valid (valid: whole "
                             f"numbers {low} to {high:g}, comma-separated)")
        out.append(n)
    return out


@app.command("bench")
def bench(
    sizes: str = typer.Option("10000,100000,400000", help="Plate sizes (elements), comma-separated."),
    kinds: str = typer.Option("elastic,metal,fabric",
                             help="Plates to run: elastic, metal, fabric, fabric_reduced."),
    threads: str = typer.Option(None, help="Thread counts, comma-separated (default: 1 and 2)."),
    steps: int = typer.Option(20, min=1, help="Timed steps per case."),
    as_json: bool = typer.Option(False, "--json", help='Print {"cases": [...]} as one JSON object.'),
    save_release: bool = typer.Option(False, "--save-release", help="Store this run's figures "
                                      "in benchmarks/release_figures.json (at a release, on "
                                      "an idle machine): the next runs print their ratio to it."),
) -> None:
    """Time the explicit step on square plates (the machine first); prints ns per
    element-cycle and stage shares. ``make bench`` also times the fabric kernel alone and
    the ply-on-ply contact."""
    from wovenimpact.benchmark import KINDS, case_line, machine, machine_line, run_cases

    from wovenimpact.jit import capped_threads
    from wovenimpact.spec.case import MAX_ELEMENTS

    try:
        size_list = _counts(sizes, "--sizes", 1, MAX_ELEMENTS)
        thread_list = _counts(threads, "--threads", 1, 1 << 16) if threads else None
    except InputError as err:
        fail(str(err))
    bad = [k for k in kinds.split(",") if k not in KINDS]
    if bad:
        fail(f"--kinds: bench kind {bad[0]!r}; valid: {', '.join(KINDS)}")
    counts = (list(dict.fromkeys(capped_threads(t, "--threads") for t in thread_list))
              if thread_list else sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)}))
    if not as_json:
        console.print(machine_line(), highlight=False, soft_wrap=True)
    cases = run_cases(kinds.split(","), size_list, counts, steps,
                      report=None if as_json else
                      (lambda c: console.print(case_line(c), soft_wrap=True)))
    if as_json:
        typer.echo(json.dumps({"cases": cases, "machine": machine(),
                               "threading_layer": numba.threading_layer()}))
    else:
        console.print(f"threading layer: {numba.threading_layer()}", highlight=False)
    if save_release:
        from wovenimpact.benchmark import RELEASE_FIGURES, release_figures
        from wovenimpact.io.atomic import atomic_write_text

        atomic_write_text(RELEASE_FIGURES, json.dumps(release_figures(cases), indent=2) + "\n")
        if not as_json:
            console.print(f"release figures written to {RELEASE_FIGURES}", highlight=False)
