"""Command-line interface: ``wovenimpact COMMAND``. One module per command."""

from wovenimpact.cli import (  # noqa: F401  (register commands)
    ballistics,
    bench,
    calibrate,
    convergence,
    crossover_cell,
    design,
    element_test,
    export_deck,
    run,
    sweep,
    validate,
)
from wovenimpact.cli.app import app


def main() -> None:
    """Entry point of the ``wovenimpact`` script."""
    app()
