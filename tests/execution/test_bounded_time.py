"""Issue 25, bounded time: every call of the subject runs under the unit's budget — the root-cause probe
before an operator law's search, and the trajectory sample after a stepper's convergence unit.

No wall-clock assertions: each test counts the subject's calls (an unbounded call would sleep its full
time and be counted again) and reads the records.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

import verimono as vm
from verimono.checks.engine.search import ROOT_LAW, _SLOW
from verimono.reference import get
from verimono.records.results import PASSED, CheckResult
from verimono.execution.timeouts import budget, supported

pytestmark = pytest.mark.skipif(not supported(), reason="time limits need a POSIX timer in the main thread")


def _sleeper(calls: list, seconds: float = 1.0):
    def resolvent(x, lam, t):
        calls.append(1)
        time.sleep(seconds)          # interrupted by the unit's timer
        return np.asarray(x) / (1 + lam)
    return vm.operator_from_resolvent(resolvent, 2, name="sleeper")


def test_a_resolvent_that_hangs_is_probed_once_under_the_budget():
    """``root_cause`` called the resolvent 4 times per law outside the limit (117 s for a 2 s budget)."""
    calls: list = []
    op = _sleeper(calls)
    with budget(0.05):
        rep = vm.check_operator(op, seed=0, examples=5)
    assert len(calls) == 1                                    # one probe, cut short, then remembered
    root = next(r for r in rep if r.check == ROOT_LAW)
    assert root.status == "failed" and "does not return within the time budget" in root.message
    others = [r for r in rep if r.check != ROOT_LAW]
    assert all(r.status == "skipped" for r in others)                 # never a battery of failures
    assert len([r for r in others if "does not return within" in r.message]) >= 6
    _SLOW.clear()


def test_a_fast_resolvent_is_not_remembered_as_slow():
    op = vm.operator_from_resolvent(lambda x, lam, t: np.asarray(x) / (1 + lam), 2, name="fast")
    with budget(5.0):
        rep = vm.check_operator(op, seed=0, examples=5)
    assert id(op) not in _SLOW and next(r for r in rep if r.check == ROOT_LAW).status == PASSED


def test_no_trajectory_sample_after_a_unit_that_ran_out_of_time():
    """``sample_trajectory`` ran unbounded after the timed-out unit (89 s for a 3 s budget)."""
    from verimono.run.stages.builtin import _convergence_unit

    calls: list = []

    def slow(problem, t_grid):
        calls.append(len(t_grid))
        time.sleep(1.0)
        return vm.solve(problem, t_grid)

    with budget(0.05):
        rep = _convergence_unit(slow, get("moving box"))
    (rec,) = rep.results
    assert rec.status == "failed" and "timed out" in rec.message
    assert len(calls) == 1 and rep.trajectories == []
    assert rec.details["trajectory_error"].startswith("not sampled")


def test_the_trajectory_sample_runs_under_the_budget(monkeypatch):
    import verimono.run.stages.builtin as builtin
    from verimono.run.stages.builtin import _convergence_unit

    monkeypatch.setattr(builtin, "check_convergence_order",
                        lambda stepper, problem: CheckResult("convergence_order", "s", PASSED, worst=0.1, bound=1.0))
    calls: list = []

    def slow(problem, t_grid):
        calls.append(1)
        time.sleep(1.0)
        return vm.solve(problem, t_grid)

    with budget(0.05):
        rep = _convergence_unit(slow, get("moving box"))
    assert len(calls) == 1 and rep.trajectories == []
    assert "UnitTimeout" in rep.results[0].details["trajectory_error"]
