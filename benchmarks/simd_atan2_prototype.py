"""Prototype (issue 13): a vectorisable atan2 for the fibre frame's angle (docs/theory.md
§4.6, "SIMD element pass", item 5). Numba's ``math.atan2`` is a call into libm, which
stops LLVM's vectoriser (no SVML here); this is Cephes' ``atan`` — reduction to
|z| ≤ tan(π/8) and a rational P(z²)/Q(z²) — in plain arithmetic, inside a block loop of
the shape of ``simd_shell_prototype.py``. A measurement, not solver code.

    python benchmarks/simd_atan2_prototype.py

Prints its largest error against ``math.atan2`` in units in the last place over
200 000 angles in (0, π) (the fibre frame's θ: sin θ > 0), whether the loop
vectorised, and ns per value of each, one thread.
"""

import math
import re
import sys
from pathlib import Path

import numpy as np
from numba import njit, prange

from wovenimpact.jit import set_threads

sys.path.insert(0, str(Path(__file__).resolve().parent))
from simd_table_prototype import best  # noqa: E402

FAST = dict(boundscheck=False, error_model="numpy")
# Cephes atan.c (S. L. Moshier): atan(z) ≈ z + z³ P(z²)/Q(z²) for |z| ≤ tan(π/8)
P = (-8.750608600031904122785e-01, -1.615753718733365076637e1, -7.500855792314704667340e1,
     -1.228866684490136173410e2, -6.485021904942025371773e1)
Q = (2.485846490142306297962e1, 1.650270098316988542046e2, 4.328810604912902668951e2,
     4.853903996359136964868e2, 1.945506571482613964425e2)
TAN_3PI_8 = 2.41421356237309504880
MOREBITS = 6.123233995736765886130e-17  # the low part of π/2 in double-double


@njit(inline="always", **FAST)
def atan_nonnegative(x):
    """atan(x) for x ≥ 0: reduced to z = −1/x (x > tan 3π/8), (x − 1)/(x + 1) (x > 0.66),
    or x, then the rational approximation; every branch a select."""
    big = x > TAN_3PI_8
    mid = (x > 0.66) & (~big)
    y0 = 0.5 * math.pi if big else (0.25 * math.pi if mid else 0.0)
    z = -1.0 / x if big else ((x - 1.0) / (x + 1.0) if mid else x)
    extra = MOREBITS if big else (0.5 * MOREBITS if mid else 0.0)
    zz = z * z
    pz = (((P[0] * zz + P[1]) * zz + P[2]) * zz + P[3]) * zz + P[4]
    qz = ((((zz + Q[0]) * zz + Q[1]) * zz + Q[2]) * zz + Q[3]) * zz + Q[4]
    return y0 + (z * zz * pz / qz + z + extra)


@njit(inline="always", **FAST)
def atan2_upper(y, x):
    """atan2(y, x) for y > 0 (an angle in (0, π))."""
    ax = abs(x)
    a = atan_nonnegative(y / ax) if ax > 0.0 else 0.5 * math.pi
    return a if x >= 0.0 else math.pi - a


@njit(forceinline=True, **FAST)
def atan2_block(b, y, x, out):
    for lane in range(8):
        e = np.uint64(b * 8 + lane)
        out[e] = atan2_upper(y[e], x[e])


@njit(parallel=True, **FAST)
def atan2_blocks(y, x, out):
    """:func:`atan2_upper` on every value, in blocks of 8 (the length a multiple of 8)."""
    for b in prange(y.shape[0] // 8):
        atan2_block(b, y, x, out)


@njit(**FAST)
def atan2_libm(y, x, out):
    for e in range(y.shape[0]):
        out[e] = math.atan2(y[e], x[e])


def main() -> int:
    set_threads(1)
    n = 200_000
    rng = np.random.default_rng(1)
    theta = rng.uniform(1e-3, math.pi - 1e-3, n)
    r = rng.uniform(0.5, 2.0, n)
    y, x = r * np.sin(theta), r * np.cos(theta)
    ref, got = np.empty(n), np.empty(n)
    atan2_libm(y, x, ref)
    atan2_blocks(y, x, got)
    ulp = np.abs(got - ref) / np.spacing(np.abs(ref))
    asm = next(iter(atan2_blocks.inspect_asm().values()))
    packed = len(re.findall(r"pd\s+%zmm", asm))
    print(f"error against math.atan2: max {ulp.max():.2f} ulp, mean {ulp.mean():.3f} ulp; "
          f"{packed} packed-double instructions")
    t_ref = best(lambda: atan2_libm(y, x, ref))
    t_new = best(lambda: atan2_blocks(y, x, got))
    print(f"{n} values, 1 thread: math.atan2 {t_ref / n * 1e9:.1f} ns, blocks "
          f"{t_new / n * 1e9:.1f} ns per value")
    return 0 if ulp.max() <= 2.0 else 1


if __name__ == "__main__":
    sys.exit(main())
