"""``wovenimpact run CASE.toml --out DIR``: run a case file with a progress bar."""

from __future__ import annotations

import time
from pathlib import Path

import typer
from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

from wovenimpact.cli.app import app, console, emit_summary, err_console, fail
from wovenimpact.errors import InputError, MaterialPointError, SimulationError

LOG_EVERY_S = 60.0  # wall seconds between progress lines when stderr is not a terminal


def _bar(quiet: bool):
    """A rich progress bar: simulated time, steps per second and ETA (wall clock)."""
    progress = Progress(
        TextColumn("[bold]{task.description}"),
        BarColumn(),
        TextColumn("t = {task.fields[t_us]:.2f} / {task.fields[end_us]:.2f} µs"),
        TextColumn("{task.fields[rate]:,.0f} steps/s"),
        TextColumn("ETA {task.fields[eta]}"),
        TimeElapsedColumn(),
        console=err_console,
        disable=quiet,
        transient=False,
    )
    return progress


def start_line(name: str, state, end_time: float) -> str:
    """The line printed once stepping has begun: the model's size, its first step Δt₁
    and the steps end_time/Δt₁ that take to the end (a lower bound: the step falls as
    the mesh deforms)."""
    dt1 = state.dt_first if state.dt_first > 0 else state.dt
    steps = int(end_time / dt1) if dt1 > 0 else 0
    return (f"{name}: stepping {state.elem.shape[0]:,} elements, {state.x.shape[0]:,} "
            f"nodes; first step {dt1:.3g} s: at least {steps:,} steps to t = "
            f"{end_time * 1e6:.4g} µs")


@app.command("run")
def run(
    case: Path = typer.Argument(..., help="Case file (TOML)."),
    out: Path = typer.Option(..., "--out", help="Output directory."),
    restart: bool = typer.Option(False, "--restart", help="Resume from the last checkpoint in OUT."),
    threads: int = typer.Option(
        None, "--threads", min=1,
        help="Kernel threads (default: all cores; more than the cores is warned of and capped)."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object (summary) on stdout."),
    overrides: list[str] = typer.Option(
        None, "--set", help="Change a case value: KEY=VALUE with a dotted key, e.g. "
        "--set 'impactor.velocity=200 m/s' (repeatable)."),
) -> None:
    """Run CASE to its end time; write history.csv, summary.json, report.html, fields/,
    plots/, checkpoints/."""
    from wovenimpact.io.outdir import prepare_output_dir, write_failure
    from wovenimpact.runs import run_case

    try:
        prepare_output_dir(out)
    except InputError as err:
        fail(str(err))
    # on a terminal a live bar; in a log (a batch job, nohup) a plain line every
    # LOG_EVERY_S of wall time, which a bar would not give until the run ends
    lines = not as_json and not err_console.is_terminal
    bar = _bar(quiet=as_json or lines)
    task = bar.add_task(case.stem, total=1.0, t_us=0.0, end_us=0.0, rate=0.0, eta="?")
    start = {"wall": time.perf_counter(), "step": None, "logged": time.perf_counter()}

    def report(state, end_time):
        now = time.perf_counter()
        if start["step"] is None:  # the bar appears once the case has compiled
            start["step"], start["wall"] = state.step, now
            if not as_json:
                err_console.print(start_line(case.stem, state, end_time),
                                  highlight=False, soft_wrap=True)
            bar.start()
        wall = now - start["wall"]
        done = state.step - start["step"]
        rate = done / wall if wall > 0 else 0.0
        frac = min(state.t / end_time, 1.0)
        remaining = (max(end_time - state.t, 0.0) / state.dt / rate
                     if rate > 0 and state.dt > 0 else None)
        eta = "?" if remaining is None else time.strftime("%H:%M:%S", time.gmtime(remaining))
        bar.update(task, completed=frac, t_us=state.t * 1e6, end_us=end_time * 1e6, rate=rate,
                   eta=eta)
        if lines and now - start["logged"] >= LOG_EVERY_S:
            start["logged"] = now
            err_console.print(
                f"{time.strftime('%H:%M:%S')} {case.stem}: t = {state.t * 1e6:.2f} / "
                f"{end_time * 1e6:.2f} µs ({frac:.0%}), step {state.step}, Δt {state.dt:.3e} s, "
                f"{rate:,.1f} steps/s, ETA {eta}", highlight=False, soft_wrap=True)

    if not as_json:
        err_console.print(f"{case.stem}: building the model (a machine's first run also "
                          "compiles the kernels: a few minutes, then cached)",
                          highlight=False, soft_wrap=True)
    try:
        summary = run_case(case, out, restart=restart, threads=threads, progress=report,
                           overrides=overrides or ())
    except (InputError, MaterialPointError) as err:
        bar.stop()
        fail(str(err))
    except SimulationError as err:
        bar.stop()
        fail(f"the run stopped: {err}", code=3)
    except OSError as err:  # a full disk, the output directory removed mid-run
        bar.stop()
        fail(write_failure(err, f"the outputs of {case}"))
    bar.stop()
    emit_summary(summary, as_json, f"{case.name}: summary (also in {out / 'summary.json'})")
    if not as_json:
        console.print(f"report: {out / 'report.html'}")
    energy_verdict(summary)


def energy_verdict(summary: dict) -> None:
    """Exit with code 4, saying why, if the run's energy balance failed its tolerance
    (``energy_check`` of the summary, which keeps the figure)."""
    if summary.get("energy_check") == "fail":
        fail(f"the energy balance failed: energy_error_fraction = "
             f"{summary['energy_error_fraction']:.3g} exceeds run.energy_tolerance = "
             f"{summary['energy_tolerance']:.3g}; the results are not trustworthy (a too "
             "large time step or a diverging material?). The outputs are written.", code=4)
