"""Exceptions that carry a message meant for the user (the CLI prints them without a traceback)."""


class InputError(ValueError):
    """A case, material or data file (or CLI argument) is invalid.

    The message names the field, the value found and what would be valid.
    """


class MaterialPointError(RuntimeError):
    """A material point could not be updated (failed solve, inadmissible deformation).

    The message names the point index, the reason and the point's state.
    """


class SimulationError(RuntimeError):
    """A run cannot continue (NaN, inverted element, collapsed time step).

    The message names the element or node, the simulated time and the cause.
    """
