"""``wovenimpact convergence``: the discretisation error of a mesh study's answers from its
results.csv — observed order, extrapolated value and grid convergence index
(studies/convergence.py, Celik et al. 2008)."""

from __future__ import annotations

import json
from pathlib import Path

import typer
from rich.table import Table

from wovenimpact.cli.app import app, cell, console, fail
from wovenimpact.errors import InputError


def _size(text: str, key: str) -> float:
    from wovenimpact.units import to_si

    value = json.loads(text) if text.startswith('"') else text
    return to_si(value, "length", key)


def study_triples(results: Path, metrics: list[str], key: str,
                  where: list[str] = ()) -> dict[str, list]:
    """Per metric, the triples of :func:`studies.convergence.mesh_convergence` over the
    finished rows of ``results`` that match every ``where`` ("column=value", the cell's
    text as results.csv holds it), one row per element size in column ``key``."""
    from wovenimpact.cli.ballistics import _column, finished_rows, rows_where
    from wovenimpact.studies.convergence import mesh_convergence

    rows = finished_rows(results)
    if not rows:
        raise InputError(f"{results}: no finished runs")
    rows = rows_where(rows, where, results)
    sizes = [_size(v, key) for v in _column(rows, key, results)]
    out = {}
    for metric in metrics:
        values = []
        for r, v in zip(rows, _column(rows, metric, results)):
            try:
                values.append(float(v))
            except ValueError:
                raise InputError(f"{results}: {metric} of variant {r.get('id', '?')} is "
                                 f"{v!r}, not a number") from None
        out[metric] = mesh_convergence(sizes, values)
    return out


@app.command("convergence")
def convergence(
    results: Path = typer.Argument(..., help="results.csv of a sweep over the element size."),
    metric: list[str] = typer.Option(..., "--metric", "-m", help="Column to assess "
                                     "(repeatable), e.g. casing_absorbed_energy_J."),
    key: str = typer.Option("mesh.element_size", help="Parameter column of the element size."),
    where: list[str] = typer.Option([], "--where", help="Keep the runs whose COLUMN has "
                                    "VALUE (repeatable), when the study varies more than "
                                    "the mesh: --where 'contact.damping=0.3'."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Observed order, extrapolated value and GCI of each answer on every three
    consecutive meshes (finest first); a triple that oscillates, diverges or converges at
    an order outside [0.5, 4] gets no error bar, and says so."""
    try:
        found = study_triples(results, metric, key, where)
    except InputError as err:
        fail(str(err))
    if as_json:
        typer.echo(json.dumps({m: [t.row() for t in ts] for m, ts in found.items()}))
        return
    for m, ts in found.items():
        table = Table(title=f"{results}: {m}")
        for col in ("element sizes (mm)", "values", "verdict", "order p",
                    "extrapolated", "GCI (fine)"):
            table.add_column(col, justify="right")
        for t in ts:
            table.add_row(", ".join(f"{h * 1e3:g}" for h in t.sizes), cell(list(t.values)),
                          t.verdict, cell(t.order) if t.order is not None else "—",
                          cell(t.extrapolated) if t.extrapolated is not None else "—",
                          f"{100 * t.gci_fine:.3g} %" if t.gci_fine is not None else "—")
        console.print(table)
