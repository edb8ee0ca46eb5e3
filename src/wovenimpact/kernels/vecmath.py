"""Elementary functions written so that LLVM can vectorise a loop that calls them.

Numba's ``math.atan2`` is a call into libm, and a call stops LLVM's loop vectoriser (there
is no SVML on the machines we build for). The element stage in blocks
(``kernels.shell_blocks``, theory §4.6 "SIMD element pass") needs the fibre frame's
angle in its vectorised loop, and the scalar crossover kernel (``kernels.fabric``) uses the
same function, so that both give bitwise the same angle.

``atan2_upper`` is Cephes' ``atan`` (S. L. Moshier, atan.c): reduction to
|z| ≤ tan(π/8) and a rational P(z²)/Q(z²), every branch a select. Against libm's
``atan2`` over 200 000 angles in (0, π): at most 1.00 ulp, mean 0.20 ulp
(measured by a benchmark prototype since removed, see docs/notes/2026-11-element-stage-
performance.md; tests/unit/test_shell_blocks.py checks the bound).
"""

from __future__ import annotations

import math

from numba import types
from numba.extending import intrinsic

from wovenimpact.jit import inline_kernel

@intrinsic
def sqrt(typingctx, x):
    """√x as LLVM's ``llvm.sqrt.f64`` (IEEE: correctly rounded, NaN for x < 0), bitwise
    what ``math.sqrt`` returns. Numba's ``math.sqrt`` calls libm's ``sqrt``, which may set
    errno, and LLVM turns it into the intrinsic only where it can prove x ≥ 0; a call left
    in a loop stops the vectoriser (a stable step's √(μ/k) is one)."""
    if not isinstance(x, types.Float):
        return None

    def codegen(context, builder, signature, args):
        (v,) = args
        fn = builder.module.declare_intrinsic("llvm.sqrt", [v.type])
        return builder.call(fn, [v])

    return x(x), codegen


# Cephes atan.c: atan(z) ≈ z + z³ P(z²)/Q(z²) for |z| ≤ tan(π/8)
_P0, _P1, _P2, _P3, _P4 = (-8.750608600031904122785e-01, -1.615753718733365076637e1,
                           -7.500855792314704667340e1, -1.228866684490136173410e2,
                           -6.485021904942025371773e1)
_Q0, _Q1, _Q2, _Q3, _Q4 = (2.485846490142306297962e1, 1.650270098316988542046e2,
                           4.328810604912902668951e2, 4.853903996359136964868e2,
                           1.945506571482613964425e2)
TAN_3PI_8 = 2.41421356237309504880
MOREBITS = 6.123233995736765886130e-17  # the low part of π/2 in double-double


@inline_kernel
def atan_nonnegative(x):
    """atan(x) for x ≥ 0: reduced to z = −1/x (x > tan 3π/8), (x − 1)/(x + 1) (x > 0.66),
    or x, then the rational approximation; every branch a select."""
    big = x > TAN_3PI_8
    mid = (x > 0.66) & (not big)
    y0 = 0.5 * math.pi if big else (0.25 * math.pi if mid else 0.0)
    z = -1.0 / x if big else ((x - 1.0) / (x + 1.0) if mid else x)
    extra = MOREBITS if big else (0.5 * MOREBITS if mid else 0.0)
    zz = z * z
    pz = (((_P0 * zz + _P1) * zz + _P2) * zz + _P3) * zz + _P4
    qz = ((((zz + _Q0) * zz + _Q1) * zz + _Q2) * zz + _Q3) * zz + _Q4
    return y0 + (z * zz * pz / qz + z + extra)


@inline_kernel
def atan2_upper(y, x):
    """atan2(y, x) for y > 0: an angle in (0, π), within 1 ulp of libm's."""
    ax = abs(x)
    a = atan_nonnegative(y / ax) if ax > 0.0 else 0.5 * math.pi
    return a if x >= 0.0 else math.pi - a
