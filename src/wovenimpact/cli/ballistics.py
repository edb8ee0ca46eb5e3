"""``wovenimpact ballistics``: V50 and plies-to-stop from a sweep's results.csv (decided
runs only: an undecided or no-contact run is refused, naming the variant)."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import typer

from wovenimpact.cli.app import app, emit, fail
from wovenimpact.errors import InputError
from wovenimpact.spec.fields import read_text
from wovenimpact.units import to_si

ballistics_app = typer.Typer(help="Ballistic fits of sweep results.", no_args_is_help=True)
app.add_typer(ballistics_app, name="ballistics")


RESIDUAL = "residual_velocity_m_per_s"
EXIT = "fragment_exit_speed_m_per_s"  # a containment run's stand-in for the residual


def finished_rows(results: Path) -> list[dict]:
    """The rows of a sweep's results.csv whose run finished (``status`` done)."""
    text = read_text(results, "results file")
    try:
        return [r for r in csv.DictReader(io.StringIO(text, newline=""))
                if r.get("status") == "done"]
    except csv.Error as err:
        raise InputError(f"{results}: not a readable CSV file ({err})") from None


def _rows(results: Path) -> list[dict]:
    rows = finished_rows(results)
    if not rows or not ({RESIDUAL, EXIT} & set(rows[0])):
        raise InputError(f"{results}: no finished runs with {RESIDUAL} (or {EXIT} for a "
                         "containment study): list it in the study's metrics")
    return rows


def _column(rows, key: str, results: Path) -> list[str]:
    if key not in rows[0]:
        raise InputError(f"{results}: no column {key!r}; columns: {list(rows[0])}")
    return [r[key] for r in rows]


def rows_where(rows: list[dict], where, results: Path) -> list[dict]:
    """The rows that match every condition of ``where`` ("COLUMN=VALUE": the cell's text
    as results.csv holds it, spaces ignored, so '1mm' matches '1 mm')."""
    for cond in where:
        column, sep, value = cond.partition("=")
        if not sep:
            raise InputError(f"--where {cond!r}: give COLUMN=VALUE, e.g. "
                             "'contact.damping=0.3'")
        cells = _column(rows, column.strip(), results)
        kept = [r for r, c in zip(rows, cells) if c.replace(" ", "") == value.replace(" ", "")]
        if not kept:
            raise InputError(f"--where {cond!r}: no finished run has it; the column holds "
                             f"{sorted(set(cells))}")
        rows = kept
    return rows


WHERE_HELP = ("Keep the runs whose COLUMN has VALUE (repeatable), e.g. a study over meshes "
              "and velocities: --where 'mesh.element_size=0.5 mm'.")


@ballistics_app.command("v50")
def v50(
    results: Path = typer.Argument(..., help="results.csv of a velocity sweep."),
    key: str = typer.Option("impactor.velocity", help="Parameter column of the striking velocity."),
    where: list[str] = typer.Option([], "--where", help=WHERE_HELP),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Lambert–Jonas fit V_r = a (V_s^p − V50^p)^(1/p) of residual against striking velocity."""
    from wovenimpact.studies.ballistics import lambert_jonas_fit, require_decided

    try:
        rows = rows_where(_rows(results), where, results)
        if EXIT in rows[0] and RESIDUAL not in rows[0]:
            raise InputError(
                f"{results}: a containment study (its runs have {EXIT}, no impactor "
                "velocity): a V50 fits residual against striking velocity; for the casing "
                "layers that contain the fragment, `wovenimpact ballistics plies` fits the "
                "exit speed against mesh.casing.layers (thesis eq. 8.2)")
        vs = [to_si(json.loads(v) if v.startswith('"') else v, "velocity", key)
              for v in _column(rows, key, results)]
        require_decided(rows, key, str(results))
        vr = [float(r["residual_velocity_m_per_s"]) for r in rows]
        fit = lambert_jonas_fit(vs, vr)
    except InputError as err:
        fail(str(err))
    emit({"v50_m_per_s": fit.v_bl, "a": fit.a, "p": fit.p, "rms_m_per_s": fit.rms,
          "runs": len(vs)}, as_json, f"{results}: Lambert–Jonas")


@ballistics_app.command("plies")
def plies(
    results: Path = typer.Argument(..., help="results.csv of a sweep over mesh.plies "
                                   "(or over mesh.casing.layers of a containment case)."),
    key: str = typer.Option(None, help="Parameter column of the number of plies (default: "
                            "mesh.plies, or mesh.casing.layers for a containment study)."),
    as_json: bool = typer.Option(False, "--json", help="Print one JSON object."),
) -> None:
    """Quadratic regression of residual velocity against plies (thesis eq. 7.1 method); of
    a containment study, of the fragment's exit speed against the casing layers (eq. 8.2)."""
    from wovenimpact.studies.ballistics import (
        CONTAINMENT_DECIDED,
        DECIDED,
        quadratic_ply_regression,
        require_decided,
        require_settled,
    )

    try:
        rows = _rows(results)
        casing = RESIDUAL not in rows[0]
        key = key or ("mesh.casing.layers" if casing else "mesh.plies")
        n = [float(v) for v in _column(rows, key, results)]
        require_decided(rows, key, str(results), CONTAINMENT_DECIDED if casing else DECIDED)
        if casing:
            require_settled(rows, key, str(results))
        vr = [float(r[EXIT if casing else RESIDUAL]) for r in rows]
        through = [(a, b) for a, b in zip(n, vr) if b > 0]
        reg = quadratic_ply_regression(*zip(*through)) if len(through) >= 3 else None
        if reg is None:
            held = "contained the fragment" if casing else "stopped the impactor"
            raise InputError(f"{results}: the regression needs three perforated ply counts, got "
                             f"{len(through)} (the others {held})")
    except InputError as err:
        fail(str(err))
    c2, c1, c0 = reg.coefficients
    answer = "layers_to_contain" if casing else "plies_to_stop"
    emit({"c2": c2, "c1": c1, "c0": c0, "r2": reg.r2, answer: reg.plies_to_stop,
          "root": reg.root}, as_json, f"{results}: V_r(N) = c2 N² + c1 N + c0")
