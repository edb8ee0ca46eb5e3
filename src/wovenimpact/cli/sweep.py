"""``wovenimpact sweep STUDY.toml``: run a parameter study locally or on a Dask cluster."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeElapsedColumn
from rich.table import Table

from wovenimpact.cli.app import app, cell, console, err_console, fail
from wovenimpact.errors import InputError


@app.command("sweep")
def sweep(
    study: Path = typer.Argument(..., help="Study file (TOML)."),
    out: Path = typer.Option(None, "--out", help="Output directory (default: out/<study name>)."),
    scheduler: str = typer.Option(None, "--scheduler", help="Dask scheduler address (tcp://host:8786)."),
    workers: int = typer.Option(2, "--workers", min=1, help="Local worker processes."),
    as_json: bool = typer.Option(False, "--json", help="Print the results as one JSON object."),
    overrides: list[str] = typer.Option(
        None, "--set", help="Change a value of the study's case for every variant: KEY=VALUE "
        "with a dotted key, e.g. --set 'run.end_time=20 us' (repeatable)."),
    keep_older_code: bool = typer.Option(
        False, "--keep-older-code", help="Keep finished variants made by other code when their "
        "case and files are unchanged (results.csv's code column names each run's code)."),
) -> None:
    """Run every variant of STUDY (finished ones are kept), write results.csv, plots/ and
    report.html (linking each variant's page)."""
    from wovenimpact.io.outdir import prepare_output_dir, write_failure
    import warnings

    from wovenimpact.studies.sweep import check_scheduler, load_study, run_study

    out_dir = out or Path("out") / study.stem
    try:
        if scheduler is not None:
            check_scheduler(scheduler)
        with warnings.catch_warnings():  # run_study reads it again and warns then
            warnings.simplefilter("ignore")
            load_study(study, overrides or ())  # a bad study creates no output directory
        prepare_output_dir(out_dir)
    except InputError as err:
        fail(str(err))
    bar = Progress(TextColumn("[bold]{task.description}"), BarColumn(), MofNCompleteColumn(),
                   TextColumn("{task.fields[last]}"), TimeElapsedColumn(),
                   console=err_console, disable=as_json)
    task = bar.add_task(study.stem, total=None, last="")

    def report(done, total, vid, result):
        state = result.get("status", "?")
        bar.update(task, completed=done, total=total, last=f"last: {vid} {state}")

    try:
        with bar:
            rows = run_study(study, out_dir, scheduler=scheduler, workers=workers,
                             progress=report, overrides=overrides or (),
                             keep_older_code=keep_older_code)
    except InputError as err:
        fail(str(err))
    except OSError as err:
        fail(write_failure(err, f"the results of {study}"))
    failed = [r for r in rows if r["status"] != "done"]
    if as_json:
        typer.echo(json.dumps({"results": rows, "failed": len(failed), "out": str(out_dir)}))
    else:
        table = Table(title=f"{study.name}: {len(rows)} variants ({len(failed)} failed) → {out_dir}")
        for col in rows[0]:
            table.add_column(col)
        for r in rows:
            table.add_row(*(cell(v) for v in r.values()))
        console.print(table)
        console.print(f"report: {out_dir / 'report.html'}")
    if failed:
        raise typer.Exit(1)
