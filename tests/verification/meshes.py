"""Small meshes and materials shared by the shell verification tests."""

from __future__ import annotations

import numpy as np

from wovenimpact.materials.metal import MetalParameters


def elastic(modulus=210e9, poisson=0.3, density=7850.0) -> MetalParameters:
    return MetalParameters(name="elastic", kind="elastic", density=density, modulus=modulus,
                           poisson=poisson)


def rect_grid(nx: int, ny: int, lx: float, ly: float):
    """Nodes (z = 0) and counter-clockwise quads of an nx × ny grid on [0, lx] × [0, ly]."""
    xs, ys = np.linspace(0.0, lx, nx + 1), np.linspace(0.0, ly, ny + 1)
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    nodes = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)

    def nid(i, j):
        return i * (ny + 1) + j

    quads = np.array([[nid(i, j), nid(i + 1, j), nid(i + 1, j + 1), nid(i, j + 1)]
                      for i in range(nx) for j in range(ny)])
    return nodes, quads
