"""``wovenimpact design plies CASE.toml``: the fewest plies that stop the impactor."""

from __future__ import annotations

from pathlib import Path

import typer

from wovenimpact.cli.app import app, emit, err_console, fail
from wovenimpact.errors import InputError

design_app = typer.Typer(help="Design searches by actual runs.", no_args_is_help=True)
app.add_typer(design_app, name="design")


@design_app.command("plies")
def plies(
    case: Path = typer.Argument(..., help="A plate-impact case (a plate mesh and an impactor: "
                                "plies to stop it) or a containment case (a casing and a "
                                "blade: casing layers to contain the fragment)."),
    out: Path = typer.Option(None, "--out", help="Where the runs go (default: out/design_<case>)."),
    workers: int = typer.Option(2, "--workers", min=1, help="Runs in parallel: with 2 or more, two packs a round (N and 2N while doubling); with 1, one pack a round (2N only if N did not hold)."),
    start: int = typer.Option(None, "--start", min=1, help="First ply count to try (default: the case's)."),
    check: int = typer.Option(0, "--check", min=0, help="Also run this many packs just above the answer (a larger pack that perforates is warned of)."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
    overrides: list[str] = typer.Option(
        None, "--set", help="Change a case value: KEY=VALUE with a dotted key, e.g. "
        "--set 'impactor.velocity=200 m/s' (repeatable)."),
) -> None:
    """Search the number of plies (doubling, then bisection) and print the answer with
    the areal mass of the pack; on a containment case, the casing layers that contain the
    fragment, with the casing's mass."""
    from wovenimpact.io.outdir import prepare_output_dir, write_failure
    from wovenimpact.studies.design import design_plies

    out = out or Path("out") / f"design_{case.stem}"
    try:
        prepare_output_dir(out)
        result = design_plies(case, out, workers=workers,
                              start=start, overrides=overrides or (), check=check,
                              log=lambda m: err_console.print(f"[yellow]{m}[/]"))
    except InputError as err:
        fail(str(err))
    except OSError as err:
        fail(write_failure(err, f"the runs of {case}"))
    shown = dict(result)
    if not as_json:
        shown["runs"] = ", ".join(f"{k}: {v}" for k, v in result["runs"].items())
        if not shown["warning"]:
            del shown["warning"]
        if shown["reruns"]:
            shown["reruns"] = ", ".join(f"{k}: {v}" for k, v in result["reruns"].items())
        else:
            del shown["reruns"]
    what = ("layers to contain the fragment" if "layers_to_contain" in result
            else "plies to stop the impactor")
    emit(shown, as_json, f"{case.name}: {what}")
    if result["warning"] and not as_json:
        err_console.print(f"[bold yellow]warning:[/] {result['warning']}")


design_app.command("layers", help="Another name of `design plies`, for a containment case: "
                   "the fewest casing layers (mesh.casing.layers: fabric plies of a hybrid "
                   "casing, aluminium layers of an all-metal one) that contain the "
                   "fragment.")(plies)
