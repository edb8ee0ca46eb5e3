"""Regenerate compression_synthetic.csv: eq. (5.8) with the thesis's a, b and 1 % noise.

F = b d / (a − d), a = 0.12389 mm, b = 0.98432 N (thesis §5.3.2, Table 7-2); 40 points
with d evenly spaced from 0.0225 a to 0.9 a; F multiplied by (1 + 0.01 ε), ε ~ N(0, 1)
from numpy's default_rng(5_8). Columns in the thesis's units: d in mm, F in mN.

    python examples/calibration/make_compression_synthetic.py
"""

from pathlib import Path

import numpy as np

A_MM, B_MN = 0.12389, 984.32
N_POINTS, NOISE, SEED = 40, 0.01, 5_8


def main() -> None:
    rng = np.random.default_rng(SEED)
    d = np.linspace(0.9 * A_MM / N_POINTS, 0.9 * A_MM, N_POINTS)
    F = B_MN * d / (A_MM - d) * (1.0 + NOISE * rng.standard_normal(N_POINTS))
    out = Path(__file__).with_name("compression_synthetic.csv")
    lines = ["d_mm,F_mN"] + [f"{x:.6f},{y:.4f}" for x, y in zip(d, F)]
    out.write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
