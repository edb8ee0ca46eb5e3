"""The local process pool of sweeps and design searches: its workers run the parent's
code (same Numba cache directory and threading layer order) on the threads asked for."""

from __future__ import annotations

import numba

from wovenimpact.jit import KEPT_CONFIG, process_pool


def worker_config() -> dict:
    """The Numba settings a pool worker runs with (called in the worker)."""
    import numba

    return {"threads": numba.config.NUMBA_NUM_THREADS,
            **{key: getattr(numba.config, key) for key in KEPT_CONFIG}}


def test_pool_workers_keep_the_parents_kernel_cache_and_threading_layer():
    """A worker used to lose the cache directory keyed on the kernel sources (Numba's
    reload_config reset it), so it could load a kernel compiled from older sources."""
    with process_pool(1, threads=1) as pool:
        seen = pool.submit(worker_config).result()
    assert seen["threads"] == 1
    assert seen["CACHE_DIR"] and seen["CACHE_DIR"] == numba.config.CACHE_DIR
    for key in KEPT_CONFIG:
        assert seen[key] == getattr(numba.config, key)
