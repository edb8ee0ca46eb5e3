"""The one place where Numba compilation flags are chosen.

Every ``@njit`` kernel in :mod:`wovenimpact.kernels` is decorated with
:func:`kernel` (per-entity functions, serial) or :func:`loop_kernel` (loops over
entities, ``prange``-parallel). Flags:

- ``cache=True``: compiled code is cached next to the sources, so only the first
  run after an install pays the compilation time.
- ``fastmath=False``: keeps NaN/inf checks meaningful and results bitwise
  reproducible.
- ``error_model="numpy"``: division by zero gives inf/NaN (detected by the
  caller) instead of raising inside a parallel loop.

Threading: Numba's OpenMP layer busy-waits, which collapses throughput on a
shared 2-core machine, so unless the user chose a layer with the environment
variable ``NUMBA_THREADING_LAYER`` we use ``workqueue``. The thread count is the
user's (``NUMBA_NUM_THREADS`` or :func:`set_threads`). ``WOVENIMPACT_SERIAL=1``
compiles loop kernels without ``parallel`` (debugging, profiling).
"""

from __future__ import annotations

import os

import numba

if "NUMBA_THREADING_LAYER" not in os.environ:
    numba.config.THREADING_LAYER = "workqueue"

JIT_FLAGS = dict(cache=True, fastmath=False, error_model="numpy", nogil=True)
PARALLEL = os.environ.get("WOVENIMPACT_SERIAL", "0") not in ("1", "true", "yes")


def kernel(fn):
    """Compile a per-entity function (serial, inlinable into loop kernels)."""
    return numba.njit(**JIT_FLAGS)(fn)


def loop_kernel(fn):
    """Compile a loop over entities; ``prange`` loops run on threads."""
    return numba.njit(parallel=PARALLEL, **JIT_FLAGS)(fn)


def set_threads(n: int) -> None:
    """Use ``n`` threads in parallel loop kernels (1 ≤ n ≤ NUMBA_NUM_THREADS)."""
    top = numba.config.NUMBA_NUM_THREADS
    if not 1 <= n <= top:
        raise ValueError(f"threads = {n} is not valid: choose 1 to {top} on this machine")
    numba.set_num_threads(n)


def inline_kernel(fn):
    """A per-entity function inlined into its callers at Numba IR level."""
    return numba.njit(inline="always", **JIT_FLAGS)(fn)
