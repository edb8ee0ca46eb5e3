"""``wovenimpact validate``: rerun the chapter-7 cases and studies, rewrite docs/validation.md."""

from __future__ import annotations

import time
from pathlib import Path

import typer

from wovenimpact.cli.app import app, console, fail
from wovenimpact.errors import InputError


@app.command("validate")
def validate(
    work: Path = typer.Option(Path("out/validation"), "--work", help="Where the runs go (resumed)."),
    report: Path = typer.Option(None, "--report", help="Report path (default: docs/validation.md; with --study, WORK/validation.md, so that a partial report never replaces the full one)."),
    study: list[str] = typer.Option(None, "--study", help="Only these studies (repeatable)."),
    workers: int = typer.Option(2, "--workers", min=1, help="Runs in parallel."),
) -> None:
    """Run (or resume) the example cases and thesis studies; write the validation report."""
    from wovenimpact.io.outdir import check_output_file, prepare_output_dir, write_failure
    from wovenimpact.studies.validation import ROOT, STUDIES, run_validation

    if report is None:
        report = work / "validation.md" if study else ROOT / "docs" / "validation.md"
    try:
        unknown = [s for s in study or () if s not in STUDIES]
        if unknown:
            raise InputError(f"--study {unknown[0]!r}: no such study (valid: one of "
                             f"{', '.join(STUDIES)})")
        prepare_output_dir(work, "--work")
        check_output_file(report, "--report")
        path = run_validation(work, report,
                              studies=tuple(study) if study else STUDIES, workers=workers,
                              log=lambda m: console.print(f"[dim]{time.strftime('%H:%M:%S')}[/] {m}"))
    except InputError as err:
        fail(str(err))
    except OSError as err:
        fail(write_failure(err, "the validation runs or report"))
    console.print(f"validation report: {path}")
    console.print(f"pages of every run and study: {work / 'report.html'}")
