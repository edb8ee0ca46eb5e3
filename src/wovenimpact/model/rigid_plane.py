"""Rigid plates: planes with a prescribed motion that press or hold (docs/solid.md §6).

A :class:`RigidPlane` is a flat rigid wall of infinite extent: a point c⁰ on it, its unit
normal n (pointing to the side where the nodes it meets are), a prescribed velocity V
(m/s, scaled in time by the case's smooth-step amplitude like a prescribed nodal
velocity), the penalty law of its node–plane pairs (β, ζ, μ, as an impactor's) and the
nodes it meets. ``Model.rigid_planes`` holds them; ``State.planes`` their position,
velocity and the force on them (kernels.contact_plane: the rows ``PL_*``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from wovenimpact.errors import InputError


@dataclass(frozen=True, eq=False)
class RigidPlane:
    """A rigid plate (module docstring).

    Attributes:
        point: (3,) a point of the plane at t = 0 (m).
        normal: (3,) its normal toward the nodes it meets (normalised here).
        velocity: (3,) its prescribed velocity (m/s); zero: it holds.
        nodes: the node indices it meets (None: every node).
        beta: penalty scale β of k = β m / Δt² (0 < β ≤ 0.5).
        damping: ζ, the dashpot as a fraction of critical (0–2).
        friction: Coulomb coefficient μ ≥ 0.
        name: its name in the energy books and outputs.
    """

    point: tuple
    normal: tuple
    velocity: tuple = (0.0, 0.0, 0.0)
    nodes: np.ndarray | None = None
    beta: float = 0.3
    damping: float = 1.0
    friction: float = 0.0
    name: str = "plane"
    unit_normal: np.ndarray = field(init=False, repr=False)

    def __post_init__(self) -> None:
        n = np.asarray(self.normal, dtype=float).reshape(-1)
        length = float(np.linalg.norm(n)) if n.shape == (3,) else 0.0
        if not (length > 0.0 and math.isfinite(length)):
            raise InputError(f"rigid plane {self.name!r}: normal {list(self.normal)} is not "
                             "a non-zero 3-vector")
        for what, vec in (("point", self.point), ("velocity", self.velocity)):
            a = np.asarray(vec, dtype=float).reshape(-1)
            if a.shape != (3,) or not np.all(np.isfinite(a)):
                raise InputError(f"rigid plane {self.name!r}: {what} {list(vec)} is not a "
                                 "finite 3-vector")
        if not (math.isfinite(self.beta) and 0.0 < self.beta <= 0.5):
            raise InputError(f"rigid plane {self.name!r}: contact_stiffness = {self.beta!r}; "
                             "valid: 0 < β ≤ 0.5")
        if not (math.isfinite(self.damping) and 0.0 <= self.damping <= 2.0):
            raise InputError(f"rigid plane {self.name!r}: contact_damping = "
                             f"{self.damping!r}; valid: 0 ≤ ζ ≤ 2")
        if not (math.isfinite(self.friction) and self.friction >= 0.0):
            raise InputError(f"rigid plane {self.name!r}: friction = {self.friction!r}; "
                             "valid: μ ≥ 0")
        object.__setattr__(self, "unit_normal", n / length)

    def node_mask(self, n_nodes: int) -> np.ndarray:
        """(n_nodes,) int8: 1 for the nodes the plane meets."""
        mask = np.zeros(n_nodes, dtype=np.int8)
        if self.nodes is None:
            mask[:] = 1
        else:
            idx = np.asarray(self.nodes, dtype=np.int64).reshape(-1)
            if idx.size and (idx.min() < 0 or idx.max() >= n_nodes):
                raise InputError(f"rigid plane {self.name!r}: node {int(idx.max())} is not "
                                 f"in the mesh of {n_nodes} nodes")
            mask[idx] = 1
        return mask

    def digest_bytes(self, n_nodes: int) -> bytes:
        """What sets the plane's response, for Model.digest."""
        head = repr((self.name, tuple(np.asarray(self.point, float).tolist()),
                     tuple(self.unit_normal.tolist()),
                     tuple(np.asarray(self.velocity, float).tolist()), self.beta,
                     self.damping, self.friction)).encode()
        return head + self.node_mask(n_nodes).tobytes()
