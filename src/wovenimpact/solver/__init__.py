"""The explicit time loop: :func:`step` advances a State by one central-difference step."""

from wovenimpact.solver.explicit import Workspace, advance, energy_balance, step

__all__ = ["Workspace", "advance", "energy_balance", "step"]
