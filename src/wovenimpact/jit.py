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

Threading: the default layer is TBB (the ``tbb`` wheel, a dependency on x86-64
Linux and Windows), then ``workqueue`` if TBB does not load. A step launches two
parallel kernels, and what a launch costs and what idle workers do decided it
(2 cores, measured; fabric plate, ns per element-cycle, 2 threads, idle / with
the other core running a busy loop):

- ``workqueue``: ~125 µs per launch even on 1 thread (8 % of a 10k-element step);
  10k 260 / 474, 100k 254 / 460; 1 thread 10k 488.
- ``tbb``: ~1–2 µs per launch, workers sleep soon when idle; 10k 236 / 450, 100k
  249 / 462; 1 thread 10k 454.
- ``omp`` as shipped: ~1–2 µs per launch, but idle workers spin for a while before
  sleeping, which fights whatever else runs on a shared 2-core machine: 10k 229 /
  790, 100k 251 / 508.
- ``omp`` with ``OMP_WAIT_POLICY=passive``: 10k 255 / 456, 100k 251 / 464. As good
  as TBB, but GNU OpenMP is not fork-safe: a process pool forked after a parallel
  kernel ran (``wovenimpact sweep``) aborts. So it is not the default; with
  ``NUMBA_THREADING_LAYER=omp`` the wait policy defaults to passive here.

The ``tbb`` wheel puts ``libtbb`` in the environment's ``lib/``, where a venv's
loader does not look; it is loaded from there before Numba asks for it. Whatever
the user set wins: a layer in ``NUMBA_THREADING_LAYER``, a wait policy in
``OMP_WAIT_POLICY``, ``GOMP_SPINCOUNT`` or ``KMP_BLOCKTIME``. The thread count is the
user's (``NUMBA_NUM_THREADS`` or :func:`set_threads`). ``WOVENIMPACT_SERIAL=1``
compiles loop kernels without ``parallel`` (debugging, profiling).

Importing wovenimpact changes no process-wide setting (issue 12): the choices above
are made by :func:`configure_threading`, which the CLI calls when it starts (and each
process-pool worker); a program that uses the library and wants them calls it too,
before the first kernel runs.

Cache: compiled kernels go to ``~/.cache/wovenimpact/numba/<digest of the kernel
sources>`` (``NUMBA_CACHE_DIR`` overrides), so editing any kernel invalidates them all.
Numba reads its cache directory when a function is decorated, so it is set only while
wovenimpact's kernels are decorated and put back at once (:func:`_cache_dir`).
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import hashlib
import multiprocessing
import os
import sys
import threading
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numba

PACKAGE = Path(__file__).resolve().parent  # the package's folder


def _preload_tbb() -> None:
    """Load the ``tbb`` wheel's libtbb from <env>/lib so Numba's TBB layer finds it."""
    for prefix in dict.fromkeys((sys.prefix, sys.base_prefix)):
        for name in ("libtbb.so.12", "libtbb.12.dylib"):
            path = os.path.join(prefix, "lib", name)
            if os.path.exists(path):
                try:
                    ctypes.CDLL(path, mode=ctypes.RTLD_GLOBAL)
                except OSError:
                    continue
                return


def configure_threading() -> None:
    """The threading layer and OpenMP wait policy of the module docstring, for this
    process (and the processes it starts): TBB, else workqueue, else OpenMP, with
    passive OpenMP waiting; what the user set in the environment wins. Call it before
    the first parallel kernel runs (the CLI does, when it starts)."""
    if "NUMBA_THREADING_LAYER" not in os.environ:
        _preload_tbb()
        numba.config.THREADING_LAYER_PRIORITY = ["tbb", "workqueue", "omp"]
        numba.config.THREADING_LAYER = "default"  # the first of the priority list that loads
    if not any(k in os.environ for k in ("OMP_WAIT_POLICY", "GOMP_SPINCOUNT", "KMP_BLOCKTIME")):
        os.environ["OMP_WAIT_POLICY"] = "passive"  # idle OpenMP workers sleep at once
        os.environ["KMP_BLOCKTIME"] = "0"  # the same for Intel's runtime

def _kernel_source_digest() -> str:
    """SHA-256 (16 hex digits) of every kernel module's source.

    Numba's on-disk cache is keyed on each function's own file: a kernel that inlines a
    function from another module (shell_force → fabric_point) keeps running the old
    callee after that module changes. Keying the cache directory on all kernel sources
    makes any kernel edit recompile everything once.
    """
    h = hashlib.sha256()
    for f in sorted((Path(__file__).parent / "kernels").glob("*.py")):
        h.update(f.name.encode() + f.read_bytes())
    h.update(Path(__file__).read_bytes())
    return h.hexdigest()[:16]


@functools.lru_cache(maxsize=1)
def source_digest() -> str:
    """SHA-256 (16 hex digits) of every ``.py`` file of the package, by relative path: the
    code's version in a run's provenance (:mod:`wovenimpact.provenance`) and in the key of
    a cached crossover table (``materials.fabric_table``)."""
    h = hashlib.sha256()
    for f in sorted(PACKAGE.rglob("*.py")):
        h.update(f.relative_to(PACKAGE).as_posix().encode() + b"\0" + f.read_bytes())
    return h.hexdigest()[:16]


def cache_root() -> Path:
    """wovenimpact's cache folder: ``$XDG_CACHE_HOME/wovenimpact`` (``~/.cache`` when
    unset). Compiled kernels go to its ``numba`` folder, crossover tables to ``tables``
    (``materials.fabric_table``)."""
    return Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "wovenimpact"


PARALLEL = os.environ.get("WOVENIMPACT_SERIAL", "0") not in ("1", "true", "yes")
# Numba's cache key ignores the ``parallel`` flag: serial builds get their own directory,
# or WOVENIMPACT_SERIAL=1 would load the parallel object code cached before it
_CACHE_DIR = None if "NUMBA_CACHE_DIR" in os.environ else str(
    cache_root() / "numba" / (_kernel_source_digest() + ("" if PARALLEL else "-serial"))
)


@contextlib.contextmanager
def _cache_dir():
    """Numba's cache directory set to wovenimpact's while a kernel is decorated (Numba
    reads it then, to place that kernel's cache), and put back afterwards."""
    if _CACHE_DIR is None:
        yield
        return
    old = numba.config.CACHE_DIR
    numba.config.CACHE_DIR = _CACHE_DIR
    try:
        yield
    finally:
        numba.config.CACHE_DIR = old


JIT_FLAGS = dict(cache=True, fastmath=False, error_model="numpy", nogil=True)


# Per-entity kernels are compiled without Numba's reference counting (``_nrt=False``):
# they allocate nothing and keep no array beyond the call, so counting the references of
# the arrays they are handed only costs. Numba increfs every array argument on entry and
# decrefs it at each exit, and its pruning pass cannot remove the pairs across the loops
# and early returns of a shell element: the elastic shell's element function made ~30
# atomic reference-count calls per element, 21 % of its samples (perf, 10 k elements, one
# thread). Without them: 3 137 → 2 764 instructions per elastic element, 11 384 → 10 291
# per fabric (2×2) element (callgrind, exact counts), results bitwise the same. A kernel
# that tried to allocate would not compile ("NRT required but not enabled"); loop kernels
# keep reference counting (their parallel lowering needs it).
NO_REFCOUNT = dict(_nrt=False)


def kernel(fn):
    """Compile a per-entity function (serial, inlinable into loop kernels; allocates
    nothing: no reference counting, :data:`NO_REFCOUNT`)."""
    with _cache_dir():
        return numba.njit(**NO_REFCOUNT, **JIT_FLAGS)(fn)


def loop_kernel(fn):
    """Compile a loop over entities; ``prange`` loops run on threads."""
    with _cache_dir():
        return numba.njit(parallel=PARALLEL, **JIT_FLAGS)(fn)


def set_threads(n: int) -> None:
    """Use ``n`` threads in parallel loop kernels (1 ≤ n ≤ NUMBA_NUM_THREADS)."""
    top = numba.config.NUMBA_NUM_THREADS
    if not 1 <= n <= top:
        raise ValueError(f"threads = {n} is not valid: choose 1 to {top} on this machine")
    numba.set_num_threads(n)


def capped_threads(n: int, source: str = "threads") -> int:
    """``n`` threads, or NUMBA_NUM_THREADS (the cores of this machine unless set) if ``n``
    is more, with an :class:`~wovenimpact.errors.InputWarning` naming ``source`` and the cap."""
    top = numba.config.NUMBA_NUM_THREADS
    if n > top:
        import warnings

        from wovenimpact.errors import InputWarning

        warnings.warn(f"{source} = {n} is more than the {top} threads of this machine "
                      f"(NUMBA_NUM_THREADS = {top}): using {top}", InputWarning, stacklevel=2)
        return top
    return n


def _limit_threads(n: int) -> None:
    """Process-pool initializer: only ``n`` Numba threads exist in this worker, which
    uses the CLI's threading layer (:func:`configure_threading`) and ends itself when
    its parent is gone (:func:`_watch_parent`).

    ``reload_config`` rereads every setting from the environment. The kernels' cache
    directory does not depend on it: it is set while they are decorated
    (:func:`_cache_dir`). When it was set at import instead, a worker's reload lost it and
    the worker loaded Numba's per-file ``__pycache__`` entries, which can hold a kernel
    compiled against an older inlined callee — pool workers could compute with other
    code than the parent (a likely cause of the 5e-9 pool/Dask difference of issue 13's
    test)."""
    os.environ["NUMBA_NUM_THREADS"] = str(n)
    numba.config.reload_config()
    configure_threading()
    # a forked worker inherits the parent's launched thread pool: without this its
    # parallel loops still ran on the parent's thread count (2 per worker here)
    numba.set_num_threads(min(n, numba.get_num_threads()))
    threading.Thread(target=_watch_parent, args=(os.getppid(),), daemon=True,
                     name="wovenimpact-parent-watchdog").start()


PARENT_POLL_S = 0.5  # how often a pool worker checks that its parent is alive


def _watch_parent(parent: int) -> None:
    """Exit this worker process at once when ``parent`` has died (a killed sweep or
    design search): its parent id changes when it is orphaned. Without it a worker of
    a killed study went on computing its queued variants."""
    while os.getppid() == parent:
        time.sleep(PARENT_POLL_S)
    os._exit(1)


@contextlib.contextmanager
def process_pool(workers: int, threads: int = 1):
    """A pool of ``workers`` fresh processes whose kernels run on ``threads`` threads each.

    The workers are spawned, not forked: forking a process whose threading layer has
    started is unsafe for some layers (GNU OpenMP aborts), and a fresh worker creates
    exactly ``threads`` threads instead of carrying idle ones. (Two 1-thread runs side
    by side on 2 cores, 4 plies at 120 m/s: 1459 ns per element-cycle each; 5980 before
    the per-step ``np.vdot`` was replaced — its OpenBLAS threads spun, not Numba's.)

    No worker outlives the study: leaving the ``with`` block by an exception (Ctrl-C
    included) cancels the queued tasks and terminates the workers, and a worker whose
    parent is killed outright ends itself within :data:`PARENT_POLL_S`.
    """
    pool = ProcessPoolExecutor(max_workers=max(1, workers),
                               mp_context=multiprocessing.get_context("spawn"),
                               initializer=_limit_threads, initargs=(threads,))
    try:
        yield pool
    except BaseException:
        workers_now = list((pool._processes or {}).values())  # no public way to list them
        pool.shutdown(wait=False, cancel_futures=True)
        for proc in workers_now:
            proc.terminate()
        raise
    pool.shutdown(wait=True)


def block_kernel(fn):
    """A stage of a parallel loop's body that LLVM must inline there (``forceinline``):
    the loop's array arguments are ``noalias``, so that a lane loop in the stage
    vectorises without run-time alias checks (kernels.shell_blocks; theory §4.6).
    Numba's own inlining (``inline="always"``) in a ``prange`` body runs the parfor
    array analysis over the stage's tuples, which fails ("Dimension mismatch")."""
    with _cache_dir():
        return numba.njit(forceinline=True, **NO_REFCOUNT, **JIT_FLAGS)(fn)


def inline_kernel(fn):
    """A per-entity function inlined into its callers at Numba IR level (allocates
    nothing, like :func:`kernel`)."""
    with _cache_dir():
        return numba.njit(inline="always", **NO_REFCOUNT, **JIT_FLAGS)(fn)
