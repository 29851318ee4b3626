"""A stepper made 3x slower must be a gate regression, and the unchanged stepper must not (issue 33).

Writes a stepper module (``verimono.solve`` called ``REPEAT`` times on the same problem and grid: the same work
repeated), records one baseline with ``verimono check``, then runs the unchanged stepper and the 3x one
``--runs`` times each, alternating, and gates each run against the baseline (``verimono gate``).  Prints one
line per run and the tally; exits 0 when every slow run regressed and no unchanged run did.

Usage (from the repository root, the venv active)::

    python tools/gate_speed_trial.py [--runs 5] [--workdir DIR] [--executor auto]
    ../shared/tools/stress -- python tools/gate_speed_trial.py --runs 5       # on a busy machine

Each ``verimono check`` takes 2 s idle (10-20 s on a loaded 2-core machine).  verimono is the one ``python -m
verimono.cli`` imports: set ``PYTHONPATH`` to a checkout to try that one.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

STEPPER = '''\
import os
import verimono as vm

REPEAT = int(os.environ.get("TRIAL_REPEAT", "1"))


def my_stepper(problem, t):
    for _ in range(REPEAT - 1):
        vm.solve(problem, t)          # the same work, repeated
    return vm.solve(problem, t)
'''


def check(work: Path, out: str, repeat: int, executor: str) -> Path:
    env = dict(os.environ, TRIAL_REPEAT=str(repeat),
               PYTHONPATH=os.pathsep.join(p for p in (str(work), os.environ.get("PYTHONPATH", "")) if p))
    proc = subprocess.run([sys.executable, "-m", "verimono.cli", "check", "trial_stepper:my_stepper", "--profile", "ci", "--out", out,
                           "--executor", executor], cwd=work, env=env, capture_output=True, text=True)
    if proc.returncode != 0:
        sys.exit(f"verimono check exited {proc.returncode}:\n{proc.stdout}\n{proc.stderr}")
    return work / out / "results.json"


def gate(work: Path, baseline: Path, results: Path) -> tuple[int, list[str]]:
    proc = subprocess.run([sys.executable, "-m", "verimono.cli", "gate", "--baseline", str(baseline), "--results", str(results), "-v"],
                          cwd=work, capture_output=True, text=True)
    return proc.returncode, [ln.strip() for ln in proc.stdout.splitlines() if "timing" in ln]


def load_line(results: Path) -> str:
    stages = json.loads(results.read_text())["meta"]["stages"]
    return ", ".join(f"{s['name']} {s['duration']:.1f} s wall, {s.get('cpu', 0):.2f} s CPU, subject "
                     f"{s.get('subject_cpu', 0):.2f} s, waiting {s.get('cpu_waiting') or 0:.0%}" for s in stages)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--workdir", default=None)
    ap.add_argument("--executor", default="auto")
    args = ap.parse_args()
    work = Path(args.workdir or tempfile.mkdtemp(prefix="gate-trial-"))
    work.mkdir(parents=True, exist_ok=True)
    (work / "trial_stepper.py").write_text(STEPPER)
    base = check(work, "base", 1, args.executor)
    print(f"baseline: {load_line(base)}")
    tally = {"same": [], "slow": []}
    for k in range(args.runs):
        for kind, repeat in (("same", 1), ("slow", 3)):
            res = check(work, f"{kind}{k}", repeat, args.executor)
            status, lines = gate(work, base, res)
            tally[kind].append(status)
            print(f"{kind} {k + 1}: gate exit {status}; {load_line(res)}")
            for ln in lines:
                print(f"    {ln}")
    caught = sum(s == 1 for s in tally["slow"])
    clean = sum(s == 0 for s in tally["same"])
    print(f"3x slower stepper a regression: {caught} of {args.runs}; unchanged stepper passed: {clean} of {args.runs}")
    return 0 if caught == clean == args.runs else 1


if __name__ == "__main__":
    sys.exit(main())
