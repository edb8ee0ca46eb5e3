"""The explicit time loop: :func:`step` advances a State by one central-difference step."""

from wovenimpact.solver.explicit import Workspace, advance, step

__all__ = ["Workspace", "advance", "step"]
