"""The kernel cache directory (jit.py): serial and parallel builds never share object
code, because Numba's own cache key ignores the ``parallel`` flag."""

from __future__ import annotations

import os
import subprocess
import sys


def cache_dir(serial: bool) -> str:
    env = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "WOVENIMPACT_SERIAL")}
    if serial:
        env["WOVENIMPACT_SERIAL"] = "1"
    out = subprocess.run([sys.executable, "-c", "import wovenimpact.jit as j; print(j._CACHE_DIR, j.PARALLEL)"],
                         env=env, capture_output=True, text=True, check=True)
    return out.stdout.split()


def test_serial_builds_have_their_own_cache_directory():
    par, par_flag = cache_dir(False)
    ser, ser_flag = cache_dir(True)
    assert par_flag == "True" and ser_flag == "False"
    assert ser == par + "-serial"
