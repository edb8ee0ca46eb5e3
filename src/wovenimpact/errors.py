"""Exceptions that carry a message meant for the user (the CLI prints them without a traceback)."""


class InputError(ValueError):
    """A case, material or data file (or CLI argument) is invalid.

    The message names the field, the value found and what would be valid.
    """


class InputWarning(UserWarning):
    """An input that works but is probably not what was meant (an output interval longer
    than the run, a quarter model without its symmetry constraints, more threads than
    cores). The message names the input and what was done about it; the CLI prints it
    as ``warning: …``.
    """


class MaterialPointError(RuntimeError):
    """A material point could not be updated (failed solve, inadmissible deformation).

    The message names the point index, the reason and the point's state.
    """


class SimulationError(RuntimeError):
    """A run cannot continue (NaN, inverted element, collapsed time step).

    The message names the element or node, the simulated time and the cause.
    """
