"""``wovenimpact export-deck CASE --out MESH.k``: a case's compiled shell mesh as an LS-DYNA
keyword deck (model/lsdyna.write_deck; docs/inputs.md, "LS-DYNA decks"), which a case reads
back with ``[mesh] kind = "lsdyna"``."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from wovenimpact.cli.app import app, console, fail
from wovenimpact.io.outdir import write_failure
from wovenimpact.errors import InputError


@app.command("export-deck")
def export_deck(
    case: Annotated[Path, typer.Argument(help="Case file (TOML) whose mesh to write.")],
    out: Annotated[Path, typer.Option("--out", help="The deck to write (.k).")] = Path("mesh.k"),
    overrides: list[str] = typer.Option(
        None, "--set", help="Change a case value first: KEY=VALUE with a dotted key, e.g. "
        "--set 'mesh.element_size=7 mm' (repeatable)."),
) -> None:
    """Write the case's shell mesh as it is compiled (a containment case's blade spun up)
    as an LS-DYNA deck: *NODE (metres), *ELEMENT_SHELL, a *PART per contact surface and
    section, a *SECTION_SHELL per section with its thickness, every element and node set as
    *SET_SHELL_LIST_TITLE / *SET_NODE_LIST_TITLE. Hexahedra, materials, boundary
    conditions and contact are not written: the case that reads the deck gives them."""
    from wovenimpact.model.lsdyna import write_deck
    from wovenimpact.setup.compile import compile_case
    from wovenimpact.spec.case import load_case

    try:
        spec, base = load_case(case, overrides or ())
        model = compile_case(spec, base).model
    except InputError as err:
        fail(str(err))
    if not model.n_elems:
        fail(f"{case}: the case has no shell elements to write (a deck holds shells only)")
    try:
        path = write_deck(out, model, title=spec.case.name)
    except OSError as err:
        fail(write_failure(err, str(out)))
    console.print(f"{path}: {model.n_nodes:,} nodes, {model.n_elems:,} shells, "
                  f"{len(model.section_names)} sections, {len(model.elem_sets)} element sets, "
                  f"{len(model.node_sets)} node sets", highlight=False)
