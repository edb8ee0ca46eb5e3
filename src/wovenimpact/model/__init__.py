"""The static description of a simulation (:class:`Model`) and how to build one."""

from wovenimpact.model.model import BoundaryConditions, Model, Section, build_model

__all__ = ["BoundaryConditions", "Model", "Section", "build_model"]
