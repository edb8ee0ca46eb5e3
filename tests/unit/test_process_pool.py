"""The local process pool of sweeps and design searches: its workers run the parent's
code (the same kernel cache, keyed on the kernel sources, and threading layer order) on
the threads asked for."""

from __future__ import annotations

import numba

from wovenimpact.jit import process_pool


def worker_config() -> dict:
    """The Numba settings and a kernel's cache path in a pool worker (called there)."""
    import numba

    from wovenimpact.kernels.contact_law import pair_force

    return {"threads": numba.config.NUMBA_NUM_THREADS,
            "cache_path": pair_force._cache._cache_path,
            "priority": list(numba.config.THREADING_LAYER_PRIORITY)}


def test_pool_workers_keep_the_parents_kernel_cache_and_threading_layer():
    """A worker used to lose the cache directory keyed on the kernel sources (Numba's
    reload_config reset it), so it could load a kernel compiled from older sources: its
    kernels must be cached where the parent's are."""
    from wovenimpact.kernels.contact_law import pair_force

    with process_pool(1, threads=1) as pool:
        seen = pool.submit(worker_config).result()
    assert seen["threads"] == 1
    assert seen["cache_path"] == pair_force._cache._cache_path
    assert seen["priority"] == list(numba.config.THREADING_LAYER_PRIORITY)
