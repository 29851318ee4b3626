"""What ``verimono check`` of a stepper imports in its own process (issue 43 item 3: a verdict ≤ 1 s beyond the
search).  The command's process builds the units, ships them to the workers and writes the report; the search
runs in the workers, which are forked from it and import what their units need.  A heavy module the command's
own process imports and never uses is paid before the first worker starts (or before the command ends), on
every run: SciPy's ``special`` (0.04-0.08 s: the Student quantile of the order fits, which the workers compute
and ship back with the studies' verdicts), its optimizers and quadrature (check2, check3), its statistics,
matplotlib (the report's plots are drawn by the drawer process), the QP back-ends and the optional executors."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

#: what the command's own process must not import for a stepper's check (each is used by the workers, the
#: drawer, or other commands)
NOT_IN_THE_PARENT = ("scipy.special", "scipy.optimize", "scipy.integrate", "scipy.stats", "matplotlib",
                     "qpsolvers", "proxsuite", "cvxpy", "dask")

#: run in a fresh interpreter: the check as the command line runs it (two worker processes), then the heavy
#: modules the command's process holds, and whether the studies' verdicts came back decided
SCRIPT = """
import sys
from verimono.cli import main
status = main(["check", "mysolver:my_stepper", "--profile", "dev", "--executor", "process:2", "--out", "out",
               "--seed", "0"])
heavy = {heavy!r}
print(status)
print(" ".join(m for m in sorted(sys.modules) if m in heavy or m.startswith(tuple(h + "." for h in heavy))) or "-")
"""


def _readme_stepper() -> str:
    text = (REPO / "README.md").read_text(encoding="utf-8")
    blocks = [b for b in re.findall(r"```python\n(.*?)```", text, re.S) if b.startswith("# mysolver.py")]
    assert len(blocks) == 1
    return blocks[0]


@pytest.mark.slow
def test_the_check_of_a_stepper_imports_no_heavy_module_its_process_does_not_use(tmp_path):
    (tmp_path / "mysolver.py").write_text(_readme_stepper())
    out = subprocess.run([sys.executable, "-c", SCRIPT.format(heavy=NOT_IN_THE_PARENT)], cwd=tmp_path,
                         capture_output=True, text=True, timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    status, loaded = out.stdout.splitlines()[-2:]
    assert status == "0", out.stdout[-3000:]          # the check ran and passed: its studies were decided
    assert loaded == "-", f"`verimono check` of a stepper imported in its own process: {loaded}"


#: an operator's check: which modules the command's process holds when it forks the workers
OPERATOR_SCRIPT = """
import sys
from verimono.execution import executors
from verimono.cli import main

held = {}
prestart = executors.ProcessRunner.prestart

def at_fork(self):
    held.update({m: m in sys.modules for m in ("verimono.checks.operator_battery", "hypothesis")})
    return prestart(self)

executors.ProcessRunner.prestart = at_fork
status = main(["check", "mysolver:moving_disc", "--profile", "dev", "--executor", "process:2", "--out", "out",
               "--seed", "0"])
print(status)
print(held)
"""


@pytest.mark.slow
def test_the_check_of_an_operator_forks_its_workers_with_the_battery_loaded(tmp_path):
    """The operator battery (its search engine, hypothesis: 0.17 s CPU) is imported once, before the workers
    fork, and inherited: on 2bc1b4d the command's process imported it after the fork, to name ``check_operator``
    in the unit, and the worker that unpickled the unit imported it again before its search could start."""
    (tmp_path / "mysolver.py").write_text(_readme_stepper())
    out = subprocess.run([sys.executable, "-c", OPERATOR_SCRIPT], cwd=tmp_path, capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0, out.stderr[-3000:]
    status, held = out.stdout.splitlines()[-2:]
    assert status == "0", out.stdout[-3000:]
    assert held == str({"verimono.checks.operator_battery": True, "hypothesis": True}), held
