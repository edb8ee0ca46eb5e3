"""``make bench``: the explicit step's cost (see :mod:`wovenimpact.benchmark`).

Options: ``--sizes=10000,100000``, ``--kinds=metal,fabric,fabric_reduced``,
``--threads=1,2``, ``--steps=N``, ``--json`` (prints {"cases": [{"name", "elements", "threads", "ns_per_element_cycle",
"shares"}], "machine", "threading_layer"}), ``--no-machine-line`` (``make bench`` prints
it first), ``--save=PATH`` (also writes the ``--json`` object to PATH). Same as
``wovenimpact bench``.
"""

from __future__ import annotations

import json
import os
import sys

import numba

from wovenimpact.benchmark import DEFAULT_SIZES, case_line, machine, machine_line, run_cases
from wovenimpact.jit import configure_threading
from performance_page import save_json  # benchmarks/ is the script's folder


def main() -> None:
    configure_threading()  # the CLI's threading layer and wait policy, as `wovenimpact bench`
    sizes = DEFAULT_SIZES
    kinds = ("elastic", "metal", "fabric", "fabric_reduced")
    thread_counts = sorted({1, min(2, numba.config.NUMBA_NUM_THREADS)})
    steps = 20
    for arg in sys.argv[1:]:
        if arg.startswith("--sizes="):
            sizes = tuple(int(s) for s in arg.split("=", 1)[1].split(","))
        elif arg.startswith("--kinds="):
            kinds = tuple(arg.split("=", 1)[1].split(","))
        elif arg.startswith("--threads="):
            thread_counts = [int(s) for s in arg.split("=", 1)[1].split(",")]
        elif arg.startswith("--steps="):
            steps = int(arg.split("=", 1)[1])
    quiet = "--json" in sys.argv
    if not quiet and "--no-machine-line" not in sys.argv:
        print(machine_line(), flush=True)
    cases = run_cases(kinds, sizes, thread_counts, steps,
                      report=None if quiet else (lambda c: print(case_line(c), flush=True)))
    doc = {"cases": cases, "machine": machine(), "threading_layer": numba.threading_layer(),
           "load_average": list(os.getloadavg())}  # how busy the machine was (page)
    save_json(doc, sys.argv[1:])
    if quiet:
        print(json.dumps(doc))
    else:
        print(f"threading layer: {numba.threading_layer()}")



if __name__ == "__main__":
    main()
