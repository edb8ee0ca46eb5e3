"""Importing wovenimpact changes no process-wide setting; the CLI sets threading when
it starts (issue 12, item 7). Each check runs in a fresh interpreter."""

from __future__ import annotations

import json
import os
import subprocess
import sys

SNAPSHOT = """
import json, os, sys
import numba

def snapshot():
    c = numba.config
    return {"environ": dict(os.environ), "layer": c.THREADING_LAYER,
            "priority": list(c.THREADING_LAYER_PRIORITY), "cache_dir": c.CACHE_DIR,
            "threads": c.NUMBA_NUM_THREADS}
"""

IMPORT_ALL = SNAPSHOT + """
before = snapshot()
import importlib, pkgutil, wovenimpact
for m in pkgutil.walk_packages(wovenimpact.__path__, "wovenimpact."):
    importlib.import_module(m.name)
print(json.dumps({"before": before, "after": snapshot(),
                  "tbb": any("libtbb" in line for line in open("/proc/self/maps"))}))
"""

CLI_START = SNAPSHOT + """
from typer.testing import CliRunner
from wovenimpact.cli import app
before = snapshot()
result = CliRunner().invoke(app, ["ballistics", "v50", "no_such_results.csv"])
print(json.dumps({"before": before, "after": snapshot(), "exit": result.exit_code}))
"""


def _run(code: str) -> dict:
    env = {k: v for k, v in os.environ.items()
           if k not in ("NUMBA_THREADING_LAYER", "OMP_WAIT_POLICY", "GOMP_SPINCOUNT",
                        "KMP_BLOCKTIME", "NUMBA_CACHE_DIR")}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env=env, check=True, timeout=600)
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_importing_every_module_changes_no_process_setting():
    r = _run(IMPORT_ALL)
    assert r["after"] == r["before"]  # os.environ and Numba's threading and cache config
    if sys.platform.startswith("linux"):
        assert not r["tbb"], "libtbb was loaded into the process at import"


def test_the_cli_sets_threading_when_it_starts():
    r = _run(CLI_START)
    assert r["exit"] == 2  # the missing file is a clean error, after the app's callback
    assert r["before"]["environ"].get("OMP_WAIT_POLICY") is None
    assert r["after"]["environ"]["OMP_WAIT_POLICY"] == "passive"
    assert r["after"]["priority"] == ["tbb", "workqueue", "omp"]
