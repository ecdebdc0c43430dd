#!/usr/bin/env python3
"""Two rules of Strata's layering (issue 34), checked on the source tree.

1. One-process code compiles without MPI: no header outside an `mpi/` folder, a test's MPI
   support or the scenario library (which runs over MPI ranks) includes <mpi.h> or a
   `strata/sim/mpi/` header.
2. Inside scenario/src no include runs back up: each file has a floor (below), and a file includes
   only the scenario/src headers of floors below or at its own. The run loop (run.cpp) is the top.

Usage: check_layers.py [ROOT]   (exit 1 and one line per breach)
"""
import os
import re
import subprocess
import sys

# scenario/src's floors, lowest first: a file's floor is its stem's.
SCENARIO_FLOORS = {
    "domain_rows": 0, "domain": 0, "scenario": 0, "settle": 1, "breach": 1, "pieces": 2, "probes": 2, "styles": 2, "check_scenario": 1, "compare": 3, "checkpoint": 2,
    "report": 2, "build_rows": 3, "run": 4,
}
MPI_OK = ("/mpi/", "tests/support/mpi_support.hpp", "tests/sim/mpi_compare.hpp", "bench/", "scenario/src/")


def code_lines(text):
    """Lines without // comments (enough for #include lines)."""
    for n, line in enumerate(text.splitlines(), 1):
        yield n, line.split("//", 1)[0]


def main():
    root = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), ".."))
    files = subprocess.run(["git", "ls-files"], cwd=root, capture_output=True, text=True, check=True).stdout.split()
    bad = []
    mpi = re.compile(r'#\s*include\s*[<"](mpi\.h|strata/sim/mpi/[^>"]*)[>"]')
    local = re.compile(r'#\s*include\s*"([\w./]+)\.hpp"')
    for f in files:
        if not f.endswith((".hpp", ".cpp", ".h")):
            continue
        text = open(os.path.join(root, f), errors="replace").read()
        if f.endswith((".hpp", ".h")) and not any(part in f for part in MPI_OK):
            for n, line in code_lines(text):
                m = mpi.search(line)
                if m:
                    bad.append(f"{f}:{n}: a header one-process code includes names MPI ({m.group(1)})")
        if f.startswith("scenario/src/"):
            stem = os.path.splitext(os.path.basename(f))[0]
            floor = SCENARIO_FLOORS.get(stem)
            if floor is None:
                bad.append(f"{f}: not on a floor of scripts/check_layers.py's SCENARIO_FLOORS")
                continue
            for n, line in code_lines(text):
                m = local.search(line)
                if not m:
                    continue
                other = os.path.basename(m.group(1))
                theirs = SCENARIO_FLOORS.get(other)
                if theirs is None or theirs > floor:
                    bad.append(f"{f}:{n}: includes {other}.hpp, above its own floor ({theirs} > {floor})")
    for b in bad:
        print(b)
    print(f"check_layers: {len(bad)} breach(es)", file=sys.stderr)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
