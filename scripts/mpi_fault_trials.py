#!/usr/bin/python3
"""Issue 33's fault checks of a run over MPI ranks, on real processes (docs/distributed.md).

  scripts/mpi_fault_trials.py SCENARIO [--trials 5] [--strata build/apps/strata] [--dir DIR]

1. The uninterrupted run: mpirun -np 2 strata flood SCENARIO -o DIR/whole.
2. Kill -9 trials: the run again; the folder is polled every 0.2 ms for the part a rank is
   writing (checkpoint.R-of-2.bin.tmp-PID-N) and that PID gets SIGKILL at its 2nd to 6th write,
   rank 0 and 1 in turn; then `--resume` at once.
3. Signal trials: SIGINT or SIGTERM to mpirun 2 to 5 s in (what Ctrl-C does); then `--resume`.

Each trial prints mpirun's exit status, whether the report says the run was stopped (signal
trials), the resume's exit status and which of the maps and series.csv differ from the
uninterrupted run (none is the pass). Pick a scenario whose run lasts 10 s or more, with several
output intervals. Prints only; exits 1 if any trial fails.
"""
import argparse
import os
import random
import re
import shutil
import signal
import subprocess
import sys
import time

from osgeo import gdal

MAPS = ["max_depth", "max_speed", "arrival_time", "inundation_duration", "final_depth"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenario")
    ap.add_argument("--trials", type=int, default=5)
    ap.add_argument("--strata", default=os.path.join(os.path.dirname(__file__), "..", "build", "apps", "strata"))
    ap.add_argument("--dir", default="mpi-fault-trials")
    a = ap.parse_args()
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1", OMP_NUM_THREADS="1",
               OMPI_MCA_mpi_yield_when_idle="1")
    command = ["mpirun", "--oversubscribe", "-np", "2", os.path.abspath(a.strata), "flood", a.scenario,
               "--no-pictures", "--no-plots"]
    os.makedirs(a.dir, exist_ok=True)

    def run(out, *extra):
        p = subprocess.run(command + ["-o", out, *extra], env=env, capture_output=True, text=True)
        return p.returncode, p.stdout + p.stderr

    def differs(out):
        whole = os.path.join(a.dir, "whole")
        bad = [m for m in MAPS
               if gdal.Open(f"{whole}/maps/{m}.tif").ReadAsArray().tobytes()
               != gdal.Open(f"{out}/maps/{m}.tif").ReadAsArray().tobytes()]
        with open(f"{whole}/series.csv", "rb") as x, open(f"{out}/series.csv", "rb") as y:
            if x.read() != y.read():
                bad.append("series.csv")
        return bad

    def resume_and_compare(out):
        code, log = run(out, "--resume")
        return code, differs(out) if code == 0 else ["the resume failed: " + log[-400:]]

    shutil.rmtree(os.path.join(a.dir, "whole"), ignore_errors=True)
    code, log = run(os.path.join(a.dir, "whole"))
    if code != 0:
        sys.exit("the uninterrupted run failed: " + log[-2000:])
    failed = 0
    for t in range(a.trials):
        out = os.path.join(a.dir, f"kill{t}")
        shutil.rmtree(out, ignore_errors=True)
        rank, nth = t % 2, random.Random(t).randint(2, 6)
        part = re.compile(rf"checkpoint\.{rank}-of-2\.bin\.tmp-(\d+)-")
        p = subprocess.Popen(command + ["-o", out], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        seen, killed = set(), None
        while p.poll() is None and killed is None:
            names = os.listdir(out) if os.path.isdir(out) else []
            for n in names:
                m = part.match(n)
                if m and n not in seen:
                    seen.add(n)
                    if len(seen) == nth:
                        os.kill(int(m.group(1)), signal.SIGKILL)
                        killed = n
            time.sleep(0.0002)
        p.wait()
        code, bad = resume_and_compare(out)
        ok = killed is not None and code == 0 and not bad
        failed += not ok
        print(f"kill -9 trial {t}: rank {rank} killed writing {killed} (its write {nth}); mpirun exit {p.returncode}; "
              f"resume exit {code}; differs: {', '.join(bad) or 'nothing'}", flush=True)
    for t, (sig, after) in enumerate([(signal.SIGINT, 2.0), (signal.SIGTERM, 3.5), (signal.SIGINT, 5.0)]):
        out = os.path.join(a.dir, f"signal{t}")
        shutil.rmtree(out, ignore_errors=True)
        p = subprocess.Popen(command + ["-o", out], env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        time.sleep(after)
        p.send_signal(sig)
        p.wait()
        report = os.path.join(out, "report.md")
        stopped = os.path.exists(report) and "stopped before the end" in open(report).read()
        code, bad = resume_and_compare(out)
        ok = stopped and code == 0 and not bad
        failed += not ok
        print(f"{signal.Signals(sig).name} to mpirun after {after} s: mpirun exit {p.returncode}; report marked "
              f"stopped: {stopped}; resume exit {code}; differs: {', '.join(bad) or 'nothing'}", flush=True)
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
