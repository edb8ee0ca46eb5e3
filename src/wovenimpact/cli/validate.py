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
    study: list[str] = typer.Option(None, "--study", help="Only these studies' sections (repeatable), into WORK/validation.md: no example cases, convergence runs or metal section."),
    workers: int = typer.Option(2, "--workers", min=1, help="Runs in parallel."),
    containment: bool = typer.Option(False, "--containment", help="Instead: the fan-blade "
                                     "containment ladders and mass table (thesis ch. 8; hours "
                                     "of runs), report docs/validation_containment.md."),
    overrides: list[str] = typer.Option(None, "--set", help="With --containment: change a "
                                        "value of both ladders' case, KEY=VALUE, e.g. --set "
                                        "'mesh.element_size=7 mm' (repeatable)."),
    runs: list[Path] = typer.Option(None, "--runs", help="With --containment: tabulate these "
                                    "finished containment runs (a run's folder or a folder of "
                                    "runs; repeatable) instead of running the ladders."),
    crossover: bool = typer.Option(False, "--crossover", help="Instead: the 3-D crossover "
                                   "cell's virtual tests on three meshes and its shear test "
                                   "(thesis ch. 5; minutes), report "
                                   "docs/validation_crossover.md."),
) -> None:
    """Run (or resume) the example cases and thesis studies; write the validation report."""
    from wovenimpact.io.outdir import check_output_file, prepare_output_dir, write_failure
    from wovenimpact.reports.validation import ON_REQUEST, ROOT, STUDIES, run_validation

    if crossover:
        from wovenimpact.reports.crossover_validation import crossover_page

        report = report or ROOT / "docs" / "validation_crossover.md"
        try:
            prepare_output_dir(work, "--work")
            check_output_file(report, "--report")
            path = crossover_page(work, report, log=lambda m: console.print(
                f"[dim]{time.strftime('%H:%M:%S')}[/] {m}"))
        except InputError as err:
            fail(str(err))
        except OSError as err:
            fail(write_failure(err, "the crossover cell's runs or page"))
        console.print(f"crossover validation page: {path}")
        return
    if containment:
        _containment(work, report or ROOT / "docs" / "validation_containment.md", workers,
                     tuple(overrides or ()), tuple(runs or ()))
        return
    if overrides or runs:
        fail(f"{'--set' if overrides else '--runs'} goes with --containment (the chapter-7 "
             "studies run their own cases)")
    if report is None:
        report = work / "validation.md" if study else ROOT / "docs" / "validation.md"
    try:
        unknown = [s for s in study or () if s not in STUDIES + ON_REQUEST]
        if unknown:
            raise InputError(f"--study {unknown[0]!r}: no such study (valid: one of "
                             f"{', '.join(STUDIES + ON_REQUEST)})")
        prepare_output_dir(work, "--work")
        check_output_file(report, "--report")
        path = run_validation(work, report,
                              studies=tuple(study) if study else STUDIES, workers=workers,
                              studies_only=bool(study),
                              log=lambda m: console.print(f"[dim]{time.strftime('%H:%M:%S')}[/] {m}"))
    except InputError as err:
        fail(str(err))
    except OSError as err:
        fail(write_failure(err, "the validation runs or report"))
    console.print(f"validation report: {path}")
    console.print(f"pages of every run and study: {work / 'report.html'}")


def _containment(work: Path, report: Path, workers: int, overrides=(), runs=()) -> None:
    """``validate --containment``: the containment section alone (its runs in
    WORK/containment, or the given ``runs``), written to ``report`` with its figures
    beside it."""
    from datetime import date

    from wovenimpact.io.atomic import atomic_write_text
    from wovenimpact.io.outdir import check_output_file, prepare_output_dir, write_failure
    from wovenimpact.reports.containment_validation import containment_section

    try:
        if not runs:
            prepare_output_dir(work, "--work")
        check_output_file(report, "--report")
        lines = containment_section(
            work, report.parent / "validation", workers=workers, overrides=overrides, runs=runs,
            log=lambda m: console.print(f"[dim]{time.strftime('%H:%M:%S')}[/] {m}"))
        command = " ".join(["wovenimpact validate --containment",
                            *(f"--set '{o}'" for o in overrides),
                            *(f"--runs {r}" for r in runs)])
        where = (f"runs in `{work / 'containment'}`" if not runs else
                 "from the runs named")
        atomic_write_text(report, "\n".join([
            "# Validation: fan-blade containment (thesis chapter 8)", "",
            f"Regenerated by `{command}` on {date.today().isoformat()}; {where}.", "",
            *lines]) + "\n")
    except InputError as err:
        fail(str(err))
    except OSError as err:
        fail(write_failure(err, "the containment runs or report"))
    console.print(f"containment report: {report}")
