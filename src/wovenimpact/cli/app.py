"""The typer application shared by the command modules, and output helpers."""

from __future__ import annotations

import json
import math
import warnings
from collections.abc import Mapping

import typer
from rich.console import Console
from rich.markup import escape
from rich.table import Table

app = typer.Typer(
    name="wovenimpact",
    help="Explicit dynamics of impacts on dry woven fabric and metal.",
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
)
calibrate_app = typer.Typer(help="Calibrate model parameters from measurements.", no_args_is_help=True)
app.add_typer(calibrate_app, name="calibrate")

console = Console()
err_console = Console(stderr=True)
_python_showwarning = warnings.showwarning


def _show_warning(message, category, filename, lineno, file=None, line=None):
    """Input warnings as ``warning: …`` lines on stderr (no source line); others as usual."""
    from wovenimpact.errors import InputWarning

    if issubclass(category, InputWarning):
        err_console.print(f"[bold yellow]warning:[/] {escape(str(message))}", soft_wrap=True)
    else:
        _python_showwarning(message, category, filename, lineno, file, line)


def _print_version(value: bool) -> None:
    if value:
        from wovenimpact import __version__

        typer.echo(f"wovenimpact {__version__}")
        raise typer.Exit()


@app.callback()
def _main(
    version: bool = typer.Option(False, "--version", callback=_print_version, is_eager=True,
                                 help="Print the version and exit."),
) -> None:
    """Explicit dynamics of impacts on dry woven fabric and metal."""
    from wovenimpact.jit import configure_threading

    warnings.showwarning = _show_warning
    configure_threading()  # the library itself sets nothing process-wide (issue 12)


def _jsonable(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None
    if hasattr(v, "item"):
        return v.item()
    return v


def cell(v) -> str:
    """A value as a table cell: numbers to 6 significant digits (NumPy scalars too, inside
    lists and mappings), markup escaped — rich reads "[np.float64(…)]" as a tag and drops it."""
    def text(x) -> str:
        if isinstance(x, (bool, str)) or x is None:
            return str(x)
        if hasattr(x, "item") and getattr(x, "ndim", 0) == 0:
            x = x.item()
        if isinstance(x, float):
            return f"{x:.6g}"
        if isinstance(x, Mapping):
            return "{" + ", ".join(f"{k}: {text(y)}" for k, y in x.items()) + "}"
        if isinstance(x, (list, tuple)) or hasattr(x, "tolist"):
            return "[" + ", ".join(text(y) for y in (x.tolist() if hasattr(x, "tolist") else x)) + "]"
        return str(x)

    return escape(text(v))


def emit(result: Mapping, as_json: bool, title: str) -> None:
    """Print ``result`` as one JSON object on stdout, or as a table for a person."""
    if as_json:
        typer.echo(json.dumps({k: _jsonable(v) for k, v in result.items()}))
        return
    table = Table(title=title)
    table.add_column("quantity")
    table.add_column("value", justify="right")
    for k, v in result.items():
        table.add_row(escape(str(k)), cell(v))
    console.print(table)


def emit_summary(summary: Mapping, as_json: bool, title: str) -> None:
    """A run's summary: one JSON object as :func:`emit`, or for a person the grouping of
    its report.html (:mod:`wovenimpact.io.summary_keys`): a section per group, each row
    its label, its value in the unit shown beside it (mm, m/s, J, %, …) and its
    summary.json key; the provenance digests are left to summary.json and report.html."""
    if as_json:
        emit(summary, True, title)
        return
    from wovenimpact.io.summary_keys import grouped

    table = Table(title=title)
    table.add_column("quantity")
    table.add_column("value", justify="right")
    table.add_column("unit")
    table.add_column("summary.json key", style="dim", overflow="fold")  # whole, not cut
    for i, (_, heading, rows) in enumerate(grouped(summary)):
        if i:
            table.add_section()
        table.add_row(f"[bold]{escape(heading)}[/]", "", "", "")
        for r in rows:
            table.add_row(escape(r.label), escape(r.value), escape(r.unit), escape(r.key))
    console.print(table)


def fail(message: str, code: int = 2) -> None:
    """Print an input error for a person and exit with ``code``."""
    err_console.print(f"[bold red]error:[/] {escape(message)}", soft_wrap=True)
    raise typer.Exit(code)
